#version 460
// The plateau's sides write t, blended by min (the darkest wins, Haines §2), into channel r
// (outer only, or one caster: the texture's only channel). Centred (issue 20), t is the
// distance to the hard shadow's boundary in half widths on both of its sides, so only
// silhouettes on that boundary may write it: the mask must be lit a couple of texels off the
// foot, across the edge (either way: an edge seen edge-on has no reliable outward side; a
// sheet's vertices probe it along the edge, penumbra.vert, a cone's fragments here). An
// interior fold (a torus's far rim, the cow's legs under its body) has shadow on both sides and
// writes nothing, so no bright streak crosses the umbra.
//
// Overlapping casters. Each caster's bands go to one channel, r for odd caster numbers and g
// for even ones, and the resolve multiplies the two channels' visibilities: blockers in
// different channels count as independent (Chan & Durand Fig. 10's overlapping penumbrae), so
// two crossing outer penumbrae multiply instead of the darkest winning; within a channel the
// darkest still wins. Over a caster's hard shadow (the mask holds the lowest caster where hard
// shadows overlap), that caster's channel holds its bands only, so one caster's inner penumbra
// never lightens what another blocks; another caster's outer penumbra there goes to the other
// channel, if its edge bounds that caster's own shadow.
layout(constant_id = 0) const bool CENTRED = false;
// More than one caster: the mask may hold another caster's number where a side is drawn. With
// one, it holds only this caster's or none, and the texel under the fragment need not be read.
layout(constant_id = 1) const bool OVERLAPS = true;
// Sheets or wedges (see penumbra.vert for what each interpolates).
layout(constant_id = 2) const bool SHEETS = false;
// Centred, partial silhouettes' sheets (geometry::plateau::partial_sides), whose hard edges lie
// inside the hard shadow: 1, the outer halves of those above the silhouette, which write only
// where the mask is lit; 2, the inner halves of those below it, which write only where it holds
// their own caster, blended by max (0 in the other channel leaves it as it is), so that they
// only darken. 0: the silhouette's sides.
layout(constant_id = 3) const uint PARTIAL = 0u;
#define PARTIAL_OUTER 1u
#define PARTIAL_INNER 2u
// Centred, the sides near the hard shadow's corners (corners.glsl), drawn apart from the rest.
layout(constant_id = 4) const bool CORNERS = false;

#include "mask.glsl"
#include "probes.glsl"
#include "corners.glsl"

layout(location = 0) in vec2 in_local;
layout(location = 1) in vec2 in_uv;
layout(location = 2) flat in vec4 in_shape0;
layout(location = 3) flat in vec4 in_shape1;
layout(location = 4) flat in uint in_caster;
// Centred sheets: what the vertices probed along the hard edge (penumbra.vert), and at how
// many samples.
layout(location = 5) flat in uvec4 in_probes;
layout(location = 6) flat in uint in_samples;
// Centred, the corners (penumbra.vert, corners.glsl).
layout(location = 7) flat in vec4 in_corner0;
layout(location = 8) flat in vec4 in_axes0;
layout(location = 9) flat in vec4 in_corner1;
layout(location = 10) flat in vec4 in_axes1;
layout(location = 11) flat in vec4 in_turns;
layout(location = 12) flat in vec2 in_angles;
// The plateau parameter, signed (−1 .. 1: centred corners write below 0, corners.glsl) and
// stored as ½ + ½·t in the unsigned texture; the resolve reads it back.
layout(location = 0) out vec2 out_t;

float cross2(vec2 a, vec2 b) {
    return a.x * b.y - a.y * b.x;
}

// SHEET_SLACK and FOLD_SLACK (src/shader_constants.rs): slack of s and t at a sheet's sides
// (f32 rounding), and how near, relative to the patch's size, a root near a fold line must map
// back, as geometry::plateau::Sheet::at.

// A sheet's smallest t over this fragment and its foot's s on the hard edge: the inverse of the
// bilinear map q = s·e + t·f + s·t·g (q = p − a), whose t solves (f × g)·t² + (f × e − q × g)·t −
// q × e = 0, in the form without cancellation (Sheet::at). False off the patch. `texel`: the
// texel's size in plane units. Below t = 0, half a texel of slack: rasterisation snaps the hard
// edge, which a sheet's inner and outer halves share, to the subpixel grid, and can hand one
// half a fragment of the other's; there t is 0 whichever half draws it. With f32's slack alone
// (plate, 256² texture) a texel 0.001 texels inside went to the outer half, whose t of −1.5e-4
// it dropped: nothing was drawn there, a lit speckle on the hard edge.
bool sheet_t(vec2 texel, out float t, out float s) {
    vec2 e = in_shape0.xy, f = in_shape0.zw, q = in_local;
    vec2 g = in_shape1.xy - f - e;
    // At most half the width: a sheet narrower than a texel takes no more than its own.
    float widest = sqrt(max(dot(f, f), dot(f + g, f + g))); // |ta − a|, |tb − b|
    float below = clamp(0.5 * max(texel.x, texel.y) / widest, SHEET_SLACK, 0.5);
    float qa = cross2(f, g), qb = cross2(f, e) - cross2(q, g), qc = -cross2(q, e);
    // Near a fold line d can round below 0 and s swings with t: a root there counts if it maps
    // back to q (Sheet::at).
    float d = qb * qb - 4.0 * qa * qc;
    float root_d = sqrt(max(d, 0.0));
    float h = -0.5 * (qb + (qb < 0.0 ? -root_d : root_d));
    float roots[2] = float[2](h != 0.0 ? qc / h : -1.0, qa != 0.0 ? h / qa : -1.0);
    float reach2 = FOLD_SLACK * FOLD_SLACK * (dot(e, e) + dot(f, f) + dot(g, g));
    t = 2.0;
    for (int k = 0; k < 2; k++) {
        float r = roots[k];
        if (r < -below || r > 1.0 + SHEET_SLACK || r >= t) {
            continue;
        }
        vec2 side = e + g * r;
        float u = dot(q - f * r, side) / dot(side, side);
        float rc = clamp(r, 0.0, 1.0), uc = clamp(u, 0.0, 1.0);
        bool inside = d >= 0.0 && u >= -SHEET_SLACK && u <= 1.0 + SHEET_SLACK;
        vec2 miss = e * uc + f * rc + g * (uc * rc) - q;
        if (inside || dot(miss, miss) <= reach2) {
            t = rc;
            s = uc;
        }
    }
    return t <= 1.0;
}

// A cone's t at y (unit-disk coordinates from the apex): the positive root of (1 − |lean|²)·t² +
// 2·(y·lean)·t − |y|² = 0 (Wedge::t_at).
float wedge_t(vec2 y, vec2 lean) {
    float yy = dot(y, y), yl = dot(y, lean);
    return yy == 0.0 ? 0.0 : yy / (yl + sqrt(yl * yl + (1.0 - dot(lean, lean)) * yy));
}

// t in the channel of caster number `caster` (r odd, g even), the other left lit; one caster's
// in r, the texture's only channel.
vec2 in_channel(uint caster, float t) {
    return !OVERLAPS || caster % 2u == 1u ? vec2(t, 1.0) : vec2(1.0, t);
}

// What the sheet's nearer corner adds to V at `from_a` (plane units from a), with `own` its
// edge's outward normal. One corner a fragment: both cost llvmpipe, which runs every branch,
// twice the arithmetic on every fragment near either, and only an edge shorter than about two
// footprints has fragments whose footprint reaches past both of its ends.
float sheet_corner_gain(vec2 from_a, vec2 own) {
    vec2 p0 = from_a - in_corner0.xy, p1 = from_a - in_corner1.xy;
    bool first = dot(p0, p0) <= dot(p1, p1);
    vec4 corner = first ? in_corner0 : in_corner1;
    mat2 axes = mat2(first ? in_axes0 : in_axes1);
    vec2 p = first ? p0 : p1;
    vec3 mine, other;
    if (!footprint_line(axes, own, p, mine) || !footprint_line(axes, corner.zw, p, other)) {
        return 0.0;
    }
    bool convex = (first ? in_turns.z : in_turns.w) > 0.5;
    return corner_v_turned(mine, other, convex, first ? in_angles.x : in_angles.y) - disk_below(mine.z);
}

// What the wedge's corner adds to V at y (unit-disk coordinates from the apex, t its cone's),
// and the side of the hard edge it lies on (1 outside, −1 inside). The cone's own line is the
// tangent of its base scaled by t at y, x·y from the apex in disk units (x = y/t − lean, its
// rim point): where a sheet leaves the cone, the sheet's edge.
float wedge_corner_gain(vec2 y, float t, out float side) {
    mat2 axes = mat2(in_axes0);
    vec3 one, other;
    side = 1.0;
    if (!footprint_line(axes, in_corner0.zw, axes * y, one) || !footprint_line(axes, in_corner1.zw, axes * y, other)) {
        return 0.0;
    }
    bool convex = in_turns.z > 0.5;
    side = (convex ? one.z < 0.0 && other.z < 0.0 : one.z < 0.0 || other.z < 0.0) ? -1.0 : 1.0;
    vec2 rim = t > 0.0 ? y / t - in_shape0.xy : vec2(1.0, 0.0);
    return corner_v_turned(one, other, convex, in_angles.x) - disk_below(side * dot(rim, y));
}

// The t a centred side writes: its own t on `side` (1 outside the hard edge, −1 inside),
// with `gain` added to V through the disk-edge curve (the distance that curve takes to V), its
// sign the one the resolve takes off: −1 where the mask holds the side's own caster (`own`).
// The mask, not the side: near a corner t is far from 0 on the hard edge, and where the mask's
// rasterised edge and the side's line part by a texel (a sharp spike's sliver) the side's sign
// flipped single pixels between lit and umbra. Where nothing is added, t itself.
float with_corner(float t, float side, float gain, bool own) {
    // A gain is a difference of two fractions of the light: anything else (a NaN from a
    // footprint too large for f32) adds nothing.
    if (!(abs(gain) <= 1.0) || gain == 0.0) {
        return t;
    }
    return (own ? -1.0 : 1.0) * disk_below_inverse(disk_below(side * t) + gain);
}

// Centred: whether this side writes here (its foot on the hard shadow's boundary, or an
// outer band over another caster's hard shadow) and what, per channel. `texel`: the texel's
// size in plane units.
bool centred_t(float t, float s, vec2 texel, out vec2 written) {
    written = vec2(1.0);
    if (PARTIAL == PARTIAL_OUTER) {
        if (caster_at(gl_FragCoord.xy) != 0u) {
            return false;
        }
        written = in_channel(in_caster, t);
        return true;
    }
    if (PARTIAL == PARTIAL_INNER) {
        // Drawn k = |normal| times its width, the umbra held beyond (partial_sides).
        float k = length(in_turns.xy);
        // The edge's half plane hides no more than its caster where the caster reaches a whole
        // width of the edge's penumbra further in, and as far to either side: its hard shadow
        // covers those points (the width along its tangent from here, turned ±45°). Where it
        // does not, the caster is narrower than the penumbra, or turns a corner within it, and
        // the silhouette's sheets, nearest edge and corners, say more: the hammer's thin handle
        // went 0.13 too dark across its shadow without the first, default's wingnut 0.13 beside
        // a corner without the others.
        // ta − a and tb − b, the sheet's widths at its ends, in texels.
        vec2 width = mix(in_shape0.zw, in_shape1.xy - in_shape0.xy, s) / k / texel;
        vec2 side = vec2(-width.y, width.x);
        vec2 at = gl_FragCoord.xy;
        if (caster_at(at) != in_caster || caster_at(at + width) != in_caster
            || caster_at(at + width + side) != in_caster || caster_at(at + width - side) != in_caster) {
            return false;
        }
        float held = min(t * k, 1.0);
        written = mix(vec2(held), vec2(-1.0), in_channel(in_caster, 0.0)); // the other channel stored 0
        return true;
    }
    uint here = OVERLAPS ? caster_at(gl_FragCoord.xy) : 0u;
    // Whether the foot lies on the hard shadow's boundary (one side lit), whether its own
    // caster lies on both sides, and whether the fragment is on the edge's outer side.
    bool boundary, own_both, outer_half;
    if (SHEETS) {
        // The vertices probed the edge at the middles of pieces a texel long at most: the
        // foot's.
        uint k = min(uint(s * float(in_samples)), in_samples - 1u);
        boundary = probed(in_probes.xy, k);
        own_both = probed(in_probes.zw, k);
        vec2 from_foot = in_local - s * in_shape0.xy;
        outer_half = dot(from_foot, in_turns.xy) > 0.0;
    } else {
        // A cone's foot is its apex, and its normal at this pixel the direction from there.
        vec2 size = vec2(textureSize(mask, 0));
        vec2 foot = in_shape1.zw * size;
        vec2 from_foot = in_uv * size - foot;
        if (dot(from_foot, from_foot) < 1e-8) {
            return false; // on the apex itself: the sheets meeting there write it
        }
        vec2 probe = MASK_PROBE * normalize(from_foot);
        uint a = caster_at(foot + probe), b = caster_at(foot - probe);
        boundary = a == 0u || b == 0u;
        own_both = a == in_caster && b == in_caster;
        outer_half = false;
    }
    // On its own caster's side of the mask, or none: where the foot is on the boundary. Over
    // another caster's hard shadow: an outer band (a sheet's outer half) of an edge with
    // something other than its own caster across it, in the other channel.
    bool mine = here == 0u || here == in_caster;
    if (mine ? !boundary : !outer_half || own_both) {
        return false; // before the corners' arithmetic, which nothing written needs
    }
    float signed_t = t;
    if (CORNERS) {
        float side = outer_half ? 1.0 : -1.0;
        float gain = SHEETS ? sheet_corner_gain(in_local, in_turns.xy) : wedge_corner_gain(in_local, t, side);
        // One caster's mask is read only near corners.
        uint under = OVERLAPS ? here : caster_at(gl_FragCoord.xy);
        signed_t = with_corner(t, side, gain, under == in_caster);
    }
    written = in_channel(mine ? in_caster : here + 1u, signed_t);
    return true;
}

void main() {
    // Before any discard: derivatives need every fragment of the quad.
    vec2 texel = fwidth(in_local);
    float t, s = 0.0;
    if (SHEETS) {
        if (!sheet_t(texel, t, s)) {
            discard;
        }
    } else {
        t = wedge_t(in_local, in_shape0.xy);
        if (t > 1.0) {
            discard; // off the base: t = 1 (lit) is what the texture holds there
        }
    }
    vec2 written = vec2(t, 1.0);
    if (CENTRED) {
        if (!centred_t(t, s, texel, written)) {
            discard;
        }
    }
    out_t = 0.5 + 0.5 * written;
}
