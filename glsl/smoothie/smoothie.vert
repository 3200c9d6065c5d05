#version 460
// Smoothie edges, corners and inner quads, generated on the CPU or by silhouettes.comp in the
// light view's tangent plane.
#include "interface.glsl"
#include "depth.glsl"
#include "corners.glsl"

layout(set = 0, binding = 0) uniform Light { LightView light; };

layout(location = 0) in vec3 in_tangent_depth; // x/z, y/z, blocker depth b
layout(location = 1) in vec2 in_shape;         // |shape| = linear alpha
layout(location = 2) in vec2 in_foot;          // inner quads: the edge's point, tangent coordinates
layout(location = 3) in vec2 in_normal;        // inner quads: the edge's outward normal
layout(location = 4) in vec2 in_range;         // inner quads: the caster's depth range; 0: outer
layout(location = 5) in float in_w;            // projective weight 1/t: edges' alpha exact (SmoothieVertex::w)
layout(location = 6) in float in_channel;      // centred: the caster's channel, 0 or 1
// Centred, near a corner of the hard shadow (SmoothieVertex::turn): its vertex, both edges'
// outward normals, and its turn (1 convex, −1 reflex; 0 none).
layout(location = 7) in vec2 in_corner;
layout(location = 8) in vec4 in_normals;
layout(location = 9) in float in_turn;
// Pieces of a cut quad (SmoothieVertex::along): how far along the edge, and the part they keep.
layout(location = 10) in float in_along;
layout(location = 11) in vec2 in_keep;
// A turn split by a short edge (ShadowCorner::chamfer): its line's outward normal and offset.
layout(location = 12) in vec3 in_chamfer;

// Linear in the buffer but the alpha (`shape`), which w makes distance over size. The blocker
// depth goes as 1/b, which is affine along a straight edge's image in the light's tangent plane
// (a perspective from its centre) where b is not: b, linear there, lay behind the edge between
// its vertices, nearer the receiver, and narrowed a sloping edge's penumbra (a thin slab leaning
// on the ground: 0.83–0.88 of the reference's width along its middle, 512²).
layout(location = 0) noperspective out float out_inverse_b;
layout(location = 1) out vec2 out_shape;
layout(location = 2) noperspective out vec2 out_probe;
layout(location = 3) flat out vec2 out_range;
layout(location = 4) flat out float out_channel;
layout(location = 5) flat out vec2 out_corner;
layout(location = 6) flat out vec4 out_normals;
layout(location = 7) flat out float out_turn;
// The smoothie size t, affine across a quad as its alpha's distance is (SmoothieVertex::w).
layout(location = 8) noperspective out float out_size;
layout(location = 9) noperspective out float out_along;
layout(location = 10) flat out vec2 out_keep;
layout(location = 11) flat out vec3 out_chamfer;
// The angles between the corner's lines' normals (corners.glsl's corner_angle), the same for
// every fragment: the long edges', the first's to the cut's, the cut's to the second's.
layout(location = 12) flat out vec3 out_angles;

void main() {
    vec2 uv = tangent_uv(light, in_tangent_depth.xy);
    out_inverse_b = 1.0 / in_tangent_depth.z;
    out_shape = in_shape;
    out_probe = tangent_uv(light, in_foot + in_normal * probe_step(light));
    out_range = in_range;
    out_channel = in_channel;
    out_corner = in_corner;
    out_normals = in_normals;
    out_turn = in_turn;
    out_size = 1.0 / in_w;
    out_along = in_along;
    out_keep = in_keep;
    out_chamfer = in_chamfer;
    vec2 n1 = in_normals.xy, n2 = in_normals.zw, m = in_chamfer.xy;
    out_angles = vec3(corner_angle(n1, n2), corner_angle(n1, m), corner_angle(m, n2));
    gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0) * in_w;
}
