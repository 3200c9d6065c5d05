//! Triangle meshes: welded positions for topology, split vertices for rendering.

use std::collections::HashMap;
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::Vec3;

use crate::error::{Error, Result};
use crate::geometry::{Aabb, EdgeAdjacency};

/// Identifies a mesh for the GPU cache; unique for the life of the process.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct MeshId(u64);

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
    pub bounds: Aabb,
}

impl Mesh {
    /// Builds a mesh from positions and triangles, welding identical positions.
    pub fn new(name: impl Into<String>, positions: Vec<Vec3>, triangles: Vec<[u32; 3]>) -> Result<Self> {
        let name = name.into();
        let invalid = |what: String| Error::Invalid(format!("mesh {name}: {what}"));
        if triangles.is_empty() {
            return Err(invalid("has no triangles".into()));
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(invalid(format!("vertex {i} is not a finite number")));
        }
        if let Some(t) = triangles.iter().position(|t| t.iter().any(|&v| v as usize >= positions.len())) {
            return Err(invalid(format!("triangle {t} indexes past the {} vertices", positions.len())));
        }
        let (positions, triangles) = weld(&positions, &triangles);
        let bounds = Aabb::from_points(positions.iter().copied());
        let adjacency = EdgeAdjacency::build(&triangles);
        static NEXT: AtomicU64 = AtomicU64::new(0);
        let id = MeshId(NEXT.fetch_add(1, Ordering::Relaxed));
        Ok(Mesh { id, name, positions, triangles, adjacency, bounds })
    }

    /// Loads every object of an OBJ file into one mesh (triangulated).
    pub fn load_obj(path: &Path) -> Result<Self> {
        let options = tobj::LoadOptions { triangulate: true, single_index: false, ..Default::default() };
        let (models, _materials) = tobj::load_obj(path, &options).map_err(|e| match e {
            tobj::LoadError::OpenFileFailed | tobj::LoadError::ReadError => {
                Error::scene(path, "cannot open or read the mesh file")
            }
            other => Error::scene(path, format!("not a valid OBJ file: {other}")),
        })?;
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
        Mesh::new(path.display().to_string(), positions, triangles).map_err(|e| Error::scene(path, e.to_string()))
    }

    pub fn id(&self) -> MeshId {
        self.id
    }

    /// Unnormalised face normal (length = twice the area); zero for a degenerate triangle.
    pub fn face_normal(&self, face: usize) -> Vec3 {
        let [a, b, c] = self.triangles[face].map(|i| self.positions[i as usize]);
        (b - a).cross(c - a)
    }

    /// Vertices and indices for drawing: normals averaged across smooth edges and split across
    /// creases sharper than 40°, so boxes stay faceted and spheres smooth from one code path.
    pub fn render_geometry(&self) -> (Vec<Vertex>, Vec<u32>) {
        let face_normals: Vec<Vec3> = (0..self.triangles.len()).map(|f| self.face_normal(f)).collect();
        let mut faces_at: Vec<Vec<u32>> = vec![Vec::new(); self.positions.len()];
        for (f, tri) in self.triangles.iter().enumerate() {
            for &v in tri {
                faces_at[v as usize].push(f as u32);
            }
        }
        let mut vertices = Vec::new();
        let mut indices = Vec::with_capacity(self.triangles.len() * 3);
        let mut lookup: HashMap<(u32, [u32; 3]), u32> = HashMap::new();
        for (f, tri) in self.triangles.iter().enumerate() {
            let own = face_normals[f].normalize_or_zero();
            for &v in tri {
                let sum: Vec3 = faces_at[v as usize]
                    .iter()
                    .map(|&g| face_normals[g as usize])
                    .filter(|n| n.normalize_or_zero().dot(own) >= CREASE_COS)
                    .sum();
                // A degenerate fan has no direction; any unit normal keeps the shader NaN-free.
                let normal = sum.try_normalize().or(own.try_normalize()).unwrap_or(Vec3::Y);
                let key = (v, normal.to_array().map(f32::to_bits));
                let index = *lookup.entry(key).or_insert_with(|| {
                    vertices
                        .push(Vertex { position: self.positions[v as usize].to_array(), normal: normal.to_array() });
                    vertices.len() as u32 - 1
                });
                indices.push(index);
            }
        }
        (vertices, indices)
    }
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
