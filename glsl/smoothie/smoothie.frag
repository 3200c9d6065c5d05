#version 460
// The smoothie buffer in one pass and one target (the paper's multiple-render-target remark,
// §4, packed): depth b (its code, depth.glsl) and remapped alpha α' (Equation 1) of the outer
// smoothies, and with inner quads (issue 20) α and 1 − code(b) of those, all composited with
// minimum blending, so the nearest smoothie depth and the minimum alpha (Parker's
// thresholding, §3.1), the shallowest inner alpha and the farthest inner depth come out in any
// drawing order. Every channel clears to 1, and each kind writes the other's channels at 1,
// which minimum blending leaves as they are; an inner alpha of 1 is umbra, as no inner quad.
//
// The shallowest inner alpha is the lightest: over a blocker, the truth at a convex corner is
// lighter than either edge's half plane alone (the blocker is their intersection), the
// opposite of the outside, where the darkest wins. Inner quads of other casters never meet
// here: the acceptance test below keeps each to its own caster's texels.
#include "interface.glsl"
#include "depth.glsl"

layout(set = 0, binding = 0) uniform Light { LightView light; };
layout(set = 0, binding = 1) uniform sampler2D shadow_map;

layout(location = 0) noperspective in float in_b;
layout(location = 1) in vec2 in_shape; // perspective-correct: distance over size (smoothie.vert)
layout(location = 2) noperspective in vec2 in_probe;
layout(location = 3) flat in vec2 in_range;

layout(location = 0) out vec4 out_smoothie;

// Depth along this texel's ray where it meets the ground plane (kernel.z: its height, kernel.w:
// the light's), infinite when it does not: view-space rays (x/z, y/z, 1) advance one unit of
// depth per unit of z.
float ground_depth(vec2 uv) {
    vec2 tangent = mix(light.extent.xy, light.extent.zw, uv);
    // World y of the ray (x/z, y/z, 1): the view matrix's rows are the light's axes.
    float down = dot(vec3(tangent, 1.0), light.view[1].xyz);
    return down < 0.0 ? (light.kernel.z - light.kernel.w) / down : 1.0 / 0.0;
}

float map_at(vec2 uv) {
    float size = light.bias.w;
    return texelFetch(shadow_map, ivec2(clamp(uv * size, vec2(0.0), vec2(size - 1.0))), 0).r;
}

void main() {
    float alpha = clamp(length(in_shape), 0.0, 1.0);
    vec2 uv = gl_FragCoord.xy / light.kernel.x;
    float caster = map_at(uv);
    if (in_range.y > 0.0) {
        // An inner texel counts only where this edge bounds this caster's hard shadow: nothing
        // cast just outside the edge (not a fold of the caster, no other caster abutting, which
        // may hide the light there), and the map's blocker here within the caster's depth range
        // (not another caster in front or behind), within two texels' depth.
        float slack = 2.0 * in_b * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / light.bias.w;
        bool own = caster >= in_range.x - slack && caster <= in_range.y + slack;
        if (!own || map_at(in_probe) < light.kernel.y) {
            discard;
        }
        out_smoothie = vec4(1.0, 1.0, alpha, 1.0 - depth_code(light, in_b));
        return;
    }
    // Equation 1 with r, the nearest surface behind this texel (Figure 11 reads it from the
    // map): the casters from the pass-1 map, the ground exactly, from its plane.
    float f = in_b / min(caster, ground_depth(uv));
    if (f >= 1.0) {
        discard; // behind a blocker: hidden from the light
    }
    out_smoothie = vec4(depth_code(light, in_b), clamp(alpha / (1.0 - f), 0.0, 1.0), 1.0, 1.0);
}
