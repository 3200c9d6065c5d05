//! Triangle meshes: welded positions for topology, split vertices for rendering.

use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

use glam::Vec3;

use super::read::{MAX_OBJ_BYTES, MAX_OBJ_LINE, overlong_line, read_limited};
use crate::error::{Error, Result};
use crate::geometry::silhouette::FacePlanes;
use crate::geometry::{Aabb, EdgeAdjacency};

/// Identifies a mesh for the GPU cache; unique for the life of the process.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId(u64);

/// The most triangles a mesh may have: ten times the largest model the suite measures.
pub const MAX_TRIANGLES: usize = 1 << 24;

/// Normals of faces meeting at a vertex at more than this angle stay split (hard edges).
const CREASE_COS: f32 = 0.766; // cos 40°: keeps box and cylinder rims sharp, spheres smooth

/// A vertex as the GPU reads it (`location 0` position, `location 1` normal).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
}

/// A closed or open triangle mesh in object space.
#[derive(Debug)]
pub struct Mesh {
    id: MeshId,
    /// Where it came from, for messages.
    pub name: String,
    /// Welded positions: one per distinct point, so edges are shared between faces.
    pub positions: Vec<Vec3>,
    /// Counter-clockwise triangles (outward normals) into `positions`.
    pub triangles: Vec<[u32; 3]>,
    /// Built once here; silhouettes walk it every frame.
    pub adjacency: EdgeAdjacency,
    /// Built once here; silhouettes test the light against them every frame.
    pub planes: FacePlanes,
    pub bounds: Aabb,
    /// Simplified copies made by [`Mesh::shadow_mesh`], by their error's power of two.
    shadow_meshes: Mutex<Vec<(i32, Arc<Mesh>)>>,
}

impl Mesh {
    /// Builds a mesh from positions and triangles, welding identical positions.
    pub fn new(name: impl Into<String>, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        let name = name.into();
        Mesh::build(name.clone(), positions, triangles).map_err(|what| Error::Invalid(format!("mesh {name}: {what}")))
    }

    /// [`Mesh::new`], failing with the bare reason (callers name the mesh their own way).
    fn build(name: String, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> std::result::Result<Self, String> {
        if triangles.is_empty() {
            return Err("has no triangles".into());
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(format!("vertex {i} is not a finite number"));
        }
        if let Some(t) = triangles.iter().position(|t| t.iter().any(|&v| v as usize >= positions.len())) {
            return Err(format!("triangle {t} indexes past the {} vertices", positions.len()));
        }
        let (positions, mut triangles) = weld(&positions, &triangles);
        // Points, lines and faces of one or two corners arrive as triangles repeating a vertex:
        // they have no area and no edges of their own.
        let given = triangles.len();
        triangles.retain(|[a, b, c]| a != b && b != c && a != c);
        let has_area = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|i| positions[i as usize]);
            (b - a).cross(c - a) != Vec3::ZERO
        };
        if !triangles.iter().any(has_area) {
            return Err(format!(
                "none of its {given} faces has area ({} repeat a vertex: points, lines or faces of one or two corners)",
                given - triangles.len()
            ));
        }
        let bounds = Aabb::from_points(positions.iter().copied());
        let adjacency = EdgeAdjacency::build(&triangles);
        let planes = FacePlanes::new(&positions, &triangles);
        static NEXT: AtomicU64 = AtomicU64::new(0);
        let id = MeshId(NEXT.fetch_add(1, Ordering::Relaxed));
        Ok(Mesh { id, name, positions, triangles, adjacency, planes, bounds, shadow_meshes: Mutex::default() })
    }

    /// Loads every object of an OBJ file into one mesh (triangulated), within the limits of
    /// [`MAX_OBJ_BYTES`](super::MAX_OBJ_BYTES), [`MAX_OBJ_LINE`](super::MAX_OBJ_LINE) and
    /// [`MAX_TRIANGLES`]. Materials are not read: only the shape casts shadows.
    pub fn load_obj(path: &Path) -> Result<Self> {
        let bytes = read_limited(path, MAX_OBJ_BYTES, "mesh file")?;
        if let Some(line) = overlong_line(&bytes, MAX_OBJ_LINE) {
            return Err(Error::scene(path, format!("line {line} is longer than {MAX_OBJ_LINE} bytes")));
        }
        let text = String::from_utf8_lossy(&bytes);
        let shape = obj_shape(&text).map_err(|what| Error::scene(path, what))?;
        let options = tobj::LoadOptions { triangulate: true, single_index: false, ..Default::default() };
        let no_materials = |_: &Path| Err(tobj::LoadError::OpenFileFailed);
        let (models, _materials) = tobj::load_obj_buf(&mut shape.as_bytes(), &options, no_materials)
            .map_err(|e| Error::scene(path, format!("not a valid OBJ file: {e}")))?;
        let mut positions = Vec::new();
        let mut triangles = Vec::new();
        for model in &models {
            let base = positions.len() as u32;
            positions.extend(model.mesh.positions.chunks_exact(3).map(|p| Vec3::new(p[0], p[1], p[2])));
            triangles.extend(model.mesh.indices.chunks_exact(3).map(|t| [base + t[0], base + t[1], base + t[2]]));
        }
        if triangles.is_empty() {
            return Err(Error::scene(path, "the OBJ file holds no triangles"));
        }
        if triangles.len() > MAX_TRIANGLES {
            return Err(Error::scene(path, format!("{} triangles, more than {MAX_TRIANGLES}", triangles.len())));
        }
        Mesh::build(path.display().to_string(), positions, triangles).map_err(|what| Error::scene(path, what))
    }

    pub fn id(&self) -> MeshId {
        self.id
    }

    /// A simpler copy to cast shadows from, the DDJ's "separate shadowing and drawing models"
    /// (shadow models "considerably simpler"): meshoptimizer's simplifier (quadric error,
    /// borders locked so open meshes keep their outline) with every surface point within
    /// `error` (object units) of this mesh. `error` is rounded down to a power of two, so a caster
    /// moving closer or farther reuses a few cached copies. This mesh itself when `error` is not
    /// positive or the simplifier removes nothing.
    ///
    /// The simplifier can fold slivers into fins (two triangles back to back), which make their
    /// edges non-manifold: they are dropped, so the copy stays closed and its silhouettes closed
    /// loops. Kept, they sent the 100k-triangle knot at 2⁻⁹ and the 1M one at every error from
    /// 2⁻⁹ to 2⁻¹⁴ (2 to 13 edges shared by four faces, each a fin) back to the full mesh.
    pub fn shadow_mesh(self: &Arc<Self>, error: f32) -> Arc<Mesh> {
        if !(error > 0.0 && error.is_finite()) {
            return self.clone();
        }
        let exponent = error.log2().floor() as i32;
        let mut cache = self.shadow_meshes.lock().unwrap_or_else(|poisoned| poisoned.into_inner());
        if let Some((_, m)) = cache.iter().find(|(e, _)| *e == exponent) {
            return m.clone();
        }
        let indices: Vec<u32> = self.triangles.iter().flatten().copied().collect();
        let points: Vec<[f32; 3]> = self.positions.iter().map(|p| p.to_array()).collect();
        let options = meshopt::SimplifyOptions::LockBorder | meshopt::SimplifyOptions::ErrorAbsolute;
        let error = 2f32.powi(exponent);
        let kept = meshopt::simplify_decoder(&indices, &points, 0, error, options, None);
        let mut triangles = without_fins(kept.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect());
        let simpler = if triangles.len() < self.triangles.len() {
            let positions = used_positions(&self.positions, &mut triangles);
            let name = format!("{} (shadow, error {error})", self.name);
            // The simplifier keeps area within a finite error; should it not, or open a closed
            // mesh otherwise than by fins (large errors can), the full mesh casts.
            match Mesh::new(name, positions, triangles) {
                Ok(m) if m.adjacency.is_closed() || !self.adjacency.is_closed() => Arc::new(m),
                _ => self.clone(),
            }
        } else {
            self.clone()
        };
        cache.push((exponent, simpler.clone()));
        simpler
    }

    /// Unnormalised face normal (length = twice the area); zero for a degenerate triangle.
    pub fn face_normal(&self, face: usize) -> Vec3 {
        let [a, b, c] = self.triangles[face].map(|i| self.positions[i as usize]);
        (b - a).cross(c - a)
    }

    /// Vertices and indices for drawing: normals averaged across smooth edges and split across
    /// creases sharper than 40°, so boxes stay faceted and spheres smooth from one code path.
    /// The corners of the faces around a vertex that are joined by smooth edges share one
    /// normal, the area-weighted sum of their faces'; found with a union-find over corners, so
    /// the cost is linear in the triangles however many meet at a vertex.
    pub fn render_geometry(&self) -> (Vec<Vertex>, Vec<u32>) {
        let face_normals: Vec<Vec3> = (0..self.triangles.len()).map(|f| self.face_normal(f)).collect();
        let unit: Vec<Vec3> = face_normals.iter().map(|n| n.normalize_or_zero()).collect();
        let corner = |f: usize, v: u32| 3 * f + self.triangles[f].iter().position(|&u| u == v).expect("v is a corner");
        let mut faces_of_edge: HashMap<(u32, u32), Vec<usize>> = HashMap::new();
        for (f, tri) in self.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                faces_of_edge.entry((a.min(b), a.max(b))).or_default().push(f);
            }
        }
        let mut corners = UnionFind::new(3 * self.triangles.len());
        for ((a, b), faces) in &faces_of_edge {
            for pair in faces.windows(2) {
                let (f, g) = (pair[0], pair[1]);
                if unit[f].dot(unit[g]) >= CREASE_COS {
                    corners.union(corner(f, *a), corner(g, *a));
                    corners.union(corner(f, *b), corner(g, *b));
                }
            }
        }
        let mut sums = vec![Vec3::ZERO; 3 * self.triangles.len()];
        for c in 0..sums.len() {
            sums[corners.find(c)] += face_normals[c / 3];
        }
        let mut vertex_of = vec![u32::MAX; sums.len()];
        let mut vertices = Vec::new();
        let mut indices = Vec::with_capacity(self.triangles.len() * 3);
        for (f, tri) in self.triangles.iter().enumerate() {
            for (k, &v) in tri.iter().enumerate() {
                let root = corners.find(3 * f + k);
                if vertex_of[root] == u32::MAX {
                    // A degenerate fan has no direction; any unit normal keeps the shader NaN-free.
                    let normal = sums[root].try_normalize().or(unit[f].try_normalize()).unwrap_or(Vec3::Y);
                    vertices
                        .push(Vertex { position: self.positions[v as usize].to_array(), normal: normal.to_array() });
                    vertex_of[root] = vertices.len() as u32 - 1;
                }
                indices.push(vertex_of[root]);
            }
        }
        (vertices, indices)
    }
}

/// Disjoint sets of indices, with path halving.
struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind { parent: (0..n).collect() }
    }

    fn find(&mut self, mut i: usize) -> usize {
        while self.parent[i] != i {
            self.parent[i] = self.parent[self.parent[i]];
            i = self.parent[i];
        }
        i
    }

    fn union(&mut self, a: usize, b: usize) {
        let (a, b) = (self.find(a), self.find(b));
        if a != b {
            self.parent[a.max(b)] = a.min(b);
        }
    }
}

/// The shape of an OBJ file, checked line by line: vertices and the faces, lines and points
/// over them, each index in range, texture and normal references dropped (only the shape casts
/// shadows). What tobj then parses cannot overflow its index arithmetic, and a bad element is
/// reported at its line.
fn obj_shape(text: &str) -> std::result::Result<String, String> {
    let mut out = String::with_capacity(text.len());
    let mut vertices: i64 = 0;
    for (n, line) in text.lines().enumerate() {
        let at = |what: String| format!("line {}: {what}", n + 1);
        let mut words = line.split_whitespace();
        match words.next() {
            Some("v") => {
                let xyz: Vec<&str> = words.take(3).collect();
                if xyz.len() < 3 || xyz.iter().any(|w| w.parse::<f32>().is_err()) {
                    return Err(at(format!("a vertex needs three numbers, got `{}`", line.trim())));
                }
                vertices += 1;
                out.push_str(&format!("v {}\n", xyz.join(" ")));
            }
            Some(element @ ("f" | "l" | "p")) => {
                out.push_str(element);
                for word in words {
                    let position = word.split('/').next().unwrap_or_default();
                    // 1-based, or negative: counted back from the last vertex so far.
                    let index = position
                        .parse::<i64>()
                        .ok()
                        .filter(|i| (1..=vertices).contains(i) || (-vertices..0).contains(i));
                    let Some(index) = index else {
                        return Err(at(format!(
                            "`{word}` is not a vertex index in 1..={vertices} or -{vertices}..=-1"
                        )));
                    };
                    let absolute = if index < 0 { vertices + 1 + index } else { index };
                    out.push_str(&format!(" {absolute}"));
                }
                out.push('\n');
            }
            _ => {}
        }
    }
    Ok(out)
}

/// The positions `triangles` use, in order of first use; `triangles` renumbered into them.
fn used_positions(positions: &[Vec3], triangles: &mut [[u32; 3]]) -> Vec<Vec3> {
    let mut new = vec![u32::MAX; positions.len()];
    let mut used = Vec::new();
    for v in triangles.iter_mut().flatten() {
        if new[*v as usize] == u32::MAX {
            new[*v as usize] = used.len() as u32;
            used.push(positions[*v as usize]);
        }
        *v = new[*v as usize];
    }
    used
}

/// `triangles` without the fins the simplifier can fold a sliver into: two triangles on the same
/// corners facing opposite ways, with no inside, whose edges each had two more faces than a
/// closed surface gives them (non-manifold). Both go; the surface around them stays closed.
fn without_fins(triangles: Vec<[u32; 3]>) -> Vec<[u32; 3]> {
    // A triangle's corners from its smallest, which keeps its orientation.
    let key = |t: &[u32; 3]| {
        let first = (0..3).min_by_key(|&k| t[k]).expect("three corners");
        [t[first], t[(first + 1) % 3], t[(first + 2) % 3]]
    };
    let mut facing: HashMap<[u32; 3], usize> = HashMap::with_capacity(triangles.len());
    for t in &triangles {
        *facing.entry(key(t)).or_default() += 1;
    }
    let flipped = |t: &[u32; 3]| key(&[t[0], t[2], t[1]]);
    let fin = |t: &[u32; 3]| facing.get(&flipped(t)).is_some_and(|&n| n == facing[&key(t)]);
    triangles.iter().filter(|t| !fin(t)).copied().collect()
}

/// Merges bit-identical positions so faces share edges (OBJ files often repeat seam vertices).
fn weld(positions: &[Vec3], triangles: &[[u32; 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut first: HashMap<[u32; 3], u32> = HashMap::with_capacity(positions.len());
    let mut welded = Vec::with_capacity(positions.len());
    let remap: Vec<u32> = positions
        .iter()
        // +0.0 and -0.0 are the same point.
        .map(|p| (*p + Vec3::ZERO).to_array().map(f32::to_bits))
        .zip(positions)
        .map(|(key, p)| {
            *first.entry(key).or_insert_with(|| {
                welded.push(*p);
                welded.len() as u32 - 1
            })
        })
        .collect();
    let triangles = triangles.iter().map(|t| t.map(|v| remap[v as usize])).collect();
    (welded, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fins_go_in_pairs_and_nothing_else_does() {
        // A tetrahedron with a fin on its edge 0–1: the triangle 0 1 4 both ways round.
        let tetrahedron = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]];
        let with_fin = [&tetrahedron[..], &[[0, 1, 4], [4, 1, 0]]].concat();
        assert_eq!(without_fins(with_fin), tetrahedron);
        // The same corners facing the same way twice is no fin.
        let twice = vec![[0, 1, 4], [1, 4, 0]];
        assert_eq!(without_fins(twice.clone()), twice);
    }
}
