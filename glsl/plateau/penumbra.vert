#version 460
// The plateau's sides, one primitive per record, expanded here from gl_VertexIndex (issue 18:
// the CPU writes 12 floats a primitive, the GPU finds t per fragment). A sheet (Haines §2) is
// its corners a, b, tb, ta; drawn as their convex hull, two triangles whose corner numbers the
// CPU chose (geometry::plateau::Sheet). A wedge, a piece of a vertex cone over the rim angles
// [from, to], is drawn in the base's unit-disk coordinates x (plane point apex + axes·(x + lean))
// as the triangle apex, rim(from), rim(to) and the trapezoid from that chord out to the rim's
// tangent at the middle angle (geometry::plateau::Wedge). Both interpolate coordinates in which
// the fragment shader solves for t exactly.
//
// Centred, a sheet writes only where its foot lies on the hard shadow's boundary, which
// probes.comp found along its hard edge: the fragments read that, and a sheet with its foot
// nowhere on the boundary (an interior fold's) is not drawn.
#include "interface.glsl"
#include "mask.glsl"
#include "probes.glsl"
#include "corners.glsl"

// As penumbra.frag's.
layout(constant_id = 0) const bool CENTRED = false;
// Sheets (6 vertices a primitive) or wedges (9).
layout(constant_id = 2) const bool SHEETS = false;
// As penumbra.frag's: partial silhouettes' sheets (1, 2), which have no probes.
layout(constant_id = 3) const uint PARTIAL = 0u;
// As penumbra.frag's: the sides near corners.
layout(constant_id = 4) const bool CORNERS = false;

layout(set = 0, binding = 0) uniform Plateau { PlateauView plateau; };
// Wedges (WEDGE_VEC4S): apex, lean | axes (columns) | from, to, caster, convex | the normals
// of the apex's two edges. Sheets (SHEET_VEC4S): a, b | ta, tb | normal, caster, hull (bits) |
// then per corner (at a, at b): its vertex, the other edge's normal | the vertex cone's axes.
// Wedges first, then sheets: gl_VertexIndex counts from the first.
layout(std430, set = 0, binding = 2) readonly buffer Sides { vec4 sides[]; };
layout(std430, set = 0, binding = 3) readonly buffer Probes { SheetProbes probes[]; };

// Sheets: p − a, in plane units. Wedges: y = x + lean, the point from the apex in unit-disk
// coordinates. Both affine in the plane point, so interpolated exactly.
layout(location = 0) out vec2 out_local;
layout(location = 1) out vec2 out_uv;
// Sheets: b − a, ta − a | tb − a, the hard edge's start a in texture coordinates. Wedges: lean,
// - | -, the apex in texture coordinates.
layout(location = 2) flat out vec4 out_shape0;
layout(location = 3) flat out vec4 out_shape1;
layout(location = 4) flat out uint out_caster;
// Centred sheets: their mask probes along the hard edge (probes.comp), for the fragments.
layout(location = 5) flat out uvec4 out_probes;
layout(location = 6) flat out uint out_samples;
// Centred, the corners (corners.glsl): per corner, its vertex from the primitive's origin (a
// sheet's a, a wedge's apex) and the other edge's normal | the footprint's axes; the sheet's
// own outward normal (plane units, which also tell the fragments its outer half), 1 where
// convex at each corner (wedges: their one corner, both normals).
layout(location = 7) flat out vec4 out_corner0;
layout(location = 8) flat out vec4 out_axes0;
layout(location = 9) flat out vec4 out_corner1;
layout(location = 10) flat out vec4 out_axes1;
layout(location = 11) flat out vec4 out_turns;
// Centred, per corner: the angle between its two lines in the footprint's disk coordinates
// (corners.glsl's corner_angle), the same for every fragment of the primitive, whose axes and
// normals are flat: found here once, not with an atan per corner fragment.
layout(location = 12) flat out vec2 out_angles;

// The angle from line `one`'s normal to `other`'s as footprint_line makes them under `axes`.
float footprint_angle(vec4 axes, vec2 one, vec2 other) {
    mat2 to_disk = transpose(mat2(axes));
    vec2 g1 = to_disk * one, g2 = to_disk * other;
    return corner_angle(g1 / max(length(g1), 1e-30), g2 / max(length(g2), 1e-30));
}

// Whether the hard shadow about a corner at `at` (plane units) is what its two lines (outward
// normals `one`, `other`) say: the mask MASK_PROBE texels out along the four bisectors of the
// lines, shadow in only the one inside both (convex) or in all but the one outside both (reflex). Not
// where the other edge is an interior fold (the cow's legs against its body) or lies off the
// boundary, or where a spike is too thin for the mask to show: no corner there. Unchecked,
// corners at the cow's legs drew its umbra lit (default's penumbra RMSE 0.169, 0.141 checked,
// 512², edges a footprint radius long).
bool corner_holds(vec2 at, vec2 one, vec2 other, bool convex) {
    vec2 size = vec2(textureSize(mask, 0));
    vec2 to_texels = size / (plateau.window.zw - plateau.window.xy);
    vec2 centre = (at - plateau.window.xy) * to_texels;
    vec2 bisectors[4] = vec2[4](-one - other, one + other, other - one, one - other);
    bool holds = true;
    for (int k = 0; k < 4; k++) {
        vec2 d = bisectors[k] * to_texels;
        bool shadow = caster_at(centre + MASK_PROBE * d / max(length(d), 1e-30)) != 0u;
        // k = 0 inside both, 1 outside both, 2 and 3 inside one.
        holds = holds && shadow == (k == 0 || !convex && k != 1);
    }
    return holds;
}

void main() {
    uint per = SHEETS ? 6u : 9u;
    uint primitive = uint(gl_VertexIndex) / per;
    uint record = SHEETS ? WEDGE_VEC4S * plateau.sheets.x + SHEET_VEC4S * (primitive - plateau.sheets.x)
                         : WEDGE_VEC4S * primitive;
    uint corner = uint(gl_VertexIndex) % per;
    vec4 r0 = sides[record], r1 = sides[record + 1u], r2 = sides[record + 2u], r3 = sides[record + 3u];
    vec2 extent = plateau.window.zw - plateau.window.xy;
    vec2 p;
    out_probes = uvec4(0u);
    out_samples = 1u;
    if (SHEETS) {
        vec2 corners[4] = vec2[4](r0.xy, r0.zw, r1.zw, r1.xy); // a, b, tb, ta
        p = corners[(floatBitsToUint(r2.w) >> (2u * corner)) & 3u];
        vec2 a = r0.xy;
        out_local = p - a;
        out_shape0 = vec4(r0.zw - a, r1.xy - a);
        out_shape1 = vec4(r1.zw - a, (a - plateau.window.xy) / extent);
        out_caster = uint(r2.z);
        vec4 r4 = sides[record + 4u], r5 = sides[record + 5u], r6 = sides[record + 6u];
        uint convex = floatBitsToUint(r2.w) >> 12u;
        out_corner0 = vec4(r3.xy - a, r3.zw);
        out_axes0 = r4;
        out_corner1 = vec4(r5.xy - a, r5.zw);
        out_axes1 = r6;
        out_turns = vec4(r2.xy, float(convex & 1u), float(convex >> 1u & 1u));
        out_angles = vec2(footprint_angle(r4, r2.xy, r3.zw), footprint_angle(r6, r2.xy, r5.zw));
        if (CORNERS) {
            // Zero normals: no corner (corners.glsl's footprint_line).
            out_corner0.zw *= float(corner_holds(r3.xy, r2.xy, r3.zw, out_turns.z > 0.5));
            out_corner1.zw *= float(corner_holds(r5.xy, r2.xy, r5.zw, out_turns.w > 0.5));
        }
        if (CENTRED && PARTIAL == 0u) {
            SheetProbes probed = probes[primitive - plateau.sheets.x];
            out_probes = probed.bits;
            out_samples = probed.samples.x;
            if (probed.samples.y != 0u) {
                p = a; // every corner at one point: nothing rasterised
            }
        }
    } else {
        vec2 apex = r0.xy, lean = r0.zw;
        mat2 axes = mat2(r1.xy, r1.zw);
        float from = r2.x, to = r2.y;
        vec2 u0 = vec2(cos(from), sin(from)), u1 = vec2(cos(to), sin(to));
        float out_by = 1.0 / cos(0.5 * (to - from));
        // apex, rim(from), rim(to); rim(from), far(from), far(to); rim(from), far(to), rim(to).
        vec2 unit[9] = vec2[9](-lean, u0, u1, u0, u0 * out_by, u1 * out_by, u0, u1 * out_by, u1);
        vec2 y = unit[corner] + lean;
        p = apex + axes * y;
        out_local = y;
        out_shape0 = vec4(lean, 0.0, 0.0);
        out_shape1 = vec4(0.0, 0.0, (apex - plateau.window.xy) / extent);
        out_caster = uint(r2.z);
        out_corner0 = vec4(0.0, 0.0, r3.xy);
        out_axes0 = r1;
        out_corner1 = vec4(0.0, 0.0, r3.zw);
        out_axes1 = r1;
        out_turns = vec4(0.0, 0.0, r2.w, r2.w);
        out_angles = vec2(footprint_angle(r1, r3.xy, r3.zw));
        if (CORNERS && !corner_holds(apex, r3.xy, r3.zw, r2.w > 0.5)) {
            out_corner0.zw = vec2(0.0);
        }
    }
    vec2 uv = (p - plateau.window.xy) / extent;
    out_uv = uv;
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
