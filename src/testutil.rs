//! Test helpers shared by the unit tests and the integration tests (`tests/hard_cases.rs`
//! includes this file with `#[path]`, so both use the same lists).

#![allow(dead_code)]

/// Values a strictly positive f64 parameter must reject: NaN, ±∞, zero, a negative value and a
/// subnormal (not physical, and it loses its digits in the first division).
pub(crate) const BAD: [f64; 6] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -1.0,
    1e-310,
];

/// The values of [`BAD`] a non-negative f64 parameter must reject: all but zero.
pub(crate) const BAD_NON_NEGATIVE: [f64; 5] =
    [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1.0, 1e-310];

/// [`BAD`] for f32 parameters; 1e-40 is subnormal as an f32 (though normal as an f64).
pub(crate) const BAD_F32: [f32; 6] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -1.0, 1e-40];

/// The values of [`BAD_F32`] a non-negative f32 parameter must reject: all but zero.
pub(crate) const BAD_F32_NON_NEGATIVE: [f32; 5] =
    [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 1e-40];

use drive_monitor::balancer::{Coupling, Platform};
use drive_monitor::drive::{DriveModel, Harmonic, Load, Motor, Parabola};

/// The seed 000 kneader: ω0 = 145 rad/s, ω_m = 36 rad/s, M_m = 158 N·m, J = 0.323 kg·m²,
/// mean load M1 = 24 N·m.
pub(crate) const W0: f64 = 145.0;
/// Breakdown speed ω_m, rad/s.
pub(crate) const WM: f64 = 36.0;
/// Breakdown torque M_m, N·m.
pub(crate) const MM: f64 = 158.0;
/// Reduced inertia J, kg·m².
pub(crate) const J: f64 = 0.323;
/// Mean load M1, N·m.
pub(crate) const M1: f64 = 24.0;

/// The seed's parabolic motor.
pub(crate) fn seed_motor() -> Motor {
    Parabola::new(W0, WM, MM).unwrap().into()
}

/// A load harmonic `amplitude·sin(order·φ + phase)`.
pub(crate) fn h(order: f64, amplitude: f64, phase: f64) -> Harmonic {
    Harmonic::new(order, amplitude, phase).unwrap()
}

/// The seed's drive with mean load M1, the given harmonics and inertia, no flywheel.
pub(crate) fn drive(harmonics: &[Harmonic], inertia: f64) -> DriveModel {
    DriveModel::new(
        seed_motor(),
        Load::new(M1, harmonics).unwrap(),
        inertia,
        0.0,
    )
    .unwrap()
}

/// A platform of a vibration machine.
pub(crate) fn platform(mass: f64, stiffness: f64, damping: f64) -> Platform {
    Platform {
        mass,
        stiffness,
        damping,
    }
}

/// A coupling between platforms `a` and `b` (1-based).
pub(crate) fn coupling(a: u8, b: u8, stiffness: f64, damping: f64) -> Coupling {
    Coupling {
        between: [a, b],
        stiffness,
        damping,
    }
}
