//! Synchronization2 barriers with explicit stage/access/layout triples (niagara's
//! `imageBarrier`). A target remembers its last [`Access`]; a transition names the next one and
//! whether the old contents may be discarded.

use ash::vk;

use super::Context;
use super::target::{Target, subresource};

/// How a pass touches an image: in which stage, with which access, in which layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Access {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
    pub layout: vk::ImageLayout,
}

impl Access {
    /// Not touched yet.
    pub const NONE: Access = Access {
        stage: vk::PipelineStageFlags2::NONE,
        access: vk::AccessFlags2::NONE,
        layout: vk::ImageLayout::UNDEFINED,
    };
    /// Written as a color attachment.
    pub const COLOR_WRITE: Access = Access {
        stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        access: vk::AccessFlags2::COLOR_ATTACHMENT_WRITE,
        layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    };
    /// Tested and written as a depth attachment.
    pub const DEPTH_WRITE: Access = Access {
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::EARLY_FRAGMENT_TESTS.as_raw()
                | vk::PipelineStageFlags2::LATE_FRAGMENT_TESTS.as_raw(),
        ),
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ.as_raw()
                | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE.as_raw(),
        ),
        layout: vk::ImageLayout::DEPTH_ATTACHMENT_OPTIMAL,
    };
    /// Tested and written as a depth-stencil attachment (depth and stencil aspects).
    pub const DEPTH_STENCIL_WRITE: Access =
        Access { layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL, ..Access::DEPTH_WRITE };
    /// Tested, not written, as a depth-stencil attachment (a stencil test against a finished
    /// count, depth testing against a finished prepass).
    pub const DEPTH_STENCIL_READ: Access = Access {
        stage: Access::DEPTH_WRITE.stage,
        access: vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_READ,
        layout: vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL,
    };
    /// Sampled by fragment shaders (color).
    pub const FRAGMENT_READ: Access = Access {
        stage: vk::PipelineStageFlags2::FRAGMENT_SHADER,
        access: vk::AccessFlags2::SHADER_SAMPLED_READ,
        layout: vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL,
    };
    /// Sampled by compute, vertex and fragment shaders (color).
    pub const SHADERS_READ: Access = Access {
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::COMPUTE_SHADER.as_raw()
                | vk::PipelineStageFlags2::VERTEX_SHADER.as_raw()
                | vk::PipelineStageFlags2::FRAGMENT_SHADER.as_raw(),
        ),
        ..Access::FRAGMENT_READ
    };
    /// Sampled by fragment shaders (depth).
    pub const DEPTH_FRAGMENT_READ: Access = Access {
        stage: vk::PipelineStageFlags2::FRAGMENT_SHADER,
        access: vk::AccessFlags2::SHADER_SAMPLED_READ,
        layout: vk::ImageLayout::DEPTH_READ_ONLY_OPTIMAL,
    };
    /// Sampled by fragment shaders (the depth aspect of a depth-stencil image).
    pub const DEPTH_STENCIL_FRAGMENT_READ: Access =
        Access { layout: vk::ImageLayout::DEPTH_STENCIL_READ_ONLY_OPTIMAL, ..Access::DEPTH_FRAGMENT_READ };
    /// Written by a copy (an image computed on the CPU).
    pub const COPY_WRITE: Access = Access {
        stage: vk::PipelineStageFlags2::COPY,
        access: vk::AccessFlags2::TRANSFER_WRITE,
        layout: vk::ImageLayout::TRANSFER_DST_OPTIMAL,
    };
    /// Handed to or back from the presentation engine. The acquire semaphore is waited on, and
    /// the present semaphore signalled, at this stage: the first and last writes of a swapchain
    /// image are color attachment writes.
    pub const PRESENT: Access = Access {
        stage: vk::PipelineStageFlags2::COLOR_ATTACHMENT_OUTPUT,
        access: vk::AccessFlags2::NONE,
        layout: vk::ImageLayout::PRESENT_SRC_KHR,
    };
    /// Copied out for readback.
    pub const COPY_READ: Access = Access {
        stage: vk::PipelineStageFlags2::COPY,
        access: vk::AccessFlags2::TRANSFER_READ,
        layout: vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
    };
}

/// Transitions `target` from its last access to `next`. With `discard`, the old contents are
/// not needed (layout UNDEFINED): only the earlier accesses must finish first.
pub fn transition(ctx: &Context, cmd: vk::CommandBuffer, targets: &mut [(&mut Target, Access, bool)]) {
    let barriers: Vec<_> = targets
        .iter_mut()
        .filter(|(t, next, discard)| *discard || t.last != *next || is_write(t.last.access))
        .map(|(t, next, discard)| {
            let last = t.last;
            t.last = *next;
            vk::ImageMemoryBarrier2::default()
                .src_stage_mask(last.stage)
                // Only writes need making available; reads need just the execution dependency.
                .src_access_mask(if is_write(last.access) { last.access } else { vk::AccessFlags2::NONE })
                .dst_stage_mask(next.stage)
                .dst_access_mask(next.access)
                .old_layout(if *discard { vk::ImageLayout::UNDEFINED } else { last.layout })
                .new_layout(next.layout)
                .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
                .image(t.image)
                .subresource_range(subresource(t.desc.aspect()))
        })
        .collect();
    if !barriers.is_empty() {
        let dep = vk::DependencyInfo::default().image_memory_barriers(&barriers);
        unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
    }
}

/// Makes transfer writes to a readback buffer visible to the host after the frame's fence.
pub fn copy_to_host(ctx: &Context, cmd: vk::CommandBuffer) {
    let barrier = [vk::MemoryBarrier2::default()
        .src_stage_mask(vk::PipelineStageFlags2::COPY)
        .src_access_mask(vk::AccessFlags2::TRANSFER_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags2::HOST)
        .dst_access_mask(vk::AccessFlags2::HOST_READ)];
    let dep = vk::DependencyInfo::default().memory_barriers(&barrier);
    unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &dep) };
}

fn is_write(access: vk::AccessFlags2) -> bool {
    access.intersects(
        vk::AccessFlags2::COLOR_ATTACHMENT_WRITE
            | vk::AccessFlags2::DEPTH_STENCIL_ATTACHMENT_WRITE
            | vk::AccessFlags2::TRANSFER_WRITE,
    )
}

/// One side of a memory dependency on buffers: a stage and what it does there.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BufferAccess {
    pub stage: vk::PipelineStageFlags2,
    pub access: vk::AccessFlags2,
}

impl BufferAccess {
    /// Written by `vkCmdUpdateBuffer` (a copy-stage transfer).
    pub const TRANSFER_WRITE: BufferAccess =
        BufferAccess { stage: vk::PipelineStageFlags2::COPY, access: vk::AccessFlags2::TRANSFER_WRITE };
    /// Read by the host (after a fence, or a mark it polls).
    pub const HOST_READ: BufferAccess =
        BufferAccess { stage: vk::PipelineStageFlags2::HOST, access: vk::AccessFlags2::HOST_READ };
    /// Read and written (atomics, appends) by a compute shader.
    pub const COMPUTE_READ_WRITE: BufferAccess = BufferAccess {
        stage: vk::PipelineStageFlags2::COMPUTE_SHADER,
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::SHADER_STORAGE_READ.as_raw() | vk::AccessFlags2::SHADER_STORAGE_WRITE.as_raw(),
        ),
    };
    /// Written by a compute shader.
    pub const COMPUTE_WRITE: BufferAccess =
        BufferAccess { stage: vk::PipelineStageFlags2::COMPUTE_SHADER, access: vk::AccessFlags2::SHADER_STORAGE_WRITE };
    /// Read as a storage buffer by vertex shaders.
    pub const VERTEX_STORAGE_READ: BufferAccess =
        BufferAccess { stage: vk::PipelineStageFlags2::VERTEX_SHADER, access: vk::AccessFlags2::SHADER_STORAGE_READ };
    /// Generated geometry drawn indirectly: the vertices and the draw's arguments.
    pub const INDIRECT_DRAW: BufferAccess = BufferAccess {
        stage: vk::PipelineStageFlags2::from_raw(
            vk::PipelineStageFlags2::DRAW_INDIRECT.as_raw() | vk::PipelineStageFlags2::VERTEX_ATTRIBUTE_INPUT.as_raw(),
        ),
        access: vk::AccessFlags2::from_raw(
            vk::AccessFlags2::INDIRECT_COMMAND_READ.as_raw() | vk::AccessFlags2::VERTEX_ATTRIBUTE_READ.as_raw(),
        ),
    };
}

/// Orders buffer accesses: everything `before` did is finished and visible to `after`.
pub fn buffer_barrier(ctx: &Context, cmd: vk::CommandBuffer, before: BufferAccess, after: BufferAccess) {
    let barrier = [vk::MemoryBarrier2::default()
        .src_stage_mask(before.stage)
        .src_access_mask(before.access)
        .dst_stage_mask(after.stage)
        .dst_access_mask(after.access)];
    unsafe { ctx.device.cmd_pipeline_barrier2(cmd, &vk::DependencyInfo::default().memory_barriers(&barrier)) };
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A write must be made available before the next access: every writing access says so.
    #[test]
    fn writes_are_known_as_writes() {
        for write in [Access::COLOR_WRITE, Access::DEPTH_WRITE, Access::DEPTH_STENCIL_WRITE, Access::COPY_WRITE] {
            assert!(is_write(write.access), "{write:?}");
        }
        for read in
            [Access::NONE, Access::DEPTH_STENCIL_READ, Access::FRAGMENT_READ, Access::COPY_READ, Access::PRESENT]
        {
            assert!(!is_write(read.access), "{read:?}");
        }
    }
}
