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
