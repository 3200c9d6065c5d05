#version 460
// The paper's smoothie buffer (outer only) in one pass and one target (its multiple-render-
// target remark, §4, packed): depth b (its code, depth.glsl) and remapped alpha α' (Equation
// 1) of the smoothies, composited with minimum blending, so the nearest smoothie depth and the
// minimum alpha (Parker's thresholding, §3.1) come out in any drawing order. Both channels
// clear to 1. centred.frag and centred_one.frag are issue 20's buffers.
#include "buffer.glsl"

layout(location = 0) out vec2 out_smoothie;

void main() {
    vec2 uv = gl_FragCoord.xy / light.kernel.x;
    // r, the nearest surface behind this texel (Figure 11 reads it from the map): the casters
    // from the pass-1 map, the ground exactly, from its plane.
    float a = remapped_alpha(linear_alpha(), min(map_at(uv), ground_depth(light, uv)));
    if (a >= 1.0) {
        discard; // hidden from the light, or lit: what the clear holds
    }
    out_smoothie = vec2(depth_code(light, blocker_depth()), a);
}
