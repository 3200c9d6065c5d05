#version 460
// The corners' functions (corners.glsl) at the inputs tests/shader_math.rs hands in, so that the
// test reads what the shaders compute: for each, disk_below_inverse(v), and the fraction of the
// unit disk in u1·x ≥ d1 and u2·x ≥ d2 (disk_in_both), u1 = (1, 0) and u2 at `delta` from it.
#include "corners.glsl"

// One input a workgroup: the test dispatches as many as it hands in.
layout(local_size_x = 1) in;

struct Input {
    float v;
    float d1;
    float d2;
    float delta;
};

layout(set = 0, binding = 0) readonly buffer Inputs { Input inputs[]; };
layout(set = 0, binding = 1) writeonly buffer Outputs { vec2 outputs[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    Input c = inputs[i];
    vec2 u2 = vec2(cos(c.delta), sin(c.delta));
    outputs[i] = vec2(disk_below_inverse(c.v), disk_in_both(vec2(1.0, 0.0), c.d1, u2, c.d2, c.delta));
}
