#version 460
// Stencil-only passes (volumes, caps, marks): the fixed-function stencil does the work.
void main() {
}
