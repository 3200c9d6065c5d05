//! Instance, device, queue and allocator: Vulkan 1.3 with dynamic rendering and
//! synchronization2, push descriptors for every pass, validation on request; on a device of our
//! own, or on the embedder's.

use std::cell::Cell;
use std::ffi::{CStr, c_char};
use std::sync::Mutex;
use std::sync::atomic::{AtomicU64, AtomicUsize, Ordering};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::debug::{VALIDATION_LAYER, ValidationLog, messenger_info};
use super::device::{
    DeviceFilter, Surface, check_embedder_device, driver_of, name_of, pick_device, required_core_features,
    required_device_extensions, required_vulkan13_features,
};
use crate::error::{Error, Result, VkContext};

pub(super) const INSTALL_HINT: &str = "install a Vulkan driver, e.g. `apt-get install libvulkan1 mesa-vulkan-drivers`";

/// How to create the [`Context`].
#[derive(Clone, Debug, Default)]
pub struct ContextOptions {
    /// Khronos validation with synchronization validation; errors are recorded.
    pub validation: bool,
    /// Use the first device whose name contains this text (case-insensitive).
    pub device: Option<String>,
}

impl ContextOptions {
    /// `SOFTSHADOW_VALIDATION=1` turns validation on; `SOFTSHADOW_DEVICE=<name part>` picks a device.
    pub fn from_env() -> Self {
        ContextOptions {
            validation: std::env::var("SOFTSHADOW_VALIDATION").is_ok_and(|v| v == "1"),
            device: std::env::var("SOFTSHADOW_DEVICE").ok().filter(|d| !d.is_empty()),
        }
    }
}

/// What `softshadow info` prints and every timing figure records.
#[derive(Clone, Debug, serde::Serialize)]
pub struct DeviceInfo {
    pub name: String,
    pub driver: String,
    pub device_type: String,
    pub vulkan_version: String,
    pub max_image_dimension_2d: u32,
    pub max_push_constants_size: u32,
    pub max_storage_buffer_range: u32,
    /// The rasterizer's subpixel precision: vertices snap to 1/2^bits of a pixel.
    pub sub_pixel_precision_bits: u32,
    pub timestamp_period_ns: f32,
    pub timestamp_valid_bits: u32,
}

/// Whether the context created the instance and device, and so destroys them.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ownership {
    /// Made by [`Context::new`] (or [`Context::headless`]): `destroy` destroys the device, the
    /// debug messenger and the instance.
    Owned,
    /// The embedder's ([`Context::from_handles`]): never destroyed here.
    Borrowed,
}

/// The handles of a device an embedder created, for [`Context::from_handles`].
pub struct EmbedderHandles {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    pub physical_device: vk::PhysicalDevice,
    /// Created with [`required_device_extensions`](super::required_device_extensions) and
    /// [`required_vulkan13_features`](super::required_vulkan13_features).
    pub device: ash::Device,
    pub queue_family: u32,
    /// A queue of `queue_family` that the device was created with.
    pub queue_index: u32,
    /// The Vulkan 1.3 features passed to `vkCreateDevice` (Vulkan cannot be asked afterwards).
    pub enabled_features: vk::PhysicalDeviceVulkan13Features<'static>,
    /// The Vulkan 1.0 features passed to `vkCreateDevice`, at least
    /// [`required_core_features`](super::required_core_features).
    pub enabled_core_features: vk::PhysicalDeviceFeatures,
    /// The embedder's host allocator, passed to every `vkCreate*` and `vkDestroy*` of the engine's
    /// own objects and to gpu-allocator's `vkAllocateMemory` and `vkFreeMemory` (its functions
    /// and user data must outlive the engine).
    pub allocation_callbacks: Option<vk::AllocationCallbacks<'static>>,
}

/// The Vulkan plumbing every pass uses, on a device of its own or the embedder's; destroyed last.
pub struct Context {
    _entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// The window's surface, made by the device filter; destroyed before the instance.
    pub(super) surface: Option<Surface>,
    pub(crate) debug_utils: Option<ash::ext::debug_utils::Device>,
    pub(crate) physical: vk::PhysicalDevice,
    pub(crate) device: ash::Device,
    pub(crate) push_descriptor: ash::khr::push_descriptor::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) queue_family: u32,
    ownership: Ownership,
    /// The embedder's host allocator, if it gave one.
    host_allocator: Option<vk::AllocationCallbacks<'static>>,
    /// What gpu-allocator's device memory calls substitute while this context calls into it:
    /// set only with a host allocator.
    host_memory: Option<HostMemory>,
    // `None` only after `destroy`.
    allocator: Option<Mutex<Allocator>>,
    live_allocations: AtomicUsize,
    /// Clamp-to-edge nearest sampler, immutable in every layout that samples a target.
    pub(crate) nearest_sampler: vk::Sampler,
    pub(crate) limits: vk::PhysicalDeviceLimits,
    depth_stencil_format: vk::Format,
    pub info: DeviceInfo,
    // Boxed: the messenger holds a pointer to it. Dropped after the instance.
    log: Box<ValidationLog>,
    destroyed: bool,
    retired: Mutex<Retired>,
    /// `vkQueueWaitIdle` calls so far ([`Context::queue_waits`]).
    queue_waits: AtomicU64,
    /// What the surface was made from, kept alive until the surface is destroyed.
    pub(super) window: Option<std::sync::Arc<dyn std::any::Any + Send + Sync>>,
}

/// Objects replaced while frames that used them may still run on the GPU, each with the number
/// of frames recorded when it was replaced: destroyed once those frames cannot be in flight, so
/// that replacing one never waits for the queue (an embedder's frame must not, DESIGN.md §3).
#[derive(Default)]
struct Retired {
    /// Frames recorded so far: submitted, or recorded into the embedder's command buffer.
    recorded: u64,
    items: Vec<(u64, Destroyer)>,
    /// Whether the frame begun last has not been recorded yet.
    open: bool,
    /// Frames lost so far: begun but never recorded (an error), or discarded by the embedder.
    lost: u64,
}

/// When data was uploaded by copies recorded into a frame ([`Context::upload_mark`]): the
/// frames lost before it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct UploadMark(u64);

/// Destroys one retired object.
type Destroyer = Box<dyn FnOnce(&Context)>;

/// What a constructor hands to `assemble`: the handles, and what was learned checking the device.
struct Parts {
    entry: ash::Entry,
    instance: ash::Instance,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    surface: Option<Surface>,
    debug_utils: bool,
    physical: vk::PhysicalDevice,
    device: ash::Device,
    queue_family: u32,
    queue_index: u32,
    depth_stencil_format: vk::Format,
    ownership: Ownership,
    host_allocator: Option<vk::AllocationCallbacks<'static>>,
    log: Box<ValidationLog>,
}

impl Context {
    /// A context without a window: tests, offscreen rendering, benchmarks.
    pub fn headless(options: &ContextOptions) -> Result<Self> {
        Context::new(options, &DeviceFilter::HEADLESS)
    }

    /// Creates an instance and a device of its own. The one construction path: a windowed
    /// context differs from [`Context::headless`] only in its `filter` (surface extensions, and
    /// a queue family that can present).
    pub fn new(options: &ContextOptions, filter: &DeviceFilter) -> Result<Self> {
        // SAFETY: loading the system Vulkan loader; it is kept alive in `_entry`.
        let entry = unsafe { ash::Entry::load() }
            .map_err(|e| Error::NoDevice(format!("no Vulkan loader ({e}): {INSTALL_HINT}")))?;
        let log = Box::<ValidationLog>::default();

        let available_ext = unsafe { entry.enumerate_instance_extension_properties(None) }
            .vk("vkEnumerateInstanceExtensionProperties")?;
        let has_ext = |name: &CStr| available_ext.iter().any(|e| e.extension_name_as_c_str() == Ok(name));
        if let Some(missing) = filter.instance_extensions.iter().find(|name| !has_ext(name)) {
            return Err(Error::NoDevice(format!("the Vulkan instance lacks {}", missing.to_string_lossy())));
        }
        let debug_utils = has_ext(ash::ext::debug_utils::NAME);
        let mut extensions: Vec<*const c_char> = filter.instance_extensions.iter().map(|e| e.as_ptr()).collect();
        if debug_utils {
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        let mut layers: Vec<*const c_char> = Vec::new();
        if options.validation {
            let present = unsafe { entry.enumerate_instance_layer_properties() }
                .vk("vkEnumerateInstanceLayerProperties")?
                .iter()
                .any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER));
            if !present || !debug_utils {
                return Err(Error::NoDevice(
                    "validation was requested but VK_LAYER_KHRONOS_validation is missing: \
                     `apt-get install vulkan-validationlayers`"
                        .into(),
                ));
            }
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(ash::ext::validation_features::NAME.as_ptr());
        }

        let app = vk::ApplicationInfo::default()
            .application_name(c"softshadow")
            .engine_name(c"softshadow")
            .api_version(vk::API_VERSION_1_3);
        let enabled = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&enabled);
        let mut messenger_ci = messenger_info(&log);
        let mut instance_ci = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if options.validation {
            instance_ci = instance_ci.push_next(&mut features).push_next(&mut messenger_ci);
        }
        let instance = unsafe { entry.create_instance(&instance_ci, None) }.map_err(|e| match e {
            vk::Result::ERROR_INCOMPATIBLE_DRIVER => Error::NoDevice(format!("no Vulkan 1.3 driver: {INSTALL_HINT}")),
            result => Error::Vulkan { call: "vkCreateInstance", result },
        })?;
        // Until the context exists, failures must destroy what does: build the rest in a guard.
        let mut guard = InstanceGuard { instance: Some(instance), messenger: None, surface: None };
        let instance = guard.instance.as_ref().expect("just created");
        if options.validation {
            let loader = ash::ext::debug_utils::Instance::new(&entry, instance);
            let messenger = unsafe { loader.create_debug_utils_messenger(&messenger_info(&log), None) }
                .vk("vkCreateDebugUtilsMessengerEXT")?;
            guard.messenger = Some((loader, messenger));
        }

        if let Some(create) = filter.surface {
            guard.surface = Some((ash::khr::surface::Instance::new(&entry, instance), create(&entry, instance)?));
        }
        let picked = pick_device(instance, options.device.as_deref(), filter, guard.surface.as_ref())?;
        let priorities = [1.0];
        let queue_ci = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(picked.queue_family)
            .queue_priorities(&priorities)];
        let device_ext: Vec<_> =
            required_device_extensions().iter().chain(filter.device_extensions).map(|e| e.as_ptr()).collect();
        let mut v13 = required_vulkan13_features();
        let core = required_core_features();
        let device_ci = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_ci)
            .enabled_extension_names(&device_ext)
            .enabled_features(&core)
            .push_next(&mut v13);
        let device = unsafe { instance.create_device(picked.physical, &device_ci, None) }.vk("vkCreateDevice")?;
        Context::assemble(Parts {
            entry,
            instance: guard.instance.take().expect("guarded instance"),
            messenger: guard.messenger.take(),
            surface: guard.surface.take(),
            debug_utils,
            physical: picked.physical,
            device,
            queue_family: picked.queue_family,
            queue_index: 0,
            depth_stencil_format: picked.depth_stencil_format,
            ownership: Ownership::Owned,
            host_allocator: None,
            log,
        })
    }

    /// A context on the embedder's instance and device (as Dear ImGui's Vulkan backend is built):
    /// it creates and destroys only its own objects (allocator, sampler), never the instance or
    /// the device. Its validation log stays empty: messages go to the embedder's messenger, if any.
    ///
    /// # Safety
    /// The handles must be valid, belong together, and outlive the context; the embedder must not
    /// use the queue from another thread while the context submits to it or waits on it.
    pub unsafe fn from_handles(handles: EmbedderHandles) -> Result<Self> {
        let EmbedderHandles {
            entry,
            instance,
            physical_device,
            device,
            queue_family,
            queue_index,
            enabled_features,
            enabled_core_features,
            allocation_callbacks,
        } = handles;
        let depth_stencil_format = check_embedder_device(
            &instance,
            physical_device,
            &device,
            queue_family,
            &enabled_features,
            &enabled_core_features,
        )?;
        // Object names need the embedder's instance to have enabled debug utils.
        let debug_utils = unsafe {
            (instance.fp_v1_0().get_device_proc_addr)(device.handle(), c"vkSetDebugUtilsObjectNameEXT".as_ptr())
        }
        .is_some();
        Context::assemble(Parts {
            entry,
            instance,
            messenger: None,
            surface: None,
            debug_utils,
            physical: physical_device,
            device,
            queue_family,
            queue_index,
            depth_stencil_format,
            ownership: Ownership::Borrowed,
            host_allocator: allocation_callbacks,
            log: Box::default(),
        })
    }

    /// The part both constructors share, once a device exists: the context is built at once, so
    /// that a failure past this point is cleaned up by its `Drop`, which respects `ownership`.
    fn assemble(parts: Parts) -> Result<Self> {
        let Parts { entry, instance, messenger, surface, debug_utils, physical, device, .. } = parts;
        let props = unsafe { instance.get_physical_device_properties(physical) };
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let limits = props.limits;
        let v = props.api_version;
        let info = DeviceInfo {
            name: name_of(&props),
            driver: driver_of(&instance, physical),
            device_type: format!("{:?}", props.device_type),
            vulkan_version: format!(
                "{}.{}.{}",
                vk::api_version_major(v),
                vk::api_version_minor(v),
                vk::api_version_patch(v)
            ),
            max_image_dimension_2d: limits.max_image_dimension2_d,
            max_push_constants_size: limits.max_push_constants_size,
            max_storage_buffer_range: limits.max_storage_buffer_range,
            sub_pixel_precision_bits: limits.sub_pixel_precision_bits,
            timestamp_period_ns: limits.timestamp_period,
            timestamp_valid_bits: families[parts.queue_family as usize].timestamp_valid_bits,
        };
        let mut ctx = Context {
            queue: unsafe { device.get_device_queue(parts.queue_family, parts.queue_index) },
            debug_utils: debug_utils.then(|| ash::ext::debug_utils::Device::new(&instance, &device)),
            push_descriptor: ash::khr::push_descriptor::Device::new(&instance, &device),
            _entry: entry,
            instance,
            messenger,
            surface,
            physical,
            device,
            queue_family: parts.queue_family,
            ownership: parts.ownership,
            host_allocator: parts.host_allocator,
            host_memory: None,
            allocator: None,
            live_allocations: AtomicUsize::new(0),
            nearest_sampler: vk::Sampler::null(),
            limits,
            depth_stencil_format: parts.depth_stencil_format,
            info,
            log: parts.log,
            destroyed: false,
            retired: Mutex::default(),
            queue_waits: AtomicU64::new(0),
            window: None,
        };
        // gpu-allocator passes no host allocator to vkAllocateMemory and vkFreeMemory: with one,
        // it gets a device whose two entries are shims that pass ours.
        ctx.host_memory = ctx.host_allocator.map(|callbacks| HostMemory {
            callbacks,
            allocate: ctx.device.fp_v1_0().allocate_memory,
            free: ctx.device.fp_v1_0().free_memory,
        });
        let allocator_device = match ctx.host_memory {
            Some(_) => {
                let mut v1_0 = ctx.device.fp_v1_0().clone();
                v1_0.allocate_memory = allocate_memory_with_host_allocator;
                v1_0.free_memory = free_memory_with_host_allocator;
                let d = &ctx.device;
                ash::Device::from_parts_1_3(
                    d.handle(),
                    v1_0,
                    d.fp_v1_1().clone(),
                    d.fp_v1_2().clone(),
                    d.fp_v1_3().clone(),
                )
            }
            None => ctx.device.clone(),
        };
        ctx.allocator = Some(Mutex::new(Allocator::new(&AllocatorCreateDesc {
            instance: ctx.instance.clone(),
            device: allocator_device,
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        })?));
        let sampler_ci = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(0.0);
        ctx.nearest_sampler =
            unsafe { ctx.device.create_sampler(&sampler_ci, ctx.host_allocator()) }.vk("vkCreateSampler")?;
        ctx.name(ctx.nearest_sampler, "nearest clamp sampler");
        Ok(ctx)
    }

    /// Whether `destroy` destroys the instance and device.
    pub fn ownership(&self) -> Ownership {
        self.ownership
    }

    /// The instance (the embedder's, or our own).
    pub fn instance(&self) -> &ash::Instance {
        &self.instance
    }

    pub fn physical_device(&self) -> vk::PhysicalDevice {
        self.physical
    }

    /// The device, for objects an embedder makes itself (images to wrap, semaphores).
    pub fn device(&self) -> &ash::Device {
        &self.device
    }

    /// The depth-stencil format of [`TargetDesc::depth_stencil`](super::TargetDesc::depth_stencil)
    /// targets: D32_SFLOAT_S8_UINT, or D24_UNORM_S8_UINT where that is missing.
    pub fn depth_stencil_format(&self) -> vk::Format {
        self.depth_stencil_format
    }

    /// Whether optimally tiled images of `format` can be sampled and blended into as colour
    /// attachments: beyond the formats Vulkan requires, a device may lack them.
    pub fn renders_blended(&self, format: vk::Format) -> bool {
        let needed = vk::FormatFeatureFlags::SAMPLED_IMAGE | vk::FormatFeatureFlags::COLOR_ATTACHMENT_BLEND;
        unsafe { self.instance.get_physical_device_format_properties(self.physical, format) }
            .optimal_tiling_features
            .contains(needed)
    }

    /// Validation errors recorded so far: empty when validation is off, and always for a context
    /// [`from_handles`](Context::from_handles), whose messages go to the embedder's messenger.
    pub fn validation_errors(&self) -> Vec<String> {
        self.log.errors()
    }

    /// The host allocator to pass to `vkCreate*` and `vkDestroy*`: the embedder's, or none.
    pub(crate) fn host_allocator(&self) -> Option<&vk::AllocationCallbacks<'static>> {
        self.host_allocator.as_ref()
    }

    /// GPU allocations alive now: a render loop must not make this grow.
    pub fn live_allocations(&self) -> usize {
        self.live_allocations.load(Ordering::Relaxed)
    }

    /// Runs `f`, a call into gpu-allocator, with this context's host allocator in force for
    /// the device memory it allocates or frees.
    fn with_allocator<R>(&self, f: impl FnOnce(&mut Allocator) -> R) -> R {
        let mut allocator =
            self.allocator.as_ref().expect("allocator used after destroy").lock().expect("allocator lock");
        let _scope = HostMemoryScope::enter(self.host_memory);
        f(&mut allocator)
    }

    pub(crate) fn allocate(
        &self,
        desc: &gpu_allocator::vulkan::AllocationCreateDesc<'_>,
    ) -> Result<gpu_allocator::vulkan::Allocation> {
        let allocation = self.with_allocator(|a| a.allocate(desc))?;
        self.live_allocations.fetch_add(1, Ordering::Relaxed);
        Ok(allocation)
    }

    pub(crate) fn free(&self, allocation: gpu_allocator::vulkan::Allocation) {
        self.live_allocations.fetch_sub(1, Ordering::Relaxed);
        // Freeing only fails for a foreign allocation, which this crate never makes.
        if let Err(e) = self.with_allocator(|a| a.free(allocation)) {
            eprintln!("softshadow: freeing GPU memory failed: {e}");
        }
    }

    /// Names a Vulkan object for validation messages and captures (no-op without debug utils).
    pub(crate) fn name<H: vk::Handle>(&self, handle: H, name: &str) {
        if let Some(du) = &self.debug_utils {
            let Ok(name) = std::ffi::CString::new(name) else { return };
            let info = vk::DebugUtilsObjectNameInfoEXT::default().object_handle(handle).object_name(&name);
            // Naming is best effort: a failure changes nothing that renders.
            let _ = unsafe { du.set_debug_utils_object_name(&info) };
        }
    }

    /// Waits for our queue to drain (before destroying or re-creating resources it may use).
    /// Only the queue: on an embedder's device, its other queues are none of our business.
    pub fn wait_idle(&self) -> Result<()> {
        if self.destroyed {
            return Ok(()); // nothing can be in flight on a destroyed device
        }
        self.queue_waits.fetch_add(1, Ordering::Relaxed);
        unsafe { self.device.queue_wait_idle(self.queue) }.vk("vkQueueWaitIdle")
    }

    /// How many times [`Context::wait_idle`] has waited: tests check that a path never does.
    pub fn queue_waits(&self) -> u64 {
        self.queue_waits.load(Ordering::Relaxed)
    }

    /// Runs `destroy` (of an object the frames recorded so far may use) once none of those
    /// frames can still be in flight: [`FRAMES_IN_FLIGHT`](super::FRAMES_IN_FLIGHT) frames
    /// later, or when the context is destroyed.
    pub fn retire(&self, destroy: impl FnOnce(&Context) + 'static) {
        let mut retired = self.retired.lock().expect("retire list");
        let recorded = retired.recorded;
        retired.items.push((recorded, Box::new(destroy)));
    }

    /// Frames recorded so far (submitted, or recorded into the embedder's command buffer): a
    /// frame that fails before then does not count.
    pub fn frames_recorded(&self) -> u64 {
        self.retired.lock().expect("retire list").recorded
    }

    /// A frame begins recording; the one begun before it, if never recorded, is lost.
    pub(super) fn frame_begun(&self) {
        let mut r = self.retired.lock().expect("retire list");
        r.lost += u64::from(r.open);
        r.open = true;
    }

    /// A frame has been recorded (submitted, or handed to the embedder to submit).
    pub(super) fn frame_recorded(&self) {
        let mut r = self.retired.lock().expect("retire list");
        r.recorded += 1;
        r.open = false;
    }

    /// The frame recorded last was discarded by the embedder: it never runs, so it does not
    /// count (what was retired meanwhile waits for frames that do), and it is lost.
    pub(super) fn frame_discarded(&self) {
        let mut r = self.retired.lock().expect("retire list");
        r.recorded -= 1;
        r.lost += 1;
    }

    /// The mark of data uploaded (or computed) by copies recorded into the frame being
    /// recorded, for [`Context::upload_kept`].
    pub fn upload_mark(&self) -> UploadMark {
        UploadMark(self.retired.lock().expect("retire list").lost)
    }

    /// Whether data marked `mark` is (or will be, once the frames recorded so far run) on the
    /// GPU: no frame has been lost since it was uploaded, so the frame that uploaded it is the
    /// one being recorded or was recorded (frames are lost only between frames). After a lost
    /// frame every earlier upload counts as lost too: uploading again is cheaper than
    /// remembering which frame was lost.
    pub fn upload_kept(&self, mark: UploadMark) -> bool {
        mark.0 == self.retired.lock().expect("retire list").lost
    }

    /// Destroys what was retired before the frames now known finished: called as frame n
    /// begins, once its slot's previous frame (and so every frame up to n − FRAMES_IN_FLIGHT)
    /// has finished. An object retired while frames up to m were recorded (m included, for one
    /// replaced while recording frame m) goes when n ≥ m + FRAMES_IN_FLIGHT.
    pub(super) fn destroy_finished(&self) {
        let ready: Vec<_> = {
            let mut retired = self.retired.lock().expect("retire list");
            let n = retired.recorded;
            let (ready, kept) = std::mem::take(&mut retired.items)
                .into_iter()
                .partition(|(at, _)| at + super::FRAMES_IN_FLIGHT as u64 <= n);
            retired.items = kept;
            ready
        };
        ready.into_iter().for_each(|(_, destroy)| destroy(self));
    }

    /// Destroys everything retired: only once the queue is idle.
    pub(crate) fn destroy_retired(&self) {
        let items = std::mem::take(&mut self.retired.lock().expect("retire list").items);
        items.into_iter().for_each(|(_, destroy)| destroy(self));
    }

    /// Destroys our objects, then the device and instance if we own them; validation reports
    /// any object still alive into the log, which stays readable afterwards. Runs once; `Drop`
    /// calls it too.
    pub fn destroy(&mut self) {
        if std::mem::replace(&mut self.destroyed, true) {
            return;
        }
        unsafe {
            // Nothing to do on failure: our objects are being torn down regardless.
            let _ = self.device.queue_wait_idle(self.queue);
            self.destroy_retired();
            self.device.destroy_sampler(self.nearest_sampler, self.host_allocator());
            // Dropping the allocator frees its memory blocks.
            if let Some(allocator) = self.allocator.take() {
                let _scope = HostMemoryScope::enter(self.host_memory);
                drop(allocator);
            }
            if self.ownership == Ownership::Owned {
                self.device.destroy_device(None);
                if let Some((loader, surface)) = self.surface.take() {
                    loader.destroy_surface(surface, None);
                }
                if let Some((loader, messenger)) = self.messenger.take() {
                    loader.destroy_debug_utils_messenger(messenger, None);
                }
                self.instance.destroy_instance(None);
            }
        }
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        self.destroy();
    }
}

/// The embedder's host allocator and the device's own `vkAllocateMemory` and `vkFreeMemory`,
/// for the shims gpu-allocator calls instead.
#[derive(Clone, Copy)]
struct HostMemory {
    callbacks: vk::AllocationCallbacks<'static>,
    allocate: vk::PFN_vkAllocateMemory,
    free: vk::PFN_vkFreeMemory,
}

thread_local! {
    /// The [`HostMemory`] of the context whose call into gpu-allocator this thread is making:
    /// gpu-allocator keeps no user data to find it by, and calls Vulkan only from within those
    /// calls, on the calling thread.
    static HOST_MEMORY: Cell<Option<HostMemory>> = const { Cell::new(None) };
}

/// Sets [`HOST_MEMORY`] for its lifetime, restoring the previous value after (a panic too).
struct HostMemoryScope(Option<HostMemory>);

impl HostMemoryScope {
    fn enter(memory: Option<HostMemory>) -> Self {
        HostMemoryScope(HOST_MEMORY.replace(memory))
    }
}

impl Drop for HostMemoryScope {
    fn drop(&mut self) {
        HOST_MEMORY.set(self.0);
    }
}

/// gpu-allocator's `vkAllocateMemory` on a context with a host allocator: the device's own,
/// passed the embedder's callbacks for the NULL gpu-allocator gives.
unsafe extern "system" fn allocate_memory_with_host_allocator(
    device: vk::Device,
    info: *const vk::MemoryAllocateInfo<'_>,
    allocator: *const vk::AllocationCallbacks<'_>,
    memory: *mut vk::DeviceMemory,
) -> vk::Result {
    match HOST_MEMORY.get() {
        // SAFETY: gpu-allocator's arguments, passed on; the callbacks outlive the context.
        Some(h) => unsafe {
            (h.allocate)(device, info, if allocator.is_null() { &h.callbacks } else { allocator }, memory)
        },
        // Unreachable: the allocator this device is given is only called through `with_allocator`.
        None => vk::Result::ERROR_INITIALIZATION_FAILED,
    }
}

/// gpu-allocator's `vkFreeMemory`, as [`allocate_memory_with_host_allocator`].
unsafe extern "system" fn free_memory_with_host_allocator(
    device: vk::Device,
    memory: vk::DeviceMemory,
    allocator: *const vk::AllocationCallbacks<'_>,
) {
    // Without one (unreachable, as above) the memory is leaked rather than freed with callbacks
    // other than those it was allocated with.
    if let Some(h) = HOST_MEMORY.get() {
        // SAFETY: as above.
        unsafe { (h.free)(device, memory, if allocator.is_null() { &h.callbacks } else { allocator }) }
    }
}

/// Destroys a half-built instance (its surface and messenger too) if construction fails.
struct InstanceGuard {
    instance: Option<ash::Instance>,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    surface: Option<Surface>,
}

impl Drop for InstanceGuard {
    fn drop(&mut self) {
        unsafe {
            if let Some((loader, surface)) = self.surface.take() {
                loader.destroy_surface(surface, None);
            }
            if let Some((loader, messenger)) = self.messenger.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            if let Some(instance) = self.instance.take() {
                instance.destroy_instance(None);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The zero-errors assertions of every GPU test rest on this: an invalid call is recorded.
    #[test]
    fn validation_errors_are_recorded() {
        let mut ctx = Context::headless(&ContextOptions { validation: true, device: None }).unwrap();
        assert!(ctx.validation_errors().is_empty());
        // VUID-VkBufferCreateInfo-size-00912: size must be greater than 0.
        let ci = vk::BufferCreateInfo::default().size(0).usage(vk::BufferUsageFlags::UNIFORM_BUFFER);
        if let Ok(buffer) = unsafe { ctx.device.create_buffer(&ci, ctx.host_allocator()) } {
            unsafe { ctx.device.destroy_buffer(buffer, ctx.host_allocator()) };
        }
        ctx.destroy();
        let errors = ctx.validation_errors();
        assert!(errors.iter().any(|e| e.contains("00912")), "{errors:?}");
    }

    #[test]
    fn a_device_name_that_matches_nothing_is_an_error() {
        let options = ContextOptions { validation: false, device: Some("no such gpu 9000".into()) };
        let err = Context::headless(&options).err().expect("no device matches").to_string();
        assert!(err.contains("no such gpu 9000") && err.contains("have:"), "{err}");
    }
}
