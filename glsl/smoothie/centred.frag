#version 460
// The centred smoothie buffer (issue 20) in one pass and two targets, every channel composited
// with minimum blending, so the outcome is the same in any drawing order; every channel clears
// to 1, and each kind of smoothie writes 1 where it has nothing to say, which the minimum
// leaves as it is.
//
// Target 0: the outer smoothies' nearest depth b (its code, depth.glsl), their remapped alpha
// α' (Equation 1) in two channels, one per caster parity (SmoothieVertex::channel), and the
// inner quads' alpha α. Target 1: the inner quads' 1 − code(b), the farthest inner depth.
//
// Two outer channels: the resolve multiplies their visibilities. Where two casters' penumbrae
// cross, the light each hides is about independent of the other's (at the crossing of two hard
// edges the truth is about ¼, either edge alone ½), and one minimum kept only the darker (leaks
// of 0.15–0.24 on overlap and two_boxes). Within a caster the minimum still rules: its own
// edges' smoothies overlap at its turns, where the darkest is the paper's answer (§3.1).
// Smoothies behind the map's caster are kept (see main).
//
// The inner alpha carries its caster's channel in its lowest bit: the resolve puts the inner
// half in the channel of the outer half it continues across the hard edge, so one caster's
// penumbra stays one curve. The bit costs the alpha 1/65535; the minimum of one caster's inner
// quads keeps its parity, and no other caster's inner quads meet them (below).
//
// The shallowest inner alpha is the lightest: over a blocker, the truth at a convex corner is
// lighter than either edge's half plane alone (the blocker is their intersection), the
// opposite of the outside, where the darkest wins.
#include "buffer.glsl"

layout(location = 0) out vec4 out_smoothie;
layout(location = 1) out float out_inner_depth;

// α with the channel in its lowest bit, as a 16-bit unsigned normalized value (32-bit floats
// hold the same code exactly); resolve.frag's texels() reads it back.
float with_channel(float alpha, float channel) {
    return (2.0 * round(alpha * 32767.0) + channel) / 65535.0;
}

void main() {
    vec2 uv = gl_FragCoord.xy / light.kernel.x;
    float caster = map_at(uv);
    float alpha = linear_alpha();
    if (in_range.y > 0.0) {
        // An inner texel counts only where this edge bounds this caster's hard shadow: nothing
        // cast just outside the edge (not a fold of the caster, no other caster abutting, which
        // may hide the light there), and the map's blocker here within the caster's depth range
        // (not another caster in front or behind), within two texels' depth.
        float slack = 2.0 * in_b * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / light.bias.w;
        bool own = caster >= in_range.x - slack && caster <= in_range.y + slack;
        if (!own || map_at(in_probe) < light.kernel.y) {
            discard;
        }
        out_smoothie = vec4(1.0, 1.0, 1.0, with_channel(alpha, in_channel));
        out_inner_depth = 1.0 - depth_code(light, in_b);
        return;
    }
    // Equation 1, r the nearest surface behind the texel (Figure 11 reads it from the map). A
    // smoothie behind the map's caster still counts: a centred penumbra lets light past that
    // caster, and the receivers there are behind both (r: the ground, the one surface known
    // behind it).
    // A partial silhouette's (range (b, −1), geometry::smoothie::partial_smoothies) lies over
    // its own caster's outline: only its outer half counts, where the map is lit, and only for
    // receivers behind b, past its turned face, which its own terminator already shades.
    bool partial = in_range.y < 0.0;
    if (partial && caster < light.kernel.y) {
        discard;
    }
    float ground = ground_depth(light, uv);
    float a = remapped_alpha(alpha, in_b < caster ? min(caster, ground) : ground);
    if (a >= 1.0) {
        discard; // behind the ground, or lit: what the clear holds
    }
    out_smoothie = vec4(depth_code(light, partial ? in_range.x : in_b), in_channel == 0.0 ? a : 1.0, in_channel == 0.0 ? 1.0 : a, 1.0);
    out_inner_depth = 1.0;
}
