#version 460
// Make shadows (Chan & Durand §3, step 5): behind a blocker in the shadow map, V = 0; else
// behind a smoothie, V = its alpha; else 1. Both tests at the four nearest texels, filtered
// bilinearly, then the falloff curve.
#include "interface.glsl"
#include "camera.glsl"
#include "shadow.glsl"
#include "falloff.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Light { LightView light; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D shadow_map;
layout(set = 0, binding = 5) uniform sampler2D smoothie_depth;
layout(set = 0, binding = 6) uniform sampler2D smoothie_alpha;
layout(set = 0, binding = 7) uniform sampler2D falloff;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

// The smoothie test at the four texels around uv, bilinearly weighted.
float smoothie_test(vec2 uv, float depth) {
    float size = light.kernel.x;
    vec2 pos = clamp(uv * size - 0.5, vec2(0.0), vec2(size - 1.001));
    ivec2 i = ivec2(floor(pos));
    vec2 f = fract(pos);
    float v[4];
    for (int k = 0; k < 4; k++) {
        ivec2 texel = i + ivec2(k & 1, k >> 1);
        float b = texelFetch(smoothie_depth, texel, 0).r;
        v[k] = depth > b ? texelFetch(smoothie_alpha, texel, 0).r : 1.0;
    }
    return mix(mix(v[0], v[1], f.x), mix(v[2], v[3], f.x), f.y);
}

void main() {
    Surface s = read_surface(frame, camera_depth, camera_normal, in_uv);
    if (!s.receives) {
        out_visibility = 1.0;
        return;
    }
    if (hides_itself(s, frame.light.xyz)) {
        out_visibility = 0.0;
        return;
    }
    ShadowLookup l = shadow_lookup(light, frame.light.xyz, s.p, s.n);
    if (!l.inside) {
        out_visibility = 1.0;
        return;
    }
    float umbra = compare_bilinear(shadow_map, vec2(0.0), light.bias.w, l.uv, l.depth);
    float penumbra = smoothie_test(l.uv, l.depth);
    out_visibility = falloff_at(falloff, int(light.kernel.y), min(umbra, penumbra));
}
