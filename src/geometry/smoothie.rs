//! Chan & Durand's smoothies ("Rendering Fake Soft Shadows with Smoothies", 2003) as pure
//! geometry: at each silhouette edge a *smoothie edge*, the edge extended outward by t in the
//! light's screen space, and at each silhouette vertex a *smoothie corner* (§3, Figure 2).
//!
//! Everything is in the light view's tangent plane (x/z, y/z), where the spot frustum's window
//! is given. Each vertex carries the blocker's linear light depth b and shape coordinates whose
//! length is the linear alpha: 0 on the silhouette, 1 at t (edges: distance from the edge / t;
//! corners: |v − p| / t, Figure 6).
//!
//! Corners here are full squares of half-size t about the vertex with radial alpha, not the
//! paper's wedges between two edges: they cover every direction around the vertex, so the §3
//! special case (averaging normals at vertices with more than two silhouette edges) is never
//! needed, and minimum blending keeps the overlap with the edges continuous.
//!
//! Beyond the paper (issue 20): with [`Penumbra::Centred`] each edge also gets an *inner* quad,
//! the mirror of its smoothie edge over the blocker, so the penumbra straddles the hard edge as
//! the truth's does: the true penumbra of a straight edge spans (R/b)(1 − b/r) on *each* side
//! of the hard edge in the light's tangent plane (similar triangles through the edge from both
//! rims of the light). Inner vertices carry what the smoothie pass needs to accept them only
//! where the edge bounds this caster's own hard shadow (`glsl/smoothie/smoothie.frag`): the
//! point of the edge they belong to, its outward normal and the caster's light-depth range.
//! Inner corners are not needed: inside a convex corner the two edges' inner quads overlap, and
//! minimum blending keeps the darker, as the outer corners' squares already cover the outside.

use glam::{Mat4, Vec2, Vec3};

use super::Aabb;
use super::silhouette::{Caster, EdgeSource, Mailbox, light_facing, penumbra_edges};

/// Nearest light depth, relative to the caster's own, a vertex may have and still be drawn.
const MIN_DEPTH: f32 = 1e-6;

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
    /// Inner quads: the caster's light-depth range; (0, 0) marks the outer smoothies.
    pub near: f32,
    pub far: f32,
}

/// Which side of the hard edge the smoothies cover (the `penumbra` knob).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Penumbra {
    /// The paper's: outward only, the hard shadow all umbra (§3).
    Outer,
    /// Both sides: inner quads too, for a caster whose surfaces lie between light depths
    /// `near` and `far` (see [`depth_range`]).
    Centred { near: f32, far: f32 },
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
    /// How far any smoothie between `near` and `far` reaches (see [`smoothies`]).
    pub fn largest_reach(self, near: f32, far: f32) -> f32 {
        self.at(near) * reach(near, far)
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
}

impl SmoothieGeometry {
    pub fn extend(&mut self, other: &SmoothieGeometry) {
        self.edges.extend_from_slice(&other.edges);
        self.corners.extend_from_slice(&other.corners);
        self.inner.extend_from_slice(&other.inner);
    }

    pub fn is_empty(&self) -> bool {
        self.edges.is_empty() && self.corners.is_empty() && self.inner.is_empty()
    }

    /// Every vertex, in drawing order.
    pub fn vertices(&self) -> impl Iterator<Item = &SmoothieVertex> {
        self.edges.iter().chain(&self.corners).chain(&self.inner)
    }
}

/// The part of a smoothie at depth b that can matter: with the farthest receiver at `far`,
/// α' = α / (1 − b/r) is already 1 for every receiver once α ≥ 1 − b/far, so the smoothie is cut
/// there (its alpha unchanged). A far light then gets thin smoothies, not huge ones.
fn reach(b: f32, far: f32) -> f32 {
    (1.0 - b / far).clamp(0.0, 1.0)
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
    }
}

/// An inner-quad vertex at `p` belonging to the edge's point `foot`.
fn inner_vertex(p: Vec2, b: f32, alpha: f32, (foot, normal): (Vec2, Vec2), (near, far): (f32, f32)) -> SmoothieVertex {
    SmoothieVertex { fx: foot.x, fy: foot.y, nx: normal.x, ny: normal.y, near, far, ..vertex(p, b, Vec2::X * alpha) }
}

fn quad(out: &mut Vec<SmoothieVertex>, v: [SmoothieVertex; 4]) {
    out.extend([v[0], v[1], v[2], v[0], v[2], v[3]]);
}

/// The silhouette edges of a caster relative to the light at `light` (boundary edges of open
/// meshes count as silhouettes), each with the third vertex of its light-facing triangle.
pub fn silhouette(caster: &Caster<'_>, light: Vec3) -> Vec<([u32; 2], u32)> {
    penumbra_edges(caster, &light_facing(caster, light), EdgeSource::Silhouettes)
}

/// The smoothies of a caster's `edges` (from [`silhouette`]) seen through `view` (the caster's
/// positions → light view, +z away from the light), for receivers no farther than `far`. Each silhouette
/// vertex gets one corner (`mailbox`); with [`Penumbra::Centred`] each edge an inner quad too.
pub fn smoothies(
    view: &Mat4,
    caster: &Caster<'_>,
    edges: &[([u32; 2], u32)],
    (size, far): (SmoothieSize, f32),
    penumbra: Penumbra,
    mailbox: &mut Mailbox,
    frame: u64,
) -> SmoothieGeometry {
    let project = |i: u32| {
        let p = view.transform_point3(caster.positions[i as usize]);
        (p.z > MIN_DEPTH).then(|| (Vec2::new(p.x, p.y) / p.z, p.z))
    };
    let mut out = SmoothieGeometry::default();
    for &([a, b], inner) in edges {
        let (Some((pa, za)), Some((pb, zb))) = (project(a), project(b)) else { continue };
        for (v, p, z) in [(a, pa, za), (b, pb, zb)] {
            if mailbox.first_visit(v, frame) {
                let (t, k) = (size.at(z), reach(z, far));
                let c = |sx: f32, sy: f32| vertex(p + Vec2::new(sx, sy) * t * k, z, Vec2::new(sx, sy) * k);
                quad(&mut out.corners, [c(-1.0, -1.0), c(1.0, -1.0), c(1.0, 1.0), c(-1.0, 1.0)]);
            }
        }
        let Some(along) = (pb - pa).try_normalize() else { continue };
        let Some((pi, _)) = project(inner) else { continue };
        // Outward: away from the light-facing triangle, across the edge.
        let normal = if along.perp().dot(pi - pa) > 0.0 { -along.perp() } else { along.perp() };
        let (ka, kb) = (reach(za, far), reach(zb, far));
        let (ta, tb) = (size.at(za) * ka, size.at(zb) * kb);
        quad(
            &mut out.edges,
            [
                vertex(pa, za, Vec2::ZERO),
                vertex(pb, zb, Vec2::ZERO),
                vertex(pb + normal * tb, zb, Vec2::X * kb),
                vertex(pa + normal * ta, za, Vec2::X * ka),
            ],
        );
        if let Penumbra::Centred { near, far } = penumbra {
            let range = (near, far);
            quad(
                &mut out.inner,
                [
                    inner_vertex(pa, za, 0.0, (pa, normal), range),
                    inner_vertex(pb, zb, 0.0, (pb, normal), range),
                    inner_vertex(pb - normal * tb, zb, kb, (pb, normal), range),
                    inner_vertex(pa - normal * ta, za, ka, (pa, normal), range),
                ],
            );
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::EdgeAdjacency;
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
            let edges = silhouette(&caster, Vec3::new(0.0, 10.0, 0.0));
            prop_assert_eq!(edges.len(), 4, "a plate under the light: its outline");
            let g = smoothies(&down(), &caster, &edges, (SmoothieSize::Fixed(t), f32::INFINITY), Penumbra::Outer, &mut Mailbox::default(), 1);
            prop_assert!(g.inner.is_empty(), "outer only: no inner quads");
            prop_assert_eq!(g.edges.len(), 4 * 6);
            prop_assert_eq!(g.corners.len(), 4 * 6, "one corner per silhouette vertex");
            let half = 0.5 / (10.0 - height);
            for v in &g.edges {
                let outer = v.sx == 1.0;
                // The outline sits at ±half; the outer rim t further out, never inside.
                let reach = v.x.abs().max(v.y.abs());
                let expected = if outer { half + t } else { half };
                prop_assert!((reach - expected).abs() < 1e-4 * (1.0 + expected), "{reach} vs {expected}");
                prop_assert!((v.b - (10.0 - height)).abs() < 1e-3);
            }
            for v in &g.corners {
                prop_assert!((Vec2::new(v.sx, v.sy).length() - 2f32.sqrt()).abs() < 1e-6);
            }
        }
    }

    /// Any depth range: only the shaders read it.
    const CENTRED: Penumbra = Penumbra::Centred { near: 1.0, far: 2.0 };

    proptest! {
        #[test]
        fn inner_quads_mirror_the_edges_over_the_blocker(height in 0.5f32..5.0, t in 0.001f32..0.2) {
            let (positions, triangles, adjacency) = plate(height);
            let caster = Caster { positions: &positions, triangles: &triangles, adjacency: &adjacency };
            let edges = silhouette(&caster, Vec3::new(0.0, 10.0, 0.0));
            let size = (SmoothieSize::Fixed(t), f32::INFINITY);
            let g = smoothies(&down(), &caster, &edges, size, CENTRED, &mut Mailbox::default(), 1);
            prop_assert_eq!(g.inner.len(), 4 * 6, "one inner quad per silhouette edge");
            let half = 0.5 / (10.0 - height);
            for v in &g.inner {
                let (p, foot, normal) = (Vec2::new(v.x, v.y), Vec2::new(v.fx, v.fy), Vec2::new(v.nx, v.ny));
                prop_assert!(v.sx == 0.0 || v.sx == 1.0, "alpha 0 on the outline, 1 at t inside it");
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
        let edges = silhouette(&caster, Vec3::new(0.0, 10.0, 0.0));
        let g = smoothies(
            &down(),
            &caster,
            &edges,
            (SmoothieSize::Fixed(0.1), f32::INFINITY),
            CENTRED,
            &mut Mailbox::default(),
            1,
        );
        assert!(g.is_empty());
    }
}
