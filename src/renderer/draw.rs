//! The meshes behind the draw list: uploaded on first sight, dropped when no frame in flight
//! draws them.

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;
use bytemuck::cast_slice;

use crate::error::Result;
use crate::frame::Draw;
use crate::geometry::Aabb;
use crate::gpu::{Buffer, Context, upload};
use crate::scene::{Mesh, MeshId};

/// A mesh on the GPU.
pub struct GpuMesh {
    vertices: Buffer,
    indices: Buffer,
    index_count: u32,
    /// Frame number of the last frame that drew it.
    last_used: u64,
}

/// Meshes uploaded once and dropped when no frame in flight draws them any more.
#[derive(Default)]
pub struct MeshCache {
    meshes: HashMap<MeshId, GpuMesh>,
}

impl MeshCache {
    /// A draw of `mesh` in frame `frame`, uploading it on first sight.
    pub fn draw(
        &mut self,
        ctx: &Context,
        mesh: &Arc<Mesh>,
        frame: u64,
        instance: u32,
        bounds: Aabb,
        flags: (bool, bool),
    ) -> Result<Draw> {
        let gpu = match self.meshes.entry(mesh.id()) {
            std::collections::hash_map::Entry::Occupied(e) => e.into_mut(),
            std::collections::hash_map::Entry::Vacant(e) => {
                let (vertices, indices) = mesh.render_geometry();
                let vb = upload(ctx, &mesh.name, cast_slice(&vertices), vk::BufferUsageFlags::VERTEX_BUFFER)?;
                let ib = match upload(ctx, &mesh.name, cast_slice(&indices), vk::BufferUsageFlags::INDEX_BUFFER) {
                    Ok(b) => b,
                    Err(err) => {
                        vb.destroy(ctx);
                        return Err(err);
                    }
                };
                e.insert(GpuMesh { vertices: vb, indices: ib, index_count: indices.len() as u32, last_used: frame })
            }
        };
        gpu.last_used = frame;
        Ok(Draw {
            vertices: gpu.vertices.buffer,
            indices: gpu.indices.buffer,
            index_count: gpu.index_count,
            instance,
            casts: flags.0,
            receives: flags.1,
            bounds,
        })
    }

    /// Destroys meshes that no frame after `completed` uses (frames up to it have finished).
    pub fn evict(&mut self, ctx: &Context, completed: u64) {
        let stale: Vec<MeshId> =
            self.meshes.iter().filter(|(_, m)| m.last_used <= completed).map(|(id, _)| *id).collect();
        for id in stale {
            if let Some(m) = self.meshes.remove(&id) {
                m.vertices.destroy(ctx);
                m.indices.destroy(ctx);
            }
        }
    }

    pub fn destroy(mut self, ctx: &Context) {
        self.evict(ctx, u64::MAX);
    }
}
