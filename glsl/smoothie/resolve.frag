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

layout(constant_id = 0) const bool CENTRED = false;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Light { LightView light; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D shadow_map;
layout(set = 0, binding = 5) uniform sampler2D smoothies; // b, α'; centred: also α and −b inside
layout(set = 0, binding = 6) uniform sampler2D falloff;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

// The four smoothie texels around a lookup, in gather order (i0,j1) (i1,j1) (i1,j0) (i0,j0).
struct Texels {
    vec2 base;    // texel (i0, j0)
    vec2 corner;  // where to gather them
    vec2 f;       // bilinear weights
    vec4 b;       // the outer smoothies' depths
    vec4 behind;  // 1 where the receiver lies behind the texel's outer smoothie
};

Texels texels(vec2 uv, float depth) {
    Texels t;
    float size = light.kernel.x;
    vec2 pos = clamp(uv * size - 0.5, vec2(0.0), vec2(size - 1.001));
    t.base = floor(pos);
    t.corner = (t.base + 1.0) / size;
    t.f = fract(pos);
    t.b = textureGather(smoothies, t.corner, 0);
    t.behind = vec4(greaterThan(vec4(depth), t.b));
    return t;
}

float bilinear(Texels t, vec4 v) {
    return mix(mix(v.w, v.z, t.f.x), mix(v.x, v.y, t.f.x), t.f.y);
}

// The paper's smoothie test: α' where the receiver lies behind a smoothie, else 1.
float outer_test(vec2 uv, float depth) {
    Texels t = texels(uv, depth);
    if (t.behind == vec4(0.0)) {
        return 1.0; // behind no smoothie: most of the frame, spared the alpha fetch
    }
    return bilinear(t, mix(vec4(1.0), textureGather(smoothies, t.corner, 1), t.behind));
}

// Centred V: the penumbra parameter, 0 umbra .. ½ hard edge .. 1 lit, through the falloff;
// `umbra`, the hard test, where no smoothie is near (exactly the hard shadow for a point light).
float centred_test(vec2 uv, float depth, float umbra) {
    Texels t = texels(uv, depth);
    vec4 inner_alpha = textureGather(smoothies, t.corner, 2); // α, or 2 where no inner quad
    vec4 inner = vec4(lessThanEqual(inner_alpha, vec4(1.0)));
    if (t.behind == vec4(0.0) && inner == vec4(0.0)) {
        return umbra;
    }
    vec4 outer = mix(vec4(1.0), textureGather(smoothies, t.corner, 1), t.behind);
    // Equation 1 for the inner half, r the receiver's depth (contact, b ≥ r: hard).
    vec4 b = -textureGather(smoothies, t.corner, 3);
    vec4 a = clamp(inner_alpha / max(1.0 - min(b / depth, vec4(1.0)), 1e-6), 0.0, 1.0);
    // The map at each smoothie texel's centre: is the receiver behind a caster there?
    float map_size = light.bias.w, size = light.kernel.x;
    ivec2 last = ivec2(map_size - 1.0);
    const vec2 offsets[4] = vec2[4](vec2(0, 1), vec2(1, 1), vec2(1, 0), vec2(0, 0));
    vec4 caster;
    for (int k = 0; k < 4; k++) {
        vec2 centre = (t.base + offsets[k] + 0.5) / size;
        caster[k] = texelFetch(shadow_map, min(ivec2(centre * map_size), last), 0).r;
    }
    // Lit: the outer half. Shadowed: only an inner half lightens it, darkened by the outer
    // penumbra of a caster in front of the map's (blockers taken as independent, which errs
    // dark; the caster's own outer smoothies, at its depth, are no other blocker).
    vec4 lit = 0.5 + 0.5 * outer;
    float slack = 2.0 * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / map_size;
    vec4 in_front = t.behind * vec4(lessThan(t.b, caster * (1.0 - slack)));
    vec4 shadowed = inner * (0.5 - 0.5 * a) * mix(vec4(1.0), lit, in_front);
    return falloff_at(falloff, FALLOFF, bilinear(t, mix(lit, shadowed, vec4(lessThan(caster, vec4(depth))))));
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
    float umbra = compare_bilinear(shadow_map, vec2(0.0), light.bias.w, l.uv, l.depth);
    // Every curve maps 0 to 0 and 1 to 1: only the penumbra needs the smoothie buffer and the
    // falloff texture.
    if (CENTRED) {
        out_visibility = min(self_lit, centred_test(l.uv, l.depth, umbra));
        return;
    }
    float v = umbra > 0.0 ? min(umbra, outer_test(l.uv, l.depth)) : 0.0;
    out_visibility = min(self_lit, v > 0.0 && v < 1.0 ? falloff_at(falloff, FALLOFF, v) : v);
}
