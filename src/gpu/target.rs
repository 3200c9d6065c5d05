//! Render targets, declared by description (kajiya's `ImageDesc`, Granite's `render_target`)
//! or wrapped from images made elsewhere, and carrying their last access so barriers are
//! derived, not guessed.

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
    /// A second view that reads the same texels as another format of the same size (R16G16_UNORM
    /// as R32_UINT: both channels in one gather), bound with [`Descriptor::Reinterpreted`].
    ///
    /// [`Descriptor::Reinterpreted`]: super::Descriptor::Reinterpreted
    pub reinterpreted: Option<vk::Format>,
}

impl TargetDesc {
    /// A color attachment that later passes sample.
    pub fn color(name: &'static str, format: vk::Format, width: u32, height: u32) -> Self {
        TargetDesc {
            name,
            format,
            extent: vk::Extent2D { width, height },
            usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            reinterpreted: None,
        }
    }

    /// A D32 depth attachment.
    pub fn depth(name: &'static str, width: u32, height: u32) -> Self {
        TargetDesc {
            name,
            format: vk::Format::D32_SFLOAT,
            extent: vk::Extent2D { width, height },
            usage: vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT,
            reinterpreted: None,
        }
    }

    /// A depth-stencil attachment of `format`, which is the context's
    /// [`depth_stencil_format`](Context::depth_stencil_format).
    pub fn depth_stencil(name: &'static str, format: vk::Format, width: u32, height: u32) -> Self {
        TargetDesc { format, ..TargetDesc::depth(name, width, height) }
    }

    /// Adds usages (`SAMPLED` to read a depth target, `TRANSFER_SRC` to read one back).
    pub fn usage(mut self, extra: vk::ImageUsageFlags) -> Self {
        self.usage |= extra;
        self
    }

    /// Adds a view reading the texels as `format`, which must be of the same size per texel.
    pub fn reinterpreted_as(mut self, format: vk::Format) -> Self {
        self.reinterpreted = Some(format);
        self
    }

    /// The aspects of the format: what barriers, views and attachments cover.
    pub fn aspect(&self) -> vk::ImageAspectFlags {
        match self.format {
            vk::Format::D16_UNORM | vk::Format::X8_D24_UNORM_PACK32 | vk::Format::D32_SFLOAT => {
                vk::ImageAspectFlags::DEPTH
            }
            vk::Format::D16_UNORM_S8_UINT | vk::Format::D24_UNORM_S8_UINT | vk::Format::D32_SFLOAT_S8_UINT => {
                vk::ImageAspectFlags::DEPTH | vk::ImageAspectFlags::STENCIL
            }
            vk::Format::S8_UINT => vk::ImageAspectFlags::STENCIL,
            _ => vk::ImageAspectFlags::COLOR,
        }
    }
}

/// What a target created, and so what `destroy` destroys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Owns {
    /// Image, view and memory.
    Everything,
    /// A view of a wrapped image.
    View,
    /// Nothing: image and view are wrapped.
    Nothing,
}

/// An image, its view and memory (our own, or wrapped), and the access that last touched it.
pub struct Target {
    pub desc: TargetDesc,
    pub(crate) image: vk::Image,
    pub(crate) view: vk::ImageView,
    /// The view of `desc.reinterpreted`, where the target made one.
    pub(crate) reinterpreted: Option<vk::ImageView>,
    allocation: Option<Allocation>,
    owns: Owns,
    pub(crate) last: Access,
}

impl Target {
    /// Creates an image and view of `desc` in memory of its own.
    pub fn new(ctx: &Context, desc: TargetDesc) -> Result<Self> {
        check_extent(ctx, &desc)?;
        let vk::Extent2D { width, height } = desc.extent;
        let formats: Vec<vk::Format> = std::iter::once(desc.format).chain(desc.reinterpreted).collect();
        let mut format_list = vk::ImageFormatListCreateInfo::default().view_formats(&formats);
        let mut ci = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(desc.format)
            .extent(vk::Extent3D { width, height, depth: 1 })
            .mip_levels(1)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(desc.usage)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        if desc.reinterpreted.is_some() {
            // Listing the formats lets a driver keep what compression both allow.
            ci = ci.flags(vk::ImageCreateFlags::MUTABLE_FORMAT).push_next(&mut format_list);
        }
        let image = unsafe { ctx.device.create_image(&ci, ctx.host_allocator()) }.vk("vkCreateImage")?;
        let requirements = unsafe { ctx.device.get_image_memory_requirements(image) };
        let alloc_desc = AllocationCreateDesc {
            name: desc.name,
            requirements,
            location: MemoryLocation::GpuOnly,
            linear: false,
            allocation_scheme: AllocationScheme::GpuAllocatorManaged,
        };
        let mut target = Target {
            desc,
            image,
            view: vk::ImageView::null(),
            reinterpreted: None,
            allocation: None,
            owns: Owns::Everything,
            last: Access::NONE,
        };
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
        if let Err(e) = target.create_views(ctx) {
            target.destroy(ctx);
            return Err(e);
        }
        ctx.name(image, desc.name);
        Ok(target)
    }

    /// The view of `desc`, and the view of its reinterpreted format where it has one.
    fn create_views(&mut self, ctx: &Context) -> Result<()> {
        self.view = create_view(ctx, self.image, &self.desc)?;
        if let Some(format) = self.desc.reinterpreted {
            let desc = TargetDesc { format, ..self.desc };
            self.reinterpreted = Some(view_of(ctx, self.image, &desc, self.desc.aspect())?);
        }
        Ok(())
    }

    /// Wraps an image created elsewhere (a swapchain image, the embedder's depth buffer) of
    /// `desc`, now in `current`, with its `view` or else a view made here. `destroy` then
    /// destroys only a view made here; barriers treat the image like one of our own.
    pub fn wrap(
        ctx: &Context,
        desc: TargetDesc,
        image: vk::Image,
        view: Option<vk::ImageView>,
        current: Access,
    ) -> Result<Self> {
        check_extent(ctx, &desc)?;
        let (view, owns) = match view {
            Some(v) => (v, Owns::Nothing),
            None => (create_view(ctx, image, &desc)?, Owns::View),
        };
        Ok(Target { desc, image, view, reinterpreted: None, allocation: None, owns, last: current })
    }

    /// [`Target::wrap`] for an image that passes only sample (the embedder's depth): the view
    /// made here covers the depth aspect alone, as sampling a depth-stencil image requires,
    /// while barriers still cover every aspect.
    pub fn wrap_for_sampling(ctx: &Context, desc: TargetDesc, image: vk::Image, current: Access) -> Result<Self> {
        check_extent(ctx, &desc)?;
        let aspect = desc.aspect();
        let sampled = if aspect.contains(vk::ImageAspectFlags::DEPTH) { vk::ImageAspectFlags::DEPTH } else { aspect };
        let view = view_of(ctx, image, &desc, sampled)?;
        Ok(Target { desc, image, view, reinterpreted: None, allocation: None, owns: Owns::View, last: current })
    }

    /// The image (ours or wrapped), for an embedder to read what the engine wrote.
    pub fn image(&self) -> vk::Image {
        self.image
    }

    /// The view passes read and write it through.
    pub fn view(&self) -> vk::ImageView {
        self.view
    }

    /// The access that last touched it: the state the next user must start from.
    pub fn last_access(&self) -> Access {
        self.last
    }

    pub fn extent(&self) -> vk::Extent2D {
        self.desc.extent
    }

    /// A copy between all of this image and tightly packed texels at `buffer_offset` (a color
    /// or depth target; a depth-stencil one copies an aspect at a time, with [`Target::aspect_copy`]).
    pub fn whole_copy(&self, buffer_offset: u64) -> vk::BufferImageCopy {
        self.aspect_copy(self.desc.aspect(), buffer_offset)
    }

    /// A copy between `aspect` of all of this image and tightly packed texels at `buffer_offset`.
    pub fn aspect_copy(&self, aspect: vk::ImageAspectFlags, buffer_offset: u64) -> vk::BufferImageCopy {
        let extent = self.extent();
        vk::BufferImageCopy {
            buffer_offset,
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

    /// Destroys what this target created: for a wrapped image, at most the view made for it.
    pub fn destroy(mut self, ctx: &Context) {
        unsafe {
            if self.owns != Owns::Nothing {
                ctx.device.destroy_image_view(self.view, ctx.host_allocator());
                if let Some(view) = self.reinterpreted {
                    ctx.device.destroy_image_view(view, ctx.host_allocator());
                }
            }
            if self.owns == Owns::Everything {
                ctx.device.destroy_image(self.image, ctx.host_allocator());
            }
        }
        if let Some(a) = self.allocation.take() {
            ctx.free(a);
        }
    }
}

fn check_extent(ctx: &Context, desc: &TargetDesc) -> Result<()> {
    let max = ctx.info.max_image_dimension_2d;
    let vk::Extent2D { width, height } = desc.extent;
    if width == 0 || height == 0 || width > max || height > max {
        return Err(Error::Invalid(format!(
            "{} target of {width}x{height}: each side must lie in 1..={max} on {}",
            desc.name, ctx.info.name
        )));
    }
    Ok(())
}

fn create_view(ctx: &Context, image: vk::Image, desc: &TargetDesc) -> Result<vk::ImageView> {
    view_of(ctx, image, desc, desc.aspect())
}

fn view_of(ctx: &Context, image: vk::Image, desc: &TargetDesc, aspect: vk::ImageAspectFlags) -> Result<vk::ImageView> {
    let view_ci = vk::ImageViewCreateInfo::default()
        .image(image)
        .view_type(vk::ImageViewType::TYPE_2D)
        .format(desc.format)
        .subresource_range(subresource(aspect));
    let view = unsafe { ctx.device.create_image_view(&view_ci, ctx.host_allocator()) }.vk("vkCreateImageView")?;
    ctx.name(view, desc.name);
    Ok(view)
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
        ctx.retire(move |ctx| old.destroy(ctx));
    }
    *slot = Some(Target::new(ctx, desc)?);
    Ok(())
}
