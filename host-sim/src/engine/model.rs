//! The simulated machine as a composition of effects.
//!
//! A scene names the effects it needs; the simulator assembles the state vector and the
//! right-hand side from exactly those. Each [`Effect`] owns a contiguous slice of the state
//! vector (possibly empty), writes the derivatives of that slice, and returns the torque it
//! applies to the drive shaft. The shaft itself (angle φ and speed ω) is either prescribed
//! (a kinematic law) or integrated from the torques of all effects with the reduced inertia
//! J(φ) (seed 000, eq. 1: J(φ)·ω' + ½·ω²·dJ/dφ = Σ torques).
//!
//! Adding an effect is adding one type that implements [`Effect`]; nothing else changes.

/// The drive shaft's kinematic state, read by every effect.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shaft {
    /// Shaft angle φ, rad (unwrapped).
    pub phi: f64,
    /// Shaft speed ω = dφ/dt, rad/s.
    pub omega: f64,
}

/// One physical effect of a scene.
pub trait Effect: Send + Sync {
    /// Short name, used in reports and in per-component evaluation counts.
    fn name(&self) -> &'static str;
    /// Number of state variables this effect owns (by default 0: a pure torque such as a
    /// load, which then needs neither this nor [`Effect::init`]).
    fn dim(&self) -> usize {
        0
    }
    /// Writes the initial values of the effect's own states (`y.len() == self.dim()`).
    fn init(&self, _y: &mut [f64]) {}
    /// Writes `dy` (the derivatives of the effect's own states `y`) at time `t` with the shaft
    /// in state `shaft`, and returns the torque the effect applies to the shaft, N·m
    /// (positive drives the shaft forward).
    fn eval(&self, t: f64, shaft: Shaft, y: &[f64], dy: &mut [f64]) -> f64;
}
