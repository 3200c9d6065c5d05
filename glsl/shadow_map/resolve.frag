#version 460
// Hard shadow resolve: one 2x2 bilinear comparison per camera pixel into V.
#include "interface.glsl"
#include "camera.glsl"

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform Light { LightView light; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform sampler2D shadow_map;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

void main() {
    ivec2 pixel = ivec2(gl_FragCoord.xy);
    float depth = texelFetch(camera_depth, pixel, 0).r;
    vec4 normal_receives = texelFetch(camera_normal, pixel, 0);
    if (!sees_surface(depth) || normal_receives.a < 0.5) {
        out_visibility = 1.0;
        return;
    }
    vec3 p = world_position(frame.inv_view_proj, in_uv, depth);
    vec3 n = normalize(normal_receives.xyz);

    float size = light.bias.w;
    // World size of one shadow-map texel at p's light depth: the biases scale with it, so they
    // hold at any scene scale.
    float z = (light.view * vec4(p, 1.0)).z;
    float texel = z * max(light.extent.z - light.extent.x, light.extent.w - light.extent.y) / size;
    vec3 to_light = normalize(frame.light.xyz - p);
    float cos_theta = clamp(dot(n, to_light), 0.0, 1.0);
    // Normal offset grows as the surface turns from the light, where acne starts.
    vec3 q = p + n * (light.bias.z * texel * (1.0 - cos_theta));
    float tan_theta = min(sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / max(cos_theta, 1e-3), 8.0);
    float bias = texel * (light.bias.x + light.bias.y * tan_theta);

    vec4 clip = light.view_proj * vec4(q, 1.0);
    if (clip.w <= 0.0) {
        out_visibility = 1.0; // behind the light: no caster lies between
        return;
    }
    vec2 uv = clip.xy / clip.w * 0.5 + 0.5;
    if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0)))) {
        // Outside the frustum fitted around every caster: nothing can block the light.
        out_visibility = 1.0;
        return;
    }
    float receiver = (light.view * vec4(q, 1.0)).z - bias;

    // 2x2 bilinear comparison: compare the four nearest texels, then weight the results.
    vec2 texel_pos = uv * size - 0.5;
    vec2 f = fract(texel_pos);
    vec4 d = textureGather(shadow_map, (floor(texel_pos) + 1.0) / size, 0);
    // textureGather order: (i0,j1) (i1,j1) (i1,j0) (i0,j0).
    vec4 lit = vec4(greaterThanEqual(d, vec4(receiver)));
    float top = mix(lit.w, lit.z, f.x);
    float bottom = mix(lit.x, lit.y, f.x);
    out_visibility = mix(top, bottom, f.y);
}
