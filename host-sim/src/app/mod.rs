//! The `drive-sim` application: scene files ([`scene`]), a run through the engine and the core
//! ([`run`]), design-time results ([`predict`]), the run-up's capture analysis ([`capture`]), and
//! the report with its plots ([`report`], [`plot`]), progress bars ([`progress`]).

pub mod analyze;
pub mod capture;
pub mod check;
pub mod logic;
pub mod plot;
pub mod predict;
pub mod progress;
pub mod report;
pub mod run;
pub mod scene;
