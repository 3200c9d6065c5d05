// What both centred smoothie-buffer shaders share (issue 20; centred.frag, several casters in
// two channels; centred_one.frag, one caster in one target): which smoothies a fragment keeps,
// and what it says.
#ifndef SOFTSHADOW_SMOOTHIE_CENTRED_GLSL
#define SOFTSHADOW_SMOOTHIE_CENTRED_GLSL
#include "buffer.glsl"

// Which smoothies a draw holds (smoothie.rs's `Part`): the inner quads, or the outer smoothies.
// Each kind is drawn apart, so a fragment runs only its own kind's code: llvmpipe runs both
// branches of a test it cannot fold.
layout(constant_id = 0) const bool INNER = false;

// What an inner quad with α < 1 leaves in the outer smoothies' depth channel, where the
// resolve's mask draw finds every smoothie with one gather (resolve.frag's near_smoothie): the
// largest code below 1, behind every receiver the frustum holds, so that no receiver counts as
// behind it.
const float INNER_MARK = 65534.0 / 65535.0;

// One fragment of a smoothie: an inner quad's linear α or an outer smoothie's remapped α', and
// the depth code (depth.glsl) it is written with.
struct Centred {
    bool inner;
    float alpha;
    float code;
    // An inner quad's: the depth code of the nearest caster in the map just outside its edge
    // (1: none), past which a receiver's light from beyond the edge may be hidden again.
    float limit;
};

// False where the fragment says nothing (the clear's 1 stands).
bool centred_fragment(out Centred c) {
    vec2 uv = gl_FragCoord.xy / light.kernel.x;
    float caster = map_at(uv);
    float alpha = linear_alpha();
    c = Centred(INNER, alpha, depth_code(light, in_b), 1.0);
    // Two map texels' depth at b, what a face at 45° to the light spans across them.
    float slack = 2.0 * in_b * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / light.bias.w;
    if (c.inner) {
        // An inner texel counts only where the map's blocker is this caster (its depth within the
        // caster's range, within two texels' depth; not another caster in front or behind), and
        // where nothing within that range is cast just outside the edge: not a fold of the
        // caster, nor another caster abutting it, either of which may hide the light that passes
        // the edge. Another caster wholly behind it there (under it: the lower of two boxes)
        // hides that light only from what lies behind that caster, not from its own surface: the
        // inner half holds down to its depth, `limit` (the resolve; one caster has no other, and
        // its limit is always 1). Dropped wherever anything was cast outside, it left the upper
        // box's shadow on the lower one's top a hard inner edge (two_boxes' penumbra RMSE 0.103;
        // 0.049 with the limit).
        bool own = caster >= in_range.x - slack && caster <= in_range.y + slack;
        float outside = map_at(in_probe);
        c.limit = depth_code(light, outside);
        return own && (outside >= light.kernel.y || outside > in_range.y + slack);
    }
    // Equation 1, r the nearest surface behind the texel (Figure 11 reads it from the map). A
    // smoothie behind the map's caster still counts: a centred penumbra lets light past that
    // caster, and the receivers there are behind both (r: the ground, the one surface known
    // behind it).
    // A partial silhouette's (range (b, −1), geometry::smoothie::partial_smoothies) lies over
    // its own caster's outline: only its outer half counts, and only for receivers behind b,
    // past its turned face, which its own terminator already shades. So it is kept where the
    // map's surface lies behind b: where the map is lit, and over any surface deeper than the
    // turned face, another caster's or a farther part of its own, whose light the partial
    // silhouette hides too. Kept only where the map was lit, it missed them: default's
    // wingnut, whose wing's silhouettes slide across its grazed top for parts of the light and
    // shadow its body, leaked 211 px (202 kept as here). Deeper by APART (depth.glsl) at
    // least: where a fine convex caster's surface runs on past the turned face, steep near its
    // outline, two texels' slack let its next rings through, and a partial smoothie darkened
    // the terminator its tangent plane already shades (a speckle at 0.30 for 0.50 on the
    // sphere at 128²).
    bool partial = in_range.y < 0.0;
    if (partial && caster <= max(in_range.x + slack, in_range.x * APART)) {
        return false;
    }
    float ground = ground_depth(light, uv);
    c.alpha = remapped_alpha(alpha, in_b < caster ? min(caster, ground) : ground);
    if (partial) {
        c.code = depth_code(light, in_range.x);
    }
    // At 1: behind the ground, or lit.
    return c.alpha < 1.0;
}

#endif
