#version 460
// One caster's black-on-white image from the light (DDJ, "projective textures", Example 2),
// drawn into its tile of the atlas.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Image { CasterImage image; };
layout(set = 0, binding = 1) readonly buffer Objects { ObjectData objects[]; };

layout(location = 0) in vec3 in_position;

void main() {
    gl_Position = image.view_proj * (objects[gl_InstanceIndex].model * vec4(in_position, 1.0));
}
