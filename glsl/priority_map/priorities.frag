#version 460
layout(location = 0) flat in uint in_priority;
layout(location = 0) out uint out_priority;

void main() {
    out_priority = in_priority;
}
