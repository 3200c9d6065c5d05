#version 460
// Beyond the paper (which found silhouettes on the host, §4): silhouette detection and
// smoothie generation on the GPU, one invocation per edge, appended into a vertex buffer whose
// counts feed two indirect draws. Same construction as src/geometry/smoothie.rs.
#include "interface.glsl"

layout(local_size_x = 64) in;

const uint NO_FACE = 0xffffffffu;
const float MIN_DEPTH = 1e-6;

// Smoothie size from the light's angular radius at the blocker (t = scale · R / b), or fixed.
layout(constant_id = 0) const bool PHYSICAL_SIZE = true;

layout(set = 0, binding = 0) uniform Params { SilhouetteParams params; };
layout(std430, set = 0, binding = 1) readonly buffer Positions { vec4 positions[]; };
layout(std430, set = 0, binding = 2) readonly buffer Triangles { uvec4 triangles[]; };
layout(std430, set = 0, binding = 3) readonly buffer Edges { uvec4 edges[]; }; // v0, v1, face0, face1
layout(std430, set = 0, binding = 4) buffer Stamps { uint stamps[]; };
// Two indirect draws: the outer smoothies', then the inner quads', each kind appended to its own
// half of the vertex buffer, so that the smoothie pass draws each with its own shader
// (smoothie.rs's `Part`).
struct Draw { uint vertex_count; uint instance_count; uint first_vertex; uint first_instance; };
layout(std430, set = 0, binding = 5) buffer Args { Draw draws[2]; };
// x, y, b, sx, sy, fx, fy, nx, ny, near, far, w, channel (src/geometry/smoothie.rs's
// SmoothieVertex)
layout(std430, set = 0, binding = 6) writeonly buffer Vertices { float vertices[]; };
const uint FLOATS = 13u;

vec3 view_position(uint v) {
    return (params.model_view * vec4(positions[v].xyz, 1.0)).xyz;
}

// Facing the light, which sits at the view's origin.
bool lit(uint face) {
    if (face == NO_FACE) {
        return false;
    }
    uvec4 t = triangles[face];
    vec3 a = view_position(t.x), b = view_position(t.y), c = view_position(t.z);
    return dot(cross(b - a, c - a), -(a + b + c) / 3.0) > 0.0;
}

float smoothie_t(float depth) {
    return PHYSICAL_SIZE ? params.size.x / (depth + params.light.x) : params.size.x;
}

// The farthest a receiver can lie behind the hull of q (src/geometry/smoothie.rs's
// ReceiverBound::far_over).
float far_over(vec2 q[4]) {
    float far = params.size.z;
    if (params.ground.w == 0.0) {
        return far;
    }
    float nearest = 3.0e38;
    for (int k = 0; k < 4; k++) {
        nearest = min(nearest, dot(params.ground.xyz, vec3(q[k], 1.0)));
    }
    return nearest > 0.0 ? min(far, 1.001 / nearest) : far;
}

float reach(float depth, float far) {
    return clamp(1.0 - depth / far, 0.0, 1.0);
}

// Inner quads' extra data: each vertex's point on the edge, the edge's outward normal, the
// caster's depth range; zero for the outer smoothies.
struct Inner {
    vec2 foot[4];
    vec2 normal;
    vec2 range;
};

void put(uint at, vec2 p, float b, vec2 shape, vec2 foot, vec2 normal, vec2 range, float w) {
    float v[13] = float[13](p.x, p.y, b, shape.x, shape.y, foot.x, foot.y, normal.x, normal.y, range.x, range.y, w, params.light.y);
    for (uint k = 0u; k < FLOATS; k++) {
        vertices[FLOATS * at + k] = v[k];
    }
}

// Six vertices, two triangles: the quad q0 q1 q2 q3, with projective weights w (1/t on edges,
// as src/geometry/smoothie.rs's SmoothieVertex::w).
void quad(vec2 q[4], float b[4], vec2 s[4], Inner inner, float w[4]) {
    // An inner quad's range is its caster's depths, beyond 0; the outer smoothies' is 0 or −1.
    uint kind = inner.range.y > 0.0 ? 1u : 0u;
    uint at = atomicAdd(draws[kind].vertex_count, 6u);
    if (at + 6u > params.counts.z) {
        return; // sized so that it never happens; never write past the kind's half
    }
    at += kind * params.counts.z;
    const int order[6] = int[6](0, 1, 2, 0, 2, 3);
    for (int k = 0; k < 6; k++) {
        int o = order[k];
        put(at + uint(k), q[o], b[o], s[o], inner.foot[o], inner.normal, inner.range, w[o]);
    }
}

const Inner OUTER = Inner(vec2[4](vec2(0.0), vec2(0.0), vec2(0.0), vec2(0.0)), vec2(0.0), vec2(0.0));

// Two dispatches per caster, as src/geometry/smoothie.rs groups edge ends by vertex: PAIRING
// counts each silhouette vertex's edge ends (stamped, so no clear is needed) and keeps the first
// two; then each vertex's first end draws its corner, a wedge from both ends' sides where
// exactly two meet, else a full square.
layout(constant_id = 1) const bool PAIRING = true;

// A silhouette edge in the light view: its ends, their depths, and where it is not edge-on its
// outward normal (`sided`).
struct Silhouette {
    uvec2 v;
    vec2 t[2];
    float z[2];
    bool sided;
    vec2 along;
    vec2 normal;
};

bool silhouette(uint i, out Silhouette s) {
    uvec4 e = edges[i];
    bool l0 = lit(e.z), l1 = lit(e.w);
    if (l0 == l1) {
        return false;
    }
    uvec4 face = triangles[l0 ? e.z : e.w];
    uint inner = face.x != e.x && face.x != e.y ? face.x : (face.y != e.x && face.y != e.y ? face.y : face.z);
    vec3 pa = view_position(e.x), pb = view_position(e.y), pi = view_position(inner);
    if (pa.z <= MIN_DEPTH || pb.z <= MIN_DEPTH) {
        return false;
    }
    s.v = e.xy;
    s.t = vec2[2](pa.xy / pa.z, pb.xy / pb.z);
    s.z = float[2](pa.z, pb.z);
    vec2 along = s.t[1] - s.t[0];
    s.sided = dot(along, along) != 0.0 && pi.z > MIN_DEPTH;
    s.along = s.sided ? normalize(along) : vec2(0.0);
    vec2 perp = vec2(-s.along.y, s.along.x);
    s.normal = dot(perp, pi.xy / pi.z - s.t[0]) > 0.0 ? -perp : perp;
    return true;
}

// The stamped count word of vertex v: this frame's count in the low two bits (saturating).
uint arrive(uint v) {
    uint stamp = params.counts.y << 2u;
    uint old = stamps[3u * v];
    for (;;) {
        uint n = (old & ~3u) == stamp ? old & 3u : 0u;
        uint seen = atomicCompSwap(stamps[3u * v], old, stamp | min(n + 1u, 3u));
        if (seen == old) {
            return n;
        }
        old = seen;
    }
}

void corner_quad(vec2 p, float z, float t, vec2 o[4], Inner inner) {
    vec2 q[4] = vec2[4](p + o[0] * t, p + o[1] * t, p + o[2] * t, p + o[3] * t);
    quad(q, float[4](z, z, z, z), o, inner, float[4](1.0, 1.0, 1.0, 1.0));
}

// The sector from n0 to n1 about their bisector m, radius kk: two kites, as
// src/geometry/smoothie.rs's wedge.
void wedge(vec2 p, float z, float t, vec2 n0, vec2 n1, vec2 m, float kk, Inner inner) {
    vec2 ns[2] = vec2[2](n0, n1);
    for (int j = 0; j < 2; j++) {
        vec2 tip = (ns[j] + m) / (1.0 + dot(ns[j], m));
        corner_quad(p, z, t, vec2[4](vec2(0.0), ns[j] * kk, tip * kk, m * kk), inner);
    }
}

// The corner at end k of silhouette s, given the vertex's end count and its other end.
void corner(Silhouette s, int k, uint count, uint other) {
    vec2 p = s.t[k];
    float z = s.z[k], t = smoothie_t(z);
    // The square of half-size t holds every kind of corner.
    float kk = reach(z, far_over(vec2[4](p + t, p + vec2(t, -t), p - t, p + vec2(-t, t))));
    Silhouette o;
    if (count == 2u && s.sided && silhouette(other >> 1u, o) && o.sided) {
        vec2 d1 = k == 0 ? s.along : -s.along, n1 = s.normal;
        vec2 d2 = (other & 1u) == 0u ? o.along : -o.along, n2 = o.normal;
        // As src/geometry/smoothie.rs: normals on opposite sides of the path get the square;
        // a convex turn the outer wedge, a concave one (centred) the inner wedge.
        vec2 p1 = vec2(d1.y, -d1.x), p2 = vec2(-d2.y, d2.x);
        bool consistent = dot(p1, n1) * dot(p2, n2) > 0.0;
        vec2 m = n1 + n2;
        if (consistent && dot(m, m) > 0.0) {
            m = normalize(m);
            float turn = dot(n1, d2);
            if (turn < 0.0) {
                wedge(p, z, t, n1, n2, m, kk, OUTER);
            } else if (turn > 0.0 && params.counts.w != 0u) {
                Inner inner = Inner(vec2[4](p, p, p, p), m, params.size.yw);
                wedge(p, z, t, -n1, -n2, -m, kk, inner);
            }
            return;
        }
    }
    corner_quad(p, z, t, vec2[4](vec2(-kk, -kk), vec2(kk, -kk), vec2(kk, kk), vec2(-kk, kk)), OUTER);
}

// The reach's receivers behind the uncut quad from edge ta–tb out by ta's and tb's t.
float far_quad(vec2 ta, vec2 tb, float sa, float sb, vec2 out_dir) {
    return far_over(vec2[4](ta, tb, ta + out_dir * sa, tb + out_dir * sb));
}

// The smoothie edge of the hard edge ta–tb (depths za, zb) out along `out_dir`, alpha 0 on the
// edge and the reach k at t·k out, with projective weights 1/t (src/geometry/smoothie.rs's
// SmoothieVertex::w).
void edge_quad(vec2 ta, vec2 tb, float za, float zb, vec2 out_dir, Inner inner) {
    float sa = smoothie_t(za), sb = smoothie_t(zb);
    float far = far_quad(ta, tb, sa, sb, out_dir);
    float ka = reach(za, far), kb = reach(zb, far);
    vec2 da = out_dir * sa * ka, db = out_dir * sb * kb;
    float wa = sa > 0.0 && !isinf(sa) ? 1.0 / sa : 1.0, wb = sb > 0.0 && !isinf(sb) ? 1.0 / sb : 1.0;
    quad(vec2[4](ta, tb, tb + db, ta + da), float[4](za, zb, zb, za),
         vec2[4](vec2(0.0), vec2(0.0), vec2(kb, 0.0), vec2(ka, 0.0)), inner, float[4](wa, wb, wb, wa));
}

uint third_of(uvec4 t, uvec2 e) {
    return t.x != e.x && t.x != e.y ? t.x : (t.y != e.x && t.y != e.y ? t.y : t.z);
}

// Centred, edge i's smoothie edges as a partial silhouette: a convex edge whose faces face the
// light's centre alike while some point of the light sphere sees one of them turned (src/
// geometry/silhouette.rs's partial_silhouettes), drawn where it reaches past what the turned
// face's far vertex casts (src/geometry/smoothie.rs's partial_smoothies).
void partial_silhouette(uint i) {
    uvec4 e = edges[i];
    float radius = params.light.z;
    if (radius <= 0.0 || e.w == NO_FACE) {
        return;
    }
    uvec4 f[2] = uvec4[2](triangles[e.z], triangles[e.w]);
    uint thirds[2] = uint[2](third_of(f[0], e.xy), third_of(f[1], e.xy));
    // Unit normals out of the mesh (a mirroring transform turns the winding round) and signed
    // distances from the light's centre, which lies `light.x` behind the view's origin.
    float side = determinant(mat3(params.model_view)) < 0.0 ? -1.0 : 1.0;
    vec3 light_at = vec3(0.0, 0.0, -params.light.x);
    vec3 n[2];
    float p[2];
    for (int k = 0; k < 2; k++) {
        vec3 a = view_position(f[k].x);
        vec3 normal = side * cross(view_position(f[k].y) - a, view_position(f[k].z) - a);
        if (dot(normal, normal) == 0.0) {
            return;
        }
        n[k] = normalize(normal);
        p[k] = dot(n[k], light_at - a);
    }
    // Facing the centre alike, across a convex edge (face 1's third vertex behind face 0).
    vec3 a0 = view_position(f[0].x);
    if (p[0] * p[1] <= 0.0 || dot(n[0], view_position(thirds[1]) - a0) >= 0.0) {
        return;
    }
    float c = dot(n[0], n[1]), sin2 = 1.0 - c * c;
    bool line = sin2 > 0.0 && (p[0] * p[0] + p[1] * p[1] - 2.0 * c * p[0] * p[1]) / sin2 < radius * radius;
    vec3 pa = view_position(e.x), pb = view_position(e.y);
    if (pa.z <= MIN_DEPTH || pb.z <= MIN_DEPTH) {
        return;
    }
    vec2 ta = pa.xy / pa.z, tb = pb.xy / pb.z;
    vec2 along = tb - ta;
    if (dot(along, along) == 0.0) {
        return;
    }
    along = normalize(along);
    for (int k = 0; k < 2; k++) {
        int j = 1 - k;
        if (!(line || abs(p[k]) < radius && (p[j] - c * p[k]) * p[j] > 0.0)) {
            continue;
        }
        // Where the centre sees both faces lit, the one that has not turned faces those points;
        // where it sees both unlit, the one that has.
        vec3 pi = view_position(p[0] > 0.0 ? thirds[j] : thirds[k]), pc = view_position(thirds[k]);
        if (pi.z <= MIN_DEPTH || pc.z <= MIN_DEPTH) {
            continue;
        }
        vec2 perp = vec2(-along.y, along.x);
        vec2 normal = dot(perp, pi.xy / pi.z - ta) > 0.0 ? -perp : perp;
        float sa = smoothie_t(pa.z), sb = smoothie_t(pb.z);
        float beyond = dot(normal, pc.xy / pc.z) + smoothie_t(pc.z);
        float gain = max(dot(normal, ta) + sa, dot(normal, tb) + sb) - beyond;
        float far = far_quad(ta, tb, sa, sb, normal);
        if (gain <= params.light.w * max(sa * reach(pa.z, far), sb * reach(pb.z, far))) {
            continue;
        }
        float behind = max(max(pa.z, pb.z), pc.z);
        edge_quad(ta, tb, pa.z, pb.z, normal, Inner(vec2[4](vec2(0.0), vec2(0.0), vec2(0.0), vec2(0.0)), vec2(0.0), vec2(behind, -1.0)));
    }
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= params.counts.x) {
        return;
    }
    Silhouette s;
    if (!silhouette(i, s)) {
        if (!PAIRING) {
            partial_silhouette(i);
        }
        return;
    }
    if (PAIRING) {
        for (uint k = 0u; k < 2u; k++) {
            uint n = arrive(s.v[k]);
            if (n < 2u) {
                stamps[3u * s.v[k] + 1u + n] = 2u * i + k;
            }
        }
        return;
    }
    for (int k = 0; k < 2; k++) {
        uint v = s.v[k];
        if (stamps[3u * v + 1u] == 2u * i + uint(k)) {
            corner(s, k, stamps[3u * v] & 3u, stamps[3u * v + 2u]);
        }
    }
    if (!s.sided) {
        return;
    }
    vec2 ta = s.t[0], tb = s.t[1];
    edge_quad(ta, tb, s.z[0], s.z[1], s.normal, OUTER);
    if (params.counts.w != 0u) {
        // The inner quad, mirrored over the blocker (issue 20).
        edge_quad(ta, tb, s.z[0], s.z[1], -s.normal, Inner(vec2[4](ta, tb, tb, ta), s.normal, params.size.yw));
    }
}
