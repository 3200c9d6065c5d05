//! What crosses rooms (DESIGN.md §1): the inputs a technique reads while it records a frame,
//! the draw list, the camera surfaces V is estimated at, V's formats and quantisation, the
//! shadow role every surface carries, and the structs shared with the shaders.
//!
//! Techniques, the reference tracer, the renderer and the measurements all meet here, so none
//! of them needs to import another.

pub mod interface;

use ash::vk;
use glam::Vec3;

use crate::geometry::{Aabb, CameraProjection};
use crate::gpu::{Context, PassTimer, Target, VertexInput, draw_indexed};
use crate::scene::{Scene, Vertex};
use crate::shader_constants::{ROLE_CASTS, ROLE_CASTS_ABOVE, ROLE_IGNORES, ROLE_RECEIVES, ROLE_RECEIVES_ABOVE};

/// Format of the visibility image V (DESIGN.md §3).
pub const VISIBILITY_FORMAT: vk::Format = vk::Format::R16_UNORM;
/// V's format when the engine keeps raw visibility: UNORM would clamp values outside [0, 1]
/// and turn NaN into 0 silently, hiding exactly what the stability checks look for.
pub const RAW_VISIBILITY_FORMAT: vk::Format = vk::Format::R32_SFLOAT;

/// V as R16_UNORM stores it: clamped to [0, 1], rounded; NaN becomes 0 (Vulkan's conversion
/// to normalized fixed point).
pub fn quantize(v: f32) -> u16 {
    (v.clamp(0.0, 1.0) * 65535.0).round() as u16
}

/// Scene meshes as the passes read them: [`Vertex`]'s position only.
pub const MESH_POSITIONS: VertexInput =
    VertexInput::Interleaved { stride: std::mem::size_of::<Vertex>() as u32, attributes: &[(0, 3)] };
/// Scene meshes with their normals: [`Vertex`]'s position (location 0) and normal (location 1).
pub const MESH_POSITIONS_NORMALS: VertexInput =
    VertexInput::Interleaved { stride: std::mem::size_of::<Vertex>() as u32, attributes: &[(0, 3), (12, 3)] };

/// How a surface takes part in shadowing. The prepass writes it into the camera normal
/// target's alpha, which `glsl/common/camera.glsl` reads back.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ShadowRole {
    /// Receives no shadow: V means nothing there.
    Ignores,
    Receives,
    ReceivesAndCasts,
}

impl ShadowRole {
    pub fn new(receives: bool, casts: bool) -> Self {
        match (receives, casts) {
            (false, _) => ShadowRole::Ignores,
            (true, false) => ShadowRole::Receives,
            (true, true) => ShadowRole::ReceivesAndCasts,
        }
    }

    /// The value written into the normal target's alpha: 0, 0.5 or 1.
    pub fn encode(self) -> f32 {
        match self {
            ShadowRole::Ignores => ROLE_IGNORES,
            ShadowRole::Receives => ROLE_RECEIVES,
            ShadowRole::ReceivesAndCasts => ROLE_CASTS,
        }
    }

    /// Whether an encoded role (as read back, possibly rounded to a half float) receives:
    /// the threshold halfway between 0 and 0.5, as the shaders test it.
    pub fn receives(encoded: f32) -> bool {
        encoded > ROLE_RECEIVES_ABOVE
    }

    /// Whether an encoded role is [`ShadowRole::ReceivesAndCasts`]: above halfway between 0.5
    /// and 1.
    pub fn casts(encoded: f32) -> bool {
        encoded > ROLE_CASTS_ABOVE
    }
}

/// One object to draw this frame: its uploaded mesh and its index in the object buffer.
#[derive(Clone, Copy, Debug)]
pub struct Draw {
    pub(crate) vertices: vk::Buffer,
    pub(crate) indices: vk::Buffer,
    pub(crate) index_count: u32,
    /// Index into the frame's `ObjectData` (the draw's first instance).
    pub instance: u32,
    pub casts: bool,
    pub receives: bool,
    /// World-space bounds.
    pub bounds: Aabb,
}

impl Draw {
    /// Records the draw with the bound pipeline (its vertex input is [`MESH_POSITIONS`] or
    /// [`MESH_POSITIONS_NORMALS`]).
    pub fn record(&self, ctx: &Context, cmd: vk::CommandBuffer) {
        draw_indexed(ctx, cmd, self.vertices, self.indices, self.index_count, self.instance);
    }
}

/// The surfaces a visibility image was estimated at.
#[derive(Clone, Debug, PartialEq)]
pub struct Surfaces {
    /// Distance along the camera's forward axis; infinite where no surface is seen.
    pub depth: Vec<f32>,
    /// The facet's unit normal on the camera's side (zero where no surface is seen).
    pub normal: Vec<Vec3>,
    /// The surface receives shadows (V means something there).
    pub receives: Vec<bool>,
    /// The surface receives shadows and belongs to a caster (it may shadow itself).
    pub casts: Vec<bool>,
}

/// What a technique reads while it records one frame.
pub struct FrameInputs<'a> {
    pub ctx: &'a Context,
    pub cmd: vk::CommandBuffer,
    /// Frame-in-flight slot: selects per-frame buffers.
    pub slot: usize,
    pub timer: &'a mut PassTimer,
    pub scene: &'a Scene,
    pub camera: &'a CameraProjection,
    /// `FrameGlobals` of this frame.
    pub globals: vk::DescriptorBufferInfo,
    /// `ObjectData` of every draw.
    pub objects: vk::DescriptorBufferInfo,
    pub draws: &'a [Draw],
    /// Camera depth and normal, ready to be sampled.
    pub depth: &'a Target,
    pub normal: &'a Target,
    /// Points whose hull is the receivers' visible part: no shadow matters outside it.
    pub receivers_in_view: &'a [Vec3],
    /// CPU work of the technique's that the timings show apart, as (name, ms): the renderer
    /// cuts it out of the frame's `technique` span.
    pub cpu_spans: Vec<(&'static str, f64)>,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shadow_roles_round_trip_through_their_encoding() {
        for (receives, casts) in [(false, false), (false, true), (true, false), (true, true)] {
            let role = ShadowRole::new(receives, casts);
            assert_eq!(ShadowRole::receives(role.encode()), receives, "{role:?}");
            assert_eq!(ShadowRole::casts(role.encode()), receives && casts, "{role:?}");
        }
    }
}
