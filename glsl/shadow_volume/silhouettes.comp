#version 460
// Beyond the papers (the DDJ and Komura find silhouettes on the host): one caster's shadow volume
// from one light point built on the GPU, the construction of src/geometry/shadow_volume.rs step
// for step. Invocation i takes edge i (its sides, as many times as its signed multiplicity) and
// triangle i (its light or turned cap and its dark cap), appending them into the ranges of three
// indirect draws. The vertices are the CPU path's: object-space position, at infinity, object.
#include "interface.glsl"

layout(local_size_x = COMPUTE_GROUP) in;

layout(set = 0, binding = 0) uniform Params { VolumeParams params; };
// Positions (float bits), then triangles, then edges (v0, v1, face0, face1), then face planes
// (n, d; float bits).
layout(std430, set = 0, binding = 1) readonly buffer Mesh { uvec4 mesh[]; };
layout(std430, set = 0, binding = 2) buffer Commands { uvec4 commands[]; }; // count, 1, first, 0
layout(std430, set = 0, binding = 3) writeonly buffer Vertices { float vertices[]; };

vec3 object_position(uint v) {
    return uintBitsToFloat(mesh[v].xyz);
}

// The host's FacePlanes::light_facing, operation for operation (precise: no fused or reordered
// arithmetic), on the same planes and object-space light: both paths agree on every face.
bool facing(uint f) {
    vec4 n = uintBitsToFloat(mesh[params.offsets.z + f]);
    vec4 l = params.light;
    precise float side = n.x * l.x + n.y * l.y + n.z * l.z + n.w * l.w;
    return side > 0.0;
}

bool blocks(uint f, bool lit) {
    return f != NO_FACE && (params.counts.z != 0u || lit);
}

// Room for `n` vertices in draw `command`'s range; ~0u if it is full (sized so that it never is).
uint reserve(uint command, uint end, uint n) {
    uint at = commands[command].z + atomicAdd(commands[command].x, n);
    return at + n <= end ? at : ~0u;
}

void put(uint at, uint vertex, bool far) {
    vec3 p = object_position(vertex);
    vertices[VOLUME_VERTEX_FLOATS * at + 0u] = p.x;
    vertices[VOLUME_VERTEX_FLOATS * at + 1u] = p.y;
    vertices[VOLUME_VERTEX_FLOATS * at + 2u] = p.z;
    vertices[VOLUME_VERTEX_FLOATS * at + 3u] = far ? 1.0 : 0.0;
    vertices[VOLUME_VERTEX_FLOATS * at + 4u] = float(params.counts.w);
}

void edge(uint i) {
    uvec4 e = mesh[params.offsets.y + i];
    bool lit0 = e.z != NO_FACE && facing(e.z);
    bool lit1 = e.w != NO_FACE && facing(e.w);
    // +1 when the face, turned towards the light, runs along the edge as stored.
    int m = 0;
    if (blocks(e.z, lit0)) {
        m += lit0 ? 1 : -1;
    }
    if (blocks(e.w, lit1)) {
        m += lit1 ? -1 : 1;
    }
    if (m == 0) {
        return;
    }
    uint a = m > 0 ? e.x : e.y, b = m > 0 ? e.y : e.x;
    uint n = uint(abs(m));
    uint at = reserve(params.commands.x, params.ends.x, 6u * n);
    if (at == ~0u) {
        return;
    }
    for (uint k = 0u; k < n; k++, at += 6u) {
        // Edge a -> b of a light-facing cap: the side runs b -> a, then out to infinity.
        put(at, b, false);
        put(at + 1u, a, false);
        put(at + 2u, a, true);
        put(at + 3u, b, false);
        put(at + 4u, a, true);
        put(at + 5u, b, true);
    }
}

void triangle(uint f) {
    bool lit = facing(f);
    if (!blocks(f, lit)) {
        return;
    }
    uvec4 t = mesh[params.offsets.x + f];
    uint caps = reserve(params.commands.y, params.ends.y, lit ? 6u : 3u);
    if (caps == ~0u) {
        return;
    }
    // The dark cap, wound like the light-facing side turned away.
    uvec3 d = lit ? t.xyz : t.xzy;
    put(caps, d.x, true);
    put(caps + 1u, d.z, true);
    put(caps + 2u, d.y, true);
    if (lit) {
        put(caps + 3u, t.x, false);
        put(caps + 4u, t.y, false);
        put(caps + 5u, t.z, false);
        return;
    }
    uint turned = reserve(params.commands.z, params.ends.z, 3u);
    if (turned != ~0u) {
        put(turned, t.x, false);
        put(turned + 1u, t.y, false);
        put(turned + 2u, t.z, false);
    }
}

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i < params.counts.x) {
        edge(i);
    }
    if (i < params.counts.y) {
        triangle(i);
    }
}
