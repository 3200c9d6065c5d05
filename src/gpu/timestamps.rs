//! Named GPU timestamps: each pass writes a begin and an end query; results are read when the
//! frame's fence has signalled (one frame late, as hypermine's `draw.rs` does), converted with
//! `timestampPeriod` and masked to the queue's valid bits.

use ash::vk;

use super::Context;
use crate::error::{Result, VkContext};

/// Passes a frame may time.
const MAX_PASSES: u32 = 32;

/// Bytes of one frame's timestamps as [`PassTimer::copy_results`] copies them.
pub const RESULT_BYTES: u64 = MAX_PASSES as u64 * 2 * 8;

/// The GPU time of one pass in one frame.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTime {
    pub name: &'static str,
    /// When the pass began on the GPU's clock, since the first pass its frame ring timed (only
    /// differences mean anything).
    pub begin_ms: f64,
    pub ms: f64,
}

/// One frame's query pool and the pass names written into it.
pub struct PassTimer {
    pool: vk::QueryPool,
    names: Vec<&'static str>,
    open: bool,
    recorded: bool,
}

impl PassTimer {
    pub fn new(ctx: &Context) -> Result<Self> {
        let ci = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(MAX_PASSES * 2);
        let pool = unsafe { ctx.device.create_query_pool(&ci, ctx.host_allocator()) }.vk("vkCreateQueryPool")?;
        ctx.name(pool, "pass timestamps");
        Ok(PassTimer { pool, names: Vec::new(), open: false, recorded: false })
    }

    /// Starts a frame's recording: queries must be reset before they are written again.
    pub fn reset(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        unsafe { ctx.device.cmd_reset_query_pool(cmd, self.pool, 0, MAX_PASSES * 2) };
        self.names.clear();
        self.recorded = false;
    }

    /// The frame was submitted: its queries will be written and can be collected.
    pub fn submitted(&mut self) {
        self.recorded = true;
    }

    /// The frame [`PassTimer::submitted`] said was submitted never will be: nothing to collect.
    pub fn discarded(&mut self) {
        self.recorded = false;
    }

    /// Opens pass `name`: a timestamp and a debug label of the same name.
    pub fn begin(&mut self, ctx: &Context, cmd: vk::CommandBuffer, name: &'static str) {
        assert!(!self.open, "pass {name} opened inside another");
        assert!((self.names.len() as u32) < MAX_PASSES, "more than {MAX_PASSES} passes in a frame");
        let index = self.names.len() as u32 * 2;
        self.names.push(name);
        self.open = true;
        if let Some(du) = &ctx.debug_utils {
            let label = std::ffi::CString::new(name).unwrap_or_default();
            unsafe { du.cmd_begin_debug_utils_label(cmd, &vk::DebugUtilsLabelEXT::default().label_name(&label)) };
        }
        unsafe { ctx.device.cmd_write_timestamp2(cmd, vk::PipelineStageFlags2::TOP_OF_PIPE, self.pool, index) };
    }

    /// Closes the open pass once all its work has finished.
    pub fn end(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        assert!(self.open, "no pass is open");
        self.open = false;
        let index = self.names.len() as u32 * 2 - 1;
        unsafe { ctx.device.cmd_write_timestamp2(cmd, vk::PipelineStageFlags2::BOTTOM_OF_PIPE, self.pool, index) };
        if let Some(du) = &ctx.debug_utils {
            unsafe { du.cmd_end_debug_utils_label(cmd) };
        }
    }

    /// The submitted frame's pass times, once its queries are written (after its fence signalled,
    /// or an embedder's frame that finished); `None` when no
    /// frame was submitted since the last call. `origin` is the raw timestamp that begin times
    /// count from, set by the first call: raw values can be so large (on an H100's driver) that
    /// an f64 of milliseconds since the counter's own zero blurs them by tenths of a microsecond.
    pub fn collect(&mut self, ctx: &Context, origin: &mut Option<u64>) -> Result<Option<Vec<PassTime>>> {
        if !self.recorded || self.names.is_empty() {
            self.recorded = false;
            return Ok(None);
        }
        let mut raw = vec![0u64; self.names.len() * 2];
        unsafe { ctx.device.get_query_pool_results(self.pool, 0, &mut raw, vk::QueryResultFlags::TYPE_64) }
            .vk("vkGetQueryPoolResults")?;
        Ok(self.collect_copied(ctx, &raw, origin))
    }

    /// Records a copy of the frame's timestamps into `dst` at `offset` ([`RESULT_BYTES`] of
    /// room), made on the GPU once they are written: for frames whose queries the host must not
    /// poll (some drivers, lavapipe among them, wait for the queue in vkGetQueryPoolResults).
    pub fn copy_results(&self, ctx: &Context, cmd: vk::CommandBuffer, dst: vk::Buffer, offset: u64) {
        let count = self.names.len() as u32 * 2;
        if count > 0 {
            let flags = vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WAIT;
            unsafe { ctx.device.cmd_copy_query_pool_results(cmd, self.pool, 0, count, dst, offset, 8, flags) };
        }
    }

    /// The submitted frame's pass times from `raw` timestamps (as [`PassTimer::copy_results`]
    /// copied them, once that copy finished); `None` when no frame was submitted since.
    pub fn collect_copied(&mut self, ctx: &Context, raw: &[u64], origin: &mut Option<u64>) -> Option<Vec<PassTime>> {
        if !std::mem::replace(&mut self.recorded, false) || self.names.is_empty() {
            return None;
        }
        let bits = ctx.info.timestamp_valid_bits;
        let mask = if bits >= 64 { u64::MAX } else { (1u64 << bits) - 1 };
        let ms = ctx.info.timestamp_period_ns as f64 * 1e-6;
        let origin = *origin.get_or_insert(raw[0] & mask);
        Some(
            self.names
                .iter()
                .zip(raw.chunks_exact(2))
                .map(|(&name, t)| PassTime {
                    name,
                    begin_ms: ticks_since(t[0], origin, mask) * ms,
                    ms: ticks_since(t[1], t[0], mask) * ms,
                })
                .collect(),
        )
    }

    pub fn destroy(self, ctx: &Context) {
        unsafe { ctx.device.destroy_query_pool(self.pool, ctx.host_allocator()) };
    }
}

/// Ticks from `origin` to `t` on a counter of `mask`'s valid bits that wraps around; a
/// difference of half the range or more means `t` came first.
fn ticks_since(t: u64, origin: u64, mask: u64) -> f64 {
    let ahead = t.wrapping_sub(origin) & mask;
    if ahead > mask / 2 { -((origin.wrapping_sub(t) & mask) as f64) } else { ahead as f64 }
}

/// Milestones of one long frame (a batch done, a batch done, ...): timestamps written as the
/// GPU gets through the work and polled without waiting, so the host can tell how far along a
/// frame of many seconds is.
pub struct Milestones {
    pool: vk::QueryPool,
    capacity: u32,
    written: u32,
}

impl Milestones {
    pub fn new(ctx: &Context, capacity: u32) -> Result<Self> {
        let ci = vk::QueryPoolCreateInfo::default().query_type(vk::QueryType::TIMESTAMP).query_count(capacity);
        let pool = unsafe { ctx.device.create_query_pool(&ci, ctx.host_allocator()) }.vk("vkCreateQueryPool")?;
        ctx.name(pool, "milestones");
        Ok(Milestones { pool, capacity, written: 0 })
    }

    pub fn capacity(&self) -> u32 {
        self.capacity
    }

    /// Starts a frame's recording.
    pub fn reset(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        unsafe { ctx.device.cmd_reset_query_pool(cmd, self.pool, 0, self.capacity) };
        self.written = 0;
    }

    /// Records a milestone, reached when all earlier work is done. Beyond capacity: ignored.
    pub fn mark(&mut self, ctx: &Context, cmd: vk::CommandBuffer) {
        if self.written < self.capacity {
            unsafe {
                ctx.device.cmd_write_timestamp2(cmd, vk::PipelineStageFlags2::ALL_COMMANDS, self.pool, self.written)
            };
            self.written += 1;
        }
    }

    /// Milestones reached so far, and how many were recorded.
    pub fn reached(&self, ctx: &Context) -> (u32, u32) {
        if self.written == 0 {
            return (0, 0);
        }
        let mut results = vec![[0u64; 2]; self.written as usize];
        let flags = vk::QueryResultFlags::TYPE_64 | vk::QueryResultFlags::WITH_AVAILABILITY;
        // NOT_READY just means some are still pending: their availability words say which.
        let _ = unsafe { ctx.device.get_query_pool_results(self.pool, 0, &mut results, flags) };
        (results.iter().take_while(|r| r[1] != 0).count() as u32, self.written)
    }

    pub fn destroy(self, ctx: &Context) {
        unsafe { ctx.device.destroy_query_pool(self.pool, ctx.host_allocator()) };
    }
}

#[cfg(test)]
mod tests {
    use super::ticks_since;

    #[test]
    fn ticks_keep_nanoseconds_at_any_clock_origin_and_across_wraparound() {
        // A nanosecond counter read about 57 years after its zero.
        let now = 1_795_000_000_123_456_789u64;
        assert_eq!(ticks_since(now + 7, now, u64::MAX), 7.0);
        assert_eq!(ticks_since(now, now + 7, u64::MAX), -7.0);
        // A 36-bit counter that wrapped between the two reads.
        let mask = (1u64 << 36) - 1;
        assert_eq!(ticks_since(3, mask - 4, mask), 8.0);
        assert_eq!(ticks_since(mask - 4, 3, mask), -8.0);
    }
}
