//! Host-side simulator for `drive-monitor`: scene files, dynamics assembled from the effects a
//! scene calls for, synthetic encoder edges, and reports computed by the same core code that
//! runs on the target.
//!
//! Three parts, one folder each:
//!
//! - [`engine`]: the simulation itself — integrators, the system assembled from effects, the
//!   drive, the vibration machine, the rotor's support loads and the encoder's edges. It knows
//!   nothing of scene files or the command line.
//! - [`app`]: the `drive-sim` application — scene files, a run, design-time prediction, the
//!   report and its plots.
//! - [`studies`]: the studies that write `docs/` — regime sweeps, the criterion study on random
//!   machines, the run-up capture page, the cost of accuracy.

pub mod app;
pub mod engine;
pub mod studies;
