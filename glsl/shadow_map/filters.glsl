// The filters of the shadow-map family, all over the same map and the same ShadowLookup: PCF
// (Reeves, Salesin & Cook 1987) on a rotated Vogel disk or a 4x4 bicubic B-spline footprint
// (the filter Chan & Durand compare smoothies with, their Figure 7), and PCSS (Fernando 2005).
#ifndef SOFTSHADOW_FILTERS_GLSL
#define SOFTSHADOW_FILTERS_GLSL
#include "shadow.glsl"

const float GOLDEN_ANGLE = 2.39996323;

// Interleaved gradient noise (Jimenez 2014): a per-pixel rotation that turns the banding of a
// few taps into fine noise.
float pixel_rotation() {
    return 6.28318531 * fract(52.9829189 * fract(dot(gl_FragCoord.xy, vec2(0.06711056, 0.00583715))));
}

// Tap i of n on a Vogel disk of unit radius, rotated by `angle`: even in area for any n.
vec2 vogel(int i, int n, float angle) {
    float r = sqrt((float(i) + 0.5) / float(n));
    float theta = float(i) * GOLDEN_ANGLE + angle;
    return r * vec2(cos(theta), sin(theta));
}

// Shadow-map texels per unit of tangent space (x/z, y/z) of the light view.
vec2 texels_per_tangent(LightView light) {
    return light.bias.w / vec2(light.extent.z - light.extent.x, light.extent.w - light.extent.y);
}

// PCF over a disk of `radius_texels`, `n` taps, each a bilinear comparison.
float pcf_disk(sampler2D map, LightView light, ShadowLookup l, float radius_texels, int n) {
    float size = light.bias.w;
    float angle = pixel_rotation();
    float lit = 0.0;
    for (int i = 0; i < n; i++) {
        vec2 uv = l.uv + vogel(i, n, angle) * radius_texels / size;
        lit += compare_bilinear(map, vec2(0.0), size, uv, l.depth);
    }
    return lit / float(n);
}

// Cubic B-spline weights of the four texels around fraction f.
vec4 bspline(float f) {
    float g = 1.0 - f;
    return vec4(g * g * g, 4.0 - 6.0 * f * f + 3.0 * f * f * f, 4.0 - 6.0 * g * g + 3.0 * g * g * g, f * f * f) / 6.0;
}

// 4x4 comparisons weighted by the bicubic B-spline: a smooth, C2 edge one texel and a half wide.
float pcf_bicubic(sampler2D map, LightView light, ShadowLookup l) {
    float size = light.bias.w;
    vec2 texel_pos = clamp(l.uv * size - 0.5, vec2(1.0), vec2(size - 2.001));
    vec2 base = floor(texel_pos);
    vec4 wx = bspline(texel_pos.x - base.x);
    vec4 wy = bspline(texel_pos.y - base.y);
    float lit = 0.0;
    for (int j = 0; j < 4; j++) {
        for (int i = 0; i < 4; i++) {
            float d = texelFetch(map, ivec2(base) + ivec2(i - 1, j - 1), 0).r;
            lit += wx[i] * wy[j] * float(d >= l.depth);
        }
    }
    return lit;
}

// PCF over a disk like pcf_disk, each tap compared against the receiver's plane.
float pcf_disk_plane(sampler2D map, LightView light, ReceiverPlane r, vec2 centre, float radius_texels, int n) {
    float size = light.bias.w;
    float angle = pixel_rotation();
    float lit = 0.0;
    for (int i = 0; i < n; i++) {
        lit += compare_bilinear_plane(map, vec2(0.0), light, r, centre + vogel(i, n, angle) * radius_texels / size);
    }
    return lit / float(n);
}

// PCSS: average the depths of the blockers in the region the light could be hidden from,
// estimate the penumbra from similar triangles, and PCF over it (Fernando 2005).
// `p`, `n`: the receiver and its facet normal (world); `radius`: the light's, as seen from the
// projection centre (apparent_radius); `taps`, `blocker_taps`: the filter's and the search's.
// light.kernel: -, light radius (world), the frustum's near depth, -.
//
// Both the search and the filter reach far beyond the few texels a depth bias covers, so on a
// surface slanted to the light they would find the receiver's own surface in front of its one
// depth: a lit face of a caster came out at V ~ 0.7 (issue 19). Both test map texels against
// the receiver's tangent plane instead (ReceiverPlane, glsl/common/shadow.glsl).
float pcss(sampler2D map, LightView light, ShadowLookup l, vec3 p, vec3 n, float radius, int taps, int blocker_taps) {
    float size = light.bias.w;
    float near = light.kernel.z;
    float per_tangent = texels_per_tangent(light).x;
    ReceiverPlane r = receiver_plane(light, p, n);
    float z = r.p.z;
    // 1. Blocker search. A blocker at depth zb hides part of the light from the receiver when it
    //    lies within R (z - zb) / (z zb) of the receiver's direction (tangent units): widest for
    //    the nearest depth the map holds, `near`. Capped at a quarter of the map.
    float search = min(radius * max(z - near, 0.0) / (z * near) * per_tangent, 0.25 * size);
    float angle = pixel_rotation();
    float sum = 0.0;
    int found = 0;
    for (int i = 0; i < blocker_taps; i++) {
        vec2 texel = floor(clamp(l.uv * size + vogel(i, blocker_taps, angle) * search, vec2(0.0), vec2(size - 1.0)));
        float d = texelFetch(map, ivec2(texel), 0).r;
        if (in_front_of(light, r, texel, d)) {
            sum += d;
            found++;
        }
    }
    if (found == 0) {
        return 1.0; // no blocker in reach: fully lit
    }
    float blocker = sum / float(found);
    // 2. Penumbra by similar triangles: w = R (z - zb) / zb at the receiver (world), that is
    //    R (z - zb) / (zb z) in tangent units.
    float filter_texels = radius * max(z - blocker, 0.0) / (blocker * z) * per_tangent;
    // 3. PCF over it; below half a texel it is the bilinear hard edge (contact hardening).
    if (filter_texels < 0.5) {
        return compare_bilinear_plane(map, vec2(0.0), light, r, l.uv);
    }
    return pcf_disk_plane(map, light, r, l.uv, filter_texels, taps);
}

#endif
