#version 460
// The umbra mask: the caster's number (0 where no hard shadow falls), as a 16-bit fraction.
layout(location = 0) flat in uint in_caster;
layout(location = 0) out float out_caster;

void main() {
    out_caster = float(min(in_caster, 65535u)) / 65535.0;
}
