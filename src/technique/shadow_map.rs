//! `shadow-map`: hard shadows from the light's centre (Williams 1978), the baseline every soft
//! technique is measured against, and pass 1 of the smoothie and PCF/PCSS techniques.
//!
//! The map stores linear light-space depth in R32_SFLOAT through a spot frustum fitted every
//! frame ([`fit_spot_frustum`]). The resolve compares each camera pixel's light depth against
//! the four nearest texels and filters the results bilinearly. Biases are measured in shadow-map
//! texels at the receiver (constant + slope-scaled, plus a normal offset), so they hold at any
//! scene scale and map size.

use ash::vk;
use bytemuck::bytes_of;
use glam::{Vec3, Vec4};

use super::knobs::{Knob, Params, TechniqueInfo};
use super::{FrameInputs, Technique, clear_visibility};
use crate::error::Result;
use crate::geometry::{Aabb, LightFrustum, fit_spot_frustum};
use crate::gpu::{
    Access, Attachment, Binding, Blend, Context, DepthState, Descriptor, FRAMES_IN_FLIGHT, PerFrame, Pipeline,
    PipelineDesc, RenderPass, Target, TargetDesc, VertexInput, ensure, fullscreen, shaders, transition,
};
use crate::gpu_types::LightView;

pub const INFO: TechniqueInfo = TechniqueInfo {
    offline: false,
    name: "shadow-map",
    summary: "hard shadows from the light's centre: one shadow map, 2x2 bilinear comparison",
    knobs: &[
        SHADOW_MAP_SIZE,
        Knob {
            name: "depth_bias",
            default: 1.0,
            min: 0.0,
            max: 64.0,
            integer: false,
            help: "constant depth bias, in shadow-map texels",
        },
        Knob {
            name: "slope_bias",
            default: 1.0,
            min: 0.0,
            max: 64.0,
            integer: false,
            help: "depth bias per unit tan(angle to the light), in texels",
        },
        Knob {
            name: "normal_offset",
            default: 1.5,
            min: 0.0,
            max: 64.0,
            integer: false,
            help: "lookup offset along the normal at grazing angles, in texels",
        },
    ],
};

/// Shared by every technique that renders a shadow map.
pub const SHADOW_MAP_SIZE: Knob = Knob {
    name: "shadow_map_size",
    default: 2048.0,
    min: 16.0,
    max: 16384.0,
    integer: true,
    help: "shadow map width and height, in texels",
};

/// Linear depth cleared beyond any caster: "nothing blocks this texel".
pub(crate) const EMPTY_DEPTH: f32 = f32::MAX;

/// Renders the casters' linear light depth (R32_SFLOAT) through the `LightView` at binding 0.
pub(crate) fn depth_pipeline(ctx: &Context) -> Result<Pipeline> {
    Pipeline::new(
        ctx,
        &PipelineDesc {
            name: "shadow_map",
            vertex: shaders::SHADOW_MAP_DEPTH_VERT,
            fragment: shaders::SHADOW_MAP_DEPTH_FRAG,
            bindings: &[
                (Binding::Uniform, vk::ShaderStageFlags::VERTEX),
                (Binding::Storage, vk::ShaderStageFlags::VERTEX),
            ],
            vertex_input: VertexInput::Position,
            color_formats: &[vk::Format::R32_SFLOAT],
            depth: Some(DepthState { format: vk::Format::D32_SFLOAT, compare: vk::CompareOp::LESS }),
            blend: Blend::None,
        },
    )
}

/// Records every caster of the frame (inside a pass whose pipeline is bound).
pub(crate) fn draw_casters(frame: &FrameInputs<'_>) {
    for draw in frame.draws.iter().filter(|d| d.casts) {
        draw.record(frame.ctx, frame.cmd);
    }
}

/// Pass 1: linear light-space depth of the casters through the fitted spot frustum.
pub struct ShadowMapPass {
    pipeline: Pipeline,
    light: PerFrame,
    map: Option<Target>,
    depth: Option<Target>,
}

impl ShadowMapPass {
    pub fn new(ctx: &Context) -> Result<Self> {
        let pipeline = depth_pipeline(ctx)?;
        let usage = vk::BufferUsageFlags::UNIFORM_BUFFER;
        let light =
            match PerFrame::new(ctx, "light view", std::mem::size_of::<LightView>() as u64, FRAMES_IN_FLIGHT, usage) {
                Ok(l) => l,
                Err(e) => {
                    pipeline.destroy(ctx);
                    return Err(e);
                }
            };
        Ok(ShadowMapPass { pipeline, light, map: None, depth: None })
    }

    /// Fits the frustum; `None` when no receiver in view can be shadowed (nothing to render).
    pub fn fit(frame: &FrameInputs<'_>) -> Option<LightFrustum> {
        let casters: Vec<Vec3> = frame.draws.iter().filter(|d| d.casts).flat_map(|d| d.bounds.corners()).collect();
        if casters.is_empty() {
            return None;
        }
        let light = &frame.scene.light;
        // DESIGN.md §3: the spot looks at `light.target`, by default the casters' centre.
        let aim = light.target.unwrap_or_else(|| Aabb::from_points(casters.iter().copied()).center());
        fit_spot_frustum(light.position, aim, &casters, frame.receivers_in_view)
    }

    /// Records the map; afterwards it is ready to be sampled by fragment shaders.
    pub fn record(
        &mut self,
        frame: &mut FrameInputs<'_>,
        frustum: &LightFrustum,
        size: u32,
        bias: [f32; 3],
    ) -> Result<()> {
        let ctx = frame.ctx;
        ensure(ctx, &mut self.map, TargetDesc::color("shadow map", vk::Format::R32_SFLOAT, size, size))?;
        ensure(ctx, &mut self.depth, TargetDesc::depth("shadow map depth", size, size))?;
        let view = LightView {
            view: frustum.view,
            view_proj: frustum.view_proj,
            extent: Vec4::from(frustum.window),
            bias: Vec4::new(bias[0], bias[1], bias[2], size as f32),
        };
        self.light.write(frame.slot, bytes_of(&view));
        let (map, depth) = (self.map.as_mut().expect("ensured"), self.depth.as_mut().expect("ensured"));
        let cmd = frame.cmd;
        frame.timer.begin(ctx, cmd, "shadow_map");
        // Last frame's contents are not needed: discard them.
        transition(ctx, cmd, &mut [(map, Access::COLOR_WRITE, true), (depth, Access::DEPTH_WRITE, true)]);
        let pass = RenderPass::begin(
            ctx,
            cmd,
            &[Attachment::clear_color(map, [EMPTY_DEPTH; 4])],
            Some(Attachment::clear_depth(depth, 1.0)),
        );
        self.pipeline.bind(
            ctx,
            cmd,
            &[Descriptor::Buffer(self.light.range(frame.slot)), Descriptor::Buffer(frame.objects)],
        );
        draw_casters(frame);
        pass.end(ctx, cmd);
        transition(ctx, cmd, &mut [(map, Access::FRAGMENT_READ, false)]);
        frame.timer.end(ctx, cmd);
        Ok(())
    }

    /// The map (after [`Self::record`]) and this frame's light view.
    pub fn inputs(&self, slot: usize) -> (&Target, vk::DescriptorBufferInfo) {
        (self.map.as_ref().expect("recorded before use"), self.light.range(slot))
    }

    pub fn destroy(self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.light.destroy(ctx);
        self.map.into_iter().chain(self.depth).for_each(|t| t.destroy(ctx));
    }
}

/// The `shadow-map` technique: [`ShadowMapPass`], then a hard resolve into V.
pub struct ShadowMap {
    pass: ShadowMapPass,
    resolve: Pipeline,
}

impl ShadowMap {
    pub fn new(ctx: &Context) -> Result<Self> {
        let pass = ShadowMapPass::new(ctx)?;
        let b = [Binding::Uniform, Binding::Uniform, Binding::Sampled, Binding::Sampled, Binding::Sampled];
        let format = crate::renderer::VISIBILITY_FORMAT;
        let resolve = Pipeline::fullscreen(ctx, "resolve", shaders::SHADOW_MAP_RESOLVE_FRAG, &b, format);
        match resolve {
            Ok(resolve) => Ok(ShadowMap { pass, resolve }),
            Err(e) => {
                pass.destroy(ctx);
                Err(e)
            }
        }
    }
}

impl Technique for ShadowMap {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        let Some(frustum) = ShadowMapPass::fit(frame) else {
            return clear_visibility(frame, visibility);
        };
        let size = params.get("shadow_map_size") as u32;
        let bias = ["depth_bias", "slope_bias", "normal_offset"].map(|k| params.get(k) as f32);
        self.pass.record(frame, &frustum, size, bias)?;

        let (ctx, cmd) = (frame.ctx, frame.cmd);
        let (map, light) = self.pass.inputs(frame.slot);
        frame.timer.begin(ctx, cmd, "resolve");
        transition(ctx, cmd, &mut [(visibility, Access::COLOR_WRITE, true)]);
        fullscreen(
            ctx,
            cmd,
            &self.resolve,
            visibility,
            &[
                Descriptor::Buffer(frame.globals),
                Descriptor::Buffer(light),
                Descriptor::Image(frame.depth),
                Descriptor::Image(frame.normal),
                Descriptor::Image(map),
            ],
        );
        frame.timer.end(ctx, cmd);
        Ok(())
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        self.pass.destroy(ctx);
        self.resolve.destroy(ctx);
    }
}
