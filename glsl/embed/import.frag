#version 460
// The embedder's depth without normals: depth copied in the engine's convention, facet normals
// rebuilt from neighbouring depths.
#include "import.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform sampler2D embedder_depth;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_normal_role;

vec3 position_at(ivec2 pixel, float depth) {
    return world_position(frame.inv_view_proj, (vec2(pixel) + 0.5) * frame.viewport.zw, depth);
}

// The step from the centre to the neighbour along `axis` that lies on the centre's facet: of
// the two sides, the one whose depth continues the centre's more smoothly (an edge between
// facets, or to the background, is a jump on one side only).
vec3 tangent(ivec2 pixel, float depth, vec3 centre, ivec2 axis) {
    ivec2 last = ivec2(frame.viewport.xy) - 1;
    ivec2 a = clamp(pixel - axis, ivec2(0), last), b = clamp(pixel + axis, ivec2(0), last);
    float da = imported_depth(embedder_depth, a), db = imported_depth(embedder_depth, b);
    bool use_a = a != pixel && sees_surface(da) && (b == pixel || !sees_surface(db) || abs(da - depth) < abs(db - depth));
    if (use_a) return centre - position_at(a, da);
    if (b != pixel && sees_surface(db)) return position_at(b, db) - centre;
    return vec3(0.0);
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float depth = imported_depth(embedder_depth, pixel);
    gl_FragDepth = depth;
    if (!sees_surface(depth)) {
        out_normal_role = vec4(vec3(0.0), ROLE_IGNORES);
        return;
    }
    vec3 p = world_position(frame.inv_view_proj, in_uv, depth);
    vec3 n = cross(tangent(pixel, depth, p, ivec2(1, 0)), tangent(pixel, depth, p, ivec2(0, 1)));
    // A lone pixel has no facet to rebuild: face the camera.
    n = dot(n, n) > 0.0 ? normalize(n) : -frame.camera_forward.xyz;
    out_normal_role = vec4(facing_camera(frame, n, p), ROLE_RECEIVES);
}
