// What the smoothie-buffer fragment shaders share (smoothie.frag, the paper's outer-only
// buffer; centred.glsl's, issue 20's): the vertex stage's outputs, the casters' depth behind a
// texel in the pass-1 map, the linear alpha and its remap (Equation 1).
#ifndef SOFTSHADOW_SMOOTHIE_BUFFER_GLSL
#define SOFTSHADOW_SMOOTHIE_BUFFER_GLSL
#include "interface.glsl"
#include "depth.glsl"

layout(set = 0, binding = 0) uniform Light { LightView light; };
layout(set = 0, binding = 1) uniform sampler2D shadow_map;

layout(location = 0) noperspective in float in_inverse_b; // 1/b (smoothie.vert)
layout(location = 1) in vec2 in_shape; // perspective-correct: distance over size (smoothie.vert)
layout(location = 2) noperspective in vec2 in_probe;
layout(location = 3) flat in vec2 in_range;
layout(location = 4) flat in float in_channel;
layout(location = 5) flat in vec2 in_corner;
layout(location = 6) flat in vec4 in_normals;
layout(location = 7) flat in float in_turn;
layout(location = 8) noperspective in float in_size;
layout(location = 9) noperspective in float in_along;
layout(location = 10) flat in vec2 in_keep;
layout(location = 11) flat in vec3 in_chamfer;
layout(location = 12) flat in vec3 in_angles;

float map_at(vec2 uv) {
    float size = light.bias.w;
    return texelFetch(shadow_map, ivec2(clamp(uv * size, vec2(0.0), vec2(size - 1.0))), 0).r;
}

// The blocker's linear light depth b at this fragment.
float blocker_depth() {
    return 1.0 / in_inverse_b;
}

// This fragment's linear alpha, 0 on the silhouette, 1 at the smoothie's far side.
float linear_alpha() {
    return clamp(length(in_shape), 0.0, 1.0);
}

// Equation 1 for a receiver at depth r; 1 where the smoothie lies at or behind it (lit there).
float remapped_alpha(float alpha, float r) {
    float f = blocker_depth() / r;
    return f >= 1.0 ? 1.0 : alpha / (1.0 - f);
}

#endif
