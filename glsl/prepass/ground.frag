#version 460
// Camera prepass for the ground, an exact plane, as the ray tracer takes it: its depth
// interpolated from corners 1e5 m away was off by 1e-6 of that near the camera (a 10 cm error
// under a 1.7 cm cube, issue 19), so it is the camera ray's own intersection, written as the
// fragment's depth. That write makes the depth test run after the shader, which is why the
// meshes have a pipeline of their own (scene.frag).
#include "surface.glsl"

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
    vec3 hit;
    float hit_depth;
    bool plane = on_plane(in_plane, hit, hit_depth);
    gl_FragDepth = plane ? hit_depth : gl_FragCoord.z;
    write_surface(plane ? hit : in_world, plane ? in_plane.xyz : cross(dFdx(in_world), dFdy(in_world)));
}
