//! Chan & Durand's smoothies ("Rendering Fake Soft Shadows with Smoothies", 2003) as pure
//! geometry: at each silhouette edge a *smoothie edge*, the edge extended outward by t in the
//! light's screen space, and at each silhouette vertex a *smoothie corner* (§3, Figure 2).
//!
//! Everything is in the light view's tangent plane (x/z, y/z), where the spot frustum's window
//! is given. Each vertex carries the blocker's linear light depth b and shape coordinates whose
//! length is the linear alpha: 0 on the silhouette, 1 at t (edges: distance from the edge / t;
//! corners: |v − p| / t, Figure 6).
//!
//! Corners are the paper's wedges where two edges meet: only the gap outside a convex turn,
//! with radial alpha; a vertex with any other number of edges gets a full square of half-size
//! t instead, which covers every direction (see [`corner`]). Full squares at every vertex
//! cost (2t)² fragments each, most of them hidden under the edges: on a finely tessellated
//! mesh, tens of times the buffer's area (issue 18).
//!
//! Beyond the paper (issue 20): with [`Penumbra::Centred`] each edge also gets an *inner* quad,
//! the mirror of its smoothie edge over the blocker, so the penumbra straddles the hard edge as
//! the truth's does: the true penumbra of a straight edge spans (R/b)(1 − b/r) on *each* side
//! of the hard edge in the light's tangent plane (similar triangles through the edge from both
//! rims of the light). Inner vertices carry what the smoothie pass needs to accept them only
//! where the edge bounds this caster's own hard shadow (`glsl/smoothie/centred.glsl`): the
//! point of the edge they belong to, its outward normal and the caster's light-depth range.
//! Inside a convex corner the two edges' inner quads overlap (minimum blending keeps the
//! shallower, lighter alpha); inside a concave one they leave a gap, which the mirror image of
//! the outer wedge fills (see [`corner`]).
//! [`partial_smoothies`] adds the smoothie edges of edges that are the silhouette for part of
//! the light only.
//!
//! Centred, near a corner of the hard shadow ([`ShadowCorner`]) the truth cuts the light's
//! footprint by both edges' lines, where each smoothie takes its own: at a convex corner the
//! apex sees ¾ of the light and the smoothies said ½ (plate: errors up to 0.25 at its four
//! corners), at a reflex one ¼. As the plateau's sides do (`geometry::plateau`'s `Corner`), the
//! smoothies near such a corner carry it, its vertex and both edges' normals, and the smoothie
//! pass writes the alpha that gives V under both lines (`glsl/smoothie/centred.glsl`). Only the
//! pieces of an edge's quads within reach of the corner carry it ([`ShadowCorner::piece`]), so that
//! only their fragments pay for its arithmetic.

use glam::{Mat2, Mat4, Vec2, Vec3};

use super::Aabb;
use super::chains::{self, MergedEdge, PenumbraEdge};
use super::plateau::MIN_TURN;
use super::silhouette::{Caster, EdgeSource, FacePlanes, PARTIAL_GAIN, PartialEdge, penumbra_edges};
pub use crate::shader_constants::KEEP_ALL;
use crate::shader_constants::{
    KEEP_SLACK, MAX_INNER_REACH, MAX_WALK, MIN_DEPTH, RUN_STRAY, SLIVER, SLIVER_STEPS, SMOOTHIE_VERTEX_FLOATS,
};

/// One smoothie vertex.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct SmoothieVertex {
    /// Light-view tangent coordinates.
    pub x: f32,
    pub y: f32,
    /// The blocker's linear light depth.
    pub b: f32,
    /// |shape| is the linear alpha.
    pub sx: f32,
    pub sy: f32,
    /// Inner quads: the point of the silhouette edge this vertex belongs to and the edge's
    /// outward normal, tangent coordinates; zero elsewhere.
    pub fx: f32,
    pub fy: f32,
    pub nx: f32,
    pub ny: f32,
    /// Inner quads: the caster's light-depth range; (0, 0) marks the outer smoothies, (b, −1)
    /// those of partial silhouettes, b the depth receivers must lie behind
    /// ([`partial_smoothies`]).
    pub near: f32,
    pub far: f32,
    /// Projective weight 1/t: an edge's t varies along it, so its alpha, distance over t, is
    /// not linear across its quad, and interpolated linearly it would depend on which diagonal
    /// splits the quad (up to 8/255 in V on the plate). Drawn with w = 1/t, the perspective-
    /// correct interpolation of α gives Σλd / Σλt, exact for the quad's affine d and t.
    /// Corners have one t, where any constant would do: theirs too, so that 1/w is the size t
    /// on every smoothie (the corners' arithmetic, `glsl/smoothie/centred.glsl`).
    pub w: f32,
    /// Which of the centred buffer's two channels the caster's smoothies go to (0 or 1, by
    /// the parity of its number; see [`SmoothieGeometry::in_channel`]).
    pub channel: f32,
    /// Centred, near a corner of the hard shadow ([`ShadowCorner`]): its vertex, tangent
    /// coordinates; zero elsewhere. A partial silhouette's inner quad, which has no corner
    /// ([`partial_smoothies`]): the silhouette's depth there in `cx`.
    pub cx: f32,
    pub cy: f32,
    /// Its two edges' outward normals; a partial silhouette's inner quad: its inward normal,
    /// then zeros.
    pub normals: [f32; 4],
    /// 1 where the hard shadow is convex there, −1 reflex; 0: no corner.
    pub turn: f32,
    /// Pieces of an edge's quads ([`edge_quad`]): how far along the edge, 0 at its first end, 1
    /// at its second; and the part of that the piece draws, its fragments elsewhere discarded.
    /// [`KEEP_ALL`] elsewhere.
    pub along: f32,
    pub keep: [f32; 2],
    /// A turn split by a short edge ([`ShadowCorner::chamfer`]): that edge's outward normal and
    /// how far the corner lies outside its line; zero elsewhere.
    pub chamfer: [f32; 3],
}

// The compute path writes the vertices as floats (glsl/smoothie/silhouettes.comp).
const _: () = assert!(size_of::<SmoothieVertex>() == SMOOTHIE_VERTEX_FLOATS * 4);

/// A vertex of the hard shadow's outline where two silhouette edges turn (issue 20): near it
/// the penumbra is the light's footprint cut by both edges' lines. As the plateau's `Corner`
/// (`geometry::plateau`): a turn of [`MIN_TURN`] at least; and each edge [`CORNER_REACH`]
/// footprint radii long or more, so that both lines stand for edges across the footprint; and
/// at most [`SHARPEST_TURN`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowCorner {
    pub at: Vec2,
    pub normals: [Vec2; 2],
    pub convex: bool,
    /// Where the turn is split by a short edge, away from `at` where the lines meet: that edge's
    /// line, its outward normal m and how far `at` lies outside it, m·(at − p) for p on it. A
    /// footprint wider than the cut sees the corner at `at`; a narrower one at the cut's foot
    /// (a receiver near contact) sees the short edge's line and the lit sliver the cut leaves
    /// (`glsl/smoothie/centred.glsl`'s corner_visibility).
    pub chamfer: Option<(Vec2, f32)>,
}

/// How many footprint radii (t·k) each of a [`ShadowCorner`]'s edges must run from it. The
/// plateau's ½ (`geometry::plateau::CORNER_REACH`) made corners of most vertices of a
/// tessellated curve, where the two lines stand for the outline no better than one, and where
/// the CPU and compute paths then parted at a few pixels (a knot at 128²: 9 px by up to 0.43,
/// cause not found; V alike within 1.2e-4 at 2): at 2 (512², against the reference, one run)
/// the sphere's penumbra RMSE is 0.0148 against 0.0106 at ½ (0.0148 without corners), the
/// torus' 0.0081 against 0.0075, `default`'s 0.0630 against 0.0621, the knot's better (0.0786
/// against 0.0810 at ½, as without corners), and the polygonal casters' the same.
pub const CORNER_REACH: f32 = 2.0;

/// The sharpest turn a [`ShadowCorner`] may have, as the cosine between its edges' normals:
/// 127°. Sharper, a spike keeps the smoothies' own V.
pub const SHARPEST_TURN: f32 = -0.6;

/// How much farther along its edges than its lines' angle needs ([`ShadowCorner::piece`]) a
/// corner's pieces reach: a quad's width, which the need is measured in, changes along it.
pub const PIECE_MARGIN: f32 = 1.25;

impl ShadowCorner {
    /// How far along each of its edges, in widths t·k of the edge's quads, the pieces of those
    /// quads carry the corner ([`corner_cuts`]). A fragment of a quad lies within its width w of
    /// the edge, and its footprint's radius is w at most, so where the other edge's line meets
    /// its own at an angle φ, the footprint reaches that line only within w·(1 + |cos φ|)/sin φ
    /// of the vertex: w at a right angle, 2w at [`SHARPEST_TURN`]; [`PIECE_MARGIN`] times that.
    /// A shallower turn needs longer pieces, and is cut as the sharpest is, where its lines part
    /// less and the corner moves V less, as the plateau's sheets are (`Sheet::near_corner`).
    /// 2.5 widths for every turn, the sharpest's, drew up to twice the corner fragments a right
    /// angle needs: the smoothie pass, interleaved runs of 30 frames (512², lavapipe), on
    /// contact 4.89–4.98 → 4.38–4.54 ms, overlap 3.32–3.69 → 2.95–2.99, two_boxes 2.78–3.08 →
    /// 2.44–2.63, plate 0.97–1.00 → 0.92–0.93, default alike; V within 4e-4 on the suite.
    pub fn piece(&self) -> f32 {
        let [n1, n2] = self.normals;
        Self::need(n1.dot(n2), n1.perp_dot(n2).abs()).min(Self::longest_piece())
    }

    /// Whether `p` lies on one of its lines, as straight a [`Run`] into it would have to be.
    fn holds(&self, p: Vec2) -> bool {
        let [n1, n2] = self.normals;
        let slack = RUN_STRAY * n1.dot(n2).clamp(-1.0, 1.0).acos() * p.distance(self.at);
        self.normals.iter().any(|n| n.dot(p - self.at).abs() <= slack)
    }

    /// The longest [`piece`](Self::piece) of any corner: the sharpest turn's.
    pub fn longest_piece() -> f32 {
        Self::need(SHARPEST_TURN, (1.0 - SHARPEST_TURN * SHARPEST_TURN).sqrt())
    }

    /// The pieces' length where the normals' angle has cosine `cos` and sine `sin`.
    fn need(cos: f32, sin: f32) -> f32 {
        PIECE_MARGIN * (1.0 + cos.abs()) / sin
    }
}

/// Which side of the hard edge the smoothies cover (the `penumbra` knob).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Penumbra {
    /// The paper's: outward only, the hard shadow all umbra (§3).
    Outer,
    /// Both sides: inner quads too, for a caster whose surfaces lie between light depths
    /// `near` and `far` (see [`depth_range`]), drawn into the buffer of `grid`.
    Centred { near: f32, far: f32, grid: CutGrid },
}

/// What the pieces of a quad cut near a corner ([`edge_quad`]) need of the smoothie buffer's
/// grid, in tangent units.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CutGrid {
    /// A texel: how far each piece reaches past its cuts.
    pub texel: f32,
    /// How far the sliver over a cut quad's base reaches from it: [`SLIVER_STEPS`] of the
    /// rasterizer's subpixel steps.
    pub sliver: f32,
}

impl CutGrid {
    /// The grid of texels `texel` wide, rasterized to `sub_pixel_bits` of subpixel precision
    /// (`VkPhysicalDeviceLimits::subPixelPrecisionBits`).
    pub fn new(texel: f32, sub_pixel_bits: u32) -> Self {
        CutGrid { texel, sliver: texel * SLIVER_STEPS / 2f32.powi(sub_pixel_bits.min(31) as i32) }
    }
}

/// The light-depth range of a box seen through `view`, conservative: what [`Penumbra::Centred`]
/// takes, from a caster's bounds (cheap on the compute path, exact enough for the acceptance
/// test, which only needs to tell this caster from another in front of or behind it).
pub fn depth_range(view: &Mat4, bounds: &Aabb) -> (f32, f32) {
    let b = bounds.transformed(view);
    (b.min.z, b.max.z)
}

/// The smoothie size t, in tangent units of the light view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SmoothieSize {
    /// t = `scale` · R / b for a vertex at light depth b, R the light's radius: the angular
    /// radius of the light seen from the blocker. With the remap α' = α / (1 − b/r) the alpha
    /// then reaches 1 at (R/b)(1 − b/r) from the silhouette, the true outer half-penumbra of a
    /// straight edge on a receiver at depth r (similar triangles). `behind`: how far the light
    /// lies behind the view's origin, which the frustum fit moves closer for a far light
    /// (depths there are offset by it, their differences are not; the angular radius is R over
    /// the distance from the light itself).
    Physical { light_radius: f32, scale: f32, behind: f32 },
    /// The paper's user parameter: one t for every smoothie.
    Fixed(f32),
}

impl SmoothieSize {
    /// How far beyond its outline any smoothie of a caster reaches whose outline lies within
    /// `window` (tangent units) and whose nearest depth is `near`: t there (the largest), cut
    /// as [`smoothies`] cuts it, for the receivers behind all it could cover.
    pub fn largest_reach(self, near: f32, window: [f32; 4], receivers: ReceiverBound) -> f32 {
        let t = self.at(near);
        let [x0, y0, x1, y1] = window;
        let covered = [
            Vec2::new(x0 - t, y0 - t),
            Vec2::new(x1 + t, y0 - t),
            Vec2::new(x1 + t, y1 + t),
            Vec2::new(x0 - t, y1 + t),
        ];
        t * reach(near, receivers.far_over(covered))
    }

    fn at(self, depth: f32) -> f32 {
        match self {
            SmoothieSize::Physical { light_radius, scale, behind } => scale * light_radius / (depth + behind),
            SmoothieSize::Fixed(t) => t,
        }
    }
}

/// Smoothie edges and corners, as triangle lists.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SmoothieGeometry {
    pub edges: Vec<SmoothieVertex>,
    pub corners: Vec<SmoothieVertex>,
    /// The edges' inner quads ([`Penumbra::Centred`]).
    pub inner: Vec<SmoothieVertex>,
    /// The inner quads of partial silhouettes below the silhouette ([`partial_smoothies`]),
    /// drawn last, blended by max.
    pub partial_inner: Vec<SmoothieVertex>,
}

impl SmoothieGeometry {
    pub fn extend(&mut self, other: &SmoothieGeometry) {
        self.edges.extend_from_slice(&other.edges);
        self.corners.extend_from_slice(&other.corners);
        self.inner.extend_from_slice(&other.inner);
        self.partial_inner.extend_from_slice(&other.partial_inner);
    }

    pub fn is_empty(&self) -> bool {
        self.vertices().next().is_none()
    }

    /// The same smoothies in the centred smoothie buffer's channel for caster number `number`,
    /// its parity: two casters' penumbrae multiply where they cross instead of the darker
    /// winning, unless their numbers have the same parity (`glsl/smoothie/centred.frag`).
    pub fn in_channel(mut self, number: u32) -> Self {
        let c = (number % 2) as f32;
        let all = self.edges.iter_mut().chain(&mut self.corners).chain(&mut self.inner);
        for v in all.chain(&mut self.partial_inner) {
            v.channel = c;
        }
        self
    }

    /// The box of every vertex in the light view's tangent plane, [min x, min y, max x, max y]:
    /// the smoothies and the silhouette they start from; none without a vertex.
    pub fn window(&self) -> Option<[f32; 4]> {
        let mut vertices = self.vertices().map(|v| [v.x, v.y]).peekable();
        vertices.peek()?;
        Some(vertices.fold([f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY], |w, [x, y]| {
            [w[0].min(x), w[1].min(y), w[2].max(x), w[3].max(y)]
        }))
    }

    /// Every vertex: the outer smoothies', then the inner quads', the partial silhouettes' last.
    pub fn vertices(&self) -> impl Iterator<Item = &SmoothieVertex> {
        self.edges.iter().chain(&self.corners).chain(&self.inner).chain(&self.partial_inner)
    }

    /// Every triangle in the smoothie pass's drawing order, and how many vertices each of its
    /// draws takes: the outer smoothies away from the hard shadow's corners, those near one
    /// ([`SmoothieVertex::turn`]), those near a chamfered one ([`SmoothieVertex::chamfer`]),
    /// then the inner quads alike, then the partial silhouettes' inner quads. Each kind is drawn
    /// apart, with its own arithmetic, which llvmpipe would run on every fragment of a draw that
    /// held any.
    pub fn drawn(&self) -> (Vec<SmoothieVertex>, [u32; 7]) {
        let kind = |v: &SmoothieVertex| match (v.turn != 0.0, v.chamfer != [0.0; 3]) {
            (false, _) => 0,
            (true, false) => 1,
            (true, true) => 2,
        };
        let mut out = Vec::with_capacity(self.vertices().count());
        let mut counts = [0; 7];
        let outer = self.edges.chunks(3).chain(self.corners.chunks(3));
        for (part, triangles) in [outer.collect::<Vec<_>>(), self.inner.chunks(3).collect()].iter().enumerate() {
            for (k, count) in counts[3 * part..3 * part + 3].iter_mut().enumerate() {
                let before = out.len();
                out.extend(triangles.iter().filter(|t| kind(&t[0]) == k).flat_map(|t| t.iter()));
                *count = (out.len() - before) as u32;
            }
        }
        out.extend_from_slice(&self.partial_inner);
        counts[6] = self.partial_inner.len() as u32;
        (out, counts)
    }
}

/// The part of a smoothie at depth b that can matter: with the farthest receiver at `far`,
/// α' = α / (1 − b/r) is already 1 for every receiver once α ≥ 1 − b/far, so the smoothie is cut
/// there (its alpha unchanged). A far light then gets thin smoothies, not huge ones.
fn reach(b: f32, far: f32) -> f32 {
    (1.0 - b / far).clamp(0.0, 1.0)
}

/// What bounds the depth of the receivers behind a smoothie, for its [`reach`]: the farthest
/// receiver in view, and the ground plane where every receiver lies on the light's side of it
/// (then none lies beyond the plane along any ray). Under a caster near the ground the plane is
/// much nearer than the farthest receiver: a plate at 1/8 of the light's height has
/// 1 − b/r = 1/8 there, and its smoothies, cut at the plane, are an eighth as wide. The cut is
/// exact for the outer halves, whose buffer alpha takes r no deeper than the plane
/// (`glsl/smoothie/centred.glsl`): every fragment cut away was discarded there.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReceiverBound {
    pub far: f32,
    /// The plane's inverse light depth along the view's ray (x/z, y/z, 1): 1/r = g · (x, y, 1)
    /// where the ray meets it, at most 0 where it does not.
    pub ground: Option<Vec3>,
}

impl ReceiverBound {
    /// Receivers anywhere up to `far`.
    pub fn up_to(far: f32) -> Self {
        ReceiverBound { far, ground: None }
    }

    /// The farthest a receiver can lie behind any point of the convex hull of `region`
    /// (tangent points): the inverse depth of a plane is affine in them, least at a corner.
    fn far_over(&self, region: impl IntoIterator<Item = Vec2>) -> f32 {
        let Some(g) = self.ground else { return self.far };
        let nearest = region.into_iter().map(|p| g.dot(p.extend(1.0))).fold(f32::INFINITY, f32::min);
        // A thousandth deeper, as the fit's far: rounding must not cut a receiver's smoothie.
        if nearest > 0.0 { self.far.min(1.001 / nearest) } else { self.far }
    }
}

fn vertex(p: Vec2, b: f32, shape: Vec2) -> SmoothieVertex {
    SmoothieVertex {
        x: p.x,
        y: p.y,
        b,
        sx: shape.x,
        sy: shape.y,
        fx: 0.0,
        fy: 0.0,
        nx: 0.0,
        ny: 0.0,
        near: 0.0,
        far: 0.0,
        w: 1.0,
        channel: 0.0,
        cx: 0.0,
        cy: 0.0,
        normals: [0.0; 4],
        turn: 0.0,
        along: 0.0,
        keep: KEEP_ALL,
        chamfer: [0.0; 3],
    }
}

/// An edge quad's vertex: `vertex` weighted by its smoothie size `t` (see [`SmoothieVertex::w`]).
fn weighted(v: SmoothieVertex, t: f32) -> SmoothieVertex {
    // A zero size draws nothing; its weight must still be finite.
    SmoothieVertex { w: if t > 0.0 && t.is_finite() { 1.0 / t } else { 1.0 }, ..v }
}

/// An inner-quad vertex at `p` belonging to the edge's point `foot`.
fn inner_vertex(p: Vec2, b: f32, alpha: f32, (foot, normal): (Vec2, Vec2), (near, far): (f32, f32)) -> SmoothieVertex {
    SmoothieVertex { fx: foot.x, fy: foot.y, nx: normal.x, ny: normal.y, near, far, ..vertex(p, b, Vec2::X * alpha) }
}

fn quad(out: &mut Vec<SmoothieVertex>, v: [SmoothieVertex; 4]) {
    out.extend([v[0], v[1], v[2], v[0], v[2], v[3]]);
}

/// The silhouette edges of a caster placed by `model`, its `planes` built from its positions,
/// relative to the light at `light` (world; boundary edges of open meshes count as
/// silhouettes), each with the third vertex of its light-facing triangle.
pub fn silhouette(caster: &Caster<'_>, planes: &FacePlanes, model: &Mat4, light: Vec3) -> Vec<([u32; 2], u32)> {
    penumbra_edges(caster, &planes.light_facing(model, light), EdgeSource::Silhouettes)
}

/// The silhouette `edges` (from [`silhouette`]) merged into chains that stray at most
/// `tolerance` (tangent units of `view`) from them, in position and in smoothie reach t · k
/// ([`chains::merge`]): on a fine mesh, whose projected outline zigzags by less than a texel,
/// far fewer edges and corners for the same smoothies (issue 18); [`merged_smoothies`] draws
/// them.
pub fn merged_silhouette(
    view: &Mat4,
    caster: &Caster<'_>,
    edges: &[PenumbraEdge],
    (size, receivers): (SmoothieSize, ReceiverBound),
    tolerance: f32,
) -> Vec<MergedEdge> {
    let at = |i: u32| view.transform_point3(caster.positions[i as usize]);
    let project = |i: u32| {
        let p = at(i);
        (p.z > MIN_DEPTH).then(|| Vec2::new(p.x, p.y) / p.z)
    };
    let width = |i: u32| {
        let far = project(i).map_or(receivers.far, |p| receivers.far_over([p]));
        let z = at(i).z;
        size.at(z) * reach(z, far)
    };
    chains::merge(edges, project, width, tolerance)
}

/// One end of a projected silhouette edge at a silhouette vertex: where the vertex lies, its
/// depth, and with the edge's direction away from the vertex and outward normal, when the edge
/// has them (not edge-on).
struct End {
    vertex: u32,
    p: Vec2,
    z: f32,
    side: Option<(Vec2, Vec2)>,
    /// 2 × the edge's number, + 1 at its second end.
    id: usize,
    /// The projected edge's length.
    length: f32,
}

/// The smoothies of a caster's `edges` (from [`silhouette`]) seen through `view` (the caster's
/// positions → light view, +z away from the light), for receivers no farther than `far`. Each
/// silhouette vertex gets one corner; with [`Penumbra::Centred`] each edge an inner quad too.
pub fn smoothies(
    view: &Mat4,
    caster: &Caster<'_>,
    edges: &[PenumbraEdge],
    size: (SmoothieSize, ReceiverBound),
    penumbra: Penumbra,
) -> SmoothieGeometry {
    merged_smoothies(view, caster, &edges.iter().copied().map(MergedEdge::single).collect::<Vec<_>>(), size, penumbra)
}

/// [`smoothies`] of merged edges ([`merged_silhouette`]): each quad starts as far beyond its
/// edge as the original strays the other way (outer quads `inside` of it, inner quads
/// `outside`), so it covers the original's penumbra from where it began, alpha 0 there; the
/// alpha then errs light outside and dark inside by at most the merge tolerance over t.
pub fn merged_smoothies(
    view: &Mat4,
    caster: &Caster<'_>,
    edges: &[MergedEdge],
    (size, receivers): (SmoothieSize, ReceiverBound),
    penumbra: Penumbra,
) -> SmoothieGeometry {
    let project = |i: u32| {
        let p = view.transform_point3(caster.positions[i as usize]);
        (p.z > MIN_DEPTH).then(|| (Vec2::new(p.x, p.y) / p.z, p.z))
    };
    // Each edge's projected ends, and where it is not edge-on its outward normal: away from
    // the light-facing triangle, across the edge.
    let projected: Vec<Option<Projected>> = edges
        .iter()
        .map(|&MergedEdge { edge: ([a, b], inner), .. }| {
            let (a, b) = (project(a)?, project(b)?);
            let along = (b.0 - a.0).try_normalize();
            let normal = along
                .zip(project(inner))
                .map(|(along, (pi, _))| if along.perp().dot(pi - a.0) > 0.0 { -along.perp() } else { along.perp() });
            Some(([a, b], normal))
        })
        .collect();
    let mut ends = Vec::with_capacity(2 * edges.len());
    for (i, (e, p)) in edges.iter().zip(&projected).enumerate() {
        let Some(([(pa, za), (pb, zb)], normal)) = *p else { continue };
        let side = |d: f32| (pb - pa).try_normalize().zip(normal).map(|(along, normal)| (along * d, normal));
        let length = (pb - pa).length();
        let [a, b] = e.edge.0;
        ends.push(End { vertex: a, p: pa, z: za, side: side(1.0), id: 2 * i, length });
        ends.push(End { vertex: b, p: pb, z: zb, side: side(-1.0), id: 2 * i + 1, length });
    }
    ends.sort_unstable_by_key(|e| e.vertex);
    let outline = Outline::new(&ends, 2 * edges.len());
    let own: Vec<Option<ShadowCorner>> =
        outline.groups.iter().map(|group| shadow_corner(group, &outline, (size, receivers), penumbra)).collect();
    let mut out = SmoothieGeometry::default();
    let mut corner_of = vec![None; 2 * edges.len()];
    for (g, group) in outline.groups.iter().enumerate() {
        let shadow = own[g].or_else(|| corner_near(group, &outline, &own, (size, receivers)));
        group.iter().for_each(|e| corner_of[e.id] = shadow);
        corner(&mut out, group, (size, receivers), penumbra, shadow);
    }
    for (i, (&MergedEdge { inside, outside, .. }, p)) in edges.iter().zip(&projected).enumerate() {
        let Some(([(pa, za), (pb, zb)], Some(normal))) = *p else { continue };
        let corners = [corner_of[2 * i], corner_of[2 * i + 1]];
        // Per end: its point, depth and size; the rim lies t · k out, alpha k there, k the
        // reach over the whole quad's receivers (both ends', so the cut is linear in b).
        let ends = [(pa, za), (pb, zb)].map(|(p, z)| (p, z, size.at(z)));
        let far_over = |offset: f32, side: Vec2| {
            receivers.far_over(ends.iter().flat_map(|&(p, _, t)| [p + side * offset, p + side * (offset + t)]))
        };
        let far = far_over(-inside, normal);
        let [a, b] = ends.map(|(p, z, t)| {
            let (p, k) = (p - normal * inside, reach(z, far));
            [vertex(p, z, Vec2::ZERO), vertex(p + normal * t * k, z, Vec2::X * k)].map(|v| weighted(v, t))
        });
        let outer = [a[0], b[0], b[1], a[1]];
        let Penumbra::Centred { near, far: deepest, grid } = penumbra else {
            quad(&mut out.edges, outer);
            continue;
        };
        let range = (near, deepest);
        let far = far_over(-outside, -normal);
        let [a, b] = ends.map(|(p, z, t)| {
            let (p, k) = (p + normal * outside, reach(z, far));
            let foot = (p, normal);
            [inner_vertex(p, z, 0.0, foot, range), inner_vertex(p - normal * t * k, z, k, foot, range)]
                .map(|v| weighted(v, t))
        });
        let inner = [a[0], b[0], b[1], a[1]];
        let cuts = corner_cuts(&[outer, inner], corners);
        edge_quad(&mut out.edges, outer, (corners, cuts), grid);
        edge_quad(&mut out.inner, inner, (corners, cuts), grid);
    }
    out
}

/// Where an edge's quads (its outer and inner, each its base from end a to end b, then its rim
/// back) are cut for the [`ShadowCorner`]s at its ends: the fractions of the edge from each end
/// within [`ShadowCorner::piece`] widths of the wider quad, meeting in the middle where they would
/// overlap. Both quads are cut alike: cut apart, their pieces met the hard edge at different
/// points, and the T-junctions there cracked (a lit speckle on two_boxes' hard edge, V 0.82
/// for 0.52).
fn corner_cuts(quads: &[[SmoothieVertex; 4]], corners: [Option<ShadowCorner>; 2]) -> [f32; 2] {
    let point = |v: SmoothieVertex| Vec2::new(v.x, v.y);
    let length = point(quads[0][0]).distance(point(quads[0][1]));
    // The widest rim at end a (base 0, rim 3) and at end b (base 1, rim 2).
    let width =
        |base: usize, rim: usize| quads.iter().map(|q| point(q[base]).distance(point(q[rim]))).fold(0.0, f32::max);
    // From the corner's vertex, which a turn split by a short edge puts off the edge's end.
    let reach = |c: Option<ShadowCorner>, end: usize, width: f32| {
        c.map_or(0.0, |c| (c.piece() * width + c.at.distance(point(quads[0][end]))) / length)
    };
    let [ua, ub] = [reach(corners[0], 0, width(0, 3)), reach(corners[1], 1, width(1, 2))];
    let apart = ua + ub < 1.0; // false for NaN too
    match corners {
        _ if apart => [ua, ub],
        [Some(_), Some(_)] => [0.5, 0.5],
        [Some(_), None] => [1.0, 0.0],
        _ => [0.0, 1.0],
    }
}

/// A silhouette edge in the light view's tangent plane: its ends' points and depths, and where
/// it is not edge-on its outward normal.
type Projected = ([(Vec2, f32); 2], Option<Vec2>);

/// An edge's quad `q` (its base from end a to end b, then its rim back) in pieces, cut at
/// `cuts` ([`corner_cuts`]): those within reach of a [`ShadowCorner`] at either end carry it,
/// the rest none. Each piece keeps only its own part of the edge (`keep`, [`KEEP_SLACK`] past its
/// cuts) and reaches a texel further, so that every fragment it keeps lies inside it; and a
/// sliver over the base comes with it (see below). Each interpolates as the whole quad did (see
/// [`between`]). Where the pieces reached a quarter of the quad's width past their cuts, that
/// much of the width was drawn twice at every cut, half of it discarded, with the corners'
/// arithmetic on one side: the smoothie pass took 4.60–4.69 ms against 4.10–4.28 on contact,
/// 2.14–2.22 against 2.01–2.07 on overlap (alternating runs of 20 frames, 512², lavapipe), V the
/// same. A texel is enough, where four subpixel steps were not (a texel of 512² kept by neither
/// piece, `open_mesh` with `smoothie_size=512`: V 0.25 on the hard edge for 0.5): a fragment's
/// `along` is interpolated, not snapped as its coverage is.
fn edge_quad(
    out: &mut Vec<SmoothieVertex>,
    q: [SmoothieVertex; 4],
    (corners, cuts): ([Option<ShadowCorner>; 2], [f32; 2]),
    CutGrid { texel, sliver }: CutGrid,
) {
    if corners == [None; 2] {
        return quad(out, q);
    }
    let [a0, b0, b1, a1] = q.map(|v| SmoothieVertex { along: 0.0, ..v });
    let [b0, b1] = [b0, b1].map(|v| SmoothieVertex { along: 1.0, ..v });
    let [ua, ub] = cuts;
    let point = |v: SmoothieVertex| Vec2::new(v.x, v.y);
    let margin = KEEP_SLACK + texel / point(a0).distance(point(b0));
    // With each piece, a sliver over the whole hard edge, so that what a piece keeps next to it
    // is covered from the quad's own base, as uncut: a piece's base runs to a cut's vertex,
    // which rounds off the hard edge's line, and a texel there could fall outside every piece, or
    // inside a piece where the map, which shares the line, holds the caster (lit speckles at cuts
    // on two_boxes' and overlap's hard edges, V 0.82 for 0.52). Only the rounding needs covering:
    // a quad `sliver` wide (a few subpixel steps) along the exact base. A triangle reaching an
    // eighth of the width at the edge's middle, as the sliver was, ran the pieces' arithmetic on
    // every fragment of a band along the whole edge, three times an edge: the smoothie pass took
    // 5.35–5.48 ms against 4.51–4.62 on contact, 2.83–3.06 against 2.42–2.46 on two_boxes and
    // 2.62–2.88 against 2.13–2.32 on overlap (five alternating runs of 20 frames, 512², lavapipe),
    // the suite's images the same on both silhouette paths.
    let rim = |base: SmoothieVertex, far: SmoothieVertex| {
        let reach = point(base).distance(point(far));
        between(base, far, (sliver / reach.max(1e-30)).min(SLIVER))
    };
    let over_base = [a0, b0, rim(b0, b1), rim(a0, a1)];
    for (u0, u1, corner) in [(0.0, ua, corners[0]), (ua, 1.0 - ub, None), (1.0 - ub, 1.0, corners[1])] {
        if u0 < u1 {
            // Beyond the quad's own ends, nothing to keep out; at a cut, both pieces keep a
            // sliver (KEEP_SLACK) of the other's part, as each interpolates `along` from its own
            // vertices, and rounding could have left a fragment to neither.
            let keep =
                [if u0 > 0.0 { u0 - KEEP_SLACK } else { f32::MIN }, if u1 < 1.0 { u1 + KEEP_SLACK } else { f32::MAX }];
            let (g0, g1) = ((u0 - margin).max(0.0), (u1 + margin).min(1.0));
            let piece = [between(a0, b0, g0), between(a0, b0, g1), between(a1, b1, g1), between(a1, b1, g0)];
            let kept = |v| near_corner(SmoothieVertex { keep, ..v }, corner);
            quad(out, piece.map(kept));
            quad(out, over_base.map(kept));
        }
    }
}

/// The vertex `u` of the way from `a` to `b`, two vertices of one quad's side, with what the
/// rasterizer interpolates there: position, foot and `along` linearly, depth as 1/b
/// (glsl/smoothie/smoothie.vert), the shape projectively by w = 1/t ([`SmoothieVertex::w`]), so
/// a piece of a quad interpolates as the whole did.
fn between(a: SmoothieVertex, b: SmoothieVertex, u: f32) -> SmoothieVertex {
    let lerp = |x: f32, y: f32| x + (y - x) * u;
    let (ta, tb) = (1.0 / a.w, 1.0 / b.w);
    let t = lerp(ta, tb);
    let shape = |x: f32, y: f32| lerp(x * ta, y * tb) / t;
    SmoothieVertex {
        x: lerp(a.x, b.x),
        y: lerp(a.y, b.y),
        // 1/b linear, in one division as silhouettes.comp's.
        b: a.b * b.b / lerp(b.b, a.b),
        sx: shape(a.sx, b.sx),
        sy: shape(a.sy, b.sy),
        fx: lerp(a.fx, b.fx),
        fy: lerp(a.fy, b.fy),
        w: 1.0 / t,
        along: lerp(a.along, b.along),
        ..a
    }
}

/// `v` carrying the hard shadow's corner `c`, where there is one.
fn near_corner(v: SmoothieVertex, c: Option<ShadowCorner>) -> SmoothieVertex {
    let Some(ShadowCorner { at, normals: [n1, n2], convex, chamfer }) = c else { return v };
    let (m, cut) = chamfer.unwrap_or((Vec2::ZERO, 0.0));
    SmoothieVertex {
        cx: at.x,
        cy: at.y,
        normals: [n1.x, n1.y, n2.x, n2.y],
        turn: if convex { 1.0 } else { -1.0 },
        chamfer: [m.x, m.y, cut],
        ..v
    }
}

/// Centred, the smoothie edges of a caster's partial silhouettes (`edges`, from
/// [`partial_silhouettes`](super::silhouette::partial_silhouettes)) seen through `view`, as
/// [`smoothies`] makes a silhouette's. Such an edge lies over its caster's own outline in the
/// map, where a face seen nearly edge-on from the light's centre is a sliver beside the
/// silhouette, and for the part of the light on the far side of that face (the turned face) it
/// is the silhouette. Each is drawn only where it gains [`PARTIAL_GAIN`] of its reach on the
/// silhouette, about the turned face's far vertex (reaches compared on the farthest receiver,
/// t·k: [`reach`]; on any receiver at depth r two smoothies' reaches differ by their t, R/b −
/// R/r taken from both). No corners: the silhouette's cover the outline's turns. Outer only,
/// nothing: the paper's penumbra spans the whole width outward, its umbra the whole hard shadow.
///
/// - An edge whose faces the centre sees lit lies above the silhouette, nearer the light, and
///   its smoothie reaches further out. Its outer smoothie goes to `edges`, marked (near, far) =
///   (b, −1): the smoothie pass keeps them only where the map's surface lies behind b (by 2 % or
///   two map texels, whichever is more: glsl/smoothie/centred.glsl), so they only darken the
///   outer half, and only receivers behind b, the deepest of the edge's and the turned vertex's
///   depths: the turned face's own surface, which its soft terminator already shades (the
///   resolve), lies in front (low_light's front face: 759 px too dark by over 0.1 without it).
/// - An edge whose faces the centre sees unlit lies below it, nearer the receiver, and for the
///   part of the light in front of its turned face, which a receiver inside the hard shadow
///   still sees, it is the silhouette, with the narrower penumbra (a thick slab: the truth's
///   umbra begins where its bottom rim's does, not its top rim's). Its inner quad goes to
///   `partial_inner`, with the caster's depth range as an inner quad's, its inward normal and
///   the turned vertex's depth, the silhouette's there (see [`SmoothieVertex::cx`]). The
///   smoothie pass draws them last and blends their alphas by max, converted to the
///   silhouette's depth, so they only darken. From such a receiver the silhouette's half plane
///   lets through more than the caster does (the caster reaches past it, to the lower edge),
///   and the lower edge is the caster's outline, exact where it runs straight across the light's
///   footprint: hence the darker of the two, and only edges that span the footprint.
pub fn partial_smoothies(
    view: &Mat4,
    caster: &Caster<'_>,
    edges: &[PartialEdge],
    (size, receivers): (SmoothieSize, ReceiverBound),
    penumbra: Penumbra,
) -> SmoothieGeometry {
    let mut out = SmoothieGeometry::default();
    let Penumbra::Centred { near, far: deepest, .. } = penumbra else { return out };
    let project = |i: u32| {
        let p = view.transform_point3(caster.positions[i as usize]);
        (p.z > MIN_DEPTH).then(|| (Vec2::new(p.x, p.y) / p.z, p.z))
    };
    for edge in edges {
        let [a, b] = edge.vertices;
        let (Some((pa, za)), Some((pb, zb))) = (project(a), project(b)) else { continue };
        let (Some((inside, _)), Some((pc, zc)), Some(along)) =
            (project(edge.inner), project(edge.turned), (pb - pa).try_normalize())
        else {
            continue;
        };
        // Away from the face that faces the light's part they bound: outward from an edge above
        // the silhouette, inward from one below it.
        let normal = if along.perp().dot(inside - pa) > 0.0 { -along.perp() } else { along.perp() };
        let far = receivers.far_over([(pa, za), (pb, zb)].into_iter().flat_map(|(p, z)| [p, p + normal * size.at(z)]));
        let ends = [(pa, za), (pb, zb)].map(|(p, z)| (p, z, reach(z, far), size.at(z)));
        let half = ends.iter().map(|(_, _, k, t)| t * k).fold(0.0, f32::max);
        if edge.lit {
            // How far out its smoothie reaches, against the turned vertex's.
            let extent = |p: Vec2, z: f32| normal.dot(p) + size.at(z);
            if extent(pa, za).max(extent(pb, zb)) - extent(pc, zc) <= PARTIAL_GAIN * half {
                continue;
            }
            let behind = za.max(zb).max(zc);
            let [a, b] = ends.map(|(p, z, k, t)| {
                [vertex(p, z, Vec2::ZERO), vertex(p + normal * t * k, z, Vec2::X * k)]
                    .map(|v| weighted(SmoothieVertex { near: behind, far: -1.0, ..v }, t))
            });
            quad(&mut out.edges, [a[0], b[0], b[1], a[1]]);
            continue;
        }
        // Where the umbra begins along the inward normal, on the farthest receiver, against the
        // turned vertex's. Its straight half plane is what a receiver sees only where the edge
        // spans the light's footprint there (2·t·k across): past the ends of a shorter one, as
        // a round caster's rings are, the outline turns away and lets more light by (without
        // this, the sphere's inner half went 0.013 too dark on average where it moved: penumbra
        // RMSE 0.01500 → 0.01531).
        let umbra = |p: Vec2, z: f32| normal.dot(p) + size.at(z) * reach(z, far);
        if umbra(pc, zc) - umbra(pa, za).max(umbra(pb, zb)) <= PARTIAL_GAIN * half || pa.distance(pb) < 2.0 * half {
            continue;
        }
        // Past its own umbra's start the edge still hides the whole light, as far as the
        // silhouette's inner half reaches: the quad reaches there, its alpha past 1 (umbra).
        let hold = umbra(pc, zc);
        let normals = [normal.x, normal.y, 0.0, 0.0];
        let [a, b] = ends.map(|(p, z, k, t)| {
            let reach = (hold - normal.dot(p)).clamp(t * k, MAX_INNER_REACH * t * k);
            let alpha = if t > 0.0 { reach / t } else { 0.0 };
            [(p, 0.0), (p + normal * reach, alpha)].map(|(q, alpha)| {
                weighted(SmoothieVertex { near, far: deepest, cx: zc, normals, ..vertex(q, z, Vec2::X * alpha) }, t)
            })
        });
        quad(&mut out.partial_inner, [a[0], b[0], b[1], a[1]]);
    }
    out
}

/// The corner at one silhouette vertex, from the ends of its edges there. Where two edges
/// meet, only the gap their quads leave needs it: outside a convex turn, the sector between the
/// two outward normals (the paper's wedge, §3), radial alpha from the vertex; a concave or
/// straight turn needs none there (the two quads overlap). Centred, a concave turn leaves the
/// mirror-image gap over the blocker, between the inner quads, and gets the mirror-image wedge:
/// radial inner alpha, accepted as the inner quads are, probing along the outward bisector. A
/// wedge's area is 2·tan(θ/4)·t² for a turn of θ, so these cost the outline's total turning,
/// not its vertex count: the squares they replace (the whole square at concave turns, centred)
/// were most of the buffer's fragments on fine meshes, whose silhouettes zigzag (issue 18).
///
/// Centred, a convex turn needs nothing over the blocker, where its two inner quads overlap. It
/// used to keep the square's inner half of outer smoothie there, which darkened the tessellated
/// terminator (sphere 0.110 → 0.086) until the resolve took a caster's own surface as lit by
/// the light above its tangent plane; since then the halves only darkened it twice. Without
/// them (bench, 512², lavapipe, one run): sphere penumbra RMSE 0.0295 → 0.0156, low_light 0.0274
/// → 0.0254, no scene worse, and the smoothie pass 0.6–0.97× as long (sphere 5.2 → 2.7 ms,
/// default 7.3 → 5.4). Any other vertex (an
/// edge-on edge, normals on opposite sides, one or three or more edges) gets the full square
/// of half-size t, which covers every direction outside: the §3 special case (averaging
/// normals) is never needed, and minimum blending keeps the overlap with the edges continuous.
fn corner(
    out: &mut SmoothieGeometry,
    group: &[End],
    size: (SmoothieSize, ReceiverBound),
    penumbra: Penumbra,
    shadow: Option<ShadowCorner>,
) {
    let End { p, z, .. } = group[0];
    let (t, k) = corner_size(p, z, size);
    let at = |offset: Vec2| near_corner(weighted(vertex(p + offset * t, z, offset), t), shadow);
    if let Some(Turn { normals: [n1, n2], bisector: m, bend }) = turn(group) {
        match penumbra {
            _ if bend < 0.0 => wedge(&mut out.corners, [n1, n2], m, k, at),
            Penumbra::Centred { near, far: deepest, .. } if bend > 0.0 => {
                let inner =
                    |offset| SmoothieVertex { fx: p.x, fy: p.y, nx: m.x, ny: m.y, near, far: deepest, ..at(offset) };
                wedge(&mut out.inner, [-n1, -n2], -m, k, inner);
            }
            _ => {}
        }
        return;
    }
    let c = |sx: f32, sy: f32| at(Vec2::new(sx, sy) * k);
    quad(&mut out.corners, [c(-1.0, -1.0), c(1.0, -1.0), c(1.0, 1.0), c(-1.0, 1.0)]);
}

/// A corner's smoothie size t at its vertex `p` (depth `z`) and its reach k ([`reach`]) over
/// the square of half-size t about it, which holds every kind of corner: t·k is the largest
/// radius of the light's footprint on its receivers.
fn corner_size(p: Vec2, z: f32, (size, receivers): (SmoothieSize, ReceiverBound)) -> (f32, f32) {
    let t = size.at(z);
    let square = [Vec2::ONE, Vec2::new(1.0, -1.0), Vec2::NEG_ONE, Vec2::new(-1.0, 1.0)];
    (t, reach(z, receivers.far_over(square.map(|c| p + c * t))))
}

/// How the outline turns at a vertex where exactly two edge ends meet: their outward normals
/// (in `group`'s order), the bisector, and the bend n1·d2 (d2 the second edge's direction away
/// from the vertex), below 0 at a convex turn, which leaves a gap outside, above 0 at a concave
/// one, which leaves it inside.
struct Turn {
    normals: [Vec2; 2],
    bisector: Vec2,
    bend: f32,
}

/// The [`Turn`] at a vertex, where both ends have sides and their normals lie on the same side
/// of the path through it (in along −d1, out along d2); else one was found from an edge-on
/// triangle, whose third vertex can project to either side.
fn turn(group: &[End]) -> Option<Turn> {
    let [End { side: Some((d1, n1)), .. }, End { side: Some((d2, n2)), .. }] = group else { return None };
    let consistent = (-*d1).perp().dot(*n1) * d2.perp().dot(*n2) > 0.0;
    let bisector = (*n1 + *n2).try_normalize().filter(|_| consistent)?;
    Some(Turn { normals: [*n1, *n2], bisector, bend: n1.dot(*d2) })
}

/// The silhouette's outline as the hard shadow's corners walk it: its edge ends grouped by
/// vertex, and each end's group.
struct Outline<'a> {
    groups: Vec<&'a [End]>,
    group_of: Vec<usize>,
}

/// The outline from a vertex to the first vertex it passes [`CORNER_REACH`] footprint radii
/// away or more ([`Outline::run`]): its chord's direction, and how far its edges turn from it
/// (the largest sine; 1 where one runs back).
struct Run {
    chord: Vec2,
    stray: f32,
}

impl Run {
    /// The run's outward normal: its chord's, on the side of its first edge's `normal`.
    fn normal(&self, normal: Vec2) -> Vec2 {
        let n = self.chord.perp();
        if n.dot(normal) < 0.0 { -n } else { n }
    }

    /// Whether it is straight enough to stand for a corner's line that turns by `angle`.
    fn straight(&self, angle: f32) -> bool {
        self.stray <= RUN_STRAY * angle
    }
}

impl<'a> Outline<'a> {
    /// From `ends` sorted by vertex, of `count` ends in all.
    fn new(ends: &'a [End], count: usize) -> Self {
        let groups: Vec<&[End]> = ends.chunk_by(|x, y| x.vertex == y.vertex).collect();
        let mut group_of = vec![usize::MAX; count];
        for (g, group) in groups.iter().enumerate() {
            group.iter().for_each(|e| group_of[e.id] = g);
        }
        Outline { groups, group_of }
    }

    /// The ends at the far vertex of `end`'s edge.
    fn far(&self, end: &End) -> Option<&'a [End]> {
        self.groups.get(self.group_of[end.id ^ 1]).copied()
    }

    /// The outline from `start`'s vertex along its edge: the end at which it arrives at each
    /// vertex it passes, on through vertices where exactly two edges meet, [`MAX_WALK`] at most.
    fn walk(&self, start: &'a End) -> impl Iterator<Item = &'a End> + '_ {
        let mut leaving = Some(start);
        std::iter::from_fn(move || {
            let end = leaving.take()?;
            let ends = self.far(end)?;
            let arriving = ends.iter().find(|e| e.id == end.id ^ 1)?;
            leaving = match ends {
                [a, b] => Some(if a.id == arriving.id { b } else { a }),
                _ => None,
            };
            Some(arriving)
        })
        .take(MAX_WALK)
    }

    /// The outline from `start`'s vertex along its edge to the first vertex at least `length`
    /// away ([`Run`]); none where the walk ends first.
    fn run(&self, start: &'a End, length: f32) -> Option<Run> {
        // The vertices passed, whose edges' turns are measured once the chord is known.
        let mut passed = [start.p; MAX_WALK + 1];
        let mut count = 1;
        let end = self.walk(start).find(|e| {
            passed[count] = e.p;
            count += 1;
            e.p.distance(start.p) >= length
        })?;
        let chord = (end.p - start.p) / end.p.distance(start.p);
        let turn = |w: &[Vec2]| {
            let d = (w[1] - w[0]) / w[1].distance(w[0]);
            // An edge that runs back along the chord turns from it the most.
            if chord.dot(d) > 0.0 { chord.perp_dot(d).abs() } else { 1.0 }
        };
        Some(Run { chord, stray: passed[..count].windows(2).map(turn).fold(0.0, f32::max) })
    }
}

/// Centred, the hard shadow's corner at a vertex, where its two edges turn by [`MIN_TURN`] to
/// [`SHARPEST_TURN`] and the outline runs straight ([`Run`]) [`CORNER_REACH`] footprint radii (t·k,
/// [`corner_size`]) or more from it along each, the corner's lines those runs'. Where one of its
/// edges is shorter than a footprint radius and the outline turns on the same way at its far end
/// into another straight run, the turn is one corner split in two, where the runs' lines meet
/// (within a footprint radius of both vertices): a plate 5 cm thick, lit past its side, turns at
/// the top and at the foot of that side's short edge, and its corners there kept ½ where the truth
/// is near ¾ (0.22 too dark; `tests/smoothie_centred.rs`).
fn shadow_corner(
    group: &[End],
    outline: &Outline<'_>,
    size: (SmoothieSize, ReceiverBound),
    penumbra: Penumbra,
) -> Option<ShadowCorner> {
    if penumbra == Penumbra::Outer {
        return None;
    }
    let Turn { normals: [n1, n2], bend, .. } = turn(group)?;
    let (t, k) = corner_size(group[0].p, group[0].z, size);
    let run = |e: &End| outline.run(e, CORNER_REACH * t * k);
    let corner = |[(n1, r1), (n2, r2)]: [(Vec2, &Run); 2], at: Vec2| {
        let [n1, n2] = [r1.normal(n1), r2.normal(n2)];
        let angle = n1.dot(n2).clamp(-1.0, 1.0).acos();
        let turns = n1.perp_dot(n2).abs() > MIN_TURN && n1.dot(n2) >= SHARPEST_TURN && bend != 0.0;
        let straight = r1.straight(angle) && r2.straight(angle);
        (turns && straight).then_some(ShadowCorner { at, normals: [n1, n2], convex: bend < 0.0, chamfer: None })
    };
    let [r1, r2] = [&group[0], &group[1]].map(run);
    if let (Some(r1), Some(r2)) = (&r1, &r2) {
        let at_vertex = corner([(n1, r1), (n2, r2)], group[0].p);
        if at_vertex.is_some() {
            return at_vertex;
        }
    }
    // Else one edge short, the other's run straight: a turn split in two?
    let (short, long) = match (group[0].length < t * k, group[1].length < t * k) {
        (true, false) => (&group[0], (n2, r2?)),
        (false, true) => (&group[1], (n1, r1?)),
        _ => return None,
    };
    let ends = outline.far(short)?;
    let Turn { normals: [f1, f2], bend: far_bend, .. } = turn(ends)?;
    let (next, next_normal) = if ends[0].id == short.id ^ 1 { (&ends[1], f2) } else { (&ends[0], f1) };
    let next_run = run(next).filter(|_| far_bend * bend > 0.0)?;
    // Where the two runs' lines meet (n·x = n·p for each), within a footprint radius of both
    // vertices.
    let normal = long.1.normal(long.0);
    let outward = next_run.normal(next_normal);
    let lines = Mat2::from_cols(normal, outward).transpose();
    let at = lines.inverse() * Vec2::new(normal.dot(group[0].p), outward.dot(next.p));
    let near = |p: Vec2| at.distance(p) <= t * k;
    if !(near(group[0].p) && near(next.p)) {
        return None;
    }
    // The short edge's line, through both vertices: its outward normal.
    let chamfer = short.side.map(|(_, m)| (m, m.dot(at - group[0].p)));
    corner([(long.0, &long.1), (next_normal, &next_run)], at).map(|c| ShadowCorner { chamfer, ..c })
}

/// The corner a vertex without its own ([`shadow_corner`]) carries: the nearest the outline
/// passes on either side (`own`, each group's) whose pieces reach the vertex, with a footprint
/// radius to spare, and on whose lines it lies. Where the runs into a corner are cut into many
/// short edges, each edge's quads and each vertex's wedge near it would else keep their own V,
/// which minimum blending takes over the corner's (lighter outside a convex corner, darker
/// inside a reflex one). Past a run the outline may turn away, and a vertex there that took
/// the corner's lines for its own lit a notch in the cow's shadow on `default` (V 1 for 0,
/// penumbra RMSE 0.0868 against 0.0626). Ties go to the lower vertex, as the compute path's do.
fn corner_near(
    group: &[End],
    outline: &Outline<'_>,
    own: &[Option<ShadowCorner>],
    size: (SmoothieSize, ReceiverBound),
) -> Option<ShadowCorner> {
    let [_, _] = group else { return None };
    let End { p, z, .. } = group[0];
    let (t, k) = corner_size(p, z, size);
    let reach = |piece: f32| (piece + 1.0) * t * k;
    let farthest = reach(ShadowCorner::longest_piece());
    group
        .iter()
        .filter_map(|start| {
            let mut passed = outline.walk(start).take_while(|e| e.p.distance(p) <= farthest);
            let found = passed.find_map(|e| own[outline.group_of[e.id]].map(|c| (c, e.vertex)))?;
            Some(found).filter(|(c, _)| c.at.distance(p) <= reach(c.piece()) && c.holds(p))
        })
        .min_by(|(a, u), (b, v)| a.at.distance(p).total_cmp(&b.at.distance(p)).then(u.cmp(v)))
        .map(|(c, _)| c)
}

/// The sector from direction `n[0]` to `n[1]` about their bisector `m`, of radius `k` in shape
/// units (`at` makes a vertex from a shape offset): two quads, each the kite of the disk's
/// tangents at one side and at the bisector, which hold the disk's sector.
fn wedge(out: &mut Vec<SmoothieVertex>, n: [Vec2; 2], m: Vec2, k: f32, at: impl Fn(Vec2) -> SmoothieVertex) {
    for n in n {
        let tip = (n + m) / (1.0 + n.dot(m)); // where the disk's tangents at n and m meet
        quad(out, [at(Vec2::ZERO), at(n * k), at(tip * k), at(m * k)]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::EdgeAdjacency;
    use crate::geometry::silhouette::{TestMesh, partial_silhouettes};
    use proptest::prelude::*;

    /// A unit plate at `height`: positions, triangles and their adjacency.
    fn plate(height: f32) -> (Vec<Vec3>, Vec<[u32; 3]>, EdgeAdjacency) {
        let (positions, triangles) = crate::geometry::shapes::cuboid(Vec3::new(1.0, 0.0, 1.0));
        let adjacency = EdgeAdjacency::build(&triangles);
        (positions.iter().map(|p| *p + Vec3::Y * height).collect(), triangles, adjacency)
    }

    /// Looking straight down from (0, 10, 0): tangent x = world x / depth, y = world z / depth.
    fn down() -> Mat4 {
        // View (x, y, z) = world (x, z, 10 − y).
        Mat4::from_cols(glam::Vec4::X, -glam::Vec4::Z, glam::Vec4::Y, glam::Vec4::new(0.0, 0.0, 10.0, 1.0))
    }

    proptest! {
        #[test]
        fn edges_extend_outward_by_t_and_corners_are_radial(height in 0.5f32..5.0, t in 0.001f32..0.5) {
            let (positions, triangles, adjacency) = plate(height);
            let caster = Caster { positions: &positions, triangles: &triangles, adjacency: &adjacency };
            let edges = silhouette(&caster, &FacePlanes::new(&positions, &triangles), &Mat4::IDENTITY, Vec3::new(0.0, 10.0, 0.0));
            prop_assert_eq!(edges.len(), 4, "a plate under the light: its outline");
            let g = smoothies(&down(), &caster, &edges, (SmoothieSize::Fixed(t), ReceiverBound::up_to(f32::INFINITY)), Penumbra::Outer);
            prop_assert!(g.inner.is_empty(), "outer only: no inner quads");
            prop_assert_eq!(g.edges.len(), 4 * 6);
            prop_assert_eq!(g.corners.len(), 4 * 12, "a wedge of two quads at each convex vertex");
            let half = 0.5 / (10.0 - height);
            for v in &g.edges {
                let outer = v.sx == 1.0;
                // The outline sits at ±half; the outer rim t further out, never inside.
                let reach = v.x.abs().max(v.y.abs());
                let expected = if outer { half + t } else { half };
                prop_assert!((reach - expected).abs() < 1e-4 * (1.0 + expected), "{reach} vs {expected}");
                prop_assert!((v.b - (10.0 - height)).abs() < 1e-3);
            }
            let outline = |p: Vec2| Vec2::new(half.copysign(p.x), half.copysign(p.y));
            for v in &g.corners {
                let (p, shape) = (Vec2::new(v.x, v.y), Vec2::new(v.sx, v.sy));
                let c = outline(p);
                prop_assert!((p - c - shape * t).length() < 1e-5 * (1.0 + t), "radial alpha: shape = offset / t");
                prop_assert!(shape.x * c.x >= -1e-6 && shape.y * c.y >= -1e-6, "only the gap outside the turn");
            }
            // Their box: the outline grown by t, which holds the map's footprint of the plate.
            let w = g.window().expect("smoothies");
            let rim = half + t;
            let close = w.iter().zip([-rim, -rim, rim, rim]).all(|(a, b)| (a - b).abs() < 1e-4 * (1.0 + rim));
            prop_assert!(close, "{:?} against ±{}", w, rim);
            prop_assert_eq!(SmoothieGeometry::default().window(), None);
            // The gap's disk: every point within t of a corner, outside both edges' quads, is
            // covered by that corner's triangles.
            for tri in g.corners.chunks(3) {
                let c = outline(Vec2::new(tri[0].x, tri[0].y));
                for k in 0..=8 {
                    let angle = k as f32 / 8.0 * std::f32::consts::FRAC_PI_2;
                    let q = c + Vec2::new(angle.cos().copysign(c.x), angle.sin().copysign(c.y)) * t * 0.999;
                    let covered = g.corners.chunks(3).any(|u| inside(u, q));
                    prop_assert!(covered, "{q} near {c} uncovered");
                }
            }
        }
    }

    proptest! {
        /// A ground plane under the plate, level or tilted (its inverse depth along the ray
        /// (x, y, 1) is g · (x, y, 1)): every smoothie's rim lies where a receiver on it, or in
        /// front of it, already has α' = α / (1 − b/r) ≥ 1, so nothing cut away could darken one;
        /// and the rim lies well inside the cut the farthest receiver alone allows. Outer only:
        /// centred, the pieces near the plate's corners ([`edge_quad`]) are cut where the reach
        /// puts them, and their slivers' far sides are no rims; the inner quads take the same reach.
        #[test]
        fn the_ground_cuts_smoothies_where_every_receiver_behind_is_lit(
            height in 0.3f32..5.0,
            t in 0.01f32..0.2,
            tilt in -0.3f32..0.3,
        ) {
            let (positions, triangles, adjacency) = plate(height);
            let caster = Caster { positions: &positions, triangles: &triangles, adjacency: &adjacency };
            let edges = silhouette(&caster, &FacePlanes::new(&positions, &triangles), &Mat4::IDENTITY, Vec3::new(0.0, 10.0, 0.0));
            // The level ground lies at depth 10 below the light; tilted, nearer on one side.
            let ground = Vec3::new(tilt * 0.1, 0.0, 0.1);
            let far = 100.0;
            let bound = ReceiverBound { far, ground: Some(ground) };
            let g = smoothies(&down(), &caster, &edges, (SmoothieSize::Fixed(t), bound), Penumbra::Outer);
            let uncut = smoothies(&down(), &caster, &edges, (SmoothieSize::Fixed(t), ReceiverBound::up_to(far)), Penumbra::Outer);
            prop_assert_eq!(g.vertices().count(), uncut.vertices().count(), "the same smoothies, cut shorter");
            let mut widest = 0.0f32;
            for v in g.vertices().filter(|v| v.sx != 0.0 || v.sy != 0.0) {
                let alpha = Vec2::new(v.sx, v.sy).length();
                let lit_from = 1.0 - v.b * ground.dot(Vec3::new(v.x, v.y, 1.0));
                prop_assert!(alpha >= lit_from - 1e-4, "rim alpha {alpha} short of {lit_from} at ({}, {})", v.x, v.y);
                widest = widest.max(alpha);
            }
            let far_cut = 1.0 - (10.0 - height) / far;
            // The ground 10 deep, the far receiver 100: 1 − b/10 against 1 − b/100.
            prop_assert!(widest < far_cut - 0.3, "rim alpha up to {widest}, the far receiver's cut {far_cut}");
        }
    }

    #[test]
    fn without_a_ground_under_them_smoothies_reach_the_farthest_receiver() {
        let (positions, triangles, adjacency) = plate(1.0);
        let caster = Caster { positions: &positions, triangles: &triangles, adjacency: &adjacency };
        let edges =
            silhouette(&caster, &FacePlanes::new(&positions, &triangles), &Mat4::IDENTITY, Vec3::new(0.0, 10.0, 0.0));
        let size = SmoothieSize::Fixed(0.1);
        let far = ReceiverBound::up_to(20.0);
        // A plane the rays climb away from (inverse depth ≤ 0: never met) bounds nothing.
        let away = ReceiverBound { ground: Some(Vec3::new(0.0, 0.0, -0.1)), ..far };
        assert_eq!(
            smoothies(&down(), &caster, &edges, (size, away), CENTRED),
            smoothies(&down(), &caster, &edges, (size, far), CENTRED)
        );
    }

    fn inside(tri: &[SmoothieVertex], q: Vec2) -> bool {
        let [a, b, c] = [0, 1, 2].map(|i| Vec2::new(tri[i].x, tri[i].y));
        let w = [(b - a).perp_dot(q - a), (c - b).perp_dot(q - b), (a - c).perp_dot(q - c)];
        // Rounding, relative to the triangle's size: a point on the diagonal two triangles
        // share must count for one of them.
        let eps = 1e-6 * [a, b, c].map(|p| (p - q).length_squared()).iter().fold(0.0f32, |m, d| m.max(*d));
        w.iter().all(|w| *w >= -eps) || w.iter().all(|w| *w <= eps)
    }

    #[test]
    fn concave_vertices_get_no_corner_and_odd_ones_a_square() {
        // An L-shaped outline at depth 5 (tangent = world / 5), the inside point at (0.5, 0.5).
        let outline =
            [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 1.0), (1.0, 2.0), (0.0, 2.0), (0.5, 0.5), (-1.0, -1.0)];
        let positions: Vec<Vec3> = outline.iter().map(|&(x, y)| Vec3::new(x, y, 5.0)).collect();
        let adjacency = EdgeAdjacency::default();
        let caster = Caster { positions: &positions, triangles: &[], adjacency: &adjacency };
        let mut edges: Vec<([u32; 2], u32)> = (0..6).map(|i| ([i, (i + 1) % 6], 6)).collect();
        let size = (SmoothieSize::Fixed(0.05), ReceiverBound::up_to(f32::INFINITY));
        let corners = |edges: &[([u32; 2], u32)]| {
            let g = smoothies(&Mat4::IDENTITY, &caster, edges, size, Penumbra::Outer);
            let mut at: Vec<(i32, i32, usize)> = Vec::new();
            for tri in g.corners.chunks(3) {
                // The corner's vertex: any of its points less shape · t.
                let p = tri.iter().map(|v| Vec2::new(v.x, v.y) - Vec2::new(v.sx, v.sy) * 0.05).next().unwrap() * 5.0;
                let key = (p.x.round() as i32, p.y.round() as i32);
                match at.iter_mut().find(|(x, y, _)| (*x, *y) == key) {
                    Some(entry) => entry.2 += 3,
                    None => at.push((key.0, key.1, 3)),
                }
            }
            at.sort_unstable();
            at
        };
        // Five convex turns, a wedge of 12 vertices each; none at the reflex vertex (1, 1).
        assert_eq!(corners(&edges), [(0, 0, 12), (0, 2, 12), (1, 2, 12), (2, 0, 12), (2, 1, 12)]);
        // A third edge at (0, 0) and a loose end: full squares there.
        edges.push(([0, 7], 6));
        assert_eq!(corners(&edges), [(-1, -1, 6), (0, 0, 6), (0, 2, 12), (1, 2, 12), (2, 0, 12), (2, 1, 12)]);
    }

    #[test]
    fn a_corner_costs_its_turn_not_a_square_at_concave_and_outer_turns() {
        // Two edges meeting at the origin, turning left by θ, the light-facing side on the left
        // (a convex turn) or the right (concave), at depth 5; their far ends lie 1 away, beyond
        // the squares there. The triangles within 2t of the origin are the corner's, but for
        // the pieces of the edges' quads that carry it (centred), which keep a part of their
        // edge.
        let t = 0.01;
        for i in 1..32 {
            let turn = i as f32 / 32.0 * std::f32::consts::PI;
            let (into, out) = (Vec2::X, Vec2::from_angle(turn));
            for (side, convex) in [(1.0, true), (-1.0, false)] {
                let inside = (out - into) * 0.5 * side;
                let points = [-into, Vec2::ZERO, out, inside];
                let positions: Vec<Vec3> = points.iter().map(|p| p.extend(1.0) * 5.0).collect();
                let adjacency = EdgeAdjacency::default();
                let caster = Caster { positions: &positions, triangles: &[], adjacency: &adjacency };
                let edges = [([0, 1], 3), ([1, 2], 3)];
                for penumbra in [Penumbra::Outer, CENTRED] {
                    let g = smoothies(
                        &Mat4::IDENTITY,
                        &caster,
                        &edges,
                        (SmoothieSize::Fixed(t), ReceiverBound::up_to(f32::INFINITY)),
                        penumbra,
                    );
                    let near = |tri: &&[SmoothieVertex]| {
                        tri.iter().all(|v| Vec2::new(v.x, v.y).length() < 2.0 * t && v.keep == KEEP_ALL)
                    };
                    let area = |triangles: &[SmoothieVertex]| -> f32 {
                        let area = |tri: &[SmoothieVertex]| {
                            let [a, b, c] = [0, 1, 2].map(|k| Vec2::new(tri[k].x, tri[k].y));
                            (b - a).perp_dot(c - a).abs() * 0.5
                        };
                        triangles.chunks(3).filter(near).map(area).sum()
                    };
                    // The gap is the sector of θ, area θt²/2, outside a convex turn, over the
                    // blocker inside a concave one (centred); two kites hold it, 2·tan(θ/4)·t².
                    let sector = (0.5 * turn * t * t * 0.999, turn * t * t);
                    let none = (0.0, 0.0);
                    let (outer, inner) = match (convex, penumbra) {
                        (true, _) => (sector, none),
                        (false, Penumbra::Outer) => (none, none),
                        (false, _) => (none, sector),
                    };
                    for (area, (lo, hi), what) in [(area(&g.corners), outer, "outer"), (area(&g.inner), inner, "inner")]
                    {
                        assert!(
                            (lo..=hi).contains(&area),
                            "turn {turn}, convex {convex}, {penumbra:?}: {what} area {area} not in [{lo}, {hi}]"
                        );
                    }
                }
            }
        }
    }

    /// Any depth range: only the shaders read it. The grid a 1024² buffer's over a window 1 wide,
    /// llvmpipe's 8 subpixel bits.
    const CENTRED: Penumbra = Penumbra::Centred { near: 1.0, far: 2.0, grid: GRID };
    const GRID: CutGrid = CutGrid { texel: 1.0 / 1024.0, sliver: 1.0 / 65536.0 };

    proptest! {
        #[test]
        fn inner_quads_mirror_the_edges_over_the_blocker(height in 0.5f32..5.0, t in 0.001f32..0.2) {
            let (positions, triangles, adjacency) = plate(height);
            let caster = Caster { positions: &positions, triangles: &triangles, adjacency: &adjacency };
            let edges = silhouette(&caster, &FacePlanes::new(&positions, &triangles), &Mat4::IDENTITY, Vec3::new(0.0, 10.0, 0.0));
            let size = (SmoothieSize::Fixed(t), ReceiverBound::up_to(f32::INFINITY));
            let g = smoothies(&down(), &caster, &edges, size, CENTRED);
            prop_assert_eq!(g.corners.len(), 4 * 12, "a wedge at each convex vertex, nothing over the blocker");
            let half = 0.5 / (10.0 - height);
            // Each edge's inner quad, whole or in pieces near the corners: every point t/2 inside
            // the outline is covered.
            for k in 0..=16 {
                let along = -half + 2.0 * half * k as f32 / 16.0;
                for q in [(along, half), (along, -half), (half, along), (-half, along)].map(|(x, y)| Vec2::new(x, y)) {
                    let inward = if q.x.abs() == half { Vec2::new(-q.x.signum(), 0.0) } else { Vec2::new(0.0, -q.y.signum()) };
                    let q = q + inward * 0.5 * t;
                    prop_assert!(g.inner.chunks(3).any(|u| inside(u, q)), "{q} inside the outline uncovered");
                }
            }
            for v in &g.inner {
                let (p, foot, normal) = (Vec2::new(v.x, v.y), Vec2::new(v.fx, v.fy), Vec2::new(v.nx, v.ny));
                prop_assert!((0.0..=1.0).contains(&v.sx), "alpha from 0 on the outline to 1 at t inside it");
                prop_assert!((foot.x.abs().max(foot.y.abs()) - half).abs() < 1e-4, "the foot lies on the outline");
                prop_assert!((normal.length() - 1.0).abs() < 1e-5 && normal.dot(foot) > 0.0, "outward: {normal}");
                prop_assert!(((p - foot).dot(normal) + v.sx * t).abs() < 1e-5, "alpha is the depth inside / t");
                prop_assert!((p - foot).perp_dot(normal).abs() < 1e-6, "straight in from the foot");
                prop_assert_eq!((v.near, v.far), (1.0, 2.0));
            }
        }
    }

    #[test]
    fn depth_range_holds_the_whole_box() {
        let bounds = Aabb { min: Vec3::new(-1.0, 2.0, -1.0), max: Vec3::new(1.0, 3.0, 1.0) };
        assert_eq!(depth_range(&down(), &bounds), (7.0, 8.0));
    }

    #[test]
    fn physical_size_is_the_light_s_angular_radius_from_the_blocker() {
        let size = SmoothieSize::Physical { light_radius: 0.5, scale: 1.0, behind: 0.0 };
        assert!((size.at(5.0) - 0.1).abs() < 1e-7);
        let moved = SmoothieSize::Physical { light_radius: 0.5, scale: 1.0, behind: 3.0 };
        assert!((moved.at(2.0) - 0.1).abs() < 1e-7, "the light 3 behind the view's origin");
        assert_eq!(SmoothieSize::Fixed(0.02).at(123.0), 0.02);
    }

    #[test]
    fn vertices_behind_the_light_and_point_edges_are_skipped() {
        let (positions, triangles, adjacency) = plate(12.0); // above the light at y = 10
        let caster = Caster { positions: &positions, triangles: &triangles, adjacency: &adjacency };
        let edges =
            silhouette(&caster, &FacePlanes::new(&positions, &triangles), &Mat4::IDENTITY, Vec3::new(0.0, 10.0, 0.0));
        let g = smoothies(
            &down(),
            &caster,
            &edges,
            (SmoothieSize::Fixed(0.1), ReceiverBound::up_to(f32::INFINITY)),
            CENTRED,
        );
        assert!(g.is_empty());
    }

    /// Two edges at the origin, turning left by `turn` (radians) from +x, the light-facing side
    /// on the left (convex) or the right (concave), each `length` long, at depth 5: their
    /// smoothies with a fixed size t.
    fn turning(turn: f32, convex: bool, length: f32, t: f32, penumbra: Penumbra) -> SmoothieGeometry {
        let (into, out) = (Vec2::X, Vec2::from_angle(turn));
        let inside = (out - into) * 0.5 * if convex { 1.0 } else { -1.0 };
        let points = [-into * length, Vec2::ZERO, out * length, inside * length];
        let positions: Vec<Vec3> = points.iter().map(|p| p.extend(1.0) * 5.0).collect();
        let adjacency = EdgeAdjacency::default();
        let caster = Caster { positions: &positions, triangles: &[], adjacency: &adjacency };
        let size = (SmoothieSize::Fixed(t), ReceiverBound::up_to(f32::INFINITY));
        smoothies(&Mat4::IDENTITY, &caster, &[([0, 1], 3), ([1, 2], 3)], size, penumbra)
    }

    #[test]
    fn a_corner_s_pieces_hold_every_fragment_whose_footprint_reaches_the_other_line() {
        // Edge A from the vertex along +x, its quad's width 1, outward +y (a convex turn: the
        // other edge runs back over the shadow, below A's line); a fragment of A's quads
        // within its width of A, and its footprint's radius at most that width.
        let farthest_reaching = |n2: Vec2| {
            let mut farthest: f32 = 0.0;
            for i in 0..=400 {
                for j in -50..=50 {
                    let p = Vec2::new(i as f32 * 0.01, j as f32 * 0.02);
                    if n2.dot(p).abs() < 1.0 {
                        farthest = farthest.max(p.x);
                    }
                }
            }
            farthest
        };
        for degrees in [54.0_f32, 70.0, 90.0, 110.0, 127.0] {
            let (sin, cos) = degrees.to_radians().sin_cos();
            // The other edge's outward normal, A's turned by the turn.
            let n2 = Vec2::new(sin, cos);
            let corner = ShadowCorner { at: Vec2::ZERO, normals: [Vec2::Y, n2], convex: true, chamfer: None };
            let need = corner.piece() / PIECE_MARGIN;
            let farthest = farthest_reaching(n2);
            assert!(farthest <= need, "{degrees}°: a footprint {farthest} along reaches the other line, pieces {need}");
            assert!(farthest >= need - 0.03, "{degrees}°: pieces {need} for footprints reaching {farthest} along");
        }
        let right = ShadowCorner { at: Vec2::ZERO, normals: [Vec2::Y, Vec2::X], convex: false, chamfer: None };
        assert!((right.piece() - PIECE_MARGIN).abs() < 1e-6, "a right angle needs one width");
        let shallow = ShadowCorner {
            at: Vec2::ZERO,
            normals: [Vec2::Y, Vec2::new(0.5, 0.75_f32.sqrt())],
            convex: true,
            chamfer: None,
        };
        assert!((shallow.piece() - 2.0 * PIECE_MARGIN).abs() < 1e-5, "a shallow turn cut as the sharpest");
    }

    #[test]
    fn a_shadow_corner_needs_a_turn_long_edges_and_no_spike() {
        let t = 0.01;
        let turns = |g: &SmoothieGeometry| -> Vec<f32> {
            let mut turns: Vec<f32> = g.vertices().map(|v| v.turn).filter(|&turn| turn != 0.0).collect();
            turns.dedup();
            turns
        };
        for (degrees, length, convex, expected) in [
            (90.0, 1.0, true, Some(1.0)),
            (90.0, 1.0, false, Some(-1.0)),
            (30.0, 1.0, true, Some(1.0)),
            (125.0, 1.0, false, Some(-1.0)),
            // Straighter than MIN_TURN: a tessellated curve, not a corner.
            (0.5, 1.0, true, None),
            // Sharper than SHARPEST_TURN: a spike.
            (130.0, 1.0, true, None),
            // Edges shorter than CORNER_REACH footprints (t · 1 here).
            (90.0, 1.9 * t, true, None),
            (90.0, 2.1 * t, true, Some(1.0)),
        ] {
            let g = turning(f32::to_radians(degrees), convex, length, t, CENTRED);
            let want: Vec<f32> = expected.into_iter().collect();
            assert_eq!(turns(&g), want, "{degrees}°, {length} long, convex {convex}");
            let corner = g.vertices().find(|v| v.turn != 0.0);
            if let Some(v) = corner {
                assert_eq!((v.cx, v.cy), (0.0, 0.0), "the corner's vertex");
                let [n1, n2] = [Vec2::new(v.normals[0], v.normals[1]), Vec2::new(v.normals[2], v.normals[3])];
                let side = if convex { -1.0 } else { 1.0 };
                // Outward: away from the light-facing side, which lies left of the path (convex).
                assert!(n1.dot(Vec2::new(0.0, side)) > 0.99 || n2.dot(Vec2::new(0.0, side)) > 0.99, "{n1} {n2}");
            }
            assert!(turns(&turning(f32::to_radians(degrees), convex, length, t, Penumbra::Outer)).is_empty());
        }
    }

    /// Centred smoothies of size `t` of a caster whose silhouette is the open path through
    /// `points`, in the tangent plane at depth 5 as [`turning`]'s, its light-facing side left.
    fn path(points: &[Vec2], t: f32) -> SmoothieGeometry {
        let n = points.len() as u32;
        let left = points.windows(2).map(|w| (w[0] + w[1]) * 0.5 + (w[1] - w[0]).perp());
        let positions: Vec<Vec3> = points.iter().copied().chain(left).map(|p| p.extend(1.0) * 5.0).collect();
        let adjacency = EdgeAdjacency::default();
        let caster = Caster { positions: &positions, triangles: &[], adjacency: &adjacency };
        let edges: Vec<PenumbraEdge> = (0..n - 1).map(|i| ([i, i + 1], n + i)).collect();
        smoothies(
            &Mat4::IDENTITY,
            &caster,
            &edges,
            (SmoothieSize::Fixed(t), ReceiverBound::up_to(f32::INFINITY)),
            CENTRED,
        )
    }

    /// `path`'s points onward from its last: `turns.len()` steps of `length`, turning left by
    /// each of `turns` (radians) before its step, from `heading`.
    fn walk_on(path: &mut Vec<Vec2>, heading: f32, turns: &[f32], length: f32) -> f32 {
        turns.iter().fold(heading, |heading, turn| {
            let heading = heading + turn;
            path.push(*path.last().unwrap() + Vec2::from_angle(heading) * length);
            heading
        })
    }

    /// The hard shadow's corners a geometry's smoothies carry, each once.
    fn carried(g: &SmoothieGeometry) -> Vec<(Vec2, bool)> {
        let mut corners = Vec::new();
        for v in g.vertices().filter(|v| v.turn != 0.0) {
            let corner = (Vec2::new(v.cx, v.cy), v.turn > 0.0);
            if !corners.contains(&corner) {
                corners.push(corner);
            }
        }
        corners
    }

    #[test]
    fn a_side_cut_into_short_edges_is_one_straight_run() {
        // A right angle, convex, whose sides run 4 t each in edges of t/2 that zigzag across
        // them by a 200th of t: one corner, at the vertex, carried on by the edges within reach.
        let t = 0.01;
        let zigzag = |i: usize| if i.is_multiple_of(2) { 0.0 } else { 0.005 * t };
        let mut points: Vec<Vec2> = (0..8).map(|i| Vec2::new(-4.0 * t + 0.5 * t * i as f32, zigzag(i))).collect();
        points.extend((0..9).map(|i| Vec2::new(-zigzag(i), 0.5 * t * i as f32)));
        let g = path(&points, t);
        assert_eq!(carried(&g), [(Vec2::ZERO, true)]);
        let farthest = g.vertices().filter(|v| v.turn != 0.0).map(|v| Vec2::new(v.x, v.y).length()).fold(0.0, f32::max);
        assert!(farthest > 1.5 * t, "the corner carried past its own edges: {farthest}");
        let coarse = path(&[Vec2::new(-4.0 * t, 0.0), Vec2::ZERO, Vec2::new(0.0, 4.0 * t)], t);
        assert_eq!(carried(&coarse), carried(&g), "the four-vertex twin's");
    }

    #[test]
    fn a_turn_split_by_a_short_edge_keeps_that_edge_s_line() {
        // A convex right angle at the origin whose tip a chamfer of 0.42 t cuts off, from
        // (−0.3 t, 0) to (0, 0.3 t): one corner where the long sides' lines meet, which carries
        // the chamfer's line, its outward normal and the corner 0.3 t / √2 outside it.
        let t = 0.01;
        let (a, b) = (Vec2::new(-0.3 * t, 0.0), Vec2::new(0.0, 0.3 * t));
        let g = path(&[Vec2::new(-4.0 * t, 0.0), a, b, Vec2::new(0.0, 4.0 * t)], t);
        assert_eq!(carried(&g), [(Vec2::ZERO, true)]);
        let m = Vec2::new(1.0, -1.0).normalize();
        let expected = [m.x, m.y, 0.3 * t / 2.0_f32.sqrt()];
        for v in g.vertices().filter(|v| v.turn != 0.0) {
            let off = v.chamfer.iter().zip(expected).map(|(c, e)| (c - e).abs()).fold(0.0, f32::max);
            assert!(off < 1e-6, "chamfer {:?}, not {expected:?}", v.chamfer);
        }
        let uncut = path(&[Vec2::new(-4.0 * t, 0.0), Vec2::ZERO, Vec2::new(0.0, 4.0 * t)], t);
        assert!(uncut.vertices().all(|v| v.chamfer == [0.0; 3]), "an uncut corner has no chamfer");
    }

    #[test]
    fn a_tessellated_curve_has_no_corners() {
        // A quarter circle of radius 7.7 t in edges of t/2, each vertex turning 0.065 rad (more
        // than MIN_TURN): chords of two footprints through it turn by 0.26 rad, and its edges
        // turn from them by half that, far more than RUN_STRAY allows.
        let t = 0.01;
        let mut points = vec![Vec2::ZERO];
        walk_on(&mut points, -0.0325, &[0.065; 24], 0.5 * t);
        assert!(carried(&path(&points, t)).is_empty());
    }

    #[test]
    fn a_corner_is_carried_only_along_its_lines() {
        use std::f32::consts::{FRAC_PI_3, FRAC_PI_6};
        // A convex turn of 120° between straight sides of 4 t and 2.5 t; past the second, the
        // outline bends by 60° and curls on. The first vertex past the bend lies 0.43 t off the
        // side's line, within the corner's reach (2.78 t of 3.17 t): it keeps its own V, and so
        // does the edge after it.
        let t = 0.01;
        let mut points: Vec<Vec2> = (0..=8).map(|i| Vec2::new(-4.0 * t + 0.5 * t * i as f32, 0.0)).collect();
        let heading = walk_on(&mut points, 0.0, &[2.0 * FRAC_PI_3, 0.0, 0.0, 0.0, 0.0], 0.5 * t);
        walk_on(&mut points, heading, &[FRAC_PI_3, FRAC_PI_6, FRAC_PI_6, FRAC_PI_6], 0.5 * t);
        let g = path(&points, t);
        assert_eq!(carried(&g), [(Vec2::ZERO, true)]);
        let past = points[15];
        let carries = |v: &SmoothieVertex| v.turn != 0.0 && Vec2::new(v.fx, v.fy).distance(past) < 1e-6;
        assert!(!g.inner.iter().any(carries), "the second edge past the bend carries the corner");
    }

    /// What the smoothie pass interpolates at a fragment.
    struct Interpolated {
        shape: Vec2,
        along: f32,
        b: f32,
    }

    /// Where `q` falls in `tri` (the smoothie pass's interpolation): the shape projectively
    /// (w = 1/t), `along` and 1/b linearly; `None` outside it or where its keep leaves `q` out.
    fn kept_at(tri: &[SmoothieVertex], q: Vec2) -> Option<Interpolated> {
        let p = |k: usize| Vec2::new(tri[k].x, tri[k].y);
        let area = |a: Vec2, b: Vec2, c: Vec2| (b - a).perp_dot(c - a);
        let whole = area(p(0), p(1), p(2));
        if whole == 0.0 || !inside(tri, q) {
            return None;
        }
        let l = [area(q, p(1), p(2)) / whole, area(p(0), q, p(2)) / whole, area(p(0), p(1), q) / whole];
        let (mut shape, mut weight, mut along, mut inverse_b) = (Vec2::ZERO, 0.0, 0.0, 0.0);
        for (k, v) in tri.iter().enumerate() {
            shape += l[k] * Vec2::new(v.sx, v.sy) / v.w;
            weight += l[k] / v.w;
            along += l[k] * v.along;
            inverse_b += l[k] / v.b;
        }
        (along >= tri[0].keep[0] && along < tri[0].keep[1]).then_some(Interpolated {
            shape: shape / weight,
            along,
            b: 1.0 / inverse_b,
        })
    }

    #[test]
    fn a_cut_quad_s_pieces_interpolate_as_the_whole_and_keep_every_point() {
        // An edge from (0, 0) to (1, 0), its quad out along +y to t·k, t growing from 0.1 to 0.3
        // and the reach k falling from 1 to 0.8 (α = y / t throughout), its depth b = 0.1 / t
        // (the physical size, t = R / b), so that 1/b, not b, is linear along the edge; corners
        // at both ends, cut at 0.2 and 0.3 of the way.
        let (ta, tb, kb) = (0.1, 0.3, 0.8);
        let at = |x: f32, t: f32, alpha: f32| weighted(vertex(Vec2::new(x, alpha * t), 0.1 / t, Vec2::X * alpha), t);
        let q = [at(0.0, ta, 0.0), at(1.0, tb, 0.0), at(1.0, tb, kb), at(0.0, ta, 1.0)];
        let corner = ShadowCorner { at: Vec2::ZERO, normals: [Vec2::NEG_Y, Vec2::NEG_X], convex: true, chamfer: None };
        let mut out = Vec::new();
        let cuts = [0.2, 0.3];
        edge_quad(&mut out, q, ([Some(corner), Some(corner)], cuts), CutGrid { texel: 1e-2, sliver: 1e-3 });
        for i in 0..=40 {
            let x = 1e-3 + 0.998 * i as f32 / 40.0;
            let (t, rim) = (ta + (tb - ta) * x, ta + (tb * kb - ta) * x);
            for j in 0..=10 {
                let y = rim * (1e-3 + 0.998 * j as f32 / 10.0);
                let q = Vec2::new(x, y);
                let kept: Vec<(&[SmoothieVertex], Interpolated)> =
                    out.chunks(3).filter_map(|tri| kept_at(tri, q).map(|k| (tri, k))).collect();
                assert!(!kept.is_empty(), "{q} kept by no piece");
                for (tri, Interpolated { shape, along, b }) in kept {
                    assert!((shape.x - y / t).abs() < 1e-4 && shape.y.abs() < 1e-6, "{q}: shape {shape}");
                    assert!((along - x).abs() < 1e-5, "{q}: along {along}");
                    assert!((b * t / 0.1 - 1.0).abs() < 1e-5, "{q}: b {b} for {}", 0.1 / t);
                    // Within the cuts' slack both pieces keep it; elsewhere only its own.
                    let at_cut = [cuts[0], 1.0 - cuts[1]].iter().any(|c| (x - c).abs() < KEEP_SLACK);
                    let near = x < cuts[0] || x > 1.0 - cuts[1];
                    assert!(at_cut || (tri[0].turn != 0.0) == near, "{q}: corner {}", tri[0].turn);
                }
            }
        }
    }

    /// The sliver that comes with each piece of a cut quad ([`edge_quad`]): a quad `sliver` wide
    /// whose first triangle stands on the uncut quad's own base vertices, so that the hard
    /// edge's line, which the map's caster shares, is drawn exactly as uncut (the pieces' bases
    /// run to rounded cut vertices), each piece keeping the band in its own part of the edge.
    #[test]
    fn every_piece_of_a_cut_quad_draws_its_exact_base() {
        let at = |x: f32, alpha: f32| weighted(vertex(Vec2::new(x, alpha * 0.2), 0.5, Vec2::X * alpha), 0.2);
        let q = [at(0.0, 0.0), at(1.0, 0.0), at(1.0, 1.0), at(0.0, 1.0)];
        let corner = ShadowCorner { at: Vec2::ZERO, normals: [Vec2::NEG_Y, Vec2::NEG_X], convex: true, chamfer: None };
        let (cuts, sliver) = ([0.2, 0.3], 1e-3);
        let mut out = Vec::new();
        edge_quad(&mut out, q, ([Some(corner), Some(corner)], cuts), CutGrid { texel: 1e-2, sliver });
        let exact = |v: &SmoothieVertex, end: &SmoothieVertex| (v.x, v.y) == (end.x, end.y);
        let on_base = |tri: &&[SmoothieVertex]| [&q[0], &q[1]].iter().all(|end| tri.iter().any(|v| exact(v, end)));
        for i in 0..100 {
            let x = (i as f32 + 0.5) / 100.0;
            // Half the sliver's reach at x (it reaches `sliver` at end b, where the base's
            // triangle is widest).
            let p = Vec2::new(x, 0.5 * sliver * x);
            let keeping: Vec<&[SmoothieVertex]> =
                out.chunks(3).filter(on_base).filter(|tri| kept_at(tri, p).is_some()).collect();
            assert!(!keeping.is_empty(), "{p}: kept by no triangle on the exact base");
            let near = x < cuts[0] || x > 1.0 - cuts[1];
            assert!(keeping.iter().all(|tri| (tri[0].turn != 0.0) == near), "{p}: another piece's sliver");
        }
    }

    /// A thick slab (0.6 × 1.3 m, 4 m long, from 1 m up) under a light of radius 0.5 m 5 m
    /// straight above it, the ground 5 m below the light: its sides' bottom rims (tangent x =
    /// ±0.3/4), unlit from the centre and lit from the light's rim, are its partial silhouettes
    /// under the top rims (±0.3/2.7). Centred, each gets an inner quad from its edge inward,
    /// alpha 0 there, its own umbra (α = 1 − 4/5 of t = 0.5/4) at ±0.05 (x = 0.25 m on the
    /// ground), held on to where the top rim's inner half ends, ±(0.3 − 0.5·(1 − 2.7/5))/2.7,
    /// carrying the top rim's depth 2.7 and the inward normal. Outer only, nothing. Cut to
    /// 0.16 m long, the rims (0.04 in tangent units) no longer span the light's footprint on the
    /// ground (2 · 0.2 · 0.125 = 0.05 across) and get none; only the ends' 0.6 m bottom edges do.
    #[test]
    fn a_thick_slab_s_bottom_rims_narrow_its_inner_halves() {
        let light = Vec3::Y * 5.0;
        // Looking down from the light: view (x, y, z) = world (x, z, 5 − y).
        let down = Mat4::from_cols(glam::Vec4::X, -glam::Vec4::Z, glam::Vec4::Y, glam::Vec4::new(0.0, 0.0, 5.0, 1.0));
        let size = (SmoothieSize::Physical { light_radius: 0.5, scale: 1.0, behind: 0.0 }, ReceiverBound::up_to(5.0));
        let (near, far) = (2.7, 4.0);
        let inner_quads = |(slab, model): (TestMesh, Mat4), penumbra| {
            let (caster, planes) = (slab.caster(), &slab.planes);
            let partial = partial_silhouettes(&caster, planes, &planes.light_facing(&model, light), &model, light, 0.5);
            partial_smoothies(&(down * model), &caster, &partial, size, penumbra)
        };
        let outer = inner_quads(TestMesh::thick_slab(), Penumbra::Outer);
        assert!(outer.is_empty(), "outer only: {outer:?}");
        let centred = inner_quads(TestMesh::thick_slab(), Penumbra::Centred { near, far, grid: GRID });
        assert!(centred.edges.is_empty(), "nothing above the top rims: {:?}", centred.edges);
        assert_eq!(centred.partial_inner.len(), 2 * 6, "one quad per bottom rim");
        let (edge, t, held) = (0.3 / 4.0, 0.5 / 4.0, (0.3 - 0.5 * (1.0 - 2.7 / 5.0)) / 2.7);
        for v in &centred.partial_inner {
            let x = v.x.abs();
            let alpha = Vec2::new(v.sx, v.sy).length();
            assert!((v.b - 4.0).abs() < 1e-4 && (v.cx - 2.7).abs() < 1e-4, "depths {} and {}", v.b, v.cx);
            assert!((v.near, v.far) == (near, far) && v.turn == 0.0, "{v:?}");
            assert!(v.normals[0] * v.x < 0.0 && (v.normals[0].abs() - 1.0).abs() < 1e-5, "inward: {v:?}");
            if alpha == 0.0 {
                assert!((x - edge).abs() < 1e-5, "the bottom rim at {x}");
            } else {
                assert!((x - held).abs() < 1e-4, "held to {x}, not {held}");
                assert!((alpha - (edge - held) / t).abs() < 1e-4, "alpha {alpha} there");
            }
        }
        let short =
            (TestMesh::new(crate::geometry::shapes::cuboid(Vec3::new(0.6, 1.3, 0.16))), TestMesh::thick_slab().1);
        let cut = inner_quads(short, Penumbra::Centred { near, far, grid: GRID });
        assert!(!cut.partial_inner.is_empty(), "the ends' bottom edges");
        let rims = cut.partial_inner.iter().filter(|v| v.normals[0] != 0.0).count();
        assert_eq!(rims, 0, "vertices of quads along the short rims");
    }

    #[test]
    fn drawn_puts_the_smoothies_near_corners_apart() {
        let t = 0.01;
        // A right angle, and a chamfered one (a_turn_split_by_a_short_edge_keeps_that_edge_s_line).
        let mut g = turning(f32::to_radians(90.0), true, 1.0, t, CENTRED);
        g.extend(&path(
            &[Vec2::new(-4.0 * t, 0.0), Vec2::new(-0.3 * t, 0.0), Vec2::new(0.0, 0.3 * t), Vec2::new(0.0, 4.0 * t)],
            t,
        ));
        // A partial silhouette's inner quad (partial_smoothies), marked apart by its depth.
        let partial = SmoothieVertex { cx: 2.0, ..g.inner[0] };
        g.partial_inner = vec![partial; 6];
        let (vertices, counts) = g.drawn();
        assert_eq!(counts.iter().sum::<u32>() as usize, g.vertices().count());
        assert!(counts.iter().all(|&c| c > 0 && c % 3 == 0), "every part: {counts:?}");
        let (parts, last) = counts.split_at(6);
        let mut at = 0;
        for (k, &count) in parts.iter().enumerate() {
            let part = &vertices[at..at + count as usize];
            assert!(part.iter().all(|v| (v.turn != 0.0) == (k % 3 != 0)), "part {k}: corners");
            assert!(part.iter().all(|v| (v.chamfer != [0.0; 3]) == (k % 3 == 2)), "part {k}: chamfers");
            assert!(part.iter().all(|v| (v.near != 0.0) == (k >= 3)), "part {k}: outer, then inner");
            at += count as usize;
        }
        assert_eq!(&vertices[at..], &g.partial_inner[..last[0] as usize], "the partial silhouettes' last");
    }
}
