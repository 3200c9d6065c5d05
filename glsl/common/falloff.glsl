// The falloff curves of src/technique/falloff.rs: row 0 linear, 1 sine, 2 smoothstep, 3 disk
// edge, 256
// entries each, read with interpolation (the sampler is nearest).
#ifndef SOFTSHADOW_FALLOFF_GLSL
#define SOFTSHADOW_FALLOFF_GLSL

// The `falloff` knob: which row a resolve reads. Shaders including this file leave
// constant_id 8 to it.
layout(constant_id = 8) const int FALLOFF = 0;

float falloff_at(sampler2D curves, int row, float t) {
    float x = clamp(t, 0.0, 1.0) * 255.0;
    int i = int(floor(x));
    float lo = texelFetch(curves, ivec2(i, row), 0).r;
    float hi = texelFetch(curves, ivec2(min(i + 1, 255), row), 0).r;
    return mix(lo, hi, fract(x));
}

#endif
