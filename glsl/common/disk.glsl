// A spherical light seen from a receiver is a disk; a straight edge, or a caster's own tangent
// plane, hides the part of it beyond a chord.
#ifndef SOFTSHADOW_DISK_GLSL
#define SOFTSHADOW_DISK_GLSL

// The fraction of a unit disk on the near side of the chord at h from its centre: 0 for h ≤ −1,
// ½ at 0, 1 for h ≥ 1 (the disk segment beyond the chord is acos h − h·√(1 − h²)). Clamped: near
// h = ±1 the two terms cancel and their rounding left it at 1.0000001 (issue 19).
float disk_below(float h) {
    h = clamp(h, -1.0, 1.0);
    return clamp(1.0 - (acos(h) - h * sqrt(1.0 - h * h)) / 3.14159265358979, 0.0, 1.0);
}

#endif
