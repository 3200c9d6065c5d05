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

/// How far past what the silhouette from the light's centre casts (about: the penumbra of the
/// turned face's far vertex) a partial silhouette's outer half must reach to be drawn, in its
/// own half widths. Widening a straight edge's outer half by that fraction ε changes V by at
/// most ε/π ≈ 0.016; the partial silhouettes of a fine mesh, the next ring beside its
/// silhouette at nearly its height, reach about as far as the silhouette does and would cost a
/// second set of sides for nothing (the plateau's sheets on sphere: 6.5 → 9.5 ms on lavapipe,
/// penumbra RMSE unchanged at 0.0165).
pub const PARTIAL_GAIN: f32 = 0.05;

/// An edge that bounds the light-facing part of a caster for part of a light sphere only
/// ([`partial_silhouettes`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct PartialEdge {
    pub vertices: [u32; 2],
    /// The third vertex of the face that faces that part of the light: the umbra's inner side.
    pub inner: u32,
    /// The third vertex of the face that has turned for that part, the way the silhouette from
    /// the light's centre lies.
    pub turned: u32,
    /// The centre sees both faces lit: the edge lies on the hard shadow's outer side of the
    /// silhouette, whose outer half it may widen. Else both unlit: it lies under the silhouette,
    /// nearer the receiver, and may narrow its inner half.
    pub lit: bool,
}

/// The edges that bound the light-facing part of the caster for part of a light sphere
/// (`light`, `radius`) but not for its centre (issue 20): convex edges whose faces face the
/// centre alike while some point of the sphere sees one of them from its other side, a face
/// within the light's angular radius of edge-on. Each comes with the third vertex of the face
/// that faces that point (the umbra's inner side, as [`penumbra_edges`] gives it). From those
/// points of the light the silhouette has moved onto these edges: a box's face seen nearly
/// edge-on hands it from its far edge to its near one, which stands higher and casts a wider
/// outer penumbra than the silhouette from the centre. An edge comes twice when both its faces
/// turn, each for its own part of the light. `facing` must be this caster's, from `planes`
/// ([`FacePlanes::light_facing`]).
pub fn partial_silhouettes(
    caster: &Caster<'_>,
    planes: &FacePlanes,
    facing: &Facing,
    model: &Mat4,
    light: Vec3,
    radius: f32,
) -> Vec<PartialEdge> {
    assert_eq!(facing.len(), caster.triangles.len(), "facing flags of another mesh");
    if radius <= 0.0 {
        return Vec::new();
    }
    // In the world, face f's plane is the object one through M⁻¹ = (A, ·): normal Aᵀn, so its
    // signed distance from the light is plane·l / |Aᵀn| (l: the light in object space, signed
    // as the facing test signs it). No vertex is transformed.
    let l = FacePlanes::object_light(model, light);
    let to_world = glam::Mat3::from_mat4(model.inverse()).transpose();
    // The faces the sphere reaches across (|plane·l| < radius·|Aᵀn|, streamed as the facing
    // test is), then the one more of a missing face (never).
    let [cx, cy, cz] = [to_world.x_axis, to_world.y_axis, to_world.z_axis];
    let planes_of = planes.nx.iter().zip(&planes.ny).zip(&planes.nz).zip(&planes.d);
    let mut near: Vec<bool> = planes_of
        .map(|(((&x, &y), &z), &d)| {
            let p = x * l.x + y * l.y + z * l.z + d * l.w;
            let n = cx * x + cy * y + cz * z;
            p * p < radius * radius * n.length_squared()
        })
        .collect();
    near.push(false);
    let lit = &facing.0;
    let third = |f: u32, e: [u32; 2]| caster.triangles[f as usize].into_iter().find(|v| !e.contains(v));
    let mut out = Vec::new();
    for (i, &[f0, f1]) in caster.adjacency.face_pairs.iter().enumerate() {
        if lit[f0 as usize] != lit[f1 as usize] || !(near[f0 as usize] || near[f1 as usize]) {
            continue;
        }
        let edge = caster.adjacency.edges[i];
        if edge.is_boundary() {
            continue;
        }
        let (Some(v0), Some(v1)) = (third(f0, edge.vertices), third(f1, edge.vertices)) else { continue };
        // Convex where face 1's third vertex lies behind face 0 (in object space, where the
        // planes are those the mesh was built with); a valley or a flat edge is a silhouette of
        // no point of the light.
        let (f0, f1) = (f0 as usize, f1 as usize);
        if planes.plane(f0).dot(caster.positions[v1 as usize].extend(1.0)) >= 0.0 {
            continue;
        }
        // Unit world normals and signed world distances.
        let [(n0, p0), (n1, p1)] = [f0, f1].map(|f| {
            let plane = planes.plane(f);
            let n = to_world * plane.truncate();
            let length = n.length();
            (n / length, plane.dot(l) / length)
        });
        let thirds = [v0, v1];
        for (k, turns) in turning([p0, p1], n0.dot(n1), radius).into_iter().enumerate() {
            // Where the centre sees both faces lit, the one that has not turned faces those
            // points; where it sees both unlit, the one that has.
            let inner = if lit[f0] { thirds[1 - k] } else { thirds[k] };
            if turns {
                out.push(PartialEdge { vertices: edge.vertices, inner, turned: thirds[k], lit: lit[f0] });
            }
        }
    }
    out
}

/// For two faces across a convex edge, at signed distances `p` from the light's centre (of one
/// sign) and with unit normals at cosine `cos`, whether some point of the light sphere sees
/// face i from its other side while the other face still faces it as the centre sees it. The
/// wedge where only face i has turned is nearest at the centre's foot on face i's plane, when
/// that still sees face j as the centre does (its distance p_j − cos·p_i of p_j's sign), or else
/// at the edge's line, the rim of both wedges, at √((p₀² + p₁² − 2·cos·p₀p₁) / (1 − cos²)).
fn turning(p: [f32; 2], cos: f32, radius: f32) -> [bool; 2] {
    let sin2 = 1.0 - cos * cos;
    let line = sin2 > 0.0 && (p[0] * p[0] + p[1] * p[1] - 2.0 * cos * p[0] * p[1]) / sin2 < radius * radius;
    [0, 1].map(|i| {
        let j = 1 - i;
        line || p[i].abs() < radius && (p[j] - cos * p[i]) * p[j] > 0.0
    })
}

/// A mesh and what the silhouette finders take of it, for the geometry modules' tests.
#[cfg(test)]
pub(crate) struct TestMesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
    pub adjacency: EdgeAdjacency,
    pub planes: FacePlanes,
}

#[cfg(test)]
impl TestMesh {
    pub fn new((positions, triangles): super::shapes::Shape) -> Self {
        let adjacency = EdgeAdjacency::build(&triangles);
        let planes = FacePlanes::new(&positions, &triangles);
        TestMesh { positions, triangles, adjacency, planes }
    }

    pub fn caster(&self) -> Caster<'_> {
        Caster { positions: &self.positions, triangles: &self.triangles, adjacency: &self.adjacency }
    }

    /// The partial silhouettes' thick slab: 0.6 m wide (x), 1.3 m tall, 4 m long (z), standing
    /// from 1 m up (its model matrix).
    pub fn thick_slab() -> (Self, Mat4) {
        (TestMesh::new(super::shapes::cuboid(Vec3::new(0.6, 1.3, 4.0))), Mat4::from_translation(Vec3::Y * 1.65))
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

    /// Sorted partial silhouettes of a mesh in place, with their third vertices and whether the
    /// centre sees their faces lit.
    fn partial(positions: &[Vec3], triangles: &[[u32; 3]], light: Vec3, radius: f32) -> Vec<([u32; 2], u32, bool)> {
        let adjacency = EdgeAdjacency::build(triangles);
        let caster = Caster { positions, triangles, adjacency: &adjacency };
        let planes = FacePlanes::new(positions, triangles);
        let facing = planes.light_facing(&Mat4::IDENTITY, light);
        let edges = partial_silhouettes(&caster, &planes, &facing, &Mat4::IDENTITY, light, radius);
        let mut edges: Vec<_> = edges.iter().map(|e| (e.vertices, e.inner, e.lit)).collect();
        edges.iter_mut().for_each(|(e, _, _)| e.sort_unstable());
        edges.sort_unstable();
        edges
    }

    #[test]
    fn a_face_seen_nearly_edge_on_hands_the_silhouette_to_its_other_edges() {
        // A box of 0.8 m (vertex i: +x, +y, +z by its bits 0, 1, 2) under a light 8 m off along
        // +x and 0.6 m above its top: radius 0.42 m, 3° of angle, reaches 1° past the plane of the
        // +z face; the other faces' planes all clear it.
        let (positions, triangles) = crate::geometry::shapes::cuboid(Vec3::splat(0.8));
        let (radius, off) = (0.42, 8.0 * 1f32.to_radians().tan());
        let found = |z: f32, radius: f32| partial(&positions, &triangles, Vec3::new(8.0, 1.0, z), radius);
        // In front of the face, the light's part behind its plane sees it turned away: the
        // silhouette moves onto its edges with the lit +x and +y faces, which face that part.
        let front = found(0.4 + off, radius);
        assert_eq!(front.iter().map(|(e, _, _)| *e).collect::<Vec<_>>(), [[5, 7], [6, 7]], "{front:?}");
        assert!(
            front.iter().all(|(_, third, lit)| positions[*third as usize].z < 0.0 && *lit),
            "thirds on the lit faces: {front:?}"
        );
        // Behind it, the part in front sees it lit: its edges with the unlit −x and −y faces,
        // the face itself facing that part.
        let behind = found(0.4 - off, radius);
        assert_eq!(behind.iter().map(|(e, _, _)| *e).collect::<Vec<_>>(), [[4, 5], [4, 6]], "{behind:?}");
        assert!(
            behind.iter().all(|(_, third, lit)| positions[*third as usize].z > 0.0 && !*lit),
            "thirds on the face, the faces unlit: {behind:?}"
        );
        // The face's own diagonal is no silhouette of any point; a light clear of every plane,
        // or a point, has none.
        assert!(found(0.4 + 8.0 * 5f32.to_radians().tan(), radius).is_empty());
        assert!(found(0.4 + off, 0.0).is_empty());
    }

    proptest! {
        #[test]
        fn partial_silhouettes_hold_every_edge_some_point_of_the_light_sees_as_one(
            (positions, triangles) in mesh(),
            light in (-4.0f32..4.0, -4.0f32..4.0, -4.0f32..4.0),
            radius in 0.05f32..2.0,
            seed in any::<u64>(),
        ) {
            let light = Vec3::from(light);
            let found = partial(&positions, &triangles, light, radius);
            let adjacency = EdgeAdjacency::build(&triangles);
            // Points of the light sphere, uniform in the ball (a fixed sequence per case).
            let mut state = seed | 1;
            let mut next = || {
                state ^= state << 13;
                state ^= state >> 7;
                state ^= state << 17;
                (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
            };
            let points: Vec<_> = std::iter::repeat_with(|| glam::DVec3::new(next(), next(), next()))
                .filter(|p| p.length() < 0.999)
                .take(400)
                .map(|p| light.as_dvec3() + p * radius as f64)
                .collect();
            // Face planes in f64, unit normals; a side counts only clear of the plane.
            let plane = |f: u32| {
                let [a, b, c] = triangles[f as usize].map(|v| positions[v as usize].as_dvec3());
                let n = (b - a).cross(c - a).normalize_or_zero();
                move |x: glam::DVec3| n.dot(x - a)
            };
            let margin = 1e-3 * radius as f64;
            for e in adjacency.edges.iter().filter(|e| !e.is_boundary()) {
                let [f0, f1] = e.faces;
                let (p0, p1) = (plane(f0), plane(f1));
                let third = |f: u32| triangles[f as usize].into_iter().find(|v| !e.vertices.contains(v));
                let (Some(v0), Some(v1)) = (third(f0), third(f1)) else { continue };
                let centre = light.as_dvec3();
                let convex = p0(positions[v1 as usize].as_dvec3()) < -margin;
                if !convex || p0(centre).abs() < margin || p1(centre).abs() < margin || (p0(centre) > 0.0) != (p1(centre) > 0.0) {
                    continue;
                }
                let seen = points.iter().find(|x| {
                    let (a, b) = (p0(**x), p1(**x));
                    a.abs() > margin && b.abs() > margin && (a > 0.0) != (b > 0.0)
                });
                if let Some(x) = seen {
                    let facing = if p0(*x) > 0.0 { v0 } else { v1 };
                    let mut key = e.vertices;
                    key.sort_unstable();
                    let lit = p0(centre) > 0.0;
                    prop_assert!(found.contains(&(key, facing, lit)), "edge {:?} (third {facing}, lit {lit}) missing from {found:?}", key);
                }
            }
        }
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
