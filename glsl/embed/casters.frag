#version 460
// Marks the engine's casters on the embedder's surfaces: where a caster's fragment lies on the
// surface the embedder's depth saw (within CASTER_TOLERANCE of the distance to the camera), it
// writes the caster's facet normal and shadow role, as the prepass does (glsl/prepass/scene.frag).
#include "interface.glsl"
#include "camera.glsl"

// Relative distance within which a caster's fragment counts as the surface seen: D16 depth
// resolves about 1e-3 of the distance at a hundred times the near plane.
const float CASTER_TOLERANCE = 2e-3;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;

layout(location = 0) in vec3 in_normal;
layout(location = 1) flat in vec4 in_albedo;
layout(location = 2) in vec3 in_world;

layout(location = 0) out vec4 out_normal_role;

void main() {
    // Derivatives first, while every fragment of the quad is alive.
    vec3 g = cross(dFdx(in_world), dFdy(in_world));
    float depth = texelFetch(camera_depth, ivec2(gl_FragCoord.xy), 0).r;
    vec3 seen = world_position(frame.inv_view_proj, gl_FragCoord.xy * frame.viewport.zw, depth);
    vec3 to_camera = frame.camera_position.w > 0.5 ? frame.camera_position.xyz - in_world : -frame.camera_forward.xyz;
    float scale = length(frame.camera_position.xyz - in_world);
    if (!sees_surface(depth) || distance(seen, in_world) > CASTER_TOLERANCE * scale) discard;
    vec3 n = normalize(in_normal);
    g = dot(g, g) > 0.0 ? normalize(g) : n;
    if (dot(g, to_camera) < 0.0) g = -g;
    out_normal_role = vec4(g, in_albedo.a);
}
