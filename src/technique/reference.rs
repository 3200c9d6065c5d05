//! `reference`: ground truth on the GPU by Heckbert & Herf's accumulation ("Simulating Soft
//! Shadows with Graphics Hardware", 1997): hard shadows from many points on the area light,
//! averaged.
//!
//! V is defined (DESIGN.md §3) as the unblocked fraction of the solid angle the spherical light
//! subtends at p. The points ([`light_points`]) are spread half uniformly in area over the cap
//! of the sphere that any receiver in view can see, half uniformly in the solid angle at the
//! receivers' centre (which a huge light near them needs); each one stands for a patch of the
//! surface whose solid angle at p is max(0, cos θ_q)·dA / |p − q|², over the density it was
//! drawn with, so the accumulation weights each sample by that per pixel and divides by the
//! sum of the weights. Samples facing away from p weigh 0, which is what makes the estimate
//! right far from the light's axis too. A light too small to place points on is a point.
//!
//! Batching: the shadow maps of up to 16 samples are rendered into the tiles of one atlas, then
//! one full-screen pass adds all of their contributions at once (additive blending into an
//! RG32F sum), so N samples cost N/16 accumulation passes instead of N.

use ash::vk;
use bytemuck::{Zeroable as _, cast_slice};
use glam::{Vec3, Vec4};

use super::knobs::{Knob, Params};
use super::registry::{APPROXIMATION_BOUND, Kind, Receivers, Runs, SweepKnobs, TechniqueInfo};
use super::shadow_map::{
    DEFAULT_BIASES, EMPTY_DEPTH, SHADOW_MAP_SIZE, caster_bounds, depth_pipeline, draw_casters, warn_clipped,
};
use super::{Technique, clear_visibility, resolve};
use crate::error::Result;
use crate::frame::FrameInputs;
use crate::frame::interface::{LightSample, LightView};
use crate::geometry::{fit_spot_frustum, light_points};
use crate::gpu::{
    Access, Attachment, Blend, Context, Descriptor, FRAMES_IN_FLIGHT, Fullscreen, Guard, Milestones, PerFrame,
    Pipeline, RenderPass, Target, TargetDesc, draw_fullscreen, ensure, shaders, transition,
};

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "reference",
    summary: "ground truth: N hard shadows from points on the light, weighted by solid angle (Heckbert & Herf)",
    kind: Kind::GroundTruth(Runs::Gpu),
    knobs: &[SAMPLES, MAP_SIZE],
    create: |ctx, _, visibility| Ok(Box::new(Reference::new(ctx, visibility)?)),
    bench: &[],
    // Fewer samples than the default keep the short grids quick on lavapipe; beyond the size
    // where only soundness is checked, 4 (the same code, a fraction of the minutes).
    sweep_knobs: SweepKnobs {
        short: &[("samples", "64"), ("shadow_map_size", "256")],
        long: &[("samples", "256"), ("shadow_map_size", "1024")],
        huge: &[("samples", "4"), ("shadow_map_size", "256")],
    },
    cost_goal: None,
    receivers: Receivers::All,
    error_bound: Some(APPROXIMATION_BOUND),
};

const SAMPLES: Knob = Knob {
    name: "samples",
    default: 256.0,
    min: 1.0,
    max: 4096.0,
    integer: true,
    choices: &[],
    help: "points on the light, one shadow map each",
};
/// 2048 by default: each sample's hard edge moves by about a texel of its biases, which from a
/// light close to its caster (a frustum as wide as the cube seen from 0.6 of its side) put
/// 1024² maps 0.0125 RMSE off the ray tracer in the penumbrae, over the truths' 0.01 (issue 19);
/// 2048²: 0.006, 4096²: 0.003.
const MAP_SIZE: Knob = Knob { default: 2048.0, max: 4096.0, ..SHADOW_MAP_SIZE };

/// Tiles per atlas side at most: 16 shadow maps per accumulation pass.
const MAX_TILES: u32 = 4;
const SAMPLE_BYTES: u64 = std::mem::size_of::<LightSample>() as u64;
const SUM_FORMAT: vk::Format = vk::Format::R32G32_SFLOAT;

pub struct Reference {
    depth: Pipeline,
    accumulate: Pipeline,
    resolve: Pipeline,
    samples: Option<PerFrame>,
    atlas: Option<Target>,
    atlas_depth: Option<Target>,
    sums: Option<Target>,
    /// One milestone per batch, per frame slot: progress of long frames.
    milestones: Vec<Milestones>,
}

impl Reference {
    /// `visibility`: the format of the V target the resolve writes.
    pub fn new(ctx: &Context, visibility: vk::Format) -> Result<Self> {
        let depth = Guard::new(ctx, depth_pipeline(ctx, vk::Format::R32_SFLOAT)?);
        let accumulate =
            Fullscreen::new("accumulate", &shaders::REFERENCE_ACCUMULATE_FRAG, SUM_FORMAT).blend(Blend::Add);
        let accumulate = Guard::new(ctx, Pipeline::fullscreen(ctx, &accumulate)?);
        let resolve =
            Pipeline::fullscreen(ctx, &Fullscreen::new("resolve", &shaders::REFERENCE_RESOLVE_FRAG, visibility))?;
        Ok(Reference {
            depth: depth.keep(),
            accumulate: accumulate.keep(),
            resolve,
            samples: None,
            atlas: None,
            atlas_depth: None,
            sums: None,
            milestones: Vec::new(),
        })
    }

    /// The light samples of this frame, each with its fitted frustum.
    fn light_samples(frame: &FrameInputs<'_>, n: usize, size: u32) -> Vec<LightSample> {
        let light = &frame.scene.light;
        let casters = caster_bounds(frame);
        let points = light_points(light.position, light.radius, frame.receivers_in_view, n);
        let mut clipped = Vec::new();
        let samples = points
            .into_iter()
            .map(|point| {
                let q = point.position;
                let fit = fit_spot_frustum(q, light.target, &casters, frame.receivers_in_view);
                clipped.extend(fit.clipped);
                let frustum = fit.frustum;
                let view = frustum.map_or(LightView::zeroed(), |f| LightView {
                    view: f.view,
                    view_proj: f.view_proj,
                    extent: Vec4::from(f.window),
                    bias: Vec4::from((Vec3::from(DEFAULT_BIASES), size as f32)),
                    kernel: Vec4::ZERO,
                    depths: f.depths(),
                });
                let has_map = if frustum.is_some() { 1.0 } else { 0.0 };
                LightSample {
                    view,
                    position: q.extend(has_map),
                    normal: point.normal.extend(point.weight),
                    pad: [Vec4::ZERO; 2],
                }
            })
            .collect();
        clipped.sort_unstable();
        clipped.dedup();
        warn_clipped(frame, &clipped);
        samples
    }
}

/// `len` bytes of `base` from `offset`.
fn sub_range(base: vk::DescriptorBufferInfo, offset: u64, len: u64) -> vk::DescriptorBufferInfo {
    vk::DescriptorBufferInfo { buffer: base.buffer, offset: base.offset + offset, range: len }
}

impl Technique for Reference {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        if !frame.draws.iter().any(|d| d.casts) || frame.receivers_in_view.is_empty() {
            return clear_visibility(frame, visibility);
        }
        let ctx = frame.ctx;
        let size = params.get(&MAP_SIZE) as u32;
        let samples = Self::light_samples(frame, params.get(&SAMPLES) as usize, size);

        let bytes = samples.len() as u64 * SAMPLE_BYTES;
        let usage = vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        let buffer = PerFrame::ensure(ctx, &mut self.samples, "light samples", bytes, usage)?;
        buffer.write(frame.slot, cast_slice(&samples));
        let base = buffer.range(frame.slot);

        let tiles = MAX_TILES.min(ctx.info.max_image_dimension_2d / size).max(1);
        let side = tiles * size;
        ensure(ctx, &mut self.atlas, TargetDesc::color("reference atlas", vk::Format::R32_SFLOAT, side, side))?;
        ensure(ctx, &mut self.atlas_depth, TargetDesc::depth("reference atlas depth", side, side))?;
        let extent = visibility.extent();
        ensure(ctx, &mut self.sums, TargetDesc::color("reference sums", SUM_FORMAT, extent.width, extent.height))?;
        let (atlas, atlas_depth, sums) = (
            self.atlas.as_mut().expect("ensured"),
            self.atlas_depth.as_mut().expect("ensured"),
            self.sums.as_mut().expect("ensured"),
        );

        let cmd = frame.cmd;
        let per_batch = (tiles * tiles) as usize;
        let batches = samples.len().div_ceil(per_batch) as u32;
        if self.milestones.first().is_none_or(|m| m.capacity() < batches) {
            // Grows only; the old pools may still be written by the frame in flight.
            let old = std::mem::take(&mut self.milestones);
            ctx.retire(move |ctx| old.into_iter().for_each(|m| m.destroy(ctx)));
            for _ in 0..FRAMES_IN_FLIGHT {
                self.milestones.push(Milestones::new(ctx, batches)?);
            }
        }
        let milestones = &mut self.milestones[frame.slot];
        milestones.reset(ctx, cmd);
        frame.timer.begin(ctx, cmd, "accumulate");
        for (b, batch) in samples.chunks(per_batch).enumerate() {
            let first = (b * per_batch) as u64 * SAMPLE_BYTES;
            // The previous batch's maps have been summed: discard them.
            transition(ctx, cmd, &mut [(atlas, Access::COLOR_WRITE, true), (atlas_depth, Access::DEPTH_WRITE, true)]);
            let pass = RenderPass::begin(
                ctx,
                cmd,
                &[Attachment::clear_color(atlas, [EMPTY_DEPTH; 4])],
                Some(Attachment::clear_depth(atlas_depth, 1.0)),
            );
            for (i, sample) in batch.iter().enumerate().filter(|(_, s)| s.position.w > 0.0) {
                let i = i as u32;
                let offset = vk::Offset2D { x: ((i % tiles) * size) as i32, y: ((i / tiles) * size) as i32 };
                pass.set_area(ctx, cmd, vk::Rect2D { offset, extent: vk::Extent2D { width: size, height: size } });
                let light =
                    sub_range(base, first + i as u64 * SAMPLE_BYTES, std::mem::size_of_val(&sample.view) as u64);
                self.depth.bind(ctx, cmd, &[Descriptor::Buffer(light), Descriptor::Buffer(frame.objects)])?;
                draw_casters(frame);
            }
            pass.end(ctx, cmd);

            // The first batch starts the sums; later ones add to them.
            transition(ctx, cmd, &mut [(atlas, Access::FRAGMENT_READ, false), (sums, Access::COLOR_WRITE, b == 0)]);
            let target =
                if b == 0 { Attachment::clear_color(sums, [0.0; 4]) } else { Attachment { target: sums, clear: None } };
            let pass = RenderPass::begin(ctx, cmd, &[target], None);
            self.accumulate.bind(
                ctx,
                cmd,
                &[
                    Descriptor::Buffer(frame.globals),
                    Descriptor::Buffer(sub_range(base, first, batch.len() as u64 * SAMPLE_BYTES)),
                    Descriptor::Image(frame.depth),
                    Descriptor::Image(frame.normal),
                    Descriptor::Image(atlas),
                ],
            )?;
            draw_fullscreen(ctx, cmd);
            pass.end(ctx, cmd);
            milestones.mark(ctx, cmd);
        }
        transition(ctx, cmd, &mut [(sums, Access::FRAGMENT_READ, false)]);
        frame.timer.end(ctx, cmd);

        resolve(frame, &self.resolve, visibility, &[Descriptor::Image(sums)])
    }

    fn progress(&self, ctx: &Context, slot: usize) -> Option<(u32, u32)> {
        self.milestones.get(slot).map(|m| m.reached(ctx))
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        let this = *self;
        this.milestones.into_iter().for_each(|m| m.destroy(ctx));
        for p in [this.depth, this.accumulate, this.resolve] {
            p.destroy(ctx);
        }
        this.samples.into_iter().for_each(|b| b.destroy(ctx));
        this.atlas.into_iter().chain(this.atlas_depth).chain(this.sums).for_each(|t| t.destroy(ctx));
    }
}
