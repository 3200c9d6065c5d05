//! The C ABI (DESIGN.md §3 "Embedding", rustls-ffi style): opaque handles made by `_create`
//! (or `_load`) and freed by `_destroy`, a status code from every function, the last error's
//! message from [`softshadow_last_error`], and no panic across the boundary (each export runs
//! inside `catch_unwind`; a panic becomes [`softshadow_status::SOFTSHADOW_ERROR_PANIC`]).
//! `include/softshadow.h` is generated from this file by cbindgen (`tests/c_abi.rs` fails when
//! the checked-in header differs from a fresh generation).
//!
//! Strings are passed with a bound: `(const char *s, size_t max_len)`, NUL-terminated within
//! `max_len` bytes and UTF-8, or the call fails. Vulkan handles cross as `void *` (dispatchable)
//! and `uint64_t` (non-dispatchable), so the header needs no Vulkan header.
//!
//! Every `unsafe` here dereferences a pointer the C caller handed in, under the contract each
//! function's documentation states.

#![allow(non_camel_case_types)]

use std::cell::RefCell;
use std::ffi::{c_char, c_ulong, c_void};
use std::num::{NonZeroIsize, NonZeroU32};
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::ptr::NonNull;
use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Vec3};

use crate::error::Error;
use crate::geometry::Projection;
use crate::gpu::{Access, ContextOptions, EmbedderHandles, NativeWindow};
use crate::renderer::{
    EmbeddedFrame, EmbedderCamera, EmbedderImage, Engine, FrameSettings, FrameTimings, Presented, WindowOptions,
};
use crate::scene::{Camera, Ground, Light, Mesh, Object, RenderSettings, Scene, Transform};
use crate::technique::{Params, find};

/// What every function returns.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum softshadow_status {
    SOFTSHADOW_OK = 0,
    /// A handle or pointer argument was NULL.
    SOFTSHADOW_ERROR_NULL = 1,
    /// An argument is out of range, unknown or malformed (a string, a technique, a knob).
    SOFTSHADOW_ERROR_INVALID = 2,
    /// A scene file or scene description is malformed.
    SOFTSHADOW_ERROR_SCENE = 3,
    /// No usable Vulkan device, or the embedder's device lacks what the engine needs.
    SOFTSHADOW_ERROR_DEVICE = 4,
    /// A Vulkan call or a GPU allocation failed.
    SOFTSHADOW_ERROR_VULKAN = 5,
    /// A file could not be read or written.
    SOFTSHADOW_ERROR_IO = 6,
    /// A caller's buffer is smaller than the data.
    SOFTSHADOW_ERROR_BUFFER_TOO_SMALL = 7,
    /// The library panicked (a bug); the handle involved should be destroyed.
    SOFTSHADOW_ERROR_PANIC = 8,
}

use softshadow_status::*;

/// An engine and what it renders at: size, technique and knobs, and the last finished frame's
/// pass times.
pub struct softshadow_engine {
    engine: Engine,
    settings: FrameSettings,
    last_timings: Option<FrameTimings>,
}

/// A scene: casters, receivers, one light, one camera.
pub struct softshadow_scene {
    scene: Scene,
}

/// A perspective camera (`fov_y_deg` > 0) or an orthographic one (`fov_y_deg` = 0 and
/// `ortho_half_height` > 0), DESIGN.md §3's conventions.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_camera {
    pub position: [f32; 3],
    pub target: [f32; 3],
    pub up: [f32; 3],
    pub fov_y_deg: f32,
    pub ortho_half_height: f32,
}

/// A spherical area light (radius 0: a point light).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_light {
    pub position: [f32; 3],
    pub radius: f32,
}

/// Where an object is: translation, right-handed Euler degrees (X, then Y, then Z) and scale.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_transform {
    pub position: [f32; 3],
    pub rotation_deg: [f32; 3],
    pub scale: [f32; 3],
}

/// One object: a triangle mesh (`vertex_count` xyz positions, `index_count` indices, three per
/// triangle) placed by `transform`.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_object {
    pub positions: *const f32,
    pub vertex_count: usize,
    pub indices: *const u32,
    pub index_count: usize,
    pub transform: softshadow_transform,
    /// Linear RGB albedo.
    pub color: [f32; 3],
    /// Non-zero: the object casts shadows / receives them.
    pub casts: u32,
    pub receives: u32,
}

/// A scene described in C: camera, light, an optional ground plane y = `ground_height` of half
/// size `ground_half_size` (`has_ground` non-zero), and `object_count` objects.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_scene_desc {
    pub camera: softshadow_camera,
    pub light: softshadow_light,
    pub has_ground: u32,
    pub ground_height: f32,
    pub ground_half_size: f32,
    pub objects: *const softshadow_object,
    pub object_count: usize,
}

/// One pass of the last finished frame: its name (NUL-terminated) and GPU milliseconds.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_pass_time {
    pub name: [c_char; 32],
    pub gpu_ms: f64,
}

/// The embedder's Vulkan objects: `vkGetInstanceProcAddr`, the instance, physical device and
/// device (created with `softshadow_required_device_extension` and the Vulkan 1.3 features
/// dynamicRendering, synchronization2 and maintenance4), a queue of `queue_family`, and
/// optionally the embedder's `VkAllocationCallbacks` (NULL: none), copied at creation and passed
/// to every `vkCreate*` / `vkDestroy*` of the engine's objects and to the `vkAllocateMemory` /
/// `vkFreeMemory` of its device memory: its functions and user data must outlive the engine.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_vulkan {
    pub get_instance_proc_addr: *const c_void,
    pub instance: *const c_void,
    pub physical_device: *const c_void,
    pub device: *const c_void,
    pub queue_family: u32,
    pub queue_index: u32,
    pub allocation_callbacks: *const c_void,
}

/// The embedder's allocation callbacks at `p` (NULL: none), checked as Vulkan requires them:
/// allocation, reallocation and free set, the internal notifications both set or neither.
fn allocation_callbacks(p: *const c_void) -> Result<Option<vk::AllocationCallbacks<'static>>, Failure> {
    // SAFETY: the caller's contract: NULL or a valid VkAllocationCallbacks.
    let Some(c) = (unsafe { (p as *const vk::AllocationCallbacks<'_>).as_ref() }) else {
        return Ok(None);
    };
    if c.pfn_allocation.is_none() || c.pfn_reallocation.is_none() || c.pfn_free.is_none() {
        return Err(invalid("allocation_callbacks: pfnAllocation, pfnReallocation and pfnFree must all be set"));
    }
    if c.pfn_internal_allocation.is_some() != c.pfn_internal_free.is_some() {
        return Err(invalid("allocation_callbacks: set both internal notifications or neither"));
    }
    Ok(Some(vk::AllocationCallbacks {
        p_user_data: c.p_user_data,
        pfn_allocation: c.pfn_allocation,
        pfn_reallocation: c.pfn_reallocation,
        pfn_free: c.pfn_free,
        pfn_internal_allocation: c.pfn_internal_allocation,
        pfn_internal_free: c.pfn_internal_free,
        _marker: std::marker::PhantomData,
    }))
}

/// The state an image is in: `VkImageLayout`, and the `VkPipelineStageFlags2` and
/// `VkAccessFlags2` of the last command that touched it.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct softshadow_image_state {
    pub layout: i32,
    pub stage: u64,
    pub access: u64,
}

/// One of the embedder's images (`VkImage`, `VkFormat`, size) and the state it is in.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_image {
    pub image: u64,
    pub format: i32,
    pub width: u32,
    pub height: u32,
    pub state: softshadow_image_state,
}

/// A frame recorded into the embedder's command buffer: its camera (view and projection
/// matrices, column-major, Vulkan clip space), its depth, optionally normals and V's image
/// (`image` 0: none; without V's image the engine's own target is written).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_embedded_frame {
    pub command_buffer: *const c_void,
    pub view: [f32; 16],
    pub projection: [f32; 16],
    pub reverse_z: u32,
    pub near: f32,
    pub far: f32,
    pub depth: softshadow_image,
    pub normal: softshadow_image,
    pub visibility: softshadow_image,
}

/// What `softshadow_record` left each image in, and V's image and view.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default)]
pub struct softshadow_recorded {
    pub depth: softshadow_image_state,
    pub normal: softshadow_image_state,
    pub visibility: softshadow_image_state,
    pub visibility_image: u64,
    pub visibility_view: u64,
}

/// A failure: the status to return and the message to keep.
struct Failure(softshadow_status, String);

impl From<Error> for Failure {
    fn from(e: Error) -> Self {
        let status = match &e {
            Error::Scene { .. } => SOFTSHADOW_ERROR_SCENE,
            Error::Invalid(_) => SOFTSHADOW_ERROR_INVALID,
            Error::NoDevice(_) | Error::Window(_) => SOFTSHADOW_ERROR_DEVICE,
            Error::Vulkan { .. } | Error::Memory(_) => SOFTSHADOW_ERROR_VULKAN,
            Error::Io { .. } | Error::Image { .. } => SOFTSHADOW_ERROR_IO,
        };
        Failure(status, e.to_string())
    }
}

fn invalid(what: impl Into<String>) -> Failure {
    Failure(SOFTSHADOW_ERROR_INVALID, what.into())
}

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

/// Runs an export: its error or panic becomes a status and the thread's last error.
fn guard(f: impl FnOnce() -> Result<(), Failure>) -> softshadow_status {
    let outcome = catch_unwind(AssertUnwindSafe(f)).unwrap_or_else(|panic| {
        let what = panic
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| panic.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown".into());
        Err(Failure(SOFTSHADOW_ERROR_PANIC, format!("softshadow panicked: {what}")))
    });
    match outcome {
        Ok(()) => SOFTSHADOW_OK,
        Err(Failure(status, message)) => {
            LAST_ERROR.with(|e| *e.borrow_mut() = message);
            status
        }
    }
}

fn non_null<'a, T>(p: *const T, what: &str) -> Result<&'a T, Failure> {
    // SAFETY: the caller's contract: a non-NULL pointer points at a valid, live `T`.
    unsafe { p.as_ref() }.ok_or_else(|| Failure(SOFTSHADOW_ERROR_NULL, format!("{what} is NULL")))
}

fn non_null_mut<'a, T>(p: *mut T, what: &str) -> Result<&'a mut T, Failure> {
    // SAFETY: as `non_null`, and no one else uses it during the call.
    unsafe { p.as_mut() }.ok_or_else(|| Failure(SOFTSHADOW_ERROR_NULL, format!("{what} is NULL")))
}

/// A bounded C string: NUL-terminated within `max_len` bytes, and UTF-8.
fn string<'a>(s: *const c_char, max_len: usize, what: &str) -> Result<&'a str, Failure> {
    if s.is_null() {
        return Err(Failure(SOFTSHADOW_ERROR_NULL, format!("{what} is NULL")));
    }
    // SAFETY: the caller's contract: `s` is readable for `max_len` bytes or up to its NUL.
    let bytes = unsafe { std::slice::from_raw_parts(s as *const u8, max_len) };
    let end = bytes
        .iter()
        .position(|&b| b == 0)
        .ok_or_else(|| invalid(format!("{what} is not NUL-terminated within {max_len} bytes")))?;
    std::str::from_utf8(&bytes[..end]).map_err(|e| invalid(format!("{what} is not UTF-8: {e}")))
}

fn out<T>(p: *mut T, value: T, what: &str) -> Result<(), Failure> {
    let slot = non_null_mut(p, what)?;
    *slot = value;
    Ok(())
}

fn finite3(v: [f32; 3], what: &str) -> Result<Vec3, Failure> {
    if v.iter().all(|x| x.is_finite()) {
        Ok(Vec3::from(v))
    } else {
        Err(invalid(format!("{what} {v:?} is not finite")))
    }
}

/// The library's version, `major.minor.patch`: a static string, never freed.
#[unsafe(no_mangle)]
pub extern "C" fn softshadow_version() -> *const c_char {
    concat!(env!("CARGO_PKG_VERSION"), "\0").as_ptr() as *const c_char
}

/// Copies the calling thread's last error message into `buf` (at most `len` bytes, NUL
/// included, truncated to fit; nothing when `buf` is NULL or `len` is 0) and returns the
/// message's full length without the NUL. Safe to call at any time; "" before any error.
///
/// # Safety
/// `buf` is NULL or writable for `len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_last_error(buf: *mut c_char, len: usize) -> usize {
    catch_unwind(|| {
        LAST_ERROR.with(|e| {
            let message = e.borrow();
            if !buf.is_null() && len > 0 {
                let n = message.len().min(len - 1);
                // SAFETY: the caller's contract: `buf` is writable for `len` bytes.
                unsafe {
                    std::ptr::copy_nonoverlapping(message.as_ptr(), buf as *mut u8, n);
                    *buf.add(n) = 0;
                }
            }
            message.len()
        })
    })
    .unwrap_or(0)
}

/// The device extensions an embedder's device must enable, one at a time: `index` from 0;
/// NULL past the last. Static strings.
#[unsafe(no_mangle)]
pub extern "C" fn softshadow_required_device_extension(index: usize) -> *const c_char {
    crate::gpu::required_device_extensions().get(index).map_or(std::ptr::null(), |e| e.as_ptr())
}

fn new_engine(engine: Engine, out_engine: *mut *mut softshadow_engine) -> Result<(), Failure> {
    let params = Params::defaults(find(&RenderSettings::default().technique)?);
    let handle =
        softshadow_engine { engine, settings: FrameSettings { width: 256, height: 256, params }, last_timings: None };
    out(out_engine, Box::into_raw(Box::new(handle)), "out_engine")
}

/// Creates an engine on a device of its own, offscreen; `validation` non-zero turns on the
/// Khronos validation layer. Renders 256×256 with `shadow-map` until told otherwise.
#[unsafe(no_mangle)]
pub extern "C" fn softshadow_engine_create_headless(
    validation: u32,
    out_engine: *mut *mut softshadow_engine,
) -> softshadow_status {
    guard(|| {
        non_null_mut(out_engine, "out_engine")?;
        let engine = Engine::headless(&ContextOptions { validation: validation != 0, ..ContextOptions::from_env() })?;
        new_engine(engine, out_engine)
    })
}

/// The window systems a `softshadow_native_window` can name.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum softshadow_window_kind {
    SOFTSHADOW_WINDOW_XLIB = 1,
    SOFTSHADOW_WINDOW_XCB = 2,
    SOFTSHADOW_WINDOW_WAYLAND = 3,
    SOFTSHADOW_WINDOW_WIN32 = 4,
}

/// A window the embedder owns, by its native handles. `kind` is a `softshadow_window_kind`;
/// the other fields, by kind (a field the kind does not use must be 0 / NULL):
/// - XLIB: `display` the `Display *`, `window` the `Window`;
/// - XCB: `display` the `xcb_connection_t *`, `window` the `xcb_window_t`;
/// - WAYLAND: `display` the `struct wl_display *`, `surface` the `struct wl_surface *`;
/// - WIN32: `surface` the `HWND`, `display` its `HINSTANCE` (may be NULL).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct softshadow_native_window {
    pub kind: u32,
    pub display: *mut c_void,
    pub window: u64,
    pub surface: *mut c_void,
}

/// The window `w` describes, its fields checked against its kind.
fn native_window(w: &softshadow_native_window) -> Result<NativeWindow, Failure> {
    use softshadow_window_kind::*;
    let kinds = [SOFTSHADOW_WINDOW_XLIB, SOFTSHADOW_WINDOW_XCB, SOFTSHADOW_WINDOW_WAYLAND, SOFTSHADOW_WINDOW_WIN32];
    let kind = kinds.into_iter().find(|&k| k as u32 == w.kind).ok_or_else(|| {
        invalid(format!("window kind {} is none of XLIB (1), XCB (2), WAYLAND (3), WIN32 (4)", w.kind))
    })?;
    let name = format!("{kind:?}").trim_start_matches("SOFTSHADOW_WINDOW_").to_lowercase();
    let null = |field: &str| Failure(SOFTSHADOW_ERROR_NULL, format!("the {name} window's {field} is NULL (0)"));
    let unused = |field: &str| invalid(format!("the {name} window does not use `{field}`: it must be 0 (NULL)"));
    let display = NonNull::new(w.display);
    let surface = NonNull::new(w.surface);
    Ok(match kind {
        SOFTSHADOW_WINDOW_XLIB | SOFTSHADOW_WINDOW_XCB => {
            if surface.is_some() {
                return Err(unused("surface"));
            }
            let display = display.ok_or_else(|| null("display"))?;
            if w.window == 0 {
                return Err(null("window"));
            }
            if kind == SOFTSHADOW_WINDOW_XLIB {
                let window = c_ulong::try_from(w.window).map_err(|_| invalid("the xlib window is not an XID"))?;
                NativeWindow::Xlib { display, window }
            } else {
                let window = u32::try_from(w.window).ok().and_then(NonZeroU32::new);
                NativeWindow::Xcb {
                    connection: display,
                    window: window.ok_or_else(|| invalid("the xcb window is not a 32-bit xcb_window_t"))?,
                }
            }
        }
        SOFTSHADOW_WINDOW_WAYLAND | SOFTSHADOW_WINDOW_WIN32 => {
            if w.window != 0 {
                return Err(unused("window"));
            }
            let surface = surface.ok_or_else(|| null("surface"))?;
            if kind == SOFTSHADOW_WINDOW_WAYLAND {
                NativeWindow::Wayland { display: display.ok_or_else(|| null("display"))?, surface }
            } else {
                let as_isize = |p: NonNull<c_void>| NonZeroIsize::new(p.as_ptr() as isize).expect("non-NULL");
                NativeWindow::Win32 { hinstance: display.map(as_isize), hwnd: as_isize(surface) }
            }
        }
    })
}

/// Creates an engine on a device of its own that presents to the embedder's native window
/// (Xlib, xcb, Wayland or Win32), FIFO, at the window's size; `validation` as for
/// `softshadow_engine_create_headless`. Present frames with `softshadow_present`. A window
/// system whose surface extension the Vulkan loader lacks is refused
/// (`SOFTSHADOW_ERROR_DEVICE`, the extension named).
///
/// # Safety
/// `window` is NULL or points at a description whose handles are valid (an open display or
/// connection, a live window or surface on it); they outlive the engine.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_engine_create_window(
    window: *const softshadow_native_window,
    validation: u32,
    out_engine: *mut *mut softshadow_engine,
) -> softshadow_status {
    guard(|| {
        let window = native_window(non_null(window, "window")?)?;
        non_null_mut(out_engine, "out_engine")?;
        let options = ContextOptions { validation: validation != 0, ..ContextOptions::from_env() };
        // SAFETY: the caller's contract, passed on.
        let engine = unsafe { Engine::from_native(&options, window, WindowOptions::default()) }?;
        new_engine(engine, out_engine)
    })
}

/// Creates an engine on the embedder's Vulkan objects; it never destroys them. A device
/// without a required extension or feature is refused (`SOFTSHADOW_ERROR_INVALID`, the
/// message naming it).
///
/// # Safety
/// The handles must be valid, belong together and outlive the engine.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_engine_create_from_vulkan(
    vulkan: *const softshadow_vulkan,
    out_engine: *mut *mut softshadow_engine,
) -> softshadow_status {
    guard(|| {
        let v = non_null(vulkan, "vulkan")?;
        non_null_mut(out_engine, "out_engine")?;
        for (p, what) in [
            (v.get_instance_proc_addr, "get_instance_proc_addr"),
            (v.instance, "instance"),
            (v.physical_device, "physical_device"),
            (v.device, "device"),
        ] {
            non_null(p, what)?;
        }
        // Checked before any handle is used.
        let allocation_callbacks = allocation_callbacks(v.allocation_callbacks)?;
        // SAFETY: a non-NULL vkGetInstanceProcAddr, by the caller's contract.
        let get_proc: vk::PFN_vkGetInstanceProcAddr = unsafe { std::mem::transmute(v.get_instance_proc_addr) };
        let entry = unsafe { ash::Entry::from_static_fn(ash::StaticFn { get_instance_proc_addr: get_proc }) };
        use vk::Handle;
        let instance = unsafe { ash::Instance::load(entry.static_fn(), vk::Instance::from_raw(v.instance as u64)) };
        let device = unsafe { ash::Device::load(instance.fp_v1_0(), vk::Device::from_raw(v.device as u64)) };
        let handles = EmbedderHandles {
            entry,
            instance,
            physical_device: vk::PhysicalDevice::from_raw(v.physical_device as u64),
            device,
            queue_family: v.queue_family,
            queue_index: v.queue_index,
            enabled_features: crate::gpu::required_vulkan13_features(),
            enabled_core_features: crate::gpu::required_core_features(),
            allocation_callbacks,
        };
        // SAFETY: the caller's contract, passed on.
        let engine = unsafe { Engine::from_handles(handles) }?;
        new_engine(engine, out_engine)
    })
}

/// Destroys an engine and everything it made (waits for its queue first).
///
/// # Safety
/// `engine` came from a `softshadow_engine_create_*` and is not used afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_engine_destroy(engine: *mut softshadow_engine) -> softshadow_status {
    guard(|| {
        non_null_mut(engine, "engine")?;
        // SAFETY: made by Box::into_raw in `new_engine`, by the caller's contract.
        drop(unsafe { Box::from_raw(engine) });
        Ok(())
    })
}

/// Sets the frame size (each side 1..=the device's limit).
///
/// # Safety
/// `engine` is a live engine.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_engine_set_size(
    engine: *mut softshadow_engine,
    width: u32,
    height: u32,
) -> softshadow_status {
    guard(|| {
        let e = non_null_mut(engine, "engine")?;
        let max = e.engine.device().max_image_dimension_2d;
        if !(1..=max).contains(&width) || !(1..=max).contains(&height) {
            return Err(invalid(format!("frame size {width}x{height}: each side must lie in 1..={max}")));
        }
        (e.settings.width, e.settings.height) = (width, height);
        Ok(())
    })
}

/// Chooses the technique by name (`softshadow techniques` lists them), its knobs at their
/// defaults.
///
/// # Safety
/// `engine` is a live engine; `name` is readable up to its NUL or `max_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_engine_set_technique(
    engine: *mut softshadow_engine,
    name: *const c_char,
    max_len: usize,
) -> softshadow_status {
    guard(|| {
        let e = non_null_mut(engine, "engine")?;
        let name = string(name, max_len, "technique name")?;
        e.settings.params = Params::defaults(find(name)?);
        Ok(())
    })
}

/// Sets a knob of the chosen technique; an unknown knob or a value out of its range is refused.
///
/// # Safety
/// `engine` is a live engine; `key` is readable up to its NUL or `max_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_engine_set_knob(
    engine: *mut softshadow_engine,
    key: *const c_char,
    max_len: usize,
    value: f64,
) -> softshadow_status {
    guard(|| {
        let e = non_null_mut(engine, "engine")?;
        let key = string(key, max_len, "knob name")?;
        if !value.is_finite() {
            return Err(invalid(format!("knob {key} = {value}: not finite")));
        }
        e.settings.params.set(key, &value.to_string())?;
        Ok(())
    })
}

/// Keeps the newest finished frame's timings.
fn keep_timings(e: &mut softshadow_engine) {
    if let Some(t) = e.engine.take_timings().pop() {
        e.last_timings = Some(t);
    }
}

/// Renders one frame of `scene` into the engine's own targets (submits it; its pass times
/// arrive a frame or two later).
///
/// # Safety
/// `engine` and `scene` are live handles.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_render(
    engine: *mut softshadow_engine,
    scene: *const softshadow_scene,
) -> softshadow_status {
    frame_of(engine, scene, |e, scene| Ok(e.engine.render(scene, &e.settings)?))
}

/// Renders a frame of `scene` with `draw` on a live engine, then keeps its timings.
fn frame_of(
    engine: *mut softshadow_engine,
    scene: *const softshadow_scene,
    draw: impl FnOnce(&mut softshadow_engine, &Scene) -> Result<(), Failure>,
) -> softshadow_status {
    guard(|| {
        let e = non_null_mut(engine, "engine")?;
        let s = non_null(scene, "scene")?;
        draw(e, &s.scene)?;
        keep_timings(e);
        Ok(())
    })
}

/// Renders one frame of `scene` at the window's size and presents it (an engine made by
/// `softshadow_engine_create_window`); `*out_shown` (if not NULL) becomes 1, or 0 when the window
/// has no area and the frame was skipped. Its pass times arrive a frame or two later.
///
/// # Safety
/// `engine` and `scene` are live handles; `out_shown` is NULL or writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_present(
    engine: *mut softshadow_engine,
    scene: *const softshadow_scene,
    out_shown: *mut u32,
) -> softshadow_status {
    frame_of(engine, scene, |e, scene| {
        let shown = e.engine.present(scene, &e.settings.params)? == Presented::Shown;
        if !out_shown.is_null() {
            // SAFETY: writable, by the caller's contract.
            unsafe { *out_shown = shown as u32 };
        }
        Ok(())
    })
}

/// The size of the swapchain the last presented frame went to (an engine made by
/// `softshadow_engine_create_window`), into `*out_width` and `*out_height`; 0×0 before any.
///
/// # Safety
/// `engine` is a live handle; the outputs are writable.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_window_size(
    engine: *const softshadow_engine,
    out_width: *mut u32,
    out_height: *mut u32,
) -> softshadow_status {
    guard(|| {
        let e = non_null(engine, "engine")?;
        let stats = e.engine.window_stats().ok_or_else(|| {
            Failure(
                SOFTSHADOW_ERROR_INVALID,
                "the engine has no window (made by softshadow_engine_create_window)".into(),
            )
        })?;
        out(out_width, stats.width, "out_width")?;
        out(out_height, stats.height, "out_height")
    })
}

/// Renders one frame and copies it out (waits for the GPU): sRGB RGBA8 color into `color`
/// (`color_len` ≥ width·height·4 bytes) and V as round(V·65535) into `visibility`
/// (`visibility_len` ≥ width·height values); either may be NULL to skip it. Rows top first.
///
/// # Safety
/// `engine` and `scene` are live handles; the buffers are writable for the lengths given.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_capture(
    engine: *mut softshadow_engine,
    scene: *const softshadow_scene,
    color: *mut u8,
    color_len: usize,
    visibility: *mut u16,
    visibility_len: usize,
) -> softshadow_status {
    guard(|| {
        let e = non_null_mut(engine, "engine")?;
        let s = non_null(scene, "scene")?;
        let pixels = e.settings.width as usize * e.settings.height as usize;
        let too_small = |what: &str, len: usize, need: usize| {
            Failure(SOFTSHADOW_ERROR_BUFFER_TOO_SMALL, format!("{what} holds {len}, the frame needs {need}"))
        };
        if !color.is_null() && color_len < pixels * 4 {
            return Err(too_small("color buffer", color_len, pixels * 4));
        }
        if !visibility.is_null() && visibility_len < pixels {
            return Err(too_small("visibility buffer", visibility_len, pixels));
        }
        let capture = e.engine.render_and_capture(&s.scene, &e.settings)?;
        // SAFETY: checked above to hold the frame; the caller's contract for the rest.
        unsafe {
            if !color.is_null() {
                std::ptr::copy_nonoverlapping(capture.color.as_ptr(), color, pixels * 4);
            }
            if !visibility.is_null() {
                std::ptr::copy_nonoverlapping(capture.visibility.as_ptr(), visibility, pixels);
            }
        }
        keep_timings(e);
        Ok(())
    })
}

fn image_state(a: Access) -> softshadow_image_state {
    softshadow_image_state { layout: a.layout.as_raw(), stage: a.stage.as_raw(), access: a.access.as_raw() }
}

fn access(s: softshadow_image_state) -> Access {
    Access {
        layout: vk::ImageLayout::from_raw(s.layout),
        stage: vk::PipelineStageFlags2::from_raw(s.stage),
        access: vk::AccessFlags2::from_raw(s.access),
    }
}

fn embedder_image(i: &softshadow_image) -> Option<EmbedderImage> {
    use vk::Handle;
    (i.image != 0).then(|| EmbedderImage {
        image: vk::Image::from_raw(i.image),
        format: vk::Format::from_raw(i.format),
        extent: vk::Extent2D { width: i.width, height: i.height },
        last: access(i.state),
    })
}

/// Records the chosen technique for `scene` into the embedder's command buffer (no submission,
/// no wait; see `Engine::record` for the contract: at most two frames unfinished), writing
/// into `recorded` the state each image is left in and V's image and view.
///
/// # Safety
/// `engine` (made by `softshadow_engine_create_from_vulkan`) and `scene` are live handles;
/// the command buffer is recording, outside a render pass, and the images are valid.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_record(
    engine: *mut softshadow_engine,
    scene: *const softshadow_scene,
    frame: *const softshadow_embedded_frame,
    recorded: *mut softshadow_recorded,
) -> softshadow_status {
    guard(|| {
        use vk::Handle;
        let e = non_null_mut(engine, "engine")?;
        let s = non_null(scene, "scene")?;
        let f = non_null(frame, "frame")?;
        non_null_mut(recorded, "recorded")?;
        let depth =
            embedder_image(&f.depth).ok_or_else(|| Failure(SOFTSHADOW_ERROR_NULL, "the depth image is 0".into()))?;
        let frame = EmbeddedFrame {
            cmd: vk::CommandBuffer::from_raw(f.command_buffer as u64),
            camera: EmbedderCamera {
                view: Mat4::from_cols_array(&f.view),
                projection: Mat4::from_cols_array(&f.projection),
                reverse_z: f.reverse_z != 0,
                near: f.near,
                far: f.far,
            },
            depth,
            normal: embedder_image(&f.normal),
            visibility: embedder_image(&f.visibility),
        };
        let r = e.engine.record(&s.scene, &e.settings.params, &frame)?;
        keep_timings(e);
        let result = softshadow_recorded {
            depth: image_state(r.depth),
            normal: r.normal.map(image_state).unwrap_or_default(),
            visibility: image_state(r.visibility),
            visibility_image: r.visibility_image.as_raw(),
            visibility_view: r.visibility_view.as_raw(),
        };
        out(recorded, result, "recorded")
    })
}

/// Forgets the frame `softshadow_record` recorded last, which the embedder will never submit
/// (it resets or frees the command buffer instead): the next `softshadow_record` uploads again
/// what that frame uploaded. Only right after that `softshadow_record`, before any other frame
/// (`SOFTSHADOW_ERROR_INVALID` otherwise).
///
/// # Safety
/// `engine` is a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_discard_recorded(engine: *mut softshadow_engine) -> softshadow_status {
    guard(|| {
        let e = non_null_mut(engine, "engine")?;
        e.engine.discard_recorded()?;
        Ok(())
    })
}

/// Copies the pass times of the newest finished frame into `passes` (room for `capacity`) and
/// their number into `count`; `count` is 0 before any frame has finished.
///
/// # Safety
/// `engine` is live; `passes` is writable for `capacity` entries (or NULL with capacity 0).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_last_timings(
    engine: *mut softshadow_engine,
    passes: *mut softshadow_pass_time,
    capacity: usize,
    count: *mut usize,
) -> softshadow_status {
    guard(|| {
        let e = non_null_mut(engine, "engine")?;
        non_null_mut(count, "count")?;
        keep_timings(e);
        let times = e.last_timings.as_ref().map_or(&[][..], |t| &t.passes[..]);
        if times.len() > capacity {
            out(count, times.len(), "count")?;
            let need = times.len();
            return Err(Failure(
                SOFTSHADOW_ERROR_BUFFER_TOO_SMALL,
                format!("room for {capacity} passes, the frame has {need}"),
            ));
        }
        if !times.is_empty() {
            non_null_mut(passes, "passes")?;
        }
        for (i, t) in times.iter().enumerate() {
            let mut name = [0 as c_char; 32];
            t.name.bytes().take(31).enumerate().for_each(|(k, b)| name[k] = b as c_char);
            // SAFETY: i < times.len() <= capacity, the caller's room.
            unsafe { *passes.add(i) = softshadow_pass_time { name, gpu_ms: t.ms } };
        }
        out(count, times.len(), "count")
    })
}

fn camera(c: &softshadow_camera) -> Result<Camera, Failure> {
    let projection = match (c.fov_y_deg, c.ortho_half_height) {
        (fov, _) if fov > 0.0 && fov < 180.0 => Projection::Perspective { fov_y_deg: fov },
        (fov, h) if fov == 0.0 && h > 0.0 && h.is_finite() => Projection::Orthographic { half_height: h },
        (fov, h) => {
            return Err(invalid(format!(
                "camera: fov_y_deg {fov} must lie in (0, 180), or be 0 with ortho_half_height {h} > 0"
            )));
        }
    };
    Ok(Camera {
        position: finite3(c.position, "camera position")?,
        target: finite3(c.target, "camera target")?,
        up: finite3(c.up, "camera up")?,
        projection,
    })
}

fn light(l: &softshadow_light) -> Result<Light, Failure> {
    if !(l.radius.is_finite() && l.radius >= 0.0) {
        return Err(invalid(format!("light radius {} must be finite and >= 0", l.radius)));
    }
    Ok(Light { position: finite3(l.position, "light position")?, radius: l.radius, target: None })
}

fn transform(t: &softshadow_transform) -> Result<Transform, Failure> {
    Ok(Transform {
        position: finite3(t.position, "position")?,
        rotation_deg: finite3(t.rotation_deg, "rotation_deg")?,
        scale: finite3(t.scale, "scale")?,
    })
}

fn object(i: usize, o: &softshadow_object) -> Result<Object, Failure> {
    let name = format!("object {i}");
    if o.positions.is_null() || o.indices.is_null() {
        return Err(Failure(SOFTSHADOW_ERROR_NULL, format!("{name}: positions or indices is NULL")));
    }
    if o.index_count == 0 || !o.index_count.is_multiple_of(3) {
        return Err(invalid(format!("{name}: {} indices is not a positive multiple of 3", o.index_count)));
    }
    // SAFETY: the caller's contract: the arrays hold the counts given.
    let (positions, indices) = unsafe {
        (
            std::slice::from_raw_parts(o.positions, o.vertex_count * 3),
            std::slice::from_raw_parts(o.indices, o.index_count),
        )
    };
    let positions: Vec<Vec3> = positions.chunks_exact(3).map(Vec3::from_slice).collect();
    let triangles = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let mesh = Mesh::new(name.clone(), positions, triangles)?;
    let mut object = Object::new(name, Arc::new(mesh));
    object.transform = transform(&o.transform)?;
    object.color = finite3(o.color, "color")?;
    (object.casts, object.receives) = (o.casts != 0, o.receives != 0);
    Ok(object)
}

/// Loads a scene file (TOML, DESIGN.md §3).
///
/// # Safety
/// `path` is readable up to its NUL or `max_len` bytes.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_scene_load(
    path: *const c_char,
    max_len: usize,
    out_scene: *mut *mut softshadow_scene,
) -> softshadow_status {
    guard(|| {
        let path = string(path, max_len, "path")?;
        non_null_mut(out_scene, "out_scene")?;
        let scene = Scene::load(path)?;
        out(out_scene, Box::into_raw(Box::new(softshadow_scene { scene })), "out_scene")
    })
}

/// Builds a scene from C structs; the arrays are copied.
///
/// # Safety
/// `desc` and the arrays it points at hold what their counts say.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_scene_create(
    desc: *const softshadow_scene_desc,
    out_scene: *mut *mut softshadow_scene,
) -> softshadow_status {
    guard(|| {
        let d = non_null(desc, "desc")?;
        non_null_mut(out_scene, "out_scene")?;
        let objects = match d.object_count {
            0 => &[][..],
            n => {
                non_null(d.objects, "desc.objects")?;
                // SAFETY: the caller's contract: `object_count` objects.
                unsafe { std::slice::from_raw_parts(d.objects, n) }
            }
        };
        let ground = (d.has_ground != 0).then_some(Ground { height: d.ground_height, half_size: d.ground_half_size });
        let scene = Scene {
            camera: camera(&d.camera)?,
            light: light(&d.light)?,
            ground,
            objects: objects.iter().enumerate().map(|(i, o)| object(i, o)).collect::<Result<_, _>>()?,
            render: RenderSettings::default(),
        };
        scene.validate()?;
        out(out_scene, Box::into_raw(Box::new(softshadow_scene { scene })), "out_scene")
    })
}

/// Destroys a scene.
///
/// # Safety
/// `scene` came from `softshadow_scene_load` or `softshadow_scene_create` and is not used
/// afterwards.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_scene_destroy(scene: *mut softshadow_scene) -> softshadow_status {
    guard(|| {
        non_null_mut(scene, "scene")?;
        // SAFETY: made by Box::into_raw, by the caller's contract.
        drop(unsafe { Box::from_raw(scene) });
        Ok(())
    })
}

/// The number of objects in `scene`, into `count`.
///
/// # Safety
/// `scene` is live.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_scene_object_count(
    scene: *const softshadow_scene,
    count: *mut usize,
) -> softshadow_status {
    guard(|| {
        let s = non_null(scene, "scene")?;
        out(count, s.scene.objects.len(), "count")
    })
}

/// Moves object `index` (in file or description order).
///
/// # Safety
/// `scene` is live; `t` points at a transform.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_scene_set_transform(
    scene: *mut softshadow_scene,
    index: usize,
    t: *const softshadow_transform,
) -> softshadow_status {
    guard(|| {
        let s = non_null_mut(scene, "scene")?;
        let t = transform(non_null(t, "transform")?)?;
        let count = s.scene.objects.len();
        let o =
            s.scene.objects.get_mut(index).ok_or_else(|| invalid(format!("object {index}: the scene has {count}")))?;
        o.transform = t;
        Ok(())
    })
}

/// Sets the light.
///
/// # Safety
/// `scene` is live; `l` points at a light.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_scene_set_light(
    scene: *mut softshadow_scene,
    l: *const softshadow_light,
) -> softshadow_status {
    guard(|| {
        let s = non_null_mut(scene, "scene")?;
        s.scene.light = light(non_null(l, "light")?)?;
        Ok(())
    })
}

/// Sets the camera.
///
/// # Safety
/// `scene` is live; `c` points at a camera.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn softshadow_scene_set_camera(
    scene: *mut softshadow_scene,
    c: *const softshadow_camera,
) -> softshadow_status {
    guard(|| {
        let s = non_null_mut(scene, "scene")?;
        s.scene.camera = camera(non_null(c, "camera")?)?;
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::CStr;

    /// A panic inside an export becomes a status and a message, never an unwind into C.
    #[test]
    fn a_panic_becomes_an_error_code_and_a_message() {
        let status = guard(|| panic!("on purpose"));
        assert_eq!(status, SOFTSHADOW_ERROR_PANIC);
        let mut buf = [0 as c_char; 64];
        let len = unsafe { softshadow_last_error(buf.as_mut_ptr(), buf.len()) };
        let message = unsafe { CStr::from_ptr(buf.as_ptr()) }.to_str().unwrap();
        assert_eq!(message, "softshadow panicked: on purpose");
        assert_eq!(len, message.len());
        // Truncated to the room given, still terminated.
        let mut small = [1 as c_char; 5];
        assert_eq!(unsafe { softshadow_last_error(small.as_mut_ptr(), small.len()) }, len);
        assert_eq!(unsafe { CStr::from_ptr(small.as_ptr()) }.to_str().unwrap(), "soft");
    }
}
