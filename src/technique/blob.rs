//! `blob`: the "dark spot underneath moving objects" that opens Dr. Dobb's "Dynamic Shadows:
//! Five Algorithms" (2005, introduction): a soft-edged spot per caster on the ground, elongated
//! "into the direction opposite to the predominant light source", several spots intersecting
//! where casters are close. The floor of the speed/accuracy curve: one full-screen pass, no
//! texture, a few ALU per caster per pixel.
//!
//! What the DDJ leaves open, chosen here: the spot is the ellipse of the second moments of the
//! caster's bounding-box corners (its own box, turned with it) as projected from the light onto
//! the ground ([`blob`](crate::geometry::classic::blob)), so it lies where the shadow lies and
//! stretches away from a low light (at most
//! [`MAX_STRETCH`](crate::geometry::classic::MAX_STRETCH) times its width); V rises from 0 to 1 across ±`softness` of its radius (a smoothstep), so the
//! ellipse is the V = ½ line; spots that overlap multiply ("multiple intersecting dark spots").
//!
//! Its faults, by design and measured in tests/classic.rs: the spot is an ellipse whatever the
//! caster's shape (a box's square shadow loses its corners), its softness does not follow the
//! light's size or the caster's height (the penumbra neither vanishes at contact nor widens
//! with height), and only the ground receives it: casters and other receivers get no shadow.

use ash::vk;
use bytemuck::{bytes_of, cast_slice};
use glam::Vec4;

use super::knobs::{Knob, Params};
use super::registry::{Kind, Receivers, SweepKnobs, TechniqueInfo};
use super::{Technique, clear_visibility, ground, nearer_light, resolve, surface_inputs};
use crate::error::Result;
use crate::frame::FrameInputs;
use crate::frame::interface::{BlobData, ClassicView};
use crate::geometry::classic::blob;
use crate::geometry::plateau::ReceiverPlane;
use crate::gpu::{Context, Descriptor, FRAMES_IN_FLIGHT, Fullscreen, PerFrame, Pipeline, Target, shaders};

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "blob",
    summary: "the DDJ's dark spot: a soft ellipse per caster on the ground plane, stretched away from the light",
    kind: Kind::Realtime,
    knobs: &[SOFTNESS],
    create: |ctx, _, visibility| Ok(Box::new(Blobs::new(ctx, visibility)?)),
    bench: &[&[], &[("softness", "0.25")], &[("softness", "1")]],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::GroundPlane,
    error_bound: None,
};

const SOFTNESS: Knob = Knob {
    name: "softness",
    default: 0.5,
    min: 0.01,
    max: 1.0,
    integer: false,
    choices: &[],
    help: "half width of the soft edge, as a fraction of the spot's radius",
};

pub struct Blobs {
    resolve: Pipeline,
    view: PerFrame,
    blobs: Option<PerFrame>,
}

impl Blobs {
    pub fn new(ctx: &Context, visibility: vk::Format) -> Result<Self> {
        let resolve = Pipeline::fullscreen(ctx, &Fullscreen::new("resolve", &shaders::BLOB_RESOLVE_FRAG, visibility))?;
        let size = std::mem::size_of::<ClassicView>() as u64;
        let view = match PerFrame::new(ctx, "blob view", size, FRAMES_IN_FLIGHT, vk::BufferUsageFlags::UNIFORM_BUFFER) {
            Ok(v) => v,
            Err(e) => {
                resolve.destroy(ctx);
                return Err(e);
            }
        };
        Ok(Blobs { resolve, view, blobs: None })
    }
}

impl Technique for Blobs {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        let Some(g) = frame.scene.ground else {
            return clear_visibility(frame, visibility); // no ground: no spot to draw
        };
        let plane = ReceiverPlane::ground(g.height);
        let (light, _) = nearer_light(frame);
        let blobs: Vec<BlobData> = frame
            .draws
            .iter()
            .filter(|d| d.casts)
            .filter_map(|d| {
                // The object's own box, turned with it: a turned plate's world box is far larger.
                let corners = match frame.scene.objects.get(d.instance as usize) {
                    Some(o) => o.mesh.bounds.corners().map(|c| o.transform.matrix().transform_point3(c)),
                    None => d.bounds.corners(),
                };
                blob(&plane, light, &corners)
            })
            .map(|b| {
                let m = b.to_unit();
                BlobData { centre: b.centre.extend(0.0).extend(0.0), to_unit: Vec4::from((m.col(0), m.col(1))) }
            })
            .collect();
        if blobs.is_empty() {
            return clear_visibility(frame, visibility);
        }
        let ctx = frame.ctx;
        let params = Vec4::new(0.0, params.get(&SOFTNESS) as f32, 0.0, 0.0);
        let view = ground::view(&plane, Vec4::ZERO, params);
        self.view.write(frame.slot, bytes_of(&view));
        let bytes: &[u8] = cast_slice(&blobs);
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let buffer = PerFrame::ensure(ctx, &mut self.blobs, "blobs", bytes.len() as u64, usage)?;
        buffer.write(frame.slot, bytes);
        // Bound to this frame's blobs exactly: the resolve takes their count from its length.
        let range = vk::DescriptorBufferInfo { range: bytes.len() as u64, ..buffer.range(frame.slot) };
        let inputs = [&surface_inputs(frame, self.view.range(frame.slot))[..], &[Descriptor::Buffer(range)]].concat();
        resolve(frame, &self.resolve, visibility, &inputs)
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        let this = *self;
        this.resolve.destroy(ctx);
        this.view.destroy(ctx);
        this.blobs.into_iter().for_each(|b| b.destroy(ctx));
    }
}
