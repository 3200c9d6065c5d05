#version 460
// Umbra: the casters flattened onto the receiver plane by Blinn's projection, at the hither.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Plateau { PlateauView plateau; };
layout(set = 0, binding = 1) readonly buffer Objects { ObjectData objects[]; };

layout(location = 0) in vec3 in_position;

void main() {
    // Homogeneous: w = light height - point height, so the clipper drops what lies above the light.
    gl_Position = plateau.umbra * (objects[gl_InstanceIndex].model * vec4(in_position, 1.0));
}
