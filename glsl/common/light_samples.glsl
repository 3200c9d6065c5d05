// Heckbert & Herf's accumulation: the solid angle the light's surface around the sample q stands
// for, seen from p, max(0, cos theta_q) / |p - q|^2, relative to the centre's distance so the
// numbers are the same at any scene scale. A point light (w = 0), or the centre alone, is one
// sample of weight 1.
#ifndef SOFTSHADOW_LIGHT_SAMPLES_GLSL
#define SOFTSHADOW_LIGHT_SAMPLES_GLSL

float light_sample_weight(vec4 light, vec3 q, vec3 p) {
    if (light.w <= 0.0 || q == light.xyz) {
        return 1.0;
    }
    vec3 center = light.xyz;
    vec3 to_p = p - q;
    float d2 = dot(to_p, to_p);
    float d2_center = dot(p - center, p - center);
    return max(dot(normalize(q - center), to_p) * inversesqrt(d2), 0.0) * d2_center / d2;
}

#endif
