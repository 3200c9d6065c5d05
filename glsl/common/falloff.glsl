// The falloff curves the `falloff` knob chooses (src/technique/falloff.rs): 0 linear, 1 sine,
// 2 smoothstep, 3 disk edge. Haines (§3) and Chan & Durand (§3.1) read the curve from a 1D
// texture, which their hardware needed; here it is the closed form the texture held: on
// llvmpipe two texel fetches per evaluation cost more than the arithmetic (the centred
// plateau's resolve, which evaluates it twice per pixel, 6.7 → 5.8 ms on plate at 512²), and
// the curve is exact instead of interpolated between 256 entries.
#ifndef SOFTSHADOW_FALLOFF_GLSL
#define SOFTSHADOW_FALLOFF_GLSL
#include "disk.glsl"

// The `falloff` knob: which curve a resolve takes. Shaders including this file leave
// constant_id 8 to it.
layout(constant_id = 8) const int FALLOFF = 0;

const float FALLOFF_PI = 3.14159265358979;

// The curve at t, clamped to [0, 1]; every curve maps 0 to 0 and 1 to 1, and stays in [0, 1]
// (clamped: sin and acos round past the ends, and near u = ±1 the disk edge's two terms cancel).
float falloff_at(float t) {
    t = clamp(t, 0.0, 1.0);
    float v = t; // linear
    if (FALLOFF == 1) {
        v = 0.5 + 0.5 * sin(FALLOFF_PI * (t - 0.5)); // sine (Parker et al.)
    } else if (FALLOFF == 2) {
        v = t * t * (3.0 - 2.0 * t); // smoothstep (Parker's Bernstein interpolant)
    } else if (FALLOFF == 3) {
        // The visible fraction of a spherical light whose centre sits at t across a straight
        // edge: the disk segment beyond the chord at u = 2t − 1, ½ on the hard edge.
        v = disk_below(2.0 * t - 1.0);
    }
    return clamp(v, 0.0, 1.0);
}

#endif
