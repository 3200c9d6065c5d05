//! Instance, device, queue and allocator: Vulkan 1.3 with dynamic rendering and
//! synchronization2, push descriptors for every pass, validation on request.

use std::ffi::{CStr, c_char};
use std::mem::ManuallyDrop;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::debug::{VALIDATION_LAYER, ValidationLog, messenger_info};
use crate::error::{Error, Result, VkContext};

const INSTALL_HINT: &str = "install a Vulkan driver, e.g. `apt-get install libvulkan1 mesa-vulkan-drivers`";

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
    pub timestamp_period_ns: f32,
    pub timestamp_valid_bits: u32,
}

/// The Vulkan plumbing every pass uses. Owns the device; destroyed last.
pub struct Context {
    _entry: ash::Entry,
    pub(crate) instance: ash::Instance,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    pub(crate) debug_utils: Option<ash::ext::debug_utils::Device>,
    pub(crate) device: ash::Device,
    pub(crate) push_descriptor: ash::khr::push_descriptor::Device,
    pub(crate) queue: vk::Queue,
    pub(crate) queue_family: u32,
    allocator: ManuallyDrop<Mutex<Allocator>>,
    live_allocations: AtomicUsize,
    /// Clamp-to-edge nearest sampler, immutable in every layout that samples a target.
    pub(crate) nearest_sampler: vk::Sampler,
    pub(crate) limits: vk::PhysicalDeviceLimits,
    pub info: DeviceInfo,
    // Boxed: the messenger holds a pointer to it. Dropped after the instance.
    log: Box<ValidationLog>,
    destroyed: bool,
}

impl Context {
    /// A context without a window: tests, offscreen rendering, benchmarks. A windowed
    /// constructor will share everything but the surface check.
    pub fn headless(options: &ContextOptions) -> Result<Self> {
        // SAFETY: loading the system Vulkan loader; it is kept alive in `_entry`.
        let entry = unsafe { ash::Entry::load() }
            .map_err(|e| Error::NoDevice(format!("no Vulkan loader ({e}): {INSTALL_HINT}")))?;
        let log = Box::<ValidationLog>::default();

        let available_ext = unsafe { entry.enumerate_instance_extension_properties(None) }
            .vk("vkEnumerateInstanceExtensionProperties")?;
        let has_ext = |name: &CStr| available_ext.iter().any(|e| e.extension_name_as_c_str() == Ok(name));
        let debug_utils = has_ext(ash::ext::debug_utils::NAME);
        let mut extensions: Vec<*const c_char> = Vec::new();
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
        // From here on, failures must destroy what exists: build the rest in a guard.
        let mut guard = InstanceGuard { instance: Some(instance), messenger: None };
        let instance = guard.instance.as_ref().expect("just created");
        if options.validation {
            let loader = ash::ext::debug_utils::Instance::new(&entry, instance);
            let messenger = unsafe { loader.create_debug_utils_messenger(&messenger_info(&log), None) }
                .vk("vkCreateDebugUtilsMessengerEXT")?;
            guard.messenger = Some((loader, messenger));
        }

        let (physical, props) = pick_device(instance, options.device.as_deref())?;
        let queue_family = unsafe { instance.get_physical_device_queue_family_properties(physical) }
            .iter()
            .position(|q| {
                q.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE) && q.timestamp_valid_bits > 0
            })
            .ok_or_else(|| {
                Error::NoDevice(format!("{}: no graphics and compute queue with timestamps", name_of(&props)))
            })? as u32;
        let timestamp_valid_bits = unsafe { instance.get_physical_device_queue_family_properties(physical) }
            [queue_family as usize]
            .timestamp_valid_bits;

        let priorities = [1.0];
        let queue_ci =
            [vk::DeviceQueueCreateInfo::default().queue_family_index(queue_family).queue_priorities(&priorities)];
        let device_ext = [ash::khr::push_descriptor::NAME.as_ptr()];
        // maintenance4 (required of every Vulkan 1.3 device) lets SPIR-V 1.6 compute shaders
        // declare their workgroup size with LocalSizeId, as shaderc emits it.
        let mut v13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .synchronization2(true)
            .maintenance4(true);
        let device_ci = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_ci)
            .enabled_extension_names(&device_ext)
            .push_next(&mut v13);
        let device = unsafe { instance.create_device(physical, &device_ci, None) }.vk("vkCreateDevice")?;
        let queue = unsafe { device.get_device_queue(queue_family, 0) };

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.clone(),
            device: device.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: false,
            allocation_sizes: Default::default(),
        });
        let allocator = match allocator {
            Ok(a) => a,
            Err(e) => {
                unsafe { device.destroy_device(None) };
                return Err(e.into());
            }
        };
        let sampler_ci = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::NEAREST)
            .min_filter(vk::Filter::NEAREST)
            .mipmap_mode(vk::SamplerMipmapMode::NEAREST)
            .address_mode_u(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_v(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .address_mode_w(vk::SamplerAddressMode::CLAMP_TO_EDGE)
            .max_lod(0.0);
        let nearest_sampler = match unsafe { device.create_sampler(&sampler_ci, None) } {
            Ok(s) => s,
            Err(result) => {
                drop(allocator);
                unsafe { device.destroy_device(None) };
                return Err(Error::Vulkan { call: "vkCreateSampler", result });
            }
        };

        let limits = props.limits;
        let v = props.api_version;
        let info = DeviceInfo {
            name: name_of(&props),
            driver: driver_of(instance, physical),
            device_type: format!("{:?}", props.device_type),
            vulkan_version: format!(
                "{}.{}.{}",
                vk::api_version_major(v),
                vk::api_version_minor(v),
                vk::api_version_patch(v)
            ),
            max_image_dimension_2d: limits.max_image_dimension2_d,
            max_push_constants_size: limits.max_push_constants_size,
            timestamp_period_ns: limits.timestamp_period,
            timestamp_valid_bits,
        };
        let instance = guard.instance.take().expect("guarded instance");
        let messenger = guard.messenger.take();
        let debug_utils = debug_utils.then(|| ash::ext::debug_utils::Device::new(&instance, &device));
        let push_descriptor = ash::khr::push_descriptor::Device::new(&instance, &device);
        let ctx = Context {
            _entry: entry,
            instance,
            messenger,
            debug_utils,
            device,
            push_descriptor,
            queue,
            queue_family,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            live_allocations: AtomicUsize::new(0),
            nearest_sampler,
            limits,
            info,
            log,
            destroyed: false,
        };
        ctx.name(ctx.nearest_sampler, "nearest clamp sampler");
        Ok(ctx)
    }

    /// Validation errors recorded so far (empty when validation is off).
    pub fn validation_errors(&self) -> Vec<String> {
        self.log.errors()
    }

    /// GPU allocations alive now: a render loop must not make this grow.
    pub fn live_allocations(&self) -> usize {
        self.live_allocations.load(Ordering::Relaxed)
    }

    pub(crate) fn allocate(
        &self,
        desc: &gpu_allocator::vulkan::AllocationCreateDesc<'_>,
    ) -> Result<gpu_allocator::vulkan::Allocation> {
        let allocation = self.allocator.lock().expect("allocator lock").allocate(desc)?;
        self.live_allocations.fetch_add(1, Ordering::Relaxed);
        Ok(allocation)
    }

    pub(crate) fn free(&self, allocation: gpu_allocator::vulkan::Allocation) {
        self.live_allocations.fetch_sub(1, Ordering::Relaxed);
        // Freeing only fails for a foreign allocation, which this crate never makes.
        if let Err(e) = self.allocator.lock().expect("allocator lock").free(allocation) {
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

    /// Waits for the queue to drain (before destroying or re-creating resources it may use).
    pub fn wait_idle(&self) -> Result<()> {
        if self.destroyed {
            return Ok(()); // nothing can be in flight on a destroyed device
        }
        unsafe { self.device.device_wait_idle() }.vk("vkDeviceWaitIdle")
    }

    /// Destroys the device and instance; validation reports any object still alive into the log,
    /// which stays readable afterwards. Runs once; `Drop` calls it too.
    pub fn destroy(&mut self) {
        if std::mem::replace(&mut self.destroyed, true) {
            return;
        }
        unsafe {
            // Nothing to do on failure: the device is being torn down regardless.
            let _ = self.device.device_wait_idle();
            self.device.destroy_sampler(self.nearest_sampler, None);
            ManuallyDrop::drop(&mut self.allocator);
            self.device.destroy_device(None);
            if let Some((loader, messenger)) = self.messenger.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.instance.destroy_instance(None);
        }
    }
}

impl Drop for Context {
    fn drop(&mut self) {
        self.destroy();
    }
}

/// Destroys a half-built instance (and its messenger) if construction fails.
struct InstanceGuard {
    instance: Option<ash::Instance>,
    messenger: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
}

impl Drop for InstanceGuard {
    fn drop(&mut self) {
        unsafe {
            if let Some((loader, messenger)) = self.messenger.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            if let Some(instance) = self.instance.take() {
                instance.destroy_instance(None);
            }
        }
    }
}

fn name_of(props: &vk::PhysicalDeviceProperties) -> String {
    props.device_name_as_c_str().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default()
}

fn driver_of(instance: &ash::Instance, physical: vk::PhysicalDevice) -> String {
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    unsafe { instance.get_physical_device_properties2(physical, &mut props2) };
    let name = driver.driver_name_as_c_str().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let info = driver.driver_info_as_c_str().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    format!("{name} {info}").trim().to_string()
}

/// A real GPU when present, lavapipe otherwise; `wanted` (a name substring) overrides.
fn pick_device(
    instance: &ash::Instance,
    wanted: Option<&str>,
) -> Result<(vk::PhysicalDevice, vk::PhysicalDeviceProperties)> {
    let devices = unsafe { instance.enumerate_physical_devices() }.vk("vkEnumeratePhysicalDevices")?;
    let usable: Vec<_> = devices
        .into_iter()
        .map(|d| (d, unsafe { instance.get_physical_device_properties(d) }))
        .filter(|(d, p)| {
            let exts = unsafe { instance.enumerate_device_extension_properties(*d) }.unwrap_or_default();
            p.api_version >= vk::API_VERSION_1_3
                && exts.iter().any(|e| e.extension_name_as_c_str() == Ok(ash::khr::push_descriptor::NAME))
        })
        .collect();
    if usable.is_empty() {
        return Err(Error::NoDevice(format!("no Vulkan 1.3 device with VK_KHR_push_descriptor: {INSTALL_HINT}")));
    }
    if let Some(wanted) = wanted {
        let lower = wanted.to_lowercase();
        return usable.iter().find(|(_, p)| name_of(p).to_lowercase().contains(&lower)).copied().ok_or_else(|| {
            let names: Vec<_> = usable.iter().map(|(_, p)| name_of(p)).collect();
            Error::NoDevice(format!("SOFTSHADOW_DEVICE={wanted} matches no device (have: {})", names.join(", ")))
        });
    }
    let rank = |t: vk::PhysicalDeviceType| match t {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        vk::PhysicalDeviceType::CPU => 3,
        _ => 4,
    };
    Ok(*usable.iter().min_by_key(|(_, p)| rank(p.device_type)).expect("non-empty"))
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
        if let Ok(buffer) = unsafe { ctx.device.create_buffer(&ci, None) } {
            unsafe { ctx.device.destroy_buffer(buffer, None) };
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
