#version 460
// The plateau's sides write t, blended by min (the darkest wins, Haines §2), into channel r; g
// stays 1. Centred (issue 20), t is the distance to the hard shadow's boundary in half widths on
// both of its sides, so only silhouettes on that boundary may write it: the mask must be lit a
// couple of texels off the foot, across the edge (either way: an edge seen edge-on has no
// reliable outward side). An interior fold (a torus's far rim, the cow's legs under its body)
// has shadow on both sides and writes nothing, so no bright streak crosses the umbra.
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

layout(set = 0, binding = 1) uniform sampler2D mask;

layout(location = 0) in float in_t;
layout(location = 1) in vec2 in_uv;
layout(location = 2) in vec2 in_foot;
layout(location = 3) flat in vec2 in_normal;
layout(location = 4) flat in uint in_caster;
layout(location = 0) out vec2 out_t;

// How far off the foot the mask is probed, in texels: past the hard edge's rasterisation.
const float PROBE = 2.0;

uint caster_at(vec2 texel) {
    ivec2 size = textureSize(mask, 0);
    ivec2 i = clamp(ivec2(floor(texel)), ivec2(0), size - 1);
    return uint(round(texelFetch(mask, i, 0).r * 65535.0));
}

// t in the channel of caster number `caster` (r odd, g even), the other left lit.
vec2 in_channel(uint caster, float t) {
    return caster % 2u == 1u ? vec2(t, 1.0) : vec2(1.0, t);
}

void main() {
    out_t = vec2(in_t, 1.0);
    if (!CENTRED) {
        return;
    }
    vec2 size = vec2(textureSize(mask, 0));
    vec2 foot = in_foot * size;
    vec2 from_foot = in_uv * size - foot;
    // A cone's normal at this pixel is the direction from its apex.
    vec2 across = in_normal != vec2(0.0) ? in_normal * size : from_foot;
    if (dot(across, across) < 1e-8) {
        discard; // on the apex itself: the sheets meeting there write it
    }
    vec2 probe = PROBE * normalize(across);
    uint here = OVERLAPS ? caster_at(gl_FragCoord.xy) : 0u;
    if (here == 0u || here == in_caster) {
        // Outward first: on the hard shadow's boundary it is lit, and one read decides.
        if (caster_at(foot + probe) != 0u && caster_at(foot - probe) != 0u) {
            discard;
        }
        out_t = in_channel(in_caster, in_t);
        return;
    }
    uint a = caster_at(foot + probe), b = caster_at(foot - probe);
    // Over another caster's hard shadow: an outer band (a sheet's outer half) of an edge with
    // something other than its own caster across it.
    bool outer_half = in_normal != vec2(0.0) && dot(from_foot, in_normal * size) > 0.0;
    if (!outer_half || (a == in_caster && b == in_caster)) {
        discard;
    }
    out_t = in_channel(here + 1u, in_t);
}
