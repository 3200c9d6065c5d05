#version 460
// The caster is black on the white-cleared tile.
layout(location = 0) out float out_lit;

void main() {
    out_lit = 0.0;
}
