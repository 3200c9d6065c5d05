#version 460
// Cones and sheets, generated on the CPU in plane coordinates (u, v) with the plateau parameter
// t, drawn at depth t so that the darkest primitive wins (Haines §2).
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Plateau { PlateauView plateau; };

layout(location = 0) in vec3 in_uvt;
layout(location = 0) out float out_t;

void main() {
    vec2 uv = (in_uvt.xy - plateau.window.xy) / (plateau.window.zw - plateau.window.xy);
    out_t = in_uvt.z;
    gl_Position = vec4(uv * 2.0 - 1.0, in_uvt.z, 1.0);
}
