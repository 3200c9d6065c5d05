#version 460
// Cones and sheets, generated on the CPU in plane coordinates (u, v) with the plateau parameter
// t, drawn at depth t so that the darkest primitive wins (Haines §2). Each vertex also carries
// the silhouette point it is measured from, the edge's normal and its caster's number.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Plateau { PlateauView plateau; };

layout(location = 0) in vec3 in_uvt;
layout(location = 1) in vec2 in_foot;
layout(location = 2) in vec2 in_normal;
layout(location = 3) in float in_caster;
layout(location = 0) out float out_t;
layout(location = 1) out vec2 out_uv;
layout(location = 2) out vec2 out_foot;
layout(location = 3) flat out vec2 out_normal;
layout(location = 4) flat out uint out_caster;

void main() {
    vec2 uv = (in_uvt.xy - plateau.window.xy) / (plateau.window.zw - plateau.window.xy);
    out_t = in_uvt.z;
    out_uv = uv;
    out_foot = (in_foot - plateau.window.xy) / (plateau.window.zw - plateau.window.xy);
    out_normal = in_normal / (plateau.window.zw - plateau.window.xy);
    out_caster = uint(in_caster);
    gl_Position = vec4(uv * 2.0 - 1.0, in_uvt.z, 1.0);
}
