//! Measurement: GPU timing reports, error metrics against the reference, the speed/accuracy
//! sweep and its plot, and timing traces.

pub mod bench;
mod metrics;
mod plot;
mod timings;
mod trace;

pub use metrics::{GROSS_ERROR, Metrics, PENUMBRA, save_difference};
pub use plot::tradeoff;
pub use timings::{PassSummary, TimingReport};
pub use trace::Trace;
