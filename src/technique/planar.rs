//! `planar`: planar projected shadows (Blinn 1988, "Me and My (Fake) Shadow"; DDJ 2005
//! "planar shadows"; Komura "ground plane shadows"): the casters drawn a second time, flattened
//! onto the receiver plane from the light, soft by accumulating N of them.
//!
//! Passes: `projection` marks the pixels where the plane is the visible surface in the stencil
//! (from the camera prepass: Komura's "improving planar projected shadows with stencil"), then
//! draws the casters through Blinn's matrix in homogeneous form
//! ([`ReceiverPlane::blinn_matrix`], the plateau's), counting each marked pixel once: the
//! shadow lands only on the plane's extent, overlapping projected triangles darken once, and
//! with the depth test off no lift against z-fighting is needed. Points at or above the light
//! get w ≤ 0 and are clipped instead of casting an anti-shadow. Then each hard shadow is added
//! ([`Accumulation`]) and `resolve` divides.
//!
//! The paper's limit, kept: only the plane receives. Every other receiver, casters included,
//! keeps V = 1.

use ash::vk;
use glam::Vec4;

use super::accumulation::{Accumulation, SAMPLES, StencilRule, end_span, span, stencil};
use super::registry::{APPROXIMATION_BOUND, Kind, Receivers, SweepKnobs, TechniqueInfo};
use super::shadow_map::draw_casters;
use super::{Technique, clear_visibility};
use crate::error::Result;
use crate::frame::interface::SampleView;
use crate::frame::{FrameInputs, MESH_POSITIONS};
use crate::geometry::plateau::ReceiverPlane;
use crate::gpu::{
    Access, Attachment, Context, DepthState, Descriptor, Guard, Pipeline, PipelineDesc, RenderPass, Target, TargetDesc,
    draw_fullscreen, ensure, shaders, transition,
};
use crate::technique::knobs::Params;

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "planar",
    summary: "planar projected shadows: casters flattened onto the ground by Blinn's matrix, once per stencil pixel",
    kind: Kind::Realtime,
    knobs: &[SAMPLES],
    create: |ctx, _, visibility| Ok(Box::new(Planar::new(ctx, visibility)?)),
    bench: &[&[], &[("samples", "16")]],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::GroundPlane,
    error_bound: Some(APPROXIMATION_BOUND),
};

/// Stencil values: the plane is visible (1), and this hard shadow covers it (2).
const ON_PLANE: u32 = 1;
const SHADOWED: u32 = 2;

pub struct Planar {
    plane: Pipeline,
    projection: Pipeline,
    accumulation: Accumulation,
    format: vk::Format,
    stencil: Option<Target>,
}

impl Planar {
    pub fn new(ctx: &Context, visibility: vk::Format) -> Result<Self> {
        let format = ctx.depth_stencil_format();
        let (keep, always) = (vk::StencilOp::KEEP, vk::CompareOp::ALWAYS);
        let mark = stencil(always, ON_PLANE, (0xFF, 0xFF), vk::StencilOp::REPLACE, keep);
        let plane = PipelineDesc::new("plane", &shaders::COMMON_FULLSCREEN_VERT, &shaders::PLANAR_PLANE_FRAG)
            .depth(DepthState::test_only(format, always))
            .stencil(mark, mark);
        let plane = Guard::new(ctx, Pipeline::new(ctx, &plane)?);
        // Once per marked pixel: the first projected fragment moves it on to SHADOWED.
        let once = stencil(vk::CompareOp::EQUAL, ON_PLANE, (0xFF, 0xFF), vk::StencilOp::INCREMENT_AND_CLAMP, keep);
        let projection =
            PipelineDesc::new("projection", &shaders::PLANAR_PROJECTION_VERT, &shaders::SHADOW_VOLUME_STENCIL_FRAG)
                .vertex_input(MESH_POSITIONS)
                .depth(DepthState::test_only(format, always))
                .depth_clamp()
                .stencil(once, once);
        let projection = Guard::new(ctx, Pipeline::new(ctx, &projection)?);
        let rule = StencilRule {
            lit: (vk::CompareOp::EQUAL, ON_PLANE),
            shadowed: (vk::CompareOp::EQUAL, SHADOWED, vk::StencilOp::DECREMENT_AND_CLAMP),
        };
        let accumulation = Accumulation::new(ctx, format, visibility, rule)?;
        Ok(Planar { plane: plane.keep(), projection: projection.keep(), accumulation, format, stencil: None })
    }
}

impl Technique for Planar {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        let Some(ground) = frame.scene.ground else {
            return clear_visibility(frame, visibility); // no receiver plane: nothing receives
        };
        if !frame.draws.iter().any(|d| d.casts) || frame.receivers_in_view.is_empty() {
            return clear_visibility(frame, visibility);
        }
        let ctx = frame.ctx;
        let plane = ReceiverPlane::ground(ground.height);
        let samples = Accumulation::points(frame, params.get(&SAMPLES) as usize);
        let equation = plane.normal.extend(-plane.normal.dot(plane.origin));
        let views: Vec<SampleView> = samples
            .iter()
            .map(|s| (s.position, s.normal.extend(s.weight)))
            .map(|(q, normal)| SampleView {
                transform: frame.camera.view_proj * plane.blinn_matrix(q),
                light: q.extend(1.0),
                plane: equation,
                normal,
                pad: [Vec4::ZERO; 9],
            })
            .collect();
        let extent = visibility.extent();
        self.accumulation.prepare(frame, &views, extent)?;
        let desc = TargetDesc::depth_stencil("planar stencil", self.format, extent.width, extent.height);
        ensure(ctx, &mut self.stencil, desc)?;
        let target = self.stencil.as_mut().expect("ensured");
        let cmd = frame.cmd;
        let timed = samples.len() == 1;
        span(frame, !timed, "accumulate");
        for p in 0..samples.len() {
            let view = Descriptor::Buffer(self.accumulation.view(frame.slot, p));
            span(frame, timed, "projection");
            transition(ctx, cmd, &mut [(target, Access::DEPTH_STENCIL_WRITE, p == 0)]);
            let attachment = if p == 0 {
                Attachment::clear_depth_stencil(target, 0.0, 0)
            } else {
                Attachment { target, clear: None }
            };
            let pass = RenderPass::begin(ctx, cmd, &[], Some(attachment));
            if p == 0 {
                let inputs = [
                    Descriptor::Buffer(frame.globals),
                    view,
                    Descriptor::Image(frame.depth),
                    Descriptor::Image(frame.normal),
                ];
                self.plane.bind(ctx, cmd, &inputs)?;
                draw_fullscreen(ctx, cmd);
            }
            self.projection.bind(ctx, cmd, &[view, Descriptor::Buffer(frame.objects)])?;
            draw_casters(frame);
            pass.end(ctx, cmd);
            end_span(frame, timed);
            span(frame, timed, "accumulate");
            self.accumulation.add(frame, target, p)?;
            end_span(frame, timed);
        }
        end_span(frame, !timed);
        self.accumulation.resolve(frame, visibility)
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        let this = *self;
        this.plane.destroy(ctx);
        this.projection.destroy(ctx);
        this.accumulation.destroy(ctx);
        this.stencil.into_iter().for_each(|t| t.destroy(ctx));
    }
}
