#version 460
// Make shadows (Chan & Durand §3, step 5): behind a blocker in the shadow map, V = 0; else
// behind a smoothie, V = its alpha; else 1. Both tests at the four nearest texels, filtered
// bilinearly, then the falloff curve.
#include "interface.glsl"
#include "camera.glsl"
#include "shadow.glsl"
#include "falloff.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Light { LightView light; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D shadow_map;
layout(set = 0, binding = 5) uniform sampler2D smoothie_depth;
layout(set = 0, binding = 6) uniform sampler2D smoothie_alpha;
layout(set = 0, binding = 7) uniform sampler2D falloff;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

// The smoothie test at the four texels around uv, bilinearly weighted: a gather of depth, and
// of alpha where some texel's smoothie lies in front.
float smoothie_test(vec2 uv, float depth) {
    float size = light.kernel.x;
    vec2 pos = clamp(uv * size - 0.5, vec2(0.0), vec2(size - 1.001));
    vec2 f = fract(pos);
    vec2 corner = (floor(pos) + 1.0) / size;
    // Gather order: (i0,j1) (i1,j1) (i1,j0) (i0,j0).
    vec4 behind = vec4(greaterThan(vec4(depth), textureGather(smoothie_depth, corner, 0)));
    if (behind == vec4(0.0)) {
        return 1.0; // behind no smoothie: most of the frame, spared the alpha fetch
    }
    vec4 v = mix(vec4(1.0), textureGather(smoothie_alpha, corner, 0), behind);
    return mix(mix(v.w, v.z, f.x), mix(v.x, v.y, f.x), f.y);
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
    ShadowLookup l = shadow_lookup(light, frame.light.xyz, s.p, s.n);
    if (!l.inside) {
        out_visibility = 1.0;
        return;
    }
    float umbra = compare_bilinear(shadow_map, vec2(0.0), light.bias.w, l.uv, l.depth);
    // Every curve maps 0 to 0 and 1 to 1: only the penumbra needs the smoothie buffer and the
    // falloff texture.
    float v = umbra > 0.0 ? min(umbra, smoothie_test(l.uv, l.depth)) : 0.0;
    out_visibility = v > 0.0 && v < 1.0 ? falloff_at(falloff, FALLOFF, v) : v;
}
