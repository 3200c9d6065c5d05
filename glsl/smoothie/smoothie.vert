#version 460
// Smoothie edges and corners, generated on the CPU in the light view's tangent plane.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Light { LightView light; };

layout(location = 0) in vec3 in_tangent_depth; // x/z, y/z, blocker depth b
layout(location = 1) in vec2 in_shape;         // |shape| = linear alpha

layout(location = 0) out float out_b;
layout(location = 1) out vec2 out_shape;

void main() {
    vec2 uv = (in_tangent_depth.xy - light.extent.xy) / (light.extent.zw - light.extent.xy);
    out_b = in_tangent_depth.z;
    out_shape = in_shape;
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
