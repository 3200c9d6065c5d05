#version 460
// The centred smoothie buffer (issue 20) of one caster: two targets, minimum blending, every
// channel cleared to 1. Target 0: the outer smoothies' nearest depth b (its code, depth.glsl;
// where only inner quads with α < 1 lie, centred.glsl's INNER_MARK) and remapped alpha α'
// (Equation 1); target 1: the inner quads' 1 − code(b) (the farthest inner depth) and alpha α
// (the shallowest, the lightest: see centred.frag), as centred.frag's first two, less the
// channel bit; alphas as centred.glsl's alpha_code stores them. With no other caster there are
// no channels to keep apart and no limits (one caster has no other beside it): centred.frag's
// third target is not needed.
#include "centred.glsl"

layout(location = 0) out vec2 out_outer;
layout(location = 1) out vec2 out_inner;

void main() {
    Centred c;
    if (!centred_fragment(c)) {
        discard;
    }
    if (PARTIAL) {
        // Blended by max (smoothie.rs): the zeros leave the other channels as they are.
        out_outer = vec2(0.0);
        out_inner = vec2(0.0, alpha_code(c.alpha));
        return;
    }
    out_outer = c.inner ? vec2(c.alpha < 1.0 ? INNER_MARK : 1.0, 1.0) : vec2(c.code, alpha_code(c.alpha));
    out_inner = c.inner ? vec2(1.0 - c.code, alpha_code(c.alpha)) : vec2(1.0);
}
