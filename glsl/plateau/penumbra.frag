#version 460
// The plateau's sides write t. Centred (issue 20), t is the distance to the hard shadow's
// boundary in half widths on both of its sides, so only silhouettes on that boundary may write
// it: the mask must be lit a couple of texels off the foot, across the edge (either way: an
// edge seen edge-on has no reliable outward side), and the pixel must lie outside every hard
// shadow or in its own caster's. An interior fold (a torus's far rim, the cow's legs under its
// body) has shadow on both sides and writes nothing, so no bright streak crosses the umbra; an
// edge under another caster's shadow writes nothing there, nor does a caster's band inside
// another's shadow, so one caster's inner penumbra never lightens what another blocks.
layout(constant_id = 0) const bool CENTRED = false;

layout(set = 0, binding = 1) uniform sampler2D mask;

layout(location = 0) in float in_t;
layout(location = 1) in vec2 in_uv;
layout(location = 2) in vec2 in_foot;
layout(location = 3) flat in vec2 in_normal;
layout(location = 4) flat in uint in_caster;
layout(location = 0) out float out_t;

// How far off the foot the mask is probed, in texels: past the hard edge's rasterisation.
const float PROBE = 2.0;

uint caster_at(vec2 texel) {
    ivec2 size = textureSize(mask, 0);
    ivec2 i = clamp(ivec2(floor(texel)), ivec2(0), size - 1);
    return uint(round(texelFetch(mask, i, 0).r * 65535.0));
}

void main() {
    out_t = in_t;
    if (!CENTRED) {
        return;
    }
    vec2 size = vec2(textureSize(mask, 0));
    uint here = caster_at(gl_FragCoord.xy);
    if (here != 0u && here != in_caster) {
        discard;
    }
    vec2 foot = in_foot * size;
    // A cone's normal at this pixel is the direction from its apex.
    vec2 across = in_normal != vec2(0.0) ? in_normal * size : in_uv * size - foot;
    if (dot(across, across) < 1e-8) {
        discard; // on the apex itself: the sheets meeting there write it
    }
    vec2 probe = PROBE * normalize(across);
    if (caster_at(foot + probe) != 0u && caster_at(foot - probe) != 0u) {
        discard;
    }
}
