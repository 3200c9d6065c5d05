// What the camera prepass writes for every visible surface, meshes (scene.frag) and the ground
// (ground.frag) alike: the facet's true normal with the shadow role (what shadow techniques
// test), the interpolated normal (what the composite shades), the albedo.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };

layout(location = 0) in vec3 in_normal;
layout(location = 1) flat in vec4 in_albedo;
layout(location = 2) in vec3 in_world;
layout(location = 3) flat in vec4 in_plane; // xyz = 0: a mesh

layout(location = 0) out vec4 out_normal_role;
layout(location = 1) out vec4 out_shading;
layout(location = 2) out vec4 out_albedo;

// The surface at `world` with geometric normal `g` (either sign; zero: take the shading one).
void write_surface(vec3 world, vec3 g) {
    vec3 n = normalize(in_normal);
    // Two-sided surfaces (plates, open meshes): shade the side that faces the camera.
    if (!gl_FrontFacing) n = -n;
    g = dot(g, g) > 0.0 ? normalize(g) : n;
    // A select, not a branch: lavapipe compiles a shader again whenever it meets a branch on
    // uniforms alone with new uniforms bound (every frame), 65 ms a frame for this one uncached.
    bool perspective = frame.camera_position.w > 0.5;
    vec3 to_camera = mix(-frame.camera_forward.xyz, frame.camera_position.xyz - world, bvec3(perspective));
    if (dot(g, to_camera) < 0.0) g = -g;
    out_normal_role = vec4(g, in_albedo.a);
    out_shading = vec4(n * 0.5 + 0.5, 1.0);
    out_albedo = vec4(in_albedo.rgb, 1.0);
}
