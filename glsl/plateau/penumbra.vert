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
#include "probes.glsl"

// As penumbra.frag's.
layout(constant_id = 0) const bool CENTRED = false;
// Sheets (6 vertices a primitive) or wedges (9).
layout(constant_id = 2) const bool SHEETS = false;
layout(constant_id = 3) const bool PARTIAL = false;

layout(set = 0, binding = 0) uniform Plateau { PlateauView plateau; };
// Wedges: apex, lean | axes (columns) | from, to, caster, -. Sheets: a, b | ta, tb | normal,
// caster, hull (bits). Wedges first, then sheets: gl_VertexIndex counts from the first.
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
// The hard edge's direction b − a in texture coordinates (wedges: 0).
layout(location = 4) flat out vec2 out_edge;
layout(location = 5) flat out vec2 out_normal;
layout(location = 6) flat out uint out_caster;
// Centred sheets: their mask probes along the hard edge (probes.comp), for the fragments.
layout(location = 7) flat out uvec4 out_probes;
layout(location = 8) flat out uint out_samples;

void main() {
    uint per = SHEETS ? 6u : 9u;
    uint record = 3u * (uint(gl_VertexIndex) / per);
    uint corner = uint(gl_VertexIndex) % per;
    vec4 r0 = sides[record], r1 = sides[record + 1u], r2 = sides[record + 2u];
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
        out_edge = (r0.zw - a) / extent;
        out_normal = r2.xy / extent;
        out_caster = uint(r2.z);
        if (CENTRED && !PARTIAL) {
            SheetProbes probed = probes[uint(gl_VertexIndex) / per - plateau.sheets.x];
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
        out_edge = vec2(0.0);
        out_normal = vec2(0.0);
        out_caster = uint(r2.z);
    }
    vec2 uv = (p - plateau.window.xy) / extent;
    out_uv = uv;
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
