// Structs that cross to the GPU. Mirrored one-to-one by `src/frame/interface.rs` (#[repr(C)], std140
// and std430 compatible: only vec4 and mat4 members); keep the two in step.
#ifndef SOFTSHADOW_INTERFACE_GLSL
#define SOFTSHADOW_INTERFACE_GLSL

// Per-frame camera and light, shared by every pass.
struct FrameGlobals {
    mat4 view_proj;       // world -> camera clip (reverse Z: near 1, far 0)
    mat4 inv_view_proj;   // camera clip -> world
    vec4 camera_position; // xyz; w = 1 perspective, 0 orthographic
    vec4 camera_forward;  // xyz; w unused
    vec4 light;           // xyz centre, w radius (0 = point light)
    vec4 light_color;     // rgb radiance scale; a unused
    vec4 ambient;         // rgb; a unused
    vec4 sky;             // rgb background; a unused
    vec4 viewport;        // width, height, 1/width, 1/height
};

// One per drawn object, indexed by gl_InstanceIndex (the draw's firstInstance).
struct ObjectData {
    mat4 model;          // object -> world
    mat4 normal_matrix;  // inverse transpose of the model's 3x3, in the upper left; column 3:
                         // an exact plane's equation (n, -n.o) (the ground), else (0, 0, 0, 1)
    vec4 albedo;         // rgb linear albedo; a = shadow role: 0 no shadows, 0.5 receives, 1 receives + casts
};

// A perspective view from the light (the spot frustum of DESIGN.md's shadow map).
struct LightView {
    mat4 view;       // world -> light view: +Z looks away from the light, linear depth = z
    mat4 view_proj;  // world -> light clip
    vec4 extent;     // tangent-space window: x0, y0, x1, y1 (x/z and y/z of the frustum's sides)
    vec4 bias;       // constant (texels), slope (texels), normal offset (texels), map size
    vec4 kernel;     // PCF: unused, kernel radius (texels, or world units: RADIUS_IN_WORLD), unused, unused
                     // PCSS: unused, light radius (world), frustum near depth, unused (the taps:
                     // shadow_map/resolve.frag's constants)
                     // smoothie: buffer size, an empty map texel's depth, ground height, light height
    vec4 depths;     // the frustum's linear depth range: near, far, log2(far / near); the map's rounding
};

// A point sampled on the area light and the view its shadow map was rendered through (the
// reference's accumulation). 256 bytes, so one element can also be bound as a uniform buffer.
struct LightSample {
    LightView view;
    vec4 position;   // xyz; w = 1 with a shadow map, 0 when nothing in view can block it
    vec4 normal;     // xyz the sphere's outward normal there (0: a point light); w its weight
    vec4 pad[2];
};

// The plateau texture's frame (Haines): the receiver plane, in-plane axes, the window.
struct PlateauView {
    mat4 umbra;         // world -> plateau clip: window * plane coordinates * Blinn, z = 0 (hither)
    vec4 plane_origin;  // xyz; w unused (on_plane, camera.glsl, says what is on it)
    vec4 plane_normal;  // xyz; w unused
    vec4 plane_u;       // xyz; w unused
    vec4 plane_v;       // xyz
    vec4 window;        // u0, v0, u1, v1: the part of the plane the texture covers
    uvec4 sheets;       // the wedge count (the sheets follow), centred: the sheet count (plateau/probes.comp); -, -
};

// One caster's silhouette dispatch (glsl/smoothie/silhouettes.comp). 256 bytes, so an array of
// them can be bound one element at a time (a storage buffer there: see why in that shader).
struct SilhouetteParams {
    mat4 model_view;  // object -> light view (+z away from the light)
    vec4 size;        // x: t, or scale * light radius with PHYSICAL_SIZE (t = x / depth); z: farthest receiver;
                      // y, w: the caster's light-depth range (inner quads)
    uvec4 counts;     // x: edges, y: mailbox stamp, z: each kind's capacity in vertices (silhouettes.comp), w: 1 for inner quads
    vec4 light;       // x: how far the light lies behind the view's origin (PHYSICAL_SIZE);
                      // y: the caster's channel in the centred smoothie buffer (0 or 1);
                      // z: centred, the light's radius (partial silhouettes), else 0; w: PARTIAL_GAIN
    vec4 ground;      // xyz: the ground's inverse light depth along the ray (x, y, 1); w: 1 where it
                      // bounds the receivers (src/geometry/smoothie.rs's ReceiverBound), else 0
    vec4 corners;     // the hard shadow's corners (src/geometry/smoothie.rs's ShadowCorner): x MIN_TURN,
                      // y CORNER_REACH, z SHARPEST_TURN, w PIECE_MARGIN
    vec4 cuts;        // the cut quads' grid (src/geometry/smoothie.rs's CutGrid): x its texel, y its slivers' width
    vec4 pad[6];
};

// One caster's shadow volume from one light point, built on the GPU (shadow-volume,
// gpu_silhouettes = 1). 256 bytes, so one of an array can be bound as a uniform buffer.
struct VolumeParams {
    vec4 light;       // the light point in object space, homogeneous, as the face-plane test takes it
    uvec4 counts;     // x: edges, y: triangles, z: 1 for the two-sided (open) construction, w: object index
    uvec4 offsets;    // x, y, z: the mesh data's first triangle, edge, face plane (positions come first)
    uvec4 commands;   // x, y, z: the draw commands of the sides, the caps, the turned caps
    uvec4 ends;       // x, y, z: the vertex where each of those ranges ends
    vec4 pad[11];
};

// One hard shadow of an accumulation (shadow-volume, planar): the light point it is cast from and
// the transform its geometry is drawn through. 256 bytes, so one of an array can be bound as a
// uniform buffer.
struct SampleView {
    mat4 transform;  // world -> clip: the camera's (volumes), or the camera's * Blinn's (planar)
    vec4 light;      // xyz: the light point; w: volumes' reach (0: to infinity, w = 0)
    vec4 plane;      // planar: the receiver plane, n.xyz and w = -n.o
    vec4 normal;     // xyz the light sphere's normal at the point (0: a point light), w its weight
    vec4 pad[9];
};

// The classic systems' frame (blob, concentric, projective texture).
struct ClassicView {
    vec4 plane_origin;  // xyz; w unused (on_plane, camera.glsl, says what is on it)
    vec4 plane_normal;  // xyz
    vec4 plane_u;       // xyz
    vec4 plane_v;       // xyz
    vec4 window;        // u0, v0, u1, v1: the part of the plane a plan-view texture covers
    vec4 params;        // blob: -, softness (its count: the blobs' buffer's length); projective texture: count
};

// A blob (glsl/blob/resolve.frag): plane coordinates relative to `centre` times `to_unit`
// land in the unit disk inside the ellipse.
struct BlobData {
    vec4 centre;   // u, v
    vec4 to_unit;  // the 2x2 matrix, column-major: m00, m10, m01, m11
};

// One caster's image in the projective-texture atlas. 256 bytes: bound one at a time as a
// uniform buffer by the pass that draws it.
struct CasterImage {
    mat4 view_proj;  // world -> the image's clip space (w: distance in front of the light)
    vec4 tile;       // the tile in atlas uv: x0, y0, width, height
    vec4 info;       // x: distance from the light to the caster's bounding sphere; y: its object index
    vec4 pad[10];
};

#endif
