//! The object each camera pixel sees, for the techniques whose test is per object
//! (`projective-texture`: a caster does not receive its own image; `priority-map`: a pixel
//! compares its object's priority with the map's): `object_ids`, the draw list once more at
//! camera resolution into R32_UINT, the draw's instance + 1 (0: no surface).
//!
//! A pass of their own rather than a fourth target of the shared prepass: the other
//! techniques pay nothing for it, and it works where the prepass does not run (an embedder
//! hands us its depth and normals, never object IDs). It repeats the prepass's transform
//! (`frame.view_proj * (model * position)`), so both rasterise the same pixels.

use ash::vk;

use crate::error::Result;
use crate::frame::{FrameInputs, MESH_POSITIONS};
use crate::gpu::{
    Access, Attachment, Context, DepthState, Descriptor, Pipeline, PipelineDesc, RenderPass, Target, TargetDesc,
    ensure, shaders, transition,
};

pub const ID_FORMAT: vk::Format = vk::Format::R32_UINT;

pub struct ObjectIds {
    pipeline: Pipeline,
    ids: Option<Target>,
    depth: Option<Target>,
}

impl ObjectIds {
    pub fn new(ctx: &Context) -> Result<Self> {
        let colors = [ID_FORMAT];
        let desc = PipelineDesc::new("object_ids", &shaders::OBJECT_IDS_IDS_VERT, &shaders::OBJECT_IDS_IDS_FRAG)
            .vertex_input(MESH_POSITIONS)
            .colors(&colors)
            // Reverse Z, as the prepass: nearer is greater.
            .depth(DepthState::test_write(vk::Format::D32_SFLOAT, vk::CompareOp::GREATER));
        Ok(ObjectIds { pipeline: Pipeline::new(ctx, &desc)?, ids: None, depth: None })
    }

    /// Records the pass; the IDs are then ready to be sampled by fragment shaders.
    pub fn record(&mut self, frame: &mut FrameInputs<'_>) -> Result<&Target> {
        let ctx = frame.ctx;
        let vk::Extent2D { width, height } = frame.depth.extent();
        ensure(ctx, &mut self.ids, TargetDesc::color("object ids", ID_FORMAT, width, height))?;
        ensure(ctx, &mut self.depth, TargetDesc::depth("object ids depth", width, height))?;
        let (ids, depth) = (self.ids.as_mut().expect("ensured"), self.depth.as_mut().expect("ensured"));
        let cmd = frame.cmd;
        frame.timer.begin(ctx, cmd, "object_ids");
        transition(ctx, cmd, &mut [(ids, Access::COLOR_WRITE, true), (depth, Access::DEPTH_WRITE, true)]);
        let pass = RenderPass::begin(
            ctx,
            cmd,
            &[Attachment::clear_uint(ids, [0; 4])],
            Some(Attachment::clear_depth(depth, 0.0)),
        );
        self.pipeline.bind(ctx, cmd, &[Descriptor::Buffer(frame.globals), Descriptor::Buffer(frame.objects)])?;
        for draw in frame.draws {
            draw.record(ctx, cmd);
        }
        pass.end(ctx, cmd);
        transition(ctx, cmd, &mut [(ids, Access::FRAGMENT_READ, false)]);
        frame.timer.end(ctx, cmd);
        Ok(ids)
    }

    pub fn destroy(self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.ids.into_iter().chain(self.depth).for_each(|t| t.destroy(ctx));
    }
}

impl crate::gpu::Destroy for ObjectIds {
    fn destroy(self, ctx: &Context) {
        ObjectIds::destroy(self, ctx)
    }
}
