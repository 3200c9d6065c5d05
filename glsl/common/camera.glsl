// Reconstruction of camera-pass surfaces from the prepass targets.
#ifndef SOFTSHADOW_CAMERA_GLSL
#define SOFTSHADOW_CAMERA_GLSL

// Reverse Z: the prepass clears depth to 0, so 0 means "no surface".
bool sees_surface(float depth) { return depth > 0.0; }

vec3 world_position(mat4 inv_view_proj, vec2 uv, float depth) {
    vec4 clip = vec4(uv * 2.0 - 1.0, depth, 1.0);
    vec4 world = inv_view_proj * clip;
    return world.xyz / world.w;
}

#endif
