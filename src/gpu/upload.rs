//! Uploads of static data (meshes) into device-local buffers, recorded into a frame; per-frame
//! copies of CPU-computed images into targets; copies of targets out for readback.

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::barrier::{Access, transition};
use super::context::{Context, UploadMark};
use super::memory::Buffer;
use super::target::Target;
use crate::error::Result;

/// Creates a device-local buffer holding `bytes`, its copy from a staging buffer recorded into
/// `cmd` (the frame's: no submission of its own, so an embedder's frame stays the only one), the
/// staging buffer retired until the frames recorded so far are done.
pub fn upload(
    ctx: &Context,
    cmd: vk::CommandBuffer,
    name: &str,
    bytes: &[u8],
    usage: vk::BufferUsageFlags,
) -> Result<Buffer> {
    let (dst, staging) = upload_in(ctx, cmd, name, bytes, usage)?;
    ctx.retire(move |ctx| staging.destroy(ctx));
    Ok(dst)
}

/// Data uploaded by recording into frames ([`upload`]), by key. A frame lost before it ran (an
/// error while recording, or an embedder's discarded frame) never ran its copies: what it
/// uploaded is made again when next asked for ([`Context::upload_kept`]), and the old copy
/// retired (an embedder may have submitted a failed frame's command buffer all the same).
/// Data the last frame that asked for any did not ask for is retired as the next one asks,
/// as the renderer's mesh cache drops meshes no frame draws: a loop streaming meshes (level
/// after level) keeps only those it still draws.
pub struct Uploads<K, T> {
    items: Vec<Upload<K, T>>,
    /// The frame that asked last ([`Context::frames_recorded`] while it was recorded).
    asked_in: Option<u64>,
    destroy: fn(T, &Context),
}

struct Upload<K, T> {
    key: K,
    /// When it was uploaded.
    mark: UploadMark,
    /// The frame that asked for it last.
    asked_in: u64,
    data: T,
}

impl<K: PartialEq, T: 'static> Uploads<K, T> {
    pub fn new(destroy: fn(T, &Context)) -> Self {
        Uploads { items: Vec::new(), asked_in: None, destroy }
    }

    /// The index of `key`'s data, made by `make` (recording its upload into this frame) when
    /// absent or lost. Indices stay valid until a later frame asks for any.
    pub fn index(&mut self, ctx: &Context, key: K, make: impl FnOnce() -> Result<T>) -> Result<usize> {
        let (frame, destroy) = (ctx.frames_recorded(), self.destroy);
        if let Some(last) = self.asked_in.filter(|&last| last != frame) {
            // Retired, not destroyed: the frames recorded so far may still use it.
            for stale in self.items.extract_if(.., |u| u.asked_in != last) {
                ctx.retire(move |ctx| destroy(stale.data, ctx));
            }
        }
        self.asked_in = Some(frame);
        let Some(at) = self.items.iter().position(|u| u.key == key) else {
            self.items.push(Upload { key, mark: ctx.upload_mark(), asked_in: frame, data: make()? });
            return Ok(self.items.len() - 1);
        };
        let item = &mut self.items[at];
        item.asked_in = frame;
        if !ctx.upload_kept(item.mark) {
            let old = std::mem::replace(&mut item.data, make()?);
            item.mark = ctx.upload_mark();
            ctx.retire(move |ctx| destroy(old, ctx));
        }
        Ok(at)
    }

    pub fn get(&self, index: usize) -> &T {
        &self.items[index].data
    }

    pub fn get_mut(&mut self, index: usize) -> &mut T {
        &mut self.items[index].data
    }

    pub fn destroy(self, ctx: &Context) {
        self.items.into_iter().for_each(|u| (self.destroy)(u.data, ctx));
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::{ContextOptions, FrameRing, Semaphores};

    /// Data a frame uploads is kept while frames are submitted (and within its own frame), and
    /// made again once a frame is lost: begun and never submitted, as on an error, or recorded
    /// into an embedder's command buffer and discarded; or once a frame asked for other data.
    #[test]
    fn what_a_lost_frame_uploaded_or_a_later_frame_left_is_made_again() {
        let mut ctx = Context::headless(&ContextOptions { validation: true, device: None }).unwrap();
        let mut ring = FrameRing::new(&ctx).unwrap();
        let mut uploads: Uploads<u32, Buffer> = Uploads::new(Buffer::destroy);
        let mut made = 0;
        // A frame uploading `keys` into the ring's command buffer, submitted or lost.
        let mut frame = |ctx: &Context, ring: &mut FrameRing, keys: &[u32], submit: bool| {
            let (slot, cmd) = ring.begin(ctx).map(|(f, _)| (f.slot, f.cmd)).unwrap();
            for &key in keys {
                let usage = vk::BufferUsageFlags::STORAGE_BUFFER;
                uploads
                    .index(ctx, key, || {
                        made += 1;
                        upload(ctx, cmd, "uploaded", &[1, 2, 3, 4], usage)
                    })
                    .unwrap();
            }
            if submit {
                ring.submit(ctx, slot, &Semaphores::NONE).unwrap();
            }
            made
        };
        assert_eq!(frame(&ctx, &mut ring, &[1, 1], true), 1, "made twice in its own frame");
        assert_eq!(frame(&ctx, &mut ring, &[1], true), 1, "made again after a submitted frame");
        assert_eq!(frame(&ctx, &mut ring, &[2], false), 2);
        // Frame 3 was lost: its upload is made again, and, no earlier upload being trusted, 1's.
        assert_eq!(frame(&ctx, &mut ring, &[2, 1], true), 4, "not made again after a lost frame");
        assert_eq!(frame(&ctx, &mut ring, &[2, 1], true), 4, "made again after frames were submitted");
        // What the last frame that asked did not ask for goes; frames asking nothing keep all.
        assert_eq!(frame(&ctx, &mut ring, &[2], true), 4);
        assert_eq!(frame(&ctx, &mut ring, &[], true), 4);
        assert_eq!(frame(&ctx, &mut ring, &[2], true), 4, "made again across a frame that asked for nothing");
        assert_eq!(frame(&ctx, &mut ring, &[1], true), 5, "kept after a frame that did not ask for it");
        ring.drain(&ctx).unwrap();
        uploads.destroy(&ctx);
        ring.destroy(&ctx);
        ctx.destroy();
        assert!(ctx.validation_errors().is_empty(), "{:?}", ctx.validation_errors());
    }
}
