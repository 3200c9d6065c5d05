//! The engine with a window (winit + ash-window): a swapchain of the format and present mode
//! the surface offers, re-created (it and the screen-sized targets, nothing else) when the
//! window changes size or the surface goes out of date; frames skipped while minimised. The
//! frame itself is the headless one, handed a swapchain image and its semaphores.

use std::sync::Arc;
use std::time::{Duration, Instant};

use ash::vk;
use winit::application::ApplicationHandler;
use winit::dpi::PhysicalSize;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::platform::pump_events::{EventLoopExtPumpEvents, PumpStatus};
use winit::window::{Window, WindowAttributes, WindowId};

use super::passes::Composite;
use super::{Capture, Engine, FrameSettings};
use crate::error::{Error, Result};
use crate::gpu::{Acquired, Context, ContextOptions, NativeWindow, Swapchain, Target};
use crate::scene::Scene;
use crate::technique::Params;

/// What a windowed engine asks of the surface: a present mode (FIFO unless MAILBOX or
/// IMMEDIATE is asked for and offered) and optionally a surface format.
pub use crate::gpu::SwapchainRequest as WindowOptions;

/// Whether a frame reached the window.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Presented {
    Shown,
    /// The window has no area (minimised): nothing was rendered.
    Skipped,
}

/// What a windowed engine chose and how often it re-created its swapchain.
#[derive(Clone, Debug, PartialEq)]
pub struct WindowStats {
    pub format: vk::Format,
    pub present_mode: vk::PresentModeKHR,
    pub width: u32,
    pub height: u32,
    /// Swapchain re-creations after the first (resizes, out-of-date or suboptimal surfaces).
    pub recreations: u32,
    /// CPU time of the last creation: waiting for the queue, the swapchain and its views.
    pub last_recreation_ms: f64,
    /// Frames asked for while the window had no area.
    pub skipped_frames: u64,
}

/// Where a presenter learns the window's size each frame.
enum Size {
    /// A winit window: its inner size.
    Winit(Arc<Window>),
    /// A native X11 window the embedder owns: the surface's current extent, which X11 keeps
    /// equal to the window's size.
    Surface,
}

/// A window's swapchain and the composite for its format.
pub(super) struct Presenter {
    window: Size,
    request: WindowOptions,
    /// `None` until the window first has an area.
    swapchain: Option<Swapchain>,
    composite: Option<Composite>,
    made_for: PhysicalSize<u32>,
    /// The surface changed since the swapchain was made: re-create before the next frame.
    stale: bool,
    /// The last frame reached the presentation engine.
    presented: bool,
    stats: WindowStats,
}

impl Presenter {
    fn new(window: Size, request: WindowOptions) -> Self {
        let stats = WindowStats {
            format: vk::Format::UNDEFINED,
            present_mode: vk::PresentModeKHR::FIFO,
            width: 0,
            height: 0,
            recreations: 0,
            last_recreation_ms: 0.0,
            skipped_frames: 0,
        };
        Presenter {
            window,
            request,
            swapchain: None,
            composite: None,
            made_for: PhysicalSize::default(),
            stale: false,
            presented: false,
            stats,
        }
    }

    /// The swapchain's size once it matches the window, `None` while the window has no area.
    fn prepare(&mut self, ctx: &Context) -> Result<Option<vk::Extent2D>> {
        let size = match &self.window {
            Size::Winit(window) => window.inner_size(),
            Size::Surface => {
                ctx.surface_extent()?.map_or(PhysicalSize::default(), |e| PhysicalSize::new(e.width, e.height))
            }
        };
        let made_for = self.swapchain.as_ref().map(|_| self.made_for);
        let extent = match step(made_for, self.stale, size, || ctx.surface_extent())? {
            Step::Reuse => return Ok(Some(self.swapchain.as_ref().expect("made").extent())),
            Step::Skip => {
                self.stats.skipped_frames += 1;
                return Ok(None);
            }
            Step::Make(extent) => extent,
        };
        let start = Instant::now();
        // Frames in flight may still use the old images and semaphores.
        ctx.wait_idle()?;
        let swapchain = match &mut self.swapchain {
            Some(swapchain) => {
                swapchain.recreate(ctx, extent)?;
                self.stats.recreations += 1;
                swapchain
            }
            None => self.swapchain.insert(Swapchain::new(ctx, self.request, extent)?),
        };
        let format = swapchain.format();
        if self.stats.format != format {
            if let Some(old) = self.composite.take() {
                old.destroy(ctx);
            }
            self.composite = Some(Composite::new(ctx, format)?);
        }
        let extent = swapchain.extent();
        self.stats = WindowStats {
            format,
            present_mode: swapchain.present_mode(),
            width: extent.width,
            height: extent.height,
            last_recreation_ms: start.elapsed().as_secs_f64() * 1e3,
            ..self.stats
        };
        self.made_for = size;
        self.stale = false;
        Ok(Some(extent))
    }

    /// Acquires an image for frame slot `slot`; `false` when the swapchain is out of date.
    pub(super) fn acquire(&mut self, slot: usize) -> Result<bool> {
        self.presented = false;
        match self.swapchain.as_mut().expect("prepared").acquire(slot)? {
            Acquired::OutOfDate => {
                self.stale = true;
                Ok(false)
            }
            Acquired::Image { suboptimal } => {
                self.stale |= suboptimal;
                Ok(true)
            }
        }
    }

    /// The composite for the swapchain's format and the acquired image it writes.
    pub(super) fn output(&mut self) -> (&Composite, &mut Target) {
        let composite = self.composite.as_ref().expect("prepared");
        (composite, self.swapchain.as_mut().expect("prepared").image())
    }

    /// The frame's wait (image acquired) and signal (image rendered) semaphores.
    pub(super) fn semaphores(&self, slot: usize) -> [(vk::Semaphore, vk::PipelineStageFlags2); 2] {
        self.swapchain.as_ref().expect("prepared").semaphores(slot)
    }

    pub(super) fn present(&mut self, ctx: &Context) -> Result<()> {
        if !self.swapchain.as_mut().expect("prepared").present(ctx)? {
            self.stale = true;
        }
        self.presented = true;
        Ok(())
    }

    /// The presented image's bytes as RGBA, as a headless capture holds them.
    fn to_rgba(&self, mut capture: Capture) -> Capture {
        if matches!(self.stats.format, vk::Format::B8G8R8A8_SRGB | vk::Format::B8G8R8A8_UNORM) {
            capture.color.chunks_exact_mut(4).for_each(|p| p.swap(0, 2));
        }
        capture
    }

    /// The caller has waited for the queue.
    pub(super) fn destroy(self, ctx: &Context) {
        self.swapchain.into_iter().for_each(|s| s.destroy(ctx));
        self.composite.into_iter().for_each(|c| c.destroy(ctx));
    }
}

/// What a frame does with the swapchain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Step {
    /// The swapchain was made for the window's size and is still valid: render into it.
    Reuse,
    /// The window or its surface has no area (minimised): skip the frame, without error.
    Skip,
    /// Make the swapchain (again) at this size, then render.
    Make(vk::Extent2D),
}

/// The decision before each frame, from the window size the swapchain was made for (`None`
/// before there is one), whether the surface has changed since (`stale`), the window's size
/// now, and the surface's current extent (`None` when it has no area), asked only when the
/// swapchain cannot be reused.
fn step(
    made_for: Option<PhysicalSize<u32>>,
    stale: bool,
    window: PhysicalSize<u32>,
    surface: impl FnOnce() -> Result<Option<vk::Extent2D>>,
) -> Result<Step> {
    if !stale && made_for == Some(window) {
        return Ok(Step::Reuse);
    }
    if window.width == 0 || window.height == 0 || surface()?.is_none() {
        return Ok(Step::Skip);
    }
    Ok(Step::Make(vk::Extent2D { width: window.width, height: window.height }))
}

/// Formats whose presented images can be read back as RGBA8.
const READABLE: [vk::Format; 5] = [
    vk::Format::B8G8R8A8_SRGB,
    vk::Format::B8G8R8A8_UNORM,
    vk::Format::R8G8B8A8_SRGB,
    vk::Format::R8G8B8A8_UNORM,
    vk::Format::A8B8G8R8_SRGB_PACK32,
];

impl Engine {
    /// An engine presenting to `window`: the headless engine on a context whose queue can
    /// present, with a swapchain made when the window first has an area.
    pub fn windowed(options: &ContextOptions, window: Arc<Window>, request: WindowOptions) -> Result<Self> {
        let mut engine = Engine::on(Context::windowed(options, window.clone())?)?;
        engine.window = Some(Presenter::new(Size::Winit(window), request));
        Ok(engine)
    }

    /// An engine presenting to the embedder's native `window` (the C ABI's
    /// `softshadow_engine_create_window`), at the window's size, which it reads from the surface
    /// each frame.
    ///
    /// # Safety
    /// As [`Context::native`]: the handles are valid and outlive the engine.
    pub unsafe fn from_native(options: &ContextOptions, window: NativeWindow, request: WindowOptions) -> Result<Self> {
        // SAFETY: the caller's contract, passed on.
        let mut engine = Engine::on(unsafe { Context::native(options, window) }?)?;
        engine.window = Some(Presenter::new(Size::Surface, request));
        Ok(engine)
    }

    /// Renders one frame of `scene` at the window's size with `params` and presents it; skipped
    /// while the window has no area. Its GPU times come back in [`Engine::take_timings`].
    pub fn present(&mut self, scene: &Scene, params: &Params) -> Result<Presented> {
        Ok(self.present_frame(scene, params, false)?.0)
    }

    /// [`Engine::present`], reading back the presented image (as RGBA) and the frame's V and
    /// surfaces; waits for the GPU. `None` when the frame was skipped.
    pub fn present_and_capture(&mut self, scene: &Scene, params: &Params) -> Result<Option<Capture>> {
        if let Some(stats) = self.window_stats()
            && stats.format != vk::Format::UNDEFINED
            && !READABLE.contains(&stats.format)
        {
            return Err(Error::Invalid(format!("presented images of {:?} cannot be read back", stats.format)));
        }
        Ok(self.present_frame(scene, params, true)?.1)
    }

    /// The swapchain's format, present mode, size and re-creations; `None` when headless.
    pub fn window_stats(&self) -> Option<&WindowStats> {
        self.window.as_ref().map(|w| &w.stats)
    }

    fn present_frame(&mut self, scene: &Scene, params: &Params, capture: bool) -> Result<(Presented, Option<Capture>)> {
        let mut presenter =
            self.window.take().ok_or_else(|| Error::Invalid("presenting needs an Engine::windowed".into()))?;
        let result = self.present_with(&mut presenter, scene, params, capture);
        self.window = Some(presenter);
        result
    }

    fn present_with(
        &mut self,
        presenter: &mut Presenter,
        scene: &Scene,
        params: &Params,
        capture: bool,
    ) -> Result<(Presented, Option<Capture>)> {
        // An out-of-date swapchain drops the frame before recording; re-create and try again.
        for _ in 0..2 {
            let Some(extent) = presenter.prepare(&self.ctx)? else { return Ok((Presented::Skipped, None)) };
            let settings = FrameSettings { width: extent.width, height: extent.height, params: params.clone() };
            let captured = self.frame(scene, &settings, capture, Some(presenter))?;
            if presenter.presented {
                return Ok((Presented::Shown, captured.map(|c| presenter.to_rgba(c))));
            }
        }
        Ok((Presented::Skipped, None))
    }
}

/// A window and its event loop, polled once per frame the way a C game loop polls its input
/// (SDL_PollEvent): no callbacks to structure the program around. One per process (winit's
/// rule), on the main thread.
pub struct AppWindow {
    event_loop: EventLoop<()>,
    pump: Pump,
}

struct Pump {
    attributes: WindowAttributes,
    window: Option<Arc<Window>>,
    events: Vec<WindowEvent>,
    failed: Option<String>,
}

impl ApplicationHandler for Pump {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_none() && self.failed.is_none() {
            match event_loop.create_window(self.attributes.clone()) {
                Ok(w) => self.window = Some(Arc::new(w)),
                Err(e) => self.failed = Some(e.to_string()),
            }
        }
    }

    fn window_event(&mut self, _: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        self.events.push(event);
    }
}

impl AppWindow {
    /// Opens a window of `width`×`height` pixels titled `title`. With no display (neither
    /// `DISPLAY` nor `WAYLAND_DISPLAY` set) or a display that refuses, an error says so.
    pub fn open(title: &str, width: u32, height: u32) -> Result<Self> {
        let set = |name: &str| std::env::var_os(name).is_some_and(|v| !v.is_empty());
        if !set("DISPLAY") {
            let why = if set("WAYLAND_DISPLAY") {
                "WAYLAND_DISPLAY is set but this build opens windows through X11 only: set DISPLAY (XWayland)"
            } else {
                "neither DISPLAY nor WAYLAND_DISPLAY is set (run it on a desktop, or under `xvfb-run`)"
            };
            return Err(Error::Window(format!("no display to open a window on: {why}")));
        }
        let mut event_loop =
            EventLoop::new().map_err(|e| Error::Window(format!("cannot open the display {:?}: {e}", display())))?;
        let attributes =
            Window::default_attributes().with_title(title).with_inner_size(PhysicalSize::new(width, height));
        let mut pump = Pump { attributes, window: None, events: Vec::new(), failed: None };
        let start = Instant::now();
        while pump.window.is_none() {
            let status = event_loop.pump_app_events(Some(Duration::ZERO), &mut pump);
            if let Some(e) = pump.failed.take() {
                return Err(Error::Window(format!("cannot open a window: {e}")));
            }
            if matches!(status, PumpStatus::Exit(_)) || start.elapsed() > Duration::from_secs(10) {
                return Err(Error::Window("the window system closed before a window opened".into()));
            }
        }
        Ok(AppWindow { event_loop, pump })
    }

    pub fn window(&self) -> &Arc<Window> {
        self.pump.window.as_ref().expect("opened")
    }

    /// The window's events since the last poll, without waiting.
    pub fn poll(&mut self) -> Vec<WindowEvent> {
        self.event_loop.pump_app_events(Some(Duration::ZERO), &mut self.pump);
        std::mem::take(&mut self.pump.events)
    }
}

fn display() -> String {
    std::env::var("DISPLAY").unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A window's frames through minimising and restoring, as [`Presenter::prepare`] drives
    /// [`step`]: frames are skipped, never an error, while the window or its surface has no area,
    /// and resume after; restored at the size it had, the swapchain is reused, not re-made.
    #[test]
    fn frames_skip_while_the_surface_has_no_area_and_resume_after() {
        let size = |w, h| PhysicalSize::new(w, h);
        let extent = |width, height| Some(vk::Extent2D { width, height });
        // (window size, stale, the surface's current extent, the step expected)
        let frames = [
            (size(64, 48), false, extent(64, 48), Step::Make(vk::Extent2D { width: 64, height: 48 })),
            (size(64, 48), false, None, Step::Reuse),
            // A surface that takes the swapchain's size (Wayland): the window decides.
            (size(0, 0), false, extent(u32::MAX, u32::MAX), Step::Skip),
            (size(64, 0), false, extent(u32::MAX, u32::MAX), Step::Skip),
            // Iconified under X: the window keeps its size, the surface may say it has none.
            (size(64, 48), true, None, Step::Skip),
            (size(64, 48), false, None, Step::Reuse),
            (size(1, 1), false, extent(1, 1), Step::Make(vk::Extent2D { width: 1, height: 1 })),
            (size(0, 0), true, None, Step::Skip),
            (size(32, 32), false, extent(32, 32), Step::Make(vk::Extent2D { width: 32, height: 32 })),
        ];
        let mut made_for = None;
        let mut skipped = 0;
        for (n, (window, stale, surface, expected)) in frames.into_iter().enumerate() {
            let got = step(made_for, stale, window, || Ok(surface)).unwrap();
            assert_eq!(got, expected, "frame {n}: window {window:?}, stale {stale}, surface {surface:?}");
            match got {
                Step::Make(_) => made_for = Some(window),
                Step::Skip => skipped += 1,
                Step::Reuse => {}
            }
        }
        assert_eq!(skipped, 4);
    }

    #[test]
    fn a_failing_surface_query_is_an_error_not_a_skip() {
        let failed = || Err(Error::Invalid("surface lost".into()));
        assert!(step(None, false, PhysicalSize::new(8, 8), failed).is_err());
    }
}
