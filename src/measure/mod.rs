//! Measurement: GPU timing reports and error metrics against the reference.

mod metrics;
mod timings;

pub use metrics::{GROSS_ERROR, Metrics, PENUMBRA, save_difference};
pub use timings::{PassSummary, TimingReport};
