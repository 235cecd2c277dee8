//! Support-unbalance limits for a rigid rotor on two supports (seed 002, Kuklina et al.
//! 2021): unbalance split to the supports, ISO 21940-11 limits and bearing loads.
//!
//! Configuration time (f64): build a [`Rotor`] (mass, centre of mass, support planes A and B,
//! up to `N` unbalances, an optional distributed process load, gravity) and [`Limits`]
//! (balance quality grade, service speed, allowed support loads), then a [`SupportAnalysis`]
//! and from it the f32 [`SupportMonitor`] whose [`SupportMonitor::update`] runs per speed
//! update from the encoder.
//!
//! # Model
//! Unbalances are 2-D vectors `D_i` (kg·m) at axial positions `z_i`. Every result of the seed
//! — resultant static unbalance `D_st` (eq. 2, 4), moment unbalance `M_D` (eq. 3–4), the split
//! onto the support planes (eq. 5–7), the two-plane transfer between any planes (eq. 30–39,
//! Table 1, inboard scheme I and overhung scheme II) — is the one pair of vectors in two
//! planes with the same resultant and moment as the given system, which [`Rotor`] and
//! [`equivalent_planes`] compute with signed positions. At speed ω support A carries the
//! static load `S_A` (weight and process load by beam statics) and the rotating load
//! `D_A·ω²`; over one turn its magnitude runs from `||S_A| − |D_A|ω²|` to `|S_A| + |D_A|ω²`.
//!
//! # The seed's misprints (see also the project's seed notes)
//! * Eq. 33 and 37: the denominators must read `D_1 cos α_1 (…) + D_2 cos α_2 (…)`; the
//!   paper prints `sin α_2`. Eq. 37 also prints `D_1 sin α_1 / (D_A cos α_A)` for `tan α_1`.
//!   Angles here come from the vector components through `atan2`, never through tan.
//! * Eq. 30: the fourth line must use `D_AY`, not `D_BY`. Eq. 31 as printed gives the
//!   negatives of the equivalent unbalances of eq. 30 and 38 (its denominators are `Z_B − Z_A`
//!   and `Z_A − Z_B` where eq. 30 gives `Z_A − Z_B` and `Z_B − Z_A`), i.e. the corrections.
//! * Eq. 36: the second line writes `α_1` inside the root's left side (harmless: it is a
//!   magnitude).
//! * Eq. 39 (the couple case, α₂ = α_B = 180°) is eq. 38 with signed components; its printed
//!   sign changes in the second and fourth lines agree with neither signed nor magnitude form.
//! * Table 1, scheme I, static column: `D_1` repeats `D_2`; the balance gives
//!   `D_1 = (D_A·l_2 + D_B·(l_2 − L))/(l_2 − l_1)`. In the moment column `D_1` reads
//!   `D_2·l_2` where the balance gives `D_A·l_2`. Scheme II's figure did not survive the text
//!   extraction, so its printed rows cannot be checked against a definite geometry; with
//!   signed positions (planes beyond a support have `l > L` or `l < 0`) both schemes are the
//!   same balance, which the tests check for correction planes inside and outside the span.
//! * Eq. 12 and 16 add load terms to squared unbalances in different units; see
//!   [`Rotor::static_load`] for the consistent model used instead.
//!
//! # Numerics
//! Plane shares are formed as `Σ D_i·(z_B − z_i) / (z_B − z_A)` with the lever arms taken
//! exactly (each difference as its rounded value plus its rounding error) and a compensated
//! (twice-working-precision) sum, so a pure couple or unbalances that cancel to 1e-15, at
//! the same or at different planes, keep their true small result. Two planes closer than
//! [`MIN_PLANE_SEPARATION`] times the model's largest absolute axial coordinate are a
//! typed error ([`crate::ConfigError::Inconsistent`]).

mod limits;
mod rotor;
mod runtime;
mod vector;

#[cfg(test)]
mod tests;

pub use limits::{
    allocate, max_safe_speed, permissible_residual_unbalance, Allocation, Limits, Permissible,
    SupportAnalysis, SupportsReport, DEFAULT_WARNING_FRACTION, ISO_SHARE_MAX, ISO_SHARE_MIN,
};
pub use rotor::{
    equivalent_planes, LoadRange, PlaneSplit, ProcessLoad, Rotor, Unbalance, GRAVITY_ANGLE,
    STANDARD_GRAVITY,
};
pub use runtime::{Level, SupportMonitor, SupportStatus};
pub use vector::Vec2;

/// Smallest allowed separation of two planes (support planes, or the two planes of a
/// transfer), relative to the largest absolute axial coordinate in the model.
///
/// The plane shares have condition number ≈ (coordinate scale)/(separation), so at this bound
/// the f64 results keep about 10 significant digits — far below the f32 resolution of the
/// runtime. Physically it is 4 µm of separation on a 4 m rotor: planes that close are the
/// same plane.
pub const MIN_PLANE_SEPARATION: f64 = 1e-6;
