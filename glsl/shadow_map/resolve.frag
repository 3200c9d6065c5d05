#version 460
// The shadow-map family's resolve, one skeleton specialised per technique: the surface, the
// self-hiding test and the biased lookup are shared; only the filter differs.
#include "interface.glsl"
#include "camera.glsl"
#include "shadow.glsl"
#include "filters.glsl"

// The filter: FILTER_HARD, FILTER_DISK, FILTER_BICUBIC or FILTER_PCSS (src/shader_constants.rs).
layout(constant_id = 0) const uint FILTER = FILTER_HARD;
// pcf's `radius_world`: the disk radius is in world units at the receiver, not texels.
layout(constant_id = 1) const bool RADIUS_IN_WORLD = false;
// The disk's taps (pcf's `taps`, pcss's `filter_samples`) and pcss's blocker search's. Constants,
// not uniforms: lavapipe inlines a uniform a loop's end depends on and compiles the shader again
// for each new value of any uniform it inlines with it, which for pcss took every frame whose
// light view moved (190 ms a frame at 32² with a moving caster).
layout(constant_id = 2) const int TAPS = 16;
layout(constant_id = 3) const int BLOCKER_TAPS = 16;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Light { LightView light; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D shadow_map;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

void main() {
    Surface s = read_surface(frame, camera_depth, camera_normal, in_uv);
    if (!s.receives) {
        out_visibility = 1.0;
        return;
    }
    if (hides_itself(s, frame.light.xyz)) {
        out_visibility = 0.0;
        return;
    }
    ShadowLookup l = shadow_lookup(light, frame.light.xyz, s.p, s.n);
    if (!l.inside) {
        out_visibility = 1.0; // outside the frustum fitted around every caster
        return;
    }
    float size = light.bias.w;
    if (FILTER == FILTER_HARD) {
        out_visibility = compare_bilinear(shadow_map, vec2(0.0), size, l.uv, l.depth);
    } else if (FILTER == FILTER_DISK) {
        float radius = light.kernel.y;
        if (RADIUS_IN_WORLD) {
            // World units: divide by the world size of one texel at the receiver.
            float z = (light.view * vec4(s.p, 1.0)).z;
            radius *= texels_per_tangent(light).x / z;
        }
        out_visibility = pcf_disk(shadow_map, light, l, radius, TAPS);
    } else if (FILTER == FILTER_BICUBIC) {
        out_visibility = pcf_bicubic(shadow_map, light, l);
    } else {
        // The receiver-plane tests of pcss() leave a caster's own surface out of the map, so the
        // part of the light below its tangent plane is taken out here (the soft hides_itself).
        float self_lit = in_front_of_itself(s, frame.light.xyz, light.kernel.y);
        float radius = apparent_radius(light, frame.light.xyz, s.p, light.kernel.y);
        out_visibility = self_lit * pcss(shadow_map, light, l, s.p, s.n, radius, TAPS, BLOCKER_TAPS);
    }
}
