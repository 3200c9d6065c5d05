#version 460
// The camera prepass's depth copied into the depth-stencil target, bit for bit: the volumes
// test against exactly the surfaces V is estimated at.
layout(set = 0, binding = 0) uniform sampler2D camera_depth;

void main() {
    gl_FragDepth = texelFetch(camera_depth, ivec2(gl_FragCoord.xy), 0).r;
}
