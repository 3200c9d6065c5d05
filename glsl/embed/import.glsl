// The embedder's camera surfaces in the engine's convention (src/renderer/embed.rs): reverse-Z
// depth where 0 means "no surface", and every surface a receiver (casters are marked after, by
// glsl/embed/casters.frag, from the engine's own scene).
#ifndef SOFTSHADOW_IMPORT_GLSL
#define SOFTSHADOW_IMPORT_GLSL
#include "interface.glsl"
#include "camera.glsl"

// Whether the embedder's depth is already reverse Z (near 1, far 0); forward Z is flipped,
// as the engine flips the embedder's projection.
layout(constant_id = 0) const bool REVERSE_Z = true;

float imported_depth(sampler2D depth, ivec2 pixel) {
    float d = texelFetch(depth, pixel, 0).r;
    return REVERSE_Z ? d : 1.0 - d;
}

// A normal turned to the camera's side, as the prepass turns facets.
vec3 facing_camera(FrameGlobals frame, vec3 n, vec3 p) {
    vec3 to_camera = frame.camera_position.w > 0.5 ? frame.camera_position.xyz - p : -frame.camera_forward.xyz;
    return dot(n, to_camera) < 0.0 ? -n : n;
}

#endif
