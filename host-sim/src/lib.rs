//! Host-side simulator for `drive-monitor`: scene files, dynamics assembled from the effects a
//! scene calls for, synthetic encoder edges, and reports computed by the same core code that
//! runs on the target.
pub mod accuracy;
pub mod model;
pub mod plot;
pub mod scene;
