//! Measurement: GPU timing reports, error metrics against the reference, the speed/accuracy
//! sweep and its plot, the default run's contact sheet, and timing traces.

pub mod bench;
pub mod curve;
pub mod extremes;
mod metrics;
mod plot;
mod sheet;
mod timings;
mod trace;

pub use metrics::{GROSS_ERROR, Metrics, PENUMBRA, save_difference};
pub use plot::{lines, tradeoff};
pub use sheet::{Tile, contact_sheet};
pub use timings::{PassSummary, TimingReport, total_median};
pub use trace::{FileTrace, Trace};
