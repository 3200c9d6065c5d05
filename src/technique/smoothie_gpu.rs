//! The smoothie's silhouettes on the GPU (`gpu_silhouettes = 1`), beyond the paper, whose
//! hardware could not feed a shader's output back into a vertex array (§6): one compute
//! invocation per edge finds silhouettes and pairs the edge ends at each silhouette vertex, then
//! one more appends smoothie edges and corners (`glsl/smoothie/silhouettes.comp`); the smoothie
//! pass draws them with five indirect draws, the outer smoothies and the inner quads apart, each
//! away from the hard shadow's corners and near them, and the partial silhouettes' inner quads.
//! Each
//! mesh's positions, triangles, edges and per-vertex stamped slots are uploaded once, while it
//! is drawn. The output (one copy, not one per frame in flight) is only recomputed when a
//! caster, the light view or the smoothie size changed: a static scene records no silhouette
//! work after its first frame.

use std::sync::Arc;

use ash::vk;
use bytemuck::{bytes_of, cast_slice};
use glam::{Mat4, Vec4};

use super::smoothie::penumbra;
use crate::error::Result;
use crate::frame::FrameInputs;
use crate::frame::interface::SilhouetteParams;
use crate::geometry::plateau::MIN_TURN;
use crate::geometry::silhouette::PARTIAL_GAIN;
use crate::geometry::smoothie::{
    CORNER_REACH, CutGrid, PIECE_MARGIN, Penumbra, ReceiverBound, SHARPEST_TURN, SmoothieSize,
};
use crate::gpu::{
    Buffer, BufferAccess, Context, DRAW_COMMAND_BYTES, Descriptor, FRAMES_IN_FLIGHT, PerFrame, Pipeline, UploadMark,
    Uploads, Variants, buffer_barrier, dispatch, shaders, update_buffer, upload,
};
use crate::scene::{Mesh, MeshId, Object};
use crate::shader_constants::{COMPUTE_GROUP, STAGE_DRAW, STAGE_OWN, STAGE_PAIR, STAMP_WORDS};

const PARAMS_BYTES: u64 = std::mem::size_of::<SilhouetteParams>() as u64;
/// Bytes per smoothie vertex ([`crate::geometry::smoothie::SmoothieVertex`]).
const VERTEX_BYTES: u64 = std::mem::size_of::<crate::geometry::smoothie::SmoothieVertex>() as u64;
/// Five `VkDrawIndirectCommand`s, one per part of the smoothie pass (`smoothie.rs`'s `Part::INDIRECT`):
/// the outer smoothies', away from the hard shadow's corners and near them, the inner quads'
/// alike, then the partial silhouettes' inner quads.
const DRAWS_BYTES: u64 = 5 * DRAW_COMMAND_BYTES;

/// One mesh's connectivity on the GPU.
struct MeshBuffers {
    positions: Buffer,
    triangles: Buffer,
    edges: Buffer,
    stamps: Buffer,
    edge_count: u32,
}

impl MeshBuffers {
    /// The mesh's buffers, their uploads recorded into `cmd`.
    fn new(ctx: &Context, cmd: vk::CommandBuffer, mesh: &Mesh) -> Result<Self> {
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let positions: Vec<Vec4> = mesh.positions.iter().map(|p| p.extend(1.0)).collect();
        let triangles: Vec<[u32; 4]> = mesh.triangles.iter().map(|t| [t[0], t[1], t[2], 0]).collect();
        let edges: Vec<[u32; 4]> =
            mesh.adjacency.edges.iter().map(|e| [e.vertices[0], e.vertices[1], e.faces[0], e.faces[1]]).collect();
        // Per vertex: its stamped edge-end count, its first two edge ends and its own corner.
        let stamps = vec![0u32; STAMP_WORDS as usize * mesh.positions.len()];
        let mut made: Vec<Buffer> = Vec::new();
        for (name, bytes) in [
            ("silhouette positions", cast_slice::<Vec4, u8>(&positions)),
            ("silhouette triangles", cast_slice(&triangles)),
            ("silhouette edges", cast_slice(&edges)),
            ("silhouette stamps", cast_slice(&stamps)),
        ] {
            match upload(ctx, cmd, name, bytes, storage) {
                Ok(b) => made.push(b),
                Err(e) => {
                    made.into_iter().for_each(|b| b.destroy(ctx));
                    return Err(e);
                }
            }
        }
        let [positions, triangles, edges, stamps] = <[Buffer; 4]>::try_from(made).ok().expect("four buffers");
        Ok(MeshBuffers { positions, triangles, edges, stamps, edge_count: mesh.adjacency.edges.len() as u32 })
    }

    fn destroy(self, ctx: &Context) {
        for b in [self.positions, self.triangles, self.edges, self.stamps] {
            b.destroy(ctx);
        }
    }
}

/// The compute path's pipeline and buffers.
pub struct GpuSilhouettes {
    /// The silhouette pipelines, by whether the smoothie size is physical and the dispatch's
    /// stage (silhouettes.comp's STAGE: pairing edge ends, finding corners, drawing).
    pipelines: Variants<(bool, u32)>,
    meshes: Uploads<MeshId, MeshBuffers>,
    params: Option<PerFrame>,
    vertices: Option<PerFrame>,
    args: PerFrame,
    stamp: u32,
    /// What the output was last computed from, and when ([`Context::upload_kept`] says whether
    /// that frame ran); `None` when it must be computed.
    computed: Option<(OutputKey, UploadMark)>,
}

/// Everything the silhouette output depends on.
#[derive(Clone, Debug, PartialEq)]
struct OutputKey {
    casters: Vec<(MeshId, Mat4)>,
    size: [f32; 4],
    ground: Vec4,
    centred: bool,
    /// The light's radius, centred (partial silhouettes); 0 outer only.
    partial_radius: f32,
    /// The buffer's grid, which the cut quads' pieces reach past their cuts by ([`Penumbra::Centred`]).
    grid: CutGrid,
    capacity: u64,
}

impl GpuSilhouettes {
    pub fn new(ctx: &Context) -> Result<Self> {
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::INDIRECT_BUFFER
            | vk::BufferUsageFlags::TRANSFER_DST;
        let args = PerFrame::new(ctx, "smoothie draws", DRAWS_BYTES, FRAMES_IN_FLIGHT, usage)?;
        Ok(GpuSilhouettes {
            pipelines: Variants::default(),
            meshes: Uploads::new(MeshBuffers::destroy),
            params: None,
            vertices: None,
            args,
            stamp: 0,
            computed: None,
        })
    }

    /// Records the silhouette dispatches of every caster seen through `view`, each from the mesh
    /// `cast` gives its scene object (the shadow mesh the map is drawn from, as on the CPU path);
    /// returns the vertex buffer and the arguments of the smoothie pass's five indirect draws
    /// ([`DRAWS_BYTES`]).
    pub fn record(
        &mut self,
        frame: &mut FrameInputs<'_>,
        cast: &[Option<Arc<Mesh>>],
        view: &Mat4,
        (size, receivers): (SmoothieSize, ReceiverBound),
        (centred, light_radius, grid): (bool, f32, CutGrid),
    ) -> Result<(vk::DescriptorBufferInfo, vk::DescriptorBufferInfo)> {
        let ctx = frame.ctx;
        let casters: Vec<Object> = (frame.scene.objects.iter().zip(cast))
            .filter_map(|(o, mesh)| Some(Object { mesh: mesh.clone()?, ..o.clone() }))
            .collect();
        let cmd = frame.cmd;
        let meshes = casters
            .iter()
            .map(|o| self.meshes.index(ctx, o.mesh.id(), || MeshBuffers::new(ctx, cmd, &o.mesh)))
            .collect::<Result<Vec<_>>>()?;
        // Per edge, outer only, a quad of six vertices; centred, up to three pieces of its quad
        // (`ShadowCorner::piece`), each with a sliver of six, or a partial silhouette's two quads,
        // and as many of its inner quad; at most three quads per corner. As many for each kind
        // in its third of the buffer (centred: the inner quads', the partial silhouettes' inner
        // quads').
        let per_edge = if centred { 3 * (6 + 6) } else { 6 };
        // That bound is every edge a silhouette with a corner at both ends; a silhouette is a
        // small part of a mesh's edges, and the output is bound as one storage buffer, which may
        // hold no more than maxStorageBufferRange (128 MiB on lavapipe, which the bound of a full
        // 20 000-triangle knot passes): no more than that, the shader drops what would not fit.
        let kinds = 1 + 2 * u64::from(centred);
        let most = u64::from(ctx.info.max_storage_buffer_range) / (kinds * VERTEX_BYTES);
        let capacity: u64 = casters
            .iter()
            .map(|o| (per_edge * o.mesh.adjacency.edges.len() + 6 * 3 * o.mesh.positions.len()) as u64)
            .sum::<u64>()
            .clamp(1, most);
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        PerFrame::ensure(
            ctx,
            &mut self.vertices,
            "smoothies",
            kinds * capacity * VERTEX_BYTES,
            storage | vk::BufferUsageFlags::VERTEX_BUFFER,
        )?;
        let params_bytes = casters.len().max(1) as u64 * PARAMS_BYTES;
        PerFrame::ensure(ctx, &mut self.params, "silhouette params", params_bytes, storage)?;

        let partial_radius = if centred { light_radius } else { 0.0 };
        let (scale, behind, physical) = match size {
            SmoothieSize::Physical { light_radius, scale, behind } => (light_radius * scale, behind, true),
            SmoothieSize::Fixed(t) => (t, 0.0, false),
        };
        // Slot 0 holds the one copy of the output (earlier frames may still draw from it: the
        // barriers below order this frame's writes after their reads).
        let (vertices, args) = (self.vertices.as_ref().expect("ensured").range(0), self.args.range(0));
        let vertices = vk::DescriptorBufferInfo { range: kinds * capacity * VERTEX_BYTES, ..vertices };
        let args = vk::DescriptorBufferInfo { range: DRAWS_BYTES, ..args };
        let far = receivers.far;
        let ground = receivers.ground.map_or(Vec4::ZERO, |g| g.extend(1.0));
        let key = OutputKey {
            casters: casters.iter().map(|o| (o.mesh.id(), *view * o.transform.matrix())).collect(),
            size: [scale, f32::from(u8::from(physical)), far, behind],
            ground,
            centred,
            partial_radius,
            grid,
            capacity: self.vertices.as_ref().expect("ensured").capacity(),
        };
        // A lost frame ran neither its uploads nor its dispatches.
        if self.computed.as_ref().is_some_and(|(k, at)| *k == key && ctx.upload_kept(*at)) {
            return Ok((vertices, args));
        }
        let mut params = Vec::with_capacity(casters.len());
        for (number, o) in (1..).zip(&casters) {
            self.stamp = self.stamp.wrapping_add(1).max(1);
            let model = o.transform.matrix();
            let (near, caster_far) = match penumbra(centred, grid, &(*view * model), &o.mesh.bounds) {
                Penumbra::Centred { near, far, .. } => (near, far),
                Penumbra::Outer => (0.0, 0.0),
            };
            params.push(SilhouetteParams {
                model_view: *view * model,
                size: Vec4::new(scale, near, far, caster_far),
                counts: [o.mesh.adjacency.edges.len() as u32, self.stamp, capacity as u32, centred as u32],
                light: Vec4::new(behind, (number % 2) as f32, partial_radius, PARTIAL_GAIN),
                ground,
                corners: Vec4::new(MIN_TURN, CORNER_REACH, SHARPEST_TURN, PIECE_MARGIN),
                cuts: Vec4::new(grid.texel, grid.sliver, 0.0, 0.0),
                pad: [Vec4::ZERO; 6],
            });
        }
        let params_buffer = self.params.as_mut().expect("ensured");
        params_buffer.write(frame.slot, cast_slice(&params));
        let params_range = params_buffer.range(frame.slot);

        let cmd = frame.cmd;
        frame.timer.begin(ctx, cmd, "silhouettes");
        // Earlier frames' draws read the output, and their dispatches stamped the same meshes:
        // finish both before this frame's.
        buffer_barrier(ctx, cmd, BufferAccess::INDIRECT_DRAW, BufferAccess::TRANSFER_WRITE);
        buffer_barrier(ctx, cmd, BufferAccess::COMPUTE_READ_WRITE, BufferAccess::TRANSFER_WRITE);
        // No vertices yet: each third of the buffer holds one kind, the outer smoothies, the
        // inner quads and the partial silhouettes' inner quads, those away from corners appended
        // from its start, those near them from its end back (silhouettes.comp's quad).
        let cap = capacity as u32;
        let draws = [0, cap, cap, 2 * cap, 2 * cap].map(|first| [0, 1, first, 0]);
        update_buffer(ctx, cmd, args, bytes_of(&draws));
        buffer_barrier(ctx, cmd, BufferAccess::TRANSFER_WRITE, BufferAccess::COMPUTE_READ_WRITE);
        for (i, &at) in meshes.iter().enumerate() {
            let mesh = self.meshes.get(at);
            let one = vk::DescriptorBufferInfo {
                buffer: params_range.buffer,
                offset: params_range.offset + i as u64 * PARAMS_BYTES,
                range: PARAMS_BYTES,
            };
            for stage in [STAGE_PAIR, STAGE_OWN, STAGE_DRAW] {
                let pipeline = self.pipelines.get((physical, stage), |&(physical, stage)| {
                    let constants = [("PHYSICAL_SIZE", physical as u32), ("STAGE", stage)];
                    Pipeline::compute(ctx, "silhouettes", &shaders::SMOOTHIE_SILHOUETTES_COMP, &constants)
                })?;
                pipeline.bind(
                    ctx,
                    cmd,
                    &[
                        Descriptor::Buffer(one),
                        Descriptor::Buffer(mesh.positions.range()),
                        Descriptor::Buffer(mesh.triangles.range()),
                        Descriptor::Buffer(mesh.edges.range()),
                        Descriptor::Buffer(mesh.stamps.range()),
                        Descriptor::Buffer(args),
                        Descriptor::Buffer(vertices),
                    ],
                )?;
                dispatch(ctx, cmd, mesh.edge_count.div_ceil(COMPUTE_GROUP));
                buffer_barrier(ctx, cmd, BufferAccess::COMPUTE_READ_WRITE, BufferAccess::COMPUTE_READ_WRITE);
            }
        }
        buffer_barrier(ctx, cmd, BufferAccess::COMPUTE_READ_WRITE, BufferAccess::INDIRECT_DRAW);
        frame.timer.end(ctx, cmd);
        self.computed = Some((key, ctx.upload_mark()));
        Ok((vertices, args))
    }

    pub fn destroy(self, ctx: &Context) {
        self.pipelines.destroy(ctx);
        self.meshes.destroy(ctx);
        self.params.into_iter().chain(self.vertices).for_each(|b| b.destroy(ctx));
        self.args.destroy(ctx);
    }
}
