//! The timings JSON of DESIGN.md §3: per pass the median and 95th percentile of GPU ms over the
//! measured frames (after warm-up), the median total, and CPU ms.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::renderer::FrameTimings;

/// One pass's GPU time over the measured frames.
#[derive(Clone, Debug, Serialize)]
pub struct PassSummary {
    pub name: String,
    pub gpu_ms_median: f64,
    pub gpu_ms_p95: f64,
}

/// What `--timings FILE` writes.
#[derive(Clone, Debug, Default, Serialize)]
pub struct TimingReport {
    pub device: String,
    pub driver: String,
    pub technique: String,
    pub width: u32,
    pub height: u32,
    pub frames: usize,
    pub passes: Vec<PassSummary>,
    pub gpu_ms_total_median: f64,
    /// Beyond DESIGN.md's contract: the 95th percentile of the per-frame totals.
    pub gpu_ms_total_p95: f64,
    /// Medians: `record` (recording to submission) and each CPU span of
    /// [`FrameTimings::cpu`](crate::renderer::FrameTimings::cpu), `technique` being the
    /// technique's per-frame geometry and recording.
    pub cpu_ms: BTreeMap<String, f64>,
}

impl TimingReport {
    /// Summarises `frames` (warm-up already dropped); passes keep their recording order.
    pub fn new(
        device: &crate::gpu::DeviceInfo,
        technique: &str,
        width: u32,
        height: u32,
        frames: &[FrameTimings],
    ) -> Self {
        let mut names: Vec<&'static str> = Vec::new();
        for f in frames {
            for p in &f.passes {
                if !names.contains(&p.name) {
                    names.push(p.name);
                }
            }
        }
        let passes = names
            .iter()
            .map(|&name| {
                let ms: Vec<f64> =
                    frames.iter().flat_map(|f| f.passes.iter().filter(|p| p.name == name).map(|p| p.ms)).collect();
                PassSummary {
                    name: name.to_string(),
                    gpu_ms_median: percentile(&ms, 0.5),
                    gpu_ms_p95: percentile(&ms, 0.95),
                }
            })
            .collect();
        let totals = frame_totals(frames);
        let record: Vec<f64> = frames.iter().map(FrameTimings::cpu_record_ms).collect();
        let mut cpu_ms = BTreeMap::from([("record".to_string(), percentile(&record, 0.5))]);
        let mut span_names: Vec<&'static str> = frames.iter().flat_map(|f| f.cpu.iter().map(|s| s.name)).collect();
        span_names.sort_unstable();
        span_names.dedup();
        for name in span_names {
            let ms: Vec<f64> =
                frames.iter().flat_map(|f| f.cpu.iter().filter(|s| s.name == name).map(|s| s.ms)).collect();
            cpu_ms.insert(name.to_string(), percentile(&ms, 0.5));
        }
        TimingReport {
            device: device.name.clone(),
            driver: device.driver.clone(),
            technique: technique.to_string(),
            width,
            height,
            frames: frames.len(),
            passes,
            gpu_ms_total_median: percentile(&totals, 0.5),
            gpu_ms_total_p95: percentile(&totals, 0.95),
            cpu_ms,
        }
    }
}

/// Each frame's GPU ms, its passes summed.
fn frame_totals(frames: &[FrameTimings]) -> Vec<f64> {
    frames.iter().map(|f| f.passes.iter().map(|p| p.ms).sum()).collect()
}

/// The median of `frames`' GPU ms, as [`TimingReport::gpu_ms_total_median`] takes it.
pub fn total_median(frames: &[FrameTimings]) -> f64 {
    percentile(&frame_totals(frames), 0.5)
}

/// Nearest-rank percentile; 0 for no samples.
pub(crate) fn percentile(values: &[f64], q: f64) -> f64 {
    if values.is_empty() {
        return 0.0;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    let rank = ((q * v.len() as f64).ceil() as usize).clamp(1, v.len());
    v[rank - 1]
}

#[cfg(test)]
mod tests {
    use super::percentile;

    #[test]
    fn percentiles_by_nearest_rank() {
        let v: Vec<f64> = (1..=20).map(f64::from).collect();
        assert_eq!(percentile(&v, 0.5), 10.0);
        assert_eq!(percentile(&v, 0.95), 19.0);
        assert_eq!(percentile(&[3.0], 0.95), 3.0);
        assert_eq!(percentile(&[], 0.5), 0.0);
    }
}
