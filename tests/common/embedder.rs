//! An embedder written with raw ash, as a game would be: its own instance (validation and
//! synchronization validation on, its own messenger recording errors), device, command pool,
//! images and uploads. The engine is built on its handles.

use std::ffi::{CStr, c_void};
use std::sync::Mutex;

use ash::vk;
use softshadow::gpu::EmbedderHandles;

/// Validation messages of the embedder's instance.
#[derive(Default)]
pub struct Log(Mutex<Vec<String>>);

unsafe extern "system" fn record(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: the layer passes valid data; `user` is the boxed log, alive until the instance goes.
    let (message, log) = unsafe { ((*data).message_as_c_str().unwrap_or_default(), &*(user as *const Log)) };
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        log.0.lock().unwrap().push(message.to_string_lossy().into_owned());
    }
    vk::FALSE
}

pub struct Embedder {
    pub entry: ash::Entry,
    pub instance: ash::Instance,
    messenger: (ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT),
    pub physical: vk::PhysicalDevice,
    pub queue_family: u32,
    pub device: ash::Device,
    pub queue: vk::Queue,
    pub pool: vk::CommandPool,
    log: Box<Log>,
}

impl Embedder {
    /// An instance and a device created with `extensions` and `features`.
    pub fn new(extensions: &[&CStr], features: vk::PhysicalDeviceVulkan13Features<'static>) -> Self {
        let entry = unsafe { ash::Entry::load() }.expect("a Vulkan loader");
        let log = Box::<Log>::default();
        let messenger_ci = || {
            vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR)
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION | vk::DebugUtilsMessageTypeFlagsEXT::GENERAL,
                )
                .pfn_user_callback(Some(record))
                .user_data(&*log as *const Log as *mut c_void)
        };
        let app = vk::ApplicationInfo::default().api_version(vk::API_VERSION_1_3);
        let layers = [c"VK_LAYER_KHRONOS_validation".as_ptr()];
        let instance_ext = [ash::ext::debug_utils::NAME.as_ptr(), ash::ext::validation_features::NAME.as_ptr()];
        let sync = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut validation = vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync);
        let mut instance_messenger = messenger_ci();
        let instance_ci = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&instance_ext)
            .push_next(&mut validation)
            .push_next(&mut instance_messenger);
        let instance = unsafe { entry.create_instance(&instance_ci, None) }.expect("an instance with validation");
        let loader = ash::ext::debug_utils::Instance::new(&entry, &instance);
        let messenger = unsafe { loader.create_debug_utils_messenger(&messenger_ci(), None) }.unwrap();
        let (physical, queue_family) = unsafe { instance.enumerate_physical_devices() }
            .unwrap()
            .into_iter()
            .filter(|&p| unsafe { instance.get_physical_device_properties(p) }.api_version >= vk::API_VERSION_1_3)
            .find_map(|p| {
                let families = unsafe { instance.get_physical_device_queue_family_properties(p) };
                let family = families.iter().position(|f| {
                    f.queue_flags.contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
                        && f.timestamp_valid_bits > 0
                })?;
                Some((p, family as u32))
            })
            .expect("a Vulkan 1.3 device");
        let priorities = [1.0];
        let queue_ci =
            [vk::DeviceQueueCreateInfo::default().queue_family_index(queue_family).queue_priorities(&priorities)];
        let names: Vec<_> = extensions.iter().map(|e| e.as_ptr()).collect();
        let mut v13 = features;
        let core = softshadow::required_core_features();
        let ci = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_ci)
            .enabled_extension_names(&names)
            .enabled_features(&core)
            .push_next(&mut v13);
        let device = unsafe { instance.create_device(physical, &ci, None) }.unwrap();
        let queue = unsafe { device.get_device_queue(queue_family, 0) };
        let pool_ci = vk::CommandPoolCreateInfo::default()
            .queue_family_index(queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let pool = unsafe { device.create_command_pool(&pool_ci, None) }.unwrap();
        Embedder { entry, instance, messenger: (loader, messenger), physical, queue_family, device, queue, pool, log }
    }

    /// The handles the engine is built on, saying the device has `features`.
    pub fn handles(&self, features: vk::PhysicalDeviceVulkan13Features<'static>) -> EmbedderHandles {
        EmbedderHandles {
            entry: self.entry.clone(),
            instance: self.instance.clone(),
            physical_device: self.physical,
            device: self.device.clone(),
            queue_family: self.queue_family,
            queue_index: 0,
            enabled_features: features,
            enabled_core_features: softshadow::required_core_features(),
            allocation_callbacks: None,
        }
    }

    pub fn command_buffer(&self) -> vk::CommandBuffer {
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        unsafe { self.device.allocate_command_buffers(&alloc) }.unwrap()[0]
    }

    pub fn begin(&self, cmd: vk::CommandBuffer) {
        unsafe {
            self.device.reset_command_buffer(cmd, vk::CommandBufferResetFlags::empty()).unwrap();
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            self.device.begin_command_buffer(cmd, &begin).unwrap();
        }
    }

    /// Ends `cmd` and submits it, signalling `fence`.
    pub fn submit(&self, cmd: vk::CommandBuffer, fence: vk::Fence) {
        unsafe {
            self.device.end_command_buffer(cmd).unwrap();
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
            let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
            self.device.queue_submit2(self.queue, &submit, fence).unwrap();
        }
    }

    pub fn fence(&self, signalled: bool) -> vk::Fence {
        let flags = if signalled { vk::FenceCreateFlags::SIGNALED } else { vk::FenceCreateFlags::empty() };
        unsafe { self.device.create_fence(&vk::FenceCreateInfo::default().flags(flags), None) }.unwrap()
    }

    pub fn wait(&self, fence: vk::Fence) {
        unsafe {
            self.device.wait_for_fences(&[fence], true, u64::MAX).unwrap();
            self.device.reset_fences(&[fence]).unwrap();
        }
    }

    fn memory_type(&self, bits: u32, flags: vk::MemoryPropertyFlags) -> u32 {
        let props = unsafe { self.instance.get_physical_device_memory_properties(self.physical) };
        (0..props.memory_type_count)
            .find(|&i| bits & (1 << i) != 0 && props.memory_types[i as usize].property_flags.contains(flags))
            .expect("a memory type")
    }

    /// A 2D image of its own memory.
    pub fn image(&self, format: vk::Format, extent: vk::Extent2D, usage: vk::ImageUsageFlags) -> Image {
        let ci = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage);
        let image = unsafe { self.device.create_image(&ci, None) }.unwrap();
        let req = unsafe { self.device.get_image_memory_requirements(image) };
        let memory_type = self.memory_type(req.memory_type_bits, vk::MemoryPropertyFlags::DEVICE_LOCAL);
        let alloc = vk::MemoryAllocateInfo::default().allocation_size(req.size).memory_type_index(memory_type);
        let memory = unsafe { self.device.allocate_memory(&alloc, None) }.unwrap();
        unsafe { self.device.bind_image_memory(image, memory, 0) }.unwrap();
        Image { image, memory, format, extent }
    }

    /// A host-visible, coherent buffer of `size` bytes, mapped.
    pub fn buffer(&self, size: u64, usage: vk::BufferUsageFlags) -> HostBuffer {
        let ci = vk::BufferCreateInfo::default().size(size).usage(usage);
        let buffer = unsafe { self.device.create_buffer(&ci, None) }.unwrap();
        let req = unsafe { self.device.get_buffer_memory_requirements(buffer) };
        let flags = vk::MemoryPropertyFlags::HOST_VISIBLE | vk::MemoryPropertyFlags::HOST_COHERENT;
        let alloc = vk::MemoryAllocateInfo::default()
            .allocation_size(req.size)
            .memory_type_index(self.memory_type(req.memory_type_bits, flags));
        let memory = unsafe { self.device.allocate_memory(&alloc, None) }.unwrap();
        unsafe { self.device.bind_buffer_memory(buffer, memory, 0) }.unwrap();
        let ptr = unsafe { self.device.map_memory(memory, 0, size, vk::MemoryMapFlags::empty()) }.unwrap();
        HostBuffer { buffer, memory, ptr: ptr as *mut u8, size }
    }

    pub fn destroy_image(&self, image: Image) {
        unsafe {
            self.device.destroy_image(image.image, None);
            self.device.free_memory(image.memory, None);
        }
    }

    pub fn destroy_buffer(&self, buffer: HostBuffer) {
        unsafe {
            self.device.destroy_buffer(buffer.buffer, None);
            self.device.free_memory(buffer.memory, None);
        }
    }

    /// Destroys the device and then the instance, and fails on any validation error the
    /// embedder's messenger recorded (objects the engine left alive included).
    pub fn finish(self) {
        unsafe {
            self.device.destroy_command_pool(self.pool, None);
            self.device.destroy_device(None);
            self.messenger.0.destroy_debug_utils_messenger(self.messenger.1, None);
            self.instance.destroy_instance(None);
        }
        let errors = self.log.0.lock().unwrap().clone();
        assert!(errors.is_empty(), "{} validation error(s):\n{}", errors.len(), errors.join("\n"));
    }
}

pub struct Image {
    pub image: vk::Image,
    memory: vk::DeviceMemory,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
}

pub struct HostBuffer {
    pub buffer: vk::Buffer,
    memory: vk::DeviceMemory,
    ptr: *mut u8,
    pub size: u64,
}

impl HostBuffer {
    pub fn write(&self, bytes: &[u8]) {
        assert!(bytes.len() as u64 <= self.size);
        // SAFETY: mapped, coherent, at least `size` bytes; the GPU is not using it now.
        unsafe { std::ptr::copy_nonoverlapping(bytes.as_ptr(), self.ptr, bytes.len()) };
    }

    pub fn read(&self) -> Vec<u8> {
        // SAFETY: as `write`; the copy into it has finished (its fence was waited on).
        unsafe { std::slice::from_raw_parts(self.ptr, self.size as usize) }.to_vec()
    }
}

/// One image barrier with explicit stages, accesses and layouts.
pub fn barrier(
    device: &ash::Device,
    cmd: vk::CommandBuffer,
    image: vk::Image,
    aspect: vk::ImageAspectFlags,
    (src_stage, src_access, old): (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout),
    (dst_stage, dst_access, new): (vk::PipelineStageFlags2, vk::AccessFlags2, vk::ImageLayout),
) {
    let b = [vk::ImageMemoryBarrier2::default()
        .src_stage_mask(src_stage)
        .src_access_mask(src_access)
        .dst_stage_mask(dst_stage)
        .dst_access_mask(dst_access)
        .old_layout(old)
        .new_layout(new)
        .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
        .image(image)
        .subresource_range(vk::ImageSubresourceRange {
            aspect_mask: aspect,
            base_mip_level: 0,
            level_count: 1,
            base_array_layer: 0,
            layer_count: 1,
        })];
    unsafe { device.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().image_memory_barriers(&b)) };
}

/// A copy of all of `aspect` of an image of `extent` from or to tightly packed texels.
pub fn whole(aspect: vk::ImageAspectFlags, extent: vk::Extent2D) -> vk::BufferImageCopy {
    vk::BufferImageCopy {
        buffer_offset: 0,
        buffer_row_length: 0,
        buffer_image_height: 0,
        image_subresource: vk::ImageSubresourceLayers {
            aspect_mask: aspect,
            mip_level: 0,
            base_array_layer: 0,
            layer_count: 1,
        },
        image_offset: vk::Offset3D::default(),
        image_extent: vk::Extent3D { width: extent.width, height: extent.height, depth: 1 },
    }
}
