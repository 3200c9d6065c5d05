//! `smoothie`: Chan & Durand's fake soft shadows ("Rendering Fake Soft Shadows with Smoothies",
//! 2003), on every receiver, casters included.
//!
//! Passes, in the paper's order: `shadow_map` (pass 1, the shared [`ShadowMapPass`], linear depth
//! in R32F or the paper's 16-bit float), `smoothie_buffer` (the smoothie edges and corners drawn
//! from the light into depth b and remapped alpha α' = α / (1 − b/r) at once, packed in one
//! 16-bit two-channel target with minimum blending, b as a logarithmic code: see
//! [`Buffer`]), `resolve` (the two depth comparisons at the four nearest texels, then
//! the falloff; in two draws, the second only where a smoothie is near: see
//! [`MaskedResolve::record`]).
//!
//! r, the receiver's distance behind a smoothie texel, is the nearer of the casters' depth in
//! the map (as Figure 11 reads it) and the ground plane's along the texel's ray, computed
//! exactly: the paper's map held every surface, ours holds the casters, so receivers that cast
//! nothing never block light.
//!
//! Size: t = `t_scale` · R / b per vertex by default (see [`SmoothieSize::Physical`]), the
//! physical size (`t_scale` 1); the `t` knob sets the paper's fixed screen-space t instead.
//!
//! Penumbra (issue 20, the `penumbra` knob): the paper's smoothies grow outward only, so the
//! whole hard shadow stays umbra and a physical size only darkens (§3). Centred, each edge also
//! gets an inner quad over its blocker (`geometry::smoothie`), drawn into more channels of the
//! smoothie buffer (α and 1 − b, minimum-blended too: the shallowest inner alpha, as the blocker
//! is the intersection of its edges' half planes, and the farthest inner depth, which errs dark;
//! with several casters 1 − b and a limit take a second target, see [`Buffer`]), the resolve
//! maps the distance over the whole width, t = ½ ± ½α' on the lit and the shadowed side,
//! through the falloff curve, so V = ½ on the hard edge and the umbra shrinks as the light
//! grows, vanishing once the inner halves from both sides of a blocker meet. The smoothie pass
//! accepts an inner fragment only where its edge bounds its own caster's hard shadow (nothing in
//! the map just outside the edge within the caster's depth range: no fold of the same caster, no
//! other caster abutting it) and the map's blocker at the fragment is that caster (its depth
//! inside the caster's range): one caster's inner half never lightens what another blocks, and
//! interior silhouettes (folds) stay umbra. A caster wholly behind it outside the edge (the lower
//! of two boxes) takes the inner half down to its own depth, the inner quad's limit: past it,
//! the receivers it hides stay umbra.
//!
//! Overlapping casters, centred: each caster's α' goes to one of two channels by the parity of
//! its number, and the resolve multiplies the two channels' visibilities (as the plateau's
//! resolve does), so where two casters' penumbrae cross, the light each hides counts as
//! independent of the other's instead of the darker alone winning (the paper's minimum
//! blending, §3.1, which left V ½ where the truth is about ¼). And a smoothie behind the map's
//! caster is kept (the paper drops it as hidden, Figure 11): in that caster's inner penumbra the
//! receiver sees part of the light, which the caster behind may hide too, so there it counts as
//! another blocker in the channel the inner half is not in. Together they took the leaking
//! pixels on overlap and two_boxes from 90 and 51 to 0 (512², against the reference).
//!
//! Partial silhouettes, centred, as the plateau's: a face within the light's angular radius of
//! edge-on hands the silhouette to its other edge for part of the light. Above the silhouette
//! (both faces lit from the centre) that edge's smoothie reaches further out (`low_light`: 137
//! leaking pixels, 27 with them). Their smoothie edges (`geometry::smoothie::partial_smoothies`,
//! and the compute path's) lie over their caster's outline in the map; the smoothie pass keeps
//! them where the map's surface lies behind the turned face (lit, or another receiver, which a
//! partial silhouette shadows as it does the ground), and the resolve lets them darken only
//! receivers behind the turned face. Below it (both unlit), nearer the receiver, the edge is
//! the silhouette for the part of the light a receiver inside the hard shadow still sees, with
//! the narrower inner half: its inner quad is drawn last, its alpha converted to the
//! silhouette's depth and blended by max into the inner alpha (`Part::PARTIAL_INNER`). A thick
//! slab's inner half (tests/smoothie_centred.rs): 28 px against the reference's 27, 35 before
//! (128², RMSE over the image 0.023 → 0.0064).
//!
//! Corners, centred (`geometry::smoothie::ShadowCorner`): where two edges of the hard shadow's
//! outline turn, the truth cuts the light's footprint by both lines, ¾ of the light at a right
//! convex apex and ¼ at a reflex one, where each smoothie alone says ½. As the plateau's sides
//! do, the pieces of the edges' quads and the wedges within reach of such a corner carry it, and
//! the smoothie pass writes the alpha whose curve gives V under both lines, the footprint the
//! disk of radius t·(1 − b/r) about the fragment (`glsl/smoothie/centred.glsl`); they are drawn
//! apart (`Part`), as llvmpipe runs every branch. Measured (bench, 512², lavapipe, against the
//! reference, one run each), penumbra RMSE before → after: plate 0.0275 → 0.0104, open_mesh
//! 0.031 → 0.0090, overlap 0.042 → 0.0103, two_boxes 0.047 → 0.029, contact 0.035 → 0.025, the
//! suite's median 0.0275 → 0.0120, no scene worse by over 0.0005 and no leaking pixel more; the
//! smoothie pass, interleaved runs of 30 frames: plate 0.56–0.59 → 1.17–1.28 ms, overlap
//! 1.5 → 3.5–3.8, contact 2.7–3.0 → 4.7–4.9, default 3.5–3.8 → 5.2–5.6. A convex corner
//! lightens only where the light passes both edges (`corner_open`: nothing nearer than the
//! caster just outside either, as under a post standing on a slab), 0.05–0.3 ms more. A corner
//! needs the straight runs of the outline into it two footprints long, its lines theirs, so a
//! flat side cut into short edges turns as its uncut twin does, and the vertices along a run
//! within reach carry its corner (`geometry::smoothie`'s `Run`, `corner_near`). A turn split by
//! a short edge is one corner, at the runs' lines' meeting point (a thin plate lit past its
//! side: 0.22 too dark at its light-side corners before), that carries the short edge's line too
//! for footprints narrower than the cut (contact's slab at its foot: 0.94 too dark at 128²
//! before; `ShadowCorner::chamfer`).
//!
//! Shadow meshes (issue 18, `shadow_mesh_error`): the smoothies and the map of pass 1 are cast
//! from the same simplified copy of each caster, and the map is fitted to the copies, so the hard
//! edge the penumbra straddles is the silhouettes' own edge. Only the camera draws the full mesh.
//! On the scale scenes the map of the full mesh cost 13–34 ms, as much as the hard map's
//! pass of the 1024² row it is measured against (koala: 34 → 5 ms; bench, 512², lavapipe,
//! one run).
//!
//! Cost (issue 18): `merge` links each caster's silhouette into chains and simplifies them
//! (`geometry::chains`) before the smoothies are made, on the CPU path only (the compute path,
//! `gpu_silhouettes`, draws every edge); off by default, see [`MERGE`].
//!
//! Deviations: the smoothie buffer has no depth target. Minimum blending of b gives the nearest
//! smoothie in any order, which a depth test would only give for the depth, not for the alpha
//! that the paper also minimum-blends. The inner half is remapped in the resolve, with the
//! receiver's own depth for r: the map's surface behind an inner texel is the blocker itself.

use std::sync::Arc;

use ash::vk;
use bytemuck::cast_slice;
use glam::{Mat4, Vec2, Vec3, Vec4};

use super::falloff::{FALLOFF, PENUMBRA};
use super::grid::{self, Halving};
use super::knobs::{Knob, Params};
use super::registry::{APPROXIMATION_BOUND, CostGoal, Kind, Receivers, Setting, SweepKnobs, TechniqueInfo};
use super::shadow_map::{self, DEFAULT_BIASES, EMPTY_DEPTH, SHADOW_MAP_SIZE, ShadowMapPass};
use super::shadow_mesh::{CasterMeshes, LIGHT_VIEW_TEXELS, SHADOW_MESH_ERROR, SOFT_SHADOW_MESH_ERROR, shadow_mesh};
use super::smoothie_gpu::GpuSilhouettes;
use super::{Technique, clear_visibility, surface_inputs};
use crate::error::Result;
use crate::frame::FrameInputs;
use crate::geometry::silhouette::{Caster, EdgeSource, PartialEdge, partial_silhouettes, penumbra_edges};
use crate::geometry::smoothie::{
    CutGrid, Penumbra, ReceiverBound, SmoothieGeometry, SmoothieSize, depth_range, merged_silhouette, merged_smoothies,
    partial_smoothies, smoothies,
};
use crate::geometry::{Aabb, LightFrustum, any_two_meet};
use crate::gpu::{
    Access, Attachment, Blend, Context, DRAW_COMMAND_BYTES, DepthState, Descriptor, Guard, PerFrame, Pipeline,
    PipelineDesc, RenderPass, Target, TargetDesc, Variants, VertexInput, draw_fullscreen, draw_indirect, draw_vertices,
    ensure, shaders, transition,
};
use crate::scene::Mesh;

pub const INFO: TechniqueInfo = TechniqueInfo {
    name: "smoothie",
    summary: "Chan & Durand's smoothies: shadow map + silhouette quads with remapped alpha, on every receiver",
    kind: Kind::Realtime,
    knobs: &[
        MAP_SIZE,
        SMOOTHIE_SIZE,
        T,
        T_SCALE,
        CENTRED,
        SMOOTHIE_FALLOFF,
        DEPTH16,
        GPU_SILHOUETTES,
        MERGE,
        PENUMBRA_TEXELS,
        SOFT_SHADOW_MESH_ERROR,
    ],
    create: |ctx, _, visibility| Ok(Box::new(Smoothie::new(ctx, visibility)?)),
    bench: &[
        &[],
        OUTER_ONLY,
        &[("depth16", "on")],
        &[("gpu_silhouettes", "on")],
        &[("shadow_mesh_error", "0")],
        &[("merge", "1")],
        QUARTER_TEXELS,
    ],
    sweep_knobs: SweepKnobs::DEFAULTS,
    // Issue 5: the smoothie's map is 1024² by default, so against the hard map at 1024².
    cost_goal: Some(CostGoal {
        setting: &[],
        baseline: &shadow_map::INFO,
        baseline_setting: &[("shadow_map_size", "1024")],
        max_ratio: 1.3,
    }),
    receivers: Receivers::All,
    error_bound: Some(APPROXIMATION_BOUND),
};

/// The papers' form at its best-measured curve (linear: see [`FALLOFF`]), for bench's rows and
/// cost goals.
pub const OUTER_ONLY: Setting = &[("penumbra", "outer"), ("falloff", "linear")];

/// The map and the smoothie buffer at half the default width whatever the penumbrae: a quarter
/// of their texels, for bench's row of the trade.
const QUARTER_TEXELS: Setting = &[("shadow_map_size", "512"), ("smoothie_size", "512"), ("penumbra_texels", "0")];

/// The paper's map is smaller than the hard shadow map's default. At half of it with a buffer
/// to match ([`QUARTER_TEXELS`]; bench, 512², lavapipe, one run) the frame cost 0.65–0.91× the
/// default's and the penumbra RMSE stayed within 0.0007 on seven suite scenes, but where
/// penumbrae are a few texels wide it broke: the wingnut near contact 0.018 → 0.050 with 341
/// leaking pixels where there were none, `default` 0.057 → 0.063 and leaks 155 → 493 (the torus
/// 0.0089 → 0.0107 against the reference before its receiver-plane tests; against today's,
/// 0.0088 → 0.0082): hence [`PENUMBRA_TEXELS`], which halves them only where the smoothies are
/// wide. Both sizes are the largest the map and buffer get.
const MAP_SIZE: Knob = Knob { default: 1024.0, ..SHADOW_MAP_SIZE };
const SMOOTHIE_SIZE: Knob = Knob {
    name: "smoothie_size",
    default: 1024.0,
    min: 16.0,
    max: 16384.0,
    integer: true,
    choices: &[],
    help: "smoothie buffer width and height, in texels (the largest: see penumbra_texels)",
};
const T: Knob = Knob {
    name: "t",
    default: 0.0,
    min: 0.0,
    max: 1.0,
    integer: false,
    choices: &[],
    help: "smoothie size in the light's tangent units; 0: from the light radius (t_scale R / b)",
};
/// The physical size by default: centred, the penumbra RMSE is least there (256², against the
/// reference): plate 0.058, 0.028, 0.057 at 0.8, 1, 1.25; sphere 0.099, 0.088, 0.101
/// (examples/smoothie_profile.rs, docs/smoothie_t_scale.png).
const T_SCALE: Knob = Knob {
    name: "t_scale",
    default: 1.0,
    min: 0.0,
    max: 8.0,
    integer: false,
    choices: &[],
    help: "with t = 0: smoothie size as a multiple of the light's angular radius from the blocker",
};
/// Centred: what measured better. bench, 10 scenes, 512², against the reference (lavapipe, one
/// run, with the soft terminator): median penumbra RMSE 0.029 centred, 0.283 outer only (linear
/// curve), 0.071 PCSS 16 + 16.
const CENTRED: Knob = Knob { default: 1.0, ..PENUMBRA };
/// The disk edge (curve 3), exact for a straight edge over the centred width; penumbra RMSE at
/// 256² against linear: plate 0.028 / 0.050, sphere 0.088 / 0.096, default 0.112 / 0.117,
/// overlap 0.072 / 0.083, low_light 0.204 / 0.206.
const SMOOTHIE_FALLOFF: Knob = Knob { default: 3.0, ..FALLOFF };
const DEPTH16: Knob = Knob::switch("depth16", "on: the paper's 16-bit float shadow map; off: 32-bit");
const GPU_SILHOUETTES: Knob = Knob::switch(
    "gpu_silhouettes",
    "on: silhouettes and smoothies in a compute shader, drawn indirectly (every edge: no merge); off: on the CPU",
);

/// Map and buffer sized to the narrowest smoothie: where every caster's smoothies span many
/// texels, a coarser grid resolves them as well ([`grid::halvings`]): across a smoothie's width
/// its alpha is linear, which the resolve's bilinear lookup holds exactly on any grid, and what
/// a texel costs is where the map's hard edge lies, a texel of which moves V by about 1/texels
/// of the penumbra. The narrowest is estimated at each caster's deepest silhouette vertex
/// ([`narrowest_smoothie`]), on the farthest ground over the caster's window.
///
/// 8 texels, from what a halving costs (examples/grid_texels.rs, docs/grid_texels.png: plate
/// and sphere under lights of ¼ to 2× their radius, fixed grids of 1024², 512² and 256² against
/// the reference): no penumbra RMSE, to 1e-4, while the narrowest smoothie spanned 5.5 texels
/// of the coarser grid or more, 0.0002–0.0011 at 2.8–4.3 texels, 0.0072 at 1.4; and `contact`,
/// the slab leaning on the ground, lost at 2.8 (256²: 0.036 → 0.046, 52 pixels leaking at its
/// foot) and nothing at 5.6 (512²). So 8, about 1.5× the least that measured harmless: the
/// suite's grids are low_light and the sphere 256², open_mesh, overlap, plate, the torus and
/// two_boxes 512² (the last two at 9.5 and 8.4 texels of it: penumbra RMSE 0.0082 and 0.0488
/// against 0.0088 and 0.0488 at 1024², bench's `QUARTER_TEXELS` row), `contact`, `default` and
/// the wingnut 1024² (5.6, 1.3 and 0 texels of 512²). At 10, the first default, the torus and
/// two_boxes kept 1024² for nothing; and before the estimate took the ground under a caster
/// dipping into it, `contact` had got 512² from 38 texels, harmlessly, its foot uncounted.
const PENUMBRA_TEXELS: Knob = Knob {
    default: 8.0,
    help: "halve map and buffer (at most twice) while the narrowest smoothie spans this many texels; 0: off",
    ..grid::PENUMBRA_TEXELS
};

/// Silhouette chains merged before the smoothies are made (`geometry::chains`), within this
/// many smoothie-buffer texels in position and in reach: fewer edges and corners on fine
/// meshes. The CPU path only: the compute path draws every silhouette edge.
///
/// Off by default: V stays within 1/255 of the unmerged smoothies' on the suite (192²,
/// lavapipe) at no tolerance above 0. Centred, every silhouette vertex drew a corner when these
/// were measured (a square at straight and concave turns, the inner half at convex ones; now
/// wedges, see `geometry::smoothie`, not re-measured), so dropping even an exactly collinear
/// vertex changed V (open_mesh: 0.40 at any tolerance); and near contact α' = α / (1 −
/// b/r) magnifies the depth interpolated along a merged edge (wingnut: 2.6/255 at 0.03 texels,
/// 0.05 at 0.25). Outer only, open_mesh still moves by 6/255. At 1 texel (bench, 512², one
/// run) the buffer pass takes 0.4–0.9× its unmerged time on the suite and the scale scenes, but
/// the wingnut's penumbra, a few texels wide near contact, goes from RMSE 0.018 to 0.189: a
/// bound in texels is too loose where the penumbra is narrow.
const MERGE: Knob = Knob {
    name: "merge",
    default: 0.0,
    min: 0.0,
    max: 16.0,
    integer: false,
    choices: &[],
    help: "CPU path: merge silhouette chains within this many smoothie-buffer texels (position and size); 0: off",
};

const DEPTH_FORMAT: vk::Format = vk::Format::R32_SFLOAT;
/// The resolve's penumbra mask: only 0 and 1 are ever in it.
const MASK_FORMAT: vk::Format = vk::Format::D16_UNORM;
/// The largest finite 16-bit float.
const HALF_MAX: f32 = 65504.0;
/// What the smoothie buffer holds, which its fragment shader writes and the resolve reads: the
/// technique builds the smallest the scene allows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Buffer {
    /// The paper's: depth b (as a code in [0, 1], glsl/smoothie/depth.glsl) and remapped alpha
    /// α' (glsl/smoothie/smoothie.frag).
    Outer,
    /// Centred, one caster: b, α', and in a second target the inner quads' 1 − b and α
    /// (glsl/smoothie/centred_one.frag).
    Centred,
    /// Centred, several casters: as one caster's, the even casters' α' in the first target and
    /// the inner α with its caster's channel in the second, and a third, the odd casters' α'
    /// and the inner quads' limit (glsl/smoothie/centred.frag).
    Channels,
}

impl Buffer {
    const ALL: [Buffer; 3] = [Buffer::Outer, Buffer::Centred, Buffer::Channels];

    /// The buffer for the `centred` form or not, of casters whose smoothies `meet` or not
    /// ([`casters_meet`]).
    fn new(centred: bool, meet: bool) -> Self {
        match (centred, meet) {
            (false, _) => Buffer::Outer,
            (true, false) => Buffer::Centred,
            (true, true) => Buffer::Channels,
        }
    }

    fn centred(self) -> bool {
        self != Buffer::Outer
    }

    fn fragment_shader(self) -> &'static shaders::Shader {
        match self {
            Buffer::Outer => &shaders::SMOOTHIE_SMOOTHIE_FRAG,
            Buffer::Centred => &shaders::SMOOTHIE_CENTRED_ONE_FRAG,
            Buffer::Channels => &shaders::SMOOTHIE_CENTRED_FRAG,
        }
    }

    /// Its targets' formats, minimum-blended, two channels each (centred.frag says why):
    /// unsigned normalized 16-bit channels where the device blends into them (Vulkan does not
    /// require it), else 32-bit floats holding the same codes.
    fn formats(self, ctx: &Context) -> Vec<vk::Format> {
        let rg = if ctx.renders_blended(vk::Format::R16G16_UNORM) {
            vk::Format::R16G16_UNORM
        } else {
            vk::Format::R32G32_SFLOAT
        };
        let targets = match self {
            Buffer::Outer => 1,
            Buffer::Centred => 2,
            Buffer::Channels => 3,
        };
        vec![rg; targets]
    }
}

/// A resolve pipeline's specialization: falloff curve, buffer, same grid.
type ResolveKey = (u32, Buffer, bool);

/// The resolve's two draws' pipelines and the target between them.
#[derive(Default)]
struct MaskedResolve {
    masks: Variants<ResolveKey>,
    penumbrae: Variants<ResolveKey>,
    /// Which pixels the mask draw left to the penumbra draw.
    mask: Option<Target>,
}

impl MaskedResolve {
    /// The resolve in two draws into V: the mask draw shades every pixel with the hard test and
    /// the self-shadowing, and discards those near a smoothie, which keep the mask target's
    /// cleared depth; the penumbra draw, depth-tested against it, shades only those. Each pixel
    /// is written once, by one of them; the pass is timed as one.
    fn record(
        &mut self,
        frame: &mut FrameInputs<'_>,
        format: vk::Format,
        key: ResolveKey,
        visibility: &mut Target,
        inputs: &[Descriptor<'_>],
    ) -> Result<()> {
        let (ctx, cmd) = (frame.ctx, frame.cmd);
        let pipeline = |mask: bool, depth: DepthState| {
            move |&(curve, buffer, same_grid): &ResolveKey| {
                let constants = [
                    ("FALLOFF", curve),
                    ("CENTRED", u32::from(buffer.centred())),
                    ("SAME_GRID", u32::from(same_grid)),
                    ("MASK", u32::from(mask)),
                    ("CHANNELS", u32::from(buffer == Buffer::Channels)),
                ];
                let formats = [format];
                let desc =
                    PipelineDesc::new("resolve", &shaders::COMMON_FULLSCREEN_VERT, &shaders::SMOOTHIE_RESOLVE_FRAG)
                        .colors(&formats)
                        .depth(depth)
                        .constants(&constants);
                Pipeline::new(ctx, &desc)
            }
        };
        // The full-screen triangle lies at depth 0: the mask draw writes 0 where it shades, the
        // penumbra draw passes where the clear's 1 is left.
        let mask_pipeline =
            self.masks.get(key, pipeline(true, DepthState::test_write(MASK_FORMAT, vk::CompareOp::ALWAYS)))?;
        let penumbra_pipeline =
            self.penumbrae.get(key, pipeline(false, DepthState::test_only(MASK_FORMAT, vk::CompareOp::LESS)))?;
        let extent = visibility.extent();
        ensure(
            ctx,
            &mut self.mask,
            TargetDesc { format: MASK_FORMAT, ..TargetDesc::depth("penumbra mask", extent.width, extent.height) },
        )?;
        let mask = self.mask.as_mut().expect("ensured");
        frame.timer.begin(ctx, cmd, "resolve");
        transition(ctx, cmd, &mut [(visibility, Access::COLOR_WRITE, true), (mask, Access::DEPTH_WRITE, true)]);
        let pass = RenderPass::begin(
            ctx,
            cmd,
            &[Attachment { target: visibility, clear: None }],
            Some(Attachment::clear_depth(mask, 1.0)),
        );
        let mut bound = mask_pipeline.bind(ctx, cmd, inputs);
        if bound.is_ok() {
            draw_fullscreen(ctx, cmd);
            bound = penumbra_pipeline.bind(ctx, cmd, inputs);
            if bound.is_ok() {
                draw_fullscreen(ctx, cmd);
            }
        }
        pass.end(ctx, cmd);
        frame.timer.end(ctx, cmd);
        bound
    }

    fn destroy(self, ctx: &Context) {
        self.masks.destroy(ctx);
        self.penumbrae.destroy(ctx);
        self.mask.into_iter().for_each(|t| t.destroy(ctx));
    }
}

/// What a caster's silhouette was found from: recomputed only when it changes.
#[derive(Clone, Debug, PartialEq)]
struct SilhouetteKey {
    mesh: crate::scene::MeshId,
    model: Mat4,
    light: Vec3,
    /// The light's radius, centred; 0 (no partial silhouettes) outer only.
    partial_radius: f32,
}

/// A caster's silhouette edges and partial silhouettes (object-space vertex numbers), and
/// what they were found from.
struct CasterSilhouette {
    key: SilhouetteKey,
    edges: Vec<([u32; 2], u32)>,
    partial: Vec<PartialEdge>,
}

pub struct Smoothie {
    pass: ShadowMapPass,
    /// The smoothie pass, by what its buffer holds, which smoothies a draw holds and whether
    /// map and buffer share one grid (centred only; the paper's buffer reads no map texels).
    smoothie: Variants<(Buffer, Part, bool)>,
    /// The smoothie buffer's formats, by [`Buffer`] (in the order of [`Buffer::ALL`]).
    buffer_formats: [Vec<vk::Format>; 3],
    resolve: MaskedResolve,
    /// The V target's format, which the resolves write.
    visibility: vk::Format,
    vertices: Option<PerFrame>,
    /// The smoothie buffer's targets, as many as its layout has ([`Buffer::formats`]).
    buffer: [Option<Target>; 3],
    silhouettes: Vec<Option<CasterSilhouette>>,
    /// The meshes the shadow map draws: the smoothies' own (`shadow_mesh_error`).
    casters: CasterMeshes,
    /// The compute path, made when first asked for.
    gpu: Option<GpuSilhouettes>,
    /// The map and buffer's last halvings.
    halving: Halving,
}

impl Smoothie {
    /// `visibility`: the format of the V target the resolve writes.
    pub fn new(ctx: &Context, visibility: vk::Format) -> Result<Self> {
        let pass = Guard::new(ctx, ShadowMapPass::new(ctx, DEPTH_FORMAT)?);
        Ok(Smoothie {
            pass: pass.keep(),
            smoothie: Variants::default(),
            buffer_formats: Buffer::ALL.map(|b| b.formats(ctx)),
            resolve: MaskedResolve::default(),
            visibility,
            vertices: None,
            buffer: [None, None, None],
            silhouettes: Vec::new(),
            casters: CasterMeshes::default(),
            gpu: None,
            halving: Halving::default(),
        })
    }

    /// Finds the silhouettes of every caster again where it or the light moved.
    fn find_silhouettes(&mut self, frame: &FrameInputs<'_>, cast: &[Option<Arc<Mesh>>], centred: bool) {
        let objects = &frame.scene.objects;
        let light = frame.scene.light.position;
        let partial_radius = if centred { frame.scene.light.radius } else { 0.0 };
        self.silhouettes.resize_with(objects.len(), || None);
        for ((o, mesh), cached) in objects.iter().zip(cast).zip(&mut self.silhouettes) {
            let Some(mesh) = mesh else {
                *cached = None;
                continue;
            };
            let model = o.transform.matrix();
            let key = SilhouetteKey { mesh: mesh.id(), model, light, partial_radius };
            if cached.as_ref().is_some_and(|c| c.key == key) {
                continue;
            }
            // In object space: the face planes built with the mesh against the light taken
            // there, then the silhouette's own vertices through view · model, so a moved caster
            // costs no transform of its whole mesh.
            let caster = Caster { positions: &mesh.positions, triangles: &mesh.triangles, adjacency: &mesh.adjacency };
            let facing = mesh.planes.light_facing(&model, light);
            let edges = penumbra_edges(&caster, &facing, EdgeSource::Silhouettes);
            let partial = partial_silhouettes(&caster, &mesh.planes, &facing, &model, light, partial_radius);
            *cached = Some(CasterSilhouette { key, edges, partial });
        }
    }

    /// Where each caster's smoothies start ([`Self::find_silhouettes`]), as
    /// [`narrowest_smoothie`] takes it: the caster's window in `frustum` and its deepest
    /// silhouette vertex; nothing for a caster without a silhouette.
    fn silhouette_starts<'a>(
        &'a self,
        frame: &'a FrameInputs<'_>,
        cast: &'a [Option<Arc<Mesh>>],
        frustum: &'a LightFrustum,
    ) -> impl Iterator<Item = ([f32; 4], f32)> + 'a {
        let objects = frame.scene.objects.iter().zip(cast).zip(&self.silhouettes);
        objects.filter_map(|((o, mesh), silhouette)| {
            let (mesh, silhouette) = (mesh.as_ref()?, silhouette.as_ref()?);
            let model = o.transform.matrix();
            let view = frustum.view * model;
            let ends = silhouette.edges.iter().flat_map(|(e, _)| *e);
            let deepest = ends.map(|v| view.transform_point3(mesh.positions[v as usize]).z).reduce(f32::max)?;
            Some((frustum.window_of(&mesh.bounds.transformed(&model)), deepest))
        })
    }

    /// The smoothies of every caster ([`Self::find_silhouettes`]) through this frame's light
    /// view, and where each caster's lie for [`casters_meet`]: their box
    /// ([`SmoothieGeometry::window`], which holds the caster's outline in the map too, the
    /// silhouette they start from, within the merge `tolerance`), everywhere for a caster
    /// reaching the light's plane (its outline is unbounded), none for one without smoothies.
    fn geometry(
        &self,
        frame: &FrameInputs<'_>,
        cast: &[Option<Arc<Mesh>>],
        frustum: &LightFrustum,
        (size, receivers): (SmoothieSize, ReceiverBound),
        (centred, grid, tolerance): (bool, CutGrid, f32),
    ) -> (SmoothieGeometry, Vec<[f32; 4]>) {
        let mut out = SmoothieGeometry::default();
        let mut windows = Vec::new();
        let casters = frame.scene.objects.iter().zip(cast).zip(&self.silhouettes);
        // Casters numbered as the compute path numbers them: those that cast, in order.
        let casting = casters.filter_map(|((o, mesh), c)| Some((o, mesh.as_ref()?, c.as_ref().expect("found"))));
        for (number, (o, mesh, c)) in (1..).zip(casting) {
            let caster = Caster { positions: &mesh.positions, triangles: &mesh.triangles, adjacency: &mesh.adjacency };
            let model = o.transform.matrix();
            let view = frustum.view * model;
            let penumbra = penumbra(centred, grid, &view, &mesh.bounds);
            let mut geometry = if tolerance > 0.0 {
                let merged = merged_silhouette(&view, &caster, &c.edges, (size, receivers), tolerance);
                merged_smoothies(&view, &caster, &merged, (size, receivers), penumbra)
            } else {
                smoothies(&view, &caster, &c.edges, (size, receivers), penumbra)
            };
            geometry.extend(&partial_smoothies(&view, &caster, &c.partial, (size, receivers), penumbra));
            if !frustum.window_of(&mesh.bounds.transformed(&model)).iter().all(|v| v.is_finite()) {
                windows.push(EVERYWHERE);
            } else if let Some([x0, y0, x1, y1]) = geometry.window() {
                windows.push([x0 - tolerance, y0 - tolerance, x1 + tolerance, y1 + tolerance]);
            }
            out.extend(&geometry.in_channel(number));
        }
        (out, windows)
    }
}

impl Technique for Smoothie {
    fn record(&mut self, frame: &mut FrameInputs<'_>, params: &Params, visibility: &mut Target) -> Result<()> {
        // Every pass casts from the same meshes, the simplified ones where `shadow_mesh_error`
        // asks for them, the map fitted to them too: its hard edge is where the smoothies'
        // silhouettes are.
        let light = frame.scene.light.position;
        let cast: Vec<Option<Arc<Mesh>>> =
            frame.scene.objects.iter().map(|o| o.casts.then(|| shadow_mesh(o, light, params))).collect();
        self.casters.prepare(frame, |i| cast.get(i).and_then(Option::as_ref))?;
        let bounds = self.casters.bounds();
        let Some(frustum) = ShadowMapPass::fit_to(frame, &bounds) else {
            return clear_visibility(frame, visibility);
        };
        let t = params.get(&T) as f32;
        let centred = params.is_on(&CENTRED);
        let smoothie_size = if t > 0.0 {
            SmoothieSize::Fixed(t)
        } else {
            SmoothieSize::Physical {
                light_radius: frame.scene.light.radius,
                scale: params.get(&T_SCALE) as f32,
                behind: frustum.view.transform_point3(frame.scene.light.position).length(),
            }
        };
        // Smoothies reach t beyond the casters' outline, cut at their receivers: the map and
        // buffer must cover them.
        let receivers = receiver_bound(frame, &frustum);
        let frustum = frustum.grown(smoothie_size.largest_reach(frustum.near, frustum.window, receivers));
        let ctx = frame.ctx;
        let format = if params.is_on(&DEPTH16) { vk::Format::R16_SFLOAT } else { DEPTH_FORMAT };
        if self.pass.format() != format {
            let old = std::mem::replace(&mut self.pass, ShadowMapPass::new(ctx, format)?);
            ctx.retire(move |ctx| old.destroy(ctx));
        }
        let [x0, y0, x1, y1] = frustum.window;
        let window = (x1 - x0).max(y1 - y0);
        let gpu_silhouettes = params.is_on(&GPU_SILHOUETTES);
        // What the compute path knows of its casters before the GPU finds their silhouettes.
        let extents: Vec<CasterExtent> =
            if gpu_silhouettes { bounds.iter().map(|b| CasterExtent::new(&frustum, b)).collect() } else { Vec::new() };
        if !gpu_silhouettes {
            self.find_silhouettes(frame, &cast, centred);
        }
        // The outer-only form's penumbra begins at the map's hard edge, which a coarser grid
        // moves by its texel: a box's outline 0.5 mm off moved V by up to 0.063 at 512² against
        // 2/255 at 1024² (tests/smoothie.rs, a_finely_tessellated_outline_casts_*).
        let texels = if centred { params.get(&PENUMBRA_TEXELS) as f32 } else { 0.0 };
        // The CPU path knows where the smoothies start, on the silhouettes; the compute path
        // finds them only on the GPU, and takes the casters' bounds, which hold them: never a
        // coarser grid, and a narrower estimate where a caster's bounds reach deeper than its
        // silhouettes (the sphere, the torus, the box on the ground of two_boxes).
        // The penumbra the grid must resolve lies on the receivers, the ground among them even
        // where a caster dips into it, as one touching it does: the smoothies' cut above cannot
        // take the plane there (part of that caster lies beyond it), but without it a slab
        // leaning on the ground (`contact`) measured 38 texels at its foot, where its penumbra
        // vanishes, and took a grid that lost accuracy there (see PENUMBRA_TEXELS).
        let penumbra_receivers =
            ReceiverBound { ground: ground_plane(frame, &frustum), ..ReceiverBound::up_to(frustum.far) };
        let narrowest = if texels <= 0.0 {
            f32::INFINITY
        } else if gpu_silhouettes {
            narrowest_smoothie(extents.iter().map(|c| (c.window, c.deepest)), smoothie_size, penumbra_receivers)
        } else {
            narrowest_smoothie(self.silhouette_starts(frame, &cast, &frustum), smoothie_size, penumbra_receivers)
        };
        let (size, buffer_size) = (params.get(&MAP_SIZE) as u32, params.get(&SMOOTHIE_SIZE) as u32);
        let finest = size.min(buffer_size);
        let halved = self.halving.next(narrowest / window * finest as f32, finest, texels);
        let (size, buffer_size) = (size >> halved, buffer_size >> halved);
        // The ground's height (none: infinitely far below) and the light view origin's, for r in
        // pass 2.
        let ground = frame.scene.ground.map_or(-f32::MAX, |g| g.height);
        // The projection centre's: the fit moves a far light closer (LightFrustum::centre).
        let light_y = frustum.centre().y;
        // What an empty map texel reads: the clear depth, which a 16-bit map saturates.
        let empty = if format == DEPTH_FORMAT { EMPTY_DEPTH } else { HALF_MAX };
        let kernel = Vec4::new(buffer_size as f32, empty, ground, light_y);
        // A simplified caster strays from its surface by up to its bound, in front of it too:
        // the depth biases hold that much more (in this map's texels, at most as large as the
        // bound's, whose view is fitted to one caster), so its lit side does not shadow itself.
        // Without one they stay: more bias moves contact shadows (wingnut penumbra RMSE 0.018 →
        // 0.020 at one texel more).
        let bound = if self.casters.simplified() { params.get(&SHADOW_MESH_ERROR) as f32 } else { 0.0 };
        let stray = bound * size as f32 / LIGHT_VIEW_TEXELS;
        let [depth_bias, slope_bias, normal_offset] = DEFAULT_BIASES;
        let biases = [depth_bias + stray, slope_bias + stray, normal_offset];
        self.pass.record(frame, &frustum, size, biases, kernel, Some(&self.casters))?;

        // The smoothies: vertices drawn directly (CPU path) or indirectly (compute path), and
        // where each caster's lie ([`casters_meet`]).
        let grid = CutGrid::new(window / buffer_size as f32, ctx.info.sub_pixel_precision_bits);
        let (source, windows) = if gpu_silhouettes {
            if self.gpu.is_none() {
                self.gpu = Some(GpuSilhouettes::new(ctx)?);
            }
            let gpu = self.gpu.as_mut().expect("made above");
            let radius = frame.scene.light.radius;
            let (vertices, args) =
                gpu.record(frame, &cast, &frustum.view, (smoothie_size, receivers), (centred, radius, grid))?;
            let windows = extents.iter().map(|c| c.reach(smoothie_size, receivers)).collect();
            (Smoothies::Indirect { vertices, args }, windows)
        } else {
            // The merge bound in tangent units: texels of the smoothie buffer over the window.
            let [x0, y0, x1, y1] = frustum.window;
            let tolerance = params.get(&MERGE) as f32 * (x1 - x0).max(y1 - y0) / buffer_size as f32;
            let (geometry, windows) =
                self.geometry(frame, &cast, &frustum, (smoothie_size, receivers), (centred, grid, tolerance));
            let (vertices, counts) = geometry.drawn();
            let bytes: &[u8] = cast_slice(&vertices);
            let source = if bytes.is_empty() {
                Smoothies::None
            } else {
                let usage = vk::BufferUsageFlags::VERTEX_BUFFER;
                let v = PerFrame::ensure(ctx, &mut self.vertices, "smoothies", bytes.len() as u64, usage)?;
                v.write(frame.slot, bytes);
                Smoothies::Direct { vertices: v.range(frame.slot), counts }
            };
            (source, windows)
        };

        // Two texels of the coarser grid: an inner quad's probe looks 1.5 map texels outside.
        let texel = window / buffer_size.min(size) as f32;
        let layout = Buffer::new(centred, casters_meet(&windows, 2.0 * texel));
        let formats = &self.buffer_formats[layout as usize];
        for ((target, &format), name) in
            self.buffer.iter_mut().zip(formats).zip(["smoothie buffer", "inner smoothies", "odd smoothies"])
        {
            ensure(ctx, target, TargetDesc::color(name, format, buffer_size, buffer_size))?;
        }
        let draws = source.draws(layout.centred());
        let same_grid = !layout.centred() || buffer_size == size;
        let make = |&(layout, part, same_grid): &(Buffer, Part, bool)| {
            let constants = if layout.centred() {
                vec![
                    ("INNER", u32::from(part.inner)),
                    ("CORNERS", u32::from(part.corners)),
                    ("CHAMFER", u32::from(part.chamfer)),
                    ("SAME_GRID", u32::from(same_grid)),
                    ("PARTIAL", u32::from(part.partial)),
                ]
            } else {
                Vec::new()
            };
            // Every channel by minimum (the shader's), but the partial silhouettes' inner quads,
            // which only darken what the others left.
            let blend = if part.partial { Blend::Max } else { Blend::Min };
            let desc = PipelineDesc::new("smoothie_buffer", &shaders::SMOOTHIE_SMOOTHIE_VERT, layout.fragment_shader())
                .vertex_input(VertexInput::Floats(&[3, 2, 2, 2, 2, 1, 1, 2, 4, 1, 1, 2, 3]))
                .colors(formats)
                .constants(&constants)
                .blend(blend);
            Pipeline::new(ctx, &desc)
        };
        // Made before anything is recorded, so that a failure leaves no pass half recorded.
        for &(part, _) in &draws {
            self.smoothie.get((layout, part, same_grid), make)?;
        }
        let cmd = frame.cmd;
        let (map, light) = self.pass.inputs(frame.slot);
        let targets = &mut self.buffer[..formats.len()];

        frame.timer.begin(ctx, cmd, "smoothie_buffer");
        let mut writes: Vec<_> = targets.iter_mut().flatten().map(|t| (t, Access::COLOR_WRITE, true)).collect();
        transition(ctx, cmd, &mut writes);
        // What minimum blending leaves where no smoothie is: the farthest depth code, alphas of
        // 1, an inner alpha of 1 (umbra, as no inner quad) and the nearest inner depth.
        let clears: Vec<_> = targets.iter().flatten().map(|t| Attachment::clear_color(t, [1.0; 4])).collect();
        let pass = RenderPass::begin(ctx, cmd, &clears, None);
        for (part, draw) in draws {
            let smoothie = self.smoothie.get((layout, part, same_grid), make)?;
            smoothie.bind(ctx, cmd, &[Descriptor::Buffer(light), Descriptor::Image(map)])?;
            match draw {
                Draw::Vertices { vertices, first, count } => draw_vertices(ctx, cmd, vertices, first, count),
                Draw::Indirect { vertices, args } => draw_indirect(ctx, cmd, vertices, args),
            }
        }
        pass.end(ctx, cmd);
        frame.timer.end(ctx, cmd);

        let mut reads: Vec<_> = targets.iter_mut().flatten().map(|t| (t, Access::FRAGMENT_READ, false)).collect();
        transition(ctx, cmd, &mut reads);
        // The resolve reads only the buffer's targets of this layout; the first stands in for
        // the others.
        let [outer, inner, odd] = [0, 1, 2].map(|i| self.buffer[i].as_ref().filter(|_| i < formats.len()));
        let outer = outer.expect("ensured");
        let [inner, odd] = [inner, odd].map(|t| Descriptor::Image(t.unwrap_or(outer)));
        let inputs =
            [&surface_inputs(frame, light)[..], &[Descriptor::Image(map), Descriptor::Image(outer), inner, odd]]
                .concat();
        // One frustum for both: equal sizes put the buffer's texels on the map's.
        let key = (params.get(&SMOOTHIE_FALLOFF) as u32, layout, buffer_size == size);
        self.resolve.record(frame, self.visibility, key, visibility, &inputs)
    }

    fn destroy(self: Box<Self>, ctx: &Context) {
        let this = *self;
        this.pass.destroy(ctx);
        this.smoothie.destroy(ctx);
        this.resolve.destroy(ctx);
        this.vertices.into_iter().for_each(|b| b.destroy(ctx));
        this.buffer.into_iter().flatten().for_each(|t| t.destroy(ctx));
        this.casters.destroy(ctx);
        this.gpu.into_iter().for_each(|g| g.destroy(ctx));
    }
}

/// What bounds the receivers' depths behind the smoothies of `frustum` ([`ReceiverBound`]): the
/// ground plane too where the light and every receiver in view lie above it.
fn receiver_bound(frame: &FrameInputs<'_>, frustum: &LightFrustum) -> ReceiverBound {
    let far = ReceiverBound::up_to(frustum.far);
    let (Some(ground), Some(plane)) = (frame.scene.ground, ground_plane(frame, frustum)) else { return far };
    let height = frustum.centre().y - ground.height;
    // A receiver's bounds may touch the plane from below by rounding.
    let above = |p: &Vec3| p.y >= ground.height - 1e-4 * height;
    if !frame.receivers_in_view.iter().all(above) {
        return far;
    }
    ReceiverBound { ground: Some(plane), ..far }
}

/// The ground plane as [`ReceiverBound::ground`] takes it, where the light lies above it.
fn ground_plane(frame: &FrameInputs<'_>, frustum: &LightFrustum) -> Option<Vec3> {
    let height = frustum.centre().y - frame.scene.ground?.height;
    // 1/r along the ray (x/z, y/z, 1): its world y per unit depth (the view's rows are the
    // light's axes; glsl/smoothie/depth.glsl's ground_depth) over the plane's, −height.
    (height > 0.0).then(|| frustum.view.y_axis.truncate() / -height)
}

/// Where a caster's bounds lie in the light view: their tangent window and depth range, which
/// the compute path takes for [`casters_meet`] and [`narrowest_smoothie`].
struct CasterExtent {
    window: [f32; 4],
    near: f32,
    deepest: f32,
}

impl CasterExtent {
    fn new(frustum: &LightFrustum, bounds: &Aabb) -> Self {
        let (near, deepest) = depth_range(&frustum.view, bounds);
        CasterExtent { window: frustum.window_of(bounds), near, deepest }
    }

    /// Where its smoothies can lie, for [`casters_meet`] on the compute path, which makes them
    /// on the GPU: its window grown by the farthest they reach, everywhere for a caster
    /// reaching the light's plane.
    fn reach(&self, size: SmoothieSize, receivers: ReceiverBound) -> [f32; 4] {
        let pad = size.largest_reach(self.near, self.window, receivers);
        let [x0, y0, x1, y1] = self.window;
        let grown = [x0 - pad, y0 - pad, x1 + pad, y1 + pad];
        if grown.iter().all(|v| v.is_finite()) { grown } else { EVERYWHERE }
    }
}

/// A window that meets every other.
const EVERYWHERE: [f32; 4] = [f32::NEG_INFINITY, f32::NEG_INFINITY, f32::INFINITY, f32::INFINITY];

/// Whether two casters' smoothies can meet in the buffer, or one's inner quads probe the other
/// just outside its edge (glsl/smoothie/centred.glsl): only then do they need the channels of
/// [`Buffer::Channels`]. Casters apart, one caster's buffer holds them all as well, a target
/// fewer (overlap's two plates moved about 3 m further apart, 512², lavapipe, three interleaved
/// runs: the smoothie pass 5.5–6.7 → 4.4–5.5 ms, the resolve 11.9–15.6 → 10.4–14.4, V the same
/// within 1e-4). `windows`: where each caster's smoothies and outline lie (tangent boxes), each
/// grown by `pad` against every other's.
///
/// The CPU path gives the boxes of the smoothies it made ([`Smoothie::geometry`]), the compute
/// path its casters' bounds grown by the smoothies' reach ([`CasterExtent::reach`]): a bounds'
/// box reaches well past its silhouette's smoothies. On `default` every caster's grown bounds
/// met another's, none of their smoothies' boxes did, and the one-caster buffer took the
/// smoothie pass from 5.3–6.5 to 4.2–5.0 ms and the resolve from 9.9–14.0 to 8.2–10.5 (512²,
/// lavapipe, four interleaved runs of 40 frames), V the same within 6e-4 (the channel bit).
fn casters_meet(windows: &[[f32; 4]], pad: f32) -> bool {
    let boxes: Vec<(Vec2, Vec2)> =
        windows.iter().map(|&[x0, y0, x1, y1]| (Vec2::new(x0, y0), Vec2::new(x1, y1))).collect();
    any_two_meet(&boxes, pad)
}

/// An estimate of the narrowest smoothie of `casters` (each its window and the deepest point a
/// smoothie of it starts from: its deepest silhouette vertex, or its bounds' deepest point,
/// which lies no nearer), in tangent units: each caster's at that point, where t = R/b is least
/// and so is the part 1 − b/r of it that `receivers` (the ground) can need; the least of them.
/// Partial silhouettes do not count: one is drawn only where it reaches further than the
/// silhouette's ([`partial_smoothies`]). Its receivers' own penumbrae are narrower still where
/// they lie in front of the ground (a caster on another): those receivers then get the coarser
/// grid.
fn narrowest_smoothie(
    casters: impl Iterator<Item = ([f32; 4], f32)>,
    size: SmoothieSize,
    receivers: ReceiverBound,
) -> f32 {
    casters.map(|(window, deepest)| size.largest_reach(deepest, window, receivers)).fold(f32::INFINITY, f32::min)
}

/// The smoothies' side for a caster within `bounds` seen through `view`; centred, into the
/// buffer of `grid`.
pub(super) fn penumbra(centred: bool, grid: CutGrid, view: &Mat4, bounds: &Aabb) -> Penumbra {
    if centred {
        let (near, far) = depth_range(view, bounds);
        Penumbra::Centred { near, far, grid }
    } else {
        Penumbra::Outer
    }
}

/// Where this frame's smoothie vertices are.
enum Smoothies {
    /// The CPU path's, one range after the other, as many vertices as `counts` gives each
    /// [`Part`] (in the order of [`Part::ALL`]).
    Direct {
        vertices: vk::DescriptorBufferInfo,
        counts: [u32; 7],
    },
    /// The compute path's: an indirect draw per part of [`Part::INDIRECT`], one after the other in `args`.
    Indirect {
        vertices: vk::DescriptorBufferInfo,
        args: vk::DescriptorBufferInfo,
    },
    None,
}

impl Smoothies {
    /// The draws of the smoothie pass, one per [`Part`]; into the paper's buffer (`centred`
    /// false) only the outer smoothies away from corners, the only part there is.
    fn draws(&self, centred: bool) -> Vec<(Part, Draw)> {
        let all = match self {
            Smoothies::Indirect { .. } => &Part::INDIRECT[..],
            _ => &Part::ALL[..],
        };
        let parts = if centred { all } else { &all[..1] };
        let draw = |(i, &part): (usize, &Part)| match *self {
            Smoothies::Direct { vertices, counts } => {
                let first = counts[..i].iter().sum();
                (counts[i] > 0).then_some((part, Draw::Vertices { vertices, first, count: counts[i] }))
            }
            Smoothies::Indirect { vertices, args } => {
                let offset = args.offset + i as u64 * DRAW_COMMAND_BYTES;
                let one = vk::DescriptorBufferInfo { offset, range: DRAW_COMMAND_BYTES, ..args };
                Some((part, Draw::Indirect { vertices, args: one }))
            }
            Smoothies::None => None,
        };
        parts.iter().enumerate().filter_map(draw).collect()
    }
}

/// One draw of the smoothie pass.
enum Draw {
    Vertices { vertices: vk::DescriptorBufferInfo, first: u32, count: u32 },
    Indirect { vertices: vk::DescriptorBufferInfo, args: vk::DescriptorBufferInfo },
}

/// Which smoothies a draw of the smoothie pass holds: the outer smoothies or the inner quads
/// (`INNER`, glsl/smoothie/centred.glsl), near the hard shadow's corners or not (`CORNERS`),
/// chamfered ones among them or not (`CHAMFER`), or the inner quads of partial silhouettes
/// below the silhouette (`PARTIAL`), drawn last and blended by max
/// (`geometry::smoothie::partial_smoothies`).
/// Centred, each is drawn apart, running only its own part of the shader, since llvmpipe runs
/// both branches of a test it cannot fold. Outer and inner drawn together, every fragment ran
/// both; the images are the same bit for bit (the suite, both paths), and apart the smoothie
/// pass took 0.85× its time on two_boxes (6.83 → 5.79 ms) and the wingnut, 0.90× on the
/// sphere, 0.92× on the torus, and 1.03× on `default`, whose five casters' two draws cost more
/// than their fragments save (512², lavapipe, medians of three interleaved runs of 20 frames;
/// the compute path alike: two_boxes 7.0 → 5.9 ms).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Part {
    inner: bool,
    corners: bool,
    chamfer: bool,
    partial: bool,
}

impl Part {
    const fn new(inner: bool, corners: bool, chamfer: bool) -> Self {
        Part { inner, corners, chamfer, partial: false }
    }

    const PARTIAL_INNER: Part = Part { inner: true, corners: false, chamfer: false, partial: true };

    /// The CPU path's parts, in drawing order (`SmoothieGeometry::drawn`): the chamfered corners
    /// apart, whose three line pairs cost twice the corner's arithmetic again; drawn with the
    /// others, every corner fragment paid it. contact's smoothie pass (512², lavapipe, medians of
    /// six interleaved runs of 40 frames): 5.92 ms before the chamfers, 7.3 with every corner
    /// paying them, 6.65 with them apart (6.02 with their arithmetic off), 5.85–5.99 since
    /// corners.glsl's corner_v runs one disk_in_both and takes the angles from the vertices.
    const ALL: [Part; 7] = [
        Part::new(false, false, false),
        Part::new(false, true, false),
        Part::new(false, true, true),
        Part::new(true, false, false),
        Part::new(true, true, false),
        Part::new(true, true, true),
        Part::PARTIAL_INNER,
    ];

    /// The compute path's, one indirect draw each (silhouettes.comp's `Args`): its corners,
    /// chamfered or not, in one draw, whose every fragment pays the chamfer's arithmetic.
    const INDIRECT: [Part; 5] = [
        Part::new(false, false, false),
        Part::new(false, true, true),
        Part::new(true, false, false),
        Part::new(true, true, true),
        Part::PARTIAL_INNER,
    ];
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::fit_spot_frustum;

    #[test]
    fn casters_get_channels_only_where_their_smoothies_can_meet() {
        let light = Vec3::new(0.0, 8.0, 0.0);
        let ground = Aabb { min: Vec3::new(-6.0, 0.0, -6.0), max: Vec3::new(6.0, 0.0, 6.0) }.corners();
        let size = SmoothieSize::Physical { light_radius: 0.5, scale: 1.0, behind: 0.0 };
        // Flat plates 7 below the light, one still, one sliding towards it.
        let plate = |x: f32| Aabb { min: Vec3::new(x - 0.3, 1.0, -0.3), max: Vec3::new(x + 0.3, 1.0, 0.3) };
        let still = plate(-2.0);
        let meet = |gap: f32| {
            let casters = [still, plate(-1.4 + gap)];
            let frustum = fit_spot_frustum(light, None, &casters, &ground).frustum.expect("in view");
            // The ground's plane bounds the receivers (receiver_bound), 8 below the light.
            let ground = Some(frustum.view.y_axis.truncate() / -8.0);
            let receivers = ReceiverBound { far: frustum.far, ground };
            casters_meet(&casters.map(|b| CasterExtent::new(&frustum, &b).reach(size, receivers)), 2e-3)
        };
        // Each plate's smoothies reach R (1 − b/r) = 0.5 (1 − 7/8) ≈ 0.06 m beyond it on the
        // ground, and two texels, 0.014 m: plates nearer than 0.15 m meet, plates further apart
        // do not.
        let gaps: Vec<(f32, bool)> =
            (0..=40).map(|i| 2.0 * (1.0 - i as f32 / 40.0)).map(|gap| (gap, meet(gap))).collect();
        assert!(gaps.iter().all(|&(gap, m)| m || gap > 0.1), "plates within both reaches meet: {gaps:?}");
        assert!(gaps.iter().all(|&(gap, m)| !m || gap < 0.2), "plates further apart do not: {gaps:?}");
        assert!(gaps.windows(2).all(|w| w[0].1 <= w[1].1), "once met, nearer still meets: {gaps:?}");
        // A caster reaching the light's plane covers every direction.
        let casters = [still, Aabb { min: Vec3::new(3.0, 7.0, -0.3), max: Vec3::new(3.6, 9.0, 0.3) }];
        let frustum = fit_spot_frustum(light, None, &casters[..1], &ground).frustum.expect("in view");
        let reach = casters.map(|b| CasterExtent::new(&frustum, &b).reach(size, ReceiverBound::up_to(frustum.far)));
        assert!(casters_meet(&reach, 2e-3));
    }
}
