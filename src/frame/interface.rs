//! Rust mirrors of `glsl/common/interface.glsl`: one definition of every struct that crosses to
//! the GPU, checked for size here (only vec4/mat4 members, so std140 and std430 agree).

use bytemuck::{Pod, Zeroable};
use glam::{Mat4, UVec4, Vec4};

/// Camera and light for every pass of a frame.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameGlobals {
    pub view_proj: Mat4,
    pub inv_view_proj: Mat4,
    pub camera_position: Vec4,
    pub camera_forward: Vec4,
    pub light: Vec4,
    pub light_color: Vec4,
    pub ambient: Vec4,
    pub sky: Vec4,
    pub viewport: Vec4,
}

/// One drawn object, indexed by the draw's first instance.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ObjectData {
    pub model: Mat4,
    pub normal_matrix: Mat4,
    pub albedo: Vec4,
}

/// A perspective view from the light.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightView {
    pub view: Mat4,
    pub view_proj: Mat4,
    pub extent: Vec4,
    pub bias: Vec4,
    pub kernel: Vec4,
    /// The frustum's linear depth range: near, far, log2(far / near); then how far the map's
    /// format may round a depth, relative to it (0 for 32-bit floats).
    pub depths: Vec4,
}

/// One point sampled on the area light, with the view its shadow map was rendered through.
/// Padded to 256 bytes, the largest uniform-buffer offset alignment Vulkan allows, so any one
/// of an array can also be bound as a uniform buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct LightSample {
    pub view: LightView,
    /// xyz the point; w 1 when it has a shadow map, 0 when nothing in view can block it.
    pub position: Vec4,
    /// xyz the light sphere's outward normal at the point (0 for a point light); w its
    /// importance weight (`geometry::LightPoint`).
    pub normal: Vec4,
    pub pad: [Vec4; 2],
}

/// The plateau texture's frame: the receiver plane and the window of it the texture covers.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct PlateauView {
    pub umbra: Mat4,
    pub plane_origin: Vec4,
    pub plane_normal: Vec4,
    pub plane_u: Vec4,
    pub plane_v: Vec4,
    pub window: Vec4,
    /// The number of wedges, whose records precede the sheets' in the sides buffer, and,
    /// centred, the number of sheets, whose mask probes `glsl/plateau/probes.comp` finds; then
    /// 0, 0.
    pub sheets: UVec4,
}

/// One caster's silhouette dispatch, padded to 256 bytes (see `LightSample`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SilhouetteParams {
    pub model_view: Mat4,
    pub size: Vec4,
    pub counts: [u32; 4],
    /// x: how far the light lies behind the view's origin; y: the caster's channel in the
    /// centred smoothie buffer (`SmoothieVertex::channel`); z: centred, the light's radius
    /// (partial silhouettes), else 0; w: their `PARTIAL_GAIN`.
    pub light: Vec4,
    /// xyz: the ground's inverse light depth along the ray (x, y, 1), w: 1 where it bounds the
    /// receivers (`geometry::smoothie::ReceiverBound`), else 0.
    pub ground: Vec4,
    /// The hard shadow's corners (`geometry::smoothie::ShadowCorner`): x `MIN_TURN`, y its
    /// `CORNER_REACH`, z `SHARPEST_TURN`, w `PIECE_MARGIN`.
    pub corners: Vec4,
    /// The cut quads' grid (`geometry::smoothie::CutGrid`): x its texel, y its slivers' width.
    pub cuts: Vec4,
    pub pad: [Vec4; 6],
}

/// One caster's shadow volume from one light point, built on the GPU, padded to 256 bytes
/// (see `LightSample`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct VolumeParams {
    /// The light point in the caster's object space, as the face-plane test takes it
    /// (`FacePlanes::object_light`).
    pub light: Vec4,
    /// Edges, triangles, 1 for the two-sided construction, the object's index.
    pub counts: [u32; 4],
    /// Where the mesh data's triangles, edges and face planes begin (positions come first).
    pub offsets: [u32; 4],
    /// The indirect draw commands of the sides, the caps and the turned caps.
    pub commands: [u32; 4],
    /// The vertex where each of those ranges ends.
    pub ends: [u32; 4],
    pub pad: [Vec4; 11],
}

/// One hard shadow of an accumulation, padded to 256 bytes (see `LightSample`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct SampleView {
    pub transform: Mat4,
    pub light: Vec4,
    pub plane: Vec4,
    /// The light sphere's normal at the point and its importance weight (`LightSample::normal`).
    pub normal: Vec4,
    pub pad: [Vec4; 9],
}

/// The classic systems' frame (blob, concentric, projective texture): the receiver plane, the
/// window of it a plan-view texture covers, and the technique's counts and knobs.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct ClassicView {
    pub plane_origin: Vec4,
    pub plane_normal: Vec4,
    pub plane_u: Vec4,
    pub plane_v: Vec4,
    pub window: Vec4,
    pub params: Vec4,
}

/// A blob on the receiver plane: its centre and the 2x2 matrix to the unit disk.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct BlobData {
    pub centre: Vec4,
    pub to_unit: Vec4,
}

/// One caster's black-on-white image in the projective-texture atlas, padded to 256 bytes
/// (see `LightSample`) so that the pass drawing it binds one element as a uniform buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct CasterImage {
    pub view_proj: Mat4,
    pub tile: Vec4,
    pub info: Vec4,
    pub pad: [Vec4; 10],
}

const _: () = assert!(std::mem::size_of::<FrameGlobals>() == 2 * 64 + 7 * 16);
const _: () = assert!(std::mem::size_of::<ObjectData>() == 2 * 64 + 16);
const _: () = assert!(std::mem::size_of::<LightView>() == 2 * 64 + 4 * 16);
const _: () = assert!(std::mem::size_of::<LightSample>() == 256);
const _: () = assert!(std::mem::size_of::<PlateauView>() == 64 + 6 * 16);
const _: () = assert!(std::mem::size_of::<SilhouetteParams>() == 256);
const _: () = assert!(std::mem::size_of::<SampleView>() == 256);
const _: () = assert!(std::mem::size_of::<VolumeParams>() == 256);
const _: () = assert!(std::mem::size_of::<ClassicView>() == 6 * 16);
const _: () = assert!(std::mem::size_of::<BlobData>() == 2 * 16);
const _: () = assert!(std::mem::size_of::<CasterImage>() == 256);
