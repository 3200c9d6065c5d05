//! An embedder's frame (DESIGN.md §3 "Embedding"), written as a game would: its own instance
//! and device (raw ash, validation and synchronization validation on, its own messenger), its
//! own camera matrices and a depth (and normal) image it computes and uploads, the engine's
//! passes recorded into its command buffer, its own submission. V must match the engine's own
//! path, and the embedder's messenger must record no error, leaks at device destruction
//! included.

mod common;

use ash::vk;
use glam::{Mat4, Vec3, Vec4};
use softshadow::frame::interface::{FrameGlobals, ObjectData};
use softshadow::geometry::{Aabb, CameraProjection};
use softshadow::gpu::Access;
use softshadow::scene::Scene;
use softshadow::technique::{Params, find};
use softshadow::{EmbeddedFrame, EmbedderCamera, EmbedderImage, Engine, Error, Recorded};

use common::embedder::{Embedder, HostBuffer, Image, barrier, whole};

const SIDE: u32 = 64;
const EXTENT: vk::Extent2D = vk::Extent2D { width: SIDE, height: SIDE };
const EYE: Vec3 = Vec3::new(0.0, 5.0, 6.0);
const FOV_DEG: f32 = 45.0;
const NEAR: f32 = 0.5;
const FAR: f32 = 30.0;

/// A box on a ground square under an area light, seen in perspective.
fn scene(box_x: f32) -> Scene {
    scene_with(box_x, true, Vec3::new(2.0, 6.0, 1.0))
}

/// [`scene`], its box receiving shadows or not, the light at `light`.
fn scene_with(box_x: f32, receives: bool, light: Vec3) -> Scene {
    common::scene(&format!(
        "[camera]\nposition = [{}, {}, {}]\ntarget = [0.0, 0.0, 0.0]\nfov_y_deg = {FOV_DEG}\n\
         [light]\nposition = [{}, {}, {}]\nradius = 0.3\n[ground]\nheight = 0.0\nhalf_size = 4.0\n\
         [[object]]\nshape = \"box\"\nsize = [1.0, 1.0, 1.0]\nposition = [{box_x}, 0.5, 0.0]\nreceives = {receives}\n",
        EYE.x, EYE.y, EYE.z, light.x, light.y, light.z
    ))
}

/// The embedder's camera, written as a game writes it: a right-handed look-at (view looks down
/// −z) and a Vulkan perspective (y down, depth in [0, 1]), depth reversed or not.
fn camera(reverse_z: bool) -> EmbedderCamera {
    camera_between(reverse_z, NEAR, FAR)
}

/// The camera the engine's own path makes for `s` (its matrices and the planes it fits to the
/// scene's bounds), as an embedder that builds its camera with the engine's helper holds it.
fn engines_camera(s: &Scene) -> EmbedderCamera {
    let objects = s.objects.iter().map(|o| o.mesh.bounds.transformed(&o.transform.matrix()));
    let bounds = objects.chain(s.ground.as_ref().map(|g| g.bounds())).fold(Aabb::EMPTY, |b, x| b.union(&x));
    let c = &s.camera;
    let cam = CameraProjection::new(c.position, c.target, c.up, c.projection, 1.0, &bounds).unwrap();
    EmbedderCamera { view: cam.view, projection: cam.projection, reverse_z: true, near: cam.near, far: cam.far }
}

fn camera_between(reverse_z: bool, near: f32, far: f32) -> EmbedderCamera {
    let f = (Vec3::ZERO - EYE).normalize();
    let s = f.cross(Vec3::Y).normalize();
    let u = s.cross(f);
    let view = Mat4::from_cols(
        Vec4::new(s.x, u.x, -f.x, 0.0),
        Vec4::new(s.y, u.y, -f.y, 0.0),
        Vec4::new(s.z, u.z, -f.z, 0.0),
        Vec4::new(-s.dot(EYE), -u.dot(EYE), f.dot(EYE), 1.0),
    );
    // Depth 0 at distance `z0` and 1 at `z1`: swapping them reverses Z.
    let (z0, z1) = if reverse_z { (far, near) } else { (near, far) };
    let g = 1.0 / (FOV_DEG.to_radians() * 0.5).tan();
    let projection = Mat4::from_cols(
        Vec4::new(g, 0.0, 0.0, 0.0),
        Vec4::new(0.0, -g, 0.0, 0.0),
        Vec4::new(0.0, 0.0, z1 / (z0 - z1), -1.0),
        Vec4::new(0.0, 0.0, z0 * z1 / (z0 - z1), 0.0),
    );
    EmbedderCamera { view, projection, reverse_z, near, far }
}

/// The embedder's own depth "prepass", computed on the CPU: each pixel centre's ray against the
/// ground square and the box, the nearest hit's depth through the embedder's matrices (the
/// clear value where nothing is hit) and its world normal.
fn surfaces(cam: &EmbedderCamera, box_x: f32) -> (Vec<f32>, Vec<[f32; 4]>) {
    let view_proj = cam.projection * cam.view;
    let inv = view_proj.inverse();
    let clear = if cam.reverse_z { 0.0 } else { 1.0 };
    let (lo, hi) = (Vec3::new(box_x - 0.5, 0.0, -0.5), Vec3::new(box_x + 0.5, 1.0, 0.5));
    let mut depth = Vec::new();
    let mut normal = Vec::new();
    for y in 0..SIDE {
        for x in 0..SIDE {
            let ndc = glam::Vec2::new((x as f32 + 0.5) / SIDE as f32, (y as f32 + 0.5) / SIDE as f32) * 2.0 - 1.0;
            let o = inv.project_point3(ndc.extend(if cam.reverse_z { 1.0 } else { 0.0 }));
            let d = (inv.project_point3(ndc.extend(0.5)) - o).normalize();
            let mut best: Option<(f32, Vec3)> = None;
            let t = -o.y / d.y;
            let p = o + d * t;
            if t > 0.0 && p.x.abs() <= 4.0 && p.z.abs() <= 4.0 {
                best = Some((t, Vec3::Y));
            }
            // Slabs: the entry face is the axis whose near plane is crossed last.
            let (t0, t1) = ((lo - o) / d, (hi - o) / d);
            let (near, far) = (t0.min(t1), t0.max(t1));
            let entry = near.max_element();
            if entry <= far.min_element() && entry > 0.0 && best.is_none_or(|(t, _)| entry < t) {
                let axis = (0..3).find(|&i| near[i] == entry).unwrap();
                let mut n = Vec3::ZERO;
                n[axis] = -d[axis].signum();
                best = Some((entry, n));
            }
            match best {
                Some((t, n)) => {
                    let clip = view_proj * (o + d * t).extend(1.0);
                    depth.push(clip.z / clip.w);
                    normal.push([n.x, n.y, n.z, 0.0]);
                }
                None => {
                    depth.push(clear);
                    normal.push([0.0; 4]);
                }
            }
        }
    }
    (depth, normal)
}

/// Depth as `format` stores it, for an upload.
fn depth_bytes(depth: &[f32], format: vk::Format) -> Vec<u8> {
    match format {
        vk::Format::D32_SFLOAT => bytemuck::cast_slice(depth).to_vec(),
        vk::Format::D16_UNORM => depth.iter().flat_map(|d| ((d * 65535.0).round() as u16).to_le_bytes()).collect(),
        // X8_D24 and the depth aspect of D24S8 copy as 32-bit words, depth in the low 24 bits.
        _ => depth.iter().flat_map(|d| ((d * 16_777_215.0).round() as u32).to_le_bytes()).collect(),
    }
}

/// The embedder's depth prepass on the GPU: its own pipeline, descriptor set, buffers and
/// dynamic rendering pass, drawing the scene's meshes (objects, then the ground) into its D32
/// reverse-Z depth. Its stages are the engine's published prepass shaders, the objects' and the
/// ground's pipelines as the engine's (the ground's fragment stage writes its depth as the
/// camera ray's exact hit on its plane), so
/// that its depth is the engine's bit for bit: V then has nothing to differ by but the engine's
/// own work (a ray-cast depth differs in the last bits, and PCF moved by up to 5 LSB on 9 pixels;
/// a rasterized ground, by 3 LSB on 1).
struct DepthPrepass {
    set_layout: vk::DescriptorSetLayout,
    layout: vk::PipelineLayout,
    /// The objects' pipeline and the ground's.
    pipelines: [vk::Pipeline; 2],
    pool: vk::DescriptorPool,
    set: vk::DescriptorSet,
    buffers: [HostBuffer; 4],
    /// (index count, first index, vertex offset) of each draw; its instance is its position.
    draws: Vec<(u32, u32, i32)>,
}

impl DepthPrepass {
    fn new(e: &Embedder, s: &Scene, camera: &EmbedderCamera) -> Self {
        let d = &e.device;
        let ground = s.ground.as_ref().expect("a ground");
        let plate = softshadow::scene::primitives::cuboid(Vec3::new(1.0, 0.0, 1.0)).unwrap();
        let side = 2.0 * ground.half_size;
        let ground_model = Mat4::from_scale_rotation_translation(
            Vec3::new(side, 1.0, side),
            glam::Quat::IDENTITY,
            Vec3::new(0.0, ground.height, 0.0),
        );
        let meshes = s.objects.iter().map(|o| (&*o.mesh, o.transform.matrix())).chain([(&plate, ground_model)]);
        let (mut vertices, mut indices, mut objects, mut draws) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        // The ground's last normal-matrix column is its plane, which the fragment stage meets.
        let plane = Vec4::new(0.0, 1.0, 0.0, -ground.height);
        let count = s.objects.len();
        for (n, (mesh, model)) in meshes.enumerate() {
            let (v, i) = mesh.render_geometry();
            draws.push((i.len() as u32, indices.len() as u32, vertices.len() as i32));
            let last = if n == count { plane } else { Vec4::W };
            let normal_matrix = Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::Z, last);
            objects.push(ObjectData { model, normal_matrix, albedo: Vec4::ZERO });
            vertices.extend(v);
            indices.extend(i);
        }
        let cam =
            CameraProjection::from_matrices(camera.view, camera.projection, camera.reverse_z, camera.near, camera.far)
                .unwrap();
        let globals = FrameGlobals {
            view_proj: cam.view_proj,
            inv_view_proj: cam.inv_view_proj,
            camera_position: cam.position.extend(1.0),
            camera_forward: cam.forward.extend(0.0),
            viewport: Vec4::new(SIDE as f32, SIDE as f32, 1.0 / SIDE as f32, 1.0 / SIDE as f32),
            ..bytemuck::Zeroable::zeroed()
        };
        let usage = vk::BufferUsageFlags::VERTEX_BUFFER
            | vk::BufferUsageFlags::INDEX_BUFFER
            | vk::BufferUsageFlags::UNIFORM_BUFFER
            | vk::BufferUsageFlags::STORAGE_BUFFER;
        let buffers = [
            bytemuck::bytes_of(&globals),
            bytemuck::cast_slice(&objects),
            bytemuck::cast_slice(&vertices),
            bytemuck::cast_slice(&indices),
        ]
        .map(|bytes| {
            let b = e.buffer(bytes.len() as u64, usage);
            b.write(bytes);
            b
        });
        let bindings = [vk::DescriptorType::UNIFORM_BUFFER, vk::DescriptorType::STORAGE_BUFFER].map(|t| t);
        let layout_bindings: Vec<_> = bindings
            .iter()
            .enumerate()
            .map(|(i, &t)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(t)
                    .descriptor_count(1)
                    .stage_flags(vk::ShaderStageFlags::VERTEX | vk::ShaderStageFlags::FRAGMENT)
            })
            .collect();
        let sizes = bindings.map(|ty| vk::DescriptorPoolSize { ty, descriptor_count: 1 });
        unsafe {
            let set_layout = d
                .create_descriptor_set_layout(
                    &vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings),
                    None,
                )
                .unwrap();
            let pool = d
                .create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes), None)
                .unwrap();
            let layouts = [set_layout];
            let alloc = vk::DescriptorSetAllocateInfo::default().descriptor_pool(pool).set_layouts(&layouts);
            let set = d.allocate_descriptor_sets(&alloc).unwrap()[0];
            let infos =
                [0, 1].map(|i| [vk::DescriptorBufferInfo::default().buffer(buffers[i].buffer).range(vk::WHOLE_SIZE)]);
            let writes = [0, 1].map(|i| {
                vk::WriteDescriptorSet::default()
                    .dst_set(set)
                    .dst_binding(i as u32)
                    .descriptor_type(bindings[i])
                    .buffer_info(&infos[i])
            });
            d.update_descriptor_sets(&writes, &[]);
            let layout =
                d.create_pipeline_layout(&vk::PipelineLayoutCreateInfo::default().set_layouts(&layouts), None).unwrap();
            let published = [
                softshadow::gpu::shaders::PREPASS_SCENE_VERT.words,
                softshadow::gpu::shaders::PREPASS_SCENE_FRAG.words,
                softshadow::gpu::shaders::PREPASS_GROUND_FRAG.words,
            ];
            let modules = published
                .map(|code| d.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(code), None).unwrap());
            let stage =
                |stage, module| vk::PipelineShaderStageCreateInfo::default().stage(stage).module(module).name(c"main");
            let stages = [1, 2].map(|frag| {
                [stage(vk::ShaderStageFlags::VERTEX, modules[0]), stage(vk::ShaderStageFlags::FRAGMENT, modules[frag])]
            });
            let stride = std::mem::size_of::<softshadow::scene::Vertex>() as u32;
            let vertex_bindings =
                [vk::VertexInputBindingDescription { binding: 0, stride, input_rate: vk::VertexInputRate::VERTEX }];
            let attributes = [0, 12].map(|offset| vk::VertexInputAttributeDescription {
                location: offset / 12,
                binding: 0,
                format: vk::Format::R32G32B32_SFLOAT,
                offset,
            });
            let vertex_input = vk::PipelineVertexInputStateCreateInfo::default()
                .vertex_binding_descriptions(&vertex_bindings)
                .vertex_attribute_descriptions(&attributes);
            let assembly =
                vk::PipelineInputAssemblyStateCreateInfo::default().topology(vk::PrimitiveTopology::TRIANGLE_LIST);
            let viewports =
                [vk::Viewport { width: SIDE as f32, height: SIDE as f32, max_depth: 1.0, ..Default::default() }];
            let scissors = [vk::Rect2D { extent: EXTENT, ..Default::default() }];
            let viewport = vk::PipelineViewportStateCreateInfo::default().viewports(&viewports).scissors(&scissors);
            let raster =
                vk::PipelineRasterizationStateCreateInfo::default().cull_mode(vk::CullModeFlags::NONE).line_width(1.0);
            let multisample =
                vk::PipelineMultisampleStateCreateInfo::default().rasterization_samples(vk::SampleCountFlags::TYPE_1);
            // Reverse Z: nearer is greater.
            let depth = vk::PipelineDepthStencilStateCreateInfo::default()
                .depth_test_enable(true)
                .depth_write_enable(true)
                .depth_compare_op(vk::CompareOp::GREATER);
            let blend = vk::PipelineColorBlendStateCreateInfo::default();
            let mut rendering =
                vk::PipelineRenderingCreateInfo::default().depth_attachment_format(vk::Format::D32_SFLOAT);
            let pipelines = stages.map(|stages| {
                let ci = [vk::GraphicsPipelineCreateInfo::default()
                    .stages(&stages)
                    .vertex_input_state(&vertex_input)
                    .input_assembly_state(&assembly)
                    .viewport_state(&viewport)
                    .rasterization_state(&raster)
                    .multisample_state(&multisample)
                    .depth_stencil_state(&depth)
                    .color_blend_state(&blend)
                    .layout(layout)
                    .push_next(&mut rendering)];
                d.create_graphics_pipelines(vk::PipelineCache::null(), &ci, None).unwrap()[0]
            });
            modules.into_iter().for_each(|m| d.destroy_shader_module(m, None));
            DepthPrepass { set_layout, layout, pipelines, pool, set, buffers, draws }
        }
    }

    /// Clears `depth` to 0 and draws the scene into it; leaves it as [`DEPTH_WRITTEN`] says.
    fn record(&self, d: &ash::Device, cmd: vk::CommandBuffer, depth: vk::ImageView) {
        let attachment = vk::RenderingAttachmentInfo::default()
            .image_view(depth)
            .image_layout(DEPTH_WRITTEN.2)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth: 0.0, stencil: 0 } });
        let info = vk::RenderingInfo::default()
            .render_area(vk::Rect2D { extent: EXTENT, ..Default::default() })
            .layer_count(1)
            .depth_attachment(&attachment);
        unsafe {
            d.cmd_begin_rendering(cmd, &info);
            d.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::GRAPHICS, self.layout, 0, &[self.set], &[]);
            d.cmd_bind_vertex_buffers(cmd, 0, &[self.buffers[2].buffer], &[0]);
            d.cmd_bind_index_buffer(cmd, self.buffers[3].buffer, 0, vk::IndexType::UINT32);
            let ground = self.draws.len() - 1;
            for (instance, &(count, first, offset)) in self.draws.iter().enumerate() {
                if instance == 0 || instance == ground {
                    d.cmd_bind_pipeline(
                        cmd,
                        vk::PipelineBindPoint::GRAPHICS,
                        self.pipelines[(instance == ground) as usize],
                    );
                }
                d.cmd_draw_indexed(cmd, count, 1, first, offset, instance as u32);
            }
            d.cmd_end_rendering(cmd);
        }
    }

    fn destroy(self, e: &Embedder) {
        unsafe {
            self.pipelines.into_iter().for_each(|p| e.device.destroy_pipeline(p, None));
            e.device.destroy_pipeline_layout(self.layout, None);
            e.device.destroy_descriptor_pool(self.pool, None);
            e.device.destroy_descriptor_set_layout(self.set_layout, None);
        }
        self.buffers.into_iter().for_each(|b| e.destroy_buffer(b));
    }
}

const COPY_WRITE: (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout) =
    (vk::PipelineStageFlags2::COPY, vk::AccessFlags2::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
const DEPTH_WRITTEN: (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout) = (
    vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS,
    vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE,
    vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
);
const UNDEFINED: (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout) =
    (vk::PipelineStageFlags2::NONE, vk::AccessFlags2::NONE, vk::ImageLayout::UNDEFINED);

fn triple(a: Access) -> (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout) {
    (a.stage, a.access, a.layout)
}

/// The embedder's images and buffers for one configuration.
struct Frames {
    depth: Image,
    normal: Option<Image>,
    visibility: Image,
    staging: HostBuffer,
    readback: HostBuffer,
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    /// What the engine left V in last time (the embedder's readback moves it on from there).
    visibility_last: Access,
    /// V goes to the engine's own target instead of `visibility`.
    own_target: bool,
    /// Depth drawn by this prepass (into a view of `depth`) instead of uploaded.
    prepass: Option<(DepthPrepass, vk::ImageView)>,
}

/// What one frame shows: the scene (its box at `box_x`), the technique, the embedder's camera.
struct Shot<'a> {
    scene: &'a Scene,
    params: &'a Params,
    camera: EmbedderCamera,
    box_x: f32,
}

impl Frames {
    fn new(e: &Embedder, depth_format: vk::Format, normals: bool) -> Self {
        let transfer = vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::SAMPLED;
        let depth = e.image(depth_format, EXTENT, transfer | vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT);
        let normal = normals.then(|| e.image(vk::Format::R32G32B32A32_SFLOAT, EXTENT, transfer));
        let usage =
            vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::SAMPLED;
        let visibility = e.image(vk::Format::R16_UNORM, EXTENT, usage);
        let texels = (SIDE * SIDE) as u64;
        Frames {
            depth,
            normal,
            visibility,
            staging: e.buffer(texels * 32, vk::BufferUsageFlags::TRANSFER_SRC),
            readback: e.buffer(texels * 2, vk::BufferUsageFlags::TRANSFER_DST),
            cmd: e.command_buffer(),
            fence: e.fence(false),
            visibility_last: Access::NONE,
            own_target: false,
            prepass: None,
        }
    }

    /// One frame: upload depth (and normals), record the engine's passes, copy V out, submit,
    /// wait. Returns V, or the engine's error (the command buffer is then left unsubmitted).
    fn run(&mut self, e: &Embedder, engine: &mut Engine, shot: &Shot) -> Result<Vec<u16>, Error> {
        let cmd = self.cmd;
        e.begin(cmd);
        let recorded = self.record(e, engine, shot, cmd)?;
        assert_eq!(recorded.visibility, Access::FRAGMENT_READ);
        assert_eq!(recorded.visibility_image, self.visibility.image);
        let d = &e.device;
        let copy_read = Access::COPY_READ;
        let color = vk::ImageAspectFlags::COLOR;
        barrier(d, cmd, self.visibility.image, color, triple(recorded.visibility), triple(copy_read));
        unsafe {
            let copy = [whole(color, EXTENT)];
            d.cmd_copy_image_to_buffer(cmd, self.visibility.image, copy_read.layout, self.readback.buffer, &copy);
            let host = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::COPY)
                .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::HOST)
                .dst_access_mask(vk::AccessFlags2::HOST_READ)];
            d.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&host));
        }
        self.visibility_last = copy_read;
        e.submit(cmd, self.fence);
        e.wait(self.fence);
        Ok(bytemuck::cast_slice(&self.readback.read()).to_vec())
    }

    /// One frame into the engine's own V target: record, submit, wait.
    fn run_into_own_target(&mut self, e: &Embedder, engine: &mut Engine, shot: &Shot) {
        e.begin(self.cmd);
        self.record(e, engine, shot, self.cmd).unwrap();
        e.submit(self.cmd, self.fence);
        e.wait(self.fence);
    }

    /// Uploads the shot's depth (and normals) in `cmd` and records the engine's passes after
    /// them, V into the embedder's image (or, with `own_target`, the engine's).
    fn record(
        &mut self,
        e: &Embedder,
        engine: &mut Engine,
        shot: &Shot,
        cmd: vk::CommandBuffer,
    ) -> Result<Recorded, Error> {
        let (depth, normal) = surfaces(&shot.camera, shot.box_x);
        let depth = depth_bytes(&depth, self.depth.format);
        let normal_at = 16 * SIDE as usize * SIDE as usize;
        self.staging.write(&[&depth[..], &vec![0; normal_at - depth.len()], bytemuck::cast_slice(&normal)].concat());
        let d = &e.device;
        let depth_aspect = vk::ImageAspectFlags::DEPTH;
        let full_aspect = match self.depth.format {
            vk::Format::D24_UNORM_S8_UINT | vk::Format::D32_SFLOAT_S8_UINT | vk::Format::D16_UNORM_S8_UINT => {
                depth_aspect | vk::ImageAspectFlags::STENCIL
            }
            _ => depth_aspect,
        };
        let depth_last = match &self.prepass {
            Some((prepass, view)) => {
                barrier(d, cmd, self.depth.image, full_aspect, UNDEFINED, DEPTH_WRITTEN);
                prepass.record(d, cmd, *view);
                DEPTH_WRITTEN
            }
            None => {
                barrier(d, cmd, self.depth.image, full_aspect, UNDEFINED, COPY_WRITE);
                let copy = [whole(depth_aspect, EXTENT)];
                unsafe { d.cmd_copy_buffer_to_image(cmd, self.staging.buffer, self.depth.image, COPY_WRITE.2, &copy) };
                COPY_WRITE
            }
        };
        if let Some(n) = &self.normal {
            barrier(d, cmd, n.image, vk::ImageAspectFlags::COLOR, UNDEFINED, COPY_WRITE);
            let copy =
                [vk::BufferImageCopy { buffer_offset: normal_at as u64, ..whole(vk::ImageAspectFlags::COLOR, EXTENT) }];
            unsafe { d.cmd_copy_buffer_to_image(cmd, self.staging.buffer, n.image, COPY_WRITE.2, &copy) };
        }
        let copied = Access { stage: COPY_WRITE.0, access: COPY_WRITE.1, layout: COPY_WRITE.2 };
        let image = |i: &Image, last| EmbedderImage { image: i.image, format: i.format, extent: EXTENT, last };
        let frame = EmbeddedFrame {
            cmd,
            camera: shot.camera,
            depth: image(&self.depth, Access { stage: depth_last.0, access: depth_last.1, layout: depth_last.2 }),
            normal: self.normal.as_ref().map(|n| image(n, copied)),
            visibility: (!self.own_target).then(|| image(&self.visibility, self.visibility_last)),
        };
        engine.record(shot.scene, shot.params, &frame)
    }

    /// Draws depth with a GPU prepass of `s` seen by `camera` from now on.
    fn draw_depth(&mut self, e: &Embedder, s: &Scene, camera: &EmbedderCamera) {
        let range = vk::ImageSubresourceRange {
            aspect_mask: vk::ImageAspectFlags::DEPTH,
            level_count: 1,
            layer_count: 1,
            ..Default::default()
        };
        let ci = vk::ImageViewCreateInfo::default()
            .image(self.depth.image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(self.depth.format)
            .subresource_range(range);
        let view = unsafe { e.device.create_image_view(&ci, None) }.unwrap();
        self.prepass = Some((DepthPrepass::new(e, s, camera), view));
    }

    fn destroy(self, e: &Embedder) {
        if let Some((prepass, view)) = self.prepass {
            prepass.destroy(e);
            unsafe { e.device.destroy_image_view(view, None) };
        }
        e.destroy_image(self.depth);
        self.normal.into_iter().for_each(|n| e.destroy_image(n));
        e.destroy_image(self.visibility);
        e.destroy_buffer(self.staging);
        e.destroy_buffer(self.readback);
        unsafe { e.device.destroy_fence(self.fence, None) };
    }
}

fn embedder() -> Embedder {
    Embedder::new(softshadow::required_device_extensions(), softshadow::required_device_features())
}

fn engine_on(e: &Embedder) -> Engine {
    unsafe { Engine::from_handles(e.handles(softshadow::required_device_features())) }
        .expect("an engine on the embedder's device")
}

fn params(technique: &str) -> Params {
    Params::defaults(find(technique).unwrap())
}

/// V of the engine's own path (its prepass, its camera), on the same engine.
fn own_v(engine: &mut Engine, s: &Scene, technique: &str) -> Vec<u16> {
    let mut settings = common::settings(s, SIDE, SIDE);
    settings.params = params(technique);
    engine.render_and_capture(s, &settings).unwrap().visibility
}

/// V at the pixel that sees world point `p` (the ground beside the box, for these checks).
fn v_at(v: &[u16], p: Vec3) -> f32 {
    let cam = camera(true);
    let ndc = (cam.projection * cam.view).project_point3(p);
    let (x, y) = (((ndc.x + 1.0) * 0.5 * SIDE as f32) as usize, ((ndc.y + 1.0) * 0.5 * SIDE as f32) as usize);
    v[y * SIDE as usize + x] as f32 / 65535.0
}

/// Pixels whose V differs by more than `lsb` steps of 65535, and the largest difference.
fn differences(a: &[u16], b: &[u16], lsb: u16) -> (usize, u16) {
    let diffs = a.iter().zip(b).map(|(x, y)| x.abs_diff(*y));
    (diffs.clone().filter(|&d| d > lsb).count(), diffs.max().unwrap_or(0))
}

/// The embedder's depth (D32, reverse Z, drawn by its own GPU prepass with the engine's camera
/// matrices) and normals give the engine's V to within 1 LSB at every pixel, for every technique
/// that records; the umbra the box casts is dark and the open ground lit.
#[test]
fn an_embedders_frame_gives_the_engines_visibility() {
    let e = embedder();
    let mut engine = engine_on(&e);
    let s = scene(0.0);
    let mut frames = Frames::new(&e, vk::Format::D32_SFLOAT, true);
    let cam = engines_camera(&s);
    frames.draw_depth(&e, &s, &cam);
    for technique in ["shadow-map", "pcf", "pcss", "smoothie", "plateau", "reference"] {
        let own = own_v(&mut engine, &s, technique);
        let p = params(technique);
        let embedded = frames.run(&e, &mut engine, &Shot { scene: &s, params: &p, camera: cam, box_x: 0.0 }).unwrap();
        let (over, max) = differences(&embedded, &own, 1);
        eprintln!("{technique}: {over} pixels differ by more than 1 LSB (max {max})");
        assert!(over == 0, "{technique}: {over} pixels differ by more than 1 LSB (max {max})");
        let (shadowed, lit) = (v_at(&embedded, Vec3::new(-0.75, 0.0, -0.1)), v_at(&embedded, Vec3::new(2.0, 0.0, 2.0)));
        assert!(shadowed < 0.05 && lit > 0.95, "{technique}: V {shadowed} in the umbra, {lit} in the open");
    }
    // The casters' roles come from the engine's scene: lit from behind, the box's face toward
    // the camera is in its own shadow; a box that casts but receives nothing has V = 1 there, as
    // on the engine's own path, where the embedder's depth alone would make it a shadowed receiver.
    let s = scene_with(0.0, false, Vec3::new(-2.0, 6.0, -1.0));
    let p = params("shadow-map");
    let embedded = frames.run(&e, &mut engine, &Shot { scene: &s, params: &p, camera: cam, box_x: 0.0 }).unwrap();
    let own = own_v(&mut engine, &s, "shadow-map");
    let face = Vec3::new(0.0, 0.5, 0.5);
    assert_eq!((v_at(&embedded, face), v_at(&own, face)), (1.0, 1.0), "V on the box's face away from the light");
    let behind = Vec3::new(0.75, 0.0, 0.3);
    assert!(v_at(&embedded, behind) < 0.05, "V {} where the box's shadow falls", v_at(&embedded, behind));
    frames.destroy(&e);
    drop(engine);
    e.finish();
}

/// Forward-Z depth in D16, X8_D24 and D24S8 without normals (facet normals rebuilt from depth),
/// and forward-Z D32: the shadow lands where the engine's own path puts it, to within the
/// depth's precision.
#[test]
fn forward_z_depth_of_every_common_format_without_normals_shadows_alike() {
    let e = embedder();
    let mut engine = engine_on(&e);
    let s = scene(0.0);
    let own = own_v(&mut engine, &s, "pcss");
    for format in
        [vk::Format::D32_SFLOAT, vk::Format::D16_UNORM, vk::Format::X8_D24_UNORM_PACK32, vk::Format::D24_UNORM_S8_UINT]
    {
        let mut frames = Frames::new(&e, format, false);
        let p = params("pcss");
        let shot = Shot { scene: &s, params: &p, camera: camera(false), box_x: 0.0 };
        let embedded = frames.run(&e, &mut engine, &shot).unwrap();
        frames.destroy(&e);
        let (over, max) = differences(&embedded, &own, 655);
        // Silhouette pixels may see another facet where the depth is coarse.
        assert!(over <= 40, "{format:?}: {over} pixels differ by more than 1 % (max {max})");
        let dark = |v: &[u16]| v.iter().filter(|&&x| x < 6554).count();
        assert!(
            dark(&embedded).abs_diff(dark(&own)) <= 40,
            "{format:?}: {} dark pixels, own {}",
            dark(&embedded),
            dark(&own)
        );
    }
    drop(engine);
    e.finish();
}

/// A moving caster over many recorded frames into the engine's own V target: every pass is
/// timed (the import, the technique's), its times come back from later frames without a wait,
/// and the embedded frame costs about what the engine's own frame does.
#[test]
fn recorded_frames_are_timed_without_waiting() {
    let e = embedder();
    let mut engine = engine_on(&e);
    let mut frames = Frames::new(&e, vk::Format::D32_SFLOAT, false);
    frames.own_target = true;
    let p = params("smoothie");
    let fences = [e.fence(true), e.fence(true)];
    let cmds = [e.command_buffer(), e.command_buffer()];
    const FRAMES: usize = 12;
    for i in 0..FRAMES {
        let box_x = (i as f32 * 0.3).sin();
        let s = scene(box_x);
        // Frame i − 2 used this slot: wait for it, as the contract asks.
        e.wait(fences[i % 2]);
        e.begin(cmds[i % 2]);
        frames
            .record(&e, &mut engine, &Shot { scene: &s, params: &p, camera: camera(true), box_x }, cmds[i % 2])
            .unwrap();
        e.submit(cmds[i % 2], fences[i % 2]);
    }
    fences.iter().for_each(|&f| unsafe { e.device.wait_for_fences(&[f], true, u64::MAX) }.unwrap());
    let timings = engine.take_timings();
    assert!(timings.len() >= FRAMES - 2, "{} of {FRAMES} frames timed", timings.len());
    for t in &timings {
        let names: Vec<_> = t.passes.iter().map(|p| p.name).collect();
        assert_eq!(names, ["import", "shadow_map", "smoothie_buffer", "resolve"], "{names:?}");
        assert!(t.passes.iter().all(|p| p.ms > 0.0), "{:?}", t.passes);
    }
    let median = |t: &[softshadow::FrameTimings]| {
        let mut ms: Vec<f64> = t.iter().map(|f| f.passes.iter().map(|p| p.ms).sum()).collect();
        ms.sort_by(f64::total_cmp);
        ms[ms.len() / 2]
    };
    let embedded = median(&timings);
    let s = scene(0.0);
    let mut settings = common::settings(&s, SIDE, SIDE);
    settings.params = p.clone();
    for _ in 0..FRAMES {
        engine.render(&s, &settings).unwrap();
    }
    engine.flush().unwrap();
    let own = median(&engine.take_timings());
    eprintln!("GPU ms per frame ({}): embedded {embedded:.3}, engine's own path {own:.3}", engine.device().name);
    fences.iter().for_each(|&f| unsafe { e.device.destroy_fence(f, None) });
    frames.destroy(&e);
    drop(engine);
    e.finish();
}

/// Switching size and technique on the record path never waits for the queue (DESIGN.md §3: no
/// device wait on this path): what a switch replaces lives on until the frames that used it can
/// no longer run. Two frames stay in flight throughout, alternating between the embedder's
/// 64 px depth with one technique and a 32 px depth (cleared: nothing but sky) with the other;
/// validation with synchronization validation stays clean, and V after the switching matches V
/// before it.
#[test]
fn switching_size_and_technique_while_recording_never_waits() {
    let e = embedder();
    let mut engine = engine_on(&e);
    let mut frames = Frames::new(&e, vk::Format::D32_SFLOAT, false);
    let s = scene(0.0);
    let (smoothie, shadow_map) = (params("smoothie"), params("shadow-map"));
    let shot = |params| Shot { scene: &s, params, camera: camera(true), box_x: 0.0 };
    let before = frames.run(&e, &mut engine, &shot(&smoothie)).unwrap();
    let waits = engine.context().queue_waits();

    let small_extent = vk::Extent2D { width: SIDE / 2, height: SIDE / 2 };
    let small =
        e.image(vk::Format::D32_SFLOAT, small_extent, vk::ImageUsageFlags::TRANSFER_DST | vk::ImageUsageFlags::SAMPLED);
    const CLEARED: (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout) =
        (vk::PipelineStageFlags2::CLEAR, vk::AccessFlags2::TRANSFER_WRITE, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
    let fences = [e.fence(true), e.fence(true)];
    let cmds = [e.command_buffer(), e.command_buffer()];
    frames.own_target = true;
    for i in 0..8 {
        let cmd = cmds[i % 2];
        // Frame i − 2 used this slot: wait for it, as the contract asks.
        e.wait(fences[i % 2]);
        e.begin(cmd);
        if i % 2 == 0 {
            let depth = vk::ImageAspectFlags::DEPTH;
            barrier(&e.device, cmd, small.image, depth, UNDEFINED, CLEARED);
            let range = [vk::ImageSubresourceRange {
                aspect_mask: depth,
                level_count: 1,
                layer_count: 1,
                ..Default::default()
            }];
            let far = vk::ClearDepthStencilValue { depth: 0.0, stencil: 0 };
            unsafe { e.device.cmd_clear_depth_stencil_image(cmd, small.image, CLEARED.2, &far, &range) };
            let last = Access { stage: CLEARED.0, access: CLEARED.1, layout: CLEARED.2 };
            let frame = EmbeddedFrame {
                cmd,
                camera: camera(true),
                depth: EmbedderImage { image: small.image, format: small.format, extent: small_extent, last },
                normal: None,
                visibility: None,
            };
            engine.record(&s, &shadow_map, &frame).unwrap();
        } else {
            frames.record(&e, &mut engine, &shot(&smoothie), cmd).unwrap();
        }
        e.submit(cmd, fences[i % 2]);
    }
    fences.iter().for_each(|&f| unsafe { e.device.wait_for_fences(&[f], true, u64::MAX) }.unwrap());
    assert_eq!(engine.context().queue_waits(), waits, "a record-path switch waited for the queue");
    frames.own_target = false;
    let after = frames.run(&e, &mut engine, &shot(&smoothie)).unwrap();
    assert_eq!(differences(&before, &after, 0), (0, 0), "V after the switching");
    fences.iter().for_each(|&f| unsafe { e.device.destroy_fence(f, None) });
    e.destroy_image(small);
    frames.destroy(&e);
    drop(engine);
    e.finish();
}

/// Recording again before the frame two records ago has finished is refused with a message
/// saying so (the GPU is held on an event the host sets afterwards); once it has finished,
/// recording works again.
#[test]
fn recording_over_an_unfinished_frame_is_an_error() {
    let e = embedder();
    let mut engine = engine_on(&e);
    let mut frames = Frames::new(&e, vk::Format::D32_SFLOAT, false);
    frames.own_target = true;
    let (s, p) = (scene(0.0), params("shadow-map"));
    let shot = Shot { scene: &s, params: &p, camera: camera(true), box_x: 0.0 };
    let event = unsafe { e.device.create_event(&vk::EventCreateInfo::default(), None) }.unwrap();
    let cmds = [e.command_buffer(), e.command_buffer(), e.command_buffer()];
    let fences = [e.fence(false), e.fence(false), e.fence(false)];
    for i in 0..2 {
        e.begin(cmds[i]);
        if i == 0 {
            let held = [vk::MemoryBarrier2::default()
                .src_stage_mask(vk::PipelineStageFlags2::HOST)
                .src_access_mask(vk::AccessFlags2::HOST_WRITE)
                .dst_stage_mask(vk::PipelineStageFlags2::ALL_COMMANDS)
                .dst_access_mask(vk::AccessFlags2::MEMORY_READ)];
            let dep = [vk::DependencyInfo::default().memory_barriers(&held)];
            unsafe { e.device.cmd_wait_events2(cmds[0], &[event], &dep) };
        }
        frames.record(&e, &mut engine, &shot, cmds[i]).unwrap();
        e.submit(cmds[i], fences[i]);
    }
    e.begin(cmds[2]);
    let why = frames.record(&e, &mut engine, &shot, cmds[2]).expect_err("frame 0 is still held").to_string();
    assert!(why.contains("has not finished"), "{why}");
    unsafe { e.device.set_event(event) }.unwrap();
    (0..2).for_each(|i| e.wait(fences[i]));
    e.begin(cmds[2]);
    frames.record(&e, &mut engine, &shot, cmds[2]).unwrap();
    e.submit(cmds[2], fences[2]);
    e.wait(fences[2]);
    unsafe {
        e.device.destroy_event(event, None);
        fences.iter().for_each(|&f| e.device.destroy_fence(f, None));
    }
    frames.destroy(&e);
    drop(engine);
    e.finish();
}

/// A frame the embedder records and then drops unsubmitted (its command buffer reset, the
/// engine told by `discard_recorded`) never ran its uploads, so the next frame makes them again:
/// for a smoothie with GPU silhouettes, the first frame ever (uploading the scene's meshes and
/// the silhouette data) and then a frame showing new meshes, each discarded and recorded again,
/// give the V of a fresh engine's own path to within 1 LSB, with no validation error. Only the
/// frame recorded last can be discarded, once.
#[test]
fn a_discarded_frame_uploads_again_in_the_next() {
    let e = embedder();
    let mut engine = engine_on(&e);
    let why = engine.discard_recorded().expect_err("nothing recorded").to_string();
    assert!(why.contains("no frame to discard"), "{why}");
    let mut p = params("smoothie");
    p.set("gpu_silhouettes", "1").unwrap();
    for box_x in [0.0, 0.5] {
        // Parsed again: new meshes, which no frame has uploaded.
        let s = scene(box_x);
        let cam = engines_camera(&s);
        let mut frames = Frames::new(&e, vk::Format::D32_SFLOAT, true);
        frames.draw_depth(&e, &s, &cam);
        let shot = Shot { scene: &s, params: &p, camera: cam, box_x };
        e.begin(frames.cmd);
        frames.record(&e, &mut engine, &shot, frames.cmd).unwrap();
        unsafe { e.device.reset_command_buffer(frames.cmd, vk::CommandBufferResetFlags::empty()) }.unwrap();
        engine.discard_recorded().unwrap();
        assert!(engine.discard_recorded().is_err(), "a frame discarded twice");
        let embedded = frames.run(&e, &mut engine, &shot).unwrap();
        let mut fresh = engine_on(&e);
        let mut settings = common::settings(&s, SIDE, SIDE);
        settings.params = p.clone();
        let own = fresh.render_and_capture(&s, &settings).unwrap().visibility;
        drop(fresh);
        let (over, max) = differences(&embedded, &own, 1);
        assert!(over == 0, "box at {box_x}: {over} pixels differ by more than 1 LSB (max {max})");
        frames.destroy(&e);
    }
    drop(engine);
    e.finish();
}

/// A device created without what the engine needs is refused, the missing piece named.
#[test]
fn an_embedders_device_without_what_the_engine_needs_is_refused_by_name() {
    let without_extensions = Embedder::new(&[], softshadow::required_device_features());
    let features = softshadow::required_device_features();
    let why = unsafe { Engine::from_handles(without_extensions.handles(features)) }.err().expect("refused").to_string();
    assert!(why.contains("VK_KHR_push_descriptor"), "{why}");
    without_extensions.finish();
    let e = embedder();
    let handles = e.handles(softshadow::required_device_features().dynamic_rendering(false));
    let why = unsafe { Engine::from_handles(handles) }.err().expect("refused").to_string();
    assert!(why.contains("dynamicRendering"), "{why}");
    e.finish();
}

/// An engine that only records into the embedder's frames makes no targets of its own shading
/// (shading normal, albedo, color): rendering a frame of its own on the same engine adds exactly
/// those three.
#[test]
fn an_engine_that_only_records_makes_no_shading_targets() {
    let e = embedder();
    let mut engine = engine_on(&e);
    let mut frames = Frames::new(&e, vk::Format::D32_SFLOAT, false);
    frames.own_target = true;
    let (s, p) = (scene(0.0), params("shadow-map"));
    frames.run_into_own_target(&e, &mut engine, &Shot { scene: &s, params: &p, camera: camera(true), box_x: 0.0 });
    engine.flush().unwrap();
    let recording = engine.context().live_allocations();
    let mut settings = common::settings(&s, SIDE, SIDE);
    settings.params = p;
    engine.render(&s, &settings).unwrap();
    engine.flush().unwrap();
    assert_eq!(engine.context().live_allocations(), recording + 3, "allocations of the engine's own frame");
    frames.destroy(&e);
    drop(engine);
    e.finish();
}

/// Host memory handed out through an embedder's allocation callbacks: how many blocks, and the
/// layout of each block alive.
#[derive(Default)]
struct HostAllocations {
    made: std::sync::atomic::AtomicUsize,
    live: std::sync::Mutex<std::collections::HashMap<usize, std::alloc::Layout>>,
}

unsafe extern "system" fn allocate(
    user: *mut std::ffi::c_void,
    size: usize,
    align: usize,
    _: vk::SystemAllocationScope,
) -> *mut std::ffi::c_void {
    // SAFETY: `user` is the test's HostAllocations, alive until the engine is dropped.
    let a = unsafe { &*(user as *const HostAllocations) };
    let layout = std::alloc::Layout::from_size_align(size.max(1), align.max(1)).unwrap();
    // SAFETY: a non-zero size.
    let p = unsafe { std::alloc::alloc(layout) };
    a.made.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    a.live.lock().unwrap().insert(p as usize, layout);
    p.cast()
}

unsafe extern "system" fn free(user: *mut std::ffi::c_void, p: *mut std::ffi::c_void) {
    if p.is_null() {
        return;
    }
    // SAFETY: as `allocate`; `p` came from it (a foreign pointer fails the lookup).
    let a = unsafe { &*(user as *const HostAllocations) };
    let layout = a.live.lock().unwrap().remove(&(p as usize)).expect("a block these callbacks made");
    unsafe { std::alloc::dealloc(p.cast(), layout) };
}

unsafe extern "system" fn reallocate(
    user: *mut std::ffi::c_void,
    original: *mut std::ffi::c_void,
    size: usize,
    align: usize,
    scope: vk::SystemAllocationScope,
) -> *mut std::ffi::c_void {
    if size == 0 {
        unsafe { free(user, original) };
        return std::ptr::null_mut();
    }
    let moved = unsafe { allocate(user, size, align, scope) };
    if !original.is_null() {
        let a = unsafe { &*(user as *const HostAllocations) };
        let old = a.live.lock().unwrap()[&(original as usize)].size();
        unsafe { std::ptr::copy_nonoverlapping(original as *const u8, moved as *mut u8, old.min(size)) };
        unsafe { free(user, original) };
    }
    moved
}

/// Host blocks alive through `host`'s callbacks while `ctx` holds a buffer of `size` bytes,
/// less those alive before it.
fn host_blocks_of_a_buffer(host: &HostAllocations, ctx: &softshadow::gpu::Context, size: u64) -> usize {
    let live = || host.live.lock().unwrap().len();
    let before = live();
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
    let buffer =
        softshadow::gpu::Buffer::new(ctx, "host blocks", size, usage, gpu_allocator::MemoryLocation::CpuToGpu).unwrap();
    let during = live();
    buffer.destroy(ctx);
    assert_eq!(live(), before, "a buffer's host blocks outlive it");
    during - before
}

/// The embedder's host allocator is used for the engine's objects and its device memory, and
/// everything allocated through it is freed once the engine is dropped; the validation layer
/// (the embedder's messenger) would report any object destroyed with other callbacks than it
/// was made with. A buffer larger than gpu-allocator's 64 MiB host-visible blocks gets
/// `VkDeviceMemory` of its own, whose host object (lavapipe allocates one per allocation) comes
/// through the callbacks too: one host block more than a small buffer placed in a block that
/// exists.
#[test]
fn the_embedders_allocation_callbacks_serve_and_are_all_freed() {
    let e = embedder();
    let host = Box::new(HostAllocations::default());
    let callbacks = vk::AllocationCallbacks::default()
        .user_data(&*host as *const HostAllocations as *mut std::ffi::c_void)
        .pfn_allocation(Some(allocate))
        .pfn_reallocation(Some(reallocate))
        .pfn_free(Some(free));
    let handles = softshadow::gpu::EmbedderHandles {
        allocation_callbacks: Some(callbacks),
        ..e.handles(softshadow::required_device_features())
    };
    let mut engine = unsafe { Engine::from_handles(handles) }.unwrap();
    let mut frames = Frames::new(&e, vk::Format::D32_SFLOAT, false);
    frames.own_target = true;
    let (s, p) = (scene(0.0), params("pcss"));
    for _ in 0..3 {
        frames.run_into_own_target(&e, &mut engine, &Shot { scene: &s, params: &p, camera: camera(true), box_x: 0.0 });
    }
    engine.flush().unwrap();
    let made = host.made.load(std::sync::atomic::Ordering::Relaxed);
    assert!(made > 0, "no host allocation went through the embedder's callbacks");
    let small = host_blocks_of_a_buffer(&host, engine.context(), 256);
    let dedicated = host_blocks_of_a_buffer(&host, engine.context(), 80 << 20);
    assert_eq!(dedicated, small + 1, "host blocks of a buffer in new device memory, and of one in a block");
    drop(engine);
    let live = host.live.lock().unwrap().len();
    assert_eq!(live, 0, "{live} of {made} blocks allocated through the callbacks outlive the engine");
    frames.destroy(&e);
    e.finish();
}
