//! `priority-map`: the priority maps of Dr. Dobb's "Dynamic Shadows: Five Algorithms" (2005,
//! "priority maps"), the shadow map's per-object cousin: objects sorted by their distance
//! from the light each get a priority; the light's view stores the nearest priority per texel;
//! a camera pixel is shadowed when the map holds a nearer priority than its own object's.
//!
//! Passes: `priority_map`, the casters drawn through the shadow map's fitted spot frustum
//! ([`ShadowMapPass::fit`]) in order from the farthest to the nearest, without a depth test,
//! so the nearest priority is the last written (the DDJ's "closest is the brightest" ambient
//! colour, kept by the painter's order instead of a brightest-wins blend); `object_ids` (the
//! shared [`ObjectIds`] pass) gives each camera pixel its object; `resolve` compares.
//!
//! Deviation: the priorities are integers in an R32_UINT target, where the DDJ drew them as
//! linearly attenuated ambient colours and subtracted two camera images, because 2005
//! hardware had no integer render targets; the comparison is the same, exact, and holds any
//! number of objects. Objects are sorted by the distance from the light to the centre of
//! their bounds; receivers that cast nothing (the ground) are not drawn into the map and rank
//! behind every caster.
//!
//! What works, as the DDJ says: multiple casters on multiple receivers, with no depth bias (a
//! surface never compares with itself). Its faults, shown by tests in tests/classic.rs:
//! - no self-shadowing: "the entire object is drawn with the same color", so a torus never
//!   shadows its own far side (its faces turned from the light are dark by the facing term);
//! - elongated objects in complex configurations: one distance per object cannot order a long
//!   plank whose centre is far from the light above a small box nearer the light; the box
//!   then loses the plank's shadow and casts a false one onto the plank's top;
//! - hard shadows only, at the map's resolution (`map_size`).

use ash::vk;
use bytemuck::{bytes_of, cast_slice};
use glam::Vec4;

use super::knobs::{Knob, Params};
use super::object_ids::ObjectIds;
use super::registry::{APPROXIMATION_BOUND, Kind, Receivers, SweepKnobs, TechniqueInfo};
use super::shadow_map::ShadowMapPass;
use super::{Technique, clear_visibility, nearer_light, resolve, surface_inputs};
use crate::error::Result;
use crate::frame::interface::LightView;
use crate::frame::{FrameInputs, MESH_POSITIONS};
use crate::gpu::{
    Access, Attachment, Context, Descriptor, FRAMES_IN_FLIGHT, Fullscreen, Guard, PerFrame, Pipeline, PipelineDesc,
    RenderPass, Target, TargetDesc, ensure, shaders, transition,
};

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "priority-map",
    summary: "the DDJ's priority maps: objects ranked by distance from the light, the nearest rank per light texel",
    kind: Kind::Realtime,
    knobs: &[MAP_SIZE],
    create: |ctx, _, visibility| Ok(Box::new(PriorityMap::new(ctx, visibility)?)),
    bench: &[&[], &[("map_size", "512")], &[("map_size", "2048")]],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::All,
    error_bound: Some(APPROXIMATION_BOUND),
};

const MAP_SIZE: Knob = Knob {
    name: "map_size",
    default: 1024.0,
    min: 16.0,
    max: 16384.0,
    integer: true,
    choices: &[],
    help: "priority map width and height, in texels",
};

const PRIORITY_FORMAT: vk::Format = vk::Format::R32_UINT;
/// The map's empty texels, and the rank of receivers that cast nothing.
const BEHIND_EVERYTHING: u32 = u32::MAX;

pub struct PriorityMap {
    pipeline: Pipeline,
    resolve: Pipeline,
    ids: ObjectIds,
    light: PerFrame,
    priorities: Option<PerFrame>,
    map: Option<Target>,
}

impl PriorityMap {
    pub fn new(ctx: &Context, visibility: vk::Format) -> Result<Self> {
        let colors = [PRIORITY_FORMAT];
        let desc = PipelineDesc::new(
            "priority_map",
            &shaders::PRIORITY_MAP_PRIORITIES_VERT,
            &shaders::PRIORITY_MAP_PRIORITIES_FRAG,
        )
        .vertex_input(MESH_POSITIONS)
        .colors(&colors);
        let pipeline = Guard::new(ctx, Pipeline::new(ctx, &desc)?);
        let resolve = Fullscreen::new("resolve", &shaders::PRIORITY_MAP_RESOLVE_FRAG, visibility);
        let resolve = Guard::new(ctx, Pipeline::fullscreen(ctx, &resolve)?);
        let ids = Guard::new(ctx, ObjectIds::new(ctx)?);
        let size = std::mem::size_of::<LightView>() as u64;
        let light = PerFrame::new(ctx, "priority light", size, FRAMES_IN_FLIGHT, vk::BufferUsageFlags::UNIFORM_BUFFER)?;
        Ok(PriorityMap {
            pipeline: pipeline.keep(),
            resolve: resolve.keep(),
            ids: ids.keep(),
            light,
            priorities: None,
            map: None,
        })
    }
}

impl Technique for PriorityMap {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        let Some(frustum) = ShadowMapPass::fit(frame) else {
            return clear_visibility(frame, visibility);
        };
        let ctx = frame.ctx;
        let size = params.get(&MAP_SIZE) as u32;
        // The DDJ's sort: casters by distance from the light, nearest first, ranked from 0.
        // From a far light taken nearer: f32 distances 1e8 m away tie casters metres apart.
        let (l, _) = nearer_light(frame);
        let mut casters: Vec<_> = frame.draws.iter().filter(|d| d.casts).collect();
        casters.sort_by(|a, b| a.bounds.center().distance(l).total_cmp(&b.bounds.center().distance(l)));
        let instances = frame.draws.iter().map(|d| d.instance as usize + 1).max().unwrap_or(0);
        let mut priorities = vec![BEHIND_EVERYTHING; instances];
        for (rank, d) in casters.iter().enumerate() {
            priorities[d.instance as usize] = rank as u32;
        }
        let bytes: &[u8] = cast_slice(&priorities);
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let buffer = PerFrame::ensure(ctx, &mut self.priorities, "priorities", bytes.len() as u64, usage)?;
        buffer.write(frame.slot, bytes);
        let priorities = buffer.range(frame.slot);
        let view = LightView {
            view: frustum.view,
            view_proj: frustum.view_proj,
            extent: Vec4::from(frustum.window),
            bias: Vec4::new(0.0, 0.0, 0.0, size as f32),
            kernel: Vec4::ZERO,
            depths: frustum.depths(),
        };
        self.light.write(frame.slot, bytes_of(&view));
        let light = self.light.range(frame.slot);

        ensure(ctx, &mut self.map, TargetDesc::color("priority map", PRIORITY_FORMAT, size, size))?;
        let map = self.map.as_mut().expect("ensured");
        let cmd = frame.cmd;
        frame.timer.begin(ctx, cmd, "priority_map");
        transition(ctx, cmd, &mut [(map, Access::COLOR_WRITE, true)]);
        let pass = RenderPass::begin(ctx, cmd, &[Attachment::clear_uint(map, [BEHIND_EVERYTHING; 4])], None);
        self.pipeline.bind(
            ctx,
            cmd,
            &[Descriptor::Buffer(light), Descriptor::Buffer(frame.objects), Descriptor::Buffer(priorities)],
        )?;
        // Farthest first: the nearest priority is written last (primitive order).
        for d in casters.iter().rev() {
            d.record(ctx, cmd);
        }
        pass.end(ctx, cmd);
        transition(ctx, cmd, &mut [(map, Access::FRAGMENT_READ, false)]);
        frame.timer.end(ctx, cmd);

        let ids = self.ids.record(frame)?;
        let map = self.map.as_ref().expect("ensured");
        let inputs = [
            &surface_inputs(frame, light)[..],
            &[Descriptor::Image(ids), Descriptor::Buffer(priorities), Descriptor::Image(map)],
        ]
        .concat();
        resolve(frame, &self.resolve, visibility, &inputs)
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        let this = *self;
        this.pipeline.destroy(ctx);
        this.resolve.destroy(ctx);
        this.ids.destroy(ctx);
        this.light.destroy(ctx);
        this.priorities.into_iter().for_each(|b| b.destroy(ctx));
        this.map.into_iter().for_each(|t| t.destroy(ctx));
    }
}
