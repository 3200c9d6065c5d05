// The smoothie buffer's depths (b of the outer smoothies and of the inner quads) as codes in
// [0, 1]: log2(b / near) over log2(far / near), for 16-bit unsigned normalized channels. The
// paper keeps these depths in a depth buffer and alpha in a fixed-point one (§4); here one
// target holds both at half the bytes of 32-bit floats, which on lavapipe is most of the
// smoothie pass (its clear) and a quarter of the resolve's fetches. Every depth of the frustum
// gets the same relative precision, ln(far / near) / 65535 ≤ 1.4e-4 (near ≥ far·1e-4), finer
// than a half float's 4.9e-4, and the code is monotonic: minimum blending and the resolve's
// depth comparisons work on codes directly. Also the light view's window coordinates, which the
// smoothie shaders' probes of the map share.
#ifndef SOFTSHADOW_SMOOTHIE_DEPTH_GLSL
#define SOFTSHADOW_SMOOTHIE_DEPTH_GLSL
#include "interface.glsl"

// How much deeper than a caster's surface another surface must lie to count as apart from it:
// 2 %, more than a caster's own face slants across the few texels between a probe and the
// smoothie it decides for (the resolve's LIMIT_SLACK, centred.glsl's partial smoothies).
const float APART = 1.02;

// What an inner quad with α < 1 (centred.glsl) leaves in the outer smoothies' depth channel,
// where the resolve's mask draw finds every smoothie with one gather (resolve.frag's
// near_smoothie): the largest code below 1, behind every receiver the frustum holds, so that no
// receiver counts as behind it.
const float INNER_MARK = 65534.0 / 65535.0;

// 0 at (and before) near, 1 at far and beyond: an empty texel's code, behind any receiver.
float depth_code(LightView light, float depth) {
    return clamp(log2(depth / light.depths.x) / light.depths.z, 0.0, 1.0);
}

vec4 depth_code(LightView light, vec4 depth) {
    return clamp(log2(depth / light.depths.x) / light.depths.z, 0.0, 1.0);
}

// The light view's window coordinates ([0, 1]², the map's uv) of a point in its tangent plane.
vec2 tangent_uv(LightView light, vec2 tangent) {
    return (tangent - light.extent.xy) / (light.extent.zw - light.extent.xy);
}

// How far outside an edge a probe of the map looks: 1.5 map texels, so the texel there lies
// wholly outside the caster's own rasterized outline (its centre is at least 0.8 texels from the
// edge). smoothie.vert's probe and centred.glsl's corner_open both look there.
float probe_step(LightView light) {
    vec2 texel = (light.extent.zw - light.extent.xy) / light.bias.w;
    return 1.5 * max(texel.x, texel.y);
}

// A texel of the coarser of the map and the smoothie buffer, in tangent units (both span the
// light view's window): how far the two grids may place one edge apart.
float coarser_texel(LightView light) {
    return max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / min(light.bias.w, light.kernel.x);
}

// The depths codes stand for.
vec4 code_depth(LightView light, vec4 code) {
    return light.depths.x * exp2(code * light.depths.z);
}

// Depth along the light's ray through `uv` (the light view's window, [0, 1]²) where it meets
// the ground plane (kernel.z: its height, kernel.w: the light's), infinite when it does not:
// view-space rays (x/z, y/z, 1) advance one unit of depth per unit of z.
float ground_depth(LightView light, vec2 uv) {
    vec2 tangent = mix(light.extent.xy, light.extent.zw, uv);
    // World y of the ray (x/z, y/z, 1): the view matrix's rows are the light's axes.
    float down = dot(vec3(tangent, 1.0), light.view[1].xyz);
    return down < 0.0 ? (light.kernel.z - light.kernel.w) / down : 1.0 / 0.0;
}

#endif
