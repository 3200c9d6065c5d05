#version 460
// The casters drawn a second time, flattened onto the receiver plane by Blinn's matrix in
// homogeneous form (DDJ Example 1, Komura's ground-plane matrix): w = light height - point
// height, so points at or above the light get w <= 0 and are clipped, never an anti-shadow.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Sample { SampleView view; };
layout(set = 0, binding = 1) readonly buffer Objects { ObjectData objects[]; };

layout(location = 0) in vec3 in_position;

void main() {
    gl_Position = view.transform * (objects[gl_InstanceIndex].model * vec4(in_position, 1.0));
}
