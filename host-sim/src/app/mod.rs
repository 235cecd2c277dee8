//! The `drive-sim` application: scene files ([`scene`]), a run through the engine and the core
//! ([`run`]), design-time results ([`predict`], the exact regime table [`regimes`]), the run-up's
//! capture analysis ([`capture`]), and
//! the report with its plots ([`report`], [`plot`]), progress bars ([`progress`]).

pub mod capture;
pub mod plot;
pub mod predict;
pub mod progress;
pub mod regimes;
pub mod report;
pub mod run;
pub mod scene;
