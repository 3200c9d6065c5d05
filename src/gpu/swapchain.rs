//! Presentation: a window's surface, made through the device filter so that headless and
//! windowed contexts share one construction path (hypermine's `Base::new`), and a swapchain
//! whose images are wrapped [`Target`]s, acquired and presented with semaphores.

use std::ffi::{CStr, c_ulong, c_void};
use std::num::{NonZeroIsize, NonZeroU32};
use std::ptr::NonNull;
use std::sync::Arc;

use ash::vk;
use raw_window_handle::{
    DisplayHandle, HandleError, HasDisplayHandle, HasWindowHandle, RawDisplayHandle, RawWindowHandle,
    WaylandDisplayHandle, WaylandWindowHandle, Win32WindowHandle, WindowHandle, WindowsDisplayHandle, XcbDisplayHandle,
    XcbWindowHandle, XlibDisplayHandle, XlibWindowHandle,
};

use super::barrier::Access;
use super::frames::FRAMES_IN_FLIGHT;
use super::target::{Target, TargetDesc};
use super::{Context, ContextOptions, DeviceFilter};
use crate::error::{Error, Result, VkContext};

/// How presented frames reach the screen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum PresentMode {
    /// Wait for the vertical blank, never tear; every Vulkan device has it.
    #[default]
    Fifo,
    /// Replace the queued frame with a newer one: no tearing, lowest latency, no throttling.
    Mailbox,
    /// Present at once; may tear.
    Immediate,
}

impl PresentMode {
    fn vk(self) -> vk::PresentModeKHR {
        match self {
            PresentMode::Fifo => vk::PresentModeKHR::FIFO,
            PresentMode::Mailbox => vk::PresentModeKHR::MAILBOX,
            PresentMode::Immediate => vk::PresentModeKHR::IMMEDIATE,
        }
    }
}

/// 8-bit sRGB formats, in order of preference: the hardware encodes what the composite writes.
const SRGB_FORMATS: [vk::Format; 3] =
    [vk::Format::B8G8R8A8_SRGB, vk::Format::R8G8B8A8_SRGB, vk::Format::A8B8G8R8_SRGB_PACK32];

/// Whether writes to `format` are sRGB-encoded by the hardware.
pub fn is_srgb(format: vk::Format) -> bool {
    SRGB_FORMATS.contains(&format)
}

impl Context {
    /// A context whose queue presents to `window`: [`Context::new`] with a filter adding the
    /// window system's instance extensions, the swapchain extension and the window's surface.
    /// The context keeps `window` alive until the surface is destroyed.
    pub fn windowed<W>(options: &ContextOptions, window: Arc<W>) -> Result<Context>
    where
        W: HasDisplayHandle + HasWindowHandle + Send + Sync + 'static,
    {
        let handle_error = |e: HandleError| Error::Window(format!("no window handle: {e}"));
        let display = window.display_handle().map_err(handle_error)?.as_raw();
        let raw = window.window_handle().map_err(handle_error)?.as_raw();
        let instance_extensions: Vec<&CStr> = ash_window::enumerate_required_extensions(display)
            .map_err(|e| Error::Window(format!("this window system has no Vulkan surface: {e}")))?
            .iter()
            // SAFETY: ash-window hands out pointers to static extension names.
            .map(|&name| unsafe { CStr::from_ptr(name) })
            .collect();
        let create = |entry: &ash::Entry, instance: &ash::Instance| {
            // SAFETY: the handles are the window's, and the context keeps the window alive for as
            // long as the surface lives.
            unsafe { ash_window::create_surface(entry, instance, display, raw, None) }.vk("vkCreateSurfaceKHR")
        };
        let filter = DeviceFilter {
            instance_extensions: &instance_extensions,
            device_extensions: &[ash::khr::swapchain::NAME],
            requirement: "can present to the window",
            surface: Some(&create),
            ..DeviceFilter::HEADLESS
        };
        let mut ctx = Context::new(options, &filter)?;
        ctx.window = Some(window);
        Ok(ctx)
    }

    /// A context presenting to the embedder's native `window`. A window system whose surface
    /// extension the Vulkan loader lacks (Win32 off Windows, Wayland without a Wayland-enabled
    /// driver) is refused, the extension named.
    ///
    /// # Safety
    /// The handles are valid (an open display or connection, a live window or surface on it)
    /// and outlive the context.
    pub unsafe fn native(options: &ContextOptions, window: NativeWindow) -> Result<Context> {
        if let NativeWindow::Xlib { window: 0, .. } = window {
            return Err(Error::Invalid("the Xlib window is None (0)".into()));
        }
        Context::windowed(options, Arc::new(window)).map_err(|e| match e {
            Error::NoDevice(why) => Error::NoDevice(format!("cannot present to the {} window: {why}", window.kind())),
            e => e,
        })
    }

    fn surface(&self) -> Result<&(ash::khr::surface::Instance, vk::SurfaceKHR)> {
        self.surface.as_ref().ok_or_else(|| Error::Invalid("a swapchain needs a Context::windowed".into()))
    }

    /// The size the surface has now: `None` while it has no area (a minimised window).
    pub fn surface_extent(&self) -> Result<Option<vk::Extent2D>> {
        let (loader, surface) = self.surface()?;
        let caps = unsafe { loader.get_physical_device_surface_capabilities(self.physical, *surface) }
            .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let e = caps.current_extent;
        // u32::MAX: the surface takes the swapchain's size (Wayland); the window decides.
        Ok((e.width != 0 && e.height != 0).then_some(e))
    }
}

/// What a swapchain is asked for; what the surface offers decides.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SwapchainRequest {
    /// Taken when offered; FIFO otherwise.
    pub present_mode: PresentMode,
    /// A surface format to take when offered; otherwise an 8-bit sRGB one, or the first.
    pub format: Option<vk::Format>,
}

/// What acquiring an image found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Acquired {
    /// An image to render into; `suboptimal`: present it, then re-create.
    Image { suboptimal: bool },
    /// The surface changed: re-create before rendering.
    OutOfDate,
}

/// A swapchain, its images as targets, and the semaphores that order them: one "acquired" per
/// frame slot (free again once the slot's fence has been waited on) and one "rendered" per
/// image (free again once that image is acquired again).
pub struct Swapchain {
    loader: ash::khr::swapchain::Device,
    handle: vk::SwapchainKHR,
    request: SwapchainRequest,
    format: vk::SurfaceFormatKHR,
    present_mode: vk::PresentModeKHR,
    images: Vec<Target>,
    acquired: Vec<vk::Semaphore>,
    rendered: Vec<vk::Semaphore>,
    current: Option<u32>,
}

impl Swapchain {
    /// A swapchain for the context's surface at `extent` (the window's size, used where the
    /// surface leaves it open); it needs a surface of non-zero size.
    pub fn new(ctx: &Context, request: SwapchainRequest, extent: vk::Extent2D) -> Result<Self> {
        let mut swapchain = Swapchain {
            loader: ash::khr::swapchain::Device::new(&ctx.instance, &ctx.device),
            handle: vk::SwapchainKHR::null(),
            request,
            format: vk::SurfaceFormatKHR::default(),
            present_mode: vk::PresentModeKHR::FIFO,
            images: Vec::new(),
            acquired: Vec::new(),
            rendered: Vec::new(),
            current: None,
        };
        let made = (0..FRAMES_IN_FLIGHT).try_for_each(|_| {
            swapchain.acquired.push(semaphore(ctx)?);
            Ok(())
        });
        if let Err(e) = made.and_then(|()| swapchain.recreate(ctx, extent)) {
            swapchain.destroy(ctx);
            return Err(e);
        }
        Ok(swapchain)
    }

    /// Re-creates the swapchain and its images for the surface as it is now; nothing else. The
    /// caller has waited for the queue to drain.
    pub fn recreate(&mut self, ctx: &Context, extent: vk::Extent2D) -> Result<()> {
        let (surface_loader, surface) = ctx.surface()?;
        let physical = ctx.physical;
        let caps = unsafe { surface_loader.get_physical_device_surface_capabilities(physical, *surface) }
            .vk("vkGetPhysicalDeviceSurfaceCapabilitiesKHR")?;
        let formats = unsafe { surface_loader.get_physical_device_surface_formats(physical, *surface) }
            .vk("vkGetPhysicalDeviceSurfaceFormatsKHR")?;
        let modes = unsafe { surface_loader.get_physical_device_surface_present_modes(physical, *surface) }
            .vk("vkGetPhysicalDeviceSurfacePresentModesKHR")?;
        let offered = |f: vk::Format| formats.iter().copied().find(|s| s.format == f);
        self.format = self
            .request
            .format
            .and_then(offered)
            .or_else(|| SRGB_FORMATS.into_iter().find_map(offered))
            .or_else(|| formats.first().copied())
            .ok_or_else(|| Error::Window("the surface offers no format".into()))?;
        let wanted = self.request.present_mode.vk();
        self.present_mode = if modes.contains(&wanted) { wanted } else { vk::PresentModeKHR::FIFO };
        let extent = if caps.current_extent.width == u32::MAX {
            vk::Extent2D {
                width: extent.width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: extent.height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        } else {
            caps.current_extent
        };
        // One more than the minimum, so acquiring need not wait for the presentation engine.
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        // Readback of presented images (tests, screenshots) copies from them.
        let usage =
            vk::ImageUsageFlags::COLOR_ATTACHMENT | (caps.supported_usage_flags & vk::ImageUsageFlags::TRANSFER_SRC);
        let alpha = [
            vk::CompositeAlphaFlagsKHR::OPAQUE,
            vk::CompositeAlphaFlagsKHR::INHERIT,
            vk::CompositeAlphaFlagsKHR::PRE_MULTIPLIED,
            vk::CompositeAlphaFlagsKHR::POST_MULTIPLIED,
        ]
        .into_iter()
        .find(|&a| caps.supported_composite_alpha.contains(a))
        .unwrap_or(vk::CompositeAlphaFlagsKHR::OPAQUE);
        let old = self.handle;
        let ci = vk::SwapchainCreateInfoKHR::default()
            .surface(*surface)
            .min_image_count(count)
            .image_format(self.format.format)
            .image_color_space(self.format.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(usage)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(alpha)
            .present_mode(self.present_mode)
            .clipped(true)
            .old_swapchain(old);
        let handle = unsafe { self.loader.create_swapchain(&ci, ctx.host_allocator()) }.vk("vkCreateSwapchainKHR")?;
        self.destroy_images(ctx);
        if old != vk::SwapchainKHR::null() {
            unsafe { self.loader.destroy_swapchain(old, ctx.host_allocator()) };
        }
        self.handle = handle;
        ctx.name(handle, "swapchain");
        let images = unsafe { self.loader.get_swapchain_images(handle) }.vk("vkGetSwapchainImagesKHR")?;
        let desc =
            TargetDesc { name: "swapchain image", format: self.format.format, extent, usage, reinterpreted: None };
        for image in images {
            self.images.push(Target::wrap(ctx, desc, image, None, Access::NONE)?);
            self.rendered.push(semaphore(ctx)?);
        }
        Ok(())
    }

    pub fn extent(&self) -> vk::Extent2D {
        self.images.first().map_or_else(Default::default, Target::extent)
    }

    /// The surface format chosen.
    pub fn format(&self) -> vk::Format {
        self.format.format
    }

    /// The present mode chosen: the one requested when the surface offers it, FIFO otherwise.
    pub fn present_mode(&self) -> vk::PresentModeKHR {
        self.present_mode
    }

    /// Acquires the next image for frame slot `slot`, whose fence the caller has waited on.
    pub fn acquire(&mut self, slot: usize) -> Result<Acquired> {
        let semaphore = self.acquired[slot];
        let result = unsafe { self.loader.acquire_next_image(self.handle, u64::MAX, semaphore, vk::Fence::null()) };
        match result {
            Ok((index, suboptimal)) => {
                self.current = Some(index);
                // The semaphore is waited on at this stage: the barrier out of it starts there.
                self.images[index as usize].last = Access::PRESENT;
                Ok(Acquired::Image { suboptimal })
            }
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(Acquired::OutOfDate),
            Err(result) => Err(Error::Vulkan { call: "vkAcquireNextImageKHR", result }),
        }
    }

    /// The image acquired last.
    pub fn image(&mut self) -> &mut Target {
        let index = self.current.expect("an image is acquired");
        &mut self.images[index as usize]
    }

    /// What the frame in `slot` waits on (the image is acquired) and signals (it is rendered),
    /// each at [`Access::PRESENT`]'s stage.
    pub fn semaphores(&self, slot: usize) -> [(vk::Semaphore, vk::PipelineStageFlags2); 2] {
        let index = self.current.expect("an image is acquired") as usize;
        [(self.acquired[slot], Access::PRESENT.stage), (self.rendered[index], Access::PRESENT.stage)]
    }

    /// Presents the acquired image once its frame has rendered; `false` when the surface has
    /// changed (out of date or suboptimal) and the swapchain should be re-created.
    pub fn present(&mut self, ctx: &Context) -> Result<bool> {
        let index = self.current.take().expect("an image is acquired");
        let (swapchains, indices, wait) = ([self.handle], [index], [self.rendered[index as usize]]);
        let info = vk::PresentInfoKHR::default().wait_semaphores(&wait).swapchains(&swapchains).image_indices(&indices);
        match unsafe { self.loader.queue_present(ctx.queue, &info) } {
            Ok(suboptimal) => Ok(!suboptimal),
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(false),
            Err(result) => Err(Error::Vulkan { call: "vkQueuePresentKHR", result }),
        }
    }

    fn destroy_images(&mut self, ctx: &Context) {
        for image in self.images.drain(..) {
            image.destroy(ctx);
        }
        for s in self.rendered.drain(..) {
            unsafe { ctx.device.destroy_semaphore(s, ctx.host_allocator()) };
        }
    }

    /// Destroys the swapchain, its views and semaphores; the caller has waited for the queue.
    pub fn destroy(mut self, ctx: &Context) {
        self.destroy_images(ctx);
        for s in self.acquired.drain(..) {
            unsafe { ctx.device.destroy_semaphore(s, ctx.host_allocator()) };
        }
        if self.handle != vk::SwapchainKHR::null() {
            unsafe { self.loader.destroy_swapchain(self.handle, ctx.host_allocator()) };
        }
    }
}

fn semaphore(ctx: &Context) -> Result<vk::Semaphore> {
    unsafe { ctx.device.create_semaphore(&vk::SemaphoreCreateInfo::default(), ctx.host_allocator()) }
        .vk("vkCreateSemaphore")
}

/// A window the embedder owns, by its native handles (the C ABI's `softshadow_native_window`),
/// for the window handle traits [`Context::windowed`] takes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum NativeWindow {
    /// An Xlib `Display*` and `Window`.
    Xlib { display: NonNull<c_void>, window: c_ulong },
    /// An `xcb_connection_t*` and `xcb_window_t`.
    Xcb { connection: NonNull<c_void>, window: NonZeroU32 },
    /// A `wl_display*` and `wl_surface*`.
    Wayland { display: NonNull<c_void>, surface: NonNull<c_void> },
    /// An `HWND` and, optionally, its `HINSTANCE`.
    Win32 { hinstance: Option<NonZeroIsize>, hwnd: NonZeroIsize },
}

impl NativeWindow {
    /// The window system's name, for messages.
    pub fn kind(&self) -> &'static str {
        match self {
            NativeWindow::Xlib { .. } => "Xlib",
            NativeWindow::Xcb { .. } => "xcb",
            NativeWindow::Wayland { .. } => "Wayland",
            NativeWindow::Win32 { .. } => "Win32",
        }
    }
}

// SAFETY: only handles the engine hands to Vulkan, whose surface functions may be called from
// any thread (the window system's libraries synchronise their own use of the connection).
unsafe impl Send for NativeWindow {}
unsafe impl Sync for NativeWindow {}

impl HasDisplayHandle for NativeWindow {
    fn display_handle(&self) -> std::result::Result<DisplayHandle<'_>, HandleError> {
        let raw: RawDisplayHandle = match *self {
            NativeWindow::Xlib { display, .. } => XlibDisplayHandle::new(Some(display), 0).into(),
            NativeWindow::Xcb { connection, .. } => XcbDisplayHandle::new(Some(connection), 0).into(),
            NativeWindow::Wayland { display, .. } => WaylandDisplayHandle::new(display).into(),
            NativeWindow::Win32 { .. } => WindowsDisplayHandle::new().into(),
        };
        // SAFETY: the embedder keeps the display open while the engine lives (Context::native's
        // contract).
        Ok(unsafe { DisplayHandle::borrow_raw(raw) })
    }
}

impl HasWindowHandle for NativeWindow {
    fn window_handle(&self) -> std::result::Result<WindowHandle<'_>, HandleError> {
        let raw: RawWindowHandle = match *self {
            NativeWindow::Xlib { window, .. } => XlibWindowHandle::new(window).into(),
            NativeWindow::Xcb { window, .. } => XcbWindowHandle::new(window).into(),
            NativeWindow::Wayland { surface, .. } => WaylandWindowHandle::new(surface).into(),
            NativeWindow::Win32 { hinstance, hwnd } => {
                let mut handle = Win32WindowHandle::new(hwnd);
                handle.hinstance = hinstance;
                handle.into()
            }
        };
        // SAFETY: the embedder keeps the window alive while the engine lives (Context::native's
        // contract).
        Ok(unsafe { WindowHandle::borrow_raw(raw) })
    }
}
