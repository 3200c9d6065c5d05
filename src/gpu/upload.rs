//! One-time uploads of static data (meshes) into device-local buffers, per-frame copies of
//! CPU-computed images into targets, and copies of targets out for readback.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::Context;
use super::barrier::{Access, transition};
use super::memory::Buffer;
use super::target::Target;
use crate::error::{Result, VkContext};

/// Creates a device-local buffer holding `bytes`, through a staging buffer, and waits for it.
pub fn upload(ctx: &Context, name: &str, bytes: &[u8], usage: vk::BufferUsageFlags) -> Result<Buffer> {
    let mut made = None;
    let result = submit_and_wait(ctx, |cmd| {
        made = Some(upload_in(ctx, cmd, name, bytes, usage));
    });
    let (dst, staging) = made.expect("recorded")?;
    staging.destroy(ctx);
    match result {
        Ok(()) => Ok(dst),
        Err(e) => {
            dst.destroy(ctx);
            Err(e)
        }
    }
}

/// Creates a device-local buffer holding `bytes` and records its copy from a staging buffer
/// into `cmd` (outside a render pass), ordered before later vertex, index and compute reads:
/// no submission, no wait. Returns the buffer and the staging buffer, which must live until
/// `cmd` has finished executing.
pub fn upload_in(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    name: &str,
    bytes: &[u8],
    usage: vk::BufferUsageFlags,
) -> Result<(Buffer, Buffer)> {
    let size = bytes.len() as u64;
    let mut staging = Buffer::new(ctx, "staging", size, vk::BufferUsageFlags::TRANSFER_SRC, MemoryLocation::CpuToGpu)?;
    staging.write(0, bytes);
    let dst = match Buffer::new(ctx, name, size, usage | vk::BufferUsageFlags::TRANSFER_DST, MemoryLocation::GpuOnly) {
        Ok(b) => b,
        Err(e) => {
            staging.destroy(ctx);
            return Err(e);
        }
    };
    unsafe {
        ctx.device.cmd_copy_buffer(
            cmd,
            staging.buffer,
            dst.buffer,
            &[vk::BufferCopy { src_offset: 0, dst_offset: 0, size }],
        );
        // Later passes read the data as vertices and indices, or compute shaders read and write
        // it: order them after the copy.
        let barrier = [vk::MemoryBarrier2::default()
            .src_stage_mask(vk::PipelineStageFlags2::COPY)
            .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
            .dst_stage_mask(
                vk::PipelineStageFlags2::VERTEX_ATTRIBUTE_INPUT
                    | vk::PipelineStageFlags2::INDEX_INPUT
                    | vk::PipelineStageFlags2::COMPUTE_SHADER,
            )
            .dst_access_mask(
                vk::AccessFlags2::VERTEX_ATTRIBUTE_READ
                    | vk::AccessFlags2::INDEX_READ
                    | vk::AccessFlags2::SHADER_STORAGE_READ
                    | vk::AccessFlags2::SHADER_STORAGE_WRITE,
            )];
        ctx.device.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&barrier));
    }
    Ok((dst, staging))
}

fn submit_and_wait(ctx: &Context, record: impl FnOnce(vk::CommandBuffer)) -> Result<()> {
    let d = &ctx.device;
    let pool_ci = vk::CommandPoolCreateInfo::default()
        .queue_family_index(ctx.queue_family)
        .flags(vk::CommandPoolCreateFlags::TRANSIENT);
    let pool = unsafe { d.create_command_pool(&pool_ci, ctx.host_allocator()) }.vk("vkCreateCommandPool")?;
    let run = || -> Result<()> {
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        let cmd = unsafe { d.allocate_command_buffers(&alloc) }.vk("vkAllocateCommandBuffers")?[0];
        let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
        unsafe { d.begin_command_buffer(cmd, &begin) }.vk("vkBeginCommandBuffer")?;
        record(cmd);
        unsafe { d.end_command_buffer(cmd) }.vk("vkEndCommandBuffer")?;
        let fence =
            unsafe { d.create_fence(&vk::FenceCreateInfo::default(), ctx.host_allocator()) }.vk("vkCreateFence")?;
        let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(cmd)];
        let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cmds)];
        let waited = unsafe { d.queue_submit2(ctx.queue, &submit, fence) }
            .vk("vkQueueSubmit2")
            .and_then(|()| unsafe { d.wait_for_fences(&[fence], true, u64::MAX) }.vk("vkWaitForFences"));
        unsafe { d.destroy_fence(fence, ctx.host_allocator()) };
        waited
    };
    let result = run();
    unsafe { d.destroy_command_pool(pool, ctx.host_allocator()) };
    result
}

/// Records a copy of tightly packed texels from `src` (a host-visible range written this frame)
/// into all of `target`, whose old contents are discarded.
pub fn copy_to_target(ctx: &Context, cmd: vk::CommandBuffer, src: vk::DescriptorBufferInfo, target: &mut Target) {
    transition(ctx, cmd, &mut [(target, Access::COPY_WRITE, true)]);
    let region = target.whole_copy(src.offset);
    unsafe {
        ctx.device.cmd_copy_buffer_to_image(
            cmd,
            src.buffer,
            target.image,
            vk::ImageLayout::TRANSFER_DST_OPTIMAL,
            &[region],
        )
    };
}

/// Records copies of `regions` of `target` (already transitioned to [`Access::COPY_READ`]) into
/// `dst`; [`copy_to_host`](super::copy_to_host) then makes them visible to the host.
pub fn copy_to_buffer(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    target: &Target,
    dst: &Buffer,
    regions: &[vk::BufferImageCopy],
) {
    unsafe { ctx.device.cmd_copy_image_to_buffer(cmd, target.image, target.last.layout, dst.buffer, regions) };
}
