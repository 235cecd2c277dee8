//! Predicted running irregularity δ of a drive (seed 000): motor characteristic, load torque,
//! reduced inertia plus flywheel (constant, or J(φ) with harmonics); the steady state in closed
//! form (by the trapezoid rule on one period for J(φ)), δ without cancellation,
//! the stall case, flywheel sizing and sensitivities.
//!
//! Everything here runs at configuration time in f64, allocation-free. The motor and load
//! types are the single definition of the model: the host simulator integrates the same
//! [`Motor::torque`] and [`Load::torque`].

mod load;
mod model;
mod motor;
mod shooting;
#[cfg(test)]
mod shooting_tests;
#[cfg(test)]
mod tests;
mod varying;

pub use load::{Harmonic, Load, MAX_HARMONICS, MAX_ORDER};
pub use model::{
    least_inertia, period_revolutions, DesignError, DriveModel, Horizon, Irregularity, Prediction,
    Sensitivity, Stall, SteadyCurve, SteadyState, MAX_DENOMINATOR, MAX_SAMPLES, MIN_DELTA_TARGET,
    SAMPLES_PER_CYCLE,
};
pub use motor::{Kloss, KlossFit, Motor, Parabola};
pub use shooting::{inertia_and_slope, rk6_step, C as RK6_C, MAX_STEPS};
pub use varying::{InertiaHarmonic, MAX_INERTIA_HARMONICS, MAX_NODES};
