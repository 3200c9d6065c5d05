#version 460
// Plateau resolve: receivers on the plane read the plateau texture where they stand; V is the
// falloff curve at the plateau parameter t (Haines §3: the curve turns t into the gradient).
// Outer only (the paper), t is 0 under the hard shadow mask. Centred (issue 20), t is the
// distance to the hard edge in half widths, signed by the mask (negative inside), and the curve
// spans the whole width: V = falloff(½ + ½·s), ½ on the hard edge, in each of two channels
// (odd and even casters, see penumbra.frag), whose blockers count as independent: their
// visibilities multiply.
#include "interface.glsl"
#include "camera.glsl"
#include "falloff.glsl"

// The `off_plane` knob: receivers off the plane read the projected light map (§2), or are
// unshadowed.
layout(constant_id = 0) const bool OFF_PLANE_MAP = false;
// The `penumbra` knob: centred on the hard edge, or outer only.
layout(constant_id = 1) const bool CENTRED = false;
// Centred, several casters: the texture's second channel (penumbra.frag). Else it has one.
layout(constant_id = 2) const bool CHANNELS = true;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Plateau { PlateauView plateau; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
// Read as integers (R16_UINT, or R32_UINT over R16G16_UNORM, src/technique/plateau.rs): one
// gather brings both channels, the first in the low 16 bits.
layout(set = 0, binding = 4) uniform usampler2D plateau_texture;
layout(set = 0, binding = 5) uniform sampler2D umbra_mask;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

// One texel's curve parameters. Outer only: t, 0 inside the mask. Centred, per channel (odd
// and even casters, see penumbra.frag; one caster's in r alone): t, or −t in the channel of the
// caster whose hard shadow covers the texel. With two channels, where either is umbra (s ≤ −1,
// V = 0 whatever the other says), both are: where two casters' hard shadows abut, the channels
// swap roles between texels (one caster's umbra beside the other's outer band), and
// interpolated apart they drew a lit seam through the umbra (V up to 0.1 on overlap's ground).
// One channel has no such seam, and the rule would square the curve between an umbra texel and
// its neighbour (both channels falling together).
// `t`: the texel's plateau parameters (both channels), `caster`: its mask's caster number.
vec2 texel_s(vec2 t, uint caster) {
    if (!CENTRED) {
        return vec2(caster > 0u ? 0.0 : t.r, 1.0);
    }
    bvec2 own = CHANNELS ? bvec2(caster % 2u == 1u, caster > 0u && caster % 2u == 0u) : bvec2(caster > 0u, false);
    vec2 s = mix(t, -t, own);
    return CHANNELS && min(s.x, s.y) <= -1.0 ? vec2(-1.0) : s;
}

// A channel's visibility: every curve maps 0 to 0 and 1 to 1, so lit and umbra channels (most
// of the frame) skip the curve.
float channel_v(float s) {
    return s >= 1.0 ? 1.0 : (s <= -1.0 ? 0.0 : falloff_at(0.5 + 0.5 * s));
}

// Bilinear from the texels (the sampler is nearest): the gradient stays smooth, and where t is
// 0 on the hard edge the sign flips without a step. The four texels come in gathers, in gather
// order (i0,j1) (i1,j1) (i1,j0) (i0,j0): llvmpipe runs every branch of a fragment shader, and
// two gathers cost it less than eight fetches.
vec2 plateau_s(vec2 tc) {
    vec2 size = vec2(textureSize(plateau_texture, 0));
    vec2 pos = clamp(tc * size - 0.5, vec2(0.0), size - 1.001);
    vec2 f = fract(pos);
    vec2 corner = (floor(pos) + 1.0) / size;
    // Stored as ½ + ½·t (penumbra.frag), in unorm16.
    uvec4 packed = textureGather(plateau_texture, corner, 0);
    vec4 r = 2.0 * vec4(packed & 0xffffu) / 65535.0 - 1.0;
    vec4 g = CENTRED && CHANNELS ? 2.0 * vec4(packed >> 16u) / 65535.0 - 1.0 : vec4(1.0);
    uvec4 casters = uvec4(round(textureGather(umbra_mask, corner, 0) * 65535.0));
    vec2 s[4];
    for (int k = 0; k < 4; k++) {
        s[k] = texel_s(vec2(r[k], g[k]), casters[k]);
    }
    return mix(mix(s[3], s[2], f.x), mix(s[0], s[1], f.x), f.y);
}

void main() {
    Surface s = read_surface(frame, camera_depth, camera_normal, in_uv);
    if (!s.receives) {
        out_visibility = 1.0;
        return;
    }
    // A caster's own surface hides the part of the light behind its tangent plane: the soft
    // terminator of an area light, exact for a convex caster (the plateau holds no shadow of a
    // caster on itself).
    float self_lit = in_front_of_itself(s, frame.light.xyz, frame.light.w);
    if (self_lit == 0.0) {
        out_visibility = 0.0;
        return;
    }
    vec3 n = plateau.plane_normal.xyz;
    vec3 o = plateau.plane_origin.xyz;
    vec3 q = s.p;
    if (!on_plane(frame, s, o, n)) {
        // Off the plane: unshadowed, or (mode 1, receivers that cast nothing) the paper's
        // projected light map: the texture where the ray from the light through p meets the plane.
        float h = dot(s.p - o, n);
        float hl = dot(frame.light.xyz - o, n);
        if (!OFF_PLANE_MAP || s.casts || h >= hl) {
            out_visibility = self_lit;
            return;
        }
        // From p along the ray, not from the light: light + (p − light)·hl/(hl − h) rounds p
        // to the ulp of the light's position (8 m from 1e8 m). The true light, not the nearer
        // one the texture is drawn from: their rays differ by at most 1/256 rad.
        vec3 d = s.p - frame.light.xyz;
        q = s.p - d * (h / dot(d, n));
    }
    vec2 uv = vec2(dot(q - o, plateau.plane_u.xyz), dot(q - o, plateau.plane_v.xyz));
    vec2 tc = (uv - plateau.window.xy) / (plateau.window.zw - plateau.window.xy);
    if (any(lessThan(tc, vec2(0.0))) || any(greaterThan(tc, vec2(1.0)))) {
        out_visibility = 1.0; // beyond the shadow's footprint
        return;
    }
    vec2 signed_t = plateau_s(tc);
    // Centred, the two channels' blockers count as independent: their visibilities multiply.
    out_visibility = CENTRED ? channel_v(signed_t.x) * channel_v(signed_t.y) : falloff_at(signed_t.x);
}
