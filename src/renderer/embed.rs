//! The embedded frame (DESIGN.md §3 "Embedding"): the embedder's camera and depth (and
//! optionally normals) in, the technique's passes recorded into the embedder's command buffer,
//! V out, with the state each image is left in.
//!
//! The embedder's depth carries no shadow roles, so the import pass makes the camera surfaces
//! every technique reads ([`FrameInputs`](crate::frame::FrameInputs) is unchanged): its depth in
//! the engine's convention (reverse Z, D32), and every surface it saw a receiver
//! ([`ShadowRole::Receives`](crate::frame::ShadowRole)). Then the engine's own casters (the
//! scene's objects that cast) are drawn over it: where a caster's fragment lies on the surface
//! the embedder saw, the pixel takes that object's role ([`ShadowRole::ReceivesAndCasts`] for
//! a caster that receives) and its exact facet normal, as the engine's own prepass writes them.
//! Elsewhere the normal is the embedder's, or, without a normal image, rebuilt from the depth of
//! neighbouring pixels.
//!
//! [`ShadowRole::ReceivesAndCasts`]: crate::frame::ShadowRole::ReceivesAndCasts

use ash::vk;
use glam::Mat4;

use super::passes::NORMAL_FORMAT;
use crate::error::{Error, Result};
use crate::frame::{Draw, MESH_POSITIONS_NORMALS};
use crate::gpu::{
    Access, Attachment, Context, DepthState, Descriptor, Frame, Pipeline, PipelineDesc, RenderPass, Target, TargetDesc,
    Variants, draw_fullscreen, shaders, transition,
};

/// The embedder's camera for one frame, as it renders with it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EmbedderCamera {
    /// World → view.
    pub view: Mat4,
    /// View → Vulkan clip space (y down, depth in [0, 1]).
    pub projection: Mat4,
    /// Depth 1 at the near plane and 0 at the far one (cleared to 0), or the other way round.
    pub reverse_z: bool,
    /// Distances along the view axis bounding what the camera sees (finite, even for an
    /// infinite projection): the frustum the engine fits shadow maps to.
    pub near: f32,
    pub far: f32,
}

/// One of the embedder's images. The engine makes (and destroys, once the frame has finished)
/// its own views of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct EmbedderImage {
    pub image: vk::Image,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    /// The layout it is in when the engine's commands begin, and the stage and access of the
    /// last command before them that touched it: the engine's first barrier waits on those.
    pub last: Access,
}

/// What the embedder hands [`Engine::record`](super::Engine::record) each frame.
#[derive(Clone, Copy, Debug)]
pub struct EmbeddedFrame {
    /// A primary command buffer in the recording state, outside a render pass.
    pub cmd: vk::CommandBuffer,
    pub camera: EmbedderCamera,
    /// Camera depth: [`DEPTH_FORMATS`], usage `SAMPLED`; only read.
    pub depth: EmbedderImage,
    /// World-space normals ([`NORMAL_FORMATS`], usage `SAMPLED`), the depth's size; only read.
    /// Without one, facet normals are rebuilt from depth.
    pub normal: Option<EmbedderImage>,
    /// Where V goes: an image of the engine's visibility format ([`VISIBILITY_FORMAT`]) and the
    /// depth's size, usage `COLOR_ATTACHMENT`; without one, a target the engine owns.
    ///
    /// [`VISIBILITY_FORMAT`]: crate::frame::VISIBILITY_FORMAT
    pub visibility: Option<EmbedderImage>,
}

/// The state [`Engine::record`](super::Engine::record) leaves each image in, once the
/// recorded commands have run: start the next barrier from these.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Recorded {
    /// The embedder's depth: sampled by fragment shaders, in `DEPTH_READ_ONLY_OPTIMAL`
    /// (`DEPTH_STENCIL_READ_ONLY_OPTIMAL` for a format with stencil).
    pub depth: Access,
    /// The embedder's normals, if given: [`Access::FRAGMENT_READ`].
    pub normal: Option<Access>,
    /// V: [`Access::FRAGMENT_READ`], ready for the embedder's fragment shaders to sample.
    pub visibility: Access,
    /// V's image: the embedder's, or the engine's own target (alive until the frame size changes
    /// or the engine is dropped).
    pub visibility_image: vk::Image,
    /// A view of V: the engine's, alive as long as its image (for the embedder's own image, it
    /// lives until the frame in flight after next has begun).
    pub visibility_view: vk::ImageView,
}

/// Depth formats the engine reads.
pub const DEPTH_FORMATS: [vk::Format; 6] = [
    vk::Format::D16_UNORM,
    vk::Format::X8_D24_UNORM_PACK32,
    vk::Format::D32_SFLOAT,
    vk::Format::D16_UNORM_S8_UINT,
    vk::Format::D24_UNORM_S8_UINT,
    vk::Format::D32_SFLOAT_S8_UINT,
];

/// Normal formats the engine reads: UNORM ones hold n/2 + 1/2, the others n.
pub const NORMAL_FORMATS: [vk::Format; 8] = [
    vk::Format::R16G16B16A16_SFLOAT,
    vk::Format::R32G32B32A32_SFLOAT,
    vk::Format::R16G16B16A16_SNORM,
    vk::Format::R8G8B8A8_SNORM,
    vk::Format::R8G8B8A8_UNORM,
    vk::Format::B8G8R8A8_UNORM,
    vk::Format::A2B10G10R10_UNORM_PACK32,
    vk::Format::R16G16B16A16_UNORM,
];

fn normal_is_unorm(format: vk::Format) -> bool {
    matches!(
        format,
        vk::Format::R8G8B8A8_UNORM
            | vk::Format::B8G8R8A8_UNORM
            | vk::Format::A2B10G10R10_UNORM_PACK32
            | vk::Format::R16G16B16A16_UNORM
    )
}

impl EmbeddedFrame {
    /// Checks what the engine can check of the frame (handles are the embedder's word): formats,
    /// sizes, the command buffer. `visibility_format` is the engine's V format.
    pub(super) fn check(&self, visibility_format: vk::Format) -> Result<()> {
        let invalid = |what: String| Err(Error::Invalid(format!("embedded frame: {what}")));
        if self.cmd == vk::CommandBuffer::null() {
            return invalid("the command buffer is null".into());
        }
        let extent = self.depth.extent;
        let images = [
            Some(("depth", &self.depth)),
            self.normal.as_ref().map(|n| ("normal", n)),
            self.visibility.as_ref().map(|v| ("visibility", v)),
        ];
        for (name, image) in images.into_iter().flatten() {
            if image.image == vk::Image::null() {
                return invalid(format!("the {name} image is null"));
            }
            if image.extent != extent {
                let (e, d) = (image.extent, extent);
                return invalid(format!(
                    "the {name} image is {}x{}, the depth image {}x{}",
                    e.width, e.height, d.width, d.height
                ));
            }
        }
        if !DEPTH_FORMATS.contains(&self.depth.format) {
            return invalid(format!("depth format {:?} is none of {DEPTH_FORMATS:?}", self.depth.format));
        }
        if let Some(n) = &self.normal
            && !NORMAL_FORMATS.contains(&n.format)
        {
            return invalid(format!("normal format {:?} is none of {NORMAL_FORMATS:?}", n.format));
        }
        if let Some(v) = &self.visibility
            && v.format != visibility_format
        {
            return invalid(format!("visibility format {:?}: the engine writes V as {visibility_format:?}", v.format));
        }
        Ok(())
    }
}

/// The access a pass that samples the embedder's depth needs it in.
pub(super) fn depth_read(format: vk::Format) -> Access {
    let stencil = matches!(
        format,
        vk::Format::D16_UNORM_S8_UINT | vk::Format::D24_UNORM_S8_UINT | vk::Format::D32_SFLOAT_S8_UINT
    );
    if stencil { Access::DEPTH_STENCIL_FRAGMENT_READ } else { Access::DEPTH_FRAGMENT_READ }
}

/// The embedder's images of one frame, wrapped with views of our own (the images are theirs).
pub(super) struct Wrapped {
    pub depth: Target,
    pub normal: Option<Target>,
    pub visibility: Option<Target>,
}

impl Wrapped {
    pub fn new(ctx: &Context, frame: &EmbeddedFrame) -> Result<Self> {
        let sampled = |name, image: &EmbedderImage| {
            let desc = TargetDesc {
                name,
                format: image.format,
                extent: image.extent,
                usage: vk::ImageUsageFlags::SAMPLED,
                reinterpreted: None,
            };
            Target::wrap_for_sampling(ctx, desc, image.image, image.last)
        };
        let mut made = Wrapped { depth: sampled("embedder depth", &frame.depth)?, normal: None, visibility: None };
        let rest = (|| {
            if let Some(n) = &frame.normal {
                made.normal = Some(sampled("embedder normal", n)?);
            }
            if let Some(v) = &frame.visibility {
                let desc = TargetDesc::color("embedder visibility", v.format, v.extent.width, v.extent.height);
                made.visibility = Some(Target::wrap(ctx, desc, v.image, None, v.last)?);
            }
            Ok(())
        })();
        match rest {
            Ok(()) => Ok(made),
            Err(e) => {
                made.into_targets().into_iter().for_each(|t| t.destroy(ctx));
                Err(e)
            }
        }
    }

    pub fn into_targets(self) -> Vec<Target> {
        std::iter::once(self.depth).chain(self.normal).chain(self.visibility).collect()
    }
}

/// The import pass: the embedder's depth (and normals) into the engine's camera depth and
/// normal targets, then the engine's casters marked on them.
pub struct Import {
    /// Keyed by (normals given, reverse Z, UNORM normals).
    surfaces: Variants<(bool, bool, bool)>,
    casters: Pipeline,
}

/// What the import pass reads and writes.
pub(super) struct ImportTargets<'a> {
    pub depth: &'a mut Target,
    pub normal: &'a mut Target,
    pub embedder_depth: &'a mut Target,
    pub embedder_normal: Option<&'a mut Target>,
}

impl Import {
    pub fn new(ctx: &Context) -> Result<Self> {
        let desc = PipelineDesc::new("caster roles", &shaders::PREPASS_SCENE_VERT, &shaders::EMBED_CASTERS_FRAG)
            .vertex_input(MESH_POSITIONS_NORMALS)
            .colors(&[NORMAL_FORMAT]);
        Ok(Import { surfaces: Variants::default(), casters: Pipeline::new(ctx, &desc)? })
    }

    /// Records the pass as `import`; leaves depth and normal ready for the technique.
    pub fn record(
        &mut self,
        ctx: &Context,
        frame: &mut Frame<'_>,
        t: ImportTargets<'_>,
        reverse_z: bool,
        inputs: [vk::DescriptorBufferInfo; 2],
        draws: &[Draw],
    ) -> Result<()> {
        let cmd = frame.cmd;
        frame.timer.begin(ctx, cmd, "import");
        let result = self.record_passes(ctx, cmd, t, reverse_z, inputs, draws);
        frame.timer.end(ctx, cmd);
        result
    }

    fn record_passes(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
        t: ImportTargets<'_>,
        reverse_z: bool,
        [globals, objects]: [vk::DescriptorBufferInfo; 2],
        draws: &[Draw],
    ) -> Result<()> {
        let ImportTargets { depth, normal, embedder_depth, embedder_normal } = t;
        let depth_access = depth_read(embedder_depth.desc.format);
        let unorm = embedder_normal.as_ref().is_some_and(|n| normal_is_unorm(n.desc.format));
        let key = (embedder_normal.is_some(), reverse_z, unorm);
        let pipeline = self.surfaces.get(key, |&(with_normal, reverse_z, unorm)| {
            let (name, shader) = match with_normal {
                true => ("import depth and normal", &shaders::EMBED_IMPORT_NORMAL_FRAG),
                false => ("import depth", &shaders::EMBED_IMPORT_FRAG),
            };
            let constants = [("REVERSE_Z", reverse_z as u32), ("NORMAL_UNORM", unorm as u32)];
            let constants = if with_normal { &constants[..] } else { &constants[..1] };
            let formats = [NORMAL_FORMAT];
            let desc = PipelineDesc::new(name, &shaders::COMMON_FULLSCREEN_VERT, shader)
                .colors(&formats)
                .depth(DepthState::test_write(vk::Format::D32_SFLOAT, vk::CompareOp::ALWAYS))
                .constants(constants);
            Pipeline::new(ctx, &desc)
        })?;
        // The embedder's images: from whatever wrote them to our fragment shaders' reads.
        let mut reads: Vec<(&mut Target, Access, bool)> = vec![(embedder_depth, depth_access, false)];
        if let Some(n) = embedder_normal {
            reads.push((n, Access::FRAGMENT_READ, false));
        }
        transition(ctx, cmd, &mut reads);
        transition(
            ctx,
            cmd,
            &mut [(&mut *depth, Access::DEPTH_WRITE, true), (&mut *normal, Access::COLOR_WRITE, true)],
        );
        let pass = RenderPass::begin(
            ctx,
            cmd,
            &[Attachment { target: normal, clear: None }],
            Some(Attachment { target: depth, clear: None }),
        );
        let mut inputs = vec![Descriptor::Buffer(globals), Descriptor::Image(&*reads[0].0)];
        if let Some((n, _, _)) = reads.get(1) {
            inputs.push(Descriptor::Image(n));
        }
        let bound = pipeline.bind(ctx, cmd, &inputs);
        if bound.is_ok() {
            draw_fullscreen(ctx, cmd);
        }
        pass.end(ctx, cmd);
        bound?;

        // The casters read the imported depth and overwrite their pixels' normal and role.
        transition(
            ctx,
            cmd,
            &mut [(&mut *depth, Access::DEPTH_FRAGMENT_READ, false), (&mut *normal, Access::COLOR_WRITE, false)],
        );
        let pass = RenderPass::begin(ctx, cmd, &[Attachment { target: normal, clear: None }], None);
        let bound = self.casters.bind(
            ctx,
            cmd,
            &[Descriptor::Buffer(globals), Descriptor::Buffer(objects), Descriptor::Image(depth)],
        );
        if bound.is_ok() {
            draws.iter().filter(|d| d.casts).for_each(|d| d.record(ctx, cmd));
        }
        pass.end(ctx, cmd);
        bound?;
        transition(ctx, cmd, &mut [(normal, Access::FRAGMENT_READ, false)]);
        Ok(())
    }

    pub fn destroy(self, ctx: &Context) {
        self.surfaces.destroy(ctx);
        self.casters.destroy(ctx);
    }
}
