//! The frame of DESIGN.md §1: prepass → technique → composite → readback, and the game-loop
//! API around it. Create an [`Engine`] once, change the scene between frames, render, read
//! timings and images; nothing assumes one frame per process.

mod capture;
mod draw;
mod embed;
mod passes;
mod prepare;
mod window;

use std::sync::Arc;
use std::time::Instant;

use ash::vk;
use glam::Vec3;
use gpu_allocator::MemoryLocation;

pub use capture::{Capture, pixel_uv};
use draw::MeshCache;
pub use embed::{DEPTH_FORMATS, EmbeddedFrame, EmbedderCamera, EmbedderImage, NORMAL_FORMATS, Recorded};
use embed::{Import, ImportTargets, Wrapped};
use passes::{ALBEDO_FORMAT, COLOR_FORMAT, Composite, NORMAL_FORMAT, Prepass, SHADING_FORMAT};
use prepare::FrameData;
pub use window::{AppWindow, Presented, WindowOptions, WindowStats};

use crate::error::{Error, Result};
use crate::frame::interface::FrameGlobals;
use crate::frame::{RAW_VISIBILITY_FORMAT, VISIBILITY_FORMAT};
use crate::geometry::CameraProjection;
use crate::gpu::{
    Access, Buffer, Context, ContextOptions, DeviceInfo, EmbedderHandles, FRAMES_IN_FLIGHT, FrameRing, PassTime,
    PerFrame, Target, TargetDesc, copy_to_host, transition,
};
use crate::scene::{Scene, primitives};
use crate::technique::{self, Params, Technique};

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
    /// `technique` (its per-frame geometry and recording, less the parts it reports apart, such
    /// as the shadow volumes' CPU `silhouettes`, which come just before it), `composite`,
    /// [`SUBMIT`], `present` (a presented frame); a captured frame adds `wait for GPU` and
    /// `readback`.
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

    /// Ends the span that began at the previous mark as `parts` (name, ms), laid end to end,
    /// then `name` for the rest.
    fn mark_split(&mut self, name: &'static str, parts: &[(&'static str, f64)]) {
        let now = Instant::now();
        let mut rest = (now - self.last).as_secs_f64() * 1e3;
        for &(part, ms) in parts {
            let ms = ms.min(rest);
            self.spans.push(CpuSpan { name: part, start: self.last, ms });
            self.last += std::time::Duration::from_secs_f64(ms * 1e-3);
            rest -= ms;
        }
        self.spans.push(CpuSpan { name, start: self.last, ms: rest });
        self.last = now;
    }
}

/// The camera-sized targets every technique shares.
pub struct CameraTargets {
    pub depth: Target,
    /// Facet normal (facing the camera) and shadow role: what techniques read.
    pub normal: Target,
    pub visibility: Target,
    /// What only the engine's own prepass and composite use: an engine that only records into
    /// an embedder's frames never makes them.
    pub shaded: Option<ShadedTargets>,
}

/// The targets of the engine's own shading.
pub struct ShadedTargets {
    /// Interpolated normal: what the composite shades with.
    pub shading: Target,
    pub albedo: Target,
    pub color: Target,
}

/// Makes every target of `descs`, or none.
fn targets<const N: usize>(ctx: &Context, descs: [TargetDesc; N]) -> Result<[Target; N]> {
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
    Ok(<[Target; N]>::try_from(made).ok().expect("one per desc"))
}

impl ShadedTargets {
    fn new(ctx: &Context, extent: vk::Extent2D) -> Result<Self> {
        let (w, h) = (extent.width, extent.height);
        let [shading, albedo, color] = targets(
            ctx,
            [
                TargetDesc::color("camera shading normal", SHADING_FORMAT, w, h),
                TargetDesc::color("camera albedo", ALBEDO_FORMAT, w, h),
                TargetDesc::color("color", COLOR_FORMAT, w, h).usage(vk::ImageUsageFlags::TRANSFER_SRC),
            ],
        )?;
        Ok(ShadedTargets { shading, albedo, color })
    }

    fn destroy(self, ctx: &Context) {
        [self.shading, self.albedo, self.color].into_iter().for_each(|t| t.destroy(ctx));
    }
}

impl CameraTargets {
    fn new(ctx: &Context, w: u32, h: u32, visibility: vk::Format) -> Result<Self> {
        let sampled = vk::ImageUsageFlags::SAMPLED;
        let readback = vk::ImageUsageFlags::TRANSFER_SRC;
        let [depth, normal, visibility] = targets(
            ctx,
            [
                TargetDesc::depth("camera depth", w, h).usage(sampled | readback),
                TargetDesc::color("camera normal", NORMAL_FORMAT, w, h).usage(readback),
                // CPU techniques (`raytrace`, `parker`) copy V in.
                TargetDesc::color("visibility", visibility, w, h).usage(readback | vk::ImageUsageFlags::TRANSFER_DST),
            ],
        )?;
        Ok(CameraTargets { depth, normal, visibility, shaded: None })
    }

    fn extent(&self) -> vk::Extent2D {
        self.depth.extent()
    }

    /// The shading targets, made on first use.
    fn ensure_shaded(&mut self, ctx: &Context) -> Result<&mut ShadedTargets> {
        if self.shaded.is_none() {
            self.shaded = Some(ShadedTargets::new(ctx, self.extent())?);
        }
        Ok(self.shaded.as_mut().expect("made above"))
    }

    fn destroy(self, ctx: &Context) {
        [self.depth, self.normal, self.visibility].into_iter().for_each(|t| t.destroy(ctx));
        self.shaded.into_iter().for_each(|s| s.destroy(ctx));
    }
}

/// Owns the GPU and everything on it; renders scenes frame after frame.
pub struct Engine {
    frames: Option<FrameRing>,
    prepass: Option<Prepass>,
    composite: Option<Composite>,
    import: Option<Import>,
    data: FrameData,
    targets: Option<CameraTargets>,
    readback: Option<Buffer>,
    technique: Option<(&'static str, Box<dyn Technique>)>,
    visibility_format: vk::Format,
    /// The embedder's images wrapped by each slot's last frame: their views live until the slot
    /// comes round again, when that frame has finished.
    wrapped: [Vec<Target>; FRAMES_IN_FLIGHT],
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

    /// An engine on the embedder's instance and device ([`Context::from_handles`]): it creates
    /// and destroys only its own objects, never the instance, device or queue. The device must
    /// have been created with [`required_device_extensions`](crate::gpu::required_device_extensions)
    /// and [`required_vulkan13_features`](crate::gpu::required_vulkan13_features) (at the crate root: `required_device_features`); a device without one is
    /// refused with an error that names it. Record frames into the embedder's command buffers
    /// with [`Engine::record`].
    ///
    /// # Safety
    /// As [`Context::from_handles`]: the handles must be valid, belong together and outlive the
    /// engine, and the queue must not be used from another thread while the engine waits on it
    /// (when it is dropped).
    pub unsafe fn from_handles(handles: EmbedderHandles) -> Result<Self> {
        // SAFETY: the caller's promise, passed on.
        Engine::on(unsafe { Context::from_handles(handles) }?)
    }

    /// The one construction path, on a context of either kind.
    fn on(ctx: Context) -> Result<Self> {
        let mut engine = Engine {
            frames: None,
            prepass: None,
            composite: None,
            import: None,
            data: FrameData {
                meshes: MeshCache::default(),
                globals: None,
                objects: None,
                ground_mesh: Arc::new(primitives::cuboid(Vec3::new(1.0, 0.0, 1.0))?),
                number: 0,
            },
            targets: None,
            readback: None,
            technique: None,
            visibility_format: VISIBILITY_FORMAT,
            wrapped: Default::default(),
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
        engine.import = Some(Import::new(ctx)?);
        let size = std::mem::size_of::<FrameGlobals>() as u64;
        engine.data.globals =
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

    /// Waits for every frame in flight, so that their timings are available. On an engine that
    /// records into the embedder's command buffers, call it only once the embedder has waited
    /// for its frames (their fences are the embedder's).
    pub fn flush(&mut self) -> Result<()> {
        let frames = self.frames.as_mut().expect("engine is built");
        let done = frames.drain(&self.ctx)?;
        self.push_timings(done);
        self.release_staging();
        Ok(())
    }

    /// Destroys everything and returns the validation errors recorded over the engine's life,
    /// including objects left alive at device destruction.
    pub fn finish(mut self) -> Vec<String> {
        self.destroy_resources();
        self.ctx.destroy();
        self.ctx.validation_errors()
    }

    /// Every frame begun has finished: their uploads' staging buffers can go.
    fn release_staging(&mut self) {
        if let Some(last) = self.data.number.checked_sub(1) {
            self.data.meshes.release_staging(&self.ctx, last);
        }
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
        let prepared = self.data.prepare(ctx, &frame, scene, None, vk::Extent2D { width: w, height: h })?;
        clock.mark("draw list");
        let targets = self.targets.as_mut().expect("ensured");
        targets.ensure_shaded(ctx)?;
        self.prepass.as_ref().expect("built").record(
            ctx,
            &mut frame,
            targets,
            prepared.inputs(),
            prepared.surfaces(),
        )?;
        clock.mark("prepass");
        let (_, technique) = self.technique.as_mut().expect("ensured");
        let mut inputs = prepared.frame_inputs(ctx, &mut frame, scene, &targets.depth, &targets.normal);
        technique.record(&mut inputs, &settings.params, &mut targets.visibility)?;
        clock.mark_split("technique", &inputs.cpu_spans);
        let (composite, into) = match window.as_deref_mut() {
            Some(w) => {
                let (composite, image) = w.output();
                (composite, Some(image))
            }
            None => (self.composite.as_ref().expect("built"), None),
        };
        composite.record(ctx, &mut frame, targets, into, prepared.globals)?;
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
                    (
                        into.as_deref_mut().unwrap_or(&mut targets.shaded.as_mut().expect("ensured").color),
                        Access::COPY_READ,
                        false,
                    ),
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
        self.data.meshes.commit();
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
        self.release_staging();
        let readback = self.readback.as_ref().expect("ensured");
        let mut capture = Capture::read(readback, w, h, &prepared.camera, self.visibility_format);
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

    /// Records a frame into the embedder's command buffer (DESIGN.md §3 "Embedding"): the
    /// embedder's camera and depth (and normals) imported (see [`EmbeddedFrame`] for how
    /// receivers and casters are told apart), then the technique of `params` for `scene`'s
    /// casters and light (its camera is not used), writing V into `frame.visibility` or the
    /// engine's own target. Neither submits nor waits: the embedder submits `frame.cmd`.
    ///
    /// The embedder keeps at most [`FRAMES_IN_FLIGHT`] recorded frames unfinished: before
    /// recording frame n it has waited for frame n − 2 to finish (an error says so otherwise),
    /// and it submits every frame it records, or, before recording another, says it never will
    /// with [`Engine::discard_recorded`]. Pass times arrive in [`Engine::take_timings`] as
    /// soon as a later `record` finds them written: one frame late when the GPU keeps up. A
    /// change of size or technique since the last frame never waits: what it replaces is
    /// destroyed [`FRAMES_IN_FLIGHT`] frames later ([`Context::retire`]), or when the engine is
    /// dropped. On an error the command buffer may hold part of the frame: reset it.
    /// Offline CPU techniques (`raytrace`, `parker`) cannot record and are refused.
    pub fn record(&mut self, scene: &Scene, params: &Params, frame: &EmbeddedFrame) -> Result<Recorded> {
        scene.validate()?;
        frame.check(self.visibility_format)?;
        let info = params.technique;
        if info.kind.offline() && info.kind != technique::Kind::GroundTruth(technique::Runs::Gpu) {
            return Err(Error::Invalid(format!(
                "technique {} runs on the CPU: it cannot record into a command buffer",
                info.name
            )));
        }
        let camera = &frame.camera;
        let projection =
            CameraProjection::from_matrices(camera.view, camera.projection, camera.reverse_z, camera.near, camera.far)
                .map_err(Error::Invalid)?;
        let extent = frame.depth.extent;
        self.ensure_targets(extent.width, extent.height)?;
        self.ensure_technique(info)?;

        let ctx = &self.ctx;
        let frames = self.frames.as_mut().expect("engine is built");
        let mut clock = SpanClock::start();
        let (mut gpu_frame, earlier) = frames.begin_external(ctx, frame.cmd)?;
        clock.mark(WAIT_FOR_SLOT);
        let slot = gpu_frame.slot;
        // The slot's last frame has finished: the views made for it can go.
        std::mem::take(&mut self.wrapped[slot]).into_iter().for_each(|t| t.destroy(ctx));
        let mut images = Wrapped::new(ctx, frame)?;
        let mut record = || -> Result<Recorded> {
            let prepared = self.data.prepare(ctx, &gpu_frame, scene, Some(projection), extent)?;
            clock.mark("draw list");
            let targets = self.targets.as_mut().expect("ensured");
            let import = ImportTargets {
                depth: &mut targets.depth,
                normal: &mut targets.normal,
                embedder_depth: &mut images.depth,
                embedder_normal: images.normal.as_mut(),
            };
            let pass = self.import.as_mut().expect("built");
            pass.record(ctx, &mut gpu_frame, import, camera.reverse_z, prepared.inputs(), &prepared.draws)?;
            clock.mark("import");
            let visibility = images.visibility.as_mut().unwrap_or(&mut targets.visibility);
            let (_, technique) = self.technique.as_mut().expect("ensured");
            let mut inputs = prepared.frame_inputs(ctx, &mut gpu_frame, scene, &targets.depth, &targets.normal);
            technique.record(&mut inputs, params, visibility)?;
            // Ready for the embedder's shading to sample.
            transition(ctx, frame.cmd, &mut [(&mut *visibility, Access::FRAGMENT_READ, false)]);
            clock.mark_split("technique", &inputs.cpu_spans);
            Ok(Recorded {
                depth: images.depth.last_access(),
                normal: images.normal.as_ref().map(Target::last_access),
                visibility: visibility.last_access(),
                visibility_image: visibility.image(),
                visibility_view: visibility.view(),
            })
        };
        let recorded = record();
        // Kept until the slot comes round again, on success or not (a failed frame's command
        // buffer may still refer to them until the embedder resets it).
        self.wrapped[slot] = images.into_targets();
        let recorded = recorded?;
        self.frames.as_mut().expect("engine is built").end_external(ctx, slot, frame.cmd);
        self.data.meshes.commit();
        self.push_timings(earlier);
        self.cpu_spans.push_back(clock.spans);
        Ok(recorded)
    }

    /// Forgets the frame the last [`Engine::record`] recorded, which the embedder will never
    /// submit (it resets or frees the command buffer instead): the frame never happened, so
    /// the next `record` uploads again what it uploaded and reuses its slot. Only right after
    /// that `record`, before any other frame: an error otherwise.
    pub fn discard_recorded(&mut self) -> Result<()> {
        self.frames.as_mut().expect("engine is built").discard_external(&self.ctx)?;
        self.data.discard_last();
        Ok(())
    }

    fn ensure_targets(&mut self, w: u32, h: u32) -> Result<()> {
        if self.targets.as_ref().is_some_and(|t| t.extent() == vk::Extent2D { width: w, height: h }) {
            return Ok(());
        }
        if let Some(old) = self.targets.take() {
            self.ctx.retire(move |ctx| old.destroy(ctx));
        }
        self.targets = Some(CameraTargets::new(&self.ctx, w, h, self.visibility_format)?);
        Ok(())
    }

    fn ensure_technique(&mut self, info: &'static technique::TechniqueInfo) -> Result<()> {
        if self.technique.as_ref().is_some_and(|(name, _)| *name == info.name) {
            return Ok(());
        }
        if let Some((_, old)) = self.technique.take() {
            self.ctx.retire(move |ctx| old.destroy(ctx));
        }
        self.technique = Some((info.name, info.create(&self.ctx, self.visibility_format)?));
        Ok(())
    }

    fn destroy_resources(&mut self) {
        let ctx = &self.ctx;
        // Nothing more can fail usefully here; the device is going away.
        let _ = ctx.wait_idle();
        ctx.destroy_retired();
        if let Some((_, t)) = self.technique.take() {
            t.destroy(ctx);
        }
        std::mem::take(&mut self.data.meshes).destroy(ctx);
        self.wrapped.iter_mut().flat_map(std::mem::take).for_each(|t| t.destroy(ctx));
        self.targets.take().into_iter().for_each(|t| t.destroy(ctx));
        self.readback.take().into_iter().for_each(|b| b.destroy(ctx));
        self.window.take().into_iter().for_each(|w| w.destroy(ctx));
        self.data.globals.take().into_iter().chain(self.data.objects.take()).for_each(|b| b.destroy(ctx));
        self.prepass.take().into_iter().for_each(|p| p.destroy(ctx));
        self.import.take().into_iter().for_each(|p| p.destroy(ctx));
        self.composite.take().into_iter().for_each(|p| p.destroy(ctx));
        self.frames.take().into_iter().for_each(|f| f.destroy(ctx));
    }
}

impl Drop for Engine {
    fn drop(&mut self) {
        self.destroy_resources();
    }
}
