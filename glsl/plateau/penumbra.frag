#version 460
layout(location = 0) in float in_t;
layout(location = 0) out float out_t;

void main() {
    out_t = in_t;
}
