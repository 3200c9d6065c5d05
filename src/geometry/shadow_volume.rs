//! Shadow volumes (Crow 1977; DDJ 2005 "shadow volumes", Komura "shadow volume"): the region
//! a caster hides from a point light, bounded by its silhouette edges extruded away from the
//! light to infinity (homogeneous w = 0) and by caps, as triangles of [`Corner`]s.
//!
//! Built as a sum of prisms, one per *blocking* triangle turned to face the light: its near cap,
//! its far cap at infinity and three sides. Sides shared by two prisms cancel, so only edges
//! with a non-zero multiplicity are drawn, that many times; the stencil then counts, at each
//! pixel, how many prisms hold the surface, and 0 means lit.
//!
//! - Closed meshes: the blocking triangles are the light-facing ones, the classic volume (sides
//!   at the silhouette edges, multiplicity 1; light cap and dark cap).
//! - Open and non-manifold meshes (DDJ's "closed" requirement does not hold): every triangle
//!   blocks, from whichever side faces the light. Boundary edges get multiplicity 1, a closed
//!   part's silhouette 2; the count still is 0 exactly where no triangle blocks the light.
//!
//! Near caps keep the mesh's own vertex order (those turned round are listed apart, for a pass
//! that swaps the stencil's front and back operations), so that drawn through the camera
//! prepass's transform they have the bit-identical depth of the surface they lie on.

use glam::{DVec2, DVec4, Mat4, Vec3, Vec4};

use super::Aabb;
use super::adjacency::NO_FACE;
use super::silhouette::Caster;

/// A volume vertex: a mesh vertex, or its extrusion away from the light to infinity.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Corner {
    pub vertex: u32,
    pub at_infinity: bool,
}

impl Corner {
    fn near(vertex: u32) -> Self {
        Corner { vertex, at_infinity: false }
    }

    fn far(vertex: u32) -> Self {
        Corner { vertex, at_infinity: true }
    }
}

/// One caster's volume from one light point: sides (z-pass needs only these) and caps (z-fail
/// needs them all), wound outward of the volume in the mesh's own counter-clockwise sense,
/// except `turned_caps`, which face the other way.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ShadowVolume {
    pub sides: Vec<[Corner; 3]>,
    /// Dark caps, at infinity.
    pub far_caps: Vec<[Corner; 3]>,
    /// Light caps: light-facing triangles, as the mesh lists them.
    pub near_caps: Vec<[u32; 3]>,
    /// Light caps of triangles facing away from the light (open meshes), as the mesh lists
    /// them: they count with the opposite sign.
    pub turned_caps: Vec<[u32; 3]>,
}

/// Whether a mesh needs the two-sided construction: it has boundary or non-manifold edges.
pub fn is_open(caster: &Caster<'_>) -> bool {
    caster.adjacency.boundary + caster.adjacency.non_manifold > 0
}

/// The volume of `caster` lit from a point, its `facing` the caster's light-facing triangles
/// from that point ([`FacePlanes::light_facing`](super::silhouette::FacePlanes::light_facing)).
/// Connectivity alone: the corners are vertex numbers, in whatever space the caster's
/// positions are, so a frame whose caster moved transforms none of them.
pub fn shadow_volume(caster: &Caster<'_>, facing: &[bool], two_sided: bool) -> ShadowVolume {
    let blocks = |f: u32| f != NO_FACE && (two_sided || facing[f as usize]);
    // +1 when the face, turned towards the light, runs along the edge as stored.
    let along = |f: u32, forward: bool| if facing[f as usize] == forward { 1 } else { -1 };
    let mut volume = ShadowVolume::default();
    for e in &caster.adjacency.edges {
        let [f0, f1] = e.faces;
        let mut m = 0i32;
        if blocks(f0) {
            m += along(f0, true);
        }
        if blocks(f1) {
            m += along(f1, false);
        }
        let [a, b] = if m > 0 { e.vertices } else { [e.vertices[1], e.vertices[0]] };
        for _ in 0..m.unsigned_abs() {
            // Edge a → b of a light-facing cap: the side runs b → a, then out to infinity.
            volume.sides.push([Corner::near(b), Corner::near(a), Corner::far(a)]);
            volume.sides.push([Corner::near(b), Corner::far(a), Corner::far(b)]);
        }
    }
    for (f, t) in caster.triangles.iter().enumerate() {
        if !blocks(f as u32) {
            continue;
        }
        let [a, b, c] = if facing[f] { *t } else { [t[0], t[2], t[1]] };
        if facing[f] { &mut volume.near_caps } else { &mut volume.turned_caps }.push(*t);
        volume.far_caps.push([Corner::far(a), Corner::far(c), Corner::far(b)]);
    }
    volume
}

/// The most prisms of one caster's volume that can hold one point, for counting within the
/// stencil's bits: a convex mesh is crossed at most once (closed) or twice (open) by a ray
/// from the light; otherwise, conservatively, one per triangle.
pub fn nesting_bound(caster: &Caster<'_>, two_sided: bool) -> u32 {
    let scale = Aabb::from_points(caster.positions.iter().copied()).corners().iter().map(|c| c.length()).sum::<f32>();
    let tolerance = 1e-5 * scale.max(f32::MIN_POSITIVE);
    let convex = caster.triangles.iter().all(|t| {
        let [a, b, c] = t.map(|i| caster.positions[i as usize]);
        let Some(n) = (b - a).cross(c - a).try_normalize() else { return true };
        caster.positions.iter().all(|p| n.dot(*p - a) <= tolerance)
    });
    match (convex, two_sided) {
        (true, false) => 1,
        (true, true) => 2,
        (false, _) => caster.triangles.len().max(1) as u32,
    }
}

/// The screen a volume's triangles fill through `view_proj`, in screens (1: one full screen's
/// worth of fragments): the stencil fill the counting pays, the method's known weakness
/// (Chan & Durand §1: "significant overdraw and large fillrate requirements"; the DDJ's
/// "fill rate ... wasted"), z-pass drawing the `sides`, z-fail the caps as well. Vertices at infinity are
/// the direction away from `light` (w = 0); triangles are clipped to the screen and to w > 0
/// only, as depth clamping leaves the near and far planes unclipped.
pub fn screen_fill(volume: &ShadowVolume, positions: &[Vec3], light: Vec3, view_proj: Mat4, caps: bool) -> f64 {
    let clip = |c: Corner| {
        let p = positions[c.vertex as usize];
        if c.at_infinity { view_proj * (p - light).extend(0.0) } else { view_proj * p.extend(1.0) }
    };
    let near = |t: &[u32; 3]| t.map(|v| view_proj * positions[v as usize].extend(1.0));
    let mut triangles: Vec<[Vec4; 3]> = volume.sides.iter().map(|t| t.map(clip)).collect();
    if caps {
        triangles.extend(volume.far_caps.iter().map(|t| t.map(clip)));
        triangles.extend(volume.near_caps.iter().chain(&volume.turned_caps).map(near));
    }
    triangles.iter().map(screen_area).sum()
}

/// The area of the clip-space triangle `t` on the screen, in screens.
fn screen_area(t: &[Vec4; 3]) -> f64 {
    let mut polygon: Vec<DVec4> = t.iter().map(|v| v.as_dvec4()).collect();
    // Inside where d(v) ≥ 0: w > 0 (a little, so that the division below is safe), |x|, |y| ≤ w.
    let planes: [fn(DVec4) -> f64; 5] = [|v| v.w - 1e-9, |v| v.w - v.x, |v| v.w + v.x, |v| v.w - v.y, |v| v.w + v.y];
    for d in planes {
        let mut out = Vec::with_capacity(polygon.len() + 1);
        for (i, &a) in polygon.iter().enumerate() {
            let b = polygon[(i + 1) % polygon.len()];
            let (da, db) = (d(a), d(b));
            if da >= 0.0 {
                out.push(a);
            }
            if (da >= 0.0) != (db >= 0.0) {
                out.push(a + (b - a) * (da / (da - db)));
            }
        }
        polygon = out;
        if polygon.len() < 3 {
            return 0.0;
        }
    }
    let ndc: Vec<DVec2> = polygon.iter().map(|v| DVec2::new(v.x / v.w, v.y / v.w)).collect();
    let twice: f64 = (0..ndc.len()).map(|i| ndc[i].perp_dot(ndc[(i + 1) % ndc.len()])).sum();
    // The screen spans 2 × 2 in normalized device coordinates.
    twice.abs() / 8.0
}

/// Whether the segment from `a` to `b` meets `bounds` (slab test, inclusive).
pub fn segment_meets_box(a: Vec3, b: Vec3, bounds: &Aabb) -> bool {
    ray_meets_box(a, b - a, 1.0, bounds)
}

/// Whether the ray `origin + t · direction`, 0 ≤ t ≤ `t_max`, meets `bounds`.
pub fn ray_meets_box(origin: Vec3, direction: Vec3, t_max: f32, bounds: &Aabb) -> bool {
    let (mut t0, mut t1) = (0.0f32, t_max);
    for axis in 0..3 {
        let (o, d) = (origin[axis], direction[axis]);
        let (lo, hi) = (bounds.min[axis], bounds.max[axis]);
        if d == 0.0 {
            if o < lo || o > hi {
                return false;
            }
            continue;
        }
        let (a, b) = ((lo - o) / d, (hi - o) / d);
        t0 = t0.max(a.min(b));
        t1 = t1.min(a.max(b));
        if t0 > t1 {
            return false;
        }
    }
    true
}

/// Whether the eye of a perspective camera may lie inside the shadow of a caster bounded by
/// one of `casters`, for a light point `light`: then z-pass, which counts from the eye, starts
/// from a wrong count and the engine switches to z-fail. Boxes are grown by a thousandth of
/// their size: a grazing case counts as inside.
pub fn eye_may_be_in_shadow(light: Vec3, eye: Vec3, casters: &[Aabb]) -> bool {
    casters.iter().any(|b| {
        let pad = (b.max - b.min).max_element().max(f32::MIN_POSITIVE) * 1e-3;
        segment_meets_box(light, eye, &Aabb { min: b.min - Vec3::splat(pad), max: b.max + Vec3::splat(pad) })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::EdgeAdjacency;
    use crate::geometry::shapes;
    use crate::geometry::silhouette::FacePlanes;
    use proptest::prelude::*;

    /// The signed number of times the closed triangle soup winds round `p` (solid angles summed,
    /// van Oosterom & Strackee), with vertices at infinity replaced by points `far` away.
    fn winding(tris: &[[Vec3; 3]], p: Vec3) -> f32 {
        let omega: f32 = tris
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| v - p);
                let (la, lb, lc) = (a.length(), b.length(), c.length());
                let num = a.dot(b.cross(c));
                let den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
                2.0 * num.atan2(den)
            })
            .sum();
        omega / (4.0 * std::f32::consts::PI)
    }

    fn soup(v: &ShadowVolume, positions: &[Vec3], light: Vec3, far: f32) -> Vec<[Vec3; 3]> {
        let at = |c: Corner| -> Vec3 {
            let p = positions[c.vertex as usize];
            if c.at_infinity { light + (p - light).normalize() * far } else { p }
        };
        let near = v.near_caps.iter().map(|t| t.map(|i| positions[i as usize]));
        let turned = v.turned_caps.iter().map(|t| [t[0], t[2], t[1]].map(|i| positions[i as usize]));
        v.sides.iter().chain(&v.far_caps).map(|t| t.map(at)).chain(near).chain(turned).collect()
    }

    fn blocked(positions: &[Vec3], triangles: &[[u32; 3]], light: Vec3, p: Vec3) -> bool {
        triangles.iter().any(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            // Möller–Trumbore on the segment from the light to p.
            let d = p - light;
            let (e1, e2) = (b - a, c - a);
            let h = d.cross(e2);
            let det = e1.dot(h);
            if det.abs() < 1e-9 {
                return false;
            }
            let s = light - a;
            let u = s.dot(h) / det;
            let q = s.cross(e1);
            let v = d.dot(q) / det;
            let t = e2.dot(q) / det;
            u > 0.0 && v > 0.0 && u + v < 1.0 && t > 0.0 && t < 1.0
        })
    }

    /// The unit cube's triangles, optionally without its bottom (y = 0) face.
    fn cube(bottom: bool) -> (Vec<Vec3>, Vec<[u32; 3]>) {
        let (positions, triangles) = shapes::cuboid(Vec3::ONE);
        let triangles = triangles
            .into_iter()
            .filter(|t| bottom || !t.iter().all(|&i| positions[i as usize].y < 0.0))
            .collect::<Vec<_>>();
        (positions, triangles)
    }

    fn check(positions: &[Vec3], triangles: &[[u32; 3]], light: Vec3, probe: Vec3) -> Result<(), TestCaseError> {
        let adjacency = EdgeAdjacency::build(triangles);
        let caster = Caster { positions, triangles, adjacency: &adjacency };
        let facing = FacePlanes::new(positions, triangles).light_facing(&Mat4::IDENTITY, light);
        let two_sided = is_open(&caster);
        let volume = shadow_volume(&caster, &facing, two_sided);
        let w = winding(&soup(&volume, positions, light, 1e4), probe);
        prop_assert!((w - w.round()).abs() < 0.05, "winding {w} not whole");
        prop_assert!(w.round() >= 0.0, "winding {w} negative");
        prop_assert!(w.round() <= nesting_bound(&caster, two_sided) as f32, "winding {w} above the bound");
        prop_assert_eq!(w.round() > 0.0, blocked(positions, triangles, light, probe), "winding {}", w);
        Ok(())
    }

    fn point(range: f32) -> impl Strategy<Value = Vec3> {
        (-range..range, -range..range, -range..range).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    proptest! {
        /// The count is non-negative, whole, within the nesting bound, and non-zero exactly
        /// where the segment to the light crosses the mesh: closed, open and non-manifold.
        #[test]
        fn the_count_is_positive_exactly_in_shadow(
            light in point(3.0).prop_filter("outside the cube", |l| l.abs().max_element() > 0.7),
            probe in point(2.5).prop_filter("off the cube", |p| p.abs().max_element() > 0.55),
            shape in 0..3usize,
        ) {
            let (mut positions, mut triangles) = cube(shape != 1);
            if shape == 2 {
                // A fin sharing the cube's top front edge: three faces on one edge.
                let n = positions.len() as u32;
                positions.extend([Vec3::new(-0.5, 1.0, 0.5), Vec3::new(0.5, 1.0, 0.5)]);
                let top_front: Vec<u32> =
                    (0..n).filter(|&i| positions[i as usize].y > 0.0 && positions[i as usize].z > 0.0).collect();
                triangles.push([top_front[0], top_front[1], n]);
                triangles.push([top_front[1], n + 1, n]);
            }
            check(&positions, &triangles, light, probe)?;
        }
    }

    #[test]
    fn a_fin_makes_an_edge_non_manifold() {
        let (positions, mut triangles) = cube(true);
        let n = positions.len() as u32;
        let top_front: Vec<u32> =
            (0..n).filter(|&i| positions[i as usize].y > 0.0 && positions[i as usize].z > 0.0).collect();
        triangles.push([top_front[0], top_front[1], n]);
        assert_eq!(EdgeAdjacency::build(&triangles).non_manifold, 1);
    }

    #[test]
    fn closed_convex_meshes_nest_once_and_others_by_their_triangles() {
        let (positions, triangles) = cube(true);
        let adjacency = EdgeAdjacency::build(&triangles);
        let caster = Caster { positions: &positions, triangles: &triangles, adjacency: &adjacency };
        assert_eq!(nesting_bound(&caster, false), 1);
        assert_eq!(nesting_bound(&caster, true), 2);
        // A corner pushed in makes a dent.
        let dented: Vec<Vec3> = positions.iter().map(|p| if p.min_element() > 0.0 { *p * 0.4 } else { *p }).collect();
        let dented = Caster { positions: &dented, ..caster };
        assert_eq!(nesting_bound(&dented, false), 12);
    }

    #[test]
    fn the_fill_is_the_screen_the_volume_covers() {
        let volume = |sides: Vec<[Corner; 3]>| ShadowVolume { sides, ..Default::default() };
        let (a, b, c) = (Corner::near(0), Corner::near(1), Corner::near(2));
        // In clip space already: a right triangle over half the screen, one reaching far past
        // it, one behind the eye.
        let half = [Vec3::new(-1.0, -1.0, 0.5), Vec3::new(1.0, -1.0, 0.5), Vec3::new(1.0, 1.0, 0.5)];
        let fill = |p: &[Vec3], sides| screen_fill(&volume(sides), p, Vec3::ZERO, Mat4::IDENTITY, false);
        assert!((fill(&half, vec![[a, b, c]]) - 0.5).abs() < 1e-9);
        assert!((fill(&half, vec![[a, b, c], [c, b, a]]) - 1.0).abs() < 1e-9, "both faces fill");
        let huge = half.map(|p| p * 100.0);
        assert!((fill(&huge, vec![[a, b, c]]) - 0.5).abs() < 1e-9, "clipped to the screen");
        // A perspective (w = z): the far corner, the direction (1, 1, 1) away from the light
        // at w = 0 in world space, lands on the screen's corner; behind the eye, nothing.
        let perspective = Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::W, Vec4::ZERO);
        let points = [Vec3::new(-1.0, -1.0, 1.0), Vec3::new(1.0, -1.0, 1.0), Vec3::ZERO, Vec3::ONE];
        let v = volume(vec![[a, b, Corner::far(3)]]);
        assert!((screen_fill(&v, &points, Vec3::ZERO, perspective, false) - 0.5).abs() < 1e-6);
        let behind = points.map(|p| p * Vec3::new(1.0, 1.0, -1.0));
        assert_eq!(screen_fill(&v, &behind, Vec3::ZERO, perspective, false), 0.0);
    }

    #[test]
    fn an_eye_under_a_roof_is_in_its_shadow() {
        let caster = [Aabb { min: Vec3::new(-1.0, 1.0, -1.0), max: Vec3::new(1.0, 1.2, 1.0) }];
        let light = Vec3::new(0.0, 5.0, 0.0);
        assert!(eye_may_be_in_shadow(light, Vec3::new(0.0, 0.5, 0.0), &caster));
        assert!(eye_may_be_in_shadow(light, Vec3::new(1.0, 0.5, 0.0), &caster), "grazing counts");
        assert!(!eye_may_be_in_shadow(light, Vec3::new(3.0, 0.5, 0.0), &caster));
        assert!(!eye_may_be_in_shadow(light, Vec3::new(0.0, 6.0, 0.0), &caster), "above the light");
    }
}
