#version 460
// Heckbert & Herf's accumulation, one batch: for each light sample q of the batch, a hard
// shadow test against its tile of the atlas, weighted by the solid angle the light's surface
// around q stands for as seen from p, max(0, cos theta_q) / |p - q|^2, over the density q was
// drawn with (its weight). Sums add across batches.
#include "interface.glsl"
#include "camera.glsl"
#include "shadow.glsl"
#include "light_samples.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(std430, set = 0, binding = 1) readonly buffer Samples { LightSample samples[]; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D atlas;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec2 out_sum; // (sum of weight * lit, sum of weight)

void main() {
    Surface s = read_surface(frame, camera_depth, camera_normal, in_uv);
    out_sum = vec2(0.0);
    if (!s.receives) {
        return; // the resolve writes V = 1 where nothing was summed
    }
    for (int i = 0; i < samples.length(); i++) {
        vec3 q = samples[i].position.xyz;
        float weight = light_sample_weight(frame.light.xyz, samples[i].normal, q, s.p);
        if (weight == 0.0) {
            continue;
        }
        float lit = 1.0;
        if (hides_itself(s, q)) {
            lit = 0.0;
        } else if (samples[i].position.w > 0.0) {
            LightView view = samples[i].view;
            float size = view.bias.w;
            int tiles = int(float(textureSize(atlas, 0).x) / size);
            ShadowLookup l = shadow_lookup(view, q, s.p, s.n);
            vec2 origin = vec2(i % tiles, i / tiles) * size;
            lit = l.inside ? compare_bilinear(atlas, origin, size, l.uv, l.depth) : 1.0;
        }
        out_sum += vec2(weight * lit, weight);
    }
}
