#version 460
// V = accumulated unblocked solid angle / accumulated solid angle; 1 where nothing was summed
// (no surface, a surface that receives no shadows).
layout(set = 0, binding = 0) uniform sampler2D sums;

layout(location = 0) in vec2 in_uv;
layout(location = 0) out float out_visibility;

void main() {
    vec2 s = textureLod(sums, in_uv, 0.0).rg; // nearest sampler: exactly this pixel
    out_visibility = s.y > 0.0 ? clamp(s.x / s.y, 0.0, 1.0) : 1.0;
}
