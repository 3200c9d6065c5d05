//! Buffers: every allocation goes through gpu-allocator and is freed explicitly.

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};

use super::Context;
use crate::error::{Error, Result, VkContext};

/// A buffer and its memory.
pub struct Buffer {
    pub(crate) buffer: vk::Buffer,
    allocation: Option<Allocation>,
    pub(crate) size: u64,
}

impl Buffer {
    /// `location`: `CpuToGpu` for per-frame data, `GpuToCpu` for readback, `GpuOnly` otherwise.
    pub fn new(
        ctx: &Context,
        name: &str,
        size: u64,
        usage: vk::BufferUsageFlags,
        location: MemoryLocation,
    ) -> Result<Self> {
        let size = size.max(4);
        let ci = vk::BufferCreateInfo::default().size(size).usage(usage).sharing_mode(vk::SharingMode::EXCLUSIVE);
        let buffer = unsafe { ctx.device.create_buffer(&ci, ctx.host_allocator()) }.vk("vkCreateBuffer")?;
        let requirements = unsafe { ctx.device.get_buffer_memory_requirements(buffer) };
        let desc = AllocationCreateDesc {
            name,
            requirements,
            location,
            linear: true,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        };
        let allocation = match ctx.allocate(&desc) {
            Ok(a) => a,
            Err(e) => {
                unsafe { ctx.device.destroy_buffer(buffer, ctx.host_allocator()) };
                return Err(e);
            }
        };
        let bound = unsafe { ctx.device.bind_buffer_memory(buffer, allocation.memory(), allocation.offset()) };
        let buf = Buffer { buffer, allocation: Some(allocation), size };
        if let Err(result) = bound {
            buf.destroy(ctx);
            return Err(Error::Vulkan { call: "vkBindBufferMemory", result });
        }
        ctx.name(buffer, name);
        Ok(buf)
    }

    /// Copies `bytes` to `offset` of a host-visible buffer.
    pub fn write(&mut self, offset: u64, bytes: &[u8]) {
        let slice = self.allocation.as_mut().and_then(Allocation::mapped_slice_mut).expect("host-visible buffer");
        slice[offset as usize..offset as usize + bytes.len()].copy_from_slice(bytes);
    }

    /// All of the buffer, as a descriptor range.
    pub fn range(&self) -> vk::DescriptorBufferInfo {
        vk::DescriptorBufferInfo { buffer: self.buffer, offset: 0, range: self.size }
    }

    /// The mapped contents of a host-visible buffer.
    pub fn read(&self) -> &[u8] {
        self.allocation.as_ref().and_then(Allocation::mapped_slice).expect("host-visible buffer")
    }

    pub fn destroy(mut self, ctx: &Context) {
        unsafe { ctx.device.destroy_buffer(self.buffer, ctx.host_allocator()) };
        if let Some(a) = self.allocation.take() {
            ctx.free(a);
        }
    }
}

/// One host-visible buffer holding a copy of `T` per frame in flight, each aligned for use as
/// a uniform or storage buffer range.
pub struct PerFrame {
    buffer: Buffer,
    stride: u64,
}

impl PerFrame {
    pub fn new(
        ctx: &Context,
        name: &str,
        bytes_per_frame: u64,
        frames: usize,
        usage: vk::BufferUsageFlags,
    ) -> Result<Self> {
        let limits = &ctx.limits;
        let align = limits.min_uniform_buffer_offset_alignment.max(limits.min_storage_buffer_offset_alignment).max(16);
        let stride = bytes_per_frame.max(16).div_ceil(align) * align;
        let buffer = Buffer::new(ctx, name, stride * frames as u64, usage, MemoryLocation::CpuToGpu)?;
        Ok(PerFrame { buffer, stride })
    }

    /// Keeps `slot` able to hold `bytes` per frame: grown (to a power of two) only when too
    /// small. Growing waits for the GPU, since the old buffer may be read by a frame in flight.
    pub fn ensure<'a>(
        ctx: &Context,
        slot: &'a mut Option<PerFrame>,
        name: &str,
        bytes: u64,
        usage: vk::BufferUsageFlags,
    ) -> Result<&'a mut PerFrame> {
        if slot.as_ref().is_none_or(|b| b.capacity() < bytes) {
            if let Some(old) = slot.take() {
                ctx.retire(move |ctx| old.destroy(ctx));
            }
            *slot = Some(PerFrame::new(ctx, name, bytes.next_power_of_two(), super::FRAMES_IN_FLIGHT, usage)?);
        }
        Ok(slot.as_mut().expect("just ensured"))
    }

    /// Bytes each frame's copy can hold.
    pub fn capacity(&self) -> u64 {
        self.stride
    }

    pub fn write(&mut self, frame: usize, bytes: &[u8]) {
        assert!(bytes.len() as u64 <= self.stride, "per-frame data larger than its slot");
        self.buffer.write(self.stride * frame as u64, bytes);
    }

    /// The descriptor range of frame `frame`'s copy.
    pub fn range(&self, frame: usize) -> vk::DescriptorBufferInfo {
        vk::DescriptorBufferInfo { buffer: self.buffer.buffer, offset: self.stride * frame as u64, range: self.stride }
    }

    pub fn destroy(self, ctx: &Context) {
        self.buffer.destroy(ctx);
    }
}
