#version 460
// Make shadows (Chan & Durand §3, step 5): behind a blocker in the shadow map, V = 0; else
// behind a smoothie, V = its remapped alpha α' = α / (1 − b/r) (Equation 1); else 1. Both
// tests at the four nearest texels, filtered bilinearly, then the falloff curve. CENTRED
// (issue 20): the penumbra straddles the hard edge, t = ½ + ½α' on the lit side and ½ − ½α'
// over the blocker, each smoothie texel classified by the map at its own centre, in two
// channels (odd and even casters, centred.frag) whose visibilities multiply; one caster's
// buffer (centred_one.frag) reads as the even channel alone.
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
// Centred: the buffer of several casters (centred.frag), or of one (centred_one.frag).
layout(constant_id = 3) const bool CHANNELS = true;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Light { LightView light; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D shadow_map;
// The outer smoothies' b and α' (smoothie.frag; centred: of the even casters, centred.frag).
layout(set = 0, binding = 5) uniform sampler2D smoothies;
// Centred: the inner quads' 1 − b and α (depth.glsl codes), with several casters α's channel in
// its lowest bit; else unread.
layout(set = 0, binding = 6) uniform sampler2D inner_smoothies;
// Centred, several casters: the odd casters' α' and the inner quads' limits; else unread.
layout(set = 0, binding = 7) uniform sampler2D odd_smoothies;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

// The four smoothie texels around a lookup, in gather order (i0,j1) (i1,j1) (i1,j0) (i0,j0),
// a gather per channel.
struct Texels {
    float code;      // the receiver's depth code
    ivec2 base;      // texel (i0, j0)
    vec2 f;          // bilinear weights
    vec4 b;          // the nearest outer smoothies' depth codes
    vec4 outer;      // their remapped alpha α' (centred: of the even casters)
    vec4 outer_odd;  // centred: of the odd casters
    vec4 inner;      // centred: the inner quads' alpha α, 1 (umbra) where none
    vec4 inner_odd;  // centred: 1 where the inner quad is an odd caster's
    vec4 inner_b;    // centred: the inner quads' depth codes
    vec4 behind;     // 1 where the receiver lies behind the texel's outer smoothie
    vec4 apart;      // and that smoothie is another blocker's, not the receiver's own silhouette
};

// How far past an inner quad's limit a receiver still counts as the surface there, in depth
// codes (depth.glsl): APART deeper.
#define LIMIT_SLACK (log2(APART) / light.depths.z)

const ivec2 GATHER_ORDER[4] = ivec2[4](ivec2(0, 1), ivec2(1, 1), ivec2(1, 0), ivec2(0, 0));

// Where a lookup falls in the smoothie buffer, in texels from texel (0, 0)'s centre.
vec2 smoothie_pos(vec2 uv) {
    float size = light.kernel.x;
    return clamp(uv * size - 0.5, vec2(0.0), vec2(size - 1.001));
}

Texels texels(vec2 uv, float depth) {
    float code = depth_code(light, depth);
    Texels t;
    t.code = code;
    vec2 pos = smoothie_pos(uv);
    t.base = ivec2(pos);
    t.f = fract(pos);
    vec2 corner = (vec2(t.base) + 1.0) / light.kernel.x;
    t.b = textureGather(smoothies, corner, 0);
    t.outer = textureGather(smoothies, corner, 1);
    t.outer_odd = vec4(1.0);
    t.inner_odd = vec4(0.0);
    if (CENTRED) {
        t.inner_b = 1.0 - textureGather(inner_smoothies, corner, 0);
        t.inner = textureGather(inner_smoothies, corner, 1);
    }
    if (CENTRED && CHANNELS) {
        t.outer_odd = textureGather(odd_smoothies, corner, 0);
        vec4 limit = textureGather(odd_smoothies, corner, 1);
        // The channel in the alpha's lowest bit (centred.frag's with_channel).
        uvec4 coded = uvec4(round(t.inner * 65535.0));
        t.inner_odd = vec4(coded & 1u);
        // Beyond its limit (centred.glsl) the receiver may not see past the edge: umbra.
        t.inner = mix(vec4(coded >> 1u) / 32767.0, vec4(1.0), greaterThan(vec4(code), limit + LIMIT_SLACK));
    }
    if (CENTRED) {
        // Signed alphas from their codes (centred.glsl's alpha_code); 1 stays 1.
        t.outer = 2.0 * t.outer - 1.0;
        t.outer_odd = 2.0 * t.outer_odd - 1.0;
        t.inner = 2.0 * t.inner - 1.0;
    }
    t.behind = vec4(greaterThan(vec4(code), t.b));
    // Its own silhouette's outer smoothie reaches a receiver only across the bilinear texel,
    // and there at contact (b/r → 1, as at a terminator): within the limits' slack.
    t.apart = t.behind * vec4(lessThan(t.b, vec4(code - LIMIT_SLACK)));
    return t;
}

float min4(vec4 v) {
    return min(min(v.x, v.y), min(v.z, v.w));
}

// The paper's smoothie test: α' where the receiver lies behind a smoothie, else 1; second, the
// same from other blockers' smoothies alone (with_own_plane), only for a surface whose own
// plane hides some of the light (`self_lit` < 1), as centred_test's.
vec2 outer_test(vec2 uv, float depth, float self_lit) {
    Texels t = texels(uv, depth);
    float v = bilinear(t.f, mix(vec4(1.0), t.outer, t.behind));
    if (self_lit >= 1.0) {
        return vec2(v, 1.0); // with_own_plane keeps v
    }
    return vec2(v, bilinear(t.f, mix(vec4(1.0), t.outer, t.apart)));
}

// The penumbra parameter of an outer half, ½ + ½α', where `covers` (else 1: lit).
vec4 outer_half(vec4 alpha, vec4 covers) {
    return 0.5 + 0.5 * mix(vec4(1.0), alpha, covers);
}

// V from each texel's lit-side factors (`lit_even`, `lit_odd`) and inner halves (`inner`), the
// inner half in its caster's channel, the two channels' visibilities multiplied (centred_test).
float channels(Texels t, vec4 lit_even, vec4 lit_odd, vec4 inner, vec4 deep) {
    vec4 even = lit_even * mix(inner, vec4(1.0), t.inner_odd);
    vec4 odd = lit_odd * mix(vec4(1.0), inner, t.inner_odd);
    // Umbra texels (a = 1, most of them beyond any inner quad, which would put them in the odd
    // channel) join the channel of the penumbra beside them, the darker among the other
    // texels, so a penumbra runs into its umbra within one channel, as with one. Left in the
    // odd channel, an even caster's penumbra interpolated toward a lit odd channel there
    // (overlap: 32 px more leaks); made umbra in both, they dimmed the other channel over
    // inner halves a texel or two wide (wingnut, near contact: penumbra RMSE 0.018 → 0.023).
    float odd_beside = float(min4(mix(odd, vec4(1.0), deep)) <= min4(mix(even, vec4(1.0), deep)));
    even = mix(even, lit_even * odd_beside, deep);
    odd = mix(odd, lit_odd * (1.0 - odd_beside), deep);
    return falloff_at(bilinear(t.f, even)) * falloff_at(bilinear(t.f, odd));
}

// Centred V: the penumbra parameter, 0 umbra .. ½ hard edge .. 1 lit, through the falloff;
// `umbra`, the hard test, where no smoothie is near (exactly the hard shadow for a point light).
// Second, V from other blockers alone, the receiver's own silhouette left out (with_own_plane),
// computed only for a surface whose own plane hides some of the light (`self_lit` < 1).
// `casts`: whether the receiver is a caster's surface.
// `map`: the shadow map's texels around the lookup, which are the smoothie texels' own where
// the two grids agree (SAME_GRID).
vec2 centred_test(vec2 uv, float depth, float umbra, MapTexels map, float self_lit, bool casts) {
    Texels t = texels(uv, depth);
    if (t.behind == vec4(0.0) && t.inner == vec4(1.0)) {
        return vec2(umbra, 1.0);
    }
    // Equation 1 for the inner half, r the receiver's depth (contact, b ≥ r: hard); below 0
    // near a convex corner, lighter than the hard edge.
    vec4 a = clamp(t.inner / max(1.0 - min(code_depth(light, t.inner_b) / depth, vec4(1.0)), 1e-6), -1.0, 1.0);
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
    // Per channel, lit: the outer half. Shadowed: the inner half in its caster's channel, so
    // the two halves of one caster's penumbra meet on the hard edge within one channel; darkened
    // by the outer penumbra of a caster in front of the map's, or behind it in the other channel
    // (blockers taken as independent, which errs dark). The map's caster's own outer smoothies
    // are no other blocker: at its depth, or behind it in its channel (a deep caster's far side,
    // which counted shadowed the wingnut's wings twice: default's penumbra RMSE 0.057 → 0.061).
    vec4 shadowed = vec4(lessThan(caster, vec4(depth)));
    // Two texels of the coarser grid: a smoothie's depth and the map's a texel from it.
    float slack = 2.0 * coarser_texel(light);
    vec4 in_front = t.behind * vec4(lessThan(t.b, depth_code(light, caster * (1.0 - slack))));
    vec4 in_back = t.behind * vec4(greaterThan(t.b, depth_code(light, caster * (1.0 + slack))));
    if (!SAME_GRID) {
        // The map texel under a smoothie texel's centre lies up to half a map texel off it, and
        // near the hard edge can say the other side of the caster's outline than the centre:
        // taken as shadowed without an inner alpha, such a texel read as umbra (dark speckles
        // in the lit half), and as lit without an outer one, as lit (light speckles on the hard
        // edge): plate, a 1024² map over a 512² buffer, 166 px off by over 0.1, penumbra RMSE
        // 0.045 against 0.010 with both 512². Near the edge the quads say the side instead: an
        // inner quad is kept where any map texel about the centre holds its caster
        // (centred.glsl), so one there means inside, for a receiver behind it; the map's
        // caster's own outer smoothie (at its depth) and no inner quad, outside. Behind it: a
        // caster's surface by the limits' slack (its own near its outline is no receiver of its
        // inner half: the plate's rim went dark), any other at all (contact's ground at the
        // slab's foot, within the slack of the slab's depth there, stayed lit: penumbra RMSE
        // 0.057, 0.024 so: a 1024² map over a 512² buffer).
        float own_slack = casts ? LIMIT_SLACK : 0.0;
        vec4 inside = vec4(lessThan(t.inner, vec4(1.0))) * vec4(greaterThan(vec4(t.code), t.inner_b + own_slack));
        vec4 outside = t.behind * (1.0 - in_front) * (1.0 - in_back) * (1.0 - inside);
        shadowed = max(shadowed, inside) * (1.0 - outside);
    }
    vec4 other_even = in_front + in_back * t.inner_odd;
    vec4 other_odd = in_front + in_back * (1.0 - t.inner_odd);
    vec4 lit_even = outer_half(t.outer, mix(t.behind, other_even, shadowed));
    vec4 lit_odd = outer_half(t.outer_odd, mix(t.behind, other_odd, shadowed));
    vec4 inner = mix(vec4(1.0), 0.5 - 0.5 * a, shadowed);
    vec4 deep = shadowed * vec4(greaterThanEqual(a, vec4(1.0)));
    float v = channels(t, lit_even, lit_odd, inner, deep);
    if (self_lit >= 1.0) {
        return vec2(v, 1.0); // with_own_plane keeps v: most receivers, the whole ground
    }
    vec4 apart_even = outer_half(t.outer, mix(t.apart, other_even, shadowed));
    vec4 apart_odd = outer_half(t.outer_odd, mix(t.apart, other_odd, shadowed));
    // An inner quad at the receiver's own depth (within the limits' slack) is its own silhouette:
    // the terminator, which with_own_plane leaves to the tangent plane.
    vec4 own = shadowed * vec4(greaterThanEqual(t.inner_b, vec4(t.code - LIMIT_SLACK)));
    return vec2(v, channels(t, apart_even, apart_odd, mix(inner, vec4(1.0), own), deep * (1.0 - own)));
}

// Whether V at this lookup can differ from the hard test's: an alpha below 1 among the four
// smoothie texels (an outer α' of 1 is lit, an inner α of 1 umbra), or the hard test's own
// bilinear edge (0 < umbra < 1), which the falloff shapes. Exact where the grids agree
// (SAME_GRID); otherwise the mask draw keeps the map's hard test where the centred one would
// classify the smoothie texels' centres instead.
bool near_smoothie(vec2 uv, float depth, float umbra, MapTexels map) {
    vec2 corner = (floor(smoothie_pos(uv)) + 1.0) / light.kernel.x;
    bool edge = umbra > 0.0 && umbra < 1.0;
    if (CENTRED) {
        // An outer smoothie is written only with α' < 1 (centred.glsl), so its depth tells, and
        // an inner quad with α < 1 leaves its mark there too.
        vec4 b = textureGather(smoothies, corner, 0);
        // Inner quads' marks alone (or the clear's 1; half a 16-bit step below the mark, as the
        // target rounds it) over a receiver the map finds lit at all four texels: none is
        // shadowed, so centred_test reads no inner half and its V is the hard test's. Most are a
        // caster's own lit surface over its inner quads: the penumbra draw shades 0.38 (contact)
        // to 0.91 (low_light) of the pixels it did without this.
        bool lit_over_inner = SAME_GRID && all(greaterThan(b, vec4(INNER_MARK - 0.5 / 65535.0)))
            && min4(lit_texels(map, depth)) == 1.0;
        return edge || (any(lessThan(b, vec4(1.0))) && !lit_over_inner);
    }
    if (umbra == 0.0) {
        return false; // outer only: the map's umbra stays umbra
    }
    return edge || any(lessThan(textureGather(smoothies, corner, 1), vec4(1.0)));
}

// The falloff where the penumbra is, 0 and 1 kept exact (the hard shadow of a point light).
float penumbra_curve(float v) {
    return v > 0.0 && v < 1.0 ? falloff_at(v) : v;
}

// V of a caster's own surface, from `self_lit`, the part of the light in front of its tangent
// plane, the shadow test's `v`, and `others`, the same test with the receiver's own
// silhouette left out (its smoothies at the receiver's depth: contact, as at a terminator).
// Another blocker's edge cuts the light's disk apart from the plane: the product, as blockers
// in two channels combine (exact for an edge square to the plane through the light's centre).
// The receiver's own silhouette is its terminator, whose map edge hides what the plane hides:
// the darker of the two, not their product, which counts it twice (the sphere's terminator).
// The darker of the plane and every blocker, as before, held a face the light grazes at the
// plane's V under another caster's penumbra: default's wingnut at 0.66 under its own wing,
// where the truth falls to 0.3 (when measured, default leaked 307 px of 512², 211 with the
// product).
float with_own_plane(float self_lit, float v, float others) {
    // A surface that sees the whole light above its plane (any receiver that casts nothing)
    // keeps the test's V exactly, whatever the two tests' umbra texels did to `others`.
    return self_lit >= 1.0 ? v : others * min(self_lit, v / max(others, 1e-6));
}

void main() {
    Surface s = read_surface(frame, camera_depth, camera_normal, in_uv);
    if (!s.receives) {
        out_visibility = 1.0;
        return;
    }
    // A caster's own surface hides the part of the light behind its tangent plane: the soft
    // terminator of an area light (exact for a convex caster), where the hard test at the
    // light's centre put most of the centred smoothie's remaining error on the casters.
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
        if (near_smoothie(l.uv, l.depth, umbra, map)) {
            discard; // the penumbra draw's
        }
        out_visibility = min(self_lit, umbra);
        return;
    }
    // Every curve maps 0 to 0 and 1 to 1: only the penumbra needs the smoothie buffer and the
    // curve.
    if (CENTRED) {
        vec2 v = centred_test(l.uv, l.depth, umbra, map, self_lit, s.casts);
        out_visibility = with_own_plane(self_lit, v.x, v.y);
        return;
    }
    vec2 outer = outer_test(l.uv, l.depth, self_lit);
    float v = umbra > 0.0 ? min(umbra, outer.x) : 0.0;
    out_visibility = with_own_plane(self_lit, penumbra_curve(v), penumbra_curve(outer.y));
}
