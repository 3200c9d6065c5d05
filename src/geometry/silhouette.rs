//! Silhouettes relative to a point light, shared by the plateau (Haines §2) and smoothie
//! (Chan & Durand §3) geometry: face facing once per face per frame, then the edges that bound
//! the light-facing part of a mesh, from the edge adjacency built at load.

use glam::Vec3;

use super::adjacency::{EdgeAdjacency, NO_FACE};

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

/// Which triangles face the light: computed once per face per frame.
pub fn light_facing(caster: &Caster<'_>, light: Vec3) -> Vec<bool> {
    caster
        .triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| caster.positions[i as usize]);
            (b - a).cross(c - a).dot(light - (a + b + c) / 3.0) > 0.0
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
        EdgeSource::Silhouettes => caster
            .adjacency
            .edges
            .iter()
            .filter_map(|e| {
                let lit = |f: u32| f != NO_FACE && facing[f as usize];
                let [f0, f1] = e.faces;
                match (lit(f0), lit(f1)) {
                    (true, false) => Some((e.vertices, third(f0, e.vertices))),
                    (false, true) => Some((e.vertices, third(f1, e.vertices))),
                    _ => None,
                }
            })
            .collect(),
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
