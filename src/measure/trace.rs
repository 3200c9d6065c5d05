//! Timing captures as Chrome trace events (the JSON Object Format that chrome://tracing and
//! Perfetto open): each frame's GPU passes as slices on a GPU track, and the CPU work that
//! made them (waiting for a slot, the draw list, recording each pass, submitting) on a CPU
//! track, nested under a slice per frame and, in `bench`, a slice per setting.
//!
//! The GPU clock and the host clock have different origins. One offset maps every GPU
//! timestamp onto the host's clock: the smallest that puts no frame's first pass before its
//! submission. A GPU may start a pass's top-of-pipe before the previous pass drains; such
//! overlaps are trimmed so that the GPU track's slices never overlap.

use std::path::Path;
use std::time::Instant;

use serde_json::{Value, json};

use crate::error::{Error, Result};
use crate::renderer::FrameTimings;

const PID: u32 = 1;
const CPU_TID: u32 = 1;
const GPU_TID: u32 = 2;

/// One frame's GPU passes, kept raw until the clock offset is known.
struct GpuFrame {
    frame: u64,
    submitted_ms: f64,
    passes: Vec<(&'static str, f64, f64)>,
    args: Value,
}

/// Trace events gathered over a run, written by [`Trace::write`].
pub struct Trace {
    origin: Instant,
    device: String,
    cpu: Vec<Value>,
    gpu: Vec<GpuFrame>,
    frames: u64,
}

impl Trace {
    /// An empty trace whose time 0 is now; `device` names the GPU track.
    pub fn new(device: &str) -> Self {
        Trace { origin: Instant::now(), device: device.to_string(), cpu: Vec::new(), gpu: Vec::new(), frames: 0 }
    }

    fn ms(&self, t: Instant) -> f64 {
        t.saturating_duration_since(self.origin).as_secs_f64() * 1e3
    }

    /// A slice on the CPU track from `start` to `end`; slices added within it nest under it.
    pub fn cpu_slice(&mut self, name: &str, start: Instant, end: Instant, args: Value) {
        let (start, end) = (self.ms(start), self.ms(end));
        self.cpu.push(slice(name, "cpu", CPU_TID, start, end - start, args));
    }

    /// Finished frames: a `frame N` slice over each frame's CPU spans, and its GPU passes.
    /// `args` (technique, scene, setting…) are attached to every slice.
    pub fn add_frames(&mut self, frames: &[FrameTimings], args: &Value) {
        for f in frames {
            let frame = self.frames;
            self.frames += 1;
            let mut frame_args = args.clone();
            frame_args["frame"] = json!(frame);
            if let (Some(first), Some(last)) = (f.cpu.first(), f.cpu.last()) {
                let start = self.ms(first.start);
                let end = self.ms(last.start) + last.ms;
                self.cpu.push(slice(&format!("frame {frame}"), "cpu", CPU_TID, start, end - start, frame_args.clone()));
                for s in &f.cpu {
                    self.cpu.push(slice(s.name, "cpu", CPU_TID, self.ms(s.start), s.ms, frame_args.clone()));
                }
            }
            if let Some(submitted) = f.submitted() {
                self.gpu.push(GpuFrame {
                    frame,
                    submitted_ms: self.ms(submitted),
                    passes: f.passes.iter().map(|p| (p.name, p.begin_ms, p.ms)).collect(),
                    args: frame_args,
                });
            }
        }
    }

    /// The trace as a Chrome trace JSON object.
    pub fn to_json(&self) -> Value {
        let offset = self
            .gpu
            .iter()
            .filter_map(|f| f.passes.iter().map(|p| p.1).reduce(f64::min).map(|begin| f.submitted_ms - begin))
            .reduce(f64::max)
            .unwrap_or(0.0);
        let mut passes: Vec<(f64, f64, &str, &GpuFrame)> = self
            .gpu
            .iter()
            .flat_map(|f| f.passes.iter().map(move |&(name, begin, ms)| (begin + offset, ms, name, f)))
            .collect();
        passes.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut gpu = Vec::with_capacity(passes.len());
        let mut free_from = f64::NEG_INFINITY;
        for (start, ms, name, f) in passes {
            let begin = start.max(free_from);
            let end = (start + ms).max(begin);
            free_from = end;
            let mut args = f.args.clone();
            args["gpu_ms"] = json!(ms);
            args["frame"] = json!(f.frame);
            gpu.push(slice(name, "gpu", GPU_TID, begin, end - begin, args));
        }
        let meta =
            |name: &str, tid: u32, args: Value| json!({"name": name, "ph": "M", "pid": PID, "tid": tid, "args": args});
        let mut events = vec![
            meta("process_name", CPU_TID, json!({"name": "softshadow"})),
            meta("thread_name", CPU_TID, json!({"name": "CPU"})),
            meta("thread_sort_index", CPU_TID, json!({"sort_index": 0})),
            meta("thread_name", GPU_TID, json!({"name": format!("GPU: {}", self.device)})),
            meta("thread_sort_index", GPU_TID, json!({"sort_index": 1})),
        ];
        events.extend(self.cpu.iter().cloned());
        events.extend(gpu);
        json!({"traceEvents": events, "displayTimeUnit": "ms"})
    }

    pub fn write(&self, path: &Path) -> Result<()> {
        let text = self.to_json().to_string();
        std::fs::write(path, text).map_err(|error| Error::Io { path: path.into(), error })
    }
}

/// A complete event ("ph": "X"); the format counts in microseconds.
fn slice(name: &str, cat: &str, tid: u32, start_ms: f64, ms: f64, args: Value) -> Value {
    json!({"name": name, "cat": cat, "ph": "X", "pid": PID, "tid": tid, "ts": start_ms * 1e3, "dur": ms * 1e3, "args": args})
}

#[cfg(test)]
mod tests {
    use std::time::{Duration, Instant};

    use serde_json::json;

    use super::Trace;
    use crate::gpu::PassTime;
    use crate::renderer::{CpuSpan, FrameTimings, SUBMIT, WAIT_FOR_SLOT};

    fn frame(at: Instant, gpu_begin_ms: f64) -> FrameTimings {
        let span =
            |name, offset_ms: f64, ms| CpuSpan { name, start: at + Duration::from_secs_f64(offset_ms * 1e-3), ms };
        let pass = |name, begin_ms, ms| PassTime { name, begin_ms, ms };
        FrameTimings {
            // The second pass starts before the first ends, as a GPU may report.
            passes: vec![
                pass("prepass", gpu_begin_ms, 2.0),
                pass("resolve", gpu_begin_ms + 1.5, 2.0),
                pass("composite", gpu_begin_ms + 3.5, 1.0),
            ],
            cpu: vec![span(WAIT_FOR_SLOT, 0.0, 0.5), span("technique", 0.5, 1.0), span(SUBMIT, 1.5, 0.5)],
        }
    }

    #[test]
    fn gpu_slices_follow_submission_and_never_overlap() {
        let mut trace = Trace::new("test device");
        let t0 = trace.origin + Duration::from_millis(10);
        // GPU clock origin far from the host's: 5000 ms.
        let frames = [frame(t0, 5000.0), frame(t0 + Duration::from_millis(3), 5005.0)];
        trace.add_frames(&frames, &json!({"technique": "pcf"}));
        let json = trace.to_json();
        let events = json["traceEvents"].as_array().unwrap();
        let slices = |tid: u64| -> Vec<(f64, f64, String)> {
            events
                .iter()
                .filter(|e| e["ph"] == "X" && e["tid"] == tid)
                .map(|e| (e["ts"].as_f64().unwrap(), e["dur"].as_f64().unwrap(), e["name"].as_str().unwrap().into()))
                .collect()
        };
        let gpu = slices(2);
        assert_eq!(gpu.len(), 6);
        for w in gpu.windows(2) {
            assert!(w[1].0 >= w[0].0 + w[0].1 - 1e-6, "GPU slices overlap: {w:?}");
        }
        // Frame 0 is submitted at 12 ms, frame 1 at 15 ms with its GPU work 5 ms after frame
        // 0's: the smallest offset that keeps both after their submissions puts frame 0's first
        // pass at its submission and frame 1's at 17 ms.
        assert!((gpu[0].0 - 12_000.0).abs() < 1e-3, "frame 0 starts at {} us", gpu[0].0);
        assert!((gpu[3].0 - 17_000.0).abs() < 1e-3, "frame 1 starts at {} us", gpu[3].0);
        // The overlapping pass is trimmed to start where the previous one ends.
        assert_eq!(gpu[1].2, "resolve");
        assert!((gpu[1].0 - 14_000.0).abs() < 1e-3 && (gpu[1].1 - 1_500.0).abs() < 1e-3, "{:?}", gpu[1]);
        let cpu = slices(1);
        assert_eq!(cpu.iter().filter(|s| s.2.starts_with("frame ")).count(), 2);
        assert!(cpu.iter().any(|s| s.2 == "technique"));
        assert!(events.iter().any(|e| e["name"] == "thread_name" && e["args"]["name"] == "GPU: test device"));
    }
}
