// Shadow-map lookups shared by every technique that compares against a linear light-depth map
// (shadow-map, reference, and later PCF, PCSS and smoothies): the biases, measured in texels at
// the receiver so they hold at any scene scale, and the 2x2 bilinear comparison.
#ifndef SOFTSHADOW_SHADOW_GLSL
#define SOFTSHADOW_SHADOW_GLSL
#include "interface.glsl"

// Where a receiver point falls in a light's map.
struct ShadowLookup {
    vec2 uv;      // in the map, 0..1 (row 0 at v = 0)
    float depth;  // the receiver's linear light depth, biased towards the light
    bool inside;  // false: behind the light or outside the frustum fitted around every caster
};

// p: receiver position, n: its normal facing the camera, from: the point the map was seen from.
ShadowLookup shadow_lookup(LightView light, vec3 from, vec3 p, vec3 n) {
    ShadowLookup s;
    float size = light.bias.w;
    // World size of one texel at p's light depth: the biases scale with it.
    float z = (light.view * vec4(p, 1.0)).z;
    float texel = z * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / size;
    vec3 to_light = normalize(from - p);
    float cos_theta = clamp(dot(n, to_light), 0.0, 1.0);
    // Normal offset grows as the surface turns from the light, where acne starts.
    vec3 q = p + n * (light.bias.z * texel * (1.0 - cos_theta));
    float tan_theta = min(sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / max(cos_theta, 1e-3), 8.0);
    float bias = texel * (light.bias.x + light.bias.y * tan_theta);

    vec4 clip = light.view_proj * vec4(q, 1.0);
    s.inside = clip.w > 0.0;
    s.uv = s.inside ? clip.xy / clip.w * 0.5 + 0.5 : vec2(0.5);
    s.inside = s.inside && all(greaterThanEqual(s.uv, vec2(0.0))) && all(lessThanEqual(s.uv, vec2(1.0)));
    s.depth = (light.view * vec4(q, 1.0)).z - bias;
    return s;
}

// The four texels nearest `uv`, compared with `depth` (1 = lit) and bilinearly weighted. The
// map is the size x size tile at texel `origin` of `atlas`; the footprint stays inside it.
float compare_bilinear(sampler2D atlas, vec2 origin, float size, vec2 uv, float depth) {
    vec2 texel_pos = clamp(uv * size - 0.5, vec2(0.0), vec2(size - 1.001));
    vec2 f = fract(texel_pos);
    // Gathering at the corner shared by the four texels: (i0,j1) (i1,j1) (i1,j0) (i0,j0).
    vec4 d = textureGather(atlas, (origin + floor(texel_pos) + 1.0) / vec2(textureSize(atlas, 0)), 0);
    vec4 lit = vec4(greaterThanEqual(d, vec4(depth)));
    float top = mix(lit.w, lit.z, f.x);
    float bottom = mix(lit.x, lit.y, f.x);
    return mix(top, bottom, f.y);
}

#endif
