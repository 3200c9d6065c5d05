#version 460
// The centred smoothie buffer (issue 20) of one caster: one target, minimum blending, every
// channel cleared to 1. Its channels: the outer smoothies' nearest depth b (its code,
// depth.glsl) and remapped alpha α' (Equation 1), the inner quads' 1 − code(b) (the farthest
// inner depth) and alpha α (the shallowest, the lightest: see centred.frag). With no other
// caster there are no channels to keep apart, so what centred.frag spreads over two targets
// fits in one: 8 bytes a texel instead of 10, cleared everywhere and blended wherever a
// smoothie lies, and the resolve reads the inner depths without a gather of their own (sphere,
// 512², lavapipe, interleaved runs: the smoothie pass 5.5 → 4.8 ms, the resolve 10.4 → 9.5).
#include "centred.glsl"

layout(location = 0) out vec4 out_smoothie;

void main() {
    Centred c;
    if (!centred_fragment(c)) {
        discard;
    }
    out_smoothie = c.inner ? vec4(1.0, 1.0, 1.0 - c.code, c.alpha) : vec4(c.code, c.alpha, 1.0, 1.0);
}
