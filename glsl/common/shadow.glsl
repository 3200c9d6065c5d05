// Shadow-map lookups shared by every technique that compares against a linear light-depth map
// (shadow-map, reference, and later PCF, PCSS and smoothies): the biases, measured in texels at
// the receiver so they hold at any scene scale, and the 2x2 bilinear comparison.
#ifndef SOFTSHADOW_SHADOW_GLSL
#define SOFTSHADOW_SHADOW_GLSL
#include "interface.glsl"

// Linear light depths are f32 sums of terms as large as the depth, the point's coordinates
// and the view's translation, computed on both sides (the map's rasterized depth, the
// receiver's rebuilt and transformed point) with a few roundings each: they disagree by a
// few ulps (2^-23) of the largest term however small a texel is. A tiny caster under a far
// light (a 1 mm cube 25 m away: texel 6e-7 m, ulp 2e-6 m) has texel biases far below that
// and shadows its own lit faces.
const float DEPTH_ROUNDING = 8.0 * 1.1920929e-7;

// The world distance the depths of a receiver at `p`, light depth `z`, may round by, and the
// map's format (depths.w, relative: a 16-bit float's ulp, or 0) on top.
float depth_rounding(LightView light, vec3 p, float z) {
    return DEPTH_ROUNDING * max(abs(z), max(length(p), length(light.view[3].xyz))) + light.depths.w * abs(z);
}

// The radius of the light `radius` wide at `from` as seen from the projection centre of
// `light`, where a far light is moved to (LightFrustum::light_scale, src/geometry): the one that
// spans the same angle from the receiver p, for similar triangles in light depths.
float apparent_radius(LightView light, vec3 from, vec3 p, float radius) {
    vec3 origin = -(transpose(mat3(light.view)) * light.view[3].xyz);
    return radius * distance(p, origin) / max(distance(p, from), 1e-30);
}

// Where p falls in a light's map, 0..1 (row 0 at v = 0; the centre behind the light): false
// behind the light or outside the frustum fitted around every caster. The receiver-plane tests
// below take p itself; shadow_lookup, a point moved along the normal.
bool map_uv(LightView light, vec3 p, out vec2 uv) {
    vec4 clip = light.view_proj * vec4(p, 1.0);
    uv = clip.w > 0.0 ? clip.xy / clip.w * 0.5 + 0.5 : vec2(0.5);
    return clip.w > 0.0 && all(greaterThanEqual(uv, vec2(0.0))) && all(lessThanEqual(uv, vec2(1.0)));
}

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
    float bias = texel * (light.bias.x + light.bias.y * tan_theta) + depth_rounding(light, p, z);

    s.inside = map_uv(light, q, s.uv);
    s.depth = (light.view * vec4(q, 1.0)).z - bias;
    return s;
}

// The four texels nearest `uv` in the size x size map at texel `origin` of `atlas` (the
// footprint stays inside it): their depths in gather order (i0,j1) (i1,j1) (i1,j0) (i0,j0), and
// the bilinear weights.
struct MapTexels {
    vec4 d;
    vec2 f;
};

MapTexels map_texels(sampler2D atlas, vec2 origin, float size, vec2 uv) {
    vec2 texel_pos = clamp(uv * size - 0.5, vec2(0.0), vec2(size - 1.001));
    // Gathering at the corner shared by the four texels.
    vec2 corner = (origin + floor(texel_pos) + 1.0) / vec2(textureSize(atlas, 0));
    return MapTexels(textureGather(atlas, corner, 0), fract(texel_pos));
}

// Four values in gather order, bilinearly weighted.
float bilinear(vec2 f, vec4 v) {
    return mix(mix(v.w, v.z, f.x), mix(v.x, v.y, f.x), f.y);
}

// The four texels compared with `depth`, 1 where lit, in gather order.
vec4 lit_texels(MapTexels m, float depth) {
    return vec4(greaterThanEqual(m.d, vec4(depth)));
}

// The same, bilinearly weighted.
float lit_bilinear(MapTexels m, float depth) {
    return bilinear(m.f, lit_texels(m, depth));
}

float compare_bilinear(sampler2D atlas, vec2 origin, float size, vec2 uv, float depth) {
    return lit_bilinear(map_texels(atlas, origin, size, uv), depth);
}

// The receiver's tangent plane in light view space, for lookups whose footprint is wide enough
// to reach the receiver's own surface (PCSS). A map texel holds the point d·(tx, ty, 1) of the
// nearest caster along its centre's ray; that point can hide part of the light from the
// receiver only if it lies on the light's side of the receiver's tangent plane (the segment
// from the receiver to any point of the light above that plane stays above it). Testing the
// texel's point against the plane, instead of the texel's depth against the receiver's one
// depth, is the receiver plane depth bias of Isidoro ("Shadow Mapping: GPU-based Tips and
// Techniques", GDC 2006) made exact: the plane comes from the prepass's facet normal, not from
// screen-space derivatives, so it holds at silhouettes and across a fullscreen resolve.
struct ReceiverPlane {
    vec3 p;       // the receiver, light view space
    vec3 n;       // its facet normal there, turned towards the light's centre (the origin)
    float margin; // world distance in front of the plane below which a texel is the receiver's own
};

ReceiverPlane receiver_plane(LightView light, vec3 p, vec3 n) {
    ReceiverPlane r;
    r.p = (light.view * vec4(p, 1.0)).xyz;
    r.n = mat3(light.view) * n; // the view is rigid
    if (dot(r.n, r.p) > 0.0) r.n = -r.n;
    // The constant depth bias (texels at the receiver): the depth map's own rounding.
    r.margin = light.bias.x * r.p.z * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / light.bias.w
             + depth_rounding(light, p, r.p.z);
    return r;
}

// Whether `depth`, stored at `texel` of the light's size x size map, is a caster point in front
// of the receiver's plane. Beyond the margin, 2e-3 per unit of distance from the receiver
// absorbs the normal's half-float rounding (about 1e-3 per component).
bool in_front_of(LightView light, ReceiverPlane r, vec2 texel, float depth) {
    if (depth > 1e30) return false; // cleared: nothing there
    vec2 t = light.extent.xy + (texel + 0.5) / light.bias.w * (light.extent.zw - light.extent.xy);
    vec3 b = depth * vec3(t, 1.0);
    return dot(r.n, b - r.p) > r.margin + 2e-3 * distance(b, r.p);
}

// compare_bilinear against the receiver's plane instead of one depth (1 = lit), in the size x
// size map at texel `origin` of `atlas`.
float compare_bilinear_plane(sampler2D atlas, vec2 origin, LightView light, ReceiverPlane r, vec2 uv) {
    float size = light.bias.w;
    vec2 texel_pos = clamp(uv * size - 0.5, vec2(0.0), vec2(size - 1.001));
    vec2 f = fract(texel_pos);
    vec2 i0 = floor(texel_pos);
    // Gathering at the corner shared by the four texels: (i0,j1) (i1,j1) (i1,j0) (i0,j0).
    vec4 d = textureGather(atlas, (origin + i0 + 1.0) / vec2(textureSize(atlas, 0)), 0);
    vec4 lit = vec4(!in_front_of(light, r, i0 + vec2(0.0, 1.0), d.x), !in_front_of(light, r, i0 + vec2(1.0, 1.0), d.y),
                    !in_front_of(light, r, i0 + vec2(1.0, 0.0), d.z), !in_front_of(light, r, i0, d.w));
    return bilinear(f, lit);
}

#endif
