#version 460
// The object each camera pixel sees: the prepass's transform, the draw's instance + 1.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) readonly buffer Objects { ObjectData objects[]; };

layout(location = 0) in vec3 in_position;
layout(location = 0) flat out uint out_id;

void main() {
    vec4 world = objects[gl_InstanceIndex].model * vec4(in_position, 1.0);
    out_id = uint(gl_InstanceIndex) + 1u;
    gl_Position = frame.view_proj * world;
}
