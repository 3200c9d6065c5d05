#version 460
layout(location = 0) flat in float in_weight;
layout(location = 0) out float out_darkness;

void main() {
    out_darkness = in_weight;
}
