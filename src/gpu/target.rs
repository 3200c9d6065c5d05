//! Render targets, declared by description (kajiya's `ImageDesc`, Granite's `render_target`)
//! and carrying their last access so barriers are derived, not guessed.

use ash::vk;
use gpu_allocator::MemoryLocation;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};

use super::Context;
use super::barrier::Access;
use crate::error::{Error, Result, VkContext};

/// What a target is: a 2D image of a format and size, and how it is used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TargetDesc {
    pub name: &'static str,
    pub format: vk::Format,
    pub extent: vk::Extent2D,
    pub usage: vk::ImageUsageFlags,
}

impl TargetDesc {
    /// A color attachment that later passes sample.
    pub fn color(name: &'static str, format: vk::Format, width: u32, height: u32) -> Self {
        TargetDesc {
            name,
            format,
            extent: vk::Extent2D { width, height },
            usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
        }
    }

    /// A D32 depth attachment.
    pub fn depth(name: &'static str, width: u32, height: u32) -> Self {
        TargetDesc {
            name,
            format: vk::Format::D32_SFLOAT,
            extent: vk::Extent2D { width, height },
            usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
        }
    }

    /// Adds usages (`SAMPLED` to read a depth target, `TRANSFER_SRC` to read one back).
    pub fn usage(mut self, extra: vk::ImageUsageFlags) -> Self {
        self.usage |= extra;
        self
    }

    pub fn aspect(&self) -> vk::ImageAspectFlags {
        if self.format == vk::Format::D32_SFLOAT { vk::ImageAspectFlags::DEPTH } else { vk::ImageAspectFlags::COLOR }
    }
}

/// An image, its view and memory, and the access that last touched it.
pub struct Target {
    pub desc: TargetDesc,
    pub(crate) image: vk::Image,
    pub(crate) view: vk::ImageView,
    allocation: Option<Allocation>,
    pub(crate) last: Access,
}

impl Target {
    pub fn new(ctx: &Context, desc: TargetDesc) -> Result<Self> {
        let max = ctx.info.max_image_dimension_2d;
        let vk::Extent2D { width, height } = desc.extent;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(Error::Invalid(format!(
                "{} target of {width}x{height}: each side must lie in 1..={max} on {}",
                desc.name, ctx.info.name
            )));
        }
        let ci = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D { width, height, depth: 1 })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let image = unsafe { ctx.device.create_image(&ci, None) }.vk("vkCreateImage")?;
        let requirements = unsafe { ctx.device.get_image_memory_requirements(image) };
        let alloc_desc = AllocationCreateDesc {
            name: desc.name,
            requirements,
            location: MemoryLocation::GpuOnly,
            linear: false,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        };
        let mut target = Target { desc, image, view: vk::ImageView::null(), allocation: None, last: Access::NONE };
        match ctx.allocate(&alloc_desc) {
            Ok(a) => target.allocation = Some(a),
            Err(e) => {
                target.destroy(ctx);
                return Err(e);
            }
        }
        let a = target.allocation.as_ref().expect("just set");
        if let Err(result) = unsafe { ctx.device.bind_image_memory(image, a.memory(), a.offset()) } {
            target.destroy(ctx);
            return Err(Error::Vulkan { call: "vkBindImageMemory", result });
        }
        let view_ci = vk::ImageViewCreateInfo::default()
            .image(image)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(desc.format)
            .subresource_range(subresource(desc.aspect()));
        match unsafe { ctx.device.create_image_view(&view_ci, None) } {
            Ok(v) => target.view = v,
            Err(result) => {
                target.destroy(ctx);
                return Err(Error::Vulkan { call: "vkCreateImageView", result });
            }
        }
        ctx.name(image, desc.name);
        ctx.name(target.view, desc.name);
        Ok(target)
    }

    pub fn extent(&self) -> vk::Extent2D {
        self.desc.extent
    }

    /// A copy between all of this image and tightly packed texels at `buffer_offset`.
    pub fn whole_copy(&self, buffer_offset: u64) -> vk::BufferImageCopy {
        let extent = self.extent();
        vk::BufferImageCopy {
            buffer_offset,
            buffer_row_length: 0,
            buffer_image_height: 0,
            image_subresource: vk::ImageSubresourceLayers {
                aspect_mask: self.desc.aspect(),
                mip_level: 0,
                base_array_layer: 0,
                layer_count: 1,
            },
            image_offset: vk::Offset3D::default(),
            image_extent: vk::Extent3D { width: extent.width, height: extent.height, depth: 1 },
        }
    }

    pub fn destroy(mut self, ctx: &Context) {
        unsafe {
            ctx.device.destroy_image_view(self.view, None);
            ctx.device.destroy_image(self.image, None);
        }
        if let Some(a) = self.allocation.take() {
            ctx.free(a);
        }
    }
}

pub(crate) fn subresource(aspect: vk::ImageAspectFlags) -> vk::ImageSubresourceRange {
    vk::ImageSubresourceRange {
        aspect_mask: aspect,
        base_mip_level: 0,
        level_count: 1,
        base_array_layer: 0,
        layer_count: 1,
    }
}

/// Keeps a target matching a description: re-created only when the description changes.
pub fn ensure(ctx: &Context, slot: &mut Option<Target>, desc: TargetDesc) -> Result<()> {
    if slot.as_ref().is_some_and(|t| t.desc == desc) {
        return Ok(());
    }
    if let Some(old) = slot.take() {
        // The old image may still be read by a frame in flight.
        ctx.wait_idle()?;
        old.destroy(ctx);
    }
    *slot = Some(Target::new(ctx, desc)?);
    Ok(())
}
