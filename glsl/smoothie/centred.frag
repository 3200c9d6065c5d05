#version 460
// The centred smoothie buffer (issue 20) of several casters, in one pass (a draw for the outer
// smoothies, one for the inner quads: centred.glsl's INNER) and three targets, every channel
// composited with minimum blending, so the outcome is the same in any drawing order; every
// channel clears to 1, and each kind of smoothie writes 1 where it has nothing to say, which
// the minimum leaves as it is. One caster needs no channels: centred_one.frag.
//
// Target 0: the outer smoothies' nearest depth b (its code, depth.glsl; where only inner quads
// with α < 1 lie, centred.glsl's INNER_MARK) and the even casters' remapped alpha α' (Equation
// 1). Target 1: the inner quads' 1 − code(b), the farthest inner depth, and their alpha α.
// Target 2: the odd casters' α' and the inner quads' limit (centred.glsl), the nearest. Alphas
// as centred.glsl's alpha_code stores them. Two
// channels each: llvmpipe clears a four-channel 16-bit target at about a third of the bytes per
// second of a two-channel one (plate, 1024², the clear alone: 3.2 ms for one RGBA target, 1.3
// ms for two RG targets of the same bytes).
//
// Two outer channels, one per caster parity (SmoothieVertex::channel): the resolve multiplies
// their visibilities. Where two casters' penumbrae
// cross, the light each hides is about independent of the other's (at the crossing of two hard
// edges the truth is about ¼, either edge alone ½), and one minimum kept only the darker (leaks
// of 0.15–0.24 on overlap and two_boxes). Within a caster the minimum still rules: its own
// edges' smoothies overlap at its turns, where the darkest is the paper's answer (§3.1).
// Smoothies behind the map's caster are kept (centred.glsl).
//
// The inner alpha carries its caster's channel in its lowest bit: the resolve puts the inner
// half in the channel of the outer half it continues across the hard edge, so one caster's
// penumbra stays one curve. The bit costs the alpha 1/65535; the minimum of one caster's inner
// quads keeps its parity, and no other caster's inner quads meet them (centred.glsl).
//
// The shallowest inner alpha is the lightest: over a blocker, the truth at a convex corner is
// lighter than either edge's half plane alone (the blocker is their intersection), the
// opposite of the outside, where the darkest wins.
#include "centred.glsl"

layout(location = 0) out vec2 out_outer;
layout(location = 1) out vec2 out_inner;
layout(location = 2) out vec2 out_odd;

// α's code (alpha_code) with the channel in its lowest bit, as a 16-bit unsigned normalized
// value (32-bit floats hold the same code exactly); resolve.frag's texels() reads it back.
float with_channel(float alpha, float channel) {
    return (2.0 * round(alpha_code(alpha) * 32767.0) + channel) / 65535.0;
}

void main() {
    Centred c;
    if (!centred_fragment(c)) {
        discard;
    }
    if (PARTIAL) {
        // Blended by max (smoothie.rs): the zeros leave the other channels as they are.
        out_outer = vec2(0.0);
        out_inner = vec2(0.0, with_channel(c.alpha, in_channel));
        out_odd = vec2(0.0);
        return;
    }
    if (c.inner) {
        out_outer = vec2(c.alpha < 1.0 ? INNER_MARK : 1.0, 1.0);
        out_inner = vec2(1.0 - c.code, with_channel(c.alpha, in_channel));
        out_odd = vec2(1.0, c.limit);
        return;
    }
    bool even = in_channel == 0.0;
    out_outer = vec2(c.code, even ? alpha_code(c.alpha) : 1.0);
    out_inner = vec2(1.0);
    out_odd = vec2(even ? 1.0 : alpha_code(c.alpha), 1.0);
}
