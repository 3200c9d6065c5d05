//! `projective-texture`: the shadow texture of Dr. Dobb's "Dynamic Shadows: Five Algorithms"
//! (2005, "projective textures") and Komura's lecture ("Shadow texture"): per caster, a
//! black-on-white image of the caster as seen from the light, used as a texture on the
//! receivers through the same projection.
//!
//! Passes: `images` draws each caster alone into its tile of one atlas, through the DDJ's
//! light-space frame (Example 2: k from the caster's centre to the light, i perpendicular to
//! the caster's up axis, a perspective fitted to its bounding sphere so that the image fills
//! the tile; [`caster_view`]); `object_ids` (the shared [`ObjectIds`] pass) says which object
//! each camera pixel sees; `resolve` projects every receiver point into every other caster's
//! image (projective texture coordinates divided per pixel, so perspective-correct: the
//! lecture's hyperbolic interpolation) and reads the nearest texel.
//!
//! Multiple casters on one receiver, which the DDJ calls hard to model (one texture stage per
//! caster in 2005's fixed function): the resolve loops over every image and keeps the darkest,
//! the union of the hard shadows (for black-on-white images the same as multiplying them), so
//! overlapping shadows never darken twice.
//!
//! Its faults, each shown by a test in tests/classic.rs:
//! - no self-shadowing (DDJ: "self shadowing is quite problematic"): a caster does not receive
//!   its own image, so a torus never shadows its own far side (its faces turned from the light
//!   are still dark: that is the facing term every technique applies, not a cast shadow);
//! - the projection has no depth: it falls on every receiver it covers, in front of the caster
//!   as well as behind it, and, through the projection's sign, on receivers behind the light (a
//!   mirrored image). `clip` says which are handled: 0 none (the method as the DDJ writes it),
//!   1 receivers behind the light are left out, 2 (the default) so are receivers nearer the
//!   light than the caster's bounding sphere begins (the DDJ's "line-of-sight calculations",
//!   by distance). The DDJ's other fault, the shadow on the far side of a closed receiver, does
//!   not reach V: there the receiver's own facing term is 0 already (the DDJ suggests "very low
//!   ambient" for the same reason);
//! - resolution: nearest texels, so a small `texture_size` makes the shadow blocky (DDJ: "if
//!   it is too small, the shadow is blocky").

use ash::vk;
use bytemuck::{bytes_of, cast_slice};
use glam::{Vec3, Vec4};

use super::knobs::{Knob, Params};
use super::object_ids::ObjectIds;
use super::registry::{APPROXIMATION_BOUND, Kind, Receivers, SweepKnobs, TechniqueInfo};
use super::{Technique, clear_visibility, nearer_light, resolve, surface_inputs};
use crate::error::Result;
use crate::frame::interface::{CasterImage, ClassicView};
use crate::frame::{FrameInputs, MESH_POSITIONS};
use crate::geometry::classic::caster_view;
use crate::gpu::{
    Access, Attachment, Context, Descriptor, FRAMES_IN_FLIGHT, Fullscreen, Guard, PerFrame, Pipeline, PipelineDesc,
    RenderPass, Target, TargetDesc, Variants, ensure, shaders, transition,
};

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "projective-texture",
    summary: "the DDJ's shadow texture: each caster's black-on-white image from the light, projected onto the others",
    kind: Kind::Realtime,
    knobs: &[TEXTURE_SIZE, CLIP],
    create: |ctx, _, visibility| Ok(Box::new(ProjectiveTexture::new(ctx, visibility)?)),
    bench: &[&[], &[("texture_size", "128")], &[("texture_size", "1024")]],
    sweep_knobs: SweepKnobs::DEFAULTS,
    cost_goal: None,
    receivers: Receivers::All,
    error_bound: Some(APPROXIMATION_BOUND),
};

const TEXTURE_SIZE: Knob = Knob {
    name: "texture_size",
    default: 512.0,
    min: 8.0,
    max: 4096.0,
    integer: true,
    choices: &[],
    help: "each caster's image, texels a side (the atlas holds them all)",
};
const CLIP: Knob = Knob::choice(
    "clip",
    2.0,
    &["none", "behind", "between"],
    "receivers an image falls on: none clipped, behind: none behind the light, between: nor nearer the light than the caster",
);

const IMAGE_FORMAT: vk::Format = vk::Format::R8_UNORM;
const IMAGE_BYTES: u64 = std::mem::size_of::<CasterImage>() as u64;

pub struct ProjectiveTexture {
    images: Pipeline,
    resolves: Variants<u32>,
    visibility: vk::Format,
    ids: ObjectIds,
    view: PerFrame,
    casters: Option<PerFrame>,
    atlas: Option<Target>,
}

impl ProjectiveTexture {
    pub fn new(ctx: &Context, visibility: vk::Format) -> Result<Self> {
        let colors = [IMAGE_FORMAT];
        let desc = PipelineDesc::new(
            "images",
            &shaders::PROJECTIVE_TEXTURE_IMAGES_VERT,
            &shaders::PROJECTIVE_TEXTURE_IMAGES_FRAG,
        )
        .vertex_input(MESH_POSITIONS)
        .colors(&colors);
        let images = Guard::new(ctx, Pipeline::new(ctx, &desc)?);
        let ids = Guard::new(ctx, ObjectIds::new(ctx)?);
        let size = std::mem::size_of::<ClassicView>() as u64;
        let view = PerFrame::new(ctx, "projective view", size, FRAMES_IN_FLIGHT, vk::BufferUsageFlags::UNIFORM_BUFFER)?;
        Ok(ProjectiveTexture {
            images: images.keep(),
            resolves: Variants::default(),
            visibility,
            ids: ids.keep(),
            view,
            casters: None,
            atlas: None,
        })
    }
}

impl Technique for ProjectiveTexture {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        // The images are projected from a far light taken nearer (f32 lost a cube's image from
        // 5.8e7 m, issue 19); `to_light` in the resolve stays the true distance.
        let (light, _) = nearer_light(frame);
        let farther = |p: Vec3| p.distance(frame.scene.light.position) - p.distance(light);
        // Each caster's bounding sphere, from its own box turned with it, and its up axis.
        let views: Vec<_> = frame
            .draws
            .iter()
            .filter(|d| d.casts)
            .filter_map(|d| {
                let (corners, up) = match frame.scene.objects.get(d.instance as usize) {
                    Some(o) => {
                        let m = o.transform.matrix();
                        (o.mesh.bounds.corners().map(|c| m.transform_point3(c)), m.transform_vector3(Vec3::Y))
                    }
                    None => (d.bounds.corners(), Vec3::Y),
                };
                let centre = corners.iter().sum::<Vec3>() / 8.0;
                let radius = corners.iter().map(|c| c.distance(centre)).fold(0.0, f32::max);
                caster_view(light, centre, radius, up).map(|v| (d, v, farther(centre)))
            })
            .collect();
        if views.is_empty() || frame.receivers_in_view.is_empty() {
            return clear_visibility(frame, visibility);
        }
        let ctx = frame.ctx;
        let grid = (views.len() as f64).sqrt().ceil() as u32;
        let tile = (params.get(&TEXTURE_SIZE) as u32).min(ctx.info.max_image_dimension_2d / grid).max(1);
        let side = grid * tile;
        let images: Vec<CasterImage> = views
            .iter()
            .enumerate()
            .map(|(i, (d, v, farther))| {
                let (x, y) = ((i as u32 % grid) as f32, (i as u32 / grid) as f32);
                let t = 1.0 / grid as f32;
                CasterImage {
                    view_proj: v.view_proj,
                    tile: Vec4::new(x * t, y * t, t, t),
                    info: Vec4::new(v.near + farther, d.instance as f32, 0.0, 0.0),
                    pad: [Vec4::ZERO; 10],
                }
            })
            .collect();
        let usage = vk::BufferUsageFlags::UNIFORM_BUFFER | vk::BufferUsageFlags::STORAGE_BUFFER;
        let bytes: &[u8] = cast_slice(&images);
        let buffer = PerFrame::ensure(ctx, &mut self.casters, "caster images", bytes.len() as u64, usage)?;
        buffer.write(frame.slot, bytes);
        let base = buffer.range(frame.slot);
        let view =
            ClassicView { params: Vec4::new(images.len() as f32, 0.0, 0.0, 0.0), ..bytemuck::Zeroable::zeroed() };
        self.view.write(frame.slot, bytes_of(&view));

        ensure(ctx, &mut self.atlas, TargetDesc::color("caster images", IMAGE_FORMAT, side, side))?;
        let atlas = self.atlas.as_mut().expect("ensured");
        let cmd = frame.cmd;
        frame.timer.begin(ctx, cmd, "images");
        transition(ctx, cmd, &mut [(atlas, Access::COLOR_WRITE, true)]);
        let pass = RenderPass::begin(ctx, cmd, &[Attachment::clear_color(atlas, [1.0; 4])], None);
        for (i, (d, _, _)) in views.iter().enumerate() {
            let i = i as u32;
            let offset = vk::Offset2D { x: ((i % grid) * tile) as i32, y: ((i / grid) * tile) as i32 };
            pass.set_area(ctx, cmd, vk::Rect2D { offset, extent: vk::Extent2D { width: tile, height: tile } });
            let range = vk::DescriptorBufferInfo {
                buffer: base.buffer,
                offset: base.offset + i as u64 * IMAGE_BYTES,
                range: IMAGE_BYTES,
            };
            self.images.bind(ctx, cmd, &[Descriptor::Buffer(range), Descriptor::Buffer(frame.objects)])?;
            d.record(ctx, cmd);
        }
        pass.end(ctx, cmd);
        transition(ctx, cmd, &mut [(atlas, Access::FRAGMENT_READ, false)]);
        frame.timer.end(ctx, cmd);

        let ids = self.ids.record(frame)?;
        let atlas = self.atlas.as_ref().expect("ensured");
        let inputs = [
            &surface_inputs(frame, self.view.range(frame.slot))[..],
            &[Descriptor::Image(ids), Descriptor::Buffer(base), Descriptor::Image(atlas)],
        ]
        .concat();
        let format = self.visibility;
        let pipeline = self.resolves.get(params.get(&CLIP) as u32, |&clip| {
            let constants = [("CLIP", clip)];
            let desc =
                Fullscreen::new("resolve", &shaders::PROJECTIVE_TEXTURE_RESOLVE_FRAG, format).constants(&constants);
            Pipeline::fullscreen(ctx, &desc)
        })?;
        resolve(frame, pipeline, visibility, &inputs)
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        let this = *self;
        this.images.destroy(ctx);
        this.resolves.destroy(ctx);
        this.ids.destroy(ctx);
        this.view.destroy(ctx);
        this.casters.into_iter().for_each(|b| b.destroy(ctx));
        this.atlas.into_iter().for_each(|t| t.destroy(ctx));
    }
}
