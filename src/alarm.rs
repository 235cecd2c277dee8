//! δ limit alarm: N-of-M windows with hysteresis, only on steady, trustworthy windows, driving
//! an `embedded-hal` output pin.
//!
//! A window counts only when it is valid, steady, and its noise floor is small against the
//! limit (floor ≤ `floor_fraction`·limit), or, with a larger floor, when δ lies on one side of
//! the limit by more than the floor (over: δ − floor > limit; within: δ + floor below the
//! clearing level); any other window with a floor near the limit is flagged
//! ([`Verdict::FloorNearLimit`]) rather than trusted. The alarm raises when at least `n` of the
//! last `m` counted windows exceed the limit, and clears when at least `n` of the last `m` are
//! below `limit·(1 − hysteresis)`, so a δ sitting on the limit does not chatter; each switch
//! counts only the windows since the last one.

// The per-edge path runs through this module: no integer operation here may overflow or
// divide by zero, and no index may fail, in a debug build either (`panic-free.sh dev` in
// examples/qemu checks the image).
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::indexing_slicing)
)]

use crate::error::{non_negative_f32, positive_f32, tri, ConfigError};
use crate::irregularity::WindowReport;
use embedded_hal::digital::OutputPin;

/// Alarm settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AlarmConfig {
    /// Permissible δ (e.g. 0.06 for the seed's kneader).
    pub limit: f32,
    /// Windows over the limit needed to raise (N).
    pub raise_after: u8,
    /// Of the last M counted windows (N ≤ M ≤ 32).
    pub of_last: u8,
    /// Relative hysteresis: clear below `limit·(1 − hysteresis)` (0 to 0.9).
    pub hysteresis: f32,
    /// Largest noise floor, as a fraction of the limit, for a window to be trusted (0 to 1).
    pub floor_fraction: f32,
}

impl AlarmConfig {
    /// Limit `limit`, 3 of 5 windows, 10 % hysteresis, floor at most 20 % of the limit.
    pub const fn new(limit: f32) -> Self {
        AlarmConfig {
            limit,
            raise_after: 3,
            of_last: 5,
            hysteresis: 0.1,
            floor_fraction: 0.2,
        }
    }

    /// Checks the settings.
    pub const fn validate(self) -> Result<DeltaAlarm, ConfigError> {
        // δ = 2(ω_max − ω_min)/(ω_max + ω_min) < 2: a limit of 2 or more never raises.
        if tri!(positive_f32("delta_limit", self.limit)) >= 2.0 {
            return Err(ConfigError::OutOfRange("delta_limit"));
        }
        if self.of_last == 0 || self.of_last > 32 {
            return Err(ConfigError::OutOfRange("of_last"));
        }
        if self.raise_after == 0 || self.raise_after > self.of_last {
            return Err(ConfigError::OutOfRange("raise_after"));
        }
        let h = tri!(non_negative_f32("hysteresis", self.hysteresis));
        if h > 0.9 {
            return Err(ConfigError::OutOfRange("hysteresis"));
        }
        let f = tri!(positive_f32("floor_fraction", self.floor_fraction));
        if f > 1.0 {
            return Err(ConfigError::OutOfRange("floor_fraction"));
        }
        Ok(DeltaAlarm {
            config: self,
            over: 0,
            under: 0,
            active: false,
        })
    }
}

/// How a window was judged.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Verdict {
    /// Counted: δ within the limit.
    Within,
    /// Counted: δ over the limit.
    Over,
    /// Not counted: the window was invalid.
    Invalid,
    /// Not counted: the speed was not steady.
    Unsteady,
    /// Not counted: the quantization floor is large against the limit, and δ lies within it
    /// of the limit (or of the clearing level), so which side it is on is not known.
    FloorNearLimit,
}

/// An alarm transition.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum AlarmEvent {
    /// The alarm went on.
    Raised,
    /// The alarm went off.
    Cleared,
}

/// Alarm state: the last M counted windows as bit histories.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DeltaAlarm {
    config: AlarmConfig,
    over: u32,
    under: u32,
    active: bool,
}

impl DeltaAlarm {
    /// The settings.
    pub fn config(&self) -> &AlarmConfig {
        &self.config
    }

    /// Whether the alarm is on.
    pub fn active(&self) -> bool {
        self.active
    }

    /// Judges a window without changing state.
    pub fn judge(&self, r: &WindowReport) -> Verdict {
        let c = &self.config;
        let Some(r) = r.measurement() else {
            return Verdict::Invalid;
        };
        let floor = r.noise_floor;
        if !r.steady {
            Verdict::Unsteady
        } else if floor.is_nan() {
            Verdict::FloorNearLimit
        } else if floor > c.floor_fraction * c.limit {
            // A floor large against the limit: δ is judged only where the floor cannot carry it
            // across (a drive six times over its limit, its floor half the limit, was never
            // judged, and the pin said no alarm).
            if r.delta - floor > c.limit {
                Verdict::Over
            } else if r.delta + floor < c.limit * (1.0 - c.hysteresis) {
                Verdict::Within
            } else {
                Verdict::FloorNearLimit
            }
        } else if r.delta > c.limit {
            Verdict::Over
        } else {
            Verdict::Within
        }
    }

    /// Takes a window; returns its verdict and the transition it caused, if any.
    pub fn update(&mut self, r: &WindowReport) -> (Verdict, Option<AlarmEvent>) {
        let v = self.judge(r);
        let Some(r) = r
            .measurement()
            .filter(|_| matches!(v, Verdict::Over | Verdict::Within))
        else {
            return (v, None);
        };
        let m = self.config.of_last as u32;
        let mask = 1u32.checked_shl(m).map_or(u32::MAX, |b| b.wrapping_sub(1));
        let below = r.delta < self.config.limit * (1.0 - self.config.hysteresis);
        self.over = ((self.over << 1) | (v == Verdict::Over) as u32) & mask;
        self.under = ((self.under << 1) | below as u32) & mask;
        // Off, the windows over the limit raise it; on, those below the hysteresis clear it
        // (one count of the history that matters: less code in the window's path).
        let (history, event) = if self.active {
            (self.under, AlarmEvent::Cleared)
        } else {
            (self.over, AlarmEvent::Raised)
        };
        // The windows counted one set bit at a time, once a window: `count_ones` is a sum by
        // bit twiddling on this core (no population count instruction), 24 bytes more code.
        let (mut left, mut count) = (history, 0u32);
        while left != 0 {
            // Opaque, so that the loop is not unrolled (code size).
            left = core::hint::black_box(left & left.wrapping_sub(1));
            count = count.wrapping_add(1);
        }
        if count < u32::from(self.config.raise_after) {
            return (v, None);
        }
        self.active = !self.active;
        // The next switch counts windows from this one on: histories kept across it cleared
        // 1 of 3 at once on windows 50 % over the limit (two below it before the raise) and
        // raised it again on windows at half the limit.
        (self.over, self.under) = (0, 0);
        (v, Some(event))
    }
}

/// Drives an output pin from the alarm state (high = alarm, or inverted).
#[derive(Debug)]
pub struct AlarmOutput<P: OutputPin> {
    pin: P,
    active_high: bool,
}

impl<P: OutputPin> AlarmOutput<P> {
    /// Wraps `pin`; `active_high` selects the level that means "alarm".
    pub fn new(pin: P, active_high: bool) -> Self {
        AlarmOutput { pin, active_high }
    }

    /// Sets the pin to show `active`.
    pub fn show(&mut self, active: bool) -> Result<(), P::Error> {
        if active == self.active_high {
            self.pin.set_high()
        } else {
            self.pin.set_low()
        }
    }

    /// Returns the pin.
    pub fn release(self) -> P {
        self.pin
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::convert::Infallible;

    fn window(delta: f32, steady: bool, floor: f32) -> WindowReport {
        WindowReport {
            start_edge: 0,
            end_edge: 8192,
            start_ticks: 0,
            end_ticks: 1_000_000,
            revolutions: 8,
            result: Ok(crate::irregularity::Measurement {
                omega_max: 0.0,
                omega_min: 0.0,
                omega_mean: 100.0,
                delta,
                spread: delta,
                noise_floor: floor,
                samples: 8192,
                steady,
            }),
        }
    }

    #[test]
    fn raises_after_n_of_m_and_clears_with_hysteresis() {
        let mut a = AlarmConfig::new(0.06).validate().unwrap();
        let over = window(0.07, true, 1e-4);
        let near = window(0.058, true, 1e-4); // within, but not below 0.054
        let low = window(0.05, true, 1e-4);
        assert_eq!(a.update(&over), (Verdict::Over, None));
        assert_eq!(a.update(&low), (Verdict::Within, None));
        assert_eq!(a.update(&over), (Verdict::Over, None));
        assert_eq!(a.update(&over), (Verdict::Over, Some(AlarmEvent::Raised)));
        assert!(a.active());
        // Sitting just under the limit does not clear it.
        for _ in 0..10 {
            assert_eq!(a.update(&near), (Verdict::Within, None));
        }
        assert!(a.active());
        assert_eq!(a.update(&low), (Verdict::Within, None));
        assert_eq!(a.update(&low), (Verdict::Within, None));
        assert_eq!(a.update(&low), (Verdict::Within, Some(AlarmEvent::Cleared)));
    }

    #[test]
    fn untrusted_windows_do_not_count() {
        let mut a = AlarmConfig::new(0.06).validate().unwrap();
        for _ in 0..10 {
            assert_eq!(a.update(&window(0.1, false, 1e-4)).0, Verdict::Unsteady);
            assert_eq!(
                a.update(&window(0.07, true, 0.02)).0,
                Verdict::FloorNearLimit
            );
            assert_eq!(
                a.update(&window(0.1, true, f32::NAN)).0,
                Verdict::FloorNearLimit
            );
            let mut bad = window(0.1, true, 1e-4);
            bad.result = Err(crate::speed::Fault::Glitch);
            assert_eq!(a.update(&bad).0, Verdict::Invalid);
        }
        assert!(!a.active());
    }

    /// A floor large against the limit (0.03 on a limit of 0.06, half of it): δ is judged
    /// where the floor cannot carry it across the limit, or the clearing level 0.054, and
    /// only there.
    #[test]
    fn a_large_floor_still_judges_a_delta_clear_of_the_limit() {
        let a = AlarmConfig::new(0.06).validate().unwrap();
        for (delta, verdict) in [
            (0.36, Verdict::Over),
            (0.0901, Verdict::Over),
            (0.0899, Verdict::FloorNearLimit),
            (0.06, Verdict::FloorNearLimit),
            (0.0241, Verdict::FloorNearLimit),
            (0.0239, Verdict::Within),
            (0.0, Verdict::Within),
        ] {
            assert_eq!(a.judge(&window(delta, true, 0.03)), verdict, "{delta}");
        }
        // Over by more than its floor every window: raised as any other.
        let mut a = a;
        let far = window(0.36, true, 0.03);
        assert_eq!(a.update(&far), (Verdict::Over, None));
        assert_eq!(a.update(&far), (Verdict::Over, None));
        assert_eq!(a.update(&far), (Verdict::Over, Some(AlarmEvent::Raised)));
    }

    #[test]
    fn bad_settings_are_rejected() {
        let mut c = AlarmConfig::new(0.06);
        c.raise_after = 6;
        assert_eq!(
            c.validate().err(),
            Some(ConfigError::OutOfRange("raise_after"))
        );
        assert_eq!(
            AlarmConfig::new(f32::NAN).validate().err(),
            Some(ConfigError::NonFinite("delta_limit"))
        );
        assert_eq!(
            AlarmConfig::new(-0.1).validate().err(),
            Some(ConfigError::NotPositive("delta_limit"))
        );
        // δ is below 2 on any window: a limit of 2 would never raise.
        assert_eq!(
            AlarmConfig::new(2.0).validate().err(),
            Some(ConfigError::OutOfRange("delta_limit"))
        );
        assert!(AlarmConfig::new(1.99).validate().is_ok());
    }

    #[test]
    fn a_switch_counts_only_the_windows_since_the_last() {
        // 1 of 3 and 2 of 5: windows below the limit before a raise cleared the alarm at
        // once on windows 50 % over it, and windows over it before a clear raised it again
        // on windows at half the limit. Steady over the limit it stays on; steady at half
        // the limit it stays off.
        for (n, m) in [(1u8, 3u8), (2, 5), (3, 10)] {
            let mut c = AlarmConfig::new(0.06);
            (c.raise_after, c.of_last) = (n, m);
            let mut a = c.validate().unwrap();
            let (low, high) = (window(0.03, true, 1e-4), window(0.09, true, 1e-4));
            let mut events = Vec::new();
            for w in [low; 8].iter().chain(&[high; 12]).chain(&[low; 12]) {
                events.extend(a.update(w).1);
            }
            assert_eq!(
                events,
                [AlarmEvent::Raised, AlarmEvent::Cleared],
                "{n} of {m}"
            );
            assert!(!a.active());
        }
    }

    struct Pin(bool);
    impl embedded_hal::digital::ErrorType for Pin {
        type Error = Infallible;
    }
    impl OutputPin for Pin {
        fn set_low(&mut self) -> Result<(), Infallible> {
            self.0 = false;
            Ok(())
        }
        fn set_high(&mut self) -> Result<(), Infallible> {
            self.0 = true;
            Ok(())
        }
    }

    #[test]
    fn output_follows_polarity() {
        let mut o = AlarmOutput::new(Pin(false), true);
        o.show(true).unwrap();
        assert!(o.release().0);
        let mut o = AlarmOutput::new(Pin(true), false);
        o.show(true).unwrap();
        assert!(!o.release().0);
    }
}
