#version 460
// Heckbert & Herf's accumulation, one batch: for each light sample q of the batch, a hard
// shadow test against its tile of the atlas, weighted by the solid angle the light's surface
// around q stands for as seen from p, max(0, cos theta_q) / |p - q|^2, over the density q was
// drawn with (its weight). Sums add across batches.
//
// Each hard test compares the map's texels with the receiver's tangent plane at p itself
// (ReceiverPlane, glsl/common/shadow.glsl), not one biased depth at a normal-offset point: the
// offset moves the lookup across the map by up to 1.5 texels where a surface turns from a
// sample, and so the hard edge it sees, toward the shadow. Against the CPU tracer (1024 rays,
// 512², 256 samples, 2048² maps) `default` had 433 pixels lit by over 0.1 too much, on the
// wingnut's faces the light grazes, and a penumbra RMSE of 0.055; with the plane, 334 and
// 0.042, and no suite scene worse (the rest within 4e-4). What the plane cannot tell is a
// neighbouring facet across a concave crease, within a texel of p, from a blocker: pixels too
// dark by over 0.1 went from 4 to 11 there (the cow's).
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
            vec2 origin = vec2(i % tiles, i / tiles) * size;
            vec2 uv;
            if (map_uv(view, s.p, uv)) {
                lit = compare_bilinear_plane(atlas, origin, view, receiver_plane(view, s.p, s.n), uv);
            }
        }
        out_sum += vec2(weight * lit, weight);
    }
}
