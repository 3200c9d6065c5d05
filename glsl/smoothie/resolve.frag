#version 460
// Make shadows (Chan & Durand §3, step 5): behind a blocker in the shadow map, V = 0; else
// behind a smoothie, V = its remapped alpha α' = α / (1 − b/r) (Equation 1); else 1. Both
// tests at the four nearest texels, filtered bilinearly, then the falloff curve. CENTRED
// (issue 20): the penumbra straddles the hard edge, t = ½ + ½α' on the lit side and ½ − ½α'
// over the blocker, each smoothie texel classified by the map at its own centre.
#include "interface.glsl"
#include "camera.glsl"
#include "shadow.glsl"
#include "falloff.glsl"
#include "depth.glsl"

layout(constant_id = 0) const bool CENTRED = false;
// The smoothie buffer's texels are the shadow map's (equal sizes over one frustum).
layout(constant_id = 1) const bool SAME_GRID = true;
// The resolve's two draws (smoothie.rs): MASK writes V where no smoothie is near, where V is
// the hard test, and discards the rest, which the second draw, with its depth test, shades
// alone. llvmpipe runs every branch of a fragment shader, so without the mask every pixel paid
// for the smoothie fetches; a GPU skips them too, but only in whole warps.
layout(constant_id = 2) const bool MASK = false;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Light { LightView light; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D shadow_map;
layout(set = 0, binding = 5) uniform sampler2D smoothies; // b, α'; centred: also α, 1 − b inside (depth.glsl codes)

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

// The four smoothie texels around a lookup, in gather order (i0,j1) (i1,j1) (i1,j0) (i0,j0),
// each fetched whole: llvmpipe runs every branch of a fragment shader, so one fetch of all
// channels costs less than a gather per channel.
struct Texels {
    ivec2 base;   // texel (i0, j0)
    vec2 f;       // bilinear weights
    vec4 b;       // the outer smoothies' depth codes
    vec4 outer;   // their remapped alpha α'
    vec4 inner;   // the inner quads' alpha α, 1 (umbra) where none (centred only)
    vec4 inner_b; // their depth codes (centred only)
    vec4 behind;  // 1 where the receiver lies behind the texel's outer smoothie
};

const ivec2 GATHER_ORDER[4] = ivec2[4](ivec2(0, 1), ivec2(1, 1), ivec2(1, 0), ivec2(0, 0));

// Where a lookup falls in the smoothie buffer, in texels from texel (0, 0)'s centre.
vec2 smoothie_pos(vec2 uv) {
    float size = light.kernel.x;
    return clamp(uv * size - 0.5, vec2(0.0), vec2(size - 1.001));
}

Texels texels(vec2 uv, float depth) {
    float code = depth_code(light, depth);
    Texels t;
    vec2 pos = smoothie_pos(uv);
    t.base = ivec2(pos);
    t.f = fract(pos);
    for (int k = 0; k < 4; k++) {
        vec4 texel = texelFetch(smoothies, t.base + GATHER_ORDER[k], 0);
        t.b[k] = texel.x;
        t.outer[k] = texel.y;
        t.inner[k] = texel.z;
        t.inner_b[k] = 1.0 - texel.w;
    }
    t.behind = vec4(greaterThan(vec4(code), t.b));
    return t;
}

// The paper's smoothie test: α' where the receiver lies behind a smoothie, else 1.
float outer_test(vec2 uv, float depth) {
    Texels t = texels(uv, depth);
    return bilinear(t.f, mix(vec4(1.0), t.outer, t.behind));
}

// Centred V: the penumbra parameter, 0 umbra .. ½ hard edge .. 1 lit, through the falloff;
// `umbra`, the hard test, where no smoothie is near (exactly the hard shadow for a point light).
// `map`: the shadow map's texels around the lookup, which are the smoothie texels' own where
// the two grids agree (SAME_GRID).
float centred_test(vec2 uv, float depth, float umbra, MapTexels map) {
    Texels t = texels(uv, depth);
    if (t.behind == vec4(0.0) && t.inner == vec4(1.0)) {
        return umbra;
    }
    // Equation 1 for the inner half, r the receiver's depth (contact, b ≥ r: hard).
    vec4 a = clamp(t.inner / max(1.0 - min(code_depth(light, t.inner_b) / depth, vec4(1.0)), 1e-6), 0.0, 1.0);
    // The map at each smoothie texel's centre: is the receiver behind a caster there?
    vec4 caster = map.d;
    float map_size = light.bias.w;
    if (!SAME_GRID) {
        ivec2 last = ivec2(map_size - 1.0);
        for (int k = 0; k < 4; k++) {
            vec2 centre = (vec2(t.base + GATHER_ORDER[k]) + 0.5) / light.kernel.x;
            caster[k] = texelFetch(shadow_map, min(ivec2(centre * map_size), last), 0).r;
        }
    }
    // Lit: the outer half. Shadowed: only an inner half lightens it, darkened by the outer
    // penumbra of a caster in front of the map's (blockers taken as independent, which errs
    // dark; the caster's own outer smoothies, at its depth, are no other blocker).
    vec4 outer = mix(vec4(1.0), t.outer, t.behind);
    vec4 lit = 0.5 + 0.5 * outer;
    float slack = 2.0 * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / map_size;
    vec4 in_front = t.behind * vec4(lessThan(t.b, depth_code(light, caster * (1.0 - slack))));
    vec4 shadowed = (0.5 - 0.5 * a) * mix(vec4(1.0), lit, in_front);
    return falloff_at(bilinear(t.f, mix(lit, shadowed, vec4(lessThan(caster, vec4(depth))))));
}

// Whether V at this lookup can differ from the hard test's: an alpha below 1 among the four
// smoothie texels (an outer α' of 1 is lit, an inner α of 1 umbra), or the hard test's own
// bilinear edge (0 < umbra < 1), which the falloff shapes. Exact where the grids agree
// (SAME_GRID); otherwise the mask draw keeps the map's hard test where the centred one would
// classify the smoothie texels' centres instead.
bool near_smoothie(vec2 uv, float umbra) {
    vec2 corner = (floor(smoothie_pos(uv)) + 1.0) / light.kernel.x;
    vec4 alpha = textureGather(smoothies, corner, 1);
    if (CENTRED) {
        alpha = min(alpha, textureGather(smoothies, corner, 2));
    } else if (umbra == 0.0) {
        return false; // outer only: the map's umbra stays umbra
    }
    return (umbra > 0.0 && umbra < 1.0) || any(lessThan(alpha, vec4(1.0)));
}

void main() {
    Surface s = read_surface(frame, camera_depth, camera_normal, in_uv);
    if (!s.receives) {
        out_visibility = 1.0;
        return;
    }
    // A caster's own surface hides the part of the light behind its tangent plane: the soft
    // terminator of an area light (exact for a convex caster), where the hard test at the
    // light's centre put most of the centred smoothie's remaining error on the casters. Past
    // the terminator the map and the caster's own smoothies see the same blocker, so the two
    // combine by the darker, not multiplied (which counts it twice).
    float self_lit = in_front_of_itself(s, frame.light.xyz, frame.light.w);
    if (self_lit == 0.0) {
        out_visibility = 0.0;
        return;
    }
    ShadowLookup l = shadow_lookup(light, frame.light.xyz, s.p, s.n);
    if (!l.inside) {
        out_visibility = self_lit;
        return;
    }
    MapTexels map = map_texels(shadow_map, vec2(0.0), light.bias.w, l.uv);
    float umbra = lit_bilinear(map, l.depth);
    if (MASK) {
        if (near_smoothie(l.uv, umbra)) {
            discard; // the penumbra draw's
        }
        out_visibility = min(self_lit, umbra);
        return;
    }
    // Every curve maps 0 to 0 and 1 to 1: only the penumbra needs the smoothie buffer and the
    // curve.
    if (CENTRED) {
        out_visibility = min(self_lit, centred_test(l.uv, l.depth, umbra, map));
        return;
    }
    float v = umbra > 0.0 ? min(umbra, outer_test(l.uv, l.depth)) : 0.0;
    out_visibility = min(self_lit, v > 0.0 && v < 1.0 ? falloff_at(v) : v);
}
