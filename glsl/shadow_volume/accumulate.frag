#version 460
// One hard shadow's share of the accumulation (Komura: soft shadowing by multiple point light
// sources), drawn twice under the stencil test: where the stencil says lit (SHADOWED false) and
// where it says shadowed. Adds (weight * lit, weight), the solid-angle weight of the reference.
#include "interface.glsl"
#include "camera.glsl"
#include "light_samples.glsl"

layout(constant_id = 0) const bool SHADOWED = false;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Sample { SampleView view; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec2 out_sum;

void main() {
    Surface s = read_surface(frame, camera_depth, camera_normal, in_uv);
    out_sum = vec2(0.0);
    if (!s.receives) {
        return; // the resolve writes V = 1 where nothing was summed
    }
    float weight = light_sample_weight(frame.light.xyz, view.normal, view.light.xyz, s.p);
    // Self-shadowing needs no test of its own: a caster's side turned from the light lies in its
    // own volume, and its lit side on a light cap of the same depth, which the count resolves.
    out_sum = vec2(SHADOWED ? 0.0 : weight, weight);
}
