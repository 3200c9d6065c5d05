//! The frame of DESIGN.md §1: prepass → technique → composite → readback, and the game-loop
//! API around it. Create an [`Engine`] once, change the scene between frames, render, read
//! timings and images; nothing assumes one frame per process.

mod capture;
mod draw;
mod passes;
mod window;

use std::sync::Arc;
use std::time::Instant;

use ash::vk;
use bytemuck::{bytes_of, cast_slice};
use glam::{Mat4, Vec3, Vec4};
use gpu_allocator::MemoryLocation;

pub use capture::{Capture, pixel_uv};
use draw::MeshCache;
use passes::{ALBEDO_FORMAT, COLOR_FORMAT, Composite, NORMAL_FORMAT, Prepass, SHADING_FORMAT};
pub use window::{AppWindow, Presented, WindowOptions, WindowStats};

use crate::error::Result;
use crate::frame::interface::{FrameGlobals, ObjectData};
use crate::frame::{Draw, FrameInputs, RAW_VISIBILITY_FORMAT, ShadowRole, VISIBILITY_FORMAT};
use crate::geometry::{Aabb, CameraProjection, Hexahedron, intersection_points};
use crate::gpu::{
    Access, Buffer, Context, ContextOptions, DeviceInfo, FRAMES_IN_FLIGHT, FrameRing, PassTime, PerFrame, Target,
    TargetDesc, copy_to_host, transition,
};
use crate::scene::{Ground, Mesh, Scene, primitives};
use crate::technique::{self, Params, Technique};

const AMBIENT: f32 = 0.15;
const SKY: [f32; 3] = [0.55, 0.62, 0.72];
const GROUND_COLOR: Vec3 = Vec3::new(0.75, 0.75, 0.72);

/// What to render a frame at: size and technique with its knobs.
#[derive(Clone, Debug)]
pub struct FrameSettings {
    pub width: u32,
    pub height: u32,
    pub params: Params,
}

impl FrameSettings {
    /// The scene's `[render]` table, its technique and knobs checked against the registry. An
    /// unknown technique or a bad knob names the scene file and the line, when it has them.
    pub fn from_scene(scene: &Scene) -> Result<Self> {
        let render = &scene.render;
        let located = |line: Option<usize>, table: &str, e: crate::error::Error| match &render.source {
            Some(path) => {
                let at = line.map_or_else(String::new, |l| format!("line {l}: "));
                crate::error::Error::scene(path, format!("{at}[{table}] {e}"))
            }
            None => e,
        };
        let info = technique::find(&render.technique).map_err(|e| located(render.technique_line, "render", e))?;
        let mut params = Params::defaults(info);
        for knob in &render.params {
            params.set(&knob.key, &knob.value).map_err(|e| located(knob.line, "render.params", e))?;
        }
        Ok(FrameSettings { width: render.width, height: render.height, params })
    }
}

/// GPU pass times of one finished frame, and the CPU work that made it.
#[derive(Clone, Debug)]
pub struct FrameTimings {
    pub passes: Vec<PassTime>,
    /// In order: [`WAIT_FOR_SLOT`], `acquire` (a presented frame), `draw list`, `prepass`,
    /// `technique` (its per-frame geometry and recording), `composite`, [`SUBMIT`], `present` (a
    /// presented frame); a captured frame adds `wait for GPU` and `readback`.
    pub cpu: Vec<CpuSpan>,
}

/// A stretch of CPU work on the host's clock.
#[derive(Clone, Debug)]
pub struct CpuSpan {
    pub name: &'static str,
    pub start: Instant,
    pub ms: f64,
}

/// Finished frames whose timings an engine keeps until they are taken: ten seconds at 60 Hz.
pub const DEFAULT_TIMING_HISTORY: usize = 600;

/// The CPU span spent waiting for a frame slot's previous frame (not recording work).
pub const WAIT_FOR_SLOT: &str = "wait for slot";
/// The CPU span that ends with the frame's submission.
pub const SUBMIT: &str = "submit";

impl FrameTimings {
    /// CPU ms from the start of recording to the submission.
    pub fn cpu_record_ms(&self) -> f64 {
        let spans = || self.cpu.iter().skip_while(|s| s.name == WAIT_FOR_SLOT);
        let until_submit = spans().position(|s| s.name == SUBMIT).map_or(0, |i| i + 1);
        spans().take(until_submit).map(|s| s.ms).sum()
    }

    /// When the frame was submitted, on the host's clock.
    pub fn submitted(&self) -> Option<Instant> {
        self.cpu.iter().find(|s| s.name == SUBMIT).map(|s| s.start + std::time::Duration::from_secs_f64(s.ms * 1e-3))
    }
}

/// Cuts a frame's CPU time into consecutive named spans.
struct SpanClock {
    spans: Vec<CpuSpan>,
    last: Instant,
}

impl SpanClock {
    fn start() -> Self {
        SpanClock { spans: Vec::new(), last: Instant::now() }
    }

    /// Ends the span that began at the previous mark.
    fn mark(&mut self, name: &'static str) {
        let now = Instant::now();
        self.spans.push(CpuSpan { name, start: self.last, ms: (now - self.last).as_secs_f64() * 1e3 });
        self.last = now;
    }
}

/// The camera-sized targets every technique shares.
pub struct CameraTargets {
    pub depth: Target,
    /// Facet normal (facing the camera) and shadow role: what techniques read.
    pub normal: Target,
    /// Interpolated normal: what the composite shades with.
    pub shading: Target,
    pub albedo: Target,
    pub visibility: Target,
    pub color: Target,
}

impl CameraTargets {
    fn new(ctx: &Context, w: u32, h: u32, visibility: vk::Format) -> Result<Self> {
        let sampled = vk::ImageUsageFlags::SAMPLED;
        let readback = vk::ImageUsageFlags::TRANSFER_SRC;
        let descs = [
            TargetDesc::depth("camera depth", w, h).usage(sampled | readback),
            TargetDesc::color("camera normal", NORMAL_FORMAT, w, h).usage(readback),
            TargetDesc::color("camera shading normal", SHADING_FORMAT, w, h),
            TargetDesc::color("camera albedo", ALBEDO_FORMAT, w, h),
            // CPU techniques (`raytrace`, `parker`) copy V in.
            TargetDesc::color("visibility", visibility, w, h).usage(readback | vk::ImageUsageFlags::TRANSFER_DST),
            TargetDesc::color("color", COLOR_FORMAT, w, h).usage(readback),
        ];
        let mut made = Vec::new();
        for desc in descs {
            match Target::new(ctx, desc) {
                Ok(t) => made.push(t),
                Err(e) => {
                    made.into_iter().for_each(|t| t.destroy(ctx));
                    return Err(e);
                }
            }
        }
        let [depth, normal, shading, albedo, visibility, color] =
            <[Target; 6]>::try_from(made).ok().expect("six targets");
        Ok(CameraTargets { depth, normal, shading, albedo, visibility, color })
    }

    fn extent(&self) -> vk::Extent2D {
        self.color.extent()
    }

    fn destroy(self, ctx: &Context) {
        for t in [self.depth, self.normal, self.shading, self.albedo, self.visibility, self.color] {
            t.destroy(ctx);
        }
    }
}

/// Owns the GPU and everything on it; renders scenes frame after frame.
pub struct Engine {
    frames: Option<FrameRing>,
    prepass: Option<Prepass>,
    composite: Option<Composite>,
    meshes: MeshCache,
    globals: Option<PerFrame>,
    objects: Option<PerFrame>,
    targets: Option<CameraTargets>,
    readback: Option<Buffer>,
    technique: Option<(&'static str, Box<dyn Technique>)>,
    visibility_format: vk::Format,
    ground_mesh: Arc<Mesh>,
    frame_number: u64,
    /// Finished frames' timings not yet taken, at most `timing_history` of them.
    timings: std::collections::VecDeque<FrameTimings>,
    timing_history: usize,
    /// CPU spans of submitted frames whose GPU times have not come back yet, oldest first.
    cpu_spans: std::collections::VecDeque<Vec<CpuSpan>>,
    /// The swapchain of an [`Engine::windowed`] engine.
    window: Option<window::Presenter>,
    // Declared last: dropped after everything above is destroyed in `Drop`.
    ctx: Context,
}

impl Engine {
    /// An engine rendering offscreen (tests, the command line, benchmarks).
    pub fn headless(options: &ContextOptions) -> Result<Self> {
        Engine::on(Context::headless(options)?)
    }

    /// The engine's passes on `ctx`; headless and windowed engines differ only in their context.
    fn on(ctx: Context) -> Result<Self> {
        let mut engine = Engine {
            frames: None,
            prepass: None,
            composite: None,
            meshes: MeshCache::default(),
            globals: None,
            objects: None,
            targets: None,
            readback: None,
            technique: None,
            visibility_format: VISIBILITY_FORMAT,
            ground_mesh: Arc::new(primitives::cuboid(Vec3::new(1.0, 0.0, 1.0))?),
            frame_number: 0,
            timings: Default::default(),
            timing_history: DEFAULT_TIMING_HISTORY,
            cpu_spans: Default::default(),
            window: None,
            ctx,
        };
        // On error, `Drop` destroys whatever was made.
        let ctx = &engine.ctx;
        engine.frames = Some(FrameRing::new(ctx)?);
        engine.prepass = Some(Prepass::new(ctx)?);
        engine.composite = Some(Composite::new(ctx, COLOR_FORMAT)?);
        let size = std::mem::size_of::<FrameGlobals>() as u64;
        engine.globals =
            Some(PerFrame::new(ctx, "frame globals", size, FRAMES_IN_FLIGHT, vk::BufferUsageFlags::UNIFORM_BUFFER)?);
        Ok(engine)
    }

    /// Keeps V in 32-bit float so that captures carry it raw
    /// ([`Capture::raw_visibility`]): a diagnostic for stability checks, off by default because
    /// DESIGN.md's V is R16_UNORM. Switching rebuilds the targets and the technique.
    pub fn set_raw_visibility(&mut self, raw: bool) -> Result<()> {
        let format = if raw { RAW_VISIBILITY_FORMAT } else { VISIBILITY_FORMAT };
        if format != self.visibility_format {
            self.ctx.wait_idle()?;
            self.targets.take().into_iter().for_each(|t| t.destroy(&self.ctx));
            self.technique.take().into_iter().for_each(|(_, t)| t.destroy(&self.ctx));
            self.visibility_format = format;
        }
        Ok(())
    }

    pub fn device(&self) -> &DeviceInfo {
        &self.ctx.info
    }

    pub fn context(&self) -> &Context {
        &self.ctx
    }

    /// Renders one frame. Its GPU times become available a frame or two later, in
    /// [`Engine::take_timings`].
    pub fn render(&mut self, scene: &Scene, settings: &FrameSettings) -> Result<()> {
        self.frame(scene, settings, false, None).map(|_| ())
    }

    /// Renders one frame and reads its color and visibility images back (waits for the GPU).
    pub fn render_and_capture(&mut self, scene: &Scene, settings: &FrameSettings) -> Result<Capture> {
        Ok(self.frame(scene, settings, true, None)?.expect("capture requested"))
    }

    /// Timings of the frames finished since the last call, oldest first: the newest
    /// [`Engine::set_timing_history`] of them, so a loop that never asks does not grow.
    pub fn take_timings(&mut self) -> Vec<FrameTimings> {
        std::mem::take(&mut self.timings).into()
    }

    /// How many finished frames' timings are kept for [`Engine::take_timings`] (older ones
    /// are dropped); [`DEFAULT_TIMING_HISTORY`] unless set. At least 1.
    pub fn set_timing_history(&mut self, frames: usize) {
        self.timing_history = frames.max(1);
        while self.timings.len() > self.timing_history {
            self.timings.pop_front();
        }
    }

    /// Waits for every frame in flight, so that their timings are available.
    pub fn flush(&mut self) -> Result<()> {
        let frames = self.frames.as_mut().expect("engine is built");
        let done = frames.drain(&self.ctx)?;
        self.push_timings(done);
        Ok(())
    }

    /// Destroys everything and returns the validation errors recorded over the engine's life,
    /// including objects left alive at device destruction.
    pub fn finish(mut self) -> Vec<String> {
        self.destroy_resources();
        self.ctx.destroy();
        self.ctx.validation_errors()
    }

    fn push_timings(&mut self, done: impl IntoIterator<Item = Vec<PassTime>>) {
        for passes in done {
            let cpu = self.cpu_spans.pop_front().unwrap_or_default();
            if self.timings.len() == self.timing_history {
                self.timings.pop_front();
            }
            self.timings.push_back(FrameTimings { passes, cpu });
        }
    }

    /// Renders a frame into the engine's color target, or into a swapchain image of `window`,
    /// which it acquires, waits on and presents; `None` when not captured, or when the swapchain
    /// is out of date (the frame is dropped before anything is recorded).
    fn frame(
        &mut self,
        scene: &Scene,
        settings: &FrameSettings,
        capture: bool,
        mut window: Option<&mut window::Presenter>,
    ) -> Result<Option<Capture>> {
        scene.validate()?;
        let (w, h) = (settings.width, settings.height);
        self.ensure_targets(w, h)?;
        self.ensure_technique(settings.params.technique)?;

        let ctx = &self.ctx;
        let frames = self.frames.as_mut().expect("engine is built");
        let mut clock = SpanClock::start();
        let (mut frame, earlier) = frames.begin(ctx)?;
        clock.mark(WAIT_FOR_SLOT);
        if let Some(w) = window.as_deref_mut() {
            let acquired = w.acquire(frame.slot)?;
            clock.mark("acquire");
            if !acquired {
                self.push_timings(earlier);
                return Ok(None);
            }
        }
        let number = self.frame_number;
        self.frame_number += 1;
        // The fence just waited on covers every frame up to `number - FRAMES_IN_FLIGHT`.
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
            draws.push(self.meshes.draw(ctx, &o.mesh, number, instance, bounds, (o.casts, o.receives))?);
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
            draws.push(self.meshes.draw(ctx, &self.ground_mesh, number, instance, g.bounds(), (false, true))?);
            objects.push(object_data(model, Mat4::IDENTITY, GROUND_COLOR, ShadowRole::Receives));
        }
        let bytes: &[u8] = cast_slice(&objects);
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let object_buffer = PerFrame::ensure(ctx, &mut self.objects, "objects", bytes.len() as u64, usage)?;
        if !bytes.is_empty() {
            object_buffer.write(frame.slot, bytes);
        }

        let aspect = w as f32 / h as f32;
        let cam = &scene.camera;
        let scene_bounds = draws.iter().fold(Aabb::EMPTY, |b, d| b.union(&d.bounds));
        let camera = CameraProjection::new(cam.position, cam.target, cam.up, cam.projection, aspect, &scene_bounds);
        let globals = FrameGlobals {
            view_proj: camera.view_proj,
            inv_view_proj: camera.inv_view_proj,
            camera_position: cam.position.extend(1.0),
            camera_forward: camera.forward.extend(0.0),
            light: scene.light.position.extend(scene.light.radius),
            light_color: Vec4::ONE,
            ambient: Vec4::splat(AMBIENT),
            sky: Vec3::from(SKY).extend(1.0),
            viewport: Vec4::new(w as f32, h as f32, 1.0 / w as f32, 1.0 / h as f32),
        };
        let globals_buffer = self.globals.as_mut().expect("engine is built");
        globals_buffer.write(frame.slot, bytes_of(&globals));
        let globals_range = globals_buffer.range(frame.slot);
        let objects_range = object_buffer.range(frame.slot);
        let receivers = receivers_in_view(&camera.frustum, &draws);

        clock.mark("draw list");
        let targets = self.targets.as_mut().expect("ensured");
        self.prepass.as_ref().expect("built").record(
            ctx,
            &mut frame,
            targets,
            [globals_range, objects_range],
            &draws,
        )?;
        clock.mark("prepass");
        let (_, technique) = self.technique.as_mut().expect("ensured");
        let mut inputs = FrameInputs {
            ctx,
            cmd: frame.cmd,
            slot: frame.slot,
            timer: &mut *frame.timer,
            scene,
            camera: &camera,
            globals: globals_range,
            objects: objects_range,
            draws: &draws,
            depth: &targets.depth,
            normal: &targets.normal,
            receivers_in_view: &receivers,
        };
        technique.record(&mut inputs, &settings.params, &mut targets.visibility)?;
        clock.mark("technique");
        let (composite, into) = match window.as_deref_mut() {
            Some(w) => {
                let (composite, image) = w.output();
                (composite, Some(image))
            }
            None => (self.composite.as_ref().expect("built"), None),
        };
        composite.record(ctx, &mut frame, targets, into, globals_range)?;
        if capture {
            let size = capture::readback_size(w, h, self.visibility_format);
            if self.readback.as_ref().is_none_or(|b| b.size != size) {
                if let Some(old) = self.readback.take() {
                    old.destroy(ctx);
                }
                let usage = vk::BufferUsageFlags::TRANSFER_DST;
                self.readback = Some(Buffer::new(ctx, "readback", size, usage, MemoryLocation::GpuToCpu)?);
            }
            let readback = self.readback.as_ref().expect("ensured");
            let mut into = window.as_deref_mut().map(|w| w.output().1);
            transition(
                ctx,
                frame.cmd,
                &mut [
                    (into.as_deref_mut().unwrap_or(&mut targets.color), Access::COPY_READ, false),
                    (&mut targets.depth, Access::COPY_READ, false),
                    (&mut targets.normal, Access::COPY_READ, false),
                    (&mut targets.visibility, Access::COPY_READ, false),
                ],
            );
            capture::record_copies(ctx, frame.cmd, targets, into.as_deref(), readback);
            copy_to_host(ctx, frame.cmd);
        }
        let slot = frame.slot;
        // A swapchain image goes to the presentation engine once the frame is done with it.
        let [wait, signal] = match window.as_deref_mut() {
            Some(w) => {
                transition(ctx, frame.cmd, &mut [(w.output().1, Access::PRESENT, false)]);
                w.semaphores(slot).map(|s| vec![s])
            }
            None => [vec![], vec![]],
        };
        let frames = self.frames.as_mut().expect("engine is built");
        frames.submit(ctx, slot, &crate::gpu::Semaphores { wait: &wait, signal: &signal })?;
        clock.mark(SUBMIT);
        if let Some(w) = window {
            w.present(ctx)?;
            clock.mark("present");
        }
        self.push_timings(earlier);
        if !capture {
            self.cpu_spans.push_back(clock.spans);
            return Ok(None);
        }
        let frames = self.frames.as_mut().expect("engine is built");
        let technique = &self.technique.as_ref().expect("ensured").1;
        let (mut bar, mut ticks) = (None, 0);
        // Waits oldest first, so timings stay in submission order. A frame of many seconds (the
        // reference at high sample counts) shows a progress bar on a terminal after half a
        // second; indicatif draws nothing when stderr is not one.
        let done = frames.drain_ticking(&self.ctx, &mut || {
            ticks += 1;
            if ticks < 5 {
                return;
            }
            if let Some((done, total)) = technique.progress(&self.ctx, slot) {
                let bar = bar.get_or_insert_with(|| indicatif::ProgressBar::new(total as u64).with_message("batches"));
                bar.set_position(done as u64);
            }
        })?;
        if let Some(bar) = bar {
            bar.finish_and_clear();
        }
        clock.mark("wait for GPU");
        let readback = self.readback.as_ref().expect("ensured");
        let mut capture = Capture::read(readback, w, h, &camera, self.visibility_format);
        if let Some((_, t)) = &self.technique
            && let Some(surfaces) = t.traced_surfaces()
        {
            capture.surfaces = surfaces.clone();
        }
        clock.mark("readback");
        self.cpu_spans.push_back(clock.spans);
        self.push_timings(done);
        Ok(Some(capture))
    }

    fn ensure_targets(&mut self, w: u32, h: u32) -> Result<()> {
        if self.targets.as_ref().is_some_and(|t| t.extent() == vk::Extent2D { width: w, height: h }) {
            return Ok(());
        }
        if let Some(old) = self.targets.take() {
            self.ctx.wait_idle()?;
            old.destroy(&self.ctx);
        }
        self.targets = Some(CameraTargets::new(&self.ctx, w, h, self.visibility_format)?);
        Ok(())
    }

    fn ensure_technique(&mut self, info: &'static technique::TechniqueInfo) -> Result<()> {
        if self.technique.as_ref().is_some_and(|(name, _)| *name == info.name) {
            return Ok(());
        }
        if let Some((_, old)) = self.technique.take() {
            self.ctx.wait_idle()?;
            old.destroy(&self.ctx);
        }
        self.technique = Some((info.name, info.create(&self.ctx, self.visibility_format)?));
        Ok(())
    }

    fn destroy_resources(&mut self) {
        let ctx = &self.ctx;
        // Nothing more can fail usefully here; the device is going away.
        let _ = ctx.wait_idle();
        if let Some((_, t)) = self.technique.take() {
            t.destroy(ctx);
        }
        std::mem::take(&mut self.meshes).destroy(ctx);
        self.targets.take().into_iter().for_each(|t| t.destroy(ctx));
        self.readback.take().into_iter().for_each(|b| b.destroy(ctx));
        self.window.take().into_iter().for_each(|w| w.destroy(ctx));
        self.globals.take().into_iter().chain(self.objects.take()).for_each(|b| b.destroy(ctx));
        self.prepass.take().into_iter().for_each(|p| p.destroy(ctx));
        self.composite.take().into_iter().for_each(|p| p.destroy(ctx));
        self.frames.take().into_iter().for_each(|f| f.destroy(ctx));
    }
}

impl Drop for Engine {
    fn drop(&mut self) {
        self.destroy_resources();
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
/// camera frustum. Flat receivers are thickened by a hair so clipping keeps them.
fn receivers_in_view(frustum: &Hexahedron, draws: &[Draw]) -> Vec<Vec3> {
    draws
        .iter()
        .filter(|d| d.receives)
        .flat_map(|d| {
            let pad = Vec3::splat(1e-4 * (d.bounds.max - d.bounds.min).max_element().max(f32::MIN_POSITIVE));
            let grown = Aabb { min: d.bounds.min - pad, max: d.bounds.max + pad };
            intersection_points(frustum, &Hexahedron { corners: grown.corners() })
        })
        .collect()
}
