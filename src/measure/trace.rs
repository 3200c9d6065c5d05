//! Timing captures as Chrome trace events (the JSON Object Format that chrome://tracing and
//! Perfetto open): each frame's GPU passes as slices on a GPU track, and the CPU work that
//! made them (waiting for a slot, the draw list, recording each pass, submitting) on a CPU
//! track, nested under a slice per frame and, in `bench`, a slice per setting.
//!
//! The GPU clock and the host clock have different origins. One offset maps every GPU
//! timestamp onto the host's clock: the smallest that puts no frame's first pass before its
//! submission. A GPU may start a pass's top-of-pipe before the previous pass drains; such
//! overlaps are trimmed so that the GPU track's slices never overlap.
//!
//! CPU events are written to the file as frames finish; only a few numbers per GPU pass stay
//! in memory until the end, so a trace of a long run does not grow the process by its size.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::Instant;

use serde_json::{Value, json};

use crate::error::{Error, Result};
use crate::renderer::FrameTimings;

const PID: u32 = 1;
const CPU_TID: u32 = 1;
const GPU_TID: u32 = 2;

/// One GPU pass, kept as numbers until the clock offset is known (its labels are shared).
struct GpuPass {
    frame: u64,
    label: usize,
    name: &'static str,
    begin_ms: f64,
    ms: f64,
}

/// A trace being written: CPU events stream to the output as they come; GPU passes wait, a
/// few numbers each, for [`Trace::finish`], since the clock offset depends on every frame.
pub struct Trace<W: Write> {
    origin: Instant,
    device: String,
    out: W,
    /// Where `out` goes, for messages.
    path: PathBuf,
    /// The first write that failed: reported by `finish`.
    failed: Option<std::io::Error>,
    gpu: Vec<GpuPass>,
    /// Distinct labels of the GPU passes, the newest last.
    labels: Vec<Value>,
    /// The smallest shift of the GPU clock that puts no frame's first pass before its
    /// submission, over the frames so far.
    offset_ms: Option<f64>,
    frames: u64,
}

/// A trace streamed to a file.
pub type FileTrace = Trace<BufWriter<File>>;

impl FileTrace {
    /// A trace written to `path` (created now, so a bad path fails before a long run);
    /// time 0 is now and `device` names the GPU track.
    pub fn create(device: &str, path: &Path) -> Result<Self> {
        let file = File::create(path).map_err(|error| Error::Io { path: path.into(), error })?;
        Ok(Trace::new(device, BufWriter::new(file), path))
    }
}

impl<W: Write> Trace<W> {
    /// A trace written to `out`; `path` names it in messages.
    pub fn new(device: &str, out: W, path: &Path) -> Self {
        let mut trace = Trace {
            origin: Instant::now(),
            device: device.to_string(),
            out,
            path: path.into(),
            failed: None,
            gpu: Vec::new(),
            labels: Vec::new(),
            offset_ms: None,
            frames: 0,
        };
        trace.emit_raw("{\"displayTimeUnit\":\"ms\",\"traceEvents\":[");
        let meta =
            |name: &str, tid: u32, args: Value| json!({"name": name, "ph": "M", "pid": PID, "tid": tid, "args": args});
        let gpu_name = format!("GPU: {}", trace.device);
        for (i, event) in [
            meta("process_name", CPU_TID, json!({"name": "softshadow"})),
            meta("thread_name", CPU_TID, json!({"name": "CPU"})),
            meta("thread_sort_index", CPU_TID, json!({"sort_index": 0})),
            meta("thread_name", GPU_TID, json!({"name": gpu_name})),
            meta("thread_sort_index", GPU_TID, json!({"sort_index": 1})),
        ]
        .iter()
        .enumerate()
        {
            trace.emit_raw(if i == 0 { "" } else { "," });
            trace.emit_raw(&event.to_string());
        }
        trace
    }

    fn ms(&self, t: Instant) -> f64 {
        t.saturating_duration_since(self.origin).as_secs_f64() * 1e3
    }

    fn emit_raw(&mut self, text: &str) {
        if self.failed.is_none()
            && let Err(e) = self.out.write_all(text.as_bytes())
        {
            self.failed = Some(e);
        }
    }

    fn emit(&mut self, event: Value) {
        self.emit_raw(",");
        self.emit_raw(&event.to_string());
    }

    /// A slice on the CPU track from `start` to `end`; slices added within it nest under it.
    pub fn cpu_slice(&mut self, name: &str, start: Instant, end: Instant, args: Value) {
        let (start, end) = (self.ms(start), self.ms(end));
        self.emit(slice(name, "cpu", CPU_TID, start, end - start, args));
    }

    /// Finished frames: a `frame N` slice over each frame's CPU spans, and its GPU passes.
    /// `args` (technique, scene, setting…) are attached to every slice.
    pub fn add_frames(&mut self, frames: &[FrameTimings], args: &Value) {
        if self.labels.last() != Some(args) {
            self.labels.push(args.clone());
        }
        let label = self.labels.len() - 1;
        for f in frames {
            let frame = self.frames;
            self.frames += 1;
            let mut frame_args = args.clone();
            frame_args["frame"] = json!(frame);
            if let (Some(first), Some(last)) = (f.cpu.first(), f.cpu.last()) {
                let start = self.ms(first.start);
                let end = self.ms(last.start) + last.ms;
                self.emit(slice(&format!("frame {frame}"), "cpu", CPU_TID, start, end - start, frame_args.clone()));
                for s in &f.cpu {
                    let event = slice(s.name, "cpu", CPU_TID, self.ms(s.start), s.ms, frame_args.clone());
                    self.emit(event);
                }
            }
            let first_begin = f.passes.iter().map(|p| p.begin_ms).reduce(f64::min);
            if let (Some(submitted), Some(begin)) = (f.submitted(), first_begin) {
                let shift = self.ms(submitted) - begin;
                self.offset_ms = Some(self.offset_ms.map_or(shift, |o| o.max(shift)));
                let passes =
                    f.passes.iter().map(|p| GpuPass { frame, label, name: p.name, begin_ms: p.begin_ms, ms: p.ms });
                self.gpu.extend(passes);
            }
        }
    }

    /// Writes the GPU track, placed on the host's clock and trimmed so that no two slices
    /// overlap, closes the trace and returns the output.
    pub fn finish(mut self) -> Result<W> {
        let offset = self.offset_ms.unwrap_or(0.0);
        let mut passes = std::mem::take(&mut self.gpu);
        passes.sort_by(|a, b| a.begin_ms.total_cmp(&b.begin_ms));
        let mut free_from = f64::NEG_INFINITY;
        for p in passes {
            let start = p.begin_ms + offset;
            let begin = start.max(free_from);
            let end = (start + p.ms).max(begin);
            free_from = end;
            let mut args = self.labels[p.label].clone();
            args["gpu_ms"] = json!(p.ms);
            args["frame"] = json!(p.frame);
            self.emit(slice(p.name, "gpu", GPU_TID, begin, end - begin, args));
        }
        self.emit_raw("]}");
        if self.failed.is_none()
            && let Err(e) = self.out.flush()
        {
            self.failed = Some(e);
        }
        match self.failed.take() {
            Some(error) => Err(Error::Io { path: self.path.clone(), error }),
            None => Ok(self.out),
        }
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
        let mut trace = Trace::new("test device", Vec::new(), "memory".as_ref());
        let t0 = trace.origin + Duration::from_millis(10);
        // GPU clock origin far from the host's: 5000 ms.
        let frames = [frame(t0, 5000.0), frame(t0 + Duration::from_millis(3), 5005.0)];
        trace.add_frames(&frames, &json!({"technique": "pcf"}));
        let json: serde_json::Value = serde_json::from_slice(&trace.finish().unwrap()).unwrap();
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
