#version 460
// Shadow map: linear light-space depth of the nearest caster.
layout(location = 0) in float in_depth;
layout(location = 0) out float out_depth;

void main() { out_depth = in_depth; }
