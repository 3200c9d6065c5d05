//! Silhouettes relative to a point light, shared by the plateau (Haines §2) and smoothie
//! (Chan & Durand §3) geometry: face facing once per face per frame, then the edges that bound
//! the light-facing part of a mesh, from the edge adjacency built at load.
//!
//! Both passes stream flat arrays with no data-dependent branch in the loop body but the rare
//! silhouette: facing from face planes built at load (four arrays, vectorised), then two facing
//! flags per edge from the compact face pairs.

use glam::{Mat4, Vec3, Vec4};

use super::adjacency::EdgeAdjacency;

/// A caster as silhouette extraction sees it.
pub struct Caster<'a> {
    /// Vertex positions, in the space of the [`Facing`] the edges are found with: object space
    /// with [`FacePlanes::light_facing`], for consumers that transform the few silhouette
    /// vertices themselves.
    pub positions: &'a [Vec3],
    pub triangles: &'a [[u32; 3]],
    pub adjacency: &'a EdgeAdjacency,
}

/// Where penumbra edges come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeSource {
    /// Silhouette edges relative to the light, from the edge adjacency (closed meshes).
    Silhouettes,
    /// Every edge of every light-facing triangle: no connectivity needed (§3), what open meshes
    /// get.
    LightFacing,
}

/// Which triangles face the light, one flag per face and then one more, always unlit, that the
/// missing face of a boundary edge points at ([`EdgeAdjacency::face_pairs`]): the edge pass then
/// reads two flags an edge without a branch for it. Derefs to the faces' flags alone.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Facing(Vec<bool>);

impl Facing {
    fn collect(faces: usize, lit: impl Iterator<Item = bool>) -> Self {
        let mut flags = Vec::with_capacity(faces + 1);
        flags.extend(lit);
        flags.push(false);
        Facing(flags)
    }
}

impl std::ops::Deref for Facing {
    type Target = [bool];

    fn deref(&self) -> &[bool] {
        &self.0[..self.0.len() - 1]
    }
}

/// A mesh's face planes in its own space, built once with the mesh: n = (b − a) × (c − a) and
/// d = −n·a (a corner rather than the centroid: the same plane, three fewer additions), as four arrays. A frame then tests each face with
/// four multiply-adds on streamed floats (vectorised, no gathers) against the light taken into
/// object space, instead of gathering three transformed vertices per face.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct FacePlanes {
    nx: Vec<f32>,
    ny: Vec<f32>,
    nz: Vec<f32>,
    d: Vec<f32>,
}

impl FacePlanes {
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        let mut planes = FacePlanes::default();
        for &[a, b, c] in triangles {
            let a = positions[a as usize];
            let n = (positions[b as usize] - a).cross(positions[c as usize] - a);
            planes.nx.push(n.x);
            planes.ny.push(n.y);
            planes.nz.push(n.z);
            planes.d.push(-n.dot(a));
        }
        planes
    }

    /// Which faces face `light` (world) for the mesh placed by `model` (object → world). A
    /// transform that mirrors (negative determinant) turns every face round, as a test on
    /// mirrored world positions would; a singular one lights none.
    pub fn light_facing(&self, model: &Mat4, light: Vec3) -> Facing {
        let l = Self::object_light(model, light);
        let planes = self.nx.iter().zip(&self.ny).zip(&self.nz).zip(&self.d);
        let lit = planes.map(|(((x, y), z), d)| x * l.x + y * l.y + z * l.z + d * l.w > 0.0);
        Facing::collect(self.d.len(), lit)
    }

    /// `light` (world) taken into the object space of `model` as [`Self::light_facing`] tests
    /// it: homogeneous, negated by a mirroring transform, so that face `f` faces the light
    /// exactly when `plane(f) · l > 0`, summed x, y, z, w in that order.
    pub fn object_light(model: &Mat4, light: Vec3) -> Vec4 {
        let side = model.determinant().signum();
        (model.inverse().transform_point3(light) * side).extend(side)
    }

    /// Face `f`'s plane: n in xyz, d in w.
    pub fn plane(&self, f: usize) -> Vec4 {
        Vec4::new(self.nx[f], self.ny[f], self.nz[f], self.d[f])
    }
}

/// The edges that bound the light-facing part of the caster, each with the third vertex of its
/// light-facing triangle (the umbra's inner side): silhouette edges between a light-facing and a
/// back-facing triangle, boundary edges of light-facing triangles, or with
/// [`EdgeSource::LightFacing`] every edge of every light-facing triangle. `facing` must be this
/// caster's ([`FacePlanes::light_facing`]).
pub fn penumbra_edges(caster: &Caster<'_>, facing: &Facing, source: EdgeSource) -> Vec<([u32; 2], u32)> {
    assert_eq!(facing.len(), caster.triangles.len(), "facing flags of another mesh");
    let third = |f: u32, e: [u32; 2]| caster.triangles[f as usize].into_iter().find(|v| !e.contains(v)).unwrap_or(e[0]);
    match source {
        EdgeSource::LightFacing => caster
            .triangles
            .iter()
            .zip(facing.iter())
            .filter(|(_, f)| **f)
            .flat_map(|(t, _)| [([t[0], t[1]], t[2]), ([t[1], t[2]], t[0]), ([t[2], t[0]], t[1])])
            .collect(),
        // The faces alone, 8 bytes an edge, two flags each, in one pass; the vertices only for
        // the few silhouettes (a branch that is almost never taken).
        EdgeSource::Silhouettes => {
            let lit = &facing.0;
            let mut out = Vec::new();
            for (i, &[f0, f1]) in caster.adjacency.face_pairs.iter().enumerate() {
                let (l0, l1) = (lit[f0 as usize], lit[f1 as usize]);
                if l0 != l1 {
                    let e = caster.adjacency.edges[i].vertices;
                    out.push((e, third(if l0 { f0 } else { f1 }, e)));
                }
            }
            out
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Quat;
    use proptest::prelude::*;

    use super::*;
    use crate::geometry::adjacency::NO_FACE;

    /// The straightforward reference: every edge, both faces tested in f64 from world
    /// positions, a missing face unlit. Also says which faces are too close to edge-on for f32
    /// to be sure of.
    fn reference(world: &[Vec3], triangles: &[[u32; 3]], adjacency: &EdgeAdjacency, light: Vec3) -> Reference {
        let side = |f: usize| {
            let [a, b, c] = triangles[f].map(|v| world[v as usize].as_dvec3());
            let n = (b - a).cross(c - a);
            let to_light = light.as_dvec3() - a;
            (n.dot(to_light), 1e-4 * n.length() * (to_light.length() + a.length()))
        };
        let sides: Vec<(f64, f64)> = (0..triangles.len()).map(side).collect();
        let lit = |f: u32| f != NO_FACE && sides[f as usize].0 > 0.0;
        let unsure = |f: u32| f != NO_FACE && sides[f as usize].0.abs() <= sides[f as usize].1;
        let third =
            |f: u32, e: [u32; 2]| triangles[f as usize].into_iter().find(|v| !e.contains(v)).expect("a triangle");
        let mut edges = Vec::new();
        let mut grazing = Vec::new();
        for e in &adjacency.edges {
            let [f0, f1] = e.faces;
            if unsure(f0) || unsure(f1) {
                grazing.extend(e.faces.iter().filter(|f| **f != NO_FACE).map(|f| (e.vertices, third(*f, e.vertices))));
            } else if lit(f0) != lit(f1) {
                edges.push((e.vertices, third(if lit(f0) { f0 } else { f1 }, e.vertices)));
            }
        }
        Reference { edges, grazing }
    }

    struct Reference {
        edges: Vec<([u32; 2], u32)>,
        /// What an edge of a near edge-on face may add.
        grazing: Vec<([u32; 2], u32)>,
    }

    impl Reference {
        /// `found` is the reference's silhouette, give or take edges of near edge-on faces.
        fn check(&self, found: &[([u32; 2], u32)]) -> std::result::Result<(), TestCaseError> {
            let mut sure: Vec<_> = found.iter().filter(|e| !self.grazing.contains(e)).copied().collect();
            let mut expected = self.edges.clone();
            sure.sort_unstable();
            expected.sort_unstable();
            prop_assert_eq!(sure, expected);
            Ok(())
        }
    }

    /// Random triangles over a few shared vertices: closed parts, open fans, fins on one edge
    /// (non-manifold), repeated faces.
    fn mesh() -> impl Strategy<Value = (Vec<Vec3>, Vec<[u32; 3]>)> {
        let point = (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0).prop_map(Vec3::from);
        let triangle = |n: u32| {
            (0..n, 1..n, 1..n).prop_filter_map("distinct corners", move |(a, b, c)| {
                let (b, c) = ((a + b) % n, (a + c) % n);
                (b != c).then_some([a, b, c])
            })
        };
        prop::collection::vec(point, 3..24).prop_flat_map(move |p| {
            let n = p.len() as u32;
            (Just(p), prop::collection::vec(triangle(n), 1..60))
        })
    }

    proptest! {
        #[test]
        fn face_planes_find_the_reference_silhouette(
            (positions, triangles) in mesh(),
            light in (-8.0f32..8.0, -8.0f32..8.0, -8.0f32..8.0),
            (axis, angle, scale, mirror) in ((-1.0f32..1.0, -1.0f32..1.0, 0.1f32..1.0), 0.0f32..6.3, 0.2f32..3.0, any::<bool>()),
            offset in (-3.0f32..3.0, -3.0f32..3.0, -3.0f32..3.0),
        ) {
            let adjacency = EdgeAdjacency::build(&triangles);
            let flip = if mirror { Vec3::new(-1.0, 1.0, 1.0) } else { Vec3::ONE };
            let rotation = Quat::from_axis_angle(Vec3::from(axis).normalize(), angle);
            let model = Mat4::from_scale_rotation_translation(flip * scale, rotation, Vec3::from(offset));
            let world: Vec<Vec3> = positions.iter().map(|p| model.transform_point3(*p)).collect();
            let light = Vec3::from(light);
            let truth = reference(&world, &triangles, &adjacency, light);

            let planes = FacePlanes::new(&positions, &triangles);
            let object = Caster { positions: &positions, triangles: &triangles, adjacency: &adjacency };
            truth.check(&penumbra_edges(&object, &planes.light_facing(&model, light), EdgeSource::Silhouettes))?;
        }
    }

    fn silhouette(triangles: &[[u32; 3]], positions: &[Vec3], light: Vec3) -> Vec<([u32; 2], u32)> {
        let adjacency = EdgeAdjacency::build(triangles);
        let caster = Caster { positions, triangles, adjacency: &adjacency };
        let facing = FacePlanes::new(positions, triangles).light_facing(&Mat4::IDENTITY, light);
        let mut edges = penumbra_edges(&caster, &facing, EdgeSource::Silhouettes);
        edges.sort_unstable();
        edges
    }

    #[test]
    fn open_meshes_bound_their_lit_faces_only() {
        // Two triangles folded at a right angle along 0–1, facing +y and +z; the light sees
        // the first only: its free edges and the fold bound it, not the unlit one's free edges.
        let positions = [Vec3::ZERO, Vec3::X, Vec3::new(0.5, 0.0, -1.0), Vec3::new(0.5, -1.0, 0.0)];
        let triangles = [[0, 1, 2], [1, 0, 3]];
        let light = Vec3::new(0.5, 5.0, -3.0);
        assert_eq!(silhouette(&triangles, &positions, light), [([0, 1], 2), ([1, 2], 0), ([2, 0], 1)]);
        // Seen from behind both: nothing.
        assert!(silhouette(&triangles, &positions, Vec3::new(0.5, -5.0, -3.0)).is_empty());
    }

    #[test]
    fn a_non_manifold_edge_counts_once_per_lit_face() {
        // Three fins on the edge 0–1, each a boundary edge of its own: the two lit fins' rims.
        let positions = [Vec3::ZERO, Vec3::X, Vec3::new(0.5, 1.0, 0.0), Vec3::new(0.5, -1.0, 0.0), Vec3::Z];
        let triangles = [[0, 1, 2], [1, 0, 3], [0, 1, 4]];
        let edges = silhouette(&triangles, &positions, Vec3::new(0.5, 0.0, 5.0));
        let on_fin_edge: Vec<_> = edges.iter().filter(|(e, _)| e.contains(&0) && e.contains(&1)).collect();
        assert_eq!(on_fin_edge, [&([0, 1], 2), &([1, 0], 3)]);
        assert!(edges.iter().all(|(_, third)| *third != 4), "the fin seen from behind bounds nothing");
    }

    #[test]
    fn mirrored_and_singular_transforms() {
        let (positions, triangles) = crate::geometry::shapes::cuboid(Vec3::ONE);
        let planes = FacePlanes::new(&positions, &triangles);
        let light = Vec3::new(0.2, 5.0, 0.1);
        let lit = |model: Mat4| planes.light_facing(&model, light).iter().filter(|l| **l).count();
        // A box seen from above shows its top: two triangles. Mirrored, its winding turns round
        // and the world test sees the other ten facing, as it would from mirrored positions.
        assert_eq!(lit(Mat4::IDENTITY), 2);
        assert_eq!(lit(Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0))), 10);
        assert_eq!(lit(Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0))), 0);
    }
}
