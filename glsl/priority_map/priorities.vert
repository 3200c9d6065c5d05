#version 460
// The priority map (DDJ, "priority maps"): each caster drawn from the light with its priority.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Light { LightView light; };
layout(set = 0, binding = 1) readonly buffer Objects { ObjectData objects[]; };
layout(set = 0, binding = 2) readonly buffer Priorities { uint priorities[]; };

layout(location = 0) in vec3 in_position;
layout(location = 0) flat out uint out_priority;

void main() {
    out_priority = priorities[gl_InstanceIndex];
    gl_Position = light.view_proj * (objects[gl_InstanceIndex].model * vec4(in_position, 1.0));
}
