//! The meshes behind the draw list: uploaded on first sight by copies recorded into the frame's
//! own command buffer (so an embedder's frame neither submits nor waits), dropped when no frame
//! in flight draws them.

use std::collections::HashMap;
use std::sync::Arc;

use ash::vk;
use bytemuck::cast_slice;

use crate::error::Result;
use crate::frame::Draw;
use crate::geometry::Aabb;
use crate::gpu::{Buffer, Context, upload_in};
use crate::scene::{Mesh, MeshId};

/// A mesh on the GPU.
pub struct GpuMesh {
    vertices: Buffer,
    indices: Buffer,
    index_count: u32,
    /// Frame number of the last frame that drew it.
    last_used: u64,
    /// The staging buffers its upload copied from, until the frame that copied has finished.
    staging: Vec<Buffer>,
    /// Frame number of the frame that uploaded it.
    uploaded_in: u64,
}

impl GpuMesh {
    fn destroy(self, ctx: &Context) {
        self.staging.into_iter().for_each(|b| b.destroy(ctx));
        self.vertices.destroy(ctx);
        self.indices.destroy(ctx);
    }
}

/// Meshes uploaded once and dropped when no frame in flight draws them any more.
#[derive(Default)]
pub struct MeshCache {
    meshes: HashMap<MeshId, GpuMesh>,
    /// Meshes uploaded by the frame being recorded, until it is submitted (or handed back to
    /// the embedder): a frame abandoned on an error never ran their copies.
    uncommitted: Vec<MeshId>,
    /// Those the frame committed last uploaded, in case the embedder discards it.
    committed: Vec<MeshId>,
}

impl MeshCache {
    /// A draw of `mesh` in frame `frame`, uploading it on first sight with copies recorded
    /// into `cmd`, the frame's command buffer, before its passes.
    #[allow(clippy::too_many_arguments)] // a draw's fields, and where and when it is drawn
    pub fn draw(
        &mut self,
        ctx: &Context,
        cmd: vk::CommandBuffer,
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
                let usage = vk::BufferUsageFlags::VERTEX_BUFFER;
                let (vb, vb_staging) = upload_in(ctx, cmd, &mesh.name, cast_slice(&vertices), usage)?;
                let usage = vk::BufferUsageFlags::INDEX_BUFFER;
                let (ib, ib_staging) = match upload_in(ctx, cmd, &mesh.name, cast_slice(&indices), usage) {
                    Ok(b) => b,
                    Err(err) => {
                        // The frame fails, and its command buffer is reset unsubmitted.
                        vb.destroy(ctx);
                        vb_staging.destroy(ctx);
                        return Err(err);
                    }
                };
                self.uncommitted.push(mesh.id());
                e.insert(GpuMesh {
                    vertices: vb,
                    indices: ib,
                    index_count: indices.len() as u32,
                    last_used: frame,
                    staging: vec![vb_staging, ib_staging],
                    uploaded_in: frame,
                })
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

    /// The frame that uploaded the uncommitted meshes was submitted.
    pub fn commit(&mut self) {
        self.committed = std::mem::take(&mut self.uncommitted);
    }

    /// The frame committed last was discarded unsubmitted: its uploads are uncommitted again.
    pub fn uncommit(&mut self) {
        self.uncommitted = std::mem::take(&mut self.committed);
    }

    /// Forgets meshes uploaded by a frame that was abandoned (its copies never ran); their
    /// buffers go at once, as nothing submitted uses them.
    pub fn drop_uncommitted(&mut self, ctx: &Context) {
        for id in std::mem::take(&mut self.uncommitted) {
            if let Some(m) = self.meshes.remove(&id) {
                m.destroy(ctx);
            }
        }
    }

    /// Destroys the staging buffers of uploads by frames up to `completed` (finished).
    pub fn release_staging(&mut self, ctx: &Context, completed: u64) {
        for m in self.meshes.values_mut().filter(|m| m.uploaded_in <= completed) {
            m.staging.drain(..).for_each(|b| b.destroy(ctx));
        }
    }

    /// Destroys meshes that no frame after `completed` uses (frames up to it have finished),
    /// and the staging buffers of uploads made by those frames.
    pub fn evict(&mut self, ctx: &Context, completed: u64) {
        self.release_staging(ctx, completed);
        let stale: Vec<MeshId> =
            self.meshes.iter().filter(|(_, m)| m.last_used <= completed).map(|(id, _)| *id).collect();
        for id in stale {
            if let Some(m) = self.meshes.remove(&id) {
                m.destroy(ctx);
            }
        }
    }

    pub fn destroy(mut self, ctx: &Context) {
        self.evict(ctx, u64::MAX);
    }
}
