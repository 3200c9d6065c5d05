//! Edge adjacency, built once per mesh at load: every edge with the faces that share it.
//!
//! Silhouette extraction (plateaus, smoothies) walks these edges every frame, so the classification
//! happens here once: an edge is *manifold* (two faces), *boundary* (one face: open meshes) or
//! *non-manifold* (three or more faces).

use std::collections::HashMap;

pub use crate::shader_constants::NO_FACE;

/// One edge, its vertices in the winding order of `faces[0]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Edge {
    pub vertices: [u32; 2],
    /// `faces[1]` is [`NO_FACE`] on a boundary edge.
    pub faces: [u32; 2],
}

impl Edge {
    pub fn is_boundary(&self) -> bool {
        self.faces[1] == NO_FACE
    }
}

/// The edges of a triangle mesh with their classification counts.
#[derive(Clone, Debug, Default)]
pub struct EdgeAdjacency {
    /// Manifold and boundary edges. A non-manifold edge appears once per incident face, as a
    /// boundary edge of that face, so that silhouette tests stay conservative.
    pub edges: Vec<Edge>,
    /// `edges[i].faces`, apart: what silhouette extraction streams through every frame, half
    /// the bytes of `edges`. Here a missing face is the face count, not [`NO_FACE`]: the index of
    /// the always unlit flag that ends a [`Facing`](super::silhouette::Facing).
    pub face_pairs: Vec<[u32; 2]>,
    /// Edges with exactly one face.
    pub boundary: usize,
    /// Edges with three or more faces.
    pub non_manifold: usize,
}

impl EdgeAdjacency {
    /// Builds the adjacency of `triangles` (indices into a welded vertex list).
    pub fn build(triangles: &[[u32; 3]]) -> Self {
        // Key: the edge's vertices sorted; value: (face, vertices in that face's winding).
        type FaceUses = Vec<(u32, [u32; 2])>;
        let mut by_edge: HashMap<(u32, u32), FaceUses> = HashMap::with_capacity(triangles.len() * 3 / 2);
        for (face, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                if a == b {
                    continue; // a collapsed edge of a degenerate triangle bounds nothing
                }
                by_edge.entry((a.min(b), a.max(b))).or_default().push((face as u32, [a, b]));
            }
        }
        let mut keys: Vec<_> = by_edge.keys().copied().collect();
        keys.sort_unstable(); // deterministic order, whatever the hasher
        let mut adjacency = EdgeAdjacency::default();
        for key in keys {
            let faces = &by_edge[&key];
            match faces.as_slice() {
                [(f0, v), (f1, _)] => adjacency.edges.push(Edge { vertices: *v, faces: [*f0, *f1] }),
                [(f0, v)] => {
                    adjacency.boundary += 1;
                    adjacency.edges.push(Edge { vertices: *v, faces: [*f0, NO_FACE] });
                }
                many => {
                    adjacency.non_manifold += 1;
                    adjacency.edges.extend(many.iter().map(|(f, v)| Edge { vertices: *v, faces: [*f, NO_FACE] }));
                }
            }
        }
        let missing = triangles.len() as u32;
        adjacency.face_pairs = adjacency.edges.iter().map(|e| e.faces.map(|f| f.min(missing))).collect();
        adjacency
    }

    /// True when every edge has exactly two faces.
    pub fn is_closed(&self) -> bool {
        self.boundary == 0 && self.non_manifold == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tetrahedron_is_closed_with_six_edges() {
        let tris = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        let adj = EdgeAdjacency::build(&tris);
        assert_eq!(adj.edges.len(), 6);
        assert!(adj.is_closed());
    }

    #[test]
    fn single_triangle_has_three_boundary_edges() {
        let adj = EdgeAdjacency::build(&[[0, 1, 2]]);
        assert_eq!(adj.boundary, 3);
        assert!(adj.edges.iter().all(Edge::is_boundary));
    }

    #[test]
    fn three_fins_on_one_edge_are_non_manifold() {
        let adj = EdgeAdjacency::build(&[[0, 1, 2], [1, 0, 3], [0, 1, 4]]);
        assert_eq!(adj.non_manifold, 1);
        assert!(!adj.is_closed());
    }
}
