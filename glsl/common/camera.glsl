// Reconstruction of camera-pass surfaces from the prepass targets.
#ifndef SOFTSHADOW_CAMERA_GLSL
#define SOFTSHADOW_CAMERA_GLSL
#include "interface.glsl"
#include "disk.glsl"

// Reverse Z: the prepass clears depth to 0, so 0 means "no surface".
bool sees_surface(float depth) { return depth > 0.0; }

vec3 world_position(mat4 inv_view_proj, vec2 uv, float depth) {
    vec4 clip = vec4(uv * 2.0 - 1.0, depth, 1.0);
    vec4 world = inv_view_proj * clip;
    return world.xyz / world.w;
}

// The normal target's alpha: how the surface takes part in shadowing (see `ShadowRole` in
// src/frame/mod.rs): 0 receives no shadow, 0.5 receives, 1 receives and casts.
struct Surface {
    vec3 p;        // world position
    vec3 n;        // the facet's unit normal, on the side facing the camera
    bool receives; // false: V = 1 here (also where no surface is seen)
    bool casts;    // the surface belongs to a caster, so it blocks light arriving from behind it
};

Surface read_surface(FrameGlobals frame, sampler2D depth_target, sampler2D normal_target, vec2 uv) {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float depth = texelFetch(depth_target, pixel, 0).r;
    vec4 normal_role = texelFetch(normal_target, pixel, 0);
    Surface s;
    s.receives = sees_surface(depth) && normal_role.a > ROLE_RECEIVES_ABOVE;
    s.casts = normal_role.a > ROLE_CASTS_ABOVE;
    s.p = s.receives ? world_position(frame.inv_view_proj, uv, depth) : vec3(0.0);
    s.n = s.receives ? normalize(normal_role.xyz) : vec3(0.0, 1.0, 0.0);
    return s;
}

// Whether the surface lies on the plane through `o` of unit normal `n`, and faces along it: off
// it by no more than its reconstructed position rounds by (f32 depth and inverse view-projection:
// a few ulps of its distance from the camera and of the camera's position). A tolerance of 1e-3
// of the light's height took a slab 0.5 m up for the ground under any light 500 m up (issue 19).
bool on_plane(FrameGlobals frame, Surface s, vec3 o, vec3 n) {
    float rounding = 1e-5 * (distance(s.p, frame.camera_position.xyz) + length(frame.camera_position.xyz));
    return abs(dot(s.p - o, n)) <= rounding && dot(s.n, n) >= 0.99;
}

// A caster's own surface hides whatever lies behind its tangent plane: a point q of the light
// there is blocked whatever a shadow map says (rays from the camera's side cross the surface).
bool hides_itself(Surface s, vec3 q) {
    return s.casts && dot(s.n, q - s.p) <= 0.0;
}

// The same for a spherical light (centre `c`, radius `radius`): the fraction of it that lies in
// front of a caster's tangent plane, 1 for surfaces that cast nothing. The light seen from p is
// a disk of angular radius a whose centre stands b above the horizon; the plane cuts it at
// h = sin b / sin a of its radius (disk.glsl).
float in_front_of_itself(Surface s, vec3 c, float radius) {
    if (!s.casts) return 1.0;
    vec3 to_light = c - s.p;
    float dist = length(to_light);
    return disk_below(dot(s.n, to_light) / max(radius, 1e-6 * dist));
}

#endif
