//! Frames in flight: a command buffer, a fence and a pass timer each. Beginning a frame waits
//! for the one that last used its slot and hands back that frame's pass times.

use ash::vk;

use gpu_allocator::MemoryLocation;

use super::Context;
use super::barrier::{BufferAccess, buffer_barrier};
use super::memory::Buffer;
use super::timestamps::{PassTime, PassTimer, RESULT_BYTES};
use crate::error::{Error, Result, VkContext};

/// Frames the CPU may record ahead of the GPU.
pub const FRAMES_IN_FLIGHT: usize = 2;

struct Slot {
    cmd: vk::CommandBuffer,
    fence: vk::Fence,
    timer: PassTimer,
}

/// The ring of frame slots.
pub struct FrameRing {
    pool: vk::CommandPool,
    slots: Vec<Slot>,
    next: usize,
    /// The raw GPU timestamp that pass begin times count from.
    gpu_origin: Option<u64>,
    /// Made by the first embedder's frame.
    external: Option<External>,
}

/// Per slot in [`External::buffer`]: the progress mark (padded to 8 bytes), then the timestamps.
const SLOT_BYTES: u64 = 8 + RESULT_BYTES;

/// What the host reads of embedders' frames, which it has no fence for.
struct External {
    buffer: Buffer,
    /// The mark the next frame writes (never 0, the buffer's first contents).
    next_mark: u32,
    /// The mark each slot's unfinished frame will write.
    pending: [Option<u32>; FRAMES_IN_FLIGHT],
    /// The slot of the frame ended last, until another begins: the embedder may still discard it.
    discardable: Option<usize>,
}

/// A frame being recorded.
pub struct Frame<'a> {
    /// Index of the slot: selects per-frame buffers.
    pub slot: usize,
    pub cmd: vk::CommandBuffer,
    pub timer: &'a mut PassTimer,
}

/// Binary semaphores a submission waits on before the stage given with each, and signals once
/// the stage given with each is done: the caller hands them in (hypermine's `draw.rs`), so a
/// frame renders the same whatever it renders to.
#[derive(Clone, Copy, Debug, Default)]
pub struct Semaphores<'a> {
    pub wait: &'a [(vk::Semaphore, vk::PipelineStageFlags2)],
    pub signal: &'a [(vk::Semaphore, vk::PipelineStageFlags2)],
}

impl Semaphores<'static> {
    /// Neither waits nor signals: offscreen frames ordered by the queue alone.
    pub const NONE: Semaphores<'static> = Semaphores { wait: &[], signal: &[] };
}

fn semaphore_infos(list: &[(vk::Semaphore, vk::PipelineStageFlags2)]) -> Vec<vk::SemaphoreSubmitInfo<'static>> {
    list.iter()
        .map(|&(semaphore, stage)| vk::SemaphoreSubmitInfo::default().semaphore(semaphore).stage_mask(stage))
        .collect()
}

impl FrameRing {
    pub fn new(ctx: &Context) -> Result<Self> {
        let pool_ci = vk::CommandPoolCreateInfo::default()
            .queue_family_index(ctx.queue_family)
            .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER);
        let pool =
            unsafe { ctx.device.create_command_pool(&pool_ci, ctx.host_allocator()) }.vk("vkCreateCommandPool")?;
        let mut ring = FrameRing { pool, slots: Vec::new(), next: 0, gpu_origin: None, external: None };
        if let Err(e) = ring.fill(ctx) {
            ring.destroy(ctx);
            return Err(e);
        }
        Ok(ring)
    }

    fn fill(&mut self, ctx: &Context) -> Result<()> {
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(self.pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(FRAMES_IN_FLIGHT as u32);
        let cmds = unsafe { ctx.device.allocate_command_buffers(&alloc) }.vk("vkAllocateCommandBuffers")?;
        for cmd in cmds {
            // Signalled, so the first wait on each slot returns at once.
            let fence_ci = vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED);
            let fence = unsafe { ctx.device.create_fence(&fence_ci, ctx.host_allocator()) }.vk("vkCreateFence")?;
            let timer = match PassTimer::new(ctx) {
                Ok(t) => t,
                Err(e) => {
                    unsafe { ctx.device.destroy_fence(fence, ctx.host_allocator()) };
                    return Err(e);
                }
            };
            self.slots.push(Slot { cmd, fence, timer });
        }
        Ok(())
    }

    /// Waits for the next slot's previous frame, returns its pass times, and starts recording.
    pub fn begin(&mut self, ctx: &Context) -> Result<(Frame<'_>, Option<Vec<PassTime>>)> {
        if let Some(external) = &mut self.external {
            external.discardable = None;
        }
        let slot = self.next;
        let earlier = self.wait(ctx, slot)?;
        ctx.frame_begun();
        ctx.destroy_finished();
        let s = &mut self.slots[slot];
        // The fence is reset only at submit: a frame abandoned on an error leaves it signalled,
        // so the next frame on this slot does not wait forever.
        unsafe {
            ctx.device.reset_command_buffer(s.cmd, vk::CommandBufferResetFlags::empty()).vk("vkResetCommandBuffer")?;
            let begin = vk::CommandBufferBeginInfo::default().flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            ctx.device.begin_command_buffer(s.cmd, &begin).vk("vkBeginCommandBuffer")?;
        }
        s.timer.reset(ctx, s.cmd);
        Ok((Frame { slot, cmd: s.cmd, timer: &mut s.timer }, earlier))
    }

    /// Begins a frame recorded into the embedder's `cmd`, which the embedder submits. The slot's
    /// previous frame must have finished on the GPU (the embedder waited for it), or this is an
    /// error that says so. Returns the pass times of every earlier frame found finished, oldest
    /// first: the last one's too when the GPU keeps up. Nothing here waits on the GPU: each
    /// embedder's frame ends by copying its timestamps and then a progress mark into host memory
    /// ([`FrameRing::end_external`]), and only those are read.
    pub fn begin_external(&mut self, ctx: &Context, cmd: vk::CommandBuffer) -> Result<(Frame<'_>, Vec<Vec<PassTime>>)> {
        if self.external.is_none() {
            let size = FRAMES_IN_FLIGHT as u64 * SLOT_BYTES;
            let usage = vk::BufferUsageFlags::TRANSFER_DST;
            self.external = Some(External {
                buffer: Buffer::new(ctx, "embedded frame progress", size, usage, MemoryLocation::GpuToCpu)?,
                next_mark: 1,
                pending: [None; FRAMES_IN_FLIGHT],
                discardable: None,
            });
        }
        let external = self.external.as_mut().expect("made above");
        external.discardable = None;
        let slot = self.next;
        let mut done = Vec::new();
        for k in 0..FRAMES_IN_FLIGHT {
            let at = (slot + k) % FRAMES_IN_FLIGHT;
            let s = &mut self.slots[at];
            match external.pending[at] {
                // A frame of our own (an engine that also renders) has its fence; none pending
                // leaves it signalled.
                None if k == 0 => done.extend(FrameRing::collect_own(ctx, s, &mut self.gpu_origin)?),
                None => {}
                Some(mark) => {
                    let bytes = &external.buffer.read()[at * SLOT_BYTES as usize..][..SLOT_BYTES as usize];
                    let written = u32::from_le_bytes(bytes[..4].try_into().expect("four bytes"));
                    if written != mark {
                        if k == 0 {
                            return Err(Error::Invalid(format!(
                                "the frame recorded {FRAMES_IN_FLIGHT} frames ago has not finished on the GPU: \
                                 wait for it (its fence) before recording another, and submit every recorded frame"
                            )));
                        }
                        // A newer frame still running: its times come with a later frame.
                        break;
                    }
                    let raw: Vec<u64> = bytemuck::pod_collect_to_vec(&bytes[8..]);
                    done.extend(s.timer.collect_copied(ctx, &raw, &mut self.gpu_origin));
                    external.pending[at] = None;
                }
            }
        }
        ctx.frame_begun();
        ctx.destroy_finished();
        let s = &mut self.slots[slot];
        s.timer.reset(ctx, cmd);
        Ok((Frame { slot, cmd, timer: &mut s.timer }, done))
    }

    fn collect_own(ctx: &Context, s: &mut Slot, origin: &mut Option<u64>) -> Result<Option<Vec<PassTime>>> {
        unsafe { ctx.device.wait_for_fences(&[s.fence], true, u64::MAX) }.vk("vkWaitForFences")?;
        s.timer.collect(ctx, origin)
    }

    /// Ends the embedder's frame begun last: records, after all of the frame's work, the copy of
    /// its timestamps and then its progress mark for the host.
    pub fn end_external(&mut self, ctx: &Context, slot: usize, cmd: vk::CommandBuffer) {
        let external = self.external.as_mut().expect("begun with begin_external");
        let timer = &mut self.slots[slot].timer;
        let offset = slot as u64 * SLOT_BYTES;
        let mark = external.next_mark;
        external.next_mark = external.next_mark.wrapping_add(1).max(1);
        timer.copy_results(ctx, cmd, external.buffer.buffer, offset + 8);
        // The mark lands only after the timestamps' copy, and the host reads both after the mark.
        buffer_barrier(ctx, cmd, BufferAccess::TRANSFER_WRITE, BufferAccess::TRANSFER_WRITE);
        unsafe { ctx.device.cmd_fill_buffer(cmd, external.buffer.buffer, offset, 4, mark) };
        buffer_barrier(ctx, cmd, BufferAccess::TRANSFER_WRITE, BufferAccess::HOST_READ);
        timer.submitted();
        external.pending[slot] = Some(mark);
        external.discardable = Some(slot);
        self.next = (slot + 1) % FRAMES_IN_FLIGHT;
        ctx.frame_recorded();
    }

    /// Forgets the embedder's frame ended last, which the embedder will never submit: its slot
    /// is free again, it will write no timestamps, and it no longer counts as recorded (so what
    /// it uploaded counts as never uploaded). Only before another frame begins.
    pub fn discard_external(&mut self, ctx: &Context) -> Result<()> {
        let external = self.external.as_mut().filter(|e| e.discardable.is_some()).ok_or_else(|| {
            Error::Invalid("no frame to discard: only the frame recorded last can be, before another begins".into())
        })?;
        let slot = external.discardable.take().expect("checked");
        external.pending[slot] = None;
        self.slots[slot].timer.discarded();
        self.next = slot;
        ctx.frame_discarded();
        Ok(())
    }

    /// Ends and submits the frame begun last, waiting on and signalling `semaphores`.
    pub fn submit(&mut self, ctx: &Context, slot: usize, semaphores: &Semaphores) -> Result<()> {
        let s = &mut self.slots[slot];
        let (wait, signal) = (semaphore_infos(semaphores.wait), semaphore_infos(semaphores.signal));
        unsafe {
            ctx.device.end_command_buffer(s.cmd).vk("vkEndCommandBuffer")?;
            ctx.device.reset_fences(&[s.fence]).vk("vkResetFences")?;
            let cmds = [vk::CommandBufferSubmitInfo::default().command_buffer(s.cmd)];
            let submit = [vk::SubmitInfo2::default()
                .wait_semaphore_infos(&wait)
                .command_buffer_infos(&cmds)
                .signal_semaphore_infos(&signal)];
            ctx.device.queue_submit2(ctx.queue, &submit, s.fence).vk("vkQueueSubmit2")?;
        }
        s.timer.submitted();
        self.next = (slot + 1) % FRAMES_IN_FLIGHT;
        ctx.frame_recorded();
        Ok(())
    }

    /// Waits for slot `slot`'s frame to finish and returns its pass times (once).
    pub fn wait(&mut self, ctx: &Context, slot: usize) -> Result<Option<Vec<PassTime>>> {
        self.wait_ticking(ctx, slot, &mut || {})
    }

    /// [`FrameRing::wait`], calling `tick` every tenth of a second while the frame runs.
    fn wait_ticking(&mut self, ctx: &Context, slot: usize, tick: &mut dyn FnMut()) -> Result<Option<Vec<PassTime>>> {
        let s = &mut self.slots[slot];
        const TICK_NS: u64 = 100_000_000;
        while unsafe { ctx.device.wait_for_fences(&[s.fence], true, TICK_NS) } == Err(vk::Result::TIMEOUT) {
            tick();
        }
        unsafe { ctx.device.wait_for_fences(&[s.fence], true, 0) }.vk("vkWaitForFences")?;
        s.timer.collect(ctx, &mut self.gpu_origin)
    }

    /// Waits for every frame in flight; returns their pass times, oldest first.
    pub fn drain(&mut self, ctx: &Context) -> Result<Vec<Vec<PassTime>>> {
        self.drain_ticking(ctx, &mut || {})
    }

    /// [`FrameRing::drain`], calling `tick` every tenth of a second while a frame runs.
    pub fn drain_ticking(&mut self, ctx: &Context, tick: &mut dyn FnMut()) -> Result<Vec<Vec<PassTime>>> {
        let mut out = Vec::new();
        for k in 0..FRAMES_IN_FLIGHT {
            let slot = (self.next + k) % FRAMES_IN_FLIGHT;
            out.extend(self.wait_ticking(ctx, slot, tick)?);
        }
        Ok(out)
    }

    pub fn destroy(self, ctx: &Context) {
        if let Some(external) = self.external {
            external.buffer.destroy(ctx);
        }
        for s in self.slots {
            unsafe { ctx.device.destroy_fence(s.fence, ctx.host_allocator()) };
            s.timer.destroy(ctx);
        }
        unsafe { ctx.device.destroy_command_pool(self.pool, ctx.host_allocator()) };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::ContextOptions;

    /// A frame abandoned between `begin` and `submit` (an error while recording) must not block
    /// the next frame on its slot, nor report timings for queries it never wrote.
    #[test]
    fn an_abandoned_frame_does_not_block_the_next() {
        let ctx = Context::headless(&ContextOptions { validation: true, device: None }).unwrap();
        let mut ring = FrameRing::new(&ctx).unwrap();
        for _ in 0..FRAMES_IN_FLIGHT + 1 {
            let (frame, earlier) = ring.begin(&ctx).unwrap();
            assert!(earlier.is_none());
            let _ = frame; // dropped without submitting, as on an error
        }
        let (frame, _) = ring.begin(&ctx).unwrap();
        let slot = frame.slot;
        frame.timer.begin(&ctx, frame.cmd, "work");
        frame.timer.end(&ctx, frame.cmd);
        ring.submit(&ctx, slot, &Semaphores::NONE).unwrap();
        let timings = ring.wait(&ctx, slot).unwrap().expect("the submitted frame has timings");
        assert_eq!(timings[0].name, "work");
        ring.destroy(&ctx);
        let errors = ctx.validation_errors();
        assert!(errors.is_empty(), "{errors:?}");
    }
}
