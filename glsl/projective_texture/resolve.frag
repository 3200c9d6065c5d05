#version 460
// Projective-texture resolve: each receiver point looks itself up in every other caster's
// image through that image's own projection (per pixel: perspective-correct), nearest texel;
// the darkest image wins.
#include "interface.glsl"
#include "camera.glsl"

// The `clip` knob: 0 every receiver an image's projection covers, behind the light included
// (the DDJ's texture-coordinate generation as is); 1 only receivers in front of the light;
// 2 only those farther from the light than the caster's bounding sphere begins.
layout(constant_id = 0) const int CLIP = 2;

layout(set = 0, binding = 0) uniform Frame { FrameGlobals frame; };
layout(set = 0, binding = 1) uniform View { ClassicView view; };
layout(set = 0, binding = 2) uniform sampler2D camera_depth;
layout(set = 0, binding = 3) uniform sampler2D camera_normal;
layout(set = 0, binding = 4) uniform usampler2D object_ids;
layout(set = 0, binding = 5) readonly buffer Images { CasterImage images[]; };
layout(set = 0, binding = 6) uniform sampler2D atlas;

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
    uint own = texelFetch(object_ids, ivec2(gl_FragCoord.xy), 0).r;
    vec2 size = vec2(textureSize(atlas, 0));
    float to_light = distance(s.p, frame.light.xyz);
    float v = 1.0;
    uint count = uint(view.params.x);
    for (uint i = 0; i < count; i++) {
        CasterImage c = images[i];
        // No self-shadowing: a caster does not receive its own image.
        if (uint(c.info.y) + 1u == own) continue;
        vec4 q = c.view_proj * vec4(s.p, 1.0);
        if (q.w == 0.0 || (CLIP >= 1 && q.w < 0.0) || (CLIP >= 2 && to_light < c.info.x)) continue;
        vec2 ndc = q.xy / q.w;
        if (any(greaterThan(abs(ndc), vec2(1.0)))) continue;
        vec2 tc = c.tile.xy + (ndc * 0.5 + 0.5) * c.tile.zw;
        ivec2 lo = ivec2(c.tile.xy * size);
        ivec2 hi = ivec2((c.tile.xy + c.tile.zw) * size) - 1;
        v = min(v, texelFetch(atlas, clamp(ivec2(tc * size), lo, hi), 0).r);
    }
    out_visibility = v;
}
