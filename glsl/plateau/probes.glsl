// A centred sheet's probes of the umbra mask along its hard edge, which probes.comp writes,
// penumbra.vert passes on and penumbra.frag reads.
#ifndef SOFTSHADOW_PLATEAU_PROBES_GLSL
#define SOFTSHADOW_PLATEAU_PROBES_GLSL

// The sides' records (geometry::plateau::Wedge, Sheet) are WEDGE_VEC4S and SHEET_VEC4S vec4s;
// a sheet's probes hold SHEET_SAMPLES samples at most (a bit each in each half of `bits`), the
// CPU cutting longer sheets into pieces, for a sample every texel (src/shader_constants.rs).

// A centred sheet's probes of the mask along its hard edge (probes.comp): per sample, the
// middles of `samples.x` equal pieces from a to b, whether the mask is lit on either side of
// the foot (bits.xy) and whether the sheet's own caster covers both sides (bits.zw);
// samples.y: 1 where the sheet can write nowhere.
struct SheetProbes {
    uvec4 bits;
    uvec4 samples;
};

// Sample k's bit in a 64-bit set.
bool probed(uvec2 bits, uint k) {
    return ((bits[k >> 5u] >> (k & 31u)) & 1u) != 0u;
}

#endif
