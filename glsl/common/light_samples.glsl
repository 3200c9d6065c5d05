// Heckbert & Herf's accumulation: the solid angle the light's surface around the sample q stands
// for, seen from p, max(0, cos theta_q) / |p - q|^2, relative to the centre's distance so the
// numbers are the same at any scene scale, times the sample's importance weight. The sphere's
// normal at q comes from the CPU (`geometry::LightPoint`): q - centre may round to nothing for a
// tiny light. A point light (normal 0), or the centre alone, is one sample of weight 1.
#ifndef SOFTSHADOW_LIGHT_SAMPLES_GLSL
#define SOFTSHADOW_LIGHT_SAMPLES_GLSL

// `normal`: xyz the outward normal at q, w the importance weight.
float light_sample_weight(vec3 center, vec4 normal, vec3 q, vec3 p) {
    if (normal.xyz == vec3(0.0)) {
        return 1.0;
    }
    vec3 to_p = p - q;
    float d2 = dot(to_p, to_p);
    float d2_center = dot(p - center, p - center);
    return max(dot(normal.xyz, to_p) * inversesqrt(d2), 0.0) * (d2_center / d2) * normal.w;
}

#endif
