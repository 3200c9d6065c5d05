#version 460
// One of Gooch et al.'s projections: the casters flattened by Blinn's matrix onto a plane at
// its own height, seen straight down into the ground's plan-view texture, at this projection's
// depth (so each texel counts it once).
#include "interface.glsl"

// `params`: x the projection's depth, y its weight 1/N; `shadow`: per object, world -> texture clip.
layout(set = 0, binding = 0) readonly buffer Projection { vec4 params; mat4 shadow[]; } projection;
layout(set = 0, binding = 1) readonly buffer Objects { ObjectData objects[]; };

layout(location = 0) in vec3 in_position;
layout(location = 0) flat out float out_weight;

void main() {
    vec4 c = projection.shadow[gl_InstanceIndex] * (objects[gl_InstanceIndex].model * vec4(in_position, 1.0));
    // Homogeneous: w = light height - point height, so the clipper drops what lies above the light.
    gl_Position = vec4(c.xy, projection.params.x * c.w, c.w);
    out_weight = projection.params.y;
}
