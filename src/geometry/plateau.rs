//! Haines' plateaus ("Soft Planar Shadows Using Plateaus", 2001) as pure geometry: the plateau
//! object whose plan view is the soft shadow texture. Its top is the hard drop shadow (the
//! umbra, drawn by the GPU with [`ReceiverPlane::shadow_matrix`]); its sides are a cone at each
//! silhouette vertex and a sheet along each silhouette edge (§2), built here on the CPU.
//!
//! Everything lives in the receiver plane's coordinates (u, v) plus the plateau parameter
//! t ∈ [0, 1]: 0 on the hard shadow edge (the hither, darkest), 1 on the penumbra's outer rim
//! (the yon, lit). Drawn with depth = t, the darkest primitive wins where they overlap (§2).
//!
//! [`Penumbra::Centred`] (issue 20) draws each sheet on both sides of its hard edge, so that t
//! becomes the distance to the nearest silhouette in units of the local half width, inside the
//! hard shadow as well as outside it; the technique keeps the hard shadow as a separate mask,
//! which gives the distance its sign. Each vertex carries the silhouette point it measures from
//! (its foot) and the edge's normal, so the GPU can drop the distances to silhouettes that do
//! not lie on the hard shadow's boundary (interior folds, edges under another caster's shadow).
//! [`partial_sides`] adds the sheets of edges that are the silhouette for part of the light
//! only: outer halves that widen the silhouette's, inner halves that narrow it ([`caster_sides`]
//! puts a caster's together).

use glam::{Mat2, Mat4, Vec2, Vec3, Vec4};

use std::f32::consts::TAU;

use rayon::prelude::*;

use crate::shader_constants::{FOLD_SLACK, MAX_INNER_REACH, SHEET_SLACK, SHEET_VEC4S, WEDGE_VEC4S};

use super::silhouette::{
    Caster, EdgeSource, FacePlanes, Facing, PARTIAL_GAIN, PartialEdge, partial_silhouettes, penumbra_edges,
};

/// Fraction of the light's height above which a point casts nothing: its projection from the
/// light would land behind the light (an anti-shadow). Such vertices get no cones or sheets,
/// and the umbra's homogeneous clip (w = light height − point height > 0) drops their part.
const ABOVE_LIGHT: f32 = 1e-4;
/// Steepest angle from the plane's normal a base ellipse follows (85°): towards the horizon the
/// true footprint grows without bound (a parabola, then a hyperbola).
const MAX_TILT_TAN: f32 = 11.43;
/// Most steps of the outer tangent's root search (bisection's for f32 resolution of s =
/// tan(δ/2) ∈ [−1, 1]), and the bracket width at which it stops.
const TANGENT_STEPS: u32 = 26;
const TANGENT_TOLERANCE: f32 = 1e-6;

/// A receiver plane with an in-plane frame: height along `normal`, coordinates along `u`, `v`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ReceiverPlane {
    pub origin: Vec3,
    pub normal: Vec3,
    pub u: Vec3,
    pub v: Vec3,
}

impl ReceiverPlane {
    /// The ground y = `height`: u = +X, v = +Z.
    pub fn ground(height: f32) -> Self {
        ReceiverPlane { origin: Vec3::new(0.0, height, 0.0), normal: Vec3::Y, u: Vec3::X, v: Vec3::Z }
    }

    pub fn height(&self, p: Vec3) -> f32 {
        (p - self.origin).dot(self.normal)
    }

    pub fn coords(&self, p: Vec3) -> Vec2 {
        let d = p - self.origin;
        Vec2::new(d.dot(self.u), d.dot(self.v))
    }

    /// Where `p` lands, projected from the point `light` (Blinn); `None` unless `p` is below
    /// the light.
    pub fn project(&self, light: Vec3, p: Vec3) -> Option<Vec2> {
        let (hl, hp) = (self.height(light), self.height(p));
        if hp >= hl * (1.0 - ABOVE_LIGHT) {
            return None;
        }
        Some(self.coords(light + (p - light) * (hl / (hl - hp))))
    }

    /// Blinn's planar projection ("Me and My (Fake) Shadow", 1988) in homogeneous form: world
    /// point p ↦ (u·w, v·w, 0, w) with w = h(light) − h(p), so that points at or above the light
    /// get w ≤ 0 and the GPU's clipper removes them instead of drawing an anti-shadow.
    pub fn shadow_matrix(&self, light: Vec3) -> Mat4 {
        // Plane coordinates of the homogeneous point: (q − o·w)·u, (q − o·w)·v, 0, w.
        let to_plane = Mat4::from_cols(
            Vec4::new(self.u.x, self.v.x, 0.0, 0.0),
            Vec4::new(self.u.y, self.v.y, 0.0, 0.0),
            Vec4::new(self.u.z, self.v.z, 0.0, 0.0),
            Vec4::new(-self.origin.dot(self.u), -self.origin.dot(self.v), 0.0, 1.0),
        );
        to_plane * self.blinn_matrix(light)
    }

    /// Blinn's projection in world space (DDJ Example 1, Komura's ground-plane matrix): p ↦
    /// (q·w, w), q the point of the plane on the ray from `light` through p, w = h(light) − h(p).
    pub fn blinn_matrix(&self, light: Vec3) -> Mat4 {
        let hl = self.height(light);
        let n = self.normal;
        // q·w = hl·p − h(p)·l, with h(p) = n·p − n·o, and w = hl − h(p).
        let no = n.dot(self.origin);
        Mat4::from_cols(
            (Vec3::X * hl - light * n.x).extend(-n.x),
            (Vec3::Y * hl - light * n.y).extend(-n.y),
            (Vec3::Z * hl - light * n.z).extend(-n.z),
            (light * no).extend(hl + no),
        )
    }
}

/// How big the penumbra of a vertex at height h is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PenumbraSize {
    /// From the light sphere: the footprint on the plane of the cone of rays from the vertex to
    /// the light (width W = D·h/(H − h) under a light overhead): cone radius `scale` × W/2, the
    /// true half width on each side of the hard edge at 1.
    Physical { scale: f32 },
    /// Haines §3: radius = factor × height (0.1 in most of the paper's images).
    Haines { factor: f32 },
}

/// A vertex cone: its apex, the projected vertex `centre`, over an elliptical base
/// { centre + offset + axes·x : |x| ≤ 1 }.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cone {
    pub centre: Vec2,
    /// From the apex to the base's centre: away from a low light, whose footprint reaches
    /// further beyond the projected vertex than short of it.
    pub offset: Vec2,
    /// Columns: the semi-major axis (pointing away from the light) and the semi-minor axis.
    pub axes: Mat2,
}

impl Cone {
    /// The support function: max over the base of ν·x.
    fn support(&self, nu: Vec2) -> f32 {
        nu.dot(self.centre + self.offset) + (self.axes.transpose() * nu).length()
    }

    /// The point of the base where the tangent with outward normal ν touches it.
    fn support_point(&self, nu: Vec2) -> Vec2 {
        let a = self.axes.transpose() * nu;
        let len = a.length();
        let base = self.centre + self.offset;
        if len == 0.0 { base } else { base + self.axes * (a / len) }
    }

    pub fn is_point(&self) -> bool {
        self.axes.col(0).length_squared() == 0.0 && self.axes.col(1).length_squared() == 0.0
    }

    /// The rim angle where the ray from the apex along `d` leaves the base; `inverse`: the
    /// axes' inverse. The apex lies inside the base (the ray through the light's centre is in
    /// the cone), so the angle turns with `d`, and the same way round: the axes keep their
    /// handedness.
    fn rim_angle(&self, inverse: Mat2, d: Vec2) -> f32 {
        let (q, w) = (inverse * d, inverse * self.offset);
        // The exit point x = s·q − w with |x| = 1, s > 0.
        let (qq, qw, ww) = (q.length_squared(), q.dot(w), w.length_squared());
        let x = q * ((qw + (qw * qw - qq * (ww - 1.0)).max(0.0).sqrt()) / qq) - w;
        atan2(x.y, x.x)
    }
}

/// atan2 within 1e-5 rad, plenty beside the wedges' overlap of [`WEDGE_OVERLAP`]: the rim
/// angles of every corner are a moving frame's only angles (issue 18: libm's atan2 took a
/// sixth of its CPU time). The odd polynomial of atan on [0, 1] of Abramowitz & Stegun 4.4.49
/// (error 2e-8), then the octant.
fn atan2(y: f32, x: f32) -> f32 {
    use std::f32::consts::{FRAC_PI_2, PI};
    let (ax, ay) = (x.abs(), y.abs());
    let (lo, hi) = (ax.min(ay), ax.max(ay));
    if hi == 0.0 {
        return 0.0;
    }
    let (z, z2) = (lo / hi, (lo / hi) * (lo / hi));
    let a = [0.021_861_23, -0.055_909_89, 0.096_420_04, -0.139_085_34, 0.199_465_36, -0.333_298_56, 0.999_999_33]
        .into_iter()
        .fold(-0.004_054_058f32, |p, c| p * z2 + c)
        * z;
    let a = if ay > ax { FRAC_PI_2 - a } else { a };
    let a = if x < 0.0 { PI - a } else { a };
    if y < 0.0 { -a } else { a }
}

/// The cone of vertex `p` under a light sphere (`light`, `radius`); `None` when `p` casts
/// nothing (at or above the light). A vertex on or under the plane has a point base: a hard
/// contact edge.
pub fn vertex_cone(plane: &ReceiverPlane, light: Vec3, radius: f32, size: PenumbraSize, p: Vec3) -> Option<Cone> {
    let centre = plane.project(light, p)?;
    let h = plane.height(p);
    if h <= 0.0 || radius == 0.0 && matches!(size, PenumbraSize::Physical { .. }) {
        return Some(Cone { centre, offset: Vec2::ZERO, axes: Mat2::ZERO });
    }
    match size {
        PenumbraSize::Haines { factor } => {
            Some(Cone { centre, offset: Vec2::ZERO, axes: Mat2::from_diagonal(Vec2::splat(factor * h)) })
        }
        PenumbraSize::Physical { scale } => {
            // The rays from p towards the light sphere form a cone of half-angle α about the
            // axis from the light through p, tilted θ from the plane's normal. Across the tilt
            // its section spans h·tan(θ ± α) from p's foot, so its middle lies beyond the
            // projected vertex (at h·tan θ) (§3's ellipse, major axis away from the light).
            let axis = (p - plane.origin - (light - plane.origin)).normalize();
            let away = Vec2::new(axis.dot(plane.u), axis.dot(plane.v));
            let (sin_theta, major) = (away.length().min(1.0), away.try_normalize().unwrap_or(Vec2::X));
            let alpha = (radius / (p - light).length()).min(1.0).asin();
            // Past the cap the section keeps the shape it has there: tilt held so that its far
            // side sits at the cap.
            let cap = MAX_TILT_TAN.atan();
            let true_theta = sin_theta.asin();
            let theta = true_theta.min((cap - alpha).max(0.0));
            let tan = |x: f32| x.min(cap).tan();
            let semi_major = 0.5 * h * (tan(theta + alpha) - tan(theta - alpha));
            let beyond = 0.5 * h * (tan(theta + alpha) + tan(theta - alpha)) - h * theta.tan();
            // Sideways, the base passes through the section's exact half width at the projected
            // vertex, h·tan α / cos θ: the slope of the penumbra along an edge running away from
            // the light (tan α / sin θ per unit of shadow) needs no cap. The section's own minor
            // axis, h·sin α / √(cos(θ + α)·cos(θ − α)), is what this gives below the cap; taking
            // h·tan α / cos θ as the minor axis instead, as the width at the ellipse's middle, made
            // a 12° light's long edges 15–17 % too narrow (tests/low_light.rs).
            let through = h * alpha.tan() / true_theta.cos().max(f32::EPSILON);
            let off_middle = if semi_major > 0.0 { (beyond / semi_major).min(1.0) } else { 0.0 };
            let semi_minor = through / (1.0 - off_middle * off_middle).max(f32::EPSILON).sqrt();
            let minor = major.perp();
            Some(Cone {
                centre,
                offset: major * beyond * scale,
                axes: Mat2::from_cols(major * semi_major * scale, minor * semi_minor * scale),
            })
        }
    }
}

/// The common outer tangent of two cone bases on the side of the segment between their centres
/// that `outward` points to: the touching points (on `a`, on `b`). `None` when one base holds
/// the other on that side (there is no such tangent) or the centres coincide.
pub fn outer_tangent(a: &Cone, b: &Cone, outward: Vec2) -> Option<(Vec2, Vec2)> {
    let along = (b.centre - a.centre).try_normalize()?;
    let side = if along.perp().dot(outward) >= 0.0 { along.perp() } else { -along.perp() };
    // Tangent normals ν(δ) = side·cos δ + along·sin δ; on the common tangent both bases reach
    // equally far: g(δ) = h_b(ν) − h_a(ν) = 0. g(−π/2) < 0 < g(π/2) unless one base holds the
    // other. Support functions scale with ν, so the sign of g needs ν only up to a positive
    // factor: ν ∝ side·(1 − s²) + along·2s with s = tan(δ/2) ∈ [−1, 1], free of trigonometry.
    let nu = |s: f32| side * (1.0 - s * s) + along * (2.0 * s);
    let g = |s: f32| b.support(nu(s)) - a.support(nu(s));
    if !(g(-1.0) < 0.0 && g(1.0) > 0.0) {
        return None;
    }
    // Newton's method from s = 0 (the tangent of equal bases), kept inside the bracket that the
    // signs of g give (bisecting where a step would leave it): g = ν·(p_b − p_a) with p the
    // bases' support points for ν, and, the support function's gradient being its support
    // point, g' = ν'·(p_b − p_a), so one pair of support points a step. Issue 18: the 26
    // bisection steps were most of a moving frame's CPU time; this takes a few.
    let (mut lo, mut hi, mut s) = (-1.0f32, 1.0f32, 0.0f32);
    let mut touch = (a.centre, b.centre);
    for _ in 0..TANGENT_STEPS {
        let n = nu(s);
        touch = (a.support_point(n), b.support_point(n));
        let gap = touch.1 - touch.0;
        let at = n.dot(gap);
        match at.partial_cmp(&0.0) {
            Some(std::cmp::Ordering::Less) => lo = s,
            Some(std::cmp::Ordering::Greater) => hi = s,
            _ => break,
        }
        let step = at / (along * 2.0 - side * (2.0 * s)).dot(gap);
        let next = if s - step > lo && s - step < hi { s - step } else { 0.5 * (lo + hi) };
        if (next - s).abs() <= TANGENT_TOLERANCE {
            break;
        }
        s = next;
    }
    Some(touch)
}

/// A sheet (§2) as one primitive: the bilinear patch P(s, t) = lerp(lerp(a, b, s), lerp(ta, tb,
/// s), t) between the hard edge a→b (t = 0) and the tangent points ta→tb (t = 1), the Coons
/// patch of four lines the paper tessellates (Figure 4, §3). Drawn as its corners' convex hull
/// (the patch, a convex combination of its corners, lies inside it); the GPU finds t per
/// fragment by inverting the map ([`Sheet::at`]), exact where the tessellation was within 1%.
/// Also the edge's unit normal in the plane and the caster's number, as the umbra mask writes it.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Sheet {
    pub a: [f32; 2],
    pub b: [f32; 2],
    pub ta: [f32; 2],
    pub tb: [f32; 2],
    /// The edge's unit normal; a partial silhouette's inward sheet's is k times it, the sheet
    /// drawn k times its width, its umbra held past it ([`partial_sides`]).
    pub normal: [f32; 2],
    pub caster: f32,
    /// The hull as two triangles: six corner numbers of 2 bits, the first lowest (0 a, 1 b,
    /// 2 tb, 3 ta; a triangular hull repeats a corner); above them [`CONVEX_BITS`].
    pub hull: u32,
    /// Where the whole edge's ends (a piece's too) meet the next edges of the outline.
    pub corners: [Corner; 2],
}

/// A vertex of the hard shadow's outline where two silhouette edges meet (issue 20): the
/// penumbra there is the light's footprint cut by both edges' lines, where the sheets alone
/// take one line each. `neighbour` is zero where the vertex has no such pair (an open chain's
/// end, three or more edges): no corner then.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Corner {
    /// The vertex's hard shadow.
    pub at: [f32; 2],
    /// The other edge's outward unit normal.
    pub neighbour: [f32; 2],
    /// The vertex cone's semi-axes (columns): the light's footprint there, as an ellipse.
    pub axes: [f32; 4],
}

/// Bits 12 and 13 of [`Sheet::hull`]: whether the hard shadow is convex at corner 0 (at a),
/// corner 1 (at b), where it is the intersection of the two edges' inner sides, not their union.
pub const CONVEX_BITS: u32 = 3 << 12;

// The records' sizes as the shaders read them.
const _: () =
    assert!(size_of::<Sheet>() == SHEET_VEC4S as usize * 16 && size_of::<Wedge>() == WEDGE_VEC4S as usize * 16);

impl Sheet {
    fn new(a: Vec2, b: Vec2, ta: Vec2, tb: Vec2, normal: Vec2, caster: f32) -> Self {
        let hull = hull_triangles([a, b, tb, ta]).iter().enumerate().fold(0, |bits, (k, &c)| bits | (c << (2 * k)));
        let corners = [Corner::default(); 2];
        Sheet { a: a.into(), b: b.into(), ta: ta.into(), tb: tb.into(), normal: normal.into(), caster, hull, corners }
    }

    /// Whether a corner can change V anywhere on this sheet (a piece, see [`Sheet::pieces`]):
    /// where the light's footprint about a point reaches past the corner, within a footprint
    /// radius (the cone's semi-major axis) of it, and the point within the sheet's width of its
    /// foot: a foot within radius + width of the corner, over sin 53° for turns up to 127°.
    /// Sharper turns are spikes, which the mask check mostly turns down (`penumbra.vert`); with
    /// every side drawn with the corners' code, no pixel of the suite moved by over 6e-5.
    pub fn near_corner(&self) -> bool {
        let (a, b) = (Vec2::from(self.a), Vec2::from(self.b));
        let width = (Vec2::from(self.ta) - a).length().max((Vec2::from(self.tb) - b).length());
        self.corners.iter().filter(|c| c.neighbour != [0.0; 2]).any(|c| {
            let axes = Mat2::from_cols_array(&c.axes);
            let radius = axes.col(0).length().max(axes.col(1).length());
            let at = Vec2::from(c.at);
            let along = (at - a).dot(b - a) / (b - a).length_squared().max(f32::MIN_POSITIVE);
            at.distance(a.lerp(b, along.clamp(0.0, 1.0))) <= 1.25 * (radius + width)
        })
    }

    /// The sheet with its edge's corners (at a, at b) and whether the shadow is convex there.
    fn with_corners(self, corners: [Corner; 2], convex: [bool; 2]) -> Self {
        let bits = (u32::from(convex[0]) | u32::from(convex[1]) << 1) << 12;
        Sheet { hull: self.hull & !CONVEX_BITS | bits, corners, ..self }
    }

    /// The corners, in the order the hull numbers them: a, b, tb, ta.
    pub fn corners(&self) -> [Vec2; 4] {
        [self.a, self.b, self.tb, self.ta].map(Vec2::from)
    }

    /// The six points of the two hull triangles the GPU draws.
    pub fn hull_points(&self) -> [Vec2; 6] {
        let corners = self.corners();
        std::array::from_fn(|k| corners[(self.hull >> (2 * k) & 3) as usize])
    }

    /// The patch's point at (s, t).
    pub fn point(&self, s: f32, t: f32) -> Vec2 {
        let [a, b, tb, ta] = self.corners();
        a.lerp(b, s).lerp(ta.lerp(tb, s), t)
    }

    /// The sheet cut across its hard edge into `n` equal pieces (n ≥ 1), each the patch over
    /// its range of s: together the same patch, each t where it was. Centred, a sheet's
    /// vertices probe the mask at a bounded number of samples along the hard edge
    /// (`glsl/plateau/penumbra.vert`), so a long edge is drawn in pieces short enough for a
    /// sample every texel.
    pub fn pieces(&self, n: u32) -> impl Iterator<Item = Sheet> + '_ {
        let n = n.max(1);
        (0..n).map(move |k| {
            let [s0, s1] = [k, k + 1].map(|k| k as f32 / n as f32);
            let [a, b, ta, tb] = [(s0, 0.0), (s1, 0.0), (s0, 1.0), (s1, 1.0)].map(|(s, t)| self.point(s, t));
            let piece = Sheet::new(a, b, ta, tb, self.normal.into(), self.caster);
            Sheet { hull: piece.hull | self.hull & CONVEX_BITS, corners: self.corners, ..piece }
        })
    }

    /// The plateau parameter at `p` and the hard edge's parameter s of its foot: the smallest t
    /// of the patch over `p` (where it folds over itself two cover it; min blending of the
    /// tessellation kept the smaller), `None` off the patch. What `glsl/plateau/penumbra.frag`
    /// computes per fragment: with e = b − a, f = ta − a, g = tb − ta − e and q = p − a,
    /// q = s·e + t·f + s·t·g; crossing with e + t·g removes s, leaving
    /// (f × g)·t² + (f × e − q × g)·t − q × e = 0, solved in the form without cancellation for
    /// either root.
    pub fn at(&self, p: Vec2) -> Option<(f32, f32)> {
        let [a, b, tb, ta] = self.corners();
        let (e, f, q) = (b - a, ta - a, p - a);
        let g = tb - ta - e;
        let (qa, qb, qc) = (f.perp_dot(g), f.perp_dot(e) - q.perp_dot(g), -q.perp_dot(e));
        // Near a folded patch's fold line the two roots meet, rounding (of q × e above all) can
        // take d below 0, and s swings with t: a root there counts if it maps back to p.
        let d = qb * qb - 4.0 * qa * qc;
        let h = -0.5 * (qb + d.max(0.0).sqrt().copysign(qb));
        let roots = [if h != 0.0 { qc / h } else { f32::NAN }, if qa != 0.0 { h / qa } else { f32::NAN }];
        let reach2 = FOLD_SLACK * FOLD_SLACK * (e.length_squared() + f.length_squared() + g.length_squared());
        let mut best: Option<(f32, f32)> = None;
        for t in roots {
            if !(-SHEET_SLACK..=1.0 + SHEET_SLACK).contains(&t) {
                continue; // NaN too
            }
            let side = e + g * t;
            let s = (q - f * t).dot(side) / side.length_squared();
            let (t, on_side) = (t.clamp(0.0, 1.0), s.clamp(0.0, 1.0));
            let inside = d >= 0.0 && (-SHEET_SLACK..=1.0 + SHEET_SLACK).contains(&s);
            let maps_back = (e * on_side + f * t + g * (on_side * t) - q).length_squared() <= reach2;
            if (inside || maps_back) && best.is_none_or(|(u, _)| t < u) {
                best = Some((t, on_side));
            }
        }
        best
    }
}

/// The convex hull of a quadrilateral's corners as two triangles of corner numbers, anticlockwise
/// (a triangular hull: the second degenerate). Andrew's monotone chain on four points.
fn hull_triangles(p: [Vec2; 4]) -> [u32; 6] {
    // Sorted by x, then y, with the five exchanges of a sorting network (a sort call with its
    // comparison closure cost more than the rest of a sheet).
    let mut order = [0u32, 1, 2, 3];
    for (i, j) in [(0, 1), (2, 3), (0, 2), (1, 3), (1, 2)] {
        let (a, b) = (p[order[i] as usize], p[order[j] as usize]);
        if b.x < a.x || b.x == a.x && b.y < a.y {
            order.swap(i, j);
        }
    }
    let turn = |o: u32, a: u32, b: u32| (p[a as usize] - p[o as usize]).perp_dot(p[b as usize] - p[o as usize]);
    let mut hull = [0u32; 8];
    let mut n = 0;
    for pass in [[0, 1, 2, 3], [3, 2, 1, 0]] {
        let start = n;
        for k in pass {
            let c = order[k];
            while n >= start + 2 && turn(hull[n - 2], hull[n - 1], c) <= 0.0 {
                n -= 1;
            }
            hull[n] = c;
            n += 1;
        }
        n -= 1; // the last point starts the other chain
    }
    let at = |k: usize| hull[k.min(n.max(1) - 1)];
    [at(0), at(1), at(2), at(0), at(2), at(3.min(n - 1).max(2))]
}

/// A piece of a vertex cone (§2) as one primitive: the part over the base's rim angles
/// `from`..`to` (at most a quarter turn and a little), t rising linearly from 0 at the apex to
/// 1 on the rim. In the base's unit-disk coordinates x (plane point apex + axes·(x + lean)) the
/// rim is |x| = 1 and the apex −lean, so t at y = x + lean is the s > 0 with |y/s − lean| = 1:
/// exact, where the paper's fan of `segments` flat triangles was polygonal ([`Wedge::t_at`]).
/// Drawn as the triangle apex→rim(from)→rim(to) and the trapezoid from that chord out to the
/// rim's tangent at the middle angle, which hold the piece whatever the apex's place.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Wedge {
    pub apex: [f32; 2],
    /// axes⁻¹ · (base centre − apex).
    pub lean: [f32; 2],
    /// The base's semi-axes (columns, x then y).
    pub axes: [f32; 4],
    pub from: f32,
    pub to: f32,
    pub caster: f32,
    /// 1 where the hard shadow is convex at the apex (see [`CONVEX_BITS`]), else 0.
    pub convex: f32,
    /// The outward unit normals of the apex's two edges, zero where it is no [`Corner`].
    pub normals: [f32; 4],
}

/// The widest rim arc of one [`Wedge`]: a quarter turn keeps its trapezoid within √2 of the rim.
const WEDGE_SPAN: f32 = std::f32::consts::FRAC_PI_2 + 2.0 * WEDGE_OVERLAP;

impl Wedge {
    fn axes(&self) -> Mat2 {
        Mat2::from_cols_array(&self.axes)
    }

    /// The nine points of the three triangles the GPU draws, in the plane.
    pub fn outline(&self) -> [Vec2; 9] {
        let half = 0.5 * (self.to - self.from);
        let (u0, u1) = (Vec2::from_angle(self.from), Vec2::from_angle(self.to));
        let (far0, far1) = (u0 / half.cos(), u1 / half.cos());
        let lean = Vec2::from(self.lean);
        let unit = [-lean, u0, u1, u0, far0, far1, u0, far1, u1];
        let (apex, axes) = (Vec2::from(self.apex), self.axes());
        unit.map(|x| apex + axes * (x + lean))
    }

    /// Whether the apex is a [`Corner`].
    pub fn at_corner(&self) -> bool {
        self.normals != [0.0; 4]
    }

    /// The cone's t at `p` (beyond 1 off the base): with y = axes⁻¹·(p − apex), the positive
    /// root of (1 − |lean|²)·t² + 2·(y·lean)·t − |y|² = 0, in the form without cancellation (the
    /// apex lies inside the base: |lean| < 1).
    pub fn t_at(&self, p: Vec2) -> f32 {
        let (y, lean) = (self.axes().inverse() * (p - Vec2::from(self.apex)), Vec2::from(self.lean));
        let (yy, yl) = (y.length_squared(), y.dot(lean));
        let root = yl + (yl * yl + (1.0 - lean.length_squared()) * yy).sqrt();
        if yy == 0.0 { 0.0 } else { yy / root }
    }
}

/// The plateau's sides, cones apart from sheets (the paper's two primitives, each its own timed
/// pass), one record per primitive.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlateauGeometry {
    pub cones: Vec<Wedge>,
    pub sheets: Vec<Sheet>,
    /// Centred, the outer halves of partial silhouettes above the silhouette ([`partial_sides`]):
    /// drawn only where the hard shadow is lit.
    pub partial: Vec<Sheet>,
    /// Centred, the inner halves of partial silhouettes below it ([`partial_sides`]): drawn
    /// only over their own caster's hard shadow, blended by max.
    pub partial_inner: Vec<Sheet>,
    /// Plane-space bounds of the shadow: the projected caster (the umbra, even when the
    /// penumbra has no width) and every cone and sheet.
    pub footprint: Option<(Vec2, Vec2)>,
    /// Part of a caster reaches the light's height: its umbra runs off to infinity.
    pub unbounded: bool,
}

impl PlateauGeometry {
    fn grow(&mut self, p: Vec2) {
        self.footprint = Some(self.footprint.map_or((p, p), |(lo, hi)| (lo.min(p), hi.max(p))));
    }

    pub fn extend(&mut self, other: &PlateauGeometry) {
        self.cones.extend_from_slice(&other.cones);
        self.sheets.extend_from_slice(&other.sheets);
        self.partial.extend_from_slice(&other.partial);
        self.partial_inner.extend_from_slice(&other.partial_inner);
        if let Some((lo, hi)) = other.footprint {
            self.grow(lo);
            self.grow(hi);
        }
        self.unbounded |= other.unbounded;
    }

    /// The narrowest half width of any sheet's penumbra (plane units): the least distance from
    /// a hard edge's end to its tangent point, infinite without sheets. Edges with no width at
    /// either end (lying on the plane) have no sheet; one end on the plane gives 0.
    pub fn narrowest_half_width(&self) -> f32 {
        let width = |s: &Sheet| {
            (Vec2::from(s.ta) - Vec2::from(s.a)).length().min((Vec2::from(s.tb) - Vec2::from(s.b)).length())
        };
        self.sheets.iter().map(width).fold(f32::INFINITY, f32::min)
    }

    /// The part of a cone over the rim angles `from`..`to` (radians, `from` < `to` ≤ `from` +
    /// 2π), as pieces of at most [`WEDGE_SPAN`]. A cone without area (a flat base) draws nothing.
    fn push_wedge(&mut self, cone: &Cone, (from, to): (f32, f32), caster: f32, corner: Option<WedgeCorner>) {
        if cone.axes.determinant() <= 0.0 {
            return;
        }
        let lean = cone.axes.inverse() * cone.offset;
        // The base's bounding box, once per cone: what the pieces draw past the rim has t > 1
        // and is discarded, so it need not fit in the texture.
        let reach = Vec2::new(cone.axes.row(0).length(), cone.axes.row(1).length());
        let base = cone.centre + cone.offset;
        [cone.centre, base - reach, base + reach].into_iter().for_each(|p| self.grow(p));
        let pieces = ((to - from) / WEDGE_SPAN).ceil().max(1.0);
        let step = (to - from) / pieces;
        for k in 0..pieces as u32 {
            let (a, b) = (from + step * k as f32, from + step * (k + 1) as f32);
            let wedge = Wedge {
                apex: cone.centre.into(),
                lean: lean.into(),
                axes: cone.axes.to_cols_array(),
                from: a,
                to: b,
                caster,
                convex: corner.map_or(0.0, |c| f32::from(u8::from(c.convex))),
                normals: corner.map_or([0.0; 4], |c| [c.normals.0.x, c.normals.0.y, c.normals.1.x, c.normals.1.y]),
            };
            self.cones.push(wedge);
        }
    }

    /// The sheet between the hard edge a→b (t = 0) and the tangent points ta→tb (t = 1), see
    /// [`Sheet`], its corners in the footprint. `normal`: the edge's unit normal, `caster`: the
    /// caster's number. `None` when the sheet has no width (a hard edge): nothing drawn.
    fn sheet(&mut self, a: Vec2, b: Vec2, ta: Vec2, tb: Vec2, normal: Vec2, caster: f32) -> Option<Sheet> {
        if (ta - a).length_squared().max((tb - b).length_squared()) == 0.0 {
            return None;
        }
        [a, b, ta, tb].into_iter().for_each(|p| self.grow(p));
        Some(Sheet::new(a, b, ta, tb, normal, caster))
    }
}

/// Where the penumbra lies about the hard shadow's edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Penumbra {
    /// Haines §2: outward only, the whole hard shadow the umbra.
    Outer,
    /// Both sides, the hard edge in the middle (issue 20): sheets on the inner side too.
    Centred,
}

/// The plateau settings of one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlateauLight {
    pub position: Vec3,
    pub radius: f32,
    pub size: PenumbraSize,
    pub penumbra: Penumbra,
    /// Only the parts of the cones between the sheets (issue 18), or whole cones (§2).
    pub wedges: bool,
}

/// The edges a caster's plateau follows, each with the third vertex of its light-facing
/// triangle (see [`penumbra_edges`]); `facing` from the mesh's face planes
/// ([`FacePlanes::light_facing`](super::silhouette::FacePlanes::light_facing)), as the smoothie
/// finds it. With
/// [`EdgeSource::Silhouettes`], an open mesh's edges also include the boundary edges of its
/// back-facing triangles: with the silhouettes and the lit boundary edges they bound its whole
/// shadow, which [`EdgeSource::LightFacing`] (every lit edge) covers with sides that mostly lie
/// inside it.
pub fn plateau_edges(caster: &Caster<'_>, facing: &Facing, source: EdgeSource) -> Vec<([u32; 2], u32)> {
    let mut edges = penumbra_edges(caster, facing, source);
    if source == EdgeSource::Silhouettes && !caster.adjacency.is_closed() {
        edges.extend(unlit_boundary_edges(caster, facing));
    }
    edges
}

/// Everything one caster adds to a frame's plateau, numbered `number`: facing from its face
/// `planes`, its penumbra edges ([`plateau_edges`]) and their sides ([`plateau_sides`]) and,
/// centred from silhouettes, its partial silhouettes' ([`partial_sides`]; lit edges are already
/// drawn whole).
pub fn caster_sides(
    plane: &ReceiverPlane,
    light: &PlateauLight,
    (caster, planes): (&Caster<'_>, &FacePlanes),
    model: &Mat4,
    source: EdgeSource,
    number: f32,
) -> PlateauGeometry {
    let facing = planes.light_facing(model, light.position);
    let edges = plateau_edges(caster, &facing, source);
    let mut sides = plateau_sides(plane, light, caster, model, &edges, source, number);
    if light.penumbra == Penumbra::Centred && source == EdgeSource::Silhouettes {
        let partial = partial_silhouettes(caster, planes, &facing, model, light.position, light.radius);
        sides.extend(&partial_sides(plane, light, caster, model, &partial, number));
    }
    sides
}

/// The plateau sides of one caster, numbered `number` (what its primitives carry): a sheet
/// along each of its penumbra `edges` ([`plateau_edges`]), on its outer side and, centred, on
/// its inner side, and at each penumbra vertex the parts of its cone that no sheet there covers.
/// `caster` may stay in object space, placed by `model` (object → world): only the edges'
/// vertices are transformed (issue 18: a moving frame transformed all of them).
///
/// Corner wedges instead of Haines' whole cones (§2; issue 18: on a fine mesh, whose edges are
/// much shorter than the penumbra, whole cones drew each texel some nine times). Where a sheet
/// leaves the vertex it is the cones' envelope, never above them; what the cone alone must
/// draw lies between the sheets: a convex corner's wedge, the outer half of a lone vertex.
/// Outer only, the inner side counts as covered: the hard shadow there is t = 0 whatever the
/// sides hold (the resolve). `source` says what the edges are: [`EdgeSource::LightFacing`]'s
/// need not bound an open mesh's shadow, so the footprint then holds every projected vertex.
pub fn plateau_sides(
    plane: &ReceiverPlane,
    light: &PlateauLight,
    caster: &Caster<'_>,
    model: &Mat4,
    edges: &[([u32; 2], u32)],
    source: EdgeSource,
    number: f32,
) -> PlateauGeometry {
    let world = |v: u32| model.transform_point3(caster.positions[v as usize]);
    // Each edge end (2i, 2i + 1 for edge i) to its vertex's cone, computed once per vertex.
    let mut ends: Vec<(u32, u32)> =
        edges.iter().enumerate().flat_map(|(i, ([a, b], _))| [(*a, 2 * i as u32), (*b, 2 * i as u32 + 1)]).collect();
    ends.sort_unstable();
    let groups: Vec<&[(u32, u32)]> = ends.chunk_by(|x, y| x.0 == y.0).collect();
    let cones: Vec<Option<Cone>> = groups
        .par_iter()
        .map(|g| vertex_cone(plane, light.position, light.radius, light.size, world(g[0].0)))
        .collect();
    let mut cone_of_end = vec![0u32; ends.len()];
    for (k, g) in groups.iter().enumerate() {
        g.iter().for_each(|(_, end)| cone_of_end[*end as usize] = k as u32);
    }
    let cone_of_end = &cone_of_end;
    let cone = |end: usize| cones[cone_of_end[end] as usize];
    // Each edge's outward normal, where both its ends cast; then, where a vertex joins two
    // edges, each end's corner (the other edge's normal) and the turn there.
    let normals: Vec<Option<Vec2>> = edges
        .par_iter()
        .enumerate()
        .map(|(i, &(_, inner))| {
            let (ca, cb) = (cone(2 * i)?, cone(2 * i + 1)?);
            Some(outward(&ca, &cb, plane.project(light.position, world(inner))?))
        })
        .collect();
    let mut other_end = vec![None; ends.len()];
    for g in groups.iter().filter(|g| g.len() == 2 && g[0].1 / 2 != g[1].1 / 2) {
        let (e0, e1) = (g[0].1 as usize, g[1].1 as usize);
        (other_end[e0], other_end[e1]) = (Some(e1), Some(e0));
    }
    let corner_at = |end: usize| -> Option<(Corner, bool)> {
        let (mine, theirs) = (normals[end / 2]?, normals[other_end[end]? / 2]?);
        let (at, far) = (cone(end)?, cone(end ^ 1)?);
        let beyond = cone(other_end[end]? ^ 1)?.centre;
        // Both lines stand for their edges only as far as the edges run: the footprint about
        // the corner may not reach past either's other end.
        let reach = CORNER_REACH * at.axes.col(0).length().max(at.axes.col(1).length());
        let long = (far.centre - at.centre).length() >= reach && (beyond - at.centre).length() >= reach;
        (long && mine.perp_dot(theirs).abs() > MIN_TURN).then(|| {
            let corner = Corner { at: at.centre.into(), neighbour: theirs.into(), axes: at.axes.to_cols_array() };
            (corner, theirs.dot(far.centre - at.centre) < 0.0)
        })
    };
    // Once per end: the end's edge and its vertex's wedges both take it.
    let corners: Vec<Option<(Corner, bool)>> = (0..ends.len()).into_par_iter().map(corner_at).collect();
    // Chunks of edges, then of vertices, in parallel (rayon), put together in order.
    let parts: Vec<(PlateauGeometry, Vec<Covers>)> = edges
        .par_chunks(PARALLEL_CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            let mut out = PlateauGeometry::default();
            let mut covers = Vec::with_capacity(2 * chunk.len());
            for j in 0..chunk.len() {
                let i = c * PARALLEL_CHUNK + j;
                let (Some(ca), Some(cb), Some(normal)) = (cone(2 * i), cone(2 * i + 1), normals[i]) else {
                    covers.extend([[None; 2]; 2]);
                    continue;
                };
                let corners = [corners[2 * i], corners[2 * i + 1]];
                covers.extend(edge_sheets(&mut out, light.penumbra, (ca, cb), normal, corners, number));
            }
            (out, covers)
        })
        .collect();
    let mut out = PlateauGeometry::default();
    let mut covers = Vec::with_capacity(ends.len());
    for (g, c) in parts {
        out.extend(&g);
        covers.extend(c);
    }
    let covers = &covers;
    let wedges: Vec<PlateauGeometry> = groups
        .par_chunks(PARALLEL_CHUNK)
        .map(|chunk| {
            let mut out = PlateauGeometry::default();
            let (mut arcs, mut gaps) = (Vec::new(), Vec::new());
            for group in chunk {
                let end = group[0].1 as usize;
                let Some(cone) = cone(end) else { continue };
                out.grow(cone.centre);
                let covered = group.iter().flat_map(|(_, end)| covers[*end as usize]).flatten();
                // The corner seen from its first edge: both normals, and the turn.
                let corner = corners[end].and_then(|(c, convex)| {
                    Some(WedgeCorner { normals: (normals[end / 2]?, c.neighbour.into()), convex })
                });
                vertex_wedges(&mut out, &cone, light, covered, (&mut arcs, &mut gaps), (number, corner));
            }
            out
        })
        .collect();
    wedges.iter().for_each(|g| out.extend(g));
    // Heights are affine in object space: h(model·p) = up·p + base, no vertex transformed.
    let up = model.transpose().transform_vector3(plane.normal);
    let base = plane.height(model.transform_point3(Vec3::ZERO));
    let reach = plane.height(light.position) * (1.0 - ABOVE_LIGHT) - base;
    out.unbounded = caster.positions.par_iter().any(|p| up.dot(*p) >= reach);
    if source == EdgeSource::LightFacing {
        // Lit edges alone need not bound an open mesh's shadow: its back faces cast too.
        for q in (0..caster.positions.len() as u32).filter_map(|v| plane.project(light.position, world(v))) {
            out.grow(q);
        }
    }
    out
}

/// Edges, or vertices, per parallel task: enough work to outweigh the task.
const PARALLEL_CHUNK: usize = 256;

/// What the sheets of an edge cover at its two ends, outer side then inner: from the end, the
/// directions of the hard edge and of the tangent point (outer only, of the inner normal: the
/// hard shadow there is t = 0 whatever the sides hold).
type Covers = [Option<(Vec2, Vec2)>; 2];

/// How far (the sine of the angle) two edges must turn at a vertex for it to be a [`Corner`]
/// (or a smoothie's [`ShadowCorner`](super::smoothie::ShadowCorner)).
/// A finely tessellated curve turns less at each vertex, where the footprint cut by both lines
/// differs from the sheets' by at most about the turn over 2π, 0.003 (an estimate, not
/// measured).
pub const MIN_TURN: f32 = 0.02;

/// How many footprint radii (the cone's semi-major axis) each of a [`Corner`]'s edges must run
/// from it: a line that runs on past its edge's end, a radius or more, cuts the footprint where
/// the next edge does (a simplified mesh's short edges). Measured on default (the cow's shadow,
/// 512²): leaks past the reference by 0.1, 1056 px with no bound, 1041 at ½, 1046 at 1, 1044 at 2
/// (as without corners), where the sphere's corners were lost too (penumbra RMSE 0.0137 → 0.0163).
const CORNER_REACH: f32 = 0.5;

/// A corner as its wedges carry it: the outward normals of its two edges, and whether the
/// shadow is convex there.
#[derive(Clone, Copy, Debug)]
struct WedgeCorner {
    normals: (Vec2, Vec2),
    convex: bool,
}

/// The sheets of an edge between the cones of its ends, `normal` its outward normal, with the
/// corners at its ends (and whether the shadow is convex there), into `out`; what they cover at
/// each end.
fn edge_sheets(
    out: &mut PlateauGeometry,
    penumbra: Penumbra,
    (ca, cb): (Cone, Cone),
    normal: Vec2,
    corners: [Option<(Corner, bool)>; 2],
    number: f32,
) -> [Covers; 2] {
    let mut covers = [[None; 2]; 2];
    let convex = corners.map(|c| c.is_some_and(|c| c.1));
    let corners = corners.map(|c| c.map_or(Corner::default(), |c| c.0));
    let ab = cb.centre - ca.centre;
    for (k, side) in [normal, -normal].into_iter().enumerate() {
        let cover = if k == 0 || penumbra == Penumbra::Centred {
            let Some((ta, tb)) = outer_tangent(&ca, &cb, side) else { continue };
            let Some(sheet) = out.sheet(ca.centre, cb.centre, ta, tb, normal, number) else { continue };
            out.sheets.push(sheet.with_corners(corners, convex));
            (ta - ca.centre, tb - cb.centre)
        } else {
            (side, side)
        };
        covers[0][k] = Some((ab, cover.0));
        covers[1][k] = Some((-ab, cover.1));
    }
    covers
}

/// The unit normal of the hard edge between two cones' apices, away from `inside` (the
/// projected third vertex of the edge's light-facing triangle); seen edge-on from that triangle,
/// either side (the GPU probes both).
fn outward(ca: &Cone, cb: &Cone, inside: Vec2) -> Vec2 {
    let mid = 0.5 * (ca.centre + cb.centre);
    let along = (cb.centre - ca.centre).normalize_or_zero();
    let across = (mid - inside) - along * (mid - inside).dot(along);
    across.try_normalize().unwrap_or(along.perp())
}

/// Centred, the sheets of one caster's partial silhouettes (`edges`, from
/// [`partial_silhouettes`]), numbered `number`, each on the side away from its inner vertex and
/// sized by its own cones, where it gains [`PARTIAL_GAIN`] of its half width on what the
/// silhouette from the centre casts (about: the cone of the turned face's far vertex). Their
/// hard edges lie inside the hard shadow, where a face seen nearly edge-on from the light's
/// centre projects to a sliver beside the silhouette's. No cones at their ends: the silhouette's
/// cover the shadow's corners. Outer only, nothing: the paper's penumbra spans the whole width
/// outward, and its umbra the whole hard shadow.
///
/// - An edge whose faces the centre sees lit lies above the silhouette, nearer the light: for
///   the part of the light behind its turned face it is the silhouette, with the wider penumbra.
///   Its sheet runs outward, and goes to `partial`, drawn only where the hard shadow is lit,
///   where it darkens only: t is its distance from the edge in its half widths, which near the
///   silhouette exceeds the silhouette's own and further out, where the wider penumbra still
///   reaches, is the smaller (`low_light`'s box).
/// - An edge whose faces the centre sees unlit lies below it, nearer the receiver: for the part
///   of the light in front of its turned face, the part a receiver inside the hard shadow still
///   sees, it is the silhouette, with the narrower penumbra. Its sheet runs inward and goes to
///   `partial_inner`, drawn only over its own caster's hard shadow and blended by max, so that
///   it only darkens there too. From such a receiver the silhouette's half plane lets through
///   more than the caster does (the caster reaches past it, to the lower edge), and the lower
///   edge is the caster's outline, exact where it runs straight across the light's footprint,
///   so the darkest of them is the nearest to the truth: a thick slab's inner half spans the
///   way from its top rim's hard edge to its bottom rim's umbra, narrower than the top rim's
///   alone.
///
/// [`partial_silhouettes`]: super::silhouette::partial_silhouettes
pub fn partial_sides(
    plane: &ReceiverPlane,
    light: &PlateauLight,
    caster: &Caster<'_>,
    model: &Mat4,
    edges: &[PartialEdge],
    number: f32,
) -> PlateauGeometry {
    let mut out = PlateauGeometry::default();
    if light.penumbra != Penumbra::Centred {
        return out;
    }
    let world = |v: u32| model.transform_point3(caster.positions[v as usize]);
    // A fine mesh has thousands of partial silhouettes, nearly all of them dropped: each vertex's
    // cone once, and an outward sheet's tangent only where the cones' reach leaves room for a
    // gain (the tangent's reach is at most the farther cone's); an inward sheet's tangent may
    // reach less than either cone, so it is always found.
    let mut vertices: Vec<u32> = edges.iter().flat_map(|e| [e.vertices[0], e.vertices[1], e.turned]).collect();
    vertices.sort_unstable();
    vertices.dedup();
    let cones: Vec<Option<Cone>> =
        vertices.par_iter().map(|&v| vertex_cone(plane, light.position, light.radius, light.size, world(v))).collect();
    let cone = |v: u32| vertices.binary_search(&v).ok().and_then(|i| cones[i]);
    let sheets: Vec<_> = edges
        .par_iter()
        .filter_map(|edge| {
            let [a, b] = edge.vertices;
            let (ca, cb, cc) = (cone(a)?, cone(b)?, cone(edge.turned)?);
            let normal = outward(&ca, &cb, plane.project(light.position, world(edge.inner))?);
            // How far the turned vertex's cone reaches along the normal, and by how much the
            // edge's sheet, reaching `reach`, passes it: outward (lit) or short of it (unlit).
            let beyond = cc.support(normal);
            let gain = |reach: f32, half: f32| {
                let past = if edge.lit { reach - beyond } else { beyond - reach };
                past > PARTIAL_GAIN * half
            };
            let half = |c: &Cone| c.support(normal) - normal.dot(c.centre);
            if edge.lit && !gain(ca.support(normal).max(cb.support(normal)), half(&ca).max(half(&cb))) {
                return None;
            }
            let (ta, tb) = outer_tangent(&ca, &cb, normal)?;
            let [ra, rb] = [ta, tb].map(|t| normal.dot(t));
            let reach = if edge.lit { ra.max(rb) } else { ra.min(rb) };
            let widths = [(ta - ca.centre).dot(normal), (tb - cb.centre).dot(normal)];
            if !gain(reach, widths[0].max(widths[1])) {
                return None;
            }
            if edge.lit {
                return Some((ca.centre, cb.centre, ta, tb, normal, true));
            }
            // Past its umbra the edge still hides the whole light, as far as the silhouette's
            // inner half reaches (about `beyond`): the sheet drawn `k` times as wide, t scaled
            // back by k and held at 1 there, k in the normal's length (penumbra.frag).
            let k = [(ca.centre, widths[0]), (cb.centre, widths[1])]
                .map(|(c, w)| (beyond - normal.dot(c)) / w)
                .into_iter()
                .fold(1.0, f32::max)
                .min(MAX_INNER_REACH);
            let (a, b) = (ca.centre, cb.centre);
            Some((a, b, a + (ta - a) * k, b + (tb - b) * k, normal * k, false))
        })
        .collect();
    for (a, b, ta, tb, normal, lit) in sheets {
        if let Some(sheet) = out.sheet(a, b, ta, tb, normal, number) {
            if lit {
                out.partial.push(sheet)
            } else {
                out.partial_inner.push(sheet)
            };
        }
    }
    out
}

/// The parts of a vertex's cone that none of the sheets there cover (`covered`: sectors from
/// the apex, see [`Covers`]), into `out`; `scratch`: reused arc lists.
fn vertex_wedges(
    out: &mut PlateauGeometry,
    cone: &Cone,
    light: &PlateauLight,
    covered: impl Iterator<Item = (Vec2, Vec2)>,
    (arcs, gaps): (&mut Arcs, &mut Arcs),
    (number, corner): (f32, Option<WedgeCorner>),
) {
    // A point or a flat base has no area to draw (and no rim angles).
    if cone.axes.determinant() <= 0.0 {
        return;
    }
    arcs.clear();
    gaps.clear();
    if light.wedges {
        let inverse = cone.axes.inverse();
        for (from, to) in covered {
            // Anticlockwise from one side of the sector to the other; a flat sector covers nothing.
            let (from, to) = if from.perp_dot(to) >= 0.0 { (from, to) } else { (to, from) };
            if from.perp_dot(to) <= 1e-6 * from.length() * to.length() {
                continue;
            }
            let start = cone.rim_angle(inverse, from);
            arcs.push((start.rem_euclid(TAU), (cone.rim_angle(inverse, to) - start).rem_euclid(TAU)));
        }
    }
    let overlap = if arcs.is_empty() { 0.0 } else { WEDGE_OVERLAP };
    uncovered(arcs, gaps);
    for &(from, to) in gaps.iter() {
        out.push_wedge(cone, (from - overlap, to + overlap), number, corner);
    }
}

/// Arcs of rim angles, (start, length) or (from, to).
type Arcs = Vec<(f32, f32)>;

/// Radians by which a corner wedge overlaps the sheets beside it: no crack between them
/// (their shared side is the same line, computed two ways).
const WEDGE_OVERLAP: f32 = 1e-3;

/// The arcs of the circle of angles that none of `arcs` (start in [0, 2π), length) covers,
/// as (from, to) with from < to, into `gaps`; all of it when `arcs` is empty.
fn uncovered(arcs: &mut [(f32, f32)], gaps: &mut Arcs) {
    arcs.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
    let Some(&(first, length)) = arcs.first() else {
        gaps.push((0.0, TAU));
        return;
    };
    let mut end = first + length;
    for &(start, length) in &arcs[1..] {
        if start > end {
            gaps.push((end, start));
        }
        end = end.max(start + length);
    }
    if end < first + TAU {
        gaps.push((end, first + TAU));
    }
}

/// Boundary edges of back-facing triangles, with their third vertex (the shadow's side): an
/// open mesh's back faces cast shadow too, out to their own boundary.
fn unlit_boundary_edges<'a>(caster: &'a Caster<'_>, facing: &'a [bool]) -> impl Iterator<Item = ([u32; 2], u32)> + 'a {
    caster.adjacency.edges.iter().filter(|e| e.is_boundary() && !facing[e.faces[0] as usize]).map(|e| {
        let third = caster.triangles[e.faces[0] as usize].into_iter().find(|v| !e.vertices.contains(v));
        (e.vertices, third.unwrap_or(e.vertices[0]))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::EdgeAdjacency;
    use crate::geometry::silhouette::{FacePlanes, TestMesh};
    use proptest::prelude::*;

    fn circle(x: f32, y: f32, r: f32) -> Cone {
        Cone { centre: Vec2::new(x, y), offset: Vec2::ZERO, axes: Mat2::from_diagonal(Vec2::splat(r)) }
    }

    /// Two cone radii in `min..2`: equal in a third of the cases (a plate parallel to the plane,
    /// every sheet flat), which two independent draws would essentially never give.
    fn radii(min: f32) -> impl Strategy<Value = (f32, f32)> {
        prop_oneof![
            1 => (min..2.0f32).prop_map(|r| (r, r)),
            2 => (min..2.0f32, min..2.0f32),
        ]
    }

    /// Distance from `p` to the line through `a` and `b`.
    fn line_distance(p: Vec2, a: Vec2, b: Vec2) -> f32 {
        ((b - a).perp_dot(p - a) / (b - a).length()).abs()
    }

    proptest! {
        #[test]
        fn the_blinn_matrix_is_the_projection(
            p in (-5.0f32..5.0, 0.0f32..4.0, -5.0f32..5.0),
            l in (-5.0f32..5.0, 5.0f32..20.0, -5.0f32..5.0),
        ) {
            let plane = ReceiverPlane::ground(0.5);
            let (p, l) = (Vec3::from(p), Vec3::from(l));
            let h = plane.shadow_matrix(l) * p.extend(1.0);
            match plane.project(l, p) {
                Some(q) => {
                    prop_assert!(h.w > 0.0);
                    prop_assert!((Vec2::new(h.x, h.y) / h.w - q).length() < 1e-3 * (1.0 + q.length()));
                }
                None => prop_assert!(h.w <= 1e-3 * l.y),
            }
        }

        #[test]
        fn outer_tangents_touch_both_circles(
            (r0, r1) in radii(0.0), d in 0.01f32..6.0, angle in 0.0f32..std::f32::consts::TAU,
        ) {
            let a = circle(0.3, -0.2, r0);
            let b = circle(0.3 + d * angle.cos(), -0.2 + d * angle.sin(), r1);
            let outward = (b.centre - a.centre).perp();
            let tangent = outer_tangent(&a, &b, outward);
            if d <= (r0 - r1).abs() * 0.999 {
                prop_assert!(tangent.is_none(), "one circle holds the other: no outer tangent");
            } else if d > (r0 - r1).abs() * 1.001 + 1e-3 {
                let (ta, tb) = tangent.expect("separate circles have outer tangents");
                prop_assert!(ta.is_finite() && tb.is_finite());
                prop_assert!(((ta - a.centre).length() - r0).abs() < 1e-3 * (1.0 + r0));
                prop_assert!(((tb - b.centre).length() - r1).abs() < 1e-3 * (1.0 + r1));
                if (tb - ta).length() > 1e-2 {
                    // The line is tangent to both: each centre is one radius away from it.
                    prop_assert!((line_distance(a.centre, ta, tb) - r0).abs() < 2e-3 * (1.0 + d));
                    prop_assert!((line_distance(b.centre, ta, tb) - r1).abs() < 2e-3 * (1.0 + d));
                }
                // On the outward side.
                prop_assert!((ta - a.centre).dot(outward) >= -1e-4);
                if r0 == r1 {
                    // Equal circles: the tangent runs parallel to the centre line, one radius
                    // out, touching each circle straight across from its centre.
                    let normal = (b.centre - a.centre).perp().normalize() * (b.centre - a.centre).perp().dot(outward).signum();
                    prop_assert!((ta - (a.centre + r0 * normal)).length() < 1e-4 * (1.0 + r0), "{ta} vs {}", a.centre + r0 * normal);
                    prop_assert!((tb - (b.centre + r1 * normal)).length() < 1e-4 * (1.0 + r1), "{tb} vs {}", b.centre + r1 * normal);
                }
            }
        }

        /// The inverse map (what penumbra.frag does per fragment) finds, at every point of a
        /// patch, a root of the patch there and none lower than the point's own t; the hull the
        /// GPU draws holds the whole patch. Random corners, so folded and triangular hulls too.
        #[test]
        fn sheets_invert_their_bilinear_map_inside_their_hull(
            corners in prop::array::uniform4((-2.0f32..2.0, -2.0f32..2.0)),
            s in 0.0f32..=1.0, t in 0.0f32..=1.0,
        ) {
            let [a, b, tb, ta] = corners.map(Vec2::from);
            prop_assume!((b - a).length() > 0.05 && (ta - a).length() > 0.05 && (tb - b).length() > 0.05);
            let sheet = Sheet::new(a, b, ta, tb, Vec2::Y, 1.0);
            let p = sheet.point(s, t);
            prop_assert!(in_triangles(&sheet.hull_points(), p), "{p} (s {s}, t {t}) outside the hull");
            let (found, at) = sheet.at(p).expect("a point of the patch has a root");
            // Above the point's own t only as far as f32 can tell them apart: near a fold line
            // the patch barely moves with t, so there both map to p.
            let apart = (sheet.point(at, found) - sheet.point(at, t)).length();
            prop_assert!(found <= t + 1e-3 || apart < 2e-3 * (1.0 + p.length()), "t {found} above the point's own {t}");
            let back = sheet.point(at, found);
            prop_assert!((back - p).length() < 2e-3 * (1.0 + p.length()), "({at}, {found}) maps to {back}, not {p}");
        }

        /// A sheet cut into pieces is the same patch: a point of the whole at (s, t) lies in
        /// the piece over s, at the same t, and inside that piece's hull.
        #[test]
        fn sheets_cut_into_pieces_keep_their_patch(
            corners in prop::array::uniform4((-2.0f32..2.0, -2.0f32..2.0)),
            n in 1u32..9, s in 0.0f32..=1.0, t in 0.0f32..=1.0,
        ) {
            let [a, b, tb, ta] = corners.map(Vec2::from);
            let sheet = Sheet::new(a, b, ta, tb, Vec2::Y, 3.0);
            let pieces: Vec<Sheet> = sheet.pieces(n).collect();
            prop_assert_eq!(pieces.len(), n as usize);
            let k = ((s * n as f32) as usize).min(n as usize - 1);
            let piece = &pieces[k];
            let local = s * n as f32 - k as f32;
            let (whole, part) = (sheet.point(s, t), piece.point(local, t));
            prop_assert!((whole - part).length() < 1e-4 * (1.0 + whole.length()), "{whole} vs {part}");
            prop_assert!(in_triangles(&piece.hull_points(), whole), "{whole} outside piece {k}'s hull");
            prop_assert_eq!((piece.normal, piece.caster), (sheet.normal, sheet.caster));
            // The pieces join: each starts where the last ended.
            for w in pieces.windows(2) {
                prop_assert!((Vec2::from(w[0].b) - Vec2::from(w[1].a)).length() < 1e-5 * (1.0 + whole.length()));
                prop_assert!((Vec2::from(w[0].tb) - Vec2::from(w[1].ta)).length() < 1e-5 * (1.0 + whole.length()));
            }
        }

        /// A wedge's t is exact: the point a fraction t of the way from the apex to the rim at
        /// any angle of the piece has t, inside the outline the GPU draws; beyond the rim t > 1.
        /// Cones of a low and a high light.
        #[test]
        fn wedges_give_the_exact_cone_inside_their_outline(
            light in (-8.0f32..8.0, 1.5f32..9.0, -8.0f32..8.0),
            (from, span) in (0.0f32..TAU, 0.01f32..WEDGE_SPAN),
            (f, t) in (0.0f32..=1.0, 0.0f32..=1.0),
        ) {
            let plane = ReceiverPlane::ground(0.0);
            let cone = vertex_cone(&plane, Vec3::from(light), 0.5, PenumbraSize::Physical { scale: 1.0 }, Vec3::new(0.3, 1.0, -0.2));
            let cone = cone.unwrap();
            let mut g = PlateauGeometry::default();
            g.push_wedge(&cone, (from, from + span), 1.0, None);
            prop_assert_eq!(g.cones.len(), 1);
            let wedge = g.cones[0];
            let rim = rim(&cone, from + f * span);
            let p = cone.centre.lerp(rim, t);
            let scale = 1.0 + p.length();
            prop_assert!(in_triangles(&wedge.outline(), p), "{p} outside the wedge's outline");
            prop_assert!((wedge.t_at(p) - t).abs() < 1e-3 * scale, "t {} at {t} of the way", wedge.t_at(p));
            let beyond = cone.centre.lerp(rim, 1.2);
            prop_assert!(wedge.t_at(beyond) > 1.0 + 1e-3);
        }

        #[test]
        fn the_rim_angles_atan2_is_libms_within_1e_5(angle in -std::f32::consts::PI..std::f32::consts::PI, r in 1e-3f32..1e3) {
            let (y, x) = (r * angle.sin(), r * angle.cos());
            prop_assert!((atan2(y, x) - y.atan2(x)).abs() < 1e-5, "{} vs {}", atan2(y, x), y.atan2(x));
        }

        #[test]
        fn silhouettes_of_a_closed_mesh_form_closed_loops(l in (-6.0f32..6.0, 2.0f32..12.0, -6.0f32..6.0)) {
            let (sphere, triangles) = crate::geometry::shapes::sphere(1.0);
            let adjacency = EdgeAdjacency::build(&triangles);
            // A light outside the sphere (centre (0, 1.5, 0), radius 1) sees a silhouette.
            prop_assume!((Vec3::from(l) - Vec3::Y * 1.5).length() > 1.1);
            let caster = Caster { positions: &sphere, triangles: &triangles, adjacency: &adjacency };
            let model = Mat4::from_translation(Vec3::Y * 1.5);
            let facing = FacePlanes::new(&sphere, &triangles).light_facing(&model, Vec3::from(l));
            let edges = plateau_edges(&caster, &facing, EdgeSource::Silhouettes);
            prop_assert!(!edges.is_empty());
            let mut degree = vec![0; sphere.len()];
            for ([a, b], inner) in &edges {
                degree[*a as usize] += 1;
                degree[*b as usize] += 1;
                prop_assert!(*inner != *a && *inner != *b);
            }
            prop_assert!(degree.iter().all(|d| d % 2 == 0), "every silhouette vertex joins an even number of edges");
        }
    }

    /// The base's rim at angle φ: centre + offset + axes·(cos φ, sin φ) (the wedges' angles).
    fn rim(cone: &Cone, angle: f32) -> Vec2 {
        cone.centre + cone.offset + cone.axes * Vec2::from_angle(angle)
    }

    /// Whether `p` lies in one of the triangles `points` holds three by three (a little slack).
    fn in_triangles(points: &[Vec2], p: Vec2) -> bool {
        points.chunks(3).any(|t| {
            let area = (t[1] - t[0]).perp_dot(t[2] - t[0]);
            let w = [(t[1] - p).perp_dot(t[2] - p), (t[2] - p).perp_dot(t[0] - p), (t[0] - p).perp_dot(t[1] - p)];
            let slack = 1e-4 * area.abs().max(1e-6);
            area != 0.0 && w.iter().all(|w| w * area.signum() >= -slack)
        })
    }

    /// The sides of a caster in object space placed by `model`, from its face planes, as the
    /// technique builds them.
    /// A light of `radius` at `position`, its penumbrae of the physical size, cones as wedges.
    fn physical(position: Vec3, radius: f32, penumbra: Penumbra) -> PlateauLight {
        PlateauLight { position, radius, size: PenumbraSize::Physical { scale: 1.0 }, penumbra, wedges: true }
    }

    fn sides(light: &PlateauLight, caster: &Caster<'_>, model: &Mat4, number: f32) -> PlateauGeometry {
        let facing = FacePlanes::new(caster.positions, caster.triangles).light_facing(model, light.position);
        let edges = plateau_edges(caster, &facing, EdgeSource::Silhouettes);
        plateau_sides(&ReceiverPlane::ground(0.0), light, caster, model, &edges, EdgeSource::Silhouettes, number)
    }

    /// Calls `f` with each centre of a `cells`² grid over [lo, hi] inside the triangle `tri`.
    fn raster(tri: [Vec2; 3], (lo, hi): (Vec2, Vec2), cells: usize, mut f: impl FnMut(usize, Vec2, [f32; 3])) {
        let cell = (hi - lo) / cells as f32;
        let p = tri.map(|v| (v - lo) / cell);
        let area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
        if area.abs() < 1e-12 {
            return;
        }
        let (min, max) = (p[0].min(p[1]).min(p[2]), p[0].max(p[1]).max(p[2]));
        for y in (min.y.floor().max(0.0) as usize)..(max.y.ceil().min(cells as f32) as usize) {
            for x in (min.x.floor().max(0.0) as usize)..(max.x.ceil().min(cells as f32) as usize) {
                let q = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
                let w = [(p[1] - q).perp_dot(p[2] - q), (p[2] - q).perp_dot(p[0] - q), (p[0] - q).perp_dot(p[1] - q)]
                    .map(|w| w / area);
                if w.iter().all(|w| *w >= -1e-6) {
                    f(y * cells + x, lo + q * cell, w);
                }
            }
        }
    }

    /// The plateau texture as the GPU draws these primitives: per cell of a `cells`² grid over
    /// `bounds`, the smallest t of any wedge or sheet whose drawn triangles hold the cell's
    /// centre and that has a root there (1 where none does).
    fn plateau_field(g: &PlateauGeometry, bounds: (Vec2, Vec2), cells: usize) -> Vec<f32> {
        let mut field = vec![1.0f32; cells * cells];
        for wedge in &g.cones {
            for tri in wedge.outline().chunks(3) {
                raster([tri[0], tri[1], tri[2]], bounds, cells, |i, p, _| field[i] = field[i].min(wedge.t_at(p)));
            }
        }
        for sheet in &g.sheets {
            for tri in sheet.hull_points().chunks(3) {
                raster([tri[0], tri[1], tri[2]], bounds, cells, |i, p, _| {
                    if let Some((t, _)) = sheet.at(p) {
                        field[i] = field[i].min(t);
                    }
                });
            }
        }
        field
    }

    /// The smallest t of Gouraud triangles (points and t, three by three) per cell: what min
    /// blending of a tessellation draws.
    fn tessellated_field(triangles: &[(Vec2, f32)], bounds: (Vec2, Vec2), cells: usize) -> Vec<f32> {
        let mut field = vec![1.0f32; cells * cells];
        for tri in triangles.chunks(3) {
            raster([tri[0].0, tri[1].0, tri[2].0], bounds, cells, |i, _, w| {
                field[i] = field[i].min(w[0] * tri[0].1 + w[1] * tri[1].1 + w[2] * tri[2].1)
            });
        }
        field
    }

    /// The paper's construction (§2, Figure 4), independent of the primitives: a sheet as an
    /// n × n grid of Gouraud quads, a cone as a fan of n flat triangles.
    fn tessellate_sheet(s: &Sheet, n: usize) -> Vec<(Vec2, f32)> {
        let at = |i: usize, j: usize| {
            let (u, t) = (i as f32 / n as f32, j as f32 / n as f32);
            (s.point(u, t), t)
        };
        let quads = (0..n).flat_map(|i| (0..n).map(move |j| (i, j)));
        quads
            .flat_map(|(i, j)| [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j), at(i + 1, j + 1), at(i, j + 1)])
            .collect()
    }

    fn tessellate_cone(cone: &Cone, n: usize) -> Vec<(Vec2, f32)> {
        let rim = |k: usize| (rim(cone, TAU * k as f32 / n as f32), 1.0);
        (0..n).flat_map(|k| [(cone.centre, 0.0), rim(k), rim(k + 1)]).collect()
    }

    /// Issue 18: the analytic primitives draw the plateau of the paper's tessellation, finely
    /// cut: sheets (tilted plate, low light: twisted; a knot's folds) and whole cones within
    /// 1/255 of t wherever both cover, over the same cells but for their rims.
    #[test]
    fn analytic_sides_draw_the_finely_tessellated_plateau() {
        let shapes =
            [crate::geometry::shapes::cuboid(Vec3::new(2.0, 0.1, 2.0)), crate::geometry::shapes::torus_knot(600)];
        for (shape, (mesh, triangles)) in shapes.iter().enumerate() {
            let adjacency = EdgeAdjacency::build(triangles);
            let model = Mat4::from_translation(Vec3::Y * 1.6) * Mat4::from_rotation_x(0.4);
            let caster = Caster { positions: mesh, triangles, adjacency: &adjacency };
            for position in [Vec3::new(0.5, 8.0, 0.3), Vec3::new(-6.0, 3.0, 2.0)] {
                let light = PlateauLight { wedges: false, ..physical(position, 0.6, Penumbra::Centred) };
                let g = sides(&light, &caster, &model, 1.0);
                let bounds = g.footprint.unwrap();
                let cells = 200;
                let mut vertices: Vec<u32> = edges_of(&light, &caster, &model).iter().flat_map(|(e, _)| *e).collect();
                vertices.sort_unstable();
                vertices.dedup();
                let cone = |v: &u32| {
                    let p = model.transform_point3(mesh[*v as usize]);
                    vertex_cone(&ReceiverPlane::ground(0.0), position, light.radius, light.size, p).unwrap()
                };
                // Primitive by primitive, against its own tessellation: each pair of fields over
                // the cells either covers.
                let sheets = g.sheets.iter().map(|s| {
                    let one = PlateauGeometry { sheets: vec![*s], ..Default::default() };
                    (plateau_field(&one, bounds, cells), tessellated_field(&tessellate_sheet(s, 48), bounds, cells))
                });
                let whole_cones = vertices.iter().map(cone).filter(|c| c.axes.determinant() > 0.0);
                let mut pieces = PlateauGeometry::default();
                let cones = whole_cones.map(|c| {
                    pieces.cones.clear();
                    pieces.push_wedge(&c, (0.0, TAU), 1.0, None);
                    (plateau_field(&pieces, bounds, cells), tessellated_field(&tessellate_cone(&c, 720), bounds, cells))
                });
                for (what, pairs) in [("sheets", sheets.collect::<Vec<_>>()), ("cones", cones.collect())] {
                    let (mut worst, mut covered, mut one_only) = (0.0f32, 0, 0);
                    for (got, want) in &pairs {
                        for (g, w) in got.iter().zip(want) {
                            match (*g < 1.0, *w < 1.0) {
                                (true, true) => (worst, covered) = (worst.max((g - w).abs()), covered + 1),
                                (false, false) => {}
                                _ => one_only += 1,
                            }
                        }
                    }
                    let case = format!("shape {shape}, light {position}, {what}");
                    assert!(covered > 1000, "{case}: {covered} cells");
                    assert!(worst <= 1.0 / 255.0, "{case}: t differs by {worst}");
                    // Cells on the sides and rims, where a centre lies on the line or t nears 1.
                    assert!(one_only * 20 <= covered, "{case}: {one_only} of {covered} cells covered by one alone");
                }
            }
        }
    }

    /// The penumbra edges of a caster in object space, from its face planes.
    fn edges_of(light: &PlateauLight, caster: &Caster<'_>, model: &Mat4) -> Vec<([u32; 2], u32)> {
        let facing = FacePlanes::new(caster.positions, caster.triangles).light_facing(model, light.position);
        plateau_edges(caster, &facing, EdgeSource::Silhouettes)
    }

    /// Issue 18: corner wedges and sheets give the plateau whole cones and sheets give (Haines
    /// §2), within 1/255 of t (and so of V, whose slope in t is at most 2/π) at 99% of the
    /// penumbra's points, on a tilted plate, a sphere, a box and a torus knot, under a high and a
    /// low light, centred and outer only (there, outside the hard shadow: inside it the resolve
    /// makes t 0).
    #[test]
    fn corner_wedges_draw_the_plateau_of_whole_cones() {
        let shapes = [
            crate::geometry::shapes::cuboid(Vec3::new(2.0, 0.1, 2.0)),
            crate::geometry::shapes::sphere(0.8),
            crate::geometry::shapes::cuboid(Vec3::new(1.0, 1.4, 0.6)),
            crate::geometry::shapes::torus_knot(2000),
        ];
        let plane = ReceiverPlane::ground(0.0);
        for (shape, (mesh, triangles)) in shapes.iter().enumerate() {
            let adjacency = EdgeAdjacency::build(triangles);
            let tilt = Mat4::from_translation(Vec3::Y * 1.6) * Mat4::from_rotation_x(0.4);
            let caster = Caster { positions: mesh, triangles, adjacency: &adjacency };
            for (position, penumbra) in [
                (Vec3::new(0.5, 8.0, 0.3), Penumbra::Centred),
                (Vec3::new(-6.0, 4.0, 2.0), Penumbra::Centred),
                (Vec3::new(0.5, 8.0, 0.3), Penumbra::Outer),
            ] {
                let light = physical(position, 0.6, penumbra);
                let wedged = sides(&light, &caster, &tilt, 1.0);
                // Whole cones on request: a full turn at every penumbra vertex.
                let whole = sides(&PlateauLight { wedges: false, ..light }, &caster, &tilt, 1.0);
                assert_eq!(wedged.sheets, whole.sheets);
                let bounds = wedged.footprint.unwrap();
                let cells = 160;
                let sheets = plateau_field(
                    &PlateauGeometry { sheets: wedged.sheets.clone(), ..Default::default() },
                    bounds,
                    cells,
                );
                let field = |g: &PlateauGeometry| {
                    plateau_field(&PlateauGeometry { cones: g.cones.clone(), ..Default::default() }, bounds, cells)
                };
                let (wedges, cones) = (field(&wedged), field(&whole));
                // Outer only, the hard shadow's texels do not count: the projected triangles.
                let mut shadow = vec![false; cells * cells];
                for t in triangles.iter() {
                    let tri = t.map(|v| plane.project(position, tilt.transform_point3(mesh[v as usize])).unwrap());
                    raster(tri, bounds, cells, |i, _, _| shadow[i] = true);
                }
                let (mut worst, mut off, mut penumbra_cells) = (0.0f32, 0, 0);
                for i in 0..cells * cells {
                    let t = cones[i].min(sheets[i]);
                    if penumbra == Penumbra::Outer && shadow[i] || t == 1.0 {
                        continue;
                    }
                    let d = (wedges[i].min(sheets[i]) - t).abs();
                    (worst, off, penumbra_cells) = (worst.max(d), off + (d > 1.0 / 255.0) as usize, penumbra_cells + 1);
                }
                // The Coons sheet is the cones' envelope only up to its bilinear twist: where the
                // radius changes fast along an edge, the cones dip a little under it near their
                // apexes (t by up to 3.5/255 on the tilted plate, 9/255 on the knot's folds).
                let what = format!("shape {shape}, light {position}, {penumbra:?}");
                assert!(worst <= 10.0 / 255.0, "{what}: t differs by {worst}");
                assert!(
                    off * 100 <= penumbra_cells,
                    "{what}: {off} of {penumbra_cells} penumbra cells differ by over 1/255"
                );
                // And the wedges are a fraction of the cones.
                let (a, b) = (wedged.cones.len(), whole.cones.len());
                assert!(a * 2 < b, "shape {shape}: {a} of {b}");
            }
        }
    }

    /// The narrowest penumbra a texture must resolve (the technique's `penumbra_texels`): under
    /// a light overhead a level slab's silhouette is its top face's rim, whose half width is
    /// R·h/(H − h) at height h; a slab tilted onto the ground touches it, where the width is 0.
    #[test]
    fn the_narrowest_half_width_is_the_lowest_silhouettes() {
        let (slab, triangles) = crate::geometry::shapes::cuboid(Vec3::new(2.0, 0.1, 2.0));
        let adjacency = EdgeAdjacency::build(&triangles);
        let caster = Caster { positions: &slab, triangles: &triangles, adjacency: &adjacency };
        let light = physical(Vec3::Y * 9.0, 0.5, Penumbra::Centred);
        for height in [0.3f32, 1.0, 4.0] {
            let g = sides(&light, &caster, &Mat4::from_translation(Vec3::Y * height), 1.0);
            let rim = height + 0.05;
            let want = 0.5 * rim / (9.0 - rim);
            let got = g.narrowest_half_width();
            assert!((got - want).abs() < 0.02 * want, "at {height} m: {got}, want {want}");
        }
        // A plate tilted by 0.5 rad about its middle, raised until its low edge meets the ground.
        let (plate, triangles) = crate::geometry::shapes::cuboid(Vec3::new(2.0, 0.0, 2.0));
        let adjacency = EdgeAdjacency::build(&triangles);
        let caster = Caster { positions: &plate, triangles: &triangles, adjacency: &adjacency };
        let tilted = Mat4::from_translation(Vec3::Y * 0.5f32.sin()) * Mat4::from_rotation_z(0.5);
        let g = sides(&light, &caster, &tilted, 1.0);
        assert!(g.narrowest_half_width() < 1e-4, "touching the ground: {}", g.narrowest_half_width());
        assert_eq!(PlateauGeometry::default().narrowest_half_width(), f32::INFINITY);
    }

    /// A thick slab (0.6 m wide, 1.3 m tall from 1 m up, 4 m long) under a light of radius
    /// 0.5 m 5 m straight above it: the sides' bottom rims, unlit from the centre and lit from
    /// the light's rim, are its partial silhouettes, and centred, their inner halves go inward
    /// from x = ±0.375 m (0.3·5/4) to their own umbra at ±0.25 m (half width 0.5·1/4), held to
    /// where the top rims' inner halves end, ±(0.556 − 0.426) m: k = 1.96. Outer only, none.
    #[test]
    fn a_thick_slab_s_bottom_rims_narrow_its_inner_halves() {
        let (slab, model) = TestMesh::thick_slab();
        let at = |penumbra| {
            let (ground, light) = (ReceiverPlane::ground(0.0), physical(Vec3::Y * 5.0, 0.5, penumbra));
            caster_sides(&ground, &light, (&slab.caster(), &slab.planes), &model, EdgeSource::Silhouettes, 2.0)
        };
        let outer = at(Penumbra::Outer);
        assert!(outer.partial.is_empty() && outer.partial_inner.is_empty());
        let centred = at(Penumbra::Centred);
        assert!(centred.partial.is_empty(), "nothing above the top rims: {:?}", centred.partial);
        assert_eq!(centred.partial_inner.len(), 2, "{:?}", centred.partial_inner);
        let (edge, umbra, held) = (0.3 * 5.0 / 4.0, 0.25, 0.3 * 5.0 / 2.7 - 0.5 * 2.3 / 2.7);
        for sheet in &centred.partial_inner {
            let k = Vec2::from(sheet.normal).length();
            assert!((k - (edge - held) / (edge - umbra)).abs() < 0.02 * k, "k {k}");
            for s in [0.1, 0.5, 0.9] {
                let x = |t: f32| sheet.point(s, t).x.abs();
                assert!((x(0.0) - edge).abs() < 1e-3, "the bottom rim's hard edge at {}", x(0.0));
                assert!((x(1.0 / k) - umbra).abs() < 0.01, "its umbra from {}", x(1.0 / k));
                assert!((x(1.0) - held).abs() < 0.01, "held to {}", x(1.0));
            }
            assert_eq!(sheet.caster, 2.0);
        }
    }

    /// A flat plate, cones of one radius: each corner's only wedge is its quarter turn, outside
    /// the hard shadow, centred or not.
    #[test]
    fn a_square_has_a_quarter_cone_at_each_corner() {
        let (cube, triangles) = crate::geometry::shapes::cuboid(Vec3::new(2.0, 0.1, 2.0));
        let adjacency = EdgeAdjacency::build(&triangles);
        let caster = Caster { positions: &cube, triangles: &triangles, adjacency: &adjacency };
        let model = Mat4::from_translation(Vec3::Y);
        let half = 9.0 / 7.95; // the top face (y = 1.05) casts the square |x|, |z| ≤ half
        // Haines' constant factor: circles, of one radius at one height.
        for penumbra in [Penumbra::Outer, Penumbra::Centred] {
            let light =
                PlateauLight { size: PenumbraSize::Haines { factor: 0.1 }, ..physical(Vec3::Y * 9.0, 0.5, penumbra) };
            let g = sides(&light, &caster, &model, 1.0);
            // 90° and the overlap past each side: one piece per corner.
            assert_eq!(g.cones.len(), 4, "{penumbra:?}: {} wedges", g.cones.len());
            let mut turned = 0.0;
            for w in &g.cones {
                let apex = Vec2::from(w.apex);
                assert!((apex.abs() - Vec2::splat(half)).abs().max_element() < 1e-3, "apexes at the corners");
                let middle = apex + Mat2::from_cols_array(&w.axes) * Vec2::from_angle(0.5 * (w.from + w.to));
                assert!(middle.abs().min_element() > half - 1e-3, "{penumbra:?}: a wedge outside the shadow");
                turned += w.to - w.from;
                // Each apex a convex corner of two perpendicular edges.
                let n = Vec2::from_slice(&w.normals[..2]).dot(Vec2::from_slice(&w.normals[2..]));
                assert!(w.at_corner() && w.convex == 1.0 && n.abs() < 1e-3, "{penumbra:?}: {w:?}");
            }
            let expected = 4.0 * (std::f32::consts::FRAC_PI_2 + 2.0 * WEDGE_OVERLAP);
            assert!((turned - expected).abs() < 1e-3, "{penumbra:?}: the wedges turn {turned}, not {expected}");
            // Every sheet ends at two convex corners, the other edge's normal across its own.
            for sheet in &g.sheets {
                let own = Vec2::from(sheet.normal);
                for (k, c) in sheet.corners.iter().enumerate() {
                    assert!(sheet.hull & CONVEX_BITS == CONVEX_BITS, "{penumbra:?}: a reflex corner");
                    assert!(Vec2::from(c.at).abs().distance(Vec2::splat(half)) < 1e-3, "corner {k} at {:?}", c.at);
                    assert!(own.dot(Vec2::from(c.neighbour)).abs() < 1e-3, "corner {k}'s neighbour {:?}", c.neighbour);
                }
            }
        }
    }

    /// Centred: every edge gets a second sheet on the inner side, mirror to the outer one, and
    /// every sheet measures t from its foot on the hard edge (t·radius away, flat plate).
    #[test]
    fn centred_sheets_straddle_the_hard_edge() {
        let (cube, triangles) = crate::geometry::shapes::cuboid(Vec3::new(2.0, 0.1, 2.0));
        let adjacency = EdgeAdjacency::build(&triangles);
        let caster = Caster { positions: &cube, triangles: &triangles, adjacency: &adjacency };
        let at =
            |penumbra| sides(&physical(Vec3::Y * 9.0, 0.5, penumbra), &caster, &Mat4::from_translation(Vec3::Y), 3.0);
        let (outer, centred) = (at(Penumbra::Outer), at(Penumbra::Centred));
        // A sheet more per edge.
        assert_eq!(centred.sheets.len(), 2 * outer.sheets.len());
        assert!(outer.sheets.iter().all(|v| centred.sheets.contains(v)));
        // The top face (y = 1.05) casts the square |x|, |z| ≤ 9/7.95; the radius is W/2
        // overhead, a few per cent more towards the corners (their cones lean out).
        let half = 9.0 / 7.95;
        let r = 0.5 * 1.05 / 7.95;
        let (mut inside, mut outside) = (0, 0);
        for sheet in &centred.sheets {
            for (s, t) in [(0.1, 0.3), (0.5, 0.9), (0.8, 0.6)] {
                let p = sheet.point(s, t);
                let (found, foot) = sheet.at(p).unwrap();
                let foot = Vec2::from(sheet.a).lerp(Vec2::from(sheet.b), foot);
                assert!((foot.abs().max_element() - half).abs() < 1e-3, "the foot {foot} lies on the hard edge");
                let d = (p - foot).length();
                assert!(d >= found * r * 0.99 - 1e-4 && d <= found * r * 1.06 + 1e-4, "t {found} at {d}");
                match p.abs().max_element() < half - 1e-4 {
                    true => inside += 1,
                    false => outside += 1,
                }
            }
            assert!((Vec2::from(sheet.normal).length() - 1.0).abs() < 1e-5 && sheet.caster == 3.0);
        }
        assert!(inside > 0 && outside > 0, "sheets on both sides: {inside} in, {outside} out");
    }

    #[test]
    fn cones_follow_the_light() {
        let plane = ReceiverPlane::ground(0.0);
        let size = PenumbraSize::Physical { scale: 1.0 };
        let p = Vec3::new(0.0, 1.0, 0.0);
        // Overhead: a circle of radius h·tan α = W/2.
        let overhead = vertex_cone(&plane, Vec3::new(0.0, 11.0, 0.0), 0.5, size, p).unwrap();
        let w = 2.0 * 0.5 * 1.0 / 10.0;
        for axis in [overhead.axes.col(0).length(), overhead.axes.col(1).length()] {
            assert!((axis - w / 2.0).abs() < 1e-3 * w, "{axis} vs {}", w / 2.0);
        }
        // Lower lights stretch the base away from the light; towards the horizon the stretch is
        // capped at 85° from the normal, so it stays finite.
        let first = overhead.axes.col(0).length();
        for elevation in [30.0f32, 5.0, 1.0] {
            let e = elevation.to_radians();
            let light = Vec3::new(-10.0 * e.cos(), 1.0 + 10.0 * e.sin(), 0.0);
            let cone = vertex_cone(&plane, light, 0.5, size, p).unwrap();
            let (major, minor) = (cone.axes.col(0), cone.axes.col(1));
            assert!(major.is_finite() && minor.is_finite() && cone.centre.is_finite());
            assert!(major.length() > first, "{elevation}°");
            assert!(major.length() <= MAX_TILT_TAN * p.y, "{elevation}°: capped");
            assert!(major.x.abs() > 0.99 * major.length(), "the major axis points along the light's azimuth");
            // The footprint reaches further beyond the projected vertex than short of it.
            let away = major.normalize();
            let (beyond, short) =
                (cone.support(away) - away.dot(cone.centre), cone.support(-away) + away.dot(cone.centre));
            assert!(beyond > short && short > 0.0, "{elevation}°: {beyond} beyond, {short} short");
        }
        // Touching the plane: a point; at or above the light: nothing.
        assert!(vertex_cone(&plane, Vec3::Y * 5.0, 0.5, size, Vec3::ZERO).unwrap().is_point());
        assert!(vertex_cone(&plane, Vec3::Y * 5.0, 0.5, size, Vec3::Y * 5.0).is_none());
        assert!(vertex_cone(&plane, Vec3::Y * 5.0, 0.5, size, Vec3::Y * 6.0).is_none());
        // Haines' constant factor: radius = factor × height.
        let haines = vertex_cone(&plane, Vec3::Y * 5.0, 0.5, PenumbraSize::Haines { factor: 0.1 }, p).unwrap();
        assert!((haines.axes.col(0).length() - 0.1).abs() < 1e-6);
    }

    /// Where the ray from `p` along `d` meets the ground, in its (u, v).
    fn ground_hit(p: Vec3, d: Vec3) -> Vec2 {
        let hit = p + d * (-p.y / d.y);
        Vec2::new(hit.x, hit.z)
    }

    #[test]
    fn a_cone_base_is_the_section_of_the_rays_to_the_light_sphere() {
        let plane = ReceiverPlane::ground(0.0);
        let p = Vec3::new(0.3, 1.2, -0.2);
        for elevation in [80.0f32, 45.0, 20.0, 12.0, 6.0, 3.0] {
            let e = elevation.to_radians();
            let light = p + Vec3::new(8.0 * e.cos(), 8.0 * e.sin(), 1.5 * e.cos());
            let cone = vertex_cone(&plane, light, 0.4, PenumbraSize::Physical { scale: 1.0 }, p).unwrap();
            let on_rim = |x: Vec2| (cone.axes.inverse() * (x - cone.centre - cone.offset)).length();
            // The cone of rays from p that graze the sphere, about the axis from the light.
            let axis = (p - light).normalize();
            let alpha = (0.4 / (p - light).length()).asin();
            let side = axis.cross(Vec3::Y).normalize();
            let up = side.cross(axis);
            let below_cap = (axis.y.abs().acos() + alpha).tan() < MAX_TILT_TAN;
            for k in 0..16 {
                let phi = k as f32 * TAU / 16.0;
                let ray = axis * alpha.cos() + (side * phi.cos() + up * phi.sin()) * alpha.sin();
                let sideways = k % 8 == 0;
                // Below the cap, the whole section; past it, the sideways rays still, which
                // set the penumbra's width along an edge that runs away from the light.
                if below_cap || sideways {
                    let r = on_rim(ground_hit(p, ray));
                    assert!((r - 1.0).abs() < 2e-3, "{elevation}°, ray {k}: at {r} of the rim");
                }
            }
        }
    }

    #[test]
    fn equal_radii_make_a_tangent_parallel_to_the_centre_line_and_one_flat_quad() {
        for r in [0.0, 0.05, 0.5, 1.0, 2.0] {
            for (i, angle) in [0.0f32, 0.7, 2.0, 3.9, 5.5].into_iter().enumerate() {
                let d = 0.5 + i as f32;
                let a = circle(-0.4, 1.3, r);
                let along = Vec2::from_angle(angle);
                let b = circle(-0.4 + d * along.x, 1.3 + d * along.y, r);
                for outward in [along.perp(), -along.perp()] {
                    let (ta, tb) = outer_tangent(&a, &b, outward).expect("equal circles apart have outer tangents");
                    // Straight across from each centre, one radius out on the outward side: the
                    // tangent is the centre line moved sideways by r.
                    let tol = 1e-4 * (1.0 + r);
                    assert!(
                        (ta - (a.centre + r * outward)).length() < tol,
                        "r {r}, {angle} rad: {ta} vs {}",
                        a.centre + r * outward
                    );
                    assert!(
                        (tb - (b.centre + r * outward)).length() < tol,
                        "r {r}, {angle} rad: {tb} vs {}",
                        b.centre + r * outward
                    );
                    assert!((tb - ta).perp_dot(along).abs() < tol, "not parallel to the centre line");
                    let sheet = PlateauGeometry::default().sheet(a.centre, b.centre, ta, tb, Vec2::Y, 1.0);
                    if r == 0.0 {
                        assert!(sheet.is_none(), "point bases: a hard edge, no sheet");
                        continue;
                    }
                    // No twist: a flat quad, t = 0 along the hard edge and 1 along the tangent,
                    // growing with the offset from it.
                    let sheet = sheet.unwrap_or_else(|| panic!("r {r}: one sheet"));
                    for (s, t) in [(0.2, 0.1), (0.5, 0.5), (0.9, 0.95)] {
                        let p = a.centre.lerp(b.centre, s) + outward * (t * r);
                        let (found, _) = sheet.at(p).expect("on the sheet");
                        assert!((found - t).abs() < tol / r.max(1e-3) + 1e-4, "r {r}: t {found} at {t} of the width");
                    }
                }
            }
        }
    }

    #[test]
    fn nearly_equal_radii_make_a_nearly_flat_sheet() {
        let (a, b) = (circle(0.0, 0.0, 1.0), circle(2.0, 0.0, 1.0 + 1e-6));
        let (ta, tb) = outer_tangent(&a, &b, Vec2::Y).unwrap();
        assert!((ta - Vec2::new(0.0, 1.0)).length() < 1e-4 && (tb - Vec2::new(2.0, 1.0)).length() < 1e-4);
        // A point base inside the other circle: no outer tangent, no sheet, no NaN.
        assert!(outer_tangent(&circle(0.0, 0.0, 2.0), &circle(0.5, 0.0, 0.0), Vec2::Y).is_none());
        assert!(outer_tangent(&circle(0.0, 0.0, 0.0), &circle(0.0, 0.0, 1.0), Vec2::Y).is_none());
    }
}
