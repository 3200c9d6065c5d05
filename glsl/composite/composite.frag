#version 460
// Composite: ambient + V * Lambert, written to an sRGB target (the hardware encodes).
#include "interface.glsl"
#include "camera.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform sampler2D camera_depth;
layout(set = 0, binding = 2) uniform sampler2D camera_shading;
layout(set = 0, binding = 3) uniform sampler2D camera_albedo;
layout(set = 0, binding = 4) uniform sampler2D visibility;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out vec4 out_color;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float depth = texelFetch(camera_depth, pixel, 0).r;
    if (!sees_surface(depth)) {
        out_color = vec4(frame.sky.rgb, 1.0);
        return;
    }
    vec3 p = world_position(frame.inv_view_proj, in_uv, depth);
    vec3 n = normalize(texelFetch(camera_shading, pixel, 0).xyz * 2.0 - 1.0);
    vec3 albedo = texelFetch(camera_albedo, pixel, 0).rgb;
    float v = texelFetch(visibility, pixel, 0).r;
    float lambert = max(dot(n, normalize(frame.light.xyz - p)), 0.0);
    out_color = vec4(albedo * (frame.ambient.rgb + v * lambert * frame.light_color.rgb), 1.0);
}
