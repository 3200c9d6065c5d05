//! The shadow volumes built on the GPU (`gpu_silhouettes = 1`), beyond the papers, which find
//! silhouettes on the host: per light point, one compute dispatch per caster
//! (`glsl/shadow_volume/silhouettes.comp`) extracts the silhouette edges, extrudes them and
//! emits the caps into one vertex buffer, in the ranges of three indirect draws per caster
//! group (sides, caps, turned caps), which the counting passes draw. The vertices are the CPU
//! path's, and so is the facing test (the mesh's face planes against the light taken into
//! object space on the host, the same operations in the same order), so the counts, and V, are
//! the same. Each mesh's positions, triangles, edges and face planes are uploaded once, while
//! it is drawn; the vertex buffer and the draw commands hold one copy of one point's volumes,
//! rebuilt for the next. With one point (hard shadows) they are kept while neither the casters nor the light
//! moved: a static scene records no silhouette work after its first frame. Accumulating
//! several points rebuilds each one's every frame (one point's volumes of a 100k-triangle
//! caster take tens of megabytes).

use ash::vk;
use bytemuck::{Pod, cast_slice};
use glam::{Mat4, Vec3, Vec4};
use gpu_allocator::MemoryLocation;

use crate::error::Result;
use crate::frame::FrameInputs;
use crate::frame::interface::VolumeParams;
use crate::geometry::NO_FACE;
use crate::geometry::silhouette::FacePlanes;
use crate::gpu::{
    Buffer, BufferAccess, Context, DRAW_COMMAND_BYTES, Descriptor, PerFrame, Pipeline, UploadMark, Uploads,
    buffer_barrier, copy_buffer, dispatch, draw_indirect, shaders, upload,
};
use crate::scene::{Mesh, MeshId};
use crate::shader_constants::{COMPUTE_GROUP, VOLUME_VERTEX_FLOATS};

const PARAMS_BYTES: u64 = std::mem::size_of::<VolumeParams>() as u64;
/// Bytes per volume vertex: position, at infinity, object (as the CPU path's).
const VERTEX_BYTES: u64 = 4 * VOLUME_VERTEX_FLOATS as u64;
/// Draws per caster group and point: sides, caps, turned caps.
pub const PARTS: usize = 3;

/// One mesh on the GPU: positions, triangles, edges and face planes in one buffer, and the
/// most vertices each part of its volume can take.
struct MeshData {
    buffer: Buffer,
    triangles_at: u32,
    edges_at: u32,
    planes_at: u32,
    triangles: u32,
    edges: u32,
    most: [u32; PARTS],
}

impl MeshData {
    /// The mesh's data, its upload recorded into `cmd`.
    fn new(ctx: &Context, cmd: vk::CommandBuffer, mesh: &Mesh) -> Result<Self> {
        let edges = &mesh.adjacency.edges;
        let mut data: Vec<[u32; 4]> = mesh.positions.iter().map(|p| [p.x, p.y, p.z, 0.0].map(f32::to_bits)).collect();
        let triangles_at = data.len() as u32;
        data.extend(mesh.triangles.iter().map(|t| [t[0], t[1], t[2], 0]));
        let edges_at = data.len() as u32;
        data.extend(edges.iter().map(|e| [e.vertices[0], e.vertices[1], e.faces[0], e.faces[1]]));
        let planes_at = data.len() as u32;
        data.extend((0..mesh.triangles.len()).map(|f| mesh.planes.plane(f).to_array().map(f32::to_bits)));
        let buffer = upload(ctx, cmd, "volume mesh", cast_slice(&data), vk::BufferUsageFlags::STORAGE_BUFFER)?;
        // An edge is extruded once per face on it, at most; a triangle gives a dark and a light
        // cap, or a dark and a turned one.
        let faces: u32 = edges.iter().map(|e| e.faces.iter().filter(|&&f| f != NO_FACE).count() as u32).sum();
        let triangles = mesh.triangles.len() as u32;
        Ok(MeshData {
            buffer,
            triangles_at,
            edges_at,
            planes_at,
            triangles,
            edges: edges.len() as u32,
            most: [6 * faces, 6 * triangles, 3 * triangles],
        })
    }
}

/// One caster's dispatch: its mesh (in `meshes`), its scene object, its group, and whether it
/// takes the two-sided construction.
struct Dispatch {
    mesh: usize,
    id: MeshId,
    object: usize,
    group: usize,
    two_sided: bool,
}

pub struct GpuVolumes {
    pipeline: Pipeline,
    meshes: Uploads<MeshId, MeshData>,
    params: Option<PerFrame>,
    /// The draw commands as the dispatches start them (no vertex yet), copied into `commands`
    /// before they run.
    starts: Option<PerFrame>,
    /// The draw commands the dispatches count into and the counting passes draw.
    commands: Option<Buffer>,
    vertices: Option<Buffer>,
    dispatches: Vec<Dispatch>,
    groups: usize,
    /// Bytes of this frame's draw commands.
    command_bytes: u64,
    /// What the kept volumes were built from, and when ([`Context::upload_kept`] says whether
    /// that frame ran).
    built: Option<(BuildKey, UploadMark)>,
    /// Whether this frame builds the volumes, or draws the kept ones.
    building: bool,
}

/// Everything the built volumes depend on: per dispatch its mesh, transform, group, two-sided
/// construction and object index; the light points; the buffers they were built into.
#[derive(Clone, Debug, PartialEq)]
struct BuildKey {
    casters: Vec<(MeshId, Mat4, usize, bool, u32)>,
    points: Vec<Vec3>,
    buffers: [vk::Buffer; 2],
}

impl GpuVolumes {
    pub fn new(ctx: &Context) -> Result<Self> {
        let pipeline = Pipeline::compute(ctx, "silhouettes", &shaders::SHADOW_VOLUME_SILHOUETTES_COMP, &[])?;
        Ok(GpuVolumes {
            pipeline,
            meshes: Uploads::new(|m, ctx| m.buffer.destroy(ctx)),
            params: None,
            starts: None,
            commands: None,
            vertices: None,
            dispatches: Vec::new(),
            groups: 0,
            command_bytes: 0,
            built: None,
            building: true,
        })
    }

    /// Lays out this frame's volumes: for every point and caster of `groups` (scene object
    /// indices, each with the mesh it casts from and whether that takes the two-sided
    /// construction) its params, for every point and group its three draw commands, each range
    /// sized for the most it can take; decides whether this frame builds them
    /// ([`Self::building`]).
    pub fn prepare(
        &mut self,
        frame: &FrameInputs<'_>,
        points: &[Vec3],
        groups: &[Vec<(usize, &Mesh, bool)>],
    ) -> Result<()> {
        let ctx = frame.ctx;
        self.dispatches.clear();
        self.groups = groups.len();
        for (g, group) in groups.iter().enumerate() {
            for &(object, mesh, two_sided) in group {
                let at = self.meshes.index(ctx, mesh.id(), || MeshData::new(ctx, frame.cmd, mesh))?;
                self.dispatches.push(Dispatch { mesh: at, id: mesh.id(), object, group: g, two_sided });
            }
        }
        // One point's ranges, group by group: [first, end) of each part.
        let mut ranges = vec![[(0u32, 0u32); PARTS]; groups.len()];
        let mut end = 0u32;
        for (g, range) in ranges.iter_mut().enumerate() {
            for (k, part) in range.iter_mut().enumerate() {
                let most: u32 = self
                    .dispatches
                    .iter()
                    .filter(|d| d.group == g && (k < 2 || d.two_sided))
                    .map(|d| self.meshes.get(d.mesh).most[k])
                    .sum();
                *part = (end, end + most);
                end += most;
            }
        }
        let commands: Vec<[u32; 4]> =
            points.iter().flat_map(|_| ranges.iter().flatten().map(|&(first, _)| [0, 1, first, 0])).collect();
        let mut params = Vec::with_capacity(points.len() * self.dispatches.len());
        for (p, q) in points.iter().enumerate() {
            for d in &self.dispatches {
                let (mesh, object) = (&self.meshes.get(d.mesh), &frame.scene.objects[d.object]);
                let command = |k: usize| ((p * groups.len() + d.group) * PARTS + k) as u32;
                let [sides, caps, turned] = ranges[d.group];
                params.push(VolumeParams {
                    light: FacePlanes::object_light(&object.transform.matrix(), *q),
                    counts: [mesh.edges, mesh.triangles, d.two_sided as u32, frame.draws[d.object].instance],
                    offsets: [mesh.triangles_at, mesh.edges_at, mesh.planes_at, 0],
                    commands: [command(0), command(1), command(2), 0],
                    ends: [sides.1, caps.1, turned.1, 0],
                    pad: [Vec4::ZERO; 11],
                });
            }
        }
        self.command_bytes = (commands.len() as u64 * DRAW_COMMAND_BYTES).max(DRAW_COMMAND_BYTES);
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let usage = storage | vk::BufferUsageFlags::INDIRECT_BUFFER | vk::BufferUsageFlags::TRANSFER_DST;
        let commands_buffer = grow(ctx, &mut self.commands, "volume draws", self.command_bytes, usage)?;
        let bytes = (end.max(1) as u64 * VERTEX_BYTES).next_power_of_two();
        let usage = storage | vk::BufferUsageFlags::VERTEX_BUFFER;
        let vertices = grow(ctx, &mut self.vertices, "gpu shadow volumes", bytes, usage)?;
        let key = BuildKey {
            casters: self
                .dispatches
                .iter()
                .map(|d| {
                    let model = frame.scene.objects[d.object].transform.matrix();
                    (d.id, model, d.group, d.two_sided, frame.draws[d.object].instance)
                })
                .collect(),
            points: points.to_vec(),
            buffers: [commands_buffer, vertices],
        };
        // A lost frame ran neither its copies nor its dispatches.
        let kept = self.built.as_ref().is_some_and(|(k, at)| *k == key && ctx.upload_kept(*at));
        self.building = points.len() > 1 || !kept;
        if self.building {
            let uniform = vk::BufferUsageFlags::UNIFORM_BUFFER;
            write(ctx, &mut self.params, frame.slot, "volume params", uniform, &params)?;
            let source = vk::BufferUsageFlags::TRANSFER_SRC;
            write(ctx, &mut self.starts, frame.slot, "volume draw starts", source, &commands)?;
            self.built = Some((key, ctx.upload_mark()));
        }
        Ok(())
    }

    /// Whether this frame records the dispatches that build the volumes; if not, the counting
    /// passes draw the ones an earlier frame built.
    pub fn building(&self) -> bool {
        self.building
    }

    /// Records the dispatches that build point `p`'s volumes (after [`Self::prepare`], when
    /// [`Self::building`]).
    pub fn record(&self, frame: &FrameInputs<'_>, p: usize) -> Result<()> {
        let (ctx, cmd) = (frame.ctx, frame.cmd);
        let params = self.params.as_ref().expect("prepared").range(frame.slot);
        let commands = self.commands.as_ref().expect("prepared").range();
        let vertices = self.vertices.as_ref().expect("prepared").range();
        if p == 0 {
            // An earlier frame's draws read the commands: start them anew after those.
            buffer_barrier(ctx, cmd, BufferAccess::INDIRECT_DRAW, BufferAccess::TRANSFER_WRITE);
            let starts = self.starts.as_ref().expect("prepared").range(frame.slot);
            copy_buffer(ctx, cmd, starts, commands, self.command_bytes);
            buffer_barrier(ctx, cmd, BufferAccess::TRANSFER_WRITE, BufferAccess::COMPUTE_READ_WRITE);
        }
        // The previous point's draws, or an earlier frame's, read the same vertices.
        buffer_barrier(ctx, cmd, BufferAccess::INDIRECT_DRAW, BufferAccess::COMPUTE_READ_WRITE);
        for (i, d) in self.dispatches.iter().enumerate() {
            let mesh = &self.meshes.get(d.mesh);
            let one = vk::DescriptorBufferInfo {
                buffer: params.buffer,
                offset: params.offset + (p * self.dispatches.len() + i) as u64 * PARAMS_BYTES,
                range: PARAMS_BYTES,
            };
            let inputs = [
                Descriptor::Buffer(one),
                Descriptor::Buffer(mesh.buffer.range()),
                Descriptor::Buffer(commands),
                Descriptor::Buffer(vertices),
            ];
            self.pipeline.bind(ctx, cmd, &inputs)?;
            dispatch(ctx, cmd, mesh.edges.max(mesh.triangles).div_ceil(COMPUTE_GROUP));
        }
        buffer_barrier(ctx, cmd, BufferAccess::COMPUTE_READ_WRITE, BufferAccess::INDIRECT_DRAW);
        Ok(())
    }

    /// Draws part `part` (0 sides, 1 caps, 2 turned caps) of group `g` of point `p`'s volumes
    /// with the bound pipeline.
    pub fn draw(&self, frame: &FrameInputs<'_>, p: usize, g: usize, part: usize) {
        let commands = self.commands.as_ref().expect("prepared").range();
        let command = vk::DescriptorBufferInfo {
            buffer: commands.buffer,
            offset: commands.offset + ((p * self.groups + g) * PARTS + part) as u64 * DRAW_COMMAND_BYTES,
            range: DRAW_COMMAND_BYTES,
        };
        let vertices = self.vertices.as_ref().expect("prepared").range();
        draw_indirect(frame.ctx, frame.cmd, vertices, command);
    }

    pub fn destroy(self, ctx: &Context) {
        self.pipeline.destroy(ctx);
        self.meshes.destroy(ctx);
        self.params.into_iter().chain(self.starts).for_each(|b| b.destroy(ctx));
        self.commands.into_iter().chain(self.vertices).for_each(|b| b.destroy(ctx));
    }
}

/// The buffer in `slot`, replaced by one of at least `bytes` (a power of two) when smaller.
fn grow(
    ctx: &Context,
    slot: &mut Option<Buffer>,
    name: &str,
    bytes: u64,
    usage: vk::BufferUsageFlags,
) -> Result<vk::Buffer> {
    if slot.as_ref().is_none_or(|b| b.range().range < bytes) {
        if let Some(old) = slot.take() {
            ctx.retire(move |ctx| old.destroy(ctx));
        }
        *slot = Some(Buffer::new(ctx, name, bytes.next_power_of_two(), usage, MemoryLocation::GpuOnly)?);
    }
    Ok(slot.as_ref().expect("made").range().buffer)
}

/// Writes `items` into this frame's copy of `slot`, grown to hold them.
fn write<T: Pod>(
    ctx: &Context,
    slot: &mut Option<PerFrame>,
    frame: usize,
    name: &str,
    usage: vk::BufferUsageFlags,
    items: &[T],
) -> Result<()> {
    let bytes: &[u8] = cast_slice(items);
    PerFrame::ensure(ctx, slot, name, bytes.len().max(16) as u64, usage)?.write(frame, bytes);
    Ok(())
}
