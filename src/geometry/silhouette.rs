//! Silhouettes relative to a point light, shared by the plateau (Haines §2) and smoothie
//! (Chan & Durand §3) geometry: face facing once per face per frame, then the edges that bound
//! the light-facing part of a mesh, from the edge adjacency built at load.

use glam::Vec3;

use super::adjacency::EdgeAdjacency;

/// A caster as silhouette extraction sees it.
pub struct Caster<'a> {
    /// World-space vertex positions.
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

/// Which triangles face the light: computed once per face per frame. The plane test uses a
/// corner rather than the centroid (the same plane, three fewer additions per face).
pub fn light_facing(caster: &Caster<'_>, light: Vec3) -> Vec<bool> {
    let p = caster.positions;
    caster
        .triangles
        .iter()
        .map(|&[a, b, c]| {
            let a = p[a as usize];
            (p[b as usize] - a).cross(p[c as usize] - a).dot(light - a) > 0.0
        })
        .collect()
}

/// The edges that bound the light-facing part of the caster, each with the third vertex of its
/// light-facing triangle (the umbra's inner side): silhouette edges between a light-facing and a
/// back-facing triangle, boundary edges of light-facing triangles, or with
/// [`EdgeSource::LightFacing`] every edge of every light-facing triangle.
pub fn penumbra_edges(caster: &Caster<'_>, facing: &[bool], source: EdgeSource) -> Vec<([u32; 2], u32)> {
    let third = |f: u32, e: [u32; 2]| caster.triangles[f as usize].into_iter().find(|v| !e.contains(v)).unwrap_or(e[0]);
    match source {
        EdgeSource::LightFacing => caster
            .triangles
            .iter()
            .zip(facing)
            .filter(|(_, f)| **f)
            .flat_map(|(t, _)| [([t[0], t[1]], t[2]), ([t[1], t[2]], t[0]), ([t[2], t[0]], t[1])])
            .collect(),
        // The faces alone, 8 bytes an edge, in one pass; the vertices only for the few
        // silhouettes. A missing face (`NO_FACE`) is past the end of `facing`: unlit.
        EdgeSource::Silhouettes => {
            let lit = |f: u32| facing.get(f as usize).copied().unwrap_or(false);
            let pairs = &caster.adjacency.face_pairs;
            let crossing = pairs.iter().enumerate().filter(|(_, [f0, f1])| lit(*f0) != lit(*f1));
            crossing
                .map(|(i, &[f0, f1])| {
                    let e = caster.adjacency.edges[i].vertices;
                    (e, third(if lit(f0) { f0 } else { f1 }, e))
                })
                .collect()
        }
    }
}

/// Cones drawn this frame, by vertex: each silhouette vertex's cone is drawn once even when
/// several edges share it (§3's mailbox).
#[derive(Clone, Debug, Default)]
pub struct Mailbox {
    stamps: Vec<u64>,
}

impl Mailbox {
    /// True the first time `vertex` is posted in `frame`.
    pub fn first_visit(&mut self, vertex: u32, frame: u64) -> bool {
        let i = vertex as usize;
        if self.stamps.len() <= i {
            self.stamps.resize(i + 1, u64::MAX);
        }
        std::mem::replace(&mut self.stamps[i], frame) != frame
    }
}
