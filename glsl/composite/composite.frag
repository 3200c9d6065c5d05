#version 460
// Composite: ambient + V * Lambert, written to an sRGB target (the hardware encodes) or, for a
// window whose surface offers only linear formats, encoded here.
#include "interface.glsl"
#include "camera.glsl"

layout(constant_id = 0) const bool ENCODE_SRGB = false;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform sampler2D camera_depth;
layout(set = 0, binding = 2) uniform sampler2D camera_shading;
layout(set = 0, binding = 3) uniform sampler2D camera_albedo;
layout(set = 0, binding = 4) uniform sampler2D visibility;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

// The sRGB transfer function (IEC 61966-2-1), for linear targets.
vec3 encode(vec3 linear) {
    if (!ENCODE_SRGB) {
        return linear;
    }
    vec3 c = clamp(linear, 0.0, 1.0);
    return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float depth = texelFetch(camera_depth, pixel, 0).r;
    if (!sees_surface(depth)) {
        out_color = vec4(encode(frame.sky.rgb), 1.0);
        return;
    }
    vec3 p = world_position(frame.inv_view_proj, in_uv, depth);
    vec3 n = normalize(texelFetch(camera_shading, pixel, 0).xyz * 2.0 - 1.0);
    vec3 albedo = texelFetch(camera_albedo, pixel, 0).rgb;
    float v = texelFetch(visibility, pixel, 0).r;
    float lambert = max(dot(n, normalize(frame.light.xyz - p)), 0.0);
    out_color = vec4(encode(albedo * (frame.ambient.rgb + v * lambert * frame.light_color.rgb)), 1.0);
}
