#version 460
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Light { LightView light; };
layout(set = 0, binding = 1) readonly buffer Objects { ObjectData objects[]; };

layout(location = 0) in vec3 in_position;

layout(location = 0) out float out_depth;

void main() {
    vec4 world = objects[gl_InstanceIndex].model * vec4(in_position, 1.0);
    out_depth = (light.view * world).z;
    gl_Position = light.view_proj * world;
}
