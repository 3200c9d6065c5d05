// The hard shadow's corners (issue 20), for centred plateaus (glsl/plateau/penumbra.frag) and
// smoothies (glsl/smoothie/centred.glsl). A side of the penumbra takes one edge's line: the
// light's footprint cut by a half plane, V ½ on the hard edge. Where two edges meet, the truth
// cuts the footprint by both lines: at a convex corner the shadow is the intersection of the
// edges' inner sides, and its apex sees ¾ of the light, not ½; at a reflex corner, their union,
// and the apex ¼. Near a corner a side takes V from both lines (a plateau's adds the difference
// between the two models to its own), the footprint an affine image of the light's disk about
// the fragment (the plateau's vertex cone on its plane; a disk in the smoothie's tangent
// plane), so area fractions are the disk's, and writes the disk-edge distance whose curve gives
// it. Far from the corner (the footprint off the other edge's line) both lines give the side's
// own V, so the sides still meet without a seam.
#ifndef SOFTSHADOW_CORNERS_GLSL
#define SOFTSHADOW_CORNERS_GLSL
#include "disk.glsl"

const float CORNER_PI = 3.14159265358979;

float corner_cross(vec2 a, vec2 b) {
    return a.x * b.y - a.y * b.x;
}

// Green's theorem term of the chord of the line u·x = d (u unit) inside the unit disk and the
// half plane v·x ≥ e, traversed with {u·x ≥ d} on its left: ½ start × end.
float chord_term(vec2 u, float d, vec2 v, float e) {
    if (abs(d) >= 1.0) {
        return 0.0;
    }
    vec2 t = vec2(-u.y, u.x), o = u * d;
    float w = sqrt(1.0 - d * d), lo = -w, hi = w;
    float vt = dot(v, t), r = e - dot(v, o);
    if (vt > 0.0) {
        lo = max(lo, r / vt);
    } else if (vt < 0.0) {
        hi = min(hi, r / vt);
    } else if (r > 0.0) {
        return 0.0;
    }
    return hi > lo ? 0.5 * corner_cross(o + hi * t, o + lo * t) : 0.0;
}

// u2's angle from u1's, in [−π, π].
float corner_angle(vec2 u1, vec2 u2) {
    return atan(corner_cross(u1, u2), dot(u1, u2));
}

// The angle of the unit circle inside both half planes u·x ≥ d: two arcs, each about u's
// angle, acos d either side of it, u2's `delta` from u1's.
float arcs_inside(float d1, float d2, float delta) {
    float h1 = acos(clamp(d1, -1.0, 1.0)), h2 = acos(clamp(d2, -1.0, 1.0));
    float sum = 0.0;
    for (int k = -1; k <= 1; k++) {
        float s = delta + 2.0 * CORNER_PI * float(k);
        sum += max(0.0, min(h1, s + h2) - max(-h1, s - h2));
    }
    return sum;
}

// The fraction of the unit disk in {u1·x ≥ d1} ∩ {u2·x ≥ d2} (u unit, u2 at `delta` from u1:
// corner_angle): Green's theorem over the region's boundary, its arcs and its two chords.
float disk_in_both(vec2 u1, float d1, vec2 u2, float d2, float delta) {
    float area = 0.5 * arcs_inside(d1, d2, delta) + chord_term(u1, d1, u2, d2) + chord_term(u2, d2, u1, d1);
    return clamp(area / CORNER_PI, 0.0, 1.0);
}

// The cube root of a ≥ 0: an estimate from the float's bits (its exponent over 3, the constant
// putting the bias back), then two of Halley's steps, each a division: within 2e-6 of the cube
// root over the range disk_below_inverse takes. a is held at 1e-30 at least, whose estimate's
// cube is still a normal float (at 0 it underflowed, and the step divided 0 by 0); its root
// squared, 1e-20, leaves disk_below_inverse's u at 1. llvmpipe's pow is a log2 and an exp2.
float corner_cbrt(float a) {
    a = max(a, 1e-30);
    float t = uintBitsToFloat(floatBitsToUint(a) / 3u + 0x2a514067u);
    for (int k = 0; k < 2; k++) {
        float t3 = t * t * t;
        t *= (t3 + 2.0 * a) / (2.0 * t3 + a);
    }
    return t;
}

// The disk-edge distance u in [−1, 1] with disk_below(u) = v. With u = sin φ, disk_below is
// ½ + (φ + ½ sin 2φ)/π; ψ = π/2 − |φ| solves x = ψ − ½ sin 2ψ for x = π/2 − π|v − ½|, about
// (2/3)ψ³ near the ends, so |u| = cos ψ is smooth in s = z², z = ∛(1.5x): 1 + s·Q(s), Q of
// degree 5 fitted to the least maximum error in V (iteratively reweighted least squares over
// ψ in [0, π/2]), 1 exactly at the ends: disk_below(u) within 1.1e-6 of v in f32. Its first
// form took ψ by a polynomial in z, then a pow for z and a cosine for u (within 4e-6): contact's
// centred smoothie pass took 5.5–8.2 ms (median 6.4) so against 6.0–8.5 (6.9), the plateau's
// sheets 1.60–1.71 against 1.67–1.73 (512², lavapipe, alternating runs of 20 frames). Newton's
// method on φ took two steps, each a sine and a cosine, to hold 1e-5.
float disk_below_inverse(float v) {
    float y = CORNER_PI * (clamp(v, 0.0, 1.0) - 0.5);
    float z = corner_cbrt(1.5 * max(0.5 * CORNER_PI - abs(y), 0.0));
    float s = z * z;
    float q = -0.499907035
        + s * (-0.0257647326 + s * (-0.00172232624 + s * (-0.00375423346 + s * (0.00169298307 + s * -0.000552975107))));
    return sign(y) * min(1.0 + s * q, 1.0);
}

// A corner's two lines in the footprint's disk coordinates x, for the fragment at `p` from the
// corner's vertex (plane units): the footprint is p − A·x over |x| ≤ 1 (A: the cone's axes),
// and a line through the vertex with outward normal n hides the light where (Aᵀn)·x ≥ n·p.
// Returned as (unit u, d) with the shadow side u·x ≥ d; false where the footprint is flat.
bool footprint_line(mat2 axes, vec2 n, vec2 p, out vec3 line) {
    vec2 g = transpose(axes) * n;
    float len = length(g);
    line = vec3(g / max(len, 1e-30), dot(n, p) / max(len, 1e-30));
    return len > 0.0 && dot(n, n) > 0.0;
}

// V under both of a corner's lines (footprint_line), `convex` the turn: at a convex corner the
// shadow is both inner sides, V = 1 − the disk in both; at a reflex one, either, and V the disk
// in both outer sides, the same lines mirrored. One disk_in_both for either turn: llvmpipe runs
// both arms of a choice it cannot fold, and a call in each arm cost every corner fragment two.
// `delta`: other's normal's angle from one's (corner_angle; mirrored alike), which both callers
// find once per vertex, their lines keeping their directions across a primitive.
float corner_v_turned(vec3 one, vec3 other, bool convex, float delta) {
    float s = convex ? 1.0 : -1.0;
    float inside = disk_in_both(s * one.xy, s * one.z, s * other.xy, s * other.z, delta);
    return convex ? 1.0 - inside : inside;
}

#endif
