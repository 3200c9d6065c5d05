#version 460
// Concentric resolve: receivers on the ground read the averaged darkness where they stand.
#include "interface.glsl"
#include "camera.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform View { ClassicView view; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D darkness;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

// Bilinear darkness (the sampler is nearest).
float darkness_at(vec2 tc) {
    vec2 size = vec2(textureSize(darkness, 0));
    vec2 pos = clamp(tc * size - 0.5, vec2(0.0), size - 1.001);
    ivec2 i = ivec2(floor(pos));
    vec2 f = fract(pos);
    float a = mix(texelFetch(darkness, i, 0).r, texelFetch(darkness, i + ivec2(1, 0), 0).r, f.x);
    float b = mix(texelFetch(darkness, i + ivec2(0, 1), 0).r, texelFetch(darkness, i + ivec2(1, 1), 0).r, f.x);
    return mix(a, b, f.y);
}

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
        out_visibility = 1.0; // off the ground: the projections fall on the ground only
        return;
    }
    vec2 uv = vec2(dot(s.p - o, view.plane_u.xyz), dot(s.p - o, view.plane_v.xyz));
    vec2 tc = (uv - view.window.xy) / (view.window.zw - view.window.xy);
    if (any(lessThan(tc, vec2(0.0))) || any(greaterThan(tc, vec2(1.0)))) {
        out_visibility = 1.0; // beyond every projection's footprint
        return;
    }
    out_visibility = clamp(1.0 - darkness_at(tc), 0.0, 1.0);
}
