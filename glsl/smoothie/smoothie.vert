#version 460
// Smoothie edges, corners and inner quads, generated on the CPU or by silhouettes.comp in the
// light view's tangent plane.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Light { LightView light; };

layout(location = 0) in vec3 in_tangent_depth; // x/z, y/z, blocker depth b
layout(location = 1) in vec2 in_shape;         // |shape| = linear alpha
layout(location = 2) in vec2 in_foot;          // inner quads: the edge's point, tangent coordinates
layout(location = 3) in vec2 in_normal;        // inner quads: the edge's outward normal
layout(location = 4) in vec2 in_range;         // inner quads: the caster's depth range; 0: outer
layout(location = 5) in float in_w;            // projective weight 1/t: edges' alpha exact (SmoothieVertex::w)
layout(location = 6) in float in_channel;      // centred: the caster's channel, 0 or 1

// Linear in the buffer but the alpha (`shape`), which w makes distance over size.
layout(location = 0) noperspective out float out_b;
layout(location = 1) out vec2 out_shape;
layout(location = 2) noperspective out vec2 out_probe;
layout(location = 3) flat out vec2 out_range;
layout(location = 4) flat out float out_channel;

vec2 to_uv(vec2 tangent) {
    return (tangent - light.extent.xy) / (light.extent.zw - light.extent.xy);
}

void main() {
    vec2 uv = to_uv(in_tangent_depth.xy);
    out_b = in_tangent_depth.z;
    out_shape = in_shape;
    // 1.5 map texels outside the edge: the texel there lies wholly outside the caster's own
    // rasterized outline (its centre is at least 0.8 texels from the edge).
    vec2 texel = (light.extent.zw - light.extent.xy) / light.bias.w;
    out_probe = to_uv(in_foot + in_normal * 1.5 * max(texel.x, texel.y));
    out_range = in_range;
    out_channel = in_channel;
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0) * in_w;
}
