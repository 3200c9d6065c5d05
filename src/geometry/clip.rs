//! Intersection of two convex hexahedra (a camera frustum and a receiver's box), as the points
//! the light frustum must cover.

use glam::{DVec3, DVec4, Vec3};

/// A convex solid with eight corners indexed like [`super::Aabb::corners`]: bit 0 selects +x,
/// bit 1 +y, bit 2 +z in the solid's own parameterisation (frusta and boxes both fit).
#[derive(Clone, Copy, Debug)]
pub struct Hexahedron {
    pub corners: [Vec3; 8],
}

/// The six faces as corner quads, counter-clockwise seen from outside.
const FACES: [[usize; 4]; 6] = [[0, 4, 6, 2], [1, 3, 7, 5], [0, 1, 5, 4], [2, 6, 7, 3], [0, 2, 3, 1], [4, 5, 7, 6]];

impl Hexahedron {
    fn faces(&self) -> impl Iterator<Item = Vec<DVec3>> + '_ {
        FACES.iter().map(|f| f.iter().map(|&i| self.corners[i].as_dvec3()).collect())
    }

    /// Inward planes (n·p + d ≥ 0 inside), skipping degenerate faces of flat solids.
    fn planes(&self) -> Vec<DVec4> {
        let center = self.corners.iter().map(|c| c.as_dvec3()).sum::<DVec3>() / 8.0;
        FACES
            .iter()
            .filter_map(|f| {
                let [a, b, c, d] = f.map(|i| self.corners[i].as_dvec3());
                // The quad's normal from its diagonals is robust to one collapsed edge.
                let n = (c - a).cross(d - b).try_normalize()?;
                let offset = (a + b + c + d) * 0.25;
                // Orient inward whatever the winding (mirrored frusta flip it).
                let n = if n.dot(center - offset) < 0.0 { -n } else { n };
                Some(n.extend(-n.dot(offset)))
            })
            .collect()
    }
}

/// Points whose convex hull is the intersection of `a` and `b`: each face of one clipped by the
/// other's planes (Sutherland–Hodgman), in f64: a point interpolated between corners 1e5 m
/// apart rounds by the corners' ulp, which in f32 is 1.6 cm. Empty when the solids do not meet.
pub fn intersection_points(a: &Hexahedron, b: &Hexahedron) -> Vec<Vec3> {
    let mut points = Vec::new();
    for (solid, other) in [(a, b), (b, a)] {
        let planes = other.planes();
        for face in solid.faces() {
            points.extend(clip_polygon(face, &planes).into_iter().map(DVec3::as_vec3));
        }
    }
    points
}

/// Slack of a plane test, per unit of the magnitudes it sums (the point's coordinates and the
/// plane's offset): 8 ulps, over what a point computed on a plane rounds to, so flat
/// receivers, which lie exactly on two opposite planes, survive. Relative to the point, not to
/// the solids: 1e-5 of a camera frustum 2e5 m deep and a ground 3e5 m wide widened a 3 cm
/// patch of ground in view into a slab metres wide and high, the light's projection centre was
/// kept kilometres away, and the depth rounding there (mm) hid a 1 mm cube's shadow (issue 19).
const SLACK: f64 = 8.0 * f64::EPSILON;

fn clip_polygon(mut poly: Vec<DVec3>, planes: &[DVec4]) -> Vec<DVec3> {
    for plane in planes {
        if poly.is_empty() {
            break;
        }
        let dist = |p: DVec3| plane.truncate().dot(p) + plane.w + SLACK * (p.abs().max_element() + plane.w.abs());
        let mut out = Vec::with_capacity(poly.len() + 1);
        for (i, &p) in poly.iter().enumerate() {
            let q = poly[(i + 1) % poly.len()];
            let (dp, dq) = (dist(p), dist(q));
            if dp >= 0.0 {
                out.push(p);
            }
            if (dp >= 0.0) != (dq >= 0.0) {
                out.push(p + (q - p) * (dp / (dp - dq)));
            }
        }
        poly = out;
    }
    poly
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;
    use proptest::prelude::*;

    fn cube(min: Vec3, max: Vec3) -> Hexahedron {
        Hexahedron { corners: Aabb { min, max }.corners() }
    }

    #[test]
    fn disjoint_boxes_do_not_meet() {
        let a = cube(Vec3::ZERO, Vec3::ONE);
        let b = cube(Vec3::splat(2.0), Vec3::splat(3.0));
        assert!(intersection_points(&a, &b).is_empty());
    }

    #[test]
    fn a_box_inside_another_is_its_own_intersection() {
        let outer = cube(Vec3::splat(-10.0), Vec3::splat(10.0));
        let inner = cube(Vec3::ZERO, Vec3::ONE);
        let pts = intersection_points(&outer, &inner);
        assert_eq!(Aabb::from_points(pts), Aabb { min: Vec3::ZERO, max: Vec3::ONE });
    }

    #[test]
    fn a_flat_plate_survives_clipping() {
        let ground = cube(Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, 5.0));
        let view = cube(Vec3::new(-1.0, -1.0, -1.0), Vec3::new(1.0, 1.0, 1.0));
        let b = Aabb::from_points(intersection_points(&view, &ground));
        // Within the clipping slack, and never smaller.
        assert!((b.min - Vec3::new(-1.0, 0.0, -1.0)).abs().max_element() < 1e-3, "{b:?}");
        assert!((b.max - Vec3::new(1.0, 0.0, 1.0)).abs().max_element() < 1e-3, "{b:?}");
    }

    /// A camera 1 cm above a ground 3e5 m wide, looking down 45° with its far plane 2e5 m off:
    /// the ground it sees is a patch of a few centimetres, and so must the points be.
    #[test]
    fn a_small_view_of_a_huge_ground_stays_small() {
        let ground = cube(Vec3::new(-1.5e5, 0.0, -1.5e5), Vec3::new(1.5e5, 0.0, 1.5e5));
        let (eye, forward) = (Vec3::new(0.0, 0.01, 0.0), Vec3::new(0.0, -1.0, -1.0).normalize());
        let (right, up) = (Vec3::X, Vec3::X.cross(forward));
        let (tan, near, far) = (20f32.to_radians().tan(), 5e-3, 2e5);
        let corners = std::array::from_fn(|i| {
            let d = if i & 4 == 0 { near } else { far };
            let (sx, sy) = (if i & 1 == 0 { -1.0 } else { 1.0 }, if i & 2 == 0 { -1.0 } else { 1.0 });
            eye + (forward + (right * sx + up * sy) * tan) * d
        });
        let b = Aabb::from_points(intersection_points(&Hexahedron { corners }, &ground));
        // Its lowest rays meet the ground 0.5 cm ahead, its highest 2.1 cm ahead, 1.6 cm apart.
        assert!(b.max.y - b.min.y < 1e-4 && (b.min.y).abs() < 1e-4, "{b:?}");
        assert!(b.min.z > -0.04 && b.max.z < 0.0 && (b.max.x - b.min.x) < 0.03, "{b:?}");
    }

    proptest! {
        /// The intersection of two boxes is the box of their overlaps.
        #[test]
        fn box_intersection_matches_overlap(
            a0 in prop::array::uniform3(-5.0f32..5.0), a1 in prop::array::uniform3(0.1f32..5.0),
            b0 in prop::array::uniform3(-5.0f32..5.0), b1 in prop::array::uniform3(0.1f32..5.0),
        ) {
            let (amin, bmin) = (Vec3::from(a0), Vec3::from(b0));
            let (amax, bmax) = (amin + Vec3::from(a1), bmin + Vec3::from(b1));
            let pts = intersection_points(&cube(amin, amax), &cube(bmin, bmax));
            let (omin, omax) = (amin.max(bmin), amax.min(bmax));
            if omin.cmplt(omax - 1e-3).all() {
                let got = Aabb::from_points(pts);
                prop_assert!((got.min - omin).abs().max_element() < 1e-3);
                prop_assert!((got.max - omax).abs().max_element() < 1e-3);
            } else if omin.cmpgt(omax + 1e-3).any() {
                prop_assert!(pts.is_empty());
            }
        }
    }
}
