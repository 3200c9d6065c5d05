//! Techniques: each owns its targets, pipelines and passes, and writes the visibility image V.
//! A technique builds only what the scene in front of it needs.

mod accumulation;
pub mod blob;
pub mod concentric;
mod falloff;
mod grid;
mod ground;
pub mod knobs;
mod object_ids;
pub mod planar;
pub mod plateau;
pub mod priority_map;
pub mod projective_texture;
pub mod reference;
pub mod registry;
pub mod shadow_map;
pub mod shadow_mesh;
pub mod shadow_volume;
mod shadow_volume_gpu;
pub mod smoothie;
mod smoothie_gpu;
pub mod traced;

use ash::vk;

use crate::error::Result;
use crate::frame::{FrameInputs, Surfaces};
use crate::gpu::{Context, Target};
pub use knobs::{Knob, Params};
pub use registry::{Kind, Runs, TechniqueInfo, find};

/// Every technique this build knows, in the order tools list them: the registry. Adding a
/// technique is one file beside this one that defines its [`TechniqueInfo`], its `mod` line
/// above, and its line here.
pub const TECHNIQUES: &[&TechniqueInfo] = &[
    &shadow_map::INFO,
    &shadow_map::PCF,
    &shadow_map::PCSS,
    &plateau::INFO,
    &smoothie::INFO,
    &shadow_volume::INFO,
    &planar::INFO,
    &blob::INFO,
    &concentric::INFO,
    &projective_texture::INFO,
    &priority_map::INFO,
    &reference::INFO,
    &traced::RAYTRACE,
    &traced::PARKER,
];

/// A shadowing technique: records its passes and leaves V written (the composite transitions
/// it from whichever access wrote it).
pub trait Technique {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()>;
    /// The surfaces V was estimated at in the last frame, when the technique found them itself
    /// (a ray tracer) instead of reading the prepass.
    fn traced_surfaces(&self) -> Option<&Surfaces> {
        None
    }
    /// For GPU work of many seconds: (steps done, steps) of the frame in `slot`, polled while
    /// the host waits for it.
    fn progress(&self, _ctx: &Context, _slot: usize) -> Option<(u32, u32)> {
        None
    }
    fn destroy(self: Box<Self>, ctx: &Context);
}

/// Refuses, naming the caster, a light so large or so close that some caster sees it wider
/// than `max_deg` (half-angle): past it, `technique`'s approximation stands for nothing, which
/// `why` says, with what to use instead.
pub(crate) fn refuse_wide_lights(scene: &crate::scene::Scene, technique: &str, max_deg: f64, why: &str) -> Result<()> {
    let (centre, radius) = (scene.light.position.as_dvec3(), scene.light.radius as f64);
    for o in scene.objects.iter().filter(|o| o.casts) {
        let b = o.bounds();
        let gap = (b.min.as_dvec3() - centre).max(centre - b.max.as_dvec3()).max(glam::DVec3::ZERO).length();
        let angle = if gap > radius { (radius / gap).asin().to_degrees() } else { 90.0 };
        if angle > max_deg {
            return Err(crate::error::Error::Invalid(format!(
                "{technique}: the light (radius {radius:e} m) spans {angle:.1}° from caster `{}`, over the {max_deg}° {why}",
                o.name
            )));
        }
    }
    Ok(())
}

/// The frame's light, taken nearer along its direction when it is farther than f32 resolves
/// the receivers in view and the casters that can shadow them from (`geometry::nearer_light`): the position and
/// radius of the light of the same direction and angular size. For the techniques that
/// project from the light themselves (Blinn's matrix from a light 1e8 m away lost a cube's
/// whole shadow, issue 19).
pub(crate) fn nearer_light(frame: &FrameInputs<'_>) -> (glam::Vec3, f32) {
    let casters = shadow_map::caster_bounds(frame);
    let light = &frame.scene.light;
    crate::geometry::nearer_light(light.position, light.radius, &casters, frame.receivers_in_view)
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
) -> Result<()> {
    use crate::gpu::{Access, fullscreen, transition};
    let (ctx, cmd) = (frame.ctx, frame.cmd);
    frame.timer.begin(ctx, cmd, "resolve");
    transition(ctx, cmd, &mut [(visibility, Access::COLOR_WRITE, true)]);
    fullscreen(ctx, cmd, pipeline, visibility, inputs)?;
    frame.timer.end(ctx, cmd);
    Ok(())
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
