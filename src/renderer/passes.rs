//! The passes every technique shares: the camera prepass before it and the composite after it.

use ash::vk;

use super::CameraTargets;
use crate::error::Result;
use crate::frame::{Draw, MESH_POSITIONS_NORMALS};
use crate::gpu::{
    Access, Attachment, Context, DepthState, Descriptor, Frame, Fullscreen, Guard, Pipeline, PipelineDesc, RenderPass,
    Target, fullscreen, is_srgb, shaders, transition,
};

/// Facet normal + shadow role, read by the techniques.
pub const NORMAL_FORMAT: vk::Format = vk::Format::R16G16B16A16_SFLOAT;
/// Interpolated normal as n/2 + 1/2, read by the composite.
pub const SHADING_FORMAT: vk::Format = vk::Format::A2B10G10R10_UNORM_PACK32;
pub const ALBEDO_FORMAT: vk::Format = vk::Format::R8G8B8A8_UNORM;
pub const COLOR_FORMAT: vk::Format = vk::Format::R8G8B8A8_SRGB;

/// Camera prepass: reverse-Z depth, facet normal with the shadow role, shading normal, albedo.
/// The meshes first, with the depth test before their shader (`glsl/prepass/scene.frag`), then
/// the ground, which writes its exact depth (`glsl/prepass/ground.frag`) and so is tested after
/// its shader: a shader that writes depth anywhere would turn the early test off for
/// everything it draws.
pub struct Prepass {
    meshes: Pipeline,
    ground: Pipeline,
}

impl Prepass {
    pub fn new(ctx: &Context) -> Result<Self> {
        let desc = |name, frag| {
            PipelineDesc::new(name, &shaders::PREPASS_SCENE_VERT, frag)
                .vertex_input(MESH_POSITIONS_NORMALS)
                .colors(&[NORMAL_FORMAT, SHADING_FORMAT, ALBEDO_FORMAT])
                // Reverse Z: nearer is greater.
                .depth(DepthState::test_write(vk::Format::D32_SFLOAT, vk::CompareOp::GREATER))
        };
        let meshes = Guard::new(ctx, Pipeline::new(ctx, &desc("prepass", &shaders::PREPASS_SCENE_FRAG))?);
        let ground = Pipeline::new(ctx, &desc("prepass ground", &shaders::PREPASS_GROUND_FRAG))?;
        Ok(Prepass { meshes: meshes.keep(), ground })
    }

    /// Draws the meshes, then the ground, in the draw list's order; leaves depth and normal
    /// ready for the technique and the composite.
    pub fn record(
        &self,
        ctx: &Context,
        frame: &mut Frame<'_>,
        t: &mut CameraTargets,
        inputs: [vk::DescriptorBufferInfo; 2],
        (meshes, ground): (&[Draw], Option<&Draw>),
    ) -> Result<()> {
        let cmd = frame.cmd;
        frame.timer.begin(ctx, cmd, "prepass");
        let shaded = t.shaded.as_mut().expect("the engine's own frames make the shading targets");
        transition(
            ctx,
            cmd,
            &mut [
                (&mut t.depth, Access::DEPTH_WRITE, true),
                (&mut t.normal, Access::COLOR_WRITE, true),
                (&mut shaded.shading, Access::COLOR_WRITE, true),
                (&mut shaded.albedo, Access::COLOR_WRITE, true),
            ],
        );
        let pass = RenderPass::begin(
            ctx,
            cmd,
            &[
                Attachment::clear_color(&t.normal, [0.0; 4]),
                Attachment::clear_color(&shaded.shading, [0.0; 4]),
                Attachment::clear_color(&shaded.albedo, [0.0; 4]),
            ],
            Some(Attachment::clear_depth(&t.depth, 0.0)),
        );
        let inputs = inputs.map(Descriptor::Buffer);
        self.meshes.bind(ctx, cmd, &inputs)?;
        for draw in meshes {
            draw.record(ctx, cmd);
        }
        if let Some(ground) = ground {
            self.ground.bind(ctx, cmd, &inputs)?;
            ground.record(ctx, cmd);
        }
        pass.end(ctx, cmd);
        transition(
            ctx,
            cmd,
            &mut [
                (&mut t.depth, Access::DEPTH_FRAGMENT_READ, false),
                (&mut t.normal, Access::FRAGMENT_READ, false),
                (&mut shaded.shading, Access::FRAGMENT_READ, false),
                (&mut shaded.albedo, Access::FRAGMENT_READ, false),
            ],
        );
        frame.timer.end(ctx, cmd);
        Ok(())
    }

    pub fn destroy(self, ctx: &Context) {
        self.meshes.destroy(ctx);
        self.ground.destroy(ctx);
    }
}

/// Composite: ambient + V·Lambert into the sRGB color target, or a swapchain image.
pub struct Composite {
    pipeline: Pipeline,
}

impl Composite {
    /// Writes `format`: sRGB-encoded by the hardware for an sRGB format, by the shader otherwise.
    pub fn new(ctx: &Context, format: vk::Format) -> Result<Self> {
        let constants = [("ENCODE_SRGB", u32::from(!is_srgb(format)))];
        let desc = Fullscreen::new("composite", &shaders::COMPOSITE_COMPOSITE_FRAG, format).constants(&constants);
        Ok(Composite { pipeline: Pipeline::fullscreen(ctx, &desc)? })
    }

    /// Composites into `into` (of this composite's format), or the engine's color target.
    pub fn record(
        &self,
        ctx: &Context,
        frame: &mut Frame<'_>,
        t: &mut CameraTargets,
        into: Option<&mut Target>,
        globals: vk::DescriptorBufferInfo,
    ) -> Result<()> {
        let cmd = frame.cmd;
        frame.timer.begin(ctx, cmd, "composite");
        let shaded = t.shaded.as_mut().expect("the engine's own frames make the shading targets");
        let color = into.unwrap_or(&mut shaded.color);
        transition(
            ctx,
            cmd,
            &mut [(&mut t.visibility, Access::FRAGMENT_READ, false), (color, Access::COLOR_WRITE, true)],
        );
        fullscreen(
            ctx,
            cmd,
            &self.pipeline,
            color,
            &[
                Descriptor::Buffer(globals),
                Descriptor::Image(&t.depth),
                Descriptor::Image(&shaded.shading),
                Descriptor::Image(&shaded.albedo),
                Descriptor::Image(&t.visibility),
            ],
        )?;
        frame.timer.end(ctx, cmd);
        Ok(())
    }

    pub fn destroy(self, ctx: &Context) {
        self.pipeline.destroy(ctx);
    }
}
