//! Techniques: each owns its targets, pipelines and passes, and writes the visibility image V.
//! A technique builds only what the scene in front of it needs.

mod falloff;
pub mod knobs;
pub mod plateau;
pub mod reference;
pub mod shadow_map;
pub mod smoothie;
mod smoothie_gpu;
pub mod traced;

use ash::vk;
use glam::Vec3;

use crate::error::Result;
use crate::geometry::CameraProjection;
use crate::gpu::{Context, PassTimer, Target};
use crate::renderer::Draw;
use crate::scene::Scene;
pub use knobs::{Params, TECHNIQUES, TechniqueInfo};

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
}

/// A shadowing technique: records its passes and leaves V written (the composite transitions
/// it from whichever access wrote it).
pub trait Technique {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()>;
    /// The surfaces V was estimated at in the last frame, when the technique found them itself
    /// (a ray tracer) instead of reading the prepass.
    fn traced_surfaces(&self) -> Option<&crate::renderer::Surfaces> {
        None
    }
    /// For GPU work of many seconds: (steps done, steps) of the frame in `slot`, polled while
    /// the host waits for it.
    fn progress(&self, _ctx: &Context, _slot: usize) -> Option<(u32, u32)> {
        None
    }
    fn destroy(self: Box<Self>, ctx: &Context);
}

/// Creates the technique `info` names.
pub fn create(ctx: &Context, info: &'static TechniqueInfo, visibility: vk::Format) -> Result<Box<dyn Technique>> {
    match info.name {
        name if [shadow_map::INFO.name, shadow_map::PCF.name, shadow_map::PCSS.name].contains(&name) => {
            Ok(Box::new(shadow_map::ShadowMap::new(ctx, info, visibility)?))
        }
        name if name == reference::INFO.name => Ok(Box::new(reference::Reference::new(ctx, visibility)?)),
        name if name == plateau::INFO.name => Ok(Box::new(plateau::Plateau::new(ctx, visibility)?)),
        name if name == smoothie::INFO.name => Ok(Box::new(smoothie::Smoothie::new(ctx, visibility)?)),
        name if name == traced::RAYTRACE.name => Ok(Box::new(traced::Traced::new(traced::Method::Exact))),
        name if name == traced::PARKER.name => Ok(Box::new(traced::Traced::new(traced::Method::Parker))),
        other => Err(crate::Error::Invalid(format!("technique `{other}` is listed but not built"))),
    }
}

/// The first inputs of every resolve that reads the camera's surfaces, in binding order: the
/// frame's globals, the technique's `light` (view) buffer, camera depth, camera normal.
pub(crate) fn surface_inputs<'a>(
    frame: &FrameInputs<'a>,
    light: vk::DescriptorBufferInfo,
) -> [crate::gpu::Descriptor<'a>; 4] {
    use crate::gpu::Descriptor;
    [
        Descriptor::Buffer(frame.globals),
        Descriptor::Buffer(light),
        Descriptor::Image(frame.depth),
        Descriptor::Image(frame.normal),
    ]
}

/// The `resolve` pass every technique ends with: V overwritten by the full-screen `pipeline`
/// reading `inputs` (already made readable).
pub(crate) fn resolve(
    frame: &mut FrameInputs<'_>,
    pipeline: &crate::gpu::Pipeline,
    visibility: &mut Target,
    inputs: &[crate::gpu::Descriptor<'_>],
) {
    use crate::gpu::{Access, fullscreen, transition};
    let (ctx, cmd) = (frame.ctx, frame.cmd);
    frame.timer.begin(ctx, cmd, "resolve");
    transition(ctx, cmd, &mut [(visibility, Access::COLOR_WRITE, true)]);
    fullscreen(ctx, cmd, pipeline, visibility, inputs);
    frame.timer.end(ctx, cmd);
}

/// Writes V = 1 everywhere: the scene in view has nothing that can shadow a receiver, so no
/// technique targets or passes are needed this frame.
pub(crate) fn clear_visibility(frame: &mut FrameInputs<'_>, visibility: &mut Target) -> Result<()> {
    use crate::gpu::{Access, Attachment, RenderPass, transition};
    let (ctx, cmd) = (frame.ctx, frame.cmd);
    frame.timer.begin(ctx, cmd, "resolve");
    transition(ctx, cmd, &mut [(visibility, Access::COLOR_WRITE, true)]);
    RenderPass::begin(ctx, cmd, &[Attachment::clear_color(visibility, [1.0; 4])], None).end(ctx, cmd);
    frame.timer.end(ctx, cmd);
    Ok(())
}
