//! The `drive-sim` application: scene files ([`scene`]), a run through the engine and the core
//! ([`run`]), design-time results ([`predict`], the predicted δ through the core's speed samples
//! [`sampled`], the exact regime table [`regimes`]) and their
//! Rust table for firmware ([`emit`]), the run-up's capture analysis ([`capture`]), scene
//! checks ([`check`]), capture files ([`logic`]) and their analysis by the core ([`analyze`]),
//! and the report with its plots ([`report`], [`plot`]), progress bars ([`progress`]).

pub mod analyze;
pub mod capture;
pub mod check;
pub mod emit;
pub mod kloss_period;
pub mod logic;
pub mod plot;
pub mod predict;
pub mod progress;
pub mod regimes;
pub mod report;
pub mod run;
pub mod sampled;
pub mod scene;
