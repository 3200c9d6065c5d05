#version 460
// Umbra mask: the casters flattened onto the receiver plane by Blinn's projection, each writing
// its number; where shadows overlap, the lowest caster's (depth = its height over the light's).
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Plateau { PlateauView plateau; };
layout(set = 0, binding = 1) readonly buffer Objects { ObjectData objects[]; };

layout(location = 0) in vec3 in_position;
layout(location = 0) flat out uint out_caster;

void main() {
    vec4 p = objects[gl_InstanceIndex].model * vec4(in_position, 1.0);
    // Homogeneous: w = light height - point height, so the clipper drops what lies above the light.
    gl_Position = plateau.umbra * p;
    float h = dot(p.xyz - plateau.plane_origin.xyz, plateau.plane_normal.xyz);
    float light_height = max(gl_Position.w + h, 1e-30);
    gl_Position.z = clamp(h / light_height, 0.0, 1.0) * gl_Position.w;
    out_caster = uint(gl_InstanceIndex) + 1u;
}
