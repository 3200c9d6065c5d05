#version 460
// Marks the pixels where the receiver plane is the visible surface (Komura: improving planar
// projected shadows with the stencil buffer), from the camera prepass, so the projected
// shadow needs no lift against z-fighting and lands only on the plane.
#include "interface.glsl"
#include "camera.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Sample { SampleView view; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;

layout(location = 0) in vec2 in_uv;

void main() {
    Surface s = read_surface(frame, camera_depth, camera_normal, in_uv);
    vec3 n = view.plane.xyz;
    if (!s.receives || !on_plane(frame, s, -view.plane.w * n, n)) {
        discard;
    }
}
