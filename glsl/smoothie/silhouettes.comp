#version 460
// Beyond the paper (which found silhouettes on the host, §4): silhouette detection and
// smoothie generation on the GPU, one invocation per edge, appended into a vertex buffer whose
// counts feed four indirect draws. Same construction as src/geometry/smoothie.rs.
#extension GL_EXT_control_flow_attributes : require
#include "interface.glsl"

layout(local_size_x = COMPUTE_GROUP) in;

// NO_FACE, MIN_DEPTH and the construction's other constants are src/shader_constants.rs's.

// Smoothie size from the light's angular radius at the blocker (t = scale · R / b), or fixed.
layout(constant_id = 0) const bool PHYSICAL_SIZE = true;

// A storage buffer, not a uniform one: lavapipe inlines the uniforms a branch or a loop's end
// depends on alone, compiling the shader again for each new value, and here some move with the
// caster (a recompile every frame, 5 s each: tests/shader_variants.rs).
layout(std430, set = 0, binding = 0) readonly buffer Params { SilhouetteParams params; };
layout(std430, set = 0, binding = 1) readonly buffer Positions { vec4 positions[]; };
layout(std430, set = 0, binding = 2) readonly buffer Triangles { uvec4 triangles[]; };
layout(std430, set = 0, binding = 3) readonly buffer Edges { uvec4 edges[]; }; // v0, v1, face0, face1
layout(std430, set = 0, binding = 4) buffer Stamps { uint stamps[]; };
// Five indirect draws, one per part of the smoothie pass (smoothie.rs's `Part::INDIRECT`): the outer
// smoothies away from the hard shadow's corners and near them, the inner quads alike, then the
// partial silhouettes' inner quads. Each kind takes a third of the vertex buffer, those away from
// corners appended from its start, those near them from its end back, so that the smoothie pass
// draws each part with its own shader.
struct Draw { uint vertex_count; uint instance_count; uint first_vertex; uint first_instance; };
layout(std430, set = 0, binding = 5) buffer Args { Draw draws[5]; };
// x, y, b, sx, sy, fx, fy, nx, ny, near, far, w, channel, cx, cy, normals, turn, along, keep, chamfer
// (src/geometry/smoothie.rs's SmoothieVertex, SMOOTHIE_VERTEX_FLOATS of them)
layout(std430, set = 0, binding = 6) writeonly buffer Vertices { float vertices[]; };

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

// The projective weight of a smoothie of size t (src/geometry/smoothie.rs's weighted).
float weight(float t) {
    return t > 0.0 && !isinf(t) ? 1.0 / t : 1.0;
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

// What a smoothie vertex interpolates: its point, depth, shape, foot (inner quads' point on
// the edge), projective weight, and how far along its edge (pieces of a cut quad).
struct Vertex {
    vec2 p;
    float b;
    vec2 shape;
    vec2 foot;
    float w;
    float along;
};

// Inner quads' extra data: the edge's outward normal (or a wedge's bisector) and the caster's
// depth range; zero for the outer smoothies. `partial`: a partial silhouette's inner quad, which
// has neither normal nor corner (its own data goes where a corner's would: partial_silhouette).
struct Inner {
    vec2 normal;
    vec2 range;
    bool partial;
};

const Inner OUTER = Inner(vec2(0.0), vec2(0.0), false);

// The hard shadow's corner a smoothie carries (src/geometry/smoothie.rs's ShadowCorner): its
// vertex, both edges' outward normals, and its turn, 1 convex, -1 reflex; 0: none; and where a
// short edge splits the turn, that edge's outward normal and how far `at` lies outside its line
// (zero elsewhere).
struct Corner {
    vec2 at;
    vec4 normals;
    float turn;
    vec3 chamfer;
};

const Corner NO_CORNER = Corner(vec2(0.0), vec4(0.0), 0.0, vec3(0.0));

void put(uint at, Vertex v, Inner inner, Corner c, vec2 keep) {
    float f[26] = float[26](v.p.x, v.p.y, v.b, v.shape.x, v.shape.y, v.foot.x, v.foot.y, inner.normal.x,
                            inner.normal.y, inner.range.x, inner.range.y, v.w, params.light.y, c.at.x, c.at.y,
                            c.normals.x, c.normals.y, c.normals.z, c.normals.w, c.turn, v.along, keep.x, keep.y,
                            c.chamfer.x, c.chamfer.y, c.chamfer.z);
    for (uint k = 0u; k < SMOOTHIE_VERTEX_FLOATS; k++) {
        vertices[SMOOTHIE_VERTEX_FLOATS * at + k] = f[k];
    }
}

// Where `count` vertices of this kind go (an inner quad's range is its caster's depths, beyond
// 0; the outer smoothies' is 0 or −1; a partial silhouette's inner quad has no corner), near a
// corner or not; false where the kind's third of the buffer is full (sized so that it never is).
bool append(Inner inner, Corner c, uint count, out uint at) {
    uint kind = inner.partial ? 2u : (inner.range.y > 0.0 ? 1u : 0u);
    if (c.turn == 0.0) {
        at = atomicAdd(draws[2u * kind].vertex_count, count);
        if (at + count > params.counts.z) {
            return false;
        }
        at += kind * params.counts.z;
        return true;
    }
    atomicAdd(draws[2u * kind + 1u].vertex_count, count);
    at = atomicAdd(draws[2u * kind + 1u].first_vertex, -count) - count;
    return at >= kind * params.counts.z && at <= (kind + 1u) * params.counts.z; // from the half's end back
}

// The quad q0 q1 q2 q3 as two triangles, keeping `keep` of its edge. Its vertices are written
// in a loop kept rolled, and its callers call it from as few places as they can: each call is
// inlined, and llvmpipe's first compile grows with every store inlined (six vertices' stores at
// each of 26 call sites took it to 50 s, against 4.5 s now).
void quad(Vertex q[4], Inner inner, Corner c, vec2 keep) {
    uint at;
    if (append(inner, c, 6u, at)) {
        const int order[6] = int[6](0, 1, 2, 0, 2, 3);
        [[dont_unroll]] for (uint k = 0u; k < 6u; k++) {
            put(at + k, q[order[k]], inner, c, keep);
        }
    }
}

// a + (b − a)·u, as src/geometry/smoothie.rs's between takes it.
float lerp(float a, float b, float u) {
    return a + (b - a) * u;
}

vec2 lerp(vec2 a, vec2 b, float u) {
    return a + (b - a) * u;
}

// The vertex u of the way from a to b, two vertices of one quad's side, as the rasterizer
// interpolates there (src/geometry/smoothie.rs's between).
Vertex between(Vertex a, Vertex b, float u) {
    float ta = 1.0 / a.w, tb = 1.0 / b.w, t = lerp(ta, tb, u);
    float depth = a.b * b.b / lerp(b.b, a.b, u); // 1/b linear, in one division
    return Vertex(lerp(a.p, b.p, u), depth, lerp(a.shape * ta, b.shape * tb, u) / t, lerp(a.foot, b.foot, u), 1.0 / t,
                  lerp(a.along, b.along, u));
}

// How far along its edges a corner's pieces carry it, in quad widths
// (src/geometry/smoothie.rs's ShadowCorner::piece).
float longest_piece() {
    float sharpest = params.corners.z;
    return params.corners.w * (1.0 - sharpest) / sqrt(1.0 - sharpest * sharpest);
}

float piece(Corner c) {
    vec2 n1 = c.normals.xy, n2 = c.normals.zw;
    return min(params.corners.w * (1.0 + abs(dot(n1, n2))) / abs(n1.x * n2.y - n1.y * n2.x), longest_piece());
}

// Where an edge's outer and inner quads are cut for the corners at its ends, alike
// (src/geometry/smoothie.rs's corner_cuts).
vec2 corner_cuts(Vertex outer[4], Vertex inner[4], Corner corners[2]) {
    float length = distance(outer[0].p, outer[1].p);
    float wa = max(distance(outer[0].p, outer[3].p), distance(inner[0].p, inner[3].p));
    float wb = max(distance(outer[1].p, outer[2].p), distance(inner[1].p, inner[2].p));
    bool a = corners[0].turn != 0.0, b = corners[1].turn != 0.0;
    // From the corner's vertex, which a turn split by a short edge puts off the edge's end.
    float ua = a ? (piece(corners[0]) * wa + distance(corners[0].at, outer[0].p)) / length : 0.0;
    float ub = b ? (piece(corners[1]) * wb + distance(corners[1].at, outer[1].p)) / length : 0.0;
    if (ua + ub < 1.0) {
        return vec2(ua, ub);
    }
    return a && b ? vec2(0.5) : vec2(a ? 1.0 : 0.0, b ? 1.0 : 0.0);
}

// An edge's quad q (its base from end a to end b, then its rim back) in pieces cut at `cuts`,
// those within reach of a corner at either end carrying it, each keeping its own part and
// reaching a texel past KEEP_SLACK (src/geometry/smoothie.rs's edge_quad).
void edge_pieces(Vertex q[4], Inner inner, Corner corners[2], vec2 cuts) {
    if (corners[0].turn == 0.0 && corners[1].turn == 0.0) {
        quad(q, inner, NO_CORNER, KEEP_ALL);
        return;
    }
    float texel = params.cuts.x, sliver = params.cuts.y;
    float margin = KEEP_SLACK + texel / distance(q[0].p, q[1].p);
    // With each piece, a sliver over the whole hard edge, `sliver` wide (at most SLIVER of the
    // quad's width).
    float sb = min(sliver / max(distance(q[1].p, q[2].p), 1e-30), SLIVER);
    float sa = min(sliver / max(distance(q[0].p, q[3].p), 1e-30), SLIVER);
    Vertex over_base[4] = Vertex[4](q[0], q[1], between(q[1], q[2], sb), between(q[0], q[3], sa));
    float u[4] = float[4](0.0, cuts.x, 1.0 - cuts.y, 1.0);
    for (int j = 0; j < 3; j++) {
        if (u[j] < u[j + 1]) {
            vec2 keep = vec2(u[j] > 0.0 ? u[j] - KEEP_SLACK : KEEP_ALL.x, u[j + 1] < 1.0 ? u[j + 1] + KEEP_SLACK : KEEP_ALL.y);
            float g0 = max(u[j] - margin, 0.0), g1 = min(u[j + 1] + margin, 1.0);
            Vertex piece[4] = Vertex[4](between(q[0], q[1], g0), between(q[0], q[1], g1), between(q[3], q[2], g1),
                                        between(q[3], q[2], g0));
            Corner c = j == 0 ? corners[0] : (j == 2 ? corners[1] : NO_CORNER);
            quad(piece, inner, c, keep);
            quad(over_base, inner, c, keep);
        }
    }
}

// Three dispatches per caster, as src/geometry/smoothie.rs groups edge ends by vertex and finds
// each vertex's own corner once: STAGE_PAIR counts each silhouette vertex's edge ends (stamped,
// so no clear is needed) and keeps the first two; STAGE_OWN has each vertex's first end find the
// hard shadow's corner there (centred); then STAGE_DRAW, where each vertex's first end draws its
// corner, a wedge from both ends' sides where exactly two meet, else a full square, and each edge
// its quads, carrying the corners near its ends. Found in STAGE_DRAW, each vertex's own corner
// would be found again by every search that passed it, each time walking its runs (as the CPU path,
// which keeps them per vertex, does not).
layout(constant_id = 1) const uint STAGE = STAGE_PAIR;

// Per vertex in `stamps`, STAMP_WORDS: the stamped count word, the first two edge ends
// (STAGE_PAIR), and the own corner's at, normals, turn and chamfer as float bits (STAGE_OWN),
// CORNER_WORDS of them.
void store_corner(uint v, Corner c) {
    float f[CORNER_WORDS] = float[CORNER_WORDS](c.at.x, c.at.y, c.normals.x, c.normals.y, c.normals.z, c.normals.w,
                                                c.turn, c.chamfer.x, c.chamfer.y, c.chamfer.z);
    for (uint k = 0u; k < CORNER_WORDS; k++) {
        stamps[STAMP_WORDS * v + 3u + k] = floatBitsToUint(f[k]);
    }
}

Corner own_corner(uint v) {
    float f[CORNER_WORDS];
    for (uint k = 0u; k < CORNER_WORDS; k++) {
        f[k] = uintBitsToFloat(stamps[STAMP_WORDS * v + 3u + k]);
    }
    return Corner(vec2(f[0], f[1]), vec4(f[2], f[3], f[4], f[5]), f[6], vec3(f[7], f[8], f[9]));
}

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
    uint old = stamps[STAMP_WORDS * v];
    for (;;) {
        uint n = (old & ~3u) == stamp ? old & 3u : 0u;
        uint seen = atomicCompSwap(stamps[STAMP_WORDS * v], old, stamp | min(n + 1u, 3u));
        if (seen == old) {
            return n;
        }
        old = seen;
    }
}

// A corner's quad: the offsets o (shape units) from p, scaled by its size t.
void corner_quad(vec2 p, float z, float t, vec2 o[4], Inner inner, Corner c) {
    Vertex q[4];
    for (int k = 0; k < 4; k++) {
        q[k] = Vertex(p + o[k] * t, z, o[k], inner.range.y > 0.0 ? p : vec2(0.0), weight(t), 0.0);
    }
    quad(q, inner, c, KEEP_ALL);
}

// The sector from n0 to n1 about their bisector m, radius kk: two kites, as
// src/geometry/smoothie.rs's wedge.
void wedge(vec2 p, float z, float t, vec2 n0, vec2 n1, vec2 m, float kk, Inner inner, Corner c) {
    vec2 ns[2] = vec2[2](n0, n1);
    for (int j = 0; j < 2; j++) {
        vec2 tip = (ns[j] + m) / (1.0 + dot(ns[j], m));
        corner_quad(p, z, t, vec2[4](vec2(0.0), ns[j] * kk, tip * kk, m * kk), inner, c);
    }
}

// A corner's size t at p (depth z) and its reach kk over the square of half-size t about it
// (src/geometry/smoothie.rs's corner_size).
void corner_size(vec2 p, float z, out float t, out float kk) {
    t = smoothie_t(z);
    kk = reach(z, far_over(vec2[4](p + t, p + vec2(t, -t), p - t, p + vec2(-t, t))));
}

// How the outline turns at end k of silhouette s, where the pairing found `count` ends at its
// vertex and `other` beside it (src/geometry/smoothie.rs's Turn): false unless exactly two
// sided ends meet with their normals on the same side of the path.
bool turn_at(Silhouette s, int k, uint count, uint other, out vec2 n1, out vec2 n2, out vec2 m, out float bend) {
    Silhouette o;
    if (count != 2u || !s.sided || !silhouette(other >> 1u, o) || !o.sided) {
        return false;
    }
    vec2 d1 = k == 0 ? s.along : -s.along, d2 = (other & 1u) == 0u ? o.along : -o.along;
    n1 = s.normal;
    n2 = o.normal;
    vec2 p1 = vec2(d1.y, -d1.x), p2 = vec2(-d2.y, d2.x);
    m = n1 + n2;
    if (dot(p1, n1) * dot(p2, n2) <= 0.0 || dot(m, m) == 0.0) {
        return false;
    }
    m = normalize(m);
    bend = dot(n1, d2);
    return true;
}

// The vertex's other end beside end k of edge i.
uint other_end(uint i, int k, uint v) {
    uint first = stamps[STAMP_WORDS * v + 1u];
    return first == 2u * i + uint(k) ? stamps[STAMP_WORDS * v + 2u] : first;
}

// No end: where the outline stops at a vertex without exactly two ends.
const uint NO_END = 0xffffffffu;

// One step of the outline from the end `code` (2 · edge + end) leaving its vertex: the vertex it
// arrives at, its point, and the end leaving that onward, NO_END where it has not exactly two
// (src/geometry/smoothie.rs's Outline::walk).
void walk(inout uint code, out uint vertex, out vec2 p) {
    uint e = code >> 1u, k = code & 1u;
    vertex = k == 0u ? edges[e].y : edges[e].x;
    vec3 q = view_position(vertex);
    p = q.xy / q.z;
    code = (stamps[STAMP_WORDS * vertex] & 3u) == 2u ? other_end(e, int(1u - k), vertex) : NO_END;
}

// The outline from p0 along the end `code` to the first vertex at least `length` away: its
// chord, and how far its edges turn from it (the largest sine; 1 where one runs back); false
// where the walk ends first (src/geometry/smoothie.rs's Outline::run). It walks twice, as the
// chord is known only at the walk's end: the CPU path keeps the points it passed instead, which
// here would hold MAX_WALK + 1 of them in every invocation (local memory on a GPU).
bool run(uint code, vec2 p0, float length, out vec2 chord, out float stray) {
    uint c = code, vertex;
    vec2 p;
    int steps = -1;
    [[dont_unroll]] for (int n = 0; n < MAX_WALK && c != NO_END; n++) {
        walk(c, vertex, p);
        if (distance(p, p0) >= length) {
            steps = n;
            break;
        }
    }
    if (steps < 0) {
        return false;
    }
    chord = (p - p0) / distance(p, p0);
    stray = 0.0;
    c = code;
    vec2 from = p0;
    [[dont_unroll]] for (int n = 0; n <= steps; n++) {
        walk(c, vertex, p);
        vec2 d = (p - from) / distance(p, from);
        stray = max(stray, dot(chord, d) > 0.0 ? abs(chord.x * d.y - chord.y * d.x) : 1.0);
        from = p;
    }
    return true;
}

// A run's outward normal: its chord's, on the side of its first edge's normal (Run::normal).
vec2 run_normal(vec2 chord, vec2 normal) {
    vec2 n = vec2(-chord.y, chord.x);
    return dot(n, normal) < 0.0 ? -n : n;
}

// The corner of the runs with outward normals n1 and n2 and strays `strays`, `at` their meeting
// point, where they turn as a corner may, `bend` says which way, and both runs are straight
// enough for it (Run::straight).
Corner lines_corner(vec2 n1, vec2 n2, vec2 strays, vec2 at, float bend) {
    float angle = acos(clamp(dot(n1, n2), -1.0, 1.0));
    bool turns = abs(n1.x * n2.y - n1.y * n2.x) > params.corners.x && dot(n1, n2) >= params.corners.z && bend != 0.0;
    bool straight = max(strays.x, strays.y) <= RUN_STRAY * angle;
    return turns && straight ? Corner(at, vec4(n1, n2), bend < 0.0 ? 1.0 : -1.0, vec3(0.0)) : NO_CORNER;
}

// Centred, the hard shadow's own corner at end k of edge i, silhouette s
// (src/geometry/smoothie.rs's shadow_corner): where the outline runs straight far enough along
// both edges, at the vertex; where one edge is shorter than a footprint radius and the outline
// turns on the same way at its far end into a straight run, where the runs' lines meet.
Corner shadow_corner(Silhouette s, uint i, int k) {
    uint v = s.v[k];
    uint other = other_end(i, k, v);
    vec2 n1, n2, m;
    float bend;
    if (params.counts.w == 0u || !turn_at(s, k, stamps[STAMP_WORDS * v] & 3u, other, n1, n2, m, bend)) {
        return NO_CORNER;
    }
    float t, kk;
    corner_size(s.t[k], s.z[k], t, kk);
    float radius = params.corners.y * t * kk;
    vec2 p = s.t[k];
    vec2 own_chord, other_chord;
    float own_stray, other_stray;
    bool own_run = run(2u * i + uint(k), p, radius, own_chord, own_stray);
    bool other_run = run(other, p, radius, other_chord, other_stray);
    if (own_run && other_run) {
        Corner at_vertex = lines_corner(run_normal(own_chord, n1), run_normal(other_chord, n2),
                                        vec2(own_stray, other_stray), p, bend);
        if (at_vertex.turn != 0.0) {
            return at_vertex;
        }
    }
    // Else one edge short, the other's run straight: a turn split in two? The short edge (this
    // one, or the other at this vertex), its end here, and the long run.
    Silhouette o;
    if (!silhouette(other >> 1u, o)) {
        return NO_CORNER;
    }
    bool own_short = distance(s.t[0], s.t[1]) < t * kk, other_short = distance(o.t[0], o.t[1]) < t * kk;
    if (own_short == other_short || !(own_short ? other_run : own_run)) {
        return NO_CORNER;
    }
    Silhouette short_edge = own_short ? s : o;
    uint short_index = own_short ? i : other >> 1u;
    int short_end = own_short ? k : int(other & 1u);
    vec2 normal = own_short ? run_normal(other_chord, n2) : run_normal(own_chord, n1);
    float long_stray = own_short ? other_stray : own_stray;
    int far_end = 1 - short_end;
    uint far = short_edge.v[far_end];
    uint next = other_end(short_index, far_end, far);
    vec2 f1, next_normal, fm;
    float far_bend;
    vec2 next_chord;
    float next_stray;
    vec2 q = short_edge.t[far_end];
    if (!turn_at(short_edge, far_end, stamps[STAMP_WORDS * far] & 3u, next, f1, next_normal, fm, far_bend) ||
        far_bend * bend <= 0.0 || !run(next, q, radius, next_chord, next_stray)) {
        return NO_CORNER;
    }
    next_normal = run_normal(next_chord, next_normal);
    // Where the two runs' lines meet (n·x = n·p for each), within a footprint radius of both
    // vertices.
    mat2 lines = transpose(mat2(normal, next_normal));
    vec2 at = inverse(lines) * vec2(dot(normal, p), dot(next_normal, q));
    if (!(distance(at, p) <= t * kk && distance(at, q) <= t * kk)) {
        return NO_CORNER;
    }
    Corner c = lines_corner(normal, next_normal, vec2(long_stray, next_stray), at, bend);
    // The short edge's line, through both vertices: its outward normal.
    if (c.turn != 0.0) {
        vec2 cut = own_short ? n1 : n2;
        c.chamfer = vec3(cut, dot(cut, at - p));
    }
    return c;
}

// Whether p lies on one of c's lines, as straight a run into it would have to be
// (src/geometry/smoothie.rs's ShadowCorner::holds).
bool holds(Corner c, vec2 p) {
    vec2 n1 = c.normals.xy, n2 = c.normals.zw;
    float slack = RUN_STRAY * acos(clamp(dot(n1, n2), -1.0, 1.0)) * distance(p, c.at);
    return abs(dot(n1, p - c.at)) <= slack || abs(dot(n2, p - c.at)) <= slack;
}

// The corner end k of edge i carries (src/geometry/smoothie.rs's corner_near): its vertex's
// own (OWN's), else the nearest the outline passes on either side whose pieces reach the vertex
// with a footprint radius to spare and on whose lines it lies, ties to the lower vertex.
Corner carried_corner(Silhouette s, uint i, int k) {
    uint v = s.v[k];
    Corner own = own_corner(v);
    if (own.turn != 0.0 || (stamps[STAMP_WORDS * v] & 3u) != 2u) {
        return own;
    }
    vec2 p = s.t[k];
    float t, kk;
    corner_size(p, s.z[k], t, kk);
    float farthest = (longest_piece() + 1.0) * t * kk;
    uint codes[2] = uint[2](2u * i + uint(k), other_end(i, k, v));
    Corner best = NO_CORNER;
    float best_distance = 3.0e38;
    uint best_vertex = 0xffffffffu;
    [[dont_unroll]] for (int side = 0; side < 2; side++) {
        uint code = codes[side], candidate;
        vec2 q;
        [[dont_unroll]] for (int n = 0; n < MAX_WALK && code != NO_END; n++) {
            walk(code, candidate, q);
            if (distance(q, p) > farthest) {
                break;
            }
            Corner c = own_corner(candidate);
            if (c.turn != 0.0) {
                float d = distance(c.at, p);
                bool nearer = d < best_distance || (d == best_distance && candidate < best_vertex);
                if (d <= (piece(c) + 1.0) * t * kk && holds(c, p) && nearer) {
                    best = c;
                    best_distance = d;
                    best_vertex = candidate;
                }
                break;
            }
        }
    }
    return best;
}

// The corner at end k of silhouette s (edge i), given the vertex's end count, its other end and
// the hard shadow's corner there, `c` (shadow_corner).
void corner(Silhouette s, int k, uint count, uint other, Corner c) {
    vec2 p = s.t[k];
    float z = s.z[k], t, kk;
    corner_size(p, z, t, kk);
    vec2 n1, n2, m;
    float bend;
    if (turn_at(s, k, count, other, n1, n2, m, bend)) {
        // As src/geometry/smoothie.rs: a convex turn the outer wedge, a concave one (centred)
        // the inner wedge.
        if (bend < 0.0) {
            wedge(p, z, t, n1, n2, m, kk, OUTER, c);
        } else if (bend > 0.0 && params.counts.w != 0u) {
            wedge(p, z, t, -n1, -n2, -m, kk, Inner(m, params.size.yw, false), c);
        }
        return;
    }
    corner_quad(p, z, t, vec2[4](vec2(-kk, -kk), vec2(kk, -kk), vec2(kk, kk), vec2(-kk, kk)), OUTER, NO_CORNER);
}

// The reach's receivers behind the uncut quad from edge ta–tb out by ta's and tb's t.
float far_quad(vec2 ta, vec2 tb, float sa, float sb, vec2 out_dir) {
    return far_over(vec2[4](ta, tb, ta + out_dir * sa, tb + out_dir * sb));
}

// The smoothie edge of the hard edge ta–tb (depths za, zb) out along `out_dir`, alpha 0 on the
// edge and the reach k at t·k out, with projective weights 1/t (src/geometry/smoothie.rs's
// SmoothieVertex::w); an inner quad's feet on the edge.
void edge_quad(vec2 ta, vec2 tb, float za, float zb, vec2 out_dir, bool feet, out Vertex q[4]) {
    float sa = smoothie_t(za), sb = smoothie_t(zb);
    float far = far_quad(ta, tb, sa, sb, out_dir);
    float ka = reach(za, far), kb = reach(zb, far);
    vec2 da = out_dir * sa * ka, db = out_dir * sb * kb;
    float wa = weight(sa), wb = weight(sb);
    vec2 fa = feet ? ta : vec2(0.0), fb = feet ? tb : vec2(0.0);
    q = Vertex[4](Vertex(ta, za, vec2(0.0), fa, wa, 0.0), Vertex(tb, zb, vec2(0.0), fb, wb, 1.0),
                  Vertex(tb + db, zb, vec2(kb, 0.0), fb, wb, 1.0), Vertex(ta + da, za, vec2(ka, 0.0), fa, wa, 0.0));
}

uint third_of(uvec4 t, uvec2 e) {
    return t.x != e.x && t.x != e.y ? t.x : (t.y != e.x && t.y != e.y ? t.y : t.z);
}

// Centred, edge i's smoothie edges as a partial silhouette: a convex edge whose faces face the
// light's centre alike while some point of the light sphere sees one of them turned (src/
// geometry/silhouette.rs's partial_silhouettes), drawn where it gains on what the turned face's
// far vertex casts: an outer smoothie reaching further out where the centre sees both faces
// lit, an inner quad whose umbra begins further out where it sees both unlit (src/geometry/
// smoothie.rs's partial_smoothies).
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
    [[dont_unroll]] for (int k = 0; k < 2; k++) {
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
        // Away from that face: outward from an edge the centre sees lit, inward from one it
        // sees unlit.
        vec2 perp = vec2(-along.y, along.x);
        vec2 normal = dot(perp, pi.xy / pi.z - ta) > 0.0 ? -perp : perp;
        float sa = smoothie_t(pa.z), sb = smoothie_t(pb.z), sc = smoothie_t(pc.z);
        float far = far_quad(ta, tb, sa, sb, normal);
        float ka = reach(pa.z, far), kb = reach(pb.z, far);
        float needed = params.light.w * max(sa * ka, sb * kb);
        vec2 tc = pc.xy / pc.z;
        Vertex q[4];
        edge_quad(ta, tb, pa.z, pb.z, normal, false, q);
        // One quad() for both kinds, in a loop kept rolled (see primitive).
        Inner inner;
        Corner corner = NO_CORNER;
        if (p[0] > 0.0) {
            // How far out its smoothie reaches, against the turned vertex's.
            float gain = max(dot(normal, ta) + sa, dot(normal, tb) + sb) - (dot(normal, tc) + sc);
            if (gain <= needed) {
                continue;
            }
            inner = Inner(vec2(0.0), vec2(max(max(pa.z, pb.z), pc.z), -1.0), false);
        } else {
            // Where the umbra begins along the inward normal, against the turned vertex's (the
            // silhouette's umbra), on an edge that spans the light's footprint; the quad carries
            // the silhouette's depth there, and the inward normal, where a corner's vertex and
            // normals go.
            float hold = dot(normal, tc) + sc * reach(pc.z, far);
            bool spans = distance(ta, tb) >= 2.0 * max(sa * ka, sb * kb);
            if (!spans || hold - max(dot(normal, ta) + sa * ka, dot(normal, tb) + sb * kb) <= needed) {
                continue;
            }
            // Past its own umbra's start it still hides the whole light, as far as the
            // silhouette's inner half reaches: the quad reaches there, its alpha past 1.
            float da = clamp(hold - dot(normal, ta), sa * ka, MAX_INNER_REACH * sa * ka);
            float db = clamp(hold - dot(normal, tb), sb * kb, MAX_INNER_REACH * sb * kb);
            q[2] = Vertex(tb + normal * db, pb.z, vec2(sb > 0.0 ? db / sb : 0.0, 0.0), vec2(0.0), weight(sb), 1.0);
            q[3] = Vertex(ta + normal * da, pa.z, vec2(sa > 0.0 ? da / sa : 0.0, 0.0), vec2(0.0), weight(sa), 0.0);
            inner = Inner(vec2(0.0), params.size.yw, true);
            corner = Corner(vec2(pc.z, 0.0), vec4(normal, 0.0, 0.0), 0.0, vec3(0.0));
        }
        quad(q, inner, corner, KEEP_ALL);
    }
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= params.counts.x) {
        return;
    }
    Silhouette s;
    if (!silhouette(i, s)) {
        if (STAGE == STAGE_DRAW) {
            partial_silhouette(i);
        }
        return;
    }
    if (STAGE == STAGE_PAIR) {
        for (uint k = 0u; k < 2u; k++) {
            uint n = arrive(s.v[k]);
            if (n < 2u) {
                stamps[STAMP_WORDS * s.v[k] + 1u + n] = 2u * i + k;
            }
        }
        return;
    }
    // In loops kept rolled: each call is inlined, and llvmpipe's compile time grows with them.
    if (STAGE == STAGE_OWN) {
        [[dont_unroll]] for (int k = 0; k < 2; k++) {
            if (stamps[STAMP_WORDS * s.v[k] + 1u] == 2u * i + uint(k)) {
                store_corner(s.v[k], shadow_corner(s, i, k));
            }
        }
        return;
    }
    Corner corners[2];
    [[dont_unroll]] for (int k = 0; k < 2; k++) {
        corners[k] = carried_corner(s, i, k);
    }
    for (int k = 0; k < 2; k++) {
        uint v = s.v[k];
        if (stamps[STAMP_WORDS * v + 1u] == 2u * i + uint(k)) {
            corner(s, k, stamps[STAMP_WORDS * v] & 3u, stamps[STAMP_WORDS * v + 2u], corners[k]);
        }
    }
    if (!s.sided) {
        return;
    }
    Vertex outer[4], inner[4];
    edge_quad(s.t[0], s.t[1], s.z[0], s.z[1], s.normal, false, outer);
    edge_quad(s.t[0], s.t[1], s.z[0], s.z[1], -s.normal, true, inner);
    vec2 cuts = corner_cuts(outer, inner, corners);
    // Centred, the inner quad too, mirrored over the blocker (issue 20), both in pieces near
    // the hard shadow's corners (outer only, there are none).
    [[dont_unroll]] for (int side = 0; side < (params.counts.w == 0u ? 1 : 2); side++) {
        edge_pieces(side == 0 ? outer : inner, side == 0 ? OUTER : Inner(s.normal, params.size.yw, false), corners, cuts);
    }
}
