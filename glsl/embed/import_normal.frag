#version 460
// The embedder's depth and world-space normals: depth copied in the engine's convention, the
// normal decoded and turned to the camera.
#include "import.glsl"

// UNORM normal images hold n / 2 + 1/2; float and SNORM ones hold n.
layout(constant_id = 1) const bool NORMAL_UNORM = false;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform sampler2D embedder_depth;
layout(set = 0, binding = 2) uniform sampler2D embedder_normal;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_normal_role;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float depth = imported_depth(embedder_depth, pixel);
    gl_FragDepth = depth;
    if (!sees_surface(depth)) {
        out_normal_role = vec4(vec3(0.0), ROLE_IGNORES);
        return;
    }
    vec3 p = world_position(frame.inv_view_proj, in_uv, depth);
    vec3 n = texelFetch(embedder_normal, pixel, 0).xyz;
    if (NORMAL_UNORM) n = n * 2.0 - 1.0;
    n = dot(n, n) > 0.0 ? normalize(n) : -frame.camera_forward.xyz;
    out_normal_role = vec4(facing_camera(frame, n, p), ROLE_RECEIVES);
}
