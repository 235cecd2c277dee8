//! Host-side simulator for `drive-monitor`: scene files, dynamics assembled from the effects a
//! scene calls for, synthetic encoder edges, and reports computed by the same core code that
//! runs on the target.

pub mod accuracy;
pub mod capture;
pub mod cost;
pub mod effects;
pub mod encoder;
pub mod model;
pub mod ode;
pub mod plot;
pub mod predict;
pub mod publish;
pub mod report;
pub mod rotor_loads;
pub mod run;
pub mod scene;
pub mod study;
pub mod sweep;
pub mod system;
pub mod vibration;
