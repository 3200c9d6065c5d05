#version 460
// Camera prepass: world normal (+ shadow role) and albedo for every visible surface.
layout(location = 0) in vec3 in_normal;
layout(location = 1) flat in vec4 in_albedo;

layout(location = 0) out vec4 out_normal_role;
layout(location = 1) out vec4 out_albedo;

void main() {
    vec3 n = normalize(in_normal);
    // Two-sided surfaces (plates, open meshes): shade the side that faces the camera.
    if (!gl_FrontFacing) n = -n;
    out_normal_role = vec4(n, in_albedo.a);
    out_albedo = vec4(in_albedo.rgb, 1.0);
}
