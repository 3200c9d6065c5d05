//! `concentric`: Gooch et al.'s soft shadows ("Interactive Technical Illustration", I3D 1998),
//! as Komura's lecture presents them (slide "Other techniques to generate soft shadow: Gooch
//! et al."): "moving the projected plane up and down instead of moving the light source", "the
//! projections cast upon it are averaged".
//!
//! Pass `projections`: N hard planar projections (Blinn's matrix, as the plateau's umbra) of
//! the casters onto planes at heights spread evenly over [−d, d] about the ground, each seen
//! straight down into one plan-view texture of the ground and added with weight 1/N. Each
//! projection is drawn at its own depth, nearer than the one before, with a LESS test, so a
//! texel takes a projection once however many caster triangles cover it (the casters' union).
//! `resolve`: on the ground, V = 1 − the averaged darkness (bilinear).
//!
//! The spread. A plane at height y scales the ground shadow about the light's foot by
//! (H − y)/H, so the planes spread an edge over 2d·|p − l|ₕ/(H − h) for a vertex p at height h
//! (H the light's height, |·|ₕ horizontal): the penumbra widens with the caster's height, as it
//! should, but also with its distance from the light's foot, and it does not vanish where the
//! caster touches the ground (the planes move the contact's shadow too). By default d is chosen
//! per caster so that the width is the physical one, 2ρ·h/(H − h) for a light of radius ρ, at
//! the caster's centre ([`concentric_spread`]); `spread_scale` multiplies it. Deviations from
//! the lecture: the spread is per caster (one stack for the scene would give a caster near the
//! light's foot no penumbra and a far one too much), and the shadow stays on the ground plane
//! (off it, receivers are unshadowed; casters keep only their own back faces' darkness).
//!
//! Komura's slide "Problems with Gooch et al. and Haine's method" finds the umbra too large,
//! as a point light makes it. That holds for the plateau, which keeps the whole hard shadow as
//! its top; with planes spread evenly on both sides of the ground, as here, the penumbra
//! straddles the hard edge (darker inside, lighter outside) and the umbra shrinks as an area
//! light's does, which is why this measures closer to the reference than the plateau does.

use ash::vk;
use bytemuck::{bytes_of, cast_slice};
use glam::{Mat4, Vec2, Vec4};

use super::knobs::{Knob, Params};
use super::registry::{APPROXIMATION_BOUND, Kind, Receivers, SweepKnobs, TechniqueInfo};
use super::shadow_map::draw_casters;
use super::{Technique, clear_visibility, ground, nearer_light, resolve, surface_inputs};
use crate::error::Result;
use crate::frame::interface::ClassicView;
use crate::frame::{FrameInputs, MESH_POSITIONS};
use crate::geometry::classic::{concentric_heights, concentric_spread};
use crate::geometry::plateau::ReceiverPlane;
use crate::gpu::{
    Access, Attachment, Blend, Context, DepthState, Descriptor, FRAMES_IN_FLIGHT, Fullscreen, Guard, PerFrame,
    Pipeline, PipelineDesc, RenderPass, Target, TargetDesc, ensure, shaders, transition,
};

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "concentric",
    summary: "Gooch et al.: hard projections onto planes moved up and down about the ground, averaged",
    kind: Kind::Realtime,
    knobs: &[PROJECTIONS, SPREAD_SCALE, TEXTURE_SIZE],
    create: |ctx, _, visibility| Ok(Box::new(Concentric::new(ctx, visibility)?)),
    bench: &[&[], &[("projections", "4")], &[("projections", "16")]],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::GroundPlane,
    error_bound: Some(APPROXIMATION_BOUND),
};

const PROJECTIONS: Knob = Knob {
    name: "projections",
    default: 8.0,
    min: 1.0,
    max: 64.0,
    integer: true,
    choices: &[],
    help: "planar projections averaged (N)",
};
const SPREAD_SCALE: Knob = Knob {
    name: "spread_scale",
    default: 1.0,
    min: 0.0,
    max: 8.0,
    integer: false,
    choices: &[],
    help: "half spread of the planes, as a multiple of the one giving the physical penumbra",
};
const TEXTURE_SIZE: Knob = Knob {
    name: "texture_size",
    default: 1024.0,
    min: 16.0,
    max: 8192.0,
    integer: true,
    choices: &[],
    help: "plan-view texture width and height, in texels",
};

/// Averaged darkness: blendable everywhere, and k/N for N ≤ 64 to well under a 16-bit step.
const DARKNESS_FORMAT: vk::Format = vk::Format::R16_SFLOAT;
/// Alignment of each projection's range (the largest storage-buffer offset alignment Vulkan
/// allows).
const RANGE_ALIGN: u64 = 256;

pub struct Concentric {
    projections: Pipeline,
    resolve: Pipeline,
    view: PerFrame,
    matrices: Option<PerFrame>,
    texture: Option<Target>,
    depth: Option<Target>,
}

impl Concentric {
    pub fn new(ctx: &Context, visibility: vk::Format) -> Result<Self> {
        let colors = [DARKNESS_FORMAT];
        let desc = PipelineDesc::new(
            "projections",
            &shaders::CONCENTRIC_PROJECTIONS_VERT,
            &shaders::CONCENTRIC_PROJECTIONS_FRAG,
        )
        .vertex_input(MESH_POSITIONS)
        .colors(&colors)
        .depth(DepthState::test_write(vk::Format::D32_SFLOAT, vk::CompareOp::LESS))
        .blend(Blend::Add);
        let projections = Guard::new(ctx, Pipeline::new(ctx, &desc)?);
        let resolve = Fullscreen::new("resolve", &shaders::CONCENTRIC_RESOLVE_FRAG, visibility);
        let resolve = Guard::new(ctx, Pipeline::fullscreen(ctx, &resolve)?);
        let size = std::mem::size_of::<ClassicView>() as u64;
        let view = PerFrame::new(ctx, "concentric view", size, FRAMES_IN_FLIGHT, vk::BufferUsageFlags::UNIFORM_BUFFER)?;
        Ok(Concentric {
            projections: projections.keep(),
            resolve: resolve.keep(),
            view,
            matrices: None,
            texture: None,
            depth: None,
        })
    }
}

impl Technique for Concentric {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        let Some(g) = frame.scene.ground else {
            return clear_visibility(frame, visibility); // no receiver plane: nothing to do
        };
        let ctx = frame.ctx;
        let plane = ReceiverPlane::ground(g.height);
        let (light, radius) = nearer_light(frame);
        let hl = plane.height(light);
        let n = params.get(&PROJECTIONS) as u32;
        let scale = params.get(&SPREAD_SCALE) as f32;
        let casters: Vec<_> = frame.draws.iter().filter(|d| d.casts).collect();
        // Each caster's plane heights, and the footprint of its outermost projections.
        let spreads: Vec<f32> =
            casters.iter().map(|d| scale * concentric_spread(&plane, light, radius, &d.bounds)).collect();
        let (mut lo, mut hi, mut unbounded) = (Vec2::MAX, Vec2::MIN, false);
        for (d, spread) in casters.iter().zip(&spreads) {
            for y in [-spread, *spread] {
                let at = ReceiverPlane::ground(g.height + y);
                for c in d.bounds.corners() {
                    match at.project(light, c) {
                        Some(q) => (lo, hi) = (lo.min(q), hi.max(q)),
                        None => unbounded = true,
                    }
                }
            }
        }
        let texels = params.get(&TEXTURE_SIZE) as u32;
        let window = if casters.is_empty() || hl <= 0.0 {
            None
        } else {
            ground::window(&plane, (lo, hi), unbounded, frame, texels)
        };
        let Some(window) = window else {
            return clear_visibility(frame, visibility);
        };
        let view = ground::view(&plane, window, Vec4::ZERO);
        self.view.write(frame.slot, bytes_of(&view));

        // Per projection: (its depth, its weight), then a matrix per draw, indexed by instance.
        let to_clip = ground::window_to_clip(window);
        let instances = frame.draws.iter().map(|d| d.instance as usize + 1).max().unwrap_or(0);
        let stride = (16 + 64 * instances as u64).div_ceil(RANGE_ALIGN) * RANGE_ALIGN;
        let mut data = vec![0u8; (stride * n as u64) as usize];
        let heights: Vec<Vec<f32>> = spreads.iter().map(|&s| concentric_heights(n, s).collect()).collect();
        for k in 0..n as usize {
            let range = &mut data[k * stride as usize..];
            let depth = 1.0 - (k + 1) as f32 / (n + 1) as f32;
            range[..16].copy_from_slice(bytes_of(&Vec4::new(depth, 1.0 / n as f32, 0.0, 0.0)));
            for (d, hs) in casters.iter().zip(&heights) {
                let m: Mat4 = to_clip * ReceiverPlane::ground(g.height + hs[k]).shadow_matrix(light);
                let at = 16 + 64 * d.instance as usize;
                range[at..at + 64].copy_from_slice(bytes_of(&m));
            }
        }
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let matrices = PerFrame::ensure(ctx, &mut self.matrices, "concentric projections", data.len() as u64, usage)?;
        matrices.write(frame.slot, cast_slice(&data));
        let base = matrices.range(frame.slot);

        ensure(ctx, &mut self.texture, TargetDesc::color("concentric texture", DARKNESS_FORMAT, texels, texels))?;
        ensure(ctx, &mut self.depth, TargetDesc::depth("concentric depth", texels, texels))?;
        let (texture, depth) = (self.texture.as_mut().expect("ensured"), self.depth.as_mut().expect("ensured"));
        let cmd = frame.cmd;
        frame.timer.begin(ctx, cmd, "projections");
        transition(ctx, cmd, &mut [(texture, Access::COLOR_WRITE, true), (depth, Access::DEPTH_WRITE, true)]);
        let pass = RenderPass::begin(
            ctx,
            cmd,
            &[Attachment::clear_color(texture, [0.0; 4])],
            Some(Attachment::clear_depth(depth, 1.0)),
        );
        for k in 0..n as u64 {
            let range =
                vk::DescriptorBufferInfo { buffer: base.buffer, offset: base.offset + k * stride, range: stride };
            self.projections.bind(ctx, cmd, &[Descriptor::Buffer(range), Descriptor::Buffer(frame.objects)])?;
            draw_casters(frame);
        }
        pass.end(ctx, cmd);
        transition(ctx, cmd, &mut [(texture, Access::FRAGMENT_READ, false)]);
        frame.timer.end(ctx, cmd);

        let inputs = [&surface_inputs(frame, self.view.range(frame.slot))[..], &[Descriptor::Image(texture)]].concat();
        resolve(frame, &self.resolve, visibility, &inputs)
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        let this = *self;
        this.projections.destroy(ctx);
        this.resolve.destroy(ctx);
        this.view.destroy(ctx);
        this.matrices.into_iter().for_each(|b| b.destroy(ctx));
        this.texture.into_iter().chain(this.depth).for_each(|t| t.destroy(ctx));
    }
}
