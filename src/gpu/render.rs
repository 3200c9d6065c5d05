//! Dynamic rendering scopes: attachments, clears, and the viewport covering them.

use ash::vk;

use super::Context;
use super::pipeline::{Descriptor, Pipeline};
use super::target::Target;
use crate::error::Result;

/// A target drawn into, cleared first or loaded.
pub struct Attachment<'a> {
    pub target: &'a Target,
    pub clear: Option<vk::ClearValue>,
}

impl<'a> Attachment<'a> {
    pub fn clear_color(target: &'a Target, rgba: [f32; 4]) -> Self {
        Attachment { target, clear: Some(vk::ClearValue { color: vk::ClearColorValue { float32: rgba } }) }
    }

    /// A color attachment of an integer format cleared to `value`.
    pub fn clear_uint(target: &'a Target, value: [u32; 4]) -> Self {
        Attachment { target, clear: Some(vk::ClearValue { color: vk::ClearColorValue { uint32: value } }) }
    }

    pub fn clear_depth(target: &'a Target, depth: f32) -> Self {
        Attachment {
            target,
            clear: Some(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth, stencil: 0 } }),
        }
    }

    /// A depth-stencil attachment cleared to `depth` and `stencil`.
    pub fn clear_depth_stencil(target: &'a Target, depth: f32, stencil: u32) -> Self {
        Attachment {
            target,
            clear: Some(vk::ClearValue { depth_stencil: vk::ClearDepthStencilValue { depth, stencil } }),
        }
    }

    fn info(&self) -> vk::RenderingAttachmentInfo<'static> {
        vk::RenderingAttachmentInfo::default()
            .image_view(self.target.view)
            .image_layout(self.target.last.layout)
            .load_op(if self.clear.is_some() { vk::AttachmentLoadOp::CLEAR } else { vk::AttachmentLoadOp::LOAD })
            .store_op(vk::AttachmentStoreOp::STORE)
            .clear_value(self.clear.unwrap_or_default())
    }
}

/// A dynamic rendering scope; `end` closes it.
pub struct RenderPass;

impl RenderPass {
    /// Begins rendering into `colors` and `depth` (all the same size, already transitioned) and
    /// sets the viewport and scissor to cover them. A `depth` target with a stencil aspect is the
    /// stencil attachment too.
    pub fn begin(
        ctx: &Context,
        cmd: vk::CommandBuffer,
        colors: &[Attachment<'_>],
        depth: Option<Attachment<'_>>,
    ) -> Self {
        let extent = colors.first().or(depth.as_ref()).expect("a pass draws into something").target.extent();
        let color_infos: Vec<_> = colors.iter().map(Attachment::info).collect();
        let depth_info = depth.as_ref().map(|d| (d.info(), d.target.desc.aspect()));
        let mut info = vk::RenderingInfo::default()
            .render_area(vk::Rect2D { offset: vk::Offset2D::default(), extent })
            .layer_count(1)
            .color_attachments(&color_infos);
        if let Some((d, aspect)) = &depth_info {
            if aspect.contains(vk::ImageAspectFlags::DEPTH) {
                info = info.depth_attachment(d);
            }
            // Dynamic rendering clears, loads and stores the stencil aspect only through this.
            if aspect.contains(vk::ImageAspectFlags::STENCIL) {
                info = info.stencil_attachment(d);
            }
        }
        let viewport = vk::Viewport {
            x: 0.0,
            y: 0.0,
            width: extent.width as f32,
            height: extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        unsafe {
            ctx.device.cmd_begin_rendering(cmd, &info);
            ctx.device.cmd_set_viewport(cmd, 0, &[viewport]);
            ctx.device.cmd_set_scissor(cmd, 0, &[vk::Rect2D { offset: vk::Offset2D::default(), extent }]);
        }
        RenderPass
    }

    /// Restricts drawing to `area` of the attachments (one tile of an atlas).
    pub fn set_area(&self, ctx: &Context, cmd: vk::CommandBuffer, area: vk::Rect2D) {
        let viewport = vk::Viewport {
            x: area.offset.x as f32,
            y: area.offset.y as f32,
            width: area.extent.width as f32,
            height: area.extent.height as f32,
            min_depth: 0.0,
            max_depth: 1.0,
        };
        unsafe {
            ctx.device.cmd_set_viewport(cmd, 0, &[viewport]);
            ctx.device.cmd_set_scissor(cmd, 0, &[area]);
        }
    }

    pub fn end(self, ctx: &Context, cmd: vk::CommandBuffer) {
        unsafe { ctx.device.cmd_end_rendering(cmd) };
    }
}

/// Runs a [`Pipeline::fullscreen`] pass over all of `target` (already transitioned for
/// writing; every pixel is overwritten, so nothing is loaded or cleared).
pub fn fullscreen(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    pipeline: &Pipeline,
    target: &Target,
    inputs: &[Descriptor<'_>],
) -> Result<()> {
    let pass = RenderPass::begin(ctx, cmd, &[Attachment { target, clear: None }], None);
    let bound = pipeline.bind(ctx, cmd, inputs);
    if bound.is_ok() {
        draw_fullscreen(ctx, cmd);
    }
    pass.end(ctx, cmd);
    bound
}

/// Draws the full-screen triangle of `glsl/common/fullscreen.vert` with the bound pipeline,
/// inside a pass the caller began (one that loads what earlier passes wrote).
pub fn draw_fullscreen(ctx: &Context, cmd: vk::CommandBuffer) {
    unsafe { ctx.device.cmd_draw(cmd, 3, 1, 0, 0) };
}

/// Draws `count` vertices of the tightly packed vertex buffer range `vertices` from `first`
/// (generated geometry), with the bound pipeline.
pub fn draw_vertices(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    vertices: vk::DescriptorBufferInfo,
    first: u32,
    count: u32,
) {
    if count == 0 {
        return;
    }
    unsafe {
        ctx.device.cmd_bind_vertex_buffers(cmd, 0, &[vertices.buffer], &[vertices.offset]);
        ctx.device.cmd_draw(cmd, count, 1, first, 0);
    }
}

/// Draws `count` vertices from `first` that the bound pipeline's vertex shader makes from
/// gl_VertexIndex alone (no vertex buffer: it reads its primitives from a storage buffer).
pub fn draw_generated(ctx: &Context, cmd: vk::CommandBuffer, first: u32, count: u32) {
    if count > 0 {
        unsafe { ctx.device.cmd_draw(cmd, count, 1, first, 0) };
    }
}

/// Draws `index_count` indices of `indices` (u32) into `vertices` as instance `instance` (a
/// mesh; the instance indexes per-object data), with the bound pipeline.
pub fn draw_indexed(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    vertices: vk::Buffer,
    indices: vk::Buffer,
    index_count: u32,
    instance: u32,
) {
    unsafe {
        ctx.device.cmd_bind_vertex_buffers(cmd, 0, &[vertices], &[0]);
        ctx.device.cmd_bind_index_buffer(cmd, indices, 0, vk::IndexType::UINT32);
        ctx.device.cmd_draw_indexed(cmd, index_count, 1, 0, 0, instance);
    }
}

/// The bytes of one `VkDrawIndirectCommand`: vertex count, instance count, first vertex, first
/// instance.
pub const DRAW_COMMAND_BYTES: u64 = std::mem::size_of::<vk::DrawIndirectCommand>() as u64;

/// Draws the vertices of `vertices` as many as the `VkDrawIndirectCommand` at `args` says
/// (geometry a compute shader generated), with the bound pipeline.
pub fn draw_indirect(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    vertices: vk::DescriptorBufferInfo,
    args: vk::DescriptorBufferInfo,
) {
    unsafe {
        ctx.device.cmd_bind_vertex_buffers(cmd, 0, &[vertices.buffer], &[vertices.offset]);
        ctx.device.cmd_draw_indirect(cmd, args.buffer, args.offset, 1, DRAW_COMMAND_BYTES as u32);
    }
}

/// Runs the bound compute pipeline over `groups` workgroups.
pub fn dispatch(ctx: &Context, cmd: vk::CommandBuffer, groups: u32) {
    unsafe { ctx.device.cmd_dispatch(cmd, groups, 1, 1) };
}

/// Copies the first `size` bytes of `src` to `dst` from the command buffer (a copy-stage
/// transfer: [`BufferAccess::TRANSFER_WRITE`](super::BufferAccess::TRANSFER_WRITE) on `dst`).
pub fn copy_buffer(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    src: vk::DescriptorBufferInfo,
    dst: vk::DescriptorBufferInfo,
    size: u64,
) {
    let region = vk::BufferCopy { src_offset: src.offset, dst_offset: dst.offset, size };
    unsafe { ctx.device.cmd_copy_buffer(cmd, src.buffer, dst.buffer, &[region]) };
}

/// Writes `data` (at most 64 KiB, a multiple of 4 bytes) into `dst` from the command buffer.
pub fn update_buffer(ctx: &Context, cmd: vk::CommandBuffer, dst: vk::DescriptorBufferInfo, data: &[u8]) {
    unsafe { ctx.device.cmd_update_buffer(cmd, dst.buffer, dst.offset, data) };
}
