#version 460
// Camera prepass for the meshes. Their depth is the raster's, bit for bit (the shadow volumes'
// caps rely on it), and this shader writes none: the depth test runs before it (early
// fragment tests), so hidden mesh fragments are never shaded. The ground, which writes its
// exact depth, is ground.frag, drawn after every mesh as before.
#include "surface.glsl"

layout(early_fragment_tests) in;

void main() {
    // The triangle's plane, exactly: visibility is a property of the geometry, and a smoothed
    // normal would move the self-shadowing terminator off the facets a ray tracer sees.
    write_surface(in_world, cross(dFdx(in_world), dFdy(in_world)));
}
