#version 460
// The plateau's top: t = 0, the darkest value.
layout(location = 0) out float out_t;

void main() {
    out_t = 0.0;
}
