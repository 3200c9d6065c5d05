#version 460
// Volume geometry: a caster's vertex (object space) or its extrusion away from the light to
// infinity (w = 0, DDJ / Everitt & Kilgard). A vertex on the mesh goes through the camera
// prepass's very transform (glsl/prepass/scene.vert, both invariant): a light cap has the
// bit-identical depth of the surface it lies on (precise: no fused operations in either), so
// no depth bias is needed.
#include "interface.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Sample { SampleView view; };
layout(set = 0, binding = 2) readonly buffer Objects { ObjectData objects[]; };

layout(location = 0) in vec3 in_position;
layout(location = 1) in float in_at_infinity;
layout(location = 2) in float in_object;

void main() {
    ObjectData object = objects[uint(in_object)];
    precise vec4 world = object.model * vec4(in_position, 1.0);
    vec3 away = world.xyz - view.light.xyz;
    if (in_at_infinity > 0.5 && view.light.w > 0.0) {
        // Orthographic views: far past every receiver instead (src/technique/shadow_volume.rs).
        gl_Position = frame.view_proj * vec4(world.xyz + normalize(away) * view.light.w, 1.0);
    } else if (in_at_infinity > 0.5) {
        gl_Position = frame.view_proj * vec4(away, 0.0);
    } else {
        precise vec4 position = frame.view_proj * world;
        gl_Position = position;
    }
}
