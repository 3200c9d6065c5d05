#version 460
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) readonly buffer Objects { ObjectData objects[]; };

layout(location = 0) in vec3 in_position;
layout(location = 1) in vec3 in_normal;

layout(location = 0) out vec3 out_normal;
layout(location = 1) flat out vec4 out_albedo;
layout(location = 2) out vec3 out_world;
layout(location = 3) flat out vec4 out_plane;

void main() {
    ObjectData object = objects[gl_InstanceIndex];
    // precise: shadow volumes draw light caps through this very transform
    // (glsl/shadow_volume/volume.vert) and need the bit-identical depth.
    precise vec4 world = object.model * vec4(in_position, 1.0);
    out_normal = mat3(object.normal_matrix) * in_normal;
    out_albedo = object.albedo;
    out_world = world.xyz;
    out_plane = object.normal_matrix[3];
    precise vec4 position = frame.view_proj * world;
    gl_Position = position;
}
