#version 460
// The smoothie buffer in one pass (the paper's multiple-render-target remark, §4): depth b and
// alpha, both composited with minimum blending, so the nearest smoothie depth and the minimum
// alpha (Parker's thresholding, §3.1) come out in any drawing order.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Light { LightView light; };
layout(set = 0, binding = 1) uniform sampler2D shadow_map;

layout(location = 0) in float in_b;
layout(location = 1) in vec2 in_shape;

layout(location = 0) out float out_b;
layout(location = 1) out float out_alpha;

// Depth along this texel's ray where it meets the ground plane (kernel.z: its height, kernel.w:
// the light's), infinite when it does not: view-space rays (x/z, y/z, 1) advance one unit of
// depth per unit of z.
float ground_depth(vec2 uv) {
    vec2 tangent = mix(light.extent.xy, light.extent.zw, uv);
    // World y of the ray (x/z, y/z, 1): the view matrix's rows are the light's axes.
    float down = dot(vec3(tangent, 1.0), light.view[1].xyz);
    return down < 0.0 ? (light.kernel.z - light.kernel.w) / down : 1.0 / 0.0;
}

void main() {
    float alpha = clamp(length(in_shape), 0.0, 1.0);
    // Equation 1 with r, the nearest surface behind this texel (Figure 11 reads it from the
    // map): the casters from the pass-1 map, the ground exactly, from its plane.
    vec2 uv = gl_FragCoord.xy / light.kernel.x;
    float r = texelFetch(shadow_map, ivec2(min(uv * light.bias.w, vec2(light.bias.w - 1.0))), 0).r;
    r = min(r, ground_depth(uv));
    float f = in_b / r;
    if (f >= 1.0) {
        discard; // behind a blocker: hidden from the light
    }
    out_b = in_b;
    out_alpha = clamp(alpha / (1.0 - f), 0.0, 1.0);
}
