//! The optional simplified shadow mesh per caster, the DDJ's "separate shadowing and drawing
//! models": the silhouette techniques find silhouettes on a simpler copy of each caster
//! ([`Mesh::shadow_mesh`]) while the camera still draws the full one, and draw their hard
//! shadows from it too ([`CasterMeshes`]: the plateau's umbra, the smoothie's map), so that hard
//! edge and penumbra come from one outline. The error bound is in texels of the light's view,
//! so a technique sets it where a texel is what it can show.

use std::sync::Arc;

use ash::vk;
use bytemuck::cast_slice;
use glam::Vec3;

use super::knobs::{Knob, Params};
use crate::error::Result;
use crate::frame::FrameInputs;
use crate::geometry::Aabb;
use crate::gpu::{Buffer, Context, Uploads, draw_indexed, upload};
use crate::scene::{Mesh, MeshId, Object};

/// Declared by each technique that casts from [`shadow_caster`].
pub const SHADOW_MESH_ERROR: Knob = Knob {
    name: "shadow_mesh_error",
    default: 0.0,
    min: 0.0,
    max: 64.0,
    integer: false,
    choices: &[],
    help: "shadows cast from a simplified caster straying at most this many texels of a 1024² light view fitted to it; 0: the full mesh",
};

/// [`SHADOW_MESH_ERROR`] for the silhouette techniques' soft shadows (plateau, smoothie): on by
/// default at one texel, which their penumbrae, many texels wide, cannot show. Fine meshes'
/// silhouettes zigzag at the scale of their triangles, and every turn costs cones, sheets and
/// smoothie corners (issue 18). Measured (bench, 512², lavapipe, one run, the full mesh → this):
/// the suite's penumbra RMSE unchanged to four places for both; on the scale scenes the plateau
/// frame 155 → 40 ms (hammer: 60k triangles, 1 250 in its shadow mesh), 117 → 62 (knot), 160 → 75
/// (koala: 100k, 7 952), penumbra RMSE within 0.002. The smoothie's map is cast from the copy
/// too (a later run, 20 frames): its frame 195 → 53 ms (hammer), 134 → 64 (knot), 219 → 91
/// (koala), its buffer 148 → 14, 71 → 19, 129 → 37 and its map 34 → 4.5 on the koala; penumbra
/// RMSE 0.001–0.003 *lower* than the full mesh's (hammer 0.069 → 0.066, knot 0.061 → 0.058),
/// the hard edge now being where its silhouettes are. `shadow_mesh_error=0` casts from the
/// full mesh.
pub const SOFT_SHADOW_MESH_ERROR: Knob = Knob { default: 1.0, ..SHADOW_MESH_ERROR };

/// Texels across the light's view of one caster that [`SHADOW_MESH_ERROR`] counts in.
pub const LIGHT_VIEW_TEXELS: f32 = 1024.0;

/// The world distance at `o` that subtends `texels` texels of a [`LIGHT_VIEW_TEXELS`]² view
/// from `light` fitted to the caster's bounding sphere, at the sphere's point nearest the light
/// (where a texel is smallest, so the bound holds for the whole caster); `None` for a light
/// inside the sphere.
pub fn texels_at_caster(o: &Object, light: Vec3, texels: f32) -> Option<f32> {
    let b = o.bounds();
    let (centre, radius) = ((b.min + b.max) * 0.5, (b.max - b.min).length() * 0.5);
    let distance = (centre - light).length();
    (distance > radius).then(|| {
        let texel_angle = 2.0 * (radius / distance).asin() / LIGHT_VIEW_TEXELS;
        texels * texel_angle * (distance - radius)
    })
}

/// The mesh `o` casts from: with [`SHADOW_MESH_ERROR`] set, the simplified one within that
/// many texels (converted through the largest scale to the mesh's own units); otherwise its
/// own.
pub fn shadow_mesh(o: &Object, light: Vec3, params: &Params) -> Arc<Mesh> {
    let texels = params.get(&SHADOW_MESH_ERROR) as f32;
    match if texels > 0.0 { texels_at_caster(o, light, texels) } else { None } {
        Some(world) => o.mesh.shadow_mesh(world / o.transform.scale.abs().max_element()),
        None => o.mesh.clone(),
    }
}

/// `o` as its shadow is cast: a copy whose mesh is [`shadow_mesh`]'s.
pub fn shadow_caster(o: &Object, light: Vec3, params: &Params) -> Object {
    Object { mesh: shadow_mesh(o, light, params), ..o.clone() }
}

/// A shadow mesh's vertices and indices, as the frame's own meshes are drawn.
struct MeshBuffers {
    vertices: Buffer,
    indices: Buffer,
    count: u32,
}

impl MeshBuffers {
    /// Uploads recorded into `cmd`.
    fn new(ctx: &Context, cmd: vk::CommandBuffer, mesh: &Mesh) -> Result<Self> {
        let (vertices, indices) = mesh.render_geometry();
        let vertex_buffer = upload(ctx, cmd, &mesh.name, cast_slice(&vertices), vk::BufferUsageFlags::VERTEX_BUFFER)?;
        match upload(ctx, cmd, &mesh.name, cast_slice(&indices), vk::BufferUsageFlags::INDEX_BUFFER) {
            Ok(index_buffer) => {
                Ok(MeshBuffers { vertices: vertex_buffer, indices: index_buffer, count: indices.len() as u32 })
            }
            Err(e) => {
                vertex_buffer.destroy(ctx);
                Err(e)
            }
        }
    }

    fn destroy(self, ctx: &Context) {
        self.vertices.destroy(ctx);
        self.indices.destroy(ctx);
    }
}

/// The frame's casters as a pass that casts their shadows draws them: each from the mesh its
/// shadow is cast from, the simplified one uploaded once (per mesh, while frames draw it) where
/// it is not the object's own.
pub struct CasterMeshes {
    uploads: Uploads<MeshId, MeshBuffers>,
    /// Per casting draw of this frame, in draw order: the upload it draws (`None`: its own
    /// mesh), and the world bounds of what it draws.
    chosen: Vec<(Option<usize>, Aabb)>,
}

impl Default for CasterMeshes {
    fn default() -> Self {
        CasterMeshes { uploads: Uploads::new(MeshBuffers::destroy), chosen: Vec::new() }
    }
}

impl CasterMeshes {
    /// Chooses this frame's meshes, `cast(i)` being the mesh scene object `i` casts from (`None`:
    /// its own), and records the uploads of new ones into the frame's command buffer: call it
    /// outside a render pass.
    pub fn prepare<'m>(
        &mut self,
        frame: &FrameInputs<'_>,
        cast: impl Fn(usize) -> Option<&'m Arc<Mesh>>,
    ) -> Result<()> {
        self.chosen.clear();
        for draw in frame.draws.iter().filter(|d| d.casts) {
            // A draw's instance is its object's index in the scene.
            let i = draw.instance as usize;
            let chosen = match (cast(i), frame.scene.objects.get(i)) {
                (Some(mesh), Some(o)) if !Arc::ptr_eq(mesh, &o.mesh) => {
                    let upload =
                        self.uploads.index(frame.ctx, mesh.id(), || MeshBuffers::new(frame.ctx, frame.cmd, mesh))?;
                    (Some(upload), mesh.bounds.transformed(&o.transform.matrix()))
                }
                _ => (None, draw.bounds),
            };
            self.chosen.push(chosen);
        }
        Ok(())
    }

    /// Records every caster as [`Self::prepare`] chose (inside a pass whose pipeline, of vertex
    /// input [`MESH_POSITIONS`](crate::frame::MESH_POSITIONS), is bound).
    pub fn record(&self, frame: &FrameInputs<'_>) {
        for (draw, (upload, _)) in frame.draws.iter().filter(|d| d.casts).zip(&self.chosen) {
            match upload.map(|u| self.uploads.get(u)) {
                Some(m) => {
                    draw_indexed(frame.ctx, frame.cmd, m.vertices.buffer, m.indices.buffer, m.count, draw.instance)
                }
                None => draw.record(frame.ctx, frame.cmd),
            }
        }
    }

    /// Whether any caster draws a simplified copy this frame.
    pub fn simplified(&self) -> bool {
        self.chosen.iter().any(|(upload, _)| upload.is_some())
    }

    /// The world bounds of what each casting draw draws, in draw order, as
    /// [`caster_bounds`](super::shadow_map::caster_bounds) gives the frame's own.
    pub fn bounds(&self) -> Vec<Aabb> {
        self.chosen.iter().map(|(_, bounds)| *bounds).collect()
    }

    pub fn destroy(self, ctx: &Context) {
        self.uploads.destroy(ctx);
    }
}
