#version 460
// Blob resolve: on the ground, the product over the casters' spots of a smoothstep across the
// ellipse's rim (the DDJ's "multiple intersecting dark spots"); elsewhere V = 1.
#include "interface.glsl"
#include "camera.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform View { ClassicView view; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) readonly buffer Blobs { BlobData blobs[]; };

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

void main() {
    Surface s = read_surface(frame, camera_depth, camera_normal, in_uv);
    if (!s.receives) {
        out_visibility = 1.0;
        return;
    }
    if (hides_itself(s, frame.light.xyz)) {
        out_visibility = 0.0;
        return;
    }
    vec3 n = view.plane_normal.xyz;
    vec3 o = view.plane_origin.xyz;
    if (!on_plane(frame, s, o, n)) {
        out_visibility = 1.0; // off the ground: blobs fall on the ground only
        return;
    }
    vec2 uv = vec2(dot(s.p - o, view.plane_u.xyz), dot(s.p - o, view.plane_v.xyz));
    float soft = view.params.y;
    float v = 1.0;
    // The buffer's length, not a uniform: lavapipe compiles a shader again whenever it meets a
    // loop bounded by a uniform with new uniforms bound (every frame), 85 ms a frame uncached.
    for (uint i = 0; i < blobs.length(); i++) {
        vec4 m = blobs[i].to_unit;
        float r = length(mat2(m.xy, m.zw) * (uv - blobs[i].centre.xy));
        v *= smoothstep(1.0 - soft, 1.0 + soft, r);
    }
    out_visibility = v;
}
