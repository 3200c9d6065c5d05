//! Soft shadows by accumulation (Komura, "soft shadowing by multiple point light sources";
//! Heckbert & Herf 1997), shared by `shadow-volume` and `planar`: N hard shadows from the
//! reference's points on the light ([`light_points`]), each added into an RG32F sum with the
//! reference's solid-angle weight (`glsl/common/light_samples.glsl`), then divided by the
//! reference's own resolve. N = 1 is the light's centre: the hard shadow of a point light.
//!
//! Each hard shadow is a stencil image; its accumulation is two full-screen draws under the
//! stencil test, one where it says lit and one where it says shadowed, which also leaves the
//! stencil ready for the next hard shadow.

use ash::vk;
use bytemuck::cast_slice;

use super::knobs::Knob;
use crate::error::Result;
use crate::frame::FrameInputs;
use crate::frame::interface::SampleView;
use crate::geometry::{LightPoint, light_points};
use crate::gpu::{
    Access, Attachment, Blend, Context, DepthState, Descriptor, Fullscreen, Guard, PerFrame, Pipeline, PipelineDesc,
    RenderPass, Target, TargetDesc, draw_fullscreen, ensure, shaders, transition,
};

pub(crate) const SAMPLES: Knob = Knob {
    name: "samples",
    default: 1.0,
    min: 1.0,
    max: 1024.0,
    integer: true,
    choices: &[],
    help: "points on the light, one hard shadow each, accumulated with the reference's weights",
};

const SUM_FORMAT: vk::Format = vk::Format::R32G32_SFLOAT;
const VIEW_BYTES: u64 = std::mem::size_of::<SampleView>() as u64;

/// A stencil state on both faces: test `compare` against `reference`, `pass` (and `depth_fail`)
/// on what passes, through the masks.
pub(crate) fn stencil(
    compare: vk::CompareOp,
    reference: u32,
    masks: (u32, u32),
    pass: vk::StencilOp,
    depth_fail: vk::StencilOp,
) -> vk::StencilOpState {
    vk::StencilOpState {
        fail_op: vk::StencilOp::KEEP,
        pass_op: pass,
        depth_fail_op: depth_fail,
        compare_op: compare,
        compare_mask: masks.0,
        write_mask: masks.1,
        reference,
    }
}

/// Where a hard shadow's stencil says lit and shadowed, and what the shadowed draw writes so
/// that the stencil is ready for the next hard shadow.
pub(crate) struct StencilRule {
    pub lit: (vk::CompareOp, u32),
    pub shadowed: (vk::CompareOp, u32, vk::StencilOp),
}

pub(crate) struct Accumulation {
    lit: Pipeline,
    shadowed: Pipeline,
    resolve: Pipeline,
    views: Option<PerFrame>,
    sums: Option<Target>,
}

impl Accumulation {
    pub fn new(ctx: &Context, depth_stencil: vk::Format, visibility: vk::Format, rule: StencilRule) -> Result<Self> {
        let formats = [SUM_FORMAT];
        let keep = vk::StencilOp::KEEP;
        let make = |shadowed: bool, state: vk::StencilOpState| {
            let constants = [("SHADOWED", shadowed as u32)];
            let desc = PipelineDesc::new(
                "accumulate",
                &shaders::COMMON_FULLSCREEN_VERT,
                &shaders::SHADOW_VOLUME_ACCUMULATE_FRAG,
            )
            .colors(&formats)
            .blend(Blend::Add)
            .depth(DepthState::test_only(depth_stencil, vk::CompareOp::ALWAYS))
            .stencil(state, state)
            .constants(&constants);
            Pipeline::new(ctx, &desc)
        };
        let (compare, reference) = rule.lit;
        let lit = Guard::new(ctx, make(false, stencil(compare, reference, (0xFF, 0), keep, keep))?);
        let (compare, reference, then) = rule.shadowed;
        let shadowed = Guard::new(ctx, make(true, stencil(compare, reference, (0xFF, 0xFF), then, then))?);
        let resolve =
            Pipeline::fullscreen(ctx, &Fullscreen::new("resolve", &shaders::REFERENCE_RESOLVE_FRAG, visibility))?;
        Ok(Accumulation { lit: lit.keep(), shadowed: shadowed.keep(), resolve, views: None, sums: None })
    }

    /// The light points of this frame: `n` over the part of the light the receivers see; one
    /// is the centre, the hard shadow every other technique's hard mode casts.
    pub fn points(frame: &FrameInputs<'_>, n: usize) -> Vec<LightPoint> {
        let light = &frame.scene.light;
        let radius = if n == 1 { 0.0 } else { light.radius };
        light_points(light.position, radius, frame.receivers_in_view, n)
    }

    /// Uploads this frame's views (one per light point) and sizes the sums like `extent`.
    pub fn prepare(&mut self, frame: &FrameInputs<'_>, views: &[SampleView], extent: vk::Extent2D) -> Result<()> {
        let ctx = frame.ctx;
        let bytes = views.len() as u64 * VIEW_BYTES;
        let buffer =
            PerFrame::ensure(ctx, &mut self.views, "sample views", bytes, vk::BufferUsageFlags::UNIFORM_BUFFER)?;
        buffer.write(frame.slot, cast_slice(views));
        ensure(ctx, &mut self.sums, TargetDesc::color("accumulated sums", SUM_FORMAT, extent.width, extent.height))
    }

    /// The view of light point `i` (after [`Self::prepare`]).
    pub fn view(&self, slot: usize, i: usize) -> vk::DescriptorBufferInfo {
        let base = self.views.as_ref().expect("prepared").range(slot);
        vk::DescriptorBufferInfo { buffer: base.buffer, offset: base.offset + i as u64 * VIEW_BYTES, range: VIEW_BYTES }
    }

    /// Adds hard shadow `i`, whose stencil `depth_stencil` holds, into the sums (the first
    /// starts them).
    pub fn add(&mut self, frame: &mut FrameInputs<'_>, depth_stencil: &mut Target, i: usize) -> Result<()> {
        let (ctx, cmd) = (frame.ctx, frame.cmd);
        let view = self.view(frame.slot, i);
        let sums = self.sums.as_mut().expect("prepared");
        transition(
            ctx,
            cmd,
            &mut [(sums, Access::COLOR_WRITE, i == 0), (depth_stencil, Access::DEPTH_STENCIL_WRITE, false)],
        );
        let target =
            if i == 0 { Attachment::clear_color(sums, [0.0; 4]) } else { Attachment { target: sums, clear: None } };
        let pass = RenderPass::begin(ctx, cmd, &[target], Some(Attachment { target: depth_stencil, clear: None }));
        let inputs = [
            Descriptor::Buffer(frame.globals),
            Descriptor::Buffer(view),
            Descriptor::Image(frame.depth),
            Descriptor::Image(frame.normal),
        ];
        let bound = self.lit.bind(ctx, cmd, &inputs).and_then(|_| {
            draw_fullscreen(ctx, cmd);
            self.shadowed.bind(ctx, cmd, &inputs)
        });
        if bound.is_ok() {
            draw_fullscreen(ctx, cmd);
        }
        pass.end(ctx, cmd);
        bound
    }

    /// V = the weighted sum of lit over the sum of weights.
    pub fn resolve(&mut self, frame: &mut FrameInputs<'_>, visibility: &mut Target) -> Result<()> {
        let sums = self.sums.as_mut().expect("prepared");
        transition(frame.ctx, frame.cmd, &mut [(sums, Access::FRAGMENT_READ, false)]);
        super::resolve(frame, &self.resolve, visibility, &[Descriptor::Image(sums)])
    }

    pub fn destroy(self, ctx: &Context) {
        for p in [self.lit, self.shadowed, self.resolve] {
            p.destroy(ctx);
        }
        self.views.into_iter().for_each(|b| b.destroy(ctx));
        self.sums.into_iter().for_each(|t| t.destroy(ctx));
    }
}

/// Opens a timed span when `timed` (single hard shadows are timed pass by pass; a frame of
/// many would overflow the timer, so the caller times it whole).
pub(crate) fn span(frame: &mut FrameInputs<'_>, timed: bool, name: &'static str) {
    if timed {
        frame.timer.begin(frame.ctx, frame.cmd, name);
    }
}

/// Closes a span opened by [`span`].
pub(crate) fn end_span(frame: &mut FrameInputs<'_>, timed: bool) {
    if timed {
        frame.timer.end(frame.ctx, frame.cmd);
    }
}
