#version 460
// Camera prepass for every visible surface: the facet's true normal with the shadow role (what
// shadow techniques test), the interpolated normal (what the composite shades), the albedo.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };

layout(location = 0) in vec3 in_normal;
layout(location = 1) flat in vec4 in_albedo;
layout(location = 2) in vec3 in_world;
layout(location = 3) flat in vec4 in_plane; // xyz = 0: a mesh

layout(location = 0) out vec4 out_normal_role;
layout(location = 1) out vec4 out_shading;
layout(location = 2) out vec4 out_albedo;

// Where this pixel's camera ray meets `plane`, and its depth, when it does within the view.
bool on_plane(vec4 plane, out vec3 hit, out float depth) {
    vec2 ndc = gl_FragCoord.xy * frame.viewport.zw * 2.0 - 1.0;
    vec4 a = frame.inv_view_proj * vec4(ndc, 1.0, 1.0); // reverse Z: 1 at the near plane
    vec4 b = frame.inv_view_proj * vec4(ndc, 0.0, 1.0);
    vec3 o = a.xyz / a.w;
    vec3 d = b.xyz / b.w - o;
    float t = -(dot(plane.xyz, o) + plane.w) / dot(plane.xyz, d);
    if (!(t >= 0.0 && t <= 1.0)) return false; // parallel or outside: keep the raster's
    hit = o + t * d;
    vec4 clip = frame.view_proj * vec4(hit, 1.0);
    depth = clip.z / clip.w;
    return true;
}

void main() {
    // The ground is an exact plane, as the ray tracer takes it: its depth interpolated from
    // corners 1e5 m away was off by 1e-6 of that near the camera (a 10 cm error under a 1.7 cm
    // cube, issue 19), so it is the camera ray's own intersection. Meshes keep the raster's
    // depth bit for bit (the shadow volumes' caps rely on it).
    vec3 hit;
    float hit_depth;
    bool plane = dot(in_plane.xyz, in_plane.xyz) > 0.0 && on_plane(in_plane, hit, hit_depth);
    vec3 world = plane ? hit : in_world;
    gl_FragDepth = plane ? hit_depth : gl_FragCoord.z;
    vec3 n = normalize(in_normal);
    // Two-sided surfaces (plates, open meshes): shade the side that faces the camera.
    if (!gl_FrontFacing) n = -n;
    // The triangle's plane, exactly: visibility is a property of the geometry, and a smoothed
    // normal would move the self-shadowing terminator off the facets a ray tracer sees.
    vec3 g = plane ? in_plane.xyz : cross(dFdx(in_world), dFdy(in_world));
    g = dot(g, g) > 0.0 ? normalize(g) : n;
    vec3 to_camera = frame.camera_position.w > 0.5 ? frame.camera_position.xyz - world : -frame.camera_forward.xyz;
    if (dot(g, to_camera) < 0.0) g = -g;
    out_normal_role = vec4(g, in_albedo.a);
    out_shading = vec4(n * 0.5 + 0.5, 1.0);
    out_albedo = vec4(in_albedo.rgb, 1.0);
}
