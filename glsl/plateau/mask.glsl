// The umbra mask as the centred sides read it (probes.comp, penumbra.frag): each texel the
// number of the caster whose hard shadow covers it, 0 where none does.
#ifndef SOFTSHADOW_PLATEAU_MASK_GLSL
#define SOFTSHADOW_PLATEAU_MASK_GLSL

layout(set = 0, binding = 1) uniform sampler2D mask;

// How far off the foot the mask is probed: MASK_PROBE texels (src/shader_constants.rs).

uint caster_at(vec2 texel) {
    ivec2 size = textureSize(mask, 0);
    ivec2 i = clamp(ivec2(floor(texel)), ivec2(0), size - 1);
    return uint(round(texelFetch(mask, i, 0).r * 65535.0));
}

#endif
