#version 460
// Priority-map resolve: a camera pixel is shadowed when the map, where the pixel projects into
// the light's view, holds a nearer priority (a smaller number) than the pixel's own object.
#include "interface.glsl"
#include "camera.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Light { LightView light; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform usampler2D object_ids;
layout(set = 0, binding = 5) readonly buffer Priorities { uint priorities[]; };
layout(set = 0, binding = 6) uniform usampler2D priority_map;

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
    uint id = texelFetch(object_ids, ivec2(gl_FragCoord.xy), 0).r;
    // Receivers that cast nothing are behind every caster: the map's empty value, 0xffffffff.
    uint own = id > 0u ? priorities[id - 1u] : 0xffffffffu;
    vec4 q = light.view_proj * vec4(s.p, 1.0);
    vec2 ndc = q.xy / q.w;
    if (q.w <= 0.0 || any(greaterThan(abs(ndc), vec2(1.0)))) {
        out_visibility = 1.0; // outside the light's view: no caster there
        return;
    }
    ivec2 size = textureSize(priority_map, 0);
    uint nearest = texelFetch(priority_map, clamp(ivec2((ndc * 0.5 + 0.5) * vec2(size)), ivec2(0), size - 1), 0).r;
    out_visibility = nearest < own ? 0.0 : 1.0;
}
