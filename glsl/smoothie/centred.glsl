// What both centred smoothie-buffer shaders share (issue 20; centred.frag, several casters in
// two channels; centred_one.frag, one caster in one target): which smoothies a fragment keeps,
// and what it says.
#ifndef SOFTSHADOW_SMOOTHIE_CENTRED_GLSL
#define SOFTSHADOW_SMOOTHIE_CENTRED_GLSL
#include "buffer.glsl"
#include "corners.glsl"

// Which smoothies a draw holds (smoothie.rs's `Part`): the inner quads, or the outer smoothies.
// Each kind is drawn apart, so a fragment runs only its own kind's code: llvmpipe runs both
// branches of a test it cannot fold.
layout(constant_id = 0) const bool INNER = false;
// Whether a draw holds the smoothies near the hard shadow's corners (smoothie.rs's `Part`),
// which write V under both of the corner's lines (corners.glsl), drawn apart for the same
// reason; and whether it holds chamfered ones (corner_visibility), whose three lines cost more.
layout(constant_id = 1) const bool CORNERS = false;
layout(constant_id = 2) const bool CHAMFER = false;
// The map's texels are the buffer's (equal sizes over one frustum), as the resolve's SAME_GRID.
layout(constant_id = 3) const bool SAME_GRID = true;
// The inner quads of partial silhouettes below the silhouette (partial_inner), blended by max.
layout(constant_id = 4) const bool PARTIAL = false;

// How the centred buffer stores an alpha: ½ + ½α. Near a corner V goes past what either edge
// alone gives, an outer α' or an inner α below 0 (corner_alpha); 1 is still the clear's, lit
// outside and umbra inside. The resolve reads it back (resolve.frag's texels).
float alpha_code(float alpha) {
    return 0.5 + 0.5 * clamp(alpha, -1.0, 1.0);
}

// This fragment's point in the light view's tangent plane.
vec2 fragment_tangent() {
    return mix(light.extent.xy, light.extent.zw, gl_FragCoord.xy / light.kernel.x);
}

// V under both of the corner's lines (corners.glsl) at this fragment, with `part` = 1 − b/r for
// a receiver at depth r: the light seen from it through the blocker's depth b is the disk of
// radius t·(1 − b/r) about the fragment in the tangent plane (similar triangles, as the
// smoothie's size: geometry::smoothie::SmoothieSize), where the edges' lines cut it.
//
// A turn split by a short edge (ShadowCorner::chamfer) has three lines: the shadow is all three
// inner sides at a convex turn, and the light all three outer sides at a reflex one. Each pair
// of lines bounds a region holding that one (convex) or held in it (reflex), so V is at least
// (at most) each pair's, and the nearest bound is the pair whose lines the footprint meets: the
// corner's two where it is wider than the cut; where it is narrower, near contact, the short
// edge's and one long edge's, which leave lit the sliver the cut takes off the corner (contact's
// slab at its foot: 0.4–0.9 too dark in a row of 7 px at 512² with the corner's two alone).
// Unless the map says otherwise between the cut and the corner, `covered` saying whether it holds
// a caster at this texel (an inner fragment's own caster, an outer one's anything at its depth or
// nearer): there the two models disagree, and where the map takes the corner's side (a caster at
// a convex turn, none at a reflex one), something the three lines leave out is there (default's
// wingnut: 4 px lit to 0.89 for 0.35 where its wing's shadow meets its body's).
float corner_visibility(float part, bool covered) {
    vec2 p = fragment_tangent() - in_corner;
    float radius = max(in_size * part, 1e-30);
    vec3 one = vec3(in_normals.xy, dot(in_normals.xy, p) / radius);
    vec3 other = vec3(in_normals.zw, dot(in_normals.zw, p) / radius);
    bool convex = in_turn > 0.0;
    float v = corner_v_turned(one, other, convex, in_angles.x);
    if (!CHAMFER || dot(in_chamfer.xy, in_chamfer.xy) == 0.0) {
        return v;
    }
    float beyond = dot(in_chamfer.xy, p) + in_chamfer.z;
    bool in_cut = convex ? max(one.z, other.z) <= 0.0 && beyond > 0.0 : min(one.z, other.z) > 0.0 && beyond <= 0.0;
    if (in_cut && covered == convex) {
        return v;
    }
    vec3 cut = vec3(in_chamfer.xy, beyond / radius);
    float a = corner_v_turned(one, cut, convex, in_angles.y), b = corner_v_turned(cut, other, convex, in_angles.z);
    return convex ? max(v, max(a, b)) : min(v, min(a, b));
}

// Whether the light passes both edges of a convex corner where this fragment's footprint meets
// them: a probe step outside each edge (depth.glsl's probe_step, as smoothie.vert's probe), at the
// fragment's foot on it, nothing is cast nearer than `far`. Where something is (a caster the
// corner's caster stands on, or one abutting it), the light beyond that edge's line never reaches
// the receiver, which sees the other edge alone: on a post standing on a slab, the post's base line
// taken as a corner's lit both ways lightened the slab behind it by up to 0.46 (6 754 px of 128²
// leaking 0.1). A reflex corner darkens past either edge alone, as any blocker beyond it would:
// kept.
bool corner_open(float far) {
    if (in_turn < 0.0) {
        return true;
    }
    vec2 p = fragment_tangent() - in_corner;
    float step = probe_step(light);
    for (int k = 0; k < 2; k++) {
        vec2 n = k == 0 ? in_normals.xy : in_normals.zw;
        vec2 other = k == 0 ? in_normals.zw : in_normals.xy;
        // The edge runs from the vertex into the other edge's inner side.
        vec2 along = vec2(-n.y, n.x);
        along = dot(along, other) > 0.0 ? -along : along;
        vec2 probe = in_corner + along * max(dot(p, along), 0.0) + n * step;
        float outside = map_at(tangent_uv(light, probe));
        if (outside < light.kernel.y && outside <= far) {
            return false;
        }
    }
    return true;
}

// How far this fragment lies outside the hard shadow the corner's lines stand for (tangent
// units; below 0 inside): the intersection of their inner sides at a convex turn, the union at a
// reflex one, a chamfer's line with them (corner_visibility).
float outside_lines() {
    vec2 p = fragment_tangent() - in_corner;
    float one = dot(in_normals.xy, p), other = dot(in_normals.zw, p);
    bool chamfered = CHAMFER && dot(in_chamfer.xy, in_chamfer.xy) > 0.0;
    float cut = dot(in_chamfer.xy, p) + in_chamfer.z;
    if (in_turn > 0.0) {
        float outside = max(one, other);
        return chamfered ? max(outside, cut) : outside;
    }
    float outside = min(one, other);
    return chamfered ? min(outside, cut) : outside;
}

// Near a corner, the alpha whose penumbra parameter gives V under both lines through the
// resolve's disk-edge curve (falloff.glsl's curve 3, V = disk_below(±α)): an outer α' for a
// receiver at r, or an inner α, which the resolve remaps by its receiver's own r (exact where
// that is the r taken here). `alpha` stands where r lies at or in front of b (contact: hard).
float corner_alpha(float alpha, float r, bool inner, bool covered) {
    float part = 1.0 - blocker_depth() / r;
    if (!(part > 0.0)) {
        return alpha;
    }
    float u = disk_below_inverse(corner_visibility(part, covered));
    return inner ? -u * part : u;
}

// One fragment of a smoothie: an inner quad's linear α or an outer smoothie's remapped α' (near
// a corner, either may fall below 0: corner_alpha), and the depth code (depth.glsl) it is
// written with.
struct Centred {
    bool inner;
    float alpha;
    float code;
    // An inner quad's: the depth code of the nearest caster in the map just outside its edge
    // (1: none), past which a receiver's light from beyond the edge may be hidden again.
    float limit;
};

// A partial silhouette's inner quad (geometry::smoothie::partial_smoothies): its edge lies
// under the silhouette, whose depth b0 (in_corner.x) the buffer's inner depth holds, so its
// alpha goes in converted, α·(1 − b0/r)/(1 − b/r), which the resolve's remap by 1 − b0/r takes
// back to its own inner parameter on a receiver at r. r: the ground, the farthest receiver
// behind (the map here holds the caster). On a nearer one the converted alpha errs light
// ((b − b0)(1/r_ground − 1/r) ≤ 0), where max blending keeps the silhouette's. Kept only where
// the map holds its caster here and a whole penumbra width further in, straight and ±45°, as
// the plateau's partial sheets are (glsl/plateau/penumbra.frag): past a caster narrower than
// its penumbra, or one turning a corner within it, the edge's half plane hides more than the
// caster does.
bool partial_inner(inout Centred c, float slack) {
    float r = ground_depth(light, gl_FragCoord.xy / light.kernel.x);
    float part = 1.0 - blocker_depth() / r;
    if (!(part > 0.0)) {
        return false;
    }
    vec2 p = fragment_tangent(), inward = in_normals.xy * (in_size * part);
    vec2 deeper = p + inward, side = vec2(-inward.y, inward.x);
    vec2 probes[4] = vec2[4](p, deeper, deeper + side, deeper - side);
    for (int k = 0; k < 4; k++) {
        float d = map_at(tangent_uv(light, probes[k]));
        if (d < in_range.x - slack || d > in_range.y + slack) {
            return false;
        }
    }
    c.alpha = min(c.alpha / part, 1.0) * (1.0 - in_corner.x / r);
    return true;
}

// False where the fragment says nothing (the clear's 1 stands).
bool centred_fragment(out Centred c) {
    // A piece of a cut quad keeps its own part of the edge (geometry::smoothie's edge_quad).
    if (in_along < in_keep.x || in_along >= in_keep.y) {
        c = Centred(INNER, 1.0, 1.0, 1.0);
        return false;
    }
    vec2 uv = gl_FragCoord.xy / light.kernel.x;
    float caster = map_at(uv);
    float alpha = linear_alpha();
    float b = blocker_depth();
    c = Centred(INNER, alpha, depth_code(light, b), 1.0);
    // Two map texels' depth at b, what a face at 45° to the light spans across them.
    float slack = 2.0 * b * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / light.bias.w;
    if (PARTIAL) {
        return partial_inner(c, slack);
    }
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
        if (!SAME_GRID) {
            // The map texel under the centre (map_at) lies up to half a map texel off it, so
            // near the hard edge it can miss the caster where the centre lies inside its
            // outline, as the quad says; one of the four map texels about the centre lies on
            // its side of the edge. Kept so, an inner quad tells the resolve that its texel is
            // inside the outline (resolve.frag's centred_test).
            vec4 around = textureGather(shadow_map, uv, 0);
            vec4 above = vec4(greaterThanEqual(around, vec4(in_range.x - slack)));
            own = dot(above, vec4(lessThanEqual(around, vec4(in_range.y + slack)))) > 0.0;
        }
        float outside = map_at(in_probe);
        c.limit = depth_code(light, outside);
        if (CORNERS && corner_open(in_range.y + slack)) {
            // The receiver taken behind the blocker: what is cast just outside the edge, which
            // the inner half holds down to (the limit), else the ground. With the ground alone,
            // overlap's upper plate's corner on the lower plate took the ground's footprint, far
            // wider than the lower plate's (97 px leaking 0.14).
            c.alpha = corner_alpha(alpha, min(outside, ground_depth(light, uv)), true, own);
        }
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
    // Where the grids differ, the map texel under this one's centre can lie on the outline's
    // other side, on the smoothie's own caster: within the slack of b, that is no receiver in
    // front of the ground. Taken as one, it dropped the outer alpha there (r ≈ b), and the
    // resolve read the texel as umbra: dark speckles on the plate's hard edge once b was exact
    // (a 1024² map over a 512² buffer, 128²: penumbra RMSE 0.0217, 0.0091 so).
    float r = b + (SAME_GRID ? 0.0 : slack) < caster ? min(caster, ground) : ground;
    c.alpha = remapped_alpha(alpha, r);
    if (CORNERS && corner_open(b + slack)) {
        // The lines stand for the caster only as far as its outline follows them. Where the map
        // holds nothing at b, the caster is not there; where the lines still put the whole
        // footprint in their shadow (their V 0), its outline has left them, past a caster
        // thinner than the footprint, and their umbra would darken a receiver the light's centre
        // sees: close to default's wingnut, the lit top of its wing behind a reflex turn of its
        // outline read 0 for the truth's 1 (a 9 × 9 px patch at 256², 11 px of default at 512²).
        // Nearer the lines their penumbra stands: there the map's outline may stray from them
        // by a merged silhouette's tolerance (trusted only to a texel, `merge=2` leaked 18 px
        // more on the sphere).
        float footprint = in_size * max(1.0 - b / r, 0.0);
        if (caster > b + slack && outside_lines() < -max(coarser_texel(light), footprint)) {
            return false;
        }
        c.alpha = corner_alpha(c.alpha, r, false, caster <= b + slack);
    }
    if (partial) {
        c.code = depth_code(light, in_range.x);
    }
    // At 1: behind the ground, or lit.
    return c.alpha < 1.0;
}

#endif
