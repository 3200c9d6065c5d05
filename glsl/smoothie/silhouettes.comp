#version 460
// Beyond the paper (which found silhouettes on the host, §4): silhouette detection and
// smoothie generation on the GPU, one invocation per edge, appended into a vertex buffer whose
// count feeds an indirect draw. Same construction as src/geometry/smoothie.rs.
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
layout(std430, set = 0, binding = 5) buffer Args { uint vertex_count; uint instance_count; uint first_vertex; uint first_instance; };
// x, y, b, sx, sy, fx, fy, nx, ny, near, far (src/geometry/smoothie.rs's SmoothieVertex)
layout(std430, set = 0, binding = 6) writeonly buffer Vertices { float vertices[]; };
const uint FLOATS = 11u;

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

float reach(float depth) {
    return clamp(1.0 - depth / params.size.z, 0.0, 1.0);
}

// Inner quads' extra data: each vertex's point on the edge, the edge's outward normal, the
// caster's depth range; zero for the outer smoothies.
struct Inner {
    vec2 foot[4];
    vec2 normal;
    vec2 range;
};

void put(uint at, vec2 p, float b, vec2 shape, vec2 foot, vec2 normal, vec2 range) {
    float v[11] = float[11](p.x, p.y, b, shape.x, shape.y, foot.x, foot.y, normal.x, normal.y, range.x, range.y);
    for (uint k = 0u; k < FLOATS; k++) {
        vertices[FLOATS * at + k] = v[k];
    }
}

// Six vertices, two triangles: the quad q0 q1 q2 q3.
void quad(vec2 q[4], float b[4], vec2 s[4], Inner inner) {
    uint at = atomicAdd(vertex_count, 6u);
    if (at + 6u > params.counts.z) {
        return; // sized so that it never happens; never write past the buffer
    }
    const int order[6] = int[6](0, 1, 2, 0, 2, 3);
    for (int k = 0; k < 6; k++) {
        int o = order[k];
        put(at + uint(k), q[o], b[o], s[o], inner.foot[o], inner.normal, inner.range);
    }
}

const Inner OUTER = Inner(vec2[4](vec2(0.0), vec2(0.0), vec2(0.0), vec2(0.0)), vec2(0.0), vec2(0.0));

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= params.counts.x) {
        return;
    }
    uvec4 e = edges[i];
    bool l0 = lit(e.z), l1 = lit(e.w);
    if (l0 == l1) {
        return;
    }
    uvec4 face = triangles[l0 ? e.z : e.w];
    uint inner = face.x != e.x && face.x != e.y ? face.x : (face.y != e.x && face.y != e.y ? face.y : face.z);
    vec3 pa = view_position(e.x), pb = view_position(e.y), pi = view_position(inner);
    if (pa.z <= MIN_DEPTH || pb.z <= MIN_DEPTH) {
        return;
    }
    vec2 ta = pa.xy / pa.z, tb = pb.xy / pb.z;
    // One corner per silhouette vertex: the first edge to stamp it this frame draws it.
    uint vs[2] = uint[2](e.x, e.y);
    vec2 tv[2] = vec2[2](ta, tb);
    float zv[2] = float[2](pa.z, pb.z);
    for (int k = 0; k < 2; k++) {
        if (atomicExchange(stamps[vs[k]], params.counts.y) != params.counts.y) {
            float r = smoothie_t(zv[k]) * reach(zv[k]);
            float kk = reach(zv[k]);
            vec2 c[4] = vec2[4](vec2(-1, -1), vec2(1, -1), vec2(1, 1), vec2(-1, 1));
            vec2 q[4] = vec2[4](tv[k] + c[0] * r, tv[k] + c[1] * r, tv[k] + c[2] * r, tv[k] + c[3] * r);
            float b[4] = float[4](zv[k], zv[k], zv[k], zv[k]);
            vec2 s[4] = vec2[4](c[0] * kk, c[1] * kk, c[2] * kk, c[3] * kk);
            quad(q, b, s, OUTER);
        }
    }
    vec2 along = tb - ta;
    if (dot(along, along) == 0.0 || pi.z <= MIN_DEPTH) {
        return;
    }
    along = normalize(along);
    vec2 perp = vec2(-along.y, along.x);
    vec2 normal = dot(perp, pi.xy / pi.z - ta) > 0.0 ? -perp : perp;
    float ka = reach(pa.z), kb = reach(pb.z);
    vec2 da = normal * smoothie_t(pa.z) * ka, db = normal * smoothie_t(pb.z) * kb;
    float b[4] = float[4](pa.z, pb.z, pb.z, pa.z);
    vec2 s[4] = vec2[4](vec2(0.0), vec2(0.0), vec2(kb, 0.0), vec2(ka, 0.0));
    quad(vec2[4](ta, tb, tb + db, ta + da), b, s, OUTER);
    if (params.counts.w != 0u) {
        // The inner quad, mirrored over the blocker (issue 20).
        quad(vec2[4](ta, tb, tb - db, ta - da), b, s, Inner(vec2[4](ta, tb, tb, ta), normal, params.size.yw));
    }
}
