//! Measurement: GPU timing reports (and, later, error metrics against the reference).

mod timings;

pub use timings::{PassSummary, TimingReport};
