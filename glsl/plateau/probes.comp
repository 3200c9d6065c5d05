#version 460
// Centred, where each sheet's foot lies on the hard shadow's boundary (penumbra.frag writes a
// sheet's t only there): the umbra mask probed MASK_PROBE texels either side of its hard edge, at
// the middles of pieces at most a texel long (the CPU cuts sheets into pieces short enough),
// once per sheet. Probed per fragment, two mask reads each cost the centred sheets on lavapipe
// more than their roots did; per sheet vertex, six times over, the long edges of a few large
// casters as much again.
#include "interface.glsl"
#include "mask.glsl"
#include "probes.glsl"

layout(local_size_x = COMPUTE_GROUP) in;

// As penumbra.frag's: more than one caster, so a sheet may write over another's hard shadow.
layout(constant_id = 1) const bool OVERLAPS = true;

layout(set = 0, binding = 0) uniform Plateau { PlateauView plateau; };
// Sheets: a, b | ta, tb | normal, caster, hull bits (penumbra.vert).
layout(std430, set = 0, binding = 2) readonly buffer Sides { vec4 sides[]; };
layout(std430, set = 0, binding = 3) writeonly buffer Probes { SheetProbes probes[]; };

// The first n bits of a 64-bit set.
uvec2 first_bits(uint n) {
    return uvec2(n >= 32u ? ~0u : (1u << n) - 1u, n >= 64u ? ~0u : n <= 32u ? 0u : (1u << (n - 32u)) - 1u);
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= plateau.sheets.y) {
        return;
    }
    uint record = WEDGE_VEC4S * plateau.sheets.x + SHEET_VEC4S * i;
    vec4 r0 = sides[record], r2 = sides[record + 2u];
    // In texels, as penumbra.frag finds the foot: a + s·(b − a).
    vec2 to_texels = vec2(textureSize(mask, 0)) / (plateau.window.zw - plateau.window.xy);
    vec2 a = (r0.xy - plateau.window.xy) * to_texels, edge = (r0.zw - r0.xy) * to_texels;
    vec2 probe = MASK_PROBE * normalize(r2.xy * to_texels);
    uint caster = uint(r2.z);
    uint n = clamp(uint(ceil(length(edge))), 1u, SHEET_SAMPLES);
    uvec4 bits = uvec4(0u);
    for (uint k = 0u; k < n; k++) {
        vec2 foot = a + edge * ((float(k) + 0.5) / float(n));
        uint pa = caster_at(foot + probe), pb = caster_at(foot - probe);
        uint bit = 1u << (k & 31u);
        bits[k >> 5u] |= pa == 0u || pb == 0u ? bit : 0u;
        bits[2u + (k >> 5u)] |= pa == caster && pb == caster ? bit : 0u;
    }
    // Off the boundary everywhere, a sheet writes only over another caster's hard shadow where
    // its own caster does not cover both sides: nowhere, if it does everywhere.
    bool nowhere = bits.xy == uvec2(0u) && (!OVERLAPS || bits.zw == first_bits(n));
    probes[i] = SheetProbes(bits, uvec4(n, uint(nowhere), 0u, 0u));
}
