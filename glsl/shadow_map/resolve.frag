#version 460
// Hard shadow resolve: one 2x2 bilinear comparison per camera pixel into V.
#include "interface.glsl"
#include "camera.glsl"
#include "shadow.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Light { LightView light; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D shadow_map;

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
    ShadowLookup l = shadow_lookup(light, frame.light.xyz, s.p, s.n);
    // Outside the fitted frustum nothing can block the light.
    out_visibility = l.inside ? compare_bilinear(shadow_map, vec2(0.0), light.bias.w, l.uv, l.depth) : 1.0;
}
