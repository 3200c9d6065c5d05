// What both centred smoothie-buffer shaders share (issue 20; centred.frag, several casters in
// two channels; centred_one.frag, one caster in one target): which smoothies a fragment keeps,
// and what it says.
#ifndef SOFTSHADOW_SMOOTHIE_CENTRED_GLSL
#define SOFTSHADOW_SMOOTHIE_CENTRED_GLSL
#include "buffer.glsl"

// One fragment of a smoothie: an inner quad's linear α or an outer smoothie's remapped α', and
// the depth code (depth.glsl) it is written with.
struct Centred {
    bool inner;
    float alpha;
    float code;
};

// False where the fragment says nothing (the clear's 1 stands).
bool centred_fragment(out Centred c) {
    vec2 uv = gl_FragCoord.xy / light.kernel.x;
    float caster = map_at(uv);
    float alpha = linear_alpha();
    c = Centred(in_range.y > 0.0, alpha, depth_code(light, in_b));
    if (c.inner) {
        // An inner texel counts only where this edge bounds this caster's hard shadow: nothing
        // cast just outside the edge (not a fold of the caster, no other caster abutting, which
        // may hide the light there), and the map's blocker here within the caster's depth range
        // (not another caster in front or behind), within two texels' depth.
        float slack = 2.0 * in_b * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / light.bias.w;
        bool own = caster >= in_range.x - slack && caster <= in_range.y + slack;
        return own && map_at(in_probe) >= light.kernel.y;
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
