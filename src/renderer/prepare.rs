//! What every frame prepares before its passes, whoever owns the command buffer: the draw list
//! and object buffer, the camera (the scene's, or the embedder's matrices), the frame globals
//! and the receivers in view.

use std::sync::Arc;

use ash::vk;
use bytemuck::{bytes_of, cast_slice};
use glam::{Mat4, Vec3, Vec4};

use super::draw::MeshCache;
use crate::error::Result;
use crate::frame::interface::{FrameGlobals, ObjectData};
use crate::frame::{Draw, FrameInputs, ShadowRole};
use crate::geometry::{Aabb, CameraProjection, Hexahedron, intersection_points};
use crate::gpu::{Context, FRAMES_IN_FLIGHT, Frame, PerFrame, Target};
use crate::scene::{Ground, Mesh, Scene};

const AMBIENT: f32 = 0.15;
const SKY: [f32; 3] = [0.55, 0.62, 0.72];
const GROUND_COLOR: Vec3 = Vec3::new(0.75, 0.75, 0.72);

/// The per-frame data an engine keeps between frames.
pub(super) struct FrameData {
    pub meshes: MeshCache,
    pub globals: Option<PerFrame>,
    pub objects: Option<PerFrame>,
    pub ground_mesh: Arc<Mesh>,
    /// Frames begun so far.
    pub number: u64,
}

/// One frame's draw list, camera and the ranges of its buffers.
pub(super) struct Prepared {
    pub draws: Vec<Draw>,
    pub camera: CameraProjection,
    pub globals: vk::DescriptorBufferInfo,
    pub objects: vk::DescriptorBufferInfo,
    pub receivers: Vec<Vec3>,
    /// Whether the last draw is the ground's.
    ground: bool,
}

impl FrameData {
    /// The frame prepared last was discarded unsubmitted: it is prepared again, uploads and
    /// all, by the next frame.
    pub fn discard_last(&mut self) {
        self.number -= 1;
        self.meshes.uncommit();
    }

    /// Prepares `frame` (its slot's previous frame has finished; new meshes are uploaded in its
    /// command buffer) at `extent`, seen by `camera`, or by the scene's camera fitted to the
    /// scene when `None`.
    pub fn prepare(
        &mut self,
        ctx: &Context,
        frame: &Frame<'_>,
        scene: &Scene,
        camera: Option<CameraProjection>,
        extent: vk::Extent2D,
    ) -> Result<Prepared> {
        self.meshes.drop_uncommitted(ctx);
        let slot = frame.slot;
        let number = self.number;
        self.number += 1;
        // The slot's previous frame, and so every frame up to `number - FRAMES_IN_FLIGHT`, is done.
        if let Some(completed) = number.checked_sub(FRAMES_IN_FLIGHT as u64) {
            self.meshes.evict(ctx, completed);
        }

        // Draw list: the scene's objects, then the ground.
        let mut objects = Vec::with_capacity(scene.objects.len() + 1);
        let mut draws = Vec::with_capacity(scene.objects.len() + 1);
        for o in &scene.objects {
            let model = o.transform.matrix();
            let bounds = o.mesh.bounds.transformed(&model);
            let instance = objects.len() as u32;
            draws.push(self.meshes.draw(ctx, frame.cmd, &o.mesh, number, instance, bounds, (o.casts, o.receives))?);
            objects.push(object_data(
                model,
                Mat4::from_mat3(o.normal_matrix()),
                o.color,
                ShadowRole::new(o.receives, o.casts),
            ));
        }
        if let Some(g) = &scene.ground {
            let model = ground_model(g);
            let instance = objects.len() as u32;
            draws.push(self.meshes.draw(
                ctx,
                frame.cmd,
                &self.ground_mesh,
                number,
                instance,
                g.bounds(),
                (false, true),
            )?);
            // The normal matrix's last column marks the ground as the exact plane y = height.
            let plane = Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::Z, Vec4::new(0.0, 1.0, 0.0, -g.height));
            objects.push(object_data(model, plane, GROUND_COLOR, ShadowRole::Receives));
        }
        let bytes: &[u8] = cast_slice(&objects);
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let object_buffer = PerFrame::ensure(ctx, &mut self.objects, "objects", bytes.len() as u64, usage)?;
        if !bytes.is_empty() {
            object_buffer.write(slot, bytes);
        }

        let (w, h) = (extent.width as f32, extent.height as f32);
        let camera = match camera {
            Some(camera) => camera,
            None => {
                let cam = &scene.camera;
                let scene_bounds = draws.iter().fold(Aabb::EMPTY, |b, d| b.union(&d.bounds));
                CameraProjection::new(cam.position, cam.target, cam.up, cam.projection, w / h, &scene_bounds)
                    .map_err(|e| crate::error::Error::Invalid(format!("scene camera: {e}")))?
            }
        };
        let globals = FrameGlobals {
            view_proj: camera.view_proj,
            inv_view_proj: camera.inv_view_proj,
            camera_position: camera.position.extend(1.0),
            camera_forward: camera.forward.extend(0.0),
            light: scene.light.position.extend(scene.light.radius),
            light_color: Vec4::ONE,
            ambient: Vec4::splat(AMBIENT),
            sky: Vec3::from(SKY).extend(1.0),
            viewport: Vec4::new(w, h, 1.0 / w, 1.0 / h),
        };
        let globals_buffer = self.globals.as_mut().expect("engine is built");
        globals_buffer.write(slot, bytes_of(&globals));
        let receivers = receivers_in_view(&camera.frustum, &draws);
        Ok(Prepared {
            globals: globals_buffer.range(slot),
            objects: object_buffer.range(slot),
            draws,
            camera,
            receivers,
            ground: scene.ground.is_some(),
        })
    }
}

impl Prepared {
    /// The frame globals and object buffer, as the prepass and import pass bind them.
    pub fn inputs(&self) -> [vk::DescriptorBufferInfo; 2] {
        [self.globals, self.objects]
    }

    /// The meshes' draws and the ground's, which the prepass draws with a pipeline of its own.
    pub fn surfaces(&self) -> (&[Draw], Option<&Draw>) {
        match self.draws.split_last() {
            Some((ground, meshes)) if self.ground => (meshes, Some(ground)),
            _ => (&self.draws, None),
        }
    }

    /// What the technique reads, with the camera surfaces in `depth` and `normal`.
    pub fn frame_inputs<'a>(
        &'a self,
        ctx: &'a Context,
        frame: &'a mut Frame<'_>,
        scene: &'a Scene,
        depth: &'a Target,
        normal: &'a Target,
    ) -> FrameInputs<'a> {
        FrameInputs {
            ctx,
            cmd: frame.cmd,
            slot: frame.slot,
            timer: &mut *frame.timer,
            scene,
            camera: &self.camera,
            globals: self.globals,
            objects: self.objects,
            draws: &self.draws,
            depth,
            normal,
            receivers_in_view: &self.receivers,
            cpu_spans: Vec::new(),
        }
    }
}

fn object_data(model: Mat4, normal: Mat4, color: Vec3, role: ShadowRole) -> ObjectData {
    ObjectData { model, normal_matrix: normal, albedo: color.extend(role.encode()) }
}

/// The ground is the unit plate scaled to the ground's square, at its height.
fn ground_model(g: &Ground) -> Mat4 {
    let side = 2.0 * g.half_size;
    Mat4::from_scale_rotation_translation(
        Vec3::new(side, 1.0, side),
        glam::Quat::IDENTITY,
        Vec3::new(0.0, g.height, 0.0),
    )
}

/// Points spanning the visible part of every receiver: each receiver's box clipped by the
/// camera frustum (the clipping's slack keeps flat receivers). Not thickened: 1e-4 of a ground
/// 2e5 m wide made a 42 m slab of the receivers in view, the light's projection centre was
/// taken 256 such heights away, and the rounding of depths there hid a 1.7 cm cube's contact
/// shadow from PCSS (issue 19).
fn receivers_in_view(frustum: &Hexahedron, draws: &[Draw]) -> Vec<Vec3> {
    draws
        .iter()
        .filter(|d| d.receives)
        .flat_map(|d| intersection_points(frustum, &Hexahedron { corners: d.bounds.corners() }))
        .collect()
}
