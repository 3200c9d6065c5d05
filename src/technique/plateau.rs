//! `plateau`: Haines' soft planar shadows ("Soft Planar Shadows Using Plateaus", 2001) on the
//! ground plane.
//!
//! Per frame, in the paper's order (§2): the casters are flattened by Blinn's planar projection
//! into a plan-view mask of the receiver plane, fitted to the shadow's footprint (`umbra`); a
//! cone at each silhouette vertex (`cones`) and a sheet along each silhouette edge (`sheets`)
//! form the plateau's sides in a second texture, cleared to t = 1 and drawn with depth = t so
//! the darkest wins; `resolve` reads both where each receiver stands and turns t into V through
//! the falloff curve (§3's 1D texture, computed in the shader instead, `glsl/common/falloff.glsl`).
//! The paper draws the umbra into the plateau texture itself at t = 0; kept apart, the same mask
//! also gives the centred penumbra its sign.
//!
//! Penumbra size. Physically, a vertex at height h casts the footprint of the cone of rays from
//! it to the light sphere (width W = D·h/(H − h) under a light overhead, stretched into an
//! ellipse away from a low light, §3); the cone radius is `penumbra_scale` × W/2, the physical
//! half width by default. `size_mode = 1` uses Haines' constant factor instead (radius =
//! `haines_factor` × h).
//!
//! Where the penumbra lies (`penumbra`, issue 20). The paper grows it outward only, so the whole
//! hard shadow stays umbra (§4), although the truth is already ½ on the hard edge: at the
//! physical width that is darker than the hard shadow itself, and only narrow cones help. The
//! default centres it: sheets on both sides of each edge make t the distance to the nearest
//! silhouette in half widths, the mask signs it (s = ±t) and V = falloff(½ + ½·s), with the
//! disk-edge curve, the exact profile of a spherical light behind a straight edge, by default.
//! The umbra then shrinks as the light grows, and vanishes once the inner penumbrae of opposite
//! edges meet (a sphere under a light larger than itself). Of the ways issue 20 weighs, this
//! keeps the paper's primitives and passes: erosion of the umbra (Kirsch & Döllner 2003) needs
//! passes per texel of width, and the sheets already hold the distance. Only silhouettes on the
//! hard shadow's boundary may write it (`glsl/plateau/penumbra.frag`): interior folds and
//! edges, or bands, under another caster's shadow are dropped, and the mask keeps, where
//! shadows overlap, the lowest caster's number, so no inner penumbra lightens what another
//! caster blocks.
//!
//! One silhouette, from the light's centre, is not always enough. A face seen within the
//! light's angular radius of edge-on turns its back to part of the light, and from there the
//! silhouette is its other edge, often higher and with the wider penumbra (`low_light`'s box:
//! the truth's outer half 4.5 px against the centred sheets' 3.2, a lit band too light by 0.13).
//! Centred, such partial silhouettes (`geometry::silhouette::partial_silhouettes`) add the outer
//! half of their own sheet wherever it reaches past what the silhouette casts, drawn only where
//! the mask is lit (`PARTIAL`); a fine mesh's, a ring beside its silhouette, almost all reach
//! no further and are dropped on the CPU. Inside the hard shadow the same holds the other way:
//! a receiver there sees only the part of the light beyond the silhouette, and from there a
//! face that the centre sees from behind, nearly edge-on, has turned to the light, so the
//! silhouette is that face's lower edge, nearer the receiver, with the narrower penumbra (a
//! thick slab's bottom rim: the truth's inner half 0.31 m where the top rim's alone is 0.43 m).
//! Such edges add the inner half of their own sheet, drawn last over their caster's hard shadow
//! and blended by max, so it only darkens: min over the silhouette's sides (the nearest edge),
//! then max over the edges that lie under it (from there the silhouette's half plane lets
//! through more than the caster does, the lower edge's about what it does). Only where the
//! mask says the caster reaches a penumbra's width beyond the fragment, straight in and to
//! either side: a caster narrower than the penumbra, or a corner, lets light past that no
//! straight edge's half plane knows of. Measured (512², lavapipe, against
//! the reference at 256 samples, penumbra RMSE without → with): sphere 0.0138 → 0.0135, torus
//! 0.0076 → 0.0075, `default` 0.14023 → 0.14010 (pixels leaking over 0.1: 1040 → 1021, its
//! outer-only form's 991), the hammer 0.108 → 0.102, the other suite scenes the same to 1e-5;
//! the sheets' pass and the CPU's sides the same within the noise.
//!
//! Corners. A sheet cuts the light's footprint by its own edge's line; where two edges of the
//! outline meet, the truth cuts it by both, and at a right-angled convex corner the apex sees ¾
//! of the light, not ½ (a reflex one ¼). Centred, the sides near such a corner add the
//! difference of the two cuts, the footprint taken as the corner vertex's cone (an affine image
//! of the light's disk, so the area fractions are the disk's: `glsl/common/corners.glsl`), and
//! write the disk-edge distance that gives the sum, its sign the mask's. Far from the corner
//! the difference is 0, so the sides meet as before. A corner is two edges of the outline that
//! turn, each at least half a footprint long, whose hard shadow the mask confirms about the
//! vertex (`penumbra.vert`: not an interior fold, not a spike too thin to show). Drawn apart
//! (`CORNERS`), as llvmpipe pays for every branch of a fragment shader on every fragment.
//! Measured (512², lavapipe, against the reference at 256 samples), penumbra RMSE without →
//! with: plate 0.0273 → 0.0068, contact 0.0261 → 0.0070, open_mesh 0.0323 → 0.0088, sphere
//! 0.0163 → 0.0138, default 0.1415 → 0.1402; the sheets' pass on plate 0.16 → 0.40 ms, on the
//! sphere 0.31 → 0.88 ms, on default 2.2 → 4.3–4.8 ms (interleaved runs), before the corners'
//! inverse curve became a polynomial (`disk_below_inverse`): the sheets' pass on contact then
//! 3.29–3.34 → 2.85–3.13 ms, on default 3.88–4.42 → 3.77–3.85 (interleaved runs).
//!
//! Cost (issue 18). A cone is drawn only where no sheet covers it, the wedge of a corner
//! (`cones = 0`: Haines' whole cones, measured against): on fine meshes, whose edges are far
//! shorter than the penumbra, whole cones drew each texel several times over (the koala's
//! cones: 9.2M fragments at 1024², 1.7M as wedges). Open meshes get sides only along their
//! shadow's outline, not along every light-facing polygon's edges (`edges = 1`), which mostly
//! lay inside it and were probed away. The centred probes read the mask's outward side first,
//! which decides alone on the hard shadow's boundary, and with a single caster skip the texel
//! under the fragment. Each sheet and each quarter-turn piece of a wedge is one record (112
//! and 64 bytes with their corners; 48 before them) in a storage buffer, which the vertex
//! shader expands (a sheet's hull, a wedge's three triangles) and whose exact t the fragment
//! shader solves: the CPU no longer tessellates
//! (koala, a moving frame, one thread: 5.6 ms before, 2.2 ms after, with facing from the mesh's
//! face planes and only the edges' vertices transformed). On lavapipe the per-fragment root
//! costs the sheets more than the vertices saved (koala 24 → 30 ms, hammer 60 → 90 ms at 512²),
//! the wedges a little less (39 → 35 ms, 168 → 156 ms).
//!
//! Centred, whether a sheet's foot lies on the hard shadow's boundary is probed once per sheet
//! (`probes`, `glsl/plateau/probes.comp`), at the middle of each texel-long piece of its hard
//! edge, rather than by each fragment (two mask reads, which on lavapipe cost the centred sheets
//! more than their roots) or each of its six vertices (the long edges of large casters as much
//! again); sheets longer than 64 texels are drawn in pieces, and a sheet whose foot is nowhere
//! on the boundary is not rasterised. Interleaved runs, 512², lavapipe: the sheets' pass on
//! the sphere 4.9 → 3.1 ms, two_boxes 6.8 → 5.8, overlap 7.7 → 6.3, the probes 0.3–0.4 ms;
//! images identical on eight scenes, 26 pixels of `default` and 2 of `overlap` changed where a
//! probe moved by up to half a texel.
//!
//! Centred, the textures are sized to the narrowest penumbra (`penumbra_texels`, shared with
//! the smoothie: `super::grid`), halved at most twice while it still spans 10 texels. The
//! outer-only form keeps the texture it is given: its penumbra starts at the mask's hard edge.
//!
//! Casters reaching the light's height: the part at or above it casts nothing (no
//! anti-shadows): its cones and sheets are skipped, and the umbra's homogeneous clip (w =
//! light height − point height > 0) cuts it off, so the shadow of the rest runs to the horizon.
//!
//! Off the plane, receivers are unshadowed (`off_plane = 0`) or read the texture where the ray
//! from the light through them meets the plane, the projected light map of §2 (`off_plane = 1`;
//! casters themselves keep only their self-shadowing, since the map holds their own shadow).
//! That self-shadowing is soft: the fraction of the light sphere in front of the surface's
//! tangent plane, exact for a convex caster (the hard test at the light's centre put most of
//! the suite's remaining penumbra error on the casters' terminators: bench's penumbra RMSE on
//! the sphere 0.110 → 0.016, low_light 0.206 → 0.046). Off the plane, shadows of other casters
//! are still missing (two_boxes' box 2 under box 1, overlap's low plate: most of their error).

use std::sync::Arc;

use ash::vk;
use bytemuck::{bytes_of, cast_slice};
use glam::{Mat4, UVec4, Vec2, Vec4};

use super::falloff::{FALLOFF, PENUMBRA};
use super::grid::{self, Halving};
use super::knobs::{Knob, Params};
use super::registry::{APPROXIMATION_BOUND, CostGoal, Kind, Receivers, Setting, SweepKnobs, TechniqueInfo};
use super::shadow_map;
use super::shadow_mesh::{CasterMeshes, SOFT_SHADOW_MESH_ERROR, shadow_caster};
use super::{Technique, clear_visibility, nearer_light, refuse_wide_lights, resolve, surface_inputs};
use crate::error::Result;
use crate::frame::interface::PlateauView;
use crate::frame::{FrameInputs, MESH_POSITIONS};
use crate::geometry::any_two_meet;
use crate::geometry::plateau::{
    Penumbra, PenumbraSize, PlateauGeometry, PlateauLight, ReceiverPlane, Sheet, Wedge, caster_sides,
};
use crate::geometry::silhouette::{Caster, EdgeSource};
use crate::gpu::{
    Access, Attachment, Blend, BufferAccess, Context, DepthState, Descriptor, FRAMES_IN_FLIGHT, Fullscreen, Guard,
    PerFrame, Pipeline, PipelineDesc, RenderPass, Target, TargetDesc, Variants, buffer_barrier, dispatch,
    draw_generated, ensure, shaders, transition,
};
use crate::scene::Mesh;
use crate::shader_constants::{COMPUTE_GROUP, MASK_PROBE, SHEET_SAMPLES};

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "plateau",
    summary: "Haines' plateaus: hard drop shadow + cones and sheets at silhouettes, on the ground plane",
    kind: Kind::Realtime,
    knobs: &[
        TEXTURE_SIZE,
        PENUMBRA_TEXELS,
        SIZE_MODE,
        PENUMBRA_SCALE,
        HAINES_FACTOR,
        CENTRED,
        CURVE,
        EDGES,
        CONES,
        OFF_PLANE,
        SOFT_SHADOW_MESH_ERROR,
    ],
    create: |ctx, _, visibility| Ok(Box::new(Plateau::new(ctx, visibility)?)),
    bench: &[
        &[],
        OUTER_ONLY,
        OUTER_ONLY_NARROW,
        WHOLE_CONES,
        &[("texture_size", "512")],
        &[("shadow_mesh_error", "0")],
    ],
    sweep_knobs: SweepKnobs::DEFAULTS,
    // Issue 4: plateaus against the hard map at the same screen size.
    cost_goal: Some(CostGoal { setting: &[], baseline: &shadow_map::INFO, baseline_setting: &[], max_ratio: 1.3 }),
    receivers: Receivers::GroundPlane,
    error_bound: Some(APPROXIMATION_BOUND),
};

/// The paper's form at its best curve (linear: the outer half starts at the hard edge, where the
/// truth is already ½, and the other curves stay darker longer), at the physical size.
pub const OUTER_ONLY: Setting = &[("penumbra", "outer"), ("falloff", "linear")];
/// The paper's form at the narrow cones it measured best with before issue 20 (0.4 of the half
/// width: wider only darkens more of the outer half).
pub const OUTER_ONLY_NARROW: Setting = &[("penumbra", "outer"), ("falloff", "linear"), ("penumbra_scale", "0.4")];

/// Centred by default: over the suite (bench, 10 scenes, 512², lavapipe, against the reference,
/// one run) its median penumbra RMSE is 0.030, against 0.312 for the outer-only form at the
/// physical size and 0.242 at its old narrow default (PCSS 16+16: 0.074, the hard map: 0.272).
const CENTRED: Knob = Knob { default: 1.0, ..PENUMBRA };
/// The disk edge by default: the exact straight-edge profile, which a centred penumbra follows.
const CURVE: Knob = Knob { default: 3.0, ..FALLOFF };

const TEXTURE_SIZE: Knob = Knob {
    name: "texture_size",
    default: 1024.0,
    min: 16.0,
    max: 8192.0,
    integer: true,
    choices: &[],
    help: "plateau texture width and height, in texels (the largest: see penumbra_texels)",
};
/// Centred, the textures sized to the narrowest penumbra ([`grid::halvings`]; the narrowest:
/// any sheet's, at its narrower end, both halves): t is exact per fragment on any texture, and
/// what a texel costs is where the mask's hard edge, the penumbra's middle, lies. At 10 (bench's
/// scenes, 512², lavapipe, interleaved runs against 0): open_mesh, overlap, plate and sphere get
/// a quarter of the width, torus and two_boxes half, the rest keep it (a caster on the ground,
/// or small ones near it); the penumbra RMSE moved by at most 0.0003 (plate 0.0278 → 0.0275,
/// open_mesh 0.0326 → 0.0324), leaks by none, and the frame took 0.80–0.89× as long (overlap
/// 42.4 → 33.8 ms, two_boxes 38.8 → 31.1, sphere 35.1 → 30.0).
const PENUMBRA_TEXELS: Knob = Knob {
    help: "centred: halve the textures (at most twice) while the narrowest penumbra spans this many texels; 0: off",
    ..grid::PENUMBRA_TEXELS
};
const SIZE_MODE: Knob = Knob::choice(
    "size_mode",
    0.0,
    &["physical", "haines"],
    "physical: penumbra from the light sphere; haines: Haines' constant factor times height",
);
const PENUMBRA_SCALE: Knob = Knob {
    name: "penumbra_scale",
    default: 1.0,
    min: 0.0,
    max: 8.0,
    integer: false,
    choices: &[],
    help: "physical mode: cone radius as a multiple of the true penumbra's half width",
};
const HAINES_FACTOR: Knob = Knob {
    name: "haines_factor",
    default: 0.1,
    min: 0.0,
    max: 10.0,
    integer: false,
    choices: &[],
    help: "size_mode=haines: cone radius per unit of height (Haines used 0.1)",
};
const EDGES: Knob = Knob::choice(
    "edges",
    0.0,
    &["outline", "polygons"],
    "outline: the shadow's outline (silhouettes, and an open mesh's boundary edges); polygons: every light-facing polygon (§3)",
);
/// Whole cones as Haines drew them (§2), against which the corner wedges are measured.
pub const WHOLE_CONES: Setting = &[("cones", "whole")];

const CONES: Knob = Knob::choice(
    "cones",
    1.0,
    &["whole", "wedges"],
    "whole: cones at silhouette vertices (§2); wedges: only their corner wedges between the sheets",
);
const OFF_PLANE: Knob = Knob::choice(
    "off_plane",
    0.0,
    &["unshadowed", "map"],
    "receivers off the plane: unshadowed, or map: the projected light map",
);

/// The plateau texture: t of the caster whose hard shadow covers the texel (or of every caster,
/// where none does), and centred with several casters, t of other casters' outer penumbrae over
/// that hard shadow (glsl/plateau/penumbra.frag's two channels).
const PLATEAU_FORMAT: vk::Format = vk::Format::R16G16_UNORM;
/// The plateau texture with nothing for a second channel to hold: outer only, or one caster.
/// Half the bytes for every pass that writes or reads it to clear, blend and gather.
const PLATEAU_FORMAT_ONE: vk::Format = vk::Format::R16_UNORM;
/// The plateau texture as the resolve reads it: its 16-bit channels packed in one integer, so
/// one gather reads both (two gathers of R16G16_UNORM cost lavapipe's resolve about 0.5 ms more
/// on `default` at 512²).
fn as_uint(format: vk::Format) -> vk::Format {
    if format == PLATEAU_FORMAT_ONE { vk::Format::R16_UINT } else { vk::Format::R32_UINT }
}
/// One sheet's probes (`SheetProbes`, two uvec4).
const SHEET_PROBE_BYTES: u64 = 32;
/// The umbra mask: each texel the number of the caster whose hard shadow covers it (0: none).
const MASK_FORMAT: vk::Format = vk::Format::R16_UNORM;

/// The largest angular radius (degrees) the light may have from a caster. A plateau keeps the
/// hard shadow as its umbra (Haines §2) and sizes each cone by the light's angle: beyond 60°
/// a vertex tilted 25° from the light already reaches the cones' 85° cap, and the hard umbra
/// stands where the truth is nearly lit (a light of radius 1e6 m 10 m above the ground: MAE
/// 0.87 against the ray tracer, streaks of capped cones to the horizon).
const MAX_LIGHT_ANGLE_DEG: f64 = 60.0;

/// The plateau's kinds of side, each drawn with its own pipeline.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Side {
    /// Corner wedges of the vertex cones.
    Wedge,
    /// Sheets along the silhouette's edges.
    Sheet,
    /// Centred, the outer halves of partial silhouettes' sheets (`partial_sides`).
    Partial,
    /// Centred, the inner halves of partial silhouettes' sheets (`partial_sides`), blended by
    /// max after the rest.
    PartialInner,
}

impl Side {
    /// penumbra.frag's `PARTIAL`: 0 the silhouette's sides, 1 partial silhouettes' outer
    /// halves, 2 their inner halves.
    fn partial(self) -> u32 {
        match self {
            Side::Wedge | Side::Sheet => 0,
            Side::Partial => 1,
            Side::PartialInner => 2,
        }
    }

    /// How its sides combine with what the texture holds: the darkest wins (§2), but the
    /// partial silhouettes' inner halves, drawn last, only darken what the rest left.
    fn blend(self) -> Blend {
        if self == Side::PartialInner { Blend::Max } else { Blend::Min }
    }
}

/// What a caster's cached sides were built from: rebuilt only when any of it changes.
#[derive(Clone, Debug, PartialEq)]
struct SidesKey {
    mesh: crate::scene::MeshId,
    model: Mat4,
    light: PlateauLight,
    plane: ReceiverPlane,
    source: EdgeSource,
}

pub struct Plateau {
    /// The umbra pass for one caster, and for several, whose depth test keeps the lowest
    /// caster's number where their hard shadows overlap: one caster needs no depth target.
    umbra: [Pipeline; 2],
    /// Side pipelines by centring, whether several casters' shadows may overlap, and the kind
    /// of side.
    penumbrae: Variants<(bool, bool, Side, bool)>,
    /// Centred, the sheets' mask probes (`glsl/plateau/probes.comp`), by whether several
    /// casters' shadows may overlap.
    probe: Variants<bool>,
    /// The probes, one [`SHEET_PROBE_BYTES`] record per sheet.
    probes: Option<PerFrame>,
    /// Resolve pipelines by falloff curve, off-plane mode, centring and whether the texture
    /// has two channels.
    resolves: Variants<(u32, bool, bool, bool)>,
    /// The plateau texture's format, with one channel and with two: where the device cannot
    /// blend into one 16-bit channel (Vulkan does not require it), two.
    formats: [vk::Format; 2],
    /// The V target's format, which the resolves write.
    visibility: vk::Format,
    view: PerFrame,
    /// The sides' primitives ([`crate::geometry::plateau::Wedge`], then `Sheet`).
    primitives: Option<PerFrame>,
    texture: Option<Target>,
    mask: Option<Target>,
    depth: Option<Target>,
    /// The textures' last halvings.
    halving: Halving,
    /// Per scene object: the sides last built and what they were built from.
    sides: Vec<Option<CasterSides>>,
    /// The meshes the umbra pass draws: the sides' (`shadow_mesh_error`).
    casters: CasterMeshes,
}

/// A caster's cached sides, and the mesh they and its umbra are cast from (the shadow mesh
/// where `shadow_mesh_error` asks for one).
#[derive(Clone)]
struct CasterSides {
    key: SidesKey,
    geometry: PlateauGeometry,
    mesh: Arc<Mesh>,
}

impl Plateau {
    /// `visibility`: the format of the V target the resolve writes.
    pub fn new(ctx: &Context, visibility: vk::Format) -> Result<Self> {
        let umbra = |depth: Option<DepthState>| {
            let desc = PipelineDesc::new("umbra", &shaders::PLATEAU_UMBRA_VERT, &shaders::PLATEAU_UMBRA_FRAG)
                .vertex_input(MESH_POSITIONS)
                .colors(&[MASK_FORMAT])
                // The depth orders casters, it must not clip them: only w > 0 may cut a caster
                // reaching above the light, whose umbra runs to the horizon.
                .depth_clamp();
            Pipeline::new(
                ctx,
                &match depth {
                    Some(depth) => desc.depth(depth),
                    None => desc,
                },
            )
        };
        let one = Guard::new(ctx, umbra(None)?);
        let several =
            Guard::new(ctx, umbra(Some(DepthState::test_write(vk::Format::D32_SFLOAT, vk::CompareOp::LESS)))?);
        let size = std::mem::size_of::<PlateauView>() as u64;
        let view = PerFrame::new(ctx, "plateau view", size, FRAMES_IN_FLIGHT, vk::BufferUsageFlags::UNIFORM_BUFFER)?;
        Ok(Plateau {
            umbra: [one.keep(), several.keep()],
            penumbrae: Variants::default(),
            probe: Variants::default(),
            probes: None,
            resolves: Variants::default(),
            formats: [
                if ctx.renders_blended(PLATEAU_FORMAT_ONE) { PLATEAU_FORMAT_ONE } else { PLATEAU_FORMAT },
                PLATEAU_FORMAT,
            ],
            visibility,
            view,
            primitives: None,
            texture: None,
            mask: None,
            depth: None,
            halving: Halving::default(),
            sides: Vec::new(),
            casters: CasterMeshes::default(),
        })
    }

    /// The plateau sides of every caster, rebuilt only for casters or a light that moved.
    fn build_sides(&mut self, frame: &FrameInputs<'_>, plane: &ReceiverPlane, light: PlateauLight, params: &Params) {
        let objects = &frame.scene.objects;
        self.sides.resize(objects.len(), None);
        for (number, (o, cached)) in objects.iter().zip(&mut self.sides).enumerate() {
            if !o.casts {
                *cached = None;
                continue;
            }
            let o = &shadow_caster(o, light.position, params);
            // Open meshes too: their silhouettes with their boundary edges bound the shadow.
            let source = if params.is_on(&EDGES) { EdgeSource::LightFacing } else { EdgeSource::Silhouettes };
            let model = o.transform.matrix();
            let key = SidesKey { mesh: o.mesh.id(), model, light, plane: *plane, source };
            if cached.as_ref().is_some_and(|c| c.key == key) {
                continue;
            }
            // In object space, as the smoothie: facing from the face planes built with the mesh,
            // then only the edges' vertices placed in the world (issue 18).
            let caster =
                Caster { positions: &o.mesh.positions, triangles: &o.mesh.triangles, adjacency: &o.mesh.adjacency };
            // The umbra mask's number: the draw's instance (the object's index) plus one.
            let number = (number + 1).min(u16::MAX as usize) as f32;
            let sides = caster_sides(plane, &light, (&caster, &o.mesh.planes), &model, source, number);
            *cached = Some(CasterSides { key, geometry: sides, mesh: o.mesh.clone() });
        }
    }

    /// The shadow's footprint (cones, sheets and the projected silhouette), cut to the visible
    /// receivers' extent on the plane: what the texture must cover.
    fn seen_footprint(
        plane: &ReceiverPlane,
        geometry: &PlateauGeometry,
        frame: &FrameInputs<'_>,
    ) -> Option<(Vec2, Vec2)> {
        let (lo, hi) = geometry.footprint?;
        // A caster reaching the light's height throws its umbra to infinity: all in view.
        let (lo, hi) = if geometry.unbounded { (Vec2::MIN, Vec2::MAX) } else { (lo, hi) };
        let seen = frame.receivers_in_view.iter().map(|p| plane.coords(*p));
        let (seen_lo, seen_hi) = seen.fold((Vec2::MAX, Vec2::MIN), |(a, b), p| (a.min(p), b.max(p)));
        let (lo, hi) = (lo.max(seen_lo), hi.min(seen_hi));
        (lo.cmplt(hi).all()).then_some((lo, hi))
    }
}

/// Moves the sides `near` a corner after the others, each kind in its order, and counts both:
/// [others, near].
fn near_last<T: Copy>(sides: &mut Vec<T>, near: impl Fn(&T) -> bool) -> [u32; 2] {
    let (close, far): (Vec<T>, Vec<T>) = sides.iter().partition(|s| near(s));
    let counts = [far.len() as u32, close.len() as u32];
    *sides = [far, close].concat();
    counts
}

/// The part of the plane a texture of `size` texels covers: `footprint` and two texels of
/// margin, which keep its rim inside.
fn window((lo, hi): (Vec2, Vec2), size: u32) -> Vec4 {
    let pad = (hi - lo) * 2.0 / size as f32;
    Vec4::new(lo.x - pad.x, lo.y - pad.y, hi.x + pad.x, hi.y + pad.y)
}

impl Technique for Plateau {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        let Some(ground) = frame.scene.ground else {
            return clear_visibility(frame, visibility); // no receiver plane: nothing to do
        };
        let ctx = frame.ctx;
        let plane = ReceiverPlane::ground(ground.height);
        refuse_wide_lights(
            frame.scene,
            "plateau",
            MAX_LIGHT_ANGLE_DEG,
            "a plateau's hard umbra and cones can stand for; use pcss, smoothie or a ground truth",
        )?;
        let size = if params.is_on(&SIZE_MODE) {
            PenumbraSize::Haines { factor: params.get(&HAINES_FACTOR) as f32 }
        } else {
            PenumbraSize::Physical { scale: params.get(&PENUMBRA_SCALE) as f32 }
        };
        let centred = params.is_on(&CENTRED);
        let (position, radius) = nearer_light(frame);
        let light = PlateauLight {
            position,
            radius,
            size,
            penumbra: if centred { Penumbra::Centred } else { Penumbra::Outer },
            wedges: params.is_on(&CONES),
        };
        self.build_sides(frame, &plane, light, params);
        let mut geometry = PlateauGeometry::default();
        self.sides.iter().flatten().for_each(|c| geometry.extend(&c.geometry));
        let finest = params.get(&TEXTURE_SIZE) as u32;
        let Some(footprint) = Self::seen_footprint(&plane, &geometry, frame) else {
            return clear_visibility(frame, visibility);
        };
        // Centred, the textures sized to the narrowest penumbra (the outer-only form's begins
        // at the hard edge, which a coarser texture moves).
        let texels = if centred { params.get(&PENUMBRA_TEXELS) as f32 } else { 0.0 };
        let extent = (footprint.1 - footprint.0).max_element();
        let narrowest = 2.0 * geometry.narrowest_half_width() / extent * finest as f32;
        let tex_size = finest >> self.halving.next(narrowest, finest, texels);
        let window = window(footprint, tex_size);
        let texel = (window.z - window.x).max(window.w - window.y) / tex_size as f32;
        let overlaps = footprints_meet(self.sides.iter().flatten().map(|c| &c.geometry), MASK_PROBE * texel);
        // Centred, a second caster's outer penumbra over one's hard shadow takes the second channel.
        let channels = centred && overlaps;
        let texture_format = self.formats[usize::from(channels)];
        let desc = TargetDesc::color("plateau texture", texture_format, tex_size, tex_size);
        ensure(ctx, &mut self.texture, desc.reinterpreted_as(as_uint(texture_format)))?;
        ensure(ctx, &mut self.mask, TargetDesc::color("plateau mask", MASK_FORMAT, tex_size, tex_size))?;
        if overlaps {
            ensure(ctx, &mut self.depth, TargetDesc::depth("plateau depth", tex_size, tex_size))?;
        }
        if centred {
            // A sample of the mask every texel along each centred sheet's hard edge.
            let texels = Vec2::splat(tex_size as f32) / Vec2::new(window.z - window.x, window.w - window.y);
            let pieces = |s: &Sheet| ((Vec2::from(s.b) - Vec2::from(s.a)) * texels).length() / SHEET_SAMPLES as f32;
            geometry.sheets = geometry.sheets.iter().flat_map(|s| s.pieces(pieces(s).ceil() as u32)).collect();
        }
        // Centred, the sides near corners go last, drawn apart (`CORNERS`): llvmpipe runs a
        // fragment shader's every branch, and the corners' arithmetic on every fragment cost
        // low_light's sheets 3.7 → 27 ms. How many of each kind: [plain, near corners].
        let (sheet_kinds, cone_kinds) = if centred {
            (near_last(&mut geometry.sheets, Sheet::near_corner), near_last(&mut geometry.cones, Wedge::at_corner))
        } else {
            ([geometry.sheets.len() as u32, 0], [geometry.cones.len() as u32, 0])
        };

        let scale = Vec2::new(2.0 / (window.z - window.x), 2.0 / (window.w - window.y));
        let to_clip = Mat4::from_cols(
            Vec4::new(scale.x, 0.0, 0.0, 0.0),
            Vec4::new(0.0, scale.y, 0.0, 0.0),
            Vec4::ZERO,
            Vec4::new(-1.0 - window.x * scale.x, -1.0 - window.y * scale.y, 0.0, 1.0),
        );
        let view = PlateauView {
            umbra: to_clip * plane.shadow_matrix(light.position),
            plane_origin: plane.origin.extend(0.0),
            plane_normal: plane.normal.extend(0.0),
            plane_u: plane.u.extend(0.0),
            plane_v: plane.v.extend(0.0),
            window,
            sheets: UVec4::new(geometry.cones.len() as u32, geometry.sheets.len() as u32 * u32::from(centred), 0, 0),
        };
        self.view.write(frame.slot, bytes_of(&view));
        let view_range = self.view.range(frame.slot);

        // One record per primitive, wedges then sheets, of one size: the vertex shader finds
        // its primitive from gl_VertexIndex (issue 18: 48 bytes a primitive, not a tessellation).
        let records: [&[u8]; 4] = [
            cast_slice(&geometry.cones),
            cast_slice(&geometry.sheets),
            cast_slice(&geometry.partial),
            cast_slice(&geometry.partial_inner),
        ];
        let bytes = records.iter().map(|r| r.len() as u64).sum();
        if bytes > 0 {
            let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
            let buffer = PerFrame::ensure(ctx, &mut self.primitives, "plateau sides", bytes, usage)?;
            buffer.write(frame.slot, &records.concat());
        }
        // Bound with every side, probed or not.
        let probe_bytes = SHEET_PROBE_BYTES * geometry.sheets.len().max(1) as u64;
        PerFrame::ensure(ctx, &mut self.probes, "plateau probes", probe_bytes, vk::BufferUsageFlags::STORAGE_BUFFER)?;
        let cmd = frame.cmd;

        // The umbra is the casters' hard shadow: drawn from the meshes the sides came from, the
        // simplified shadow meshes where `shadow_mesh_error` asks for them (their uploads recorded
        // before the pass), else the frame's own.
        let sides = &self.sides;
        self.casters.prepare(frame, |i| sides.get(i).and_then(Option::as_ref).map(|c| &c.mesh))?;
        let texture = self.texture.as_mut().expect("ensured");
        let mask = self.mask.as_mut().expect("ensured");
        // umbra: the mask cleared to 0 (no caster), then the flattened casters, the lowest nearest.
        frame.timer.begin(ctx, cmd, "umbra");
        let mut depth = self.depth.as_mut().filter(|_| overlaps);
        let mut writes = vec![(&mut *mask, Access::COLOR_WRITE, true)];
        writes.extend(depth.as_deref_mut().map(|d| (d, Access::DEPTH_WRITE, true)));
        transition(ctx, cmd, &mut writes);
        let pass = RenderPass::begin(
            ctx,
            cmd,
            &[Attachment::clear_color(mask, [0.0; 4])],
            depth.map(|d| Attachment::clear_depth(d, 1.0)),
        );
        let umbra = &self.umbra[usize::from(overlaps)];
        umbra.bind(ctx, cmd, &[Descriptor::Buffer(view_range), Descriptor::Buffer(frame.objects)])?;
        self.casters.record(frame);
        pass.end(ctx, cmd);
        frame.timer.end(ctx, cmd);
        transition(ctx, cmd, &mut [(mask, Access::SHADERS_READ, false)]);
        let probes = self.probes.as_ref().expect("ensured").range(frame.slot);
        // What the probes and the sides read.
        let inputs = self.primitives.as_ref().map(|p| {
            [
                Descriptor::Buffer(view_range),
                Descriptor::Image(mask),
                Descriptor::Buffer(p.range(frame.slot)),
                Descriptor::Buffer(probes),
            ]
        });
        if let Some(inputs) = inputs.as_ref().filter(|_| view.sheets.y > 0) {
            // probes: where each centred sheet's foot lies on the hard shadow's boundary.
            frame.timer.begin(ctx, cmd, "probes");
            let pipeline = self.probe.get(overlaps, |&overlaps| {
                let constants = [("OVERLAPS", overlaps as u32)];
                Pipeline::compute(ctx, "probes", &shaders::PLATEAU_PROBES_COMP, &constants)
            })?;
            pipeline.bind(ctx, cmd, inputs)?;
            dispatch(ctx, cmd, view.sheets.y.div_ceil(COMPUTE_GROUP));
            buffer_barrier(ctx, cmd, BufferAccess::COMPUTE_WRITE, BufferAccess::VERTEX_STORAGE_READ);
            frame.timer.end(ctx, cmd);
        }

        let (cones, sheets, partial) =
            (geometry.cones.len() as u32, geometry.sheets.len() as u32, geometry.partial.len() as u32);
        // Per primitive, a wedge's three triangles or a sheet's two (see penumbra.vert); partial
        // silhouettes' sheets in the sheets' pass, after them, the inner halves last.
        // Centred, the sides near corners after the others, with the corners' code.
        let ([plain_sheets, corner_sheets], [plain_cones, corner_cones]) = (sheet_kinds, cone_kinds);
        let sheet_draws = [
            (Side::Sheet, false, 6 * cones, 6 * plain_sheets),
            (Side::Sheet, true, 6 * (cones + plain_sheets), 6 * corner_sheets),
            (Side::Partial, false, 6 * (cones + sheets), 6 * partial),
            (Side::PartialInner, false, 6 * (cones + sheets + partial), 6 * geometry.partial_inner.len() as u32),
        ];
        let cone_draws =
            [(Side::Wedge, false, 0, 9 * plain_cones), (Side::Wedge, true, 9 * plain_cones, 9 * corner_cones)];
        let passes = [("cones", &cone_draws[..]), ("sheets", &sheet_draws[..])];
        for (i, (name, draws)) in passes.into_iter().enumerate() {
            frame.timer.begin(ctx, cmd, name);
            // The cones' pass clears t to 1 (lit), the sheets' carries on. Blended by min,
            // channel by channel: the darkest primitive wins (§2); then partial silhouettes'
            // inner halves by max, which darken the hard shadow's side (see the module's doc).
            let fresh = i == 0;
            transition(ctx, cmd, &mut [(texture, Access::COLOR_WRITE, fresh)]);
            let color = match fresh {
                true => Attachment::clear_color(texture, [1.0; 4]),
                false => Attachment { target: texture, clear: None },
            };
            let pass = RenderPass::begin(ctx, cmd, &[color], None);
            for &(side, corners, first, count) in draws.iter().filter(|d| d.3 > 0) {
                let Some(inputs) = inputs.as_ref() else { break };
                let key = (centred, overlaps, side, corners);
                let penumbra = self.penumbrae.get(key, move |&(centred, overlaps, side, corners)| {
                    let constants = [
                        ("CENTRED", centred as u32),
                        ("OVERLAPS", overlaps as u32),
                        ("SHEETS", (side != Side::Wedge) as u32),
                        ("PARTIAL", side.partial()),
                        ("CORNERS", corners as u32),
                    ];
                    let (vert, frag) = (&shaders::PLATEAU_PENUMBRA_VERT, &shaders::PLATEAU_PENUMBRA_FRAG);
                    let formats = [texture_format];
                    let desc = PipelineDesc::new("penumbra", vert, frag)
                        .colors(&formats)
                        .blend(side.blend())
                        .constants(&constants);
                    Pipeline::new(ctx, &desc)
                })?;
                penumbra.bind(ctx, cmd, inputs)?;
                draw_generated(ctx, cmd, first, count);
            }
            pass.end(ctx, cmd);
            frame.timer.end(ctx, cmd);
        }

        transition(ctx, cmd, &mut [(texture, Access::FRAGMENT_READ, false)]);
        let inputs =
            [&surface_inputs(frame, view_range)[..], &[Descriptor::Reinterpreted(texture), Descriptor::Image(mask)]]
                .concat();
        let format = self.visibility;
        let key = (params.get(&CURVE) as u32, params.is_on(&OFF_PLANE), centred, channels);
        let pipeline = self.resolves.get(key, |&(curve, off_plane, centred, channels)| {
            let constants = [
                ("FALLOFF", curve),
                ("OFF_PLANE_MAP", off_plane as u32),
                ("CENTRED", centred as u32),
                ("CHANNELS", channels as u32),
            ];
            let desc = Fullscreen::new("resolve", &shaders::PLATEAU_RESOLVE_FRAG, format).constants(&constants);
            Pipeline::fullscreen(ctx, &desc)
        })?;
        resolve(frame, pipeline, visibility, &inputs)
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        let this = *self;
        this.umbra.into_iter().for_each(|p| p.destroy(ctx));
        this.penumbrae.destroy(ctx);
        this.probe.destroy(ctx);
        this.resolves.destroy(ctx);
        this.view.destroy(ctx);
        this.primitives.into_iter().chain(this.probes).for_each(|b| b.destroy(ctx));
        this.casters.destroy(ctx);
        this.texture.into_iter().chain(this.mask).chain(this.depth).for_each(|t| t.destroy(ctx));
    }
}

/// Whether two casters' shadows may overlap: their footprints (umbra, cones and sheets: their
/// shadows' bounds on the plane, unbounded for a caster reaching the light's height) within
/// `probe` of each other, the distance the mask probes look from a hard edge. Only then do the
/// casters need the second channel, the umbra pass's depth target that orders their numbers and
/// the sides' reads of the mask; apart, one caster's targets hold them all, as exactly: no side
/// or probe of one caster reaches another's number. Overlap's plates moved 3 m apart: V the same
/// bit for bit, the umbra pass 0.49–0.67 → 0.41–0.45 ms and the sheets 0.75–0.92 → 0.65–0.69
/// (512², lavapipe, four interleaved runs of 40 frames). Every multi-caster scene of the suite
/// has shadows that meet, `default`'s too.
fn footprints_meet<'a>(casters: impl Iterator<Item = &'a PlateauGeometry>, probe: f32) -> bool {
    let boxes: Vec<(Vec2, Vec2)> =
        casters.filter_map(|g| if g.unbounded { Some((Vec2::MIN, Vec2::MAX)) } else { g.footprint }).collect();
    any_two_meet(&boxes, probe)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn casters_overlap_only_where_their_footprints_come_within_a_probe() {
        let at = |lo: Vec2, hi: Vec2| PlateauGeometry { footprint: Some((lo, hi)), ..PlateauGeometry::default() };
        let unit = at(Vec2::ZERO, Vec2::ONE);
        // Another footprint `gap` to the right of the unit square's: within two probes of
        // 0.1 they meet (each grown by one), beyond they do not.
        let beside = |gap: f32| at(Vec2::new(1.0 + gap, 0.5), Vec2::new(2.0 + gap, 0.7));
        assert!(footprints_meet([&unit, &beside(0.19)].into_iter(), 0.1));
        assert!(!footprints_meet([&unit, &beside(0.21)].into_iter(), 0.1));
        // Diagonal neighbours apart in one axis do not meet.
        assert!(!footprints_meet([&unit, &at(Vec2::new(1.5, 1.5), Vec2::splat(2.0))].into_iter(), 0.1));
        // One caster, or one without a shadow, meets nothing; one reaching the light's height
        // meets every other.
        assert!(!footprints_meet([&unit].into_iter(), 0.1));
        assert!(!footprints_meet([&unit, &PlateauGeometry::default()].into_iter(), 0.1));
        let unbounded = PlateauGeometry { unbounded: true, ..beside(50.0) };
        assert!(footprints_meet([&unit, &unbounded].into_iter(), 0.1));
    }
}
