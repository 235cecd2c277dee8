//! Per-tooth pitch storage: nothing for a wheel taken at its nominal pitches, or a 16-bit
//! correction per tooth (a learned or measured disc error).
//!
//! A monitor is generic over its [`PitchTable`], so memory follows what is used: a uniform
//! 1024-line disc at its nominal pitches keeps no table at all ([`Nominal`] is zero-sized),
//! and [`Corrected<N>`] keeps 2 bytes per tooth. A correction is the deviation of each tooth's
//! pitch from its nominal value in angle units (1/65 536 of a nominal pitch, see
//! [`crate::encoder`]), at most ±50 % of a pitch; the deviations of a revolution sum to zero,
//! so the corrected pitches close the turn exactly.

// The per-edge path runs through this module: no integer operation here may overflow or
// divide by zero, and no index may fail, in a debug build either (`panic-free.sh dev` in
// examples/qemu checks the image).
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::indexing_slicing)
)]

use crate::encoder::{Encoder, PITCH_UNITS};
use crate::error::{positive_f32, ConfigError};

/// Storage of per-tooth pitch deviations.
pub trait PitchTable: Clone {
    /// `true` when every deviation is zero by construction (no storage).
    const NOMINAL: bool;
    /// Teeth the table can hold.
    const CAPACITY: usize;
    /// The table with every deviation zero.
    const EMPTY: Self;
    /// Deviation of `tooth`'s pitch from nominal, angle units (0 beyond the table).
    fn deviation(&self, tooth: u16) -> i32;
    /// Replaces the deviations of the first `dev.len()` teeth (the caller has checked them).
    fn store(&mut self, dev: &[i16]);
}

/// Every tooth at its nominal pitch; no storage.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Nominal;

impl PitchTable for Nominal {
    const NOMINAL: bool = true;
    const CAPACITY: usize = 0;
    const EMPTY: Self = Nominal;
    #[inline(always)]
    fn deviation(&self, _tooth: u16) -> i32 {
        0
    }
    fn store(&mut self, _dev: &[i16]) {}
}

/// A correction of up to `N` teeth, 2 bytes each.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Corrected<const N: usize> {
    dev: [i16; N],
}

impl<const N: usize> Corrected<N> {
    /// All deviations zero (the nominal pitches).
    pub const fn new() -> Self {
        Corrected { dev: [0; N] }
    }
}

impl<const N: usize> Default for Corrected<N> {
    fn default() -> Self {
        Self::new()
    }
}

impl<const N: usize> PitchTable for Corrected<N> {
    const NOMINAL: bool = false;
    const CAPACITY: usize = N;
    const EMPTY: Self = Corrected { dev: [0; N] };
    #[inline(always)]
    fn deviation(&self, tooth: u16) -> i32 {
        self.dev
            .get(usize::from(tooth))
            .map_or(0, |&d| i32::from(d))
    }
    fn store(&mut self, dev: &[i16]) {
        for (slot, &d) in self.dev.iter_mut().zip(dev) {
            *slot = d;
        }
        for slot in self.dev.iter_mut().skip(dev.len()) {
            *slot = 0;
        }
    }
}

/// Converts a pitch table in radians (edge k−1 to edge k, one per edge of `encoder`) into
/// deviations from the nominal pitches in angle units, written into `out`.
///
/// Each pitch must be positive and within 50 % of its nominal value, and the table must close
/// the turn (sum 2π within 1e-4 rad); the table is rescaled to close it exactly and the
/// rounding residue of the integer deviations is spread over the teeth so they sum to zero.
pub fn deviations(encoder: &Encoder, pitches: &[f32], out: &mut [i16]) -> Result<(), ConfigError> {
    let edges = usize::from(encoder.edges());
    if pitches.len() != edges {
        return Err(ConfigError::OutOfRange("pitches.len"));
    }
    if out.len() < edges {
        return Err(ConfigError::Capacity("pitches"));
    }
    let mut sum = 0.0f64;
    for &p in pitches {
        sum += f64::from(positive_f32("pitches", p)?);
    }
    if libm::fabs(sum - core::f64::consts::TAU) > 1e-4 {
        return Err(ConfigError::Inconsistent("pitches (sum)"));
    }
    let unit = core::f64::consts::TAU / sum / f64::from(encoder.unit_rad());
    // Deviations accumulated as the rounding of a running sum: each rounds once and the total
    // is the rounding of the exact total, which is 0 by the rescaling above (to one unit).
    let mut exact = 0.0f64;
    let mut given = 0i64;
    for (k, (&p, slot)) in pitches.iter().zip(out.iter_mut()).enumerate() {
        let nominal = f64::from(encoder.nominal_pitch(k as u16));
        let d = f64::from(p) * unit - nominal;
        if libm::fabs(d) > 0.5 * f64::from(PITCH_UNITS) - 1.0 {
            return Err(ConfigError::OutOfRange("pitches"));
        }
        exact += d;
        let target = libm::round(exact) as i64;
        let step = target.checked_sub(given);
        given = target;
        *slot = step
            .and_then(|d| i16::try_from(d).ok())
            .ok_or(ConfigError::OutOfRange("pitches"))?;
    }
    // The last rounding may leave ±1 unit: fold it into the last tooth.
    if given != 0 {
        if let Some(slot) = edges.checked_sub(1).and_then(|last| out.get_mut(last)) {
            *slot = i64::from(*slot)
                .checked_sub(given)
                .and_then(|v| i16::try_from(v).ok())
                .ok_or(ConfigError::OutOfRange("pitches"))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::encoder::EncoderConfig;

    #[test]
    fn deviations_close_the_turn_exactly() {
        let e = Encoder::new(EncoderConfig::indexed(8, 1e6)).unwrap();
        let p = (core::f64::consts::TAU / 8.0) as f32;
        let mut t = [p; 8];
        t[0] *= 1.01;
        t[1] *= 0.99;
        let mut d = [0i16; 8];
        deviations(&e, &t, &mut d).unwrap();
        assert_eq!(d.iter().map(|&x| i32::from(x)).sum::<i32>(), 0);
        assert!((f64::from(d[0]) - 655.36).abs() <= 1.0, "{d:?}");
        assert!((f64::from(d[1]) + 655.36).abs() <= 1.0, "{d:?}");
        assert_eq!(
            deviations(&e, &t[..7], &mut d).err(),
            Some(ConfigError::OutOfRange("pitches.len"))
        );
        t[2] = f32::NAN;
        assert_eq!(
            deviations(&e, &t, &mut d).err(),
            Some(ConfigError::NonFinite("pitches"))
        );
        let t = [p * 1.01; 8];
        assert_eq!(
            deviations(&e, &t, &mut d).err(),
            Some(ConfigError::Inconsistent("pitches (sum)"))
        );
        let mut t = [p; 8];
        t[0] *= 1.6;
        t[1] *= 0.4;
        assert_eq!(
            deviations(&e, &t, &mut d).err(),
            Some(ConfigError::OutOfRange("pitches"))
        );
        let mut small = [0i16; 4];
        assert_eq!(
            deviations(&e, &[p; 8], &mut small).err(),
            Some(ConfigError::Capacity("pitches"))
        );
    }

    #[test]
    fn tables_store_and_report_deviations() {
        let mut c = Corrected::<4>::new();
        c.store(&[5, -5]);
        assert_eq!(c.deviation(0), 5);
        assert_eq!(c.deviation(1), -5);
        assert_eq!(c.deviation(2), 0);
        assert_eq!(c.deviation(9), 0);
        assert_eq!(Nominal.deviation(0), 0);
        assert_eq!(core::mem::size_of::<Nominal>(), 0);
        assert_eq!(core::mem::size_of::<Corrected<1024>>(), 2048);
    }
}
