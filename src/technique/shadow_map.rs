//! The shadow-map family: `shadow-map` (Williams 1978: hard shadows from the light's centre,
//! the baseline every soft technique is measured against), `pcf` (Reeves, Salesin & Cook 1987)
//! and `pcss` (Fernando 2005), the peers a game would otherwise ship. All three share one
//! [`ShadowMapPass`], also pass 1 of the smoothie, and one resolve skeleton
//! (`glsl/shadow_map/resolve.frag`) specialised by a constant per filter.
//!
//! The map stores linear light-space depth in R32_SFLOAT through a spot frustum fitted every
//! frame ([`fit_spot_frustum`]). Every lookup is a 2x2 bilinear comparison; biases are measured
//! in shadow-map texels at the receiver (constant + slope-scaled, plus a normal offset), so they
//! hold at any scene scale and map size.

use ash::vk;
use bytemuck::bytes_of;
use glam::Vec4;

use super::knobs::{Knob, Params};
use super::registry::{APPROXIMATION_BOUND, Kind, Receivers, SweepKnobs, TechniqueInfo};
use super::shadow_mesh::CasterMeshes;
use super::{Technique, clear_visibility, resolve, surface_inputs};
use crate::error::Result;
use crate::frame::interface::LightView;
use crate::frame::{FrameInputs, MESH_POSITIONS};
use crate::geometry::{Aabb, LightFrustum, fit_spot_frustum};
use crate::gpu::{
    Access, Attachment, Context, DepthState, Descriptor, Destroy, FRAMES_IN_FLIGHT, Fullscreen, Guard, PerFrame,
    Pipeline, PipelineDesc, RenderPass, Target, TargetDesc, Variants, ensure, shaders, transition,
};
use crate::shader_constants::{FILTER_BICUBIC, FILTER_DISK, FILTER_HARD, FILTER_PCSS};

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "shadow-map",
    summary: "hard shadows from the light's centre: one shadow map, 2x2 bilinear comparison",
    kind: Kind::Realtime,
    knobs: &[SHADOW_MAP_SIZE, DEPTH_BIAS, SLOPE_BIAS, NORMAL_OFFSET],
    create: ShadowMap::create,
    bench: &[&[], &[("shadow_map_size", "1024")]],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::All,
    error_bound: Some(APPROXIMATION_BOUND),
};

/// Percentage-closer filtering (Reeves, Salesin & Cook 1987) on the same map.
pub const PCF: TechniqueInfo = TechniqueInfo {
    name: "pcf",
    summary: "percentage-closer filtering: a rotated Vogel disk of taps, or the 4x4 bicubic of smoothie Fig. 7",
    kind: Kind::Realtime,
    knobs: &[SHADOW_MAP_SIZE, DEPTH_BIAS, SLOPE_BIAS, NORMAL_OFFSET, TAPS, RADIUS, RADIUS_WORLD, BICUBIC],
    create: ShadowMap::create,
    bench: &[&[("taps", "16")], &[("taps", "4")], &[("taps", "32")], &[("bicubic", "on")]],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::All,
    error_bound: Some(APPROXIMATION_BOUND),
};

/// Percentage-closer soft shadows (Fernando 2005) on the same map.
pub const PCSS: TechniqueInfo = TechniqueInfo {
    name: "pcss",
    summary: "percentage-closer soft shadows: blocker search, penumbra from similar triangles, PCF",
    kind: Kind::Realtime,
    knobs: &[SHADOW_MAP_SIZE, DEPTH_BIAS, SLOPE_BIAS, NORMAL_OFFSET, BLOCKER_SAMPLES, FILTER_SAMPLES, LIGHT_SIZE_SCALE],
    create: ShadowMap::create,
    bench: &[&[], &[("blocker_samples", "32"), ("filter_samples", "32")]],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::All,
    error_bound: Some(APPROXIMATION_BOUND),
};

const TAPS: Knob = Knob {
    name: "taps",
    default: 16.0,
    min: 1.0,
    max: 32.0,
    integer: true,
    choices: &[],
    help: "comparisons on the disk",
};
const RADIUS: Knob = Knob {
    name: "radius",
    default: 2.0,
    min: 0.0,
    max: 256.0,
    integer: false,
    choices: &[],
    help: "disk radius, in texels (or world units with radius_world = 1)",
};
const RADIUS_WORLD: Knob =
    Knob::switch("radius_world", "on: radius in world units at the receiver; off: in shadow-map texels");
const BICUBIC: Knob = Knob::switch("bicubic", "on: a 4x4 bicubic B-spline footprint instead of the disk");
const BLOCKER_SAMPLES: Knob = Knob {
    name: "blocker_samples",
    default: 16.0,
    min: 1.0,
    max: 64.0,
    integer: true,
    choices: &[],
    help: "taps of the blocker search",
};
const FILTER_SAMPLES: Knob = Knob {
    name: "filter_samples",
    default: 16.0,
    min: 1.0,
    max: 64.0,
    integer: true,
    choices: &[],
    help: "taps of the PCF",
};
const LIGHT_SIZE_SCALE: Knob = Knob {
    name: "light_size_scale",
    default: 1.0,
    min: 0.0,
    max: 16.0,
    integer: false,
    choices: &[],
    help: "light size used, as a multiple of the scene light's radius",
};

pub(crate) const DEPTH_BIAS: Knob = Knob {
    name: "depth_bias",
    default: 1.0,
    min: 0.0,
    max: 64.0,
    integer: false,
    choices: &[],
    help: "constant depth bias, in shadow-map texels",
};
pub(crate) const SLOPE_BIAS: Knob = Knob {
    name: "slope_bias",
    default: 1.0,
    min: 0.0,
    max: 64.0,
    integer: false,
    choices: &[],
    help: "depth bias per unit tan(angle to the light), in texels",
};
pub(crate) const NORMAL_OFFSET: Knob = Knob {
    name: "normal_offset",
    default: 1.5,
    min: 0.0,
    max: 64.0,
    integer: false,
    choices: &[],
    help: "lookup offset along the normal at grazing angles, in texels",
};

/// Shared by every technique that renders a shadow map.
pub const SHADOW_MAP_SIZE: Knob = Knob {
    name: "shadow_map_size",
    default: 2048.0,
    min: 16.0,
    max: 16384.0,
    integer: true,
    choices: &[],
    help: "shadow map width and height, in texels",
};

/// The constant, slope-scaled and normal-offset biases, in shadow-map texels.
pub(crate) fn texel_biases(params: &Params) -> [f32; 3] {
    [DEPTH_BIAS, SLOPE_BIAS, NORMAL_OFFSET].map(|k| params.get(&k) as f32)
}

/// The biases at their defaults, for techniques that render shadow maps without exposing them.
pub(crate) const DEFAULT_BIASES: [f32; 3] =
    [DEPTH_BIAS.default as f32, SLOPE_BIAS.default as f32, NORMAL_OFFSET.default as f32];

/// How far, relative to a depth, the map's format may round it (`LightView::depths.w`, which
/// `depth_rounding` in glsl/common/shadow.glsl adds to the bias): a half float's ulp, 2⁻¹⁰. The
/// f32 maps' rounding is already in the shader's own allowance. Without it the 16-bit map shadowed
/// flat lit faces in stripes (`two_boxes`' lower box: penumbra RMSE 0.114 against 0.049).
fn map_rounding(format: vk::Format) -> f32 {
    if format == vk::Format::R16_SFLOAT { 2f32.powi(-10) } else { 0.0 }
}

/// Linear depth cleared beyond any caster: "nothing blocks this texel".
pub(crate) const EMPTY_DEPTH: f32 = f32::MAX;

/// Renders linear light depth (into `format`: R32 or R16 float) through the `LightView` at
/// binding 0.
pub(crate) fn depth_pipeline(ctx: &Context, format: vk::Format) -> Result<Pipeline> {
    let formats = [format];
    let desc = PipelineDesc::new("shadow_map", &shaders::SHADOW_MAP_DEPTH_VERT, &shaders::SHADOW_MAP_DEPTH_FRAG)
        .vertex_input(MESH_POSITIONS)
        .colors(&formats)
        .depth(DepthState::test_write(vk::Format::D32_SFLOAT, vk::CompareOp::LESS));
    Pipeline::new(ctx, &desc)
}

/// The world bounds of the frame's casters, in draw order.
pub(crate) fn caster_bounds(frame: &FrameInputs<'_>) -> Vec<Aabb> {
    frame.draws.iter().filter(|d| d.casts).map(|d| d.bounds).collect()
}

/// Says which casters (indices into [`caster_bounds`]) lost part of their shadow in view to
/// the frustum's 160° limit (a light among its casters), once per change of the list: a
/// shadow is never dropped without a word.
pub(crate) fn warn_clipped(frame: &FrameInputs<'_>, clipped: &[usize]) {
    static LAST: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    let casting: Vec<_> = frame.draws.iter().filter(|d| d.casts).collect();
    let names: Vec<String> = clipped
        .iter()
        .map(|&i| {
            let instance = casting[i].instance as usize;
            frame
                .scene
                .objects
                .get(instance)
                .map_or(format!("caster {i}"), |o| format!("object {instance} ({})", o.name))
        })
        .collect();
    let mut last = LAST.lock().unwrap_or_else(|e| e.into_inner());
    if *last != names {
        if !names.is_empty() {
            eprintln!(
                "softshadow warning: the light at {} is among its casters: the shadows of {} reach beyond the \
                 160° one shadow-map frustum holds and are cut at its edge",
                frame.scene.light.position,
                names.join(", ")
            );
        }
        *last = names;
    }
}

/// Records every caster of the frame (inside a pass whose pipeline is bound).
pub(crate) fn draw_casters(frame: &FrameInputs<'_>) {
    for draw in frame.draws.iter().filter(|d| d.casts) {
        draw.record(frame.ctx, frame.cmd);
    }
}

/// Pass 1: linear light-space depth of the casters through the fitted spot frustum.
pub struct ShadowMapPass {
    format: vk::Format,
    pipeline: Pipeline,
    light: PerFrame,
    map: Option<Target>,
    depth: Option<Target>,
}

impl ShadowMapPass {
    /// A pass rendering into `format` (R32_SFLOAT, or the smoothie paper's R16_SFLOAT).
    pub fn new(ctx: &Context, format: vk::Format) -> Result<Self> {
        let pipeline = Guard::new(ctx, depth_pipeline(ctx, format)?);
        let usage = vk::BufferUsageFlags::UNIFORM_BUFFER;
        let size = std::mem::size_of::<LightView>() as u64;
        let light = PerFrame::new(ctx, "light view", size, FRAMES_IN_FLIGHT, usage)?;
        Ok(ShadowMapPass { format, pipeline: pipeline.keep(), light, map: None, depth: None })
    }

    pub fn format(&self) -> vk::Format {
        self.format
    }

    /// Fits the frustum to the casters that can shadow a receiver in view; `None` when there
    /// are none (nothing to render). Casters one frustum cannot hold are named in a warning.
    pub fn fit(frame: &FrameInputs<'_>) -> Option<LightFrustum> {
        Self::fit_to(frame, &caster_bounds(frame))
    }

    /// [`Self::fit`] to `casters`, the bounds of what each casting draw casts from, in draw
    /// order ([`CasterMeshes::bounds`]).
    pub fn fit_to(frame: &FrameInputs<'_>, casters: &[Aabb]) -> Option<LightFrustum> {
        let light = &frame.scene.light;
        // DESIGN.md §3: the spot looks at `light.target`, a hint the fit re-centres on the casters.
        let fit = fit_spot_frustum(light.position, light.target, casters, frame.receivers_in_view);
        warn_clipped(frame, &fit.clipped);
        fit.frustum
    }

    /// Records the map; afterwards it is ready to be sampled by fragment shaders. `bias` and
    /// `filter` are passed on to the resolve in the `LightView` (glsl/common/interface.glsl).
    /// The casters are the frame's own meshes, or `casters`' (prepared for this frame).
    pub fn record(
        &mut self,
        frame: &mut FrameInputs<'_>,
        frustum: &LightFrustum,
        size: u32,
        bias: [f32; 3],
        filter: Vec4,
        casters: Option<&CasterMeshes>,
    ) -> Result<()> {
        let ctx = frame.ctx;
        ensure(ctx, &mut self.map, TargetDesc::color("shadow map", self.format, size, size))?;
        ensure(ctx, &mut self.depth, TargetDesc::depth("shadow map depth", size, size))?;
        let view = LightView {
            view: frustum.view,
            view_proj: frustum.view_proj,
            extent: Vec4::from(frustum.window),
            bias: Vec4::new(bias[0], bias[1], bias[2], size as f32),
            kernel: filter,
            depths: frustum.depths().with_w(map_rounding(self.format)),
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
        )?;
        match casters {
            Some(casters) => casters.record(frame),
            None => draw_casters(frame),
        }
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

/// The resolve variants: `FILTER` of `glsl/shadow_map/resolve.frag`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u32)]
enum Filter {
    Hard = FILTER_HARD,
    Disk = FILTER_DISK,
    Bicubic = FILTER_BICUBIC,
    Pcss = FILTER_PCSS,
}

/// The disk's taps and the blocker search's: the resolve's `TAPS` and `BLOCKER_TAPS`, constants
/// (see there why not uniforms).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Taps {
    filter: u32,
    blockers: u32,
}

/// `shadow-map`, `pcf` and `pcss`: one [`ShadowMapPass`], then one resolve skeleton
/// specialised by the filter.
pub struct ShadowMap {
    technique: &'static TechniqueInfo,
    pass: ShadowMapPass,
    /// Resolve pipelines made so far, by filter, whether the disk radius is in world units
    /// (`pcf` knobs switch both) and the taps.
    resolves: Variants<(Filter, bool, Taps)>,
    /// The V target's format, which the resolves write.
    visibility: vk::Format,
}

impl ShadowMap {
    pub fn new(ctx: &Context, technique: &'static TechniqueInfo, visibility: vk::Format) -> Result<Self> {
        let pass = ShadowMapPass::new(ctx, vk::Format::R32_SFLOAT)?;
        Ok(ShadowMap { technique, pass, resolves: Variants::default(), visibility })
    }

    /// The registry's constructor of the family.
    fn create(ctx: &Context, technique: &'static TechniqueInfo, visibility: vk::Format) -> Result<Box<dyn Technique>> {
        Ok(Box::new(ShadowMap::new(ctx, technique, visibility)?))
    }

    /// The filter, its `LightView.kernel` parameters for this frame's knobs, and its taps.
    fn filter(&self, params: &Params, frame: &FrameInputs<'_>, frustum: &LightFrustum) -> (Filter, Vec4, Taps) {
        let none = Taps { filter: 1, blockers: 1 };
        match self.technique.name {
            name if name == PCF.name && params.is_on(&BICUBIC) => (Filter::Bicubic, Vec4::ZERO, none),
            name if name == PCF.name => {
                let taps = Taps { filter: params.get(&TAPS) as u32, ..none };
                (Filter::Disk, Vec4::new(0.0, params.get(&RADIUS) as f32, 0.0, 0.0), taps)
            }
            name if name == PCSS.name => {
                let radius = frame.scene.light.radius * params.get(&LIGHT_SIZE_SCALE) as f32;
                let taps =
                    Taps { filter: params.get(&FILTER_SAMPLES) as u32, blockers: params.get(&BLOCKER_SAMPLES) as u32 };
                (Filter::Pcss, Vec4::new(0.0, radius, frustum.near, 0.0), taps)
            }
            _ => (Filter::Hard, Vec4::ZERO, none),
        }
    }
}

impl Technique for ShadowMap {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        let Some(frustum) = ShadowMapPass::fit(frame) else {
            return clear_visibility(frame, visibility);
        };
        let size = params.get(&SHADOW_MAP_SIZE) as u32;
        let bias = texel_biases(params);
        let (filter, filter_params, taps) = self.filter(params, frame, &frustum);
        self.pass.record(frame, &frustum, size, bias, filter_params, None)?;

        let world = self.technique.name == PCF.name && params.is_on(&RADIUS_WORLD);
        let format = self.visibility;
        let pipeline = self.resolves.get((filter, world, taps), |&(filter, world, taps)| {
            let constants = [
                ("FILTER", filter as u32),
                ("RADIUS_IN_WORLD", world as u32),
                ("TAPS", taps.filter),
                ("BLOCKER_TAPS", taps.blockers),
            ];
            let desc = Fullscreen::new("resolve", &shaders::SHADOW_MAP_RESOLVE_FRAG, format).constants(&constants);
            Pipeline::fullscreen(frame.ctx, &desc)
        })?;
        let (map, light) = self.pass.inputs(frame.slot);
        let inputs = [&surface_inputs(frame, light)[..], &[Descriptor::Image(map)]].concat();
        resolve(frame, pipeline, visibility, &inputs)
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        self.pass.destroy(ctx);
        self.resolves.destroy(ctx);
    }
}

impl Destroy for ShadowMapPass {
    fn destroy(self, ctx: &Context) {
        ShadowMapPass::destroy(self, ctx)
    }
}
