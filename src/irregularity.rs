//! Running irregularity δ over one load cycle, from framed speed samples.
//!
//! δ must be taken over a window that is one period of the load cycle: the seed's kneader load
//! has order 1/8, so its cycle is 8 revolutions and a per-revolution δ would see only part of
//! the swing. A window starts at a frame (tooth 0) and ends after `W` whole revolutions, so the
//! mean speed is exact: ω_mean = W·2π / (sum of the window's intervals), the intervals summed
//! as integers (no drift over any run length).
//!
//! Reported per window: ωmax, ωmin, ω_mean, δ = 2(ωmax − ωmin)/(ωmax + ωmin) (seed 000,
//! eq. 13), the spread (ωmax − ωmin)/ω_mean, the quantization noise floor, validity with its
//! reason, and whether the speed was steady. No filtering happens before δ: a low-pass would
//! remove exactly the ripple δ measures.

use crate::error::{positive, positive_f32, ConfigError};
use crate::speed::{EdgeEvent, Fault, SpeedSample};

/// Largest window, in revolutions.
pub const MAX_WINDOW_REVS: u16 = 1024;

/// How long a δ window is.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WindowLength {
    /// A fixed number of revolutions.
    Revolutions(u16),
    /// The load's lowest order (cycles per revolution, e.g. 0.125 for one load cycle per 8
    /// revolutions). The window is the smallest whole number of revolutions holding a whole
    /// number of load cycles (order within 1e-4 relative of a fraction with denominator ≤ 1024).
    LoadOrder(f64),
}

impl WindowLength {
    /// The window in revolutions.
    pub fn revolutions(self) -> Result<u16, ConfigError> {
        match self {
            WindowLength::Revolutions(n) => {
                if n == 0 || n > MAX_WINDOW_REVS {
                    Err(ConfigError::OutOfRange("window.revolutions"))
                } else {
                    Ok(n)
                }
            }
            WindowLength::LoadOrder(order) => {
                let order = positive("window.load_order", order)?;
                for w in 1..=MAX_WINDOW_REVS {
                    let cycles = order * w as f64;
                    let whole = libm::round(cycles);
                    if whole >= 1.0 && (cycles - whole).abs() <= 1e-4 * cycles {
                        return Ok(w);
                    }
                }
                Err(ConfigError::OutOfRange("window.load_order"))
            }
        }
    }
}

/// Window settings, validated by [`WindowConfig::validate`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WindowConfig {
    /// Window length.
    pub length: WindowLength,
    /// A window is steady when its mean speed differs from the previous window's by less than
    /// this fraction (e.g. 0.02).
    pub steady_tolerance: f32,
}

/// Validated window settings.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Window {
    revolutions: u16,
    steady_tolerance: f32,
}

impl WindowConfig {
    /// Checks the settings.
    pub fn validate(self) -> Result<Window, ConfigError> {
        let revolutions = self.length.revolutions()?;
        let t = positive_f32("steady_tolerance", self.steady_tolerance)?;
        if t >= 1.0 {
            return Err(ConfigError::OutOfRange("steady_tolerance"));
        }
        Ok(Window {
            revolutions,
            steady_tolerance: self.steady_tolerance,
        })
    }
}

impl Window {
    /// Revolutions per window.
    pub fn revolutions(&self) -> u16 {
        self.revolutions
    }
}

/// The result of one window.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WindowReport {
    /// Largest speed sample, rad/s.
    pub omega_max: f32,
    /// Smallest speed sample, rad/s.
    pub omega_min: f32,
    /// Mean speed, angle over time, rad/s.
    pub omega_mean: f32,
    /// δ = 2(ωmax − ωmin)/(ωmax + ωmin).
    pub delta: f32,
    /// (ωmax − ωmin)/ω_mean.
    pub spread: f32,
    /// Bound on the error of δ from timer quantization: 2 / (mean ticks per speed sample).
    pub noise_floor: f32,
    /// Revolutions covered (the configured count for a valid window).
    pub revolutions: u16,
    /// Speed samples taken.
    pub samples: u32,
    /// `None` for a valid window, else the first fault seen in it.
    pub fault: Option<Fault>,
    /// The mean speed was within the steady tolerance of the previous valid window's.
    pub steady: bool,
}

impl WindowReport {
    /// A complete window with no fault.
    pub fn valid(&self) -> bool {
        self.fault.is_none()
    }
}

/// An extreme sample: angle and interval, the interval as its exact integer tick count (equal
/// angles compare the counts exactly; other comparisons convert them to f32).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Extreme {
    angle: f32,
    ticks: u32,
}

/// Per-window accumulation state.
#[derive(Debug, Clone)]
pub struct WindowState {
    started: bool,
    revs: u16,
    ticks: u64,
    samples: u32,
    sample_ticks: u64,
    max: Extreme,
    min: Extreme,
    /// Mean speed of the previous valid window (0 when none).
    prev_mean: f32,
}

impl Default for WindowState {
    fn default() -> Self {
        Self::new()
    }
}

/// `x as f32`, through the FPU's 32-bit conversion when `x` fits in 32 bits (the same correctly
/// rounded value; the 64-bit conversion is a software routine on a 32-bit core).
#[inline]
fn u64_to_f32(x: u64) -> f32 {
    #[cold]
    #[inline(never)]
    fn wide(x: u64) -> f32 {
        x as f32
    }
    match u32::try_from(x) {
        Ok(x) => x as f32,
        Err(_) => wide(x),
    }
}

/// Veltkamp's split: `x = hi + lo` exactly, each half with at most 12 significant bits, so
/// products of halves are exact in f32.
#[inline]
fn split(x: f32) -> (f32, f32) {
    // 2^12 + 1: splits the 24-bit significand in two.
    let c = 4097.0 * x;
    let hi = c - (c - x);
    (hi, x - hi)
}

/// Dekker's product: `p + e = x·y` exactly (no overflow or underflow here: angles and tick
/// counts are far inside the f32 range).
#[inline]
fn two_product(x: f32, y: f32) -> (f32, f32) {
    let p = x * y;
    let (xh, xl) = split(x);
    let (yh, yl) = split(y);
    let e = ((xh * yh - p) + xh * yl + xl * yh) + xl * yl;
    (p, e)
}

/// A tick count as an f32 head (its rounding) plus the exact remainder (|rem| ≤ 128).
#[inline]
fn split_ticks(t: u32) -> (f32, f32) {
    let head = t as f32;
    (head, (i64::from(t) - head as i64) as f32)
}

/// a1·t2 − a2·t1 for integer tick counts, to within about one rounding of the result: both
/// products are split exactly (Dekker) and differenced term by term, so equal speeds cancel to
/// exactly 0. Plain f32 arithmetic: on a Cortex-M4F ~40 FPU instructions, against ~400 for
/// two software `libm::fmaf` calls (no fused multiply-add is reachable from stable `core`).
///
/// Counts below 2²⁴ are exact in f32 and take this path alone; larger ones round in f32 and go
/// to [`cross_wide`], out of line. Splitting every count instead (remainders then 0) cost the
/// window finish 9 more instructions when measured (`monitor::window_finish`, examples/qemu/run.sh).
#[inline]
fn cross(a1: f32, t2: u32, a2: f32, t1: u32) -> f32 {
    if (t1 | t2) < 1 << 24 {
        let (p1, e1) = two_product(a1, t2 as f32);
        let (p2, e2) = two_product(a2, t1 as f32);
        (p1 - p2) + (e1 - e2)
    } else {
        cross_wide(a1, t2, a2, t1)
    }
}

/// [`cross`] for counts of 2²⁴ and above, which round in f32: each count is split exactly into
/// its f32 head and the remainder; the head products go through Dekker as in [`cross`], and the
/// small remainder products (|remainder| ≤ 128) are added after, so equal speeds still cancel
/// to exactly 0.
#[cold]
#[inline(never)]
fn cross_wide(a1: f32, t2: u32, a2: f32, t1: u32) -> f32 {
    let (h2, l2) = split_ticks(t2);
    let (h1, l1) = split_ticks(t1);
    let (p1, e1) = two_product(a1, h2);
    let (p2, e2) = two_product(a2, h1);
    ((p1 - p2) + (e1 - e2)) + (a1 * l2 - a2 * l1)
}

impl WindowState {
    /// No window in progress.
    pub const fn new() -> Self {
        WindowState {
            started: false,
            revs: 0,
            ticks: 0,
            samples: 0,
            sample_ticks: 0,
            max: Extreme {
                angle: 0.0,
                ticks: 0,
            },
            min: Extreme {
                angle: 0.0,
                ticks: 0,
            },
            prev_mean: 0.0,
        }
    }

    fn restart(&mut self) {
        self.started = true;
        self.revs = 0;
        self.ticks = 0;
        self.samples = 0;
        self.sample_ticks = 0;
    }

    fn take(&mut self, s: &SpeedSample) {
        if s.ticks == 0 {
            return;
        }
        // A window holds at most MAX_WINDOW_REVS·65535 < 2^26 edges of < 2^32 ticks each, so
        // neither count can reach its type's limit: plain wrapping adds are exact.
        self.samples = self.samples.wrapping_add(1);
        self.sample_ticks = self.sample_ticks.wrapping_add(s.ticks as u64);
        let e = Extreme {
            angle: s.angle,
            ticks: s.ticks,
        };
        if self.samples == 1 {
            self.max = e;
            self.min = e;
            return;
        }
        // Compare angle/ticks by cross-multiplying: no division per edge. Equal angles (a
        // uniform disc) compare the exact integer counts, which round in f32 above 2²⁴.
        let t = s.ticks as f32;
        let faster = if s.angle == self.max.angle {
            s.ticks < self.max.ticks
        } else {
            s.angle * self.max.ticks as f32 > self.max.angle * t
        };
        if faster {
            self.max = e;
        }
        let slower = if s.angle == self.min.angle {
            s.ticks > self.min.ticks
        } else {
            s.angle * (self.min.ticks as f32) < self.min.angle * t
        };
        if slower {
            self.min = e;
        }
    }

    fn report(&self, window: &Window, timer_hz: f32, fault: Option<Fault>) -> WindowReport {
        let (a1, t1) = (self.max.angle, self.max.ticks as f32);
        let (a2, t2) = (self.min.angle, self.min.ticks as f32);
        let omega_max = if t1 > 0.0 { a1 * timer_hz / t1 } else { 0.0 };
        let omega_min = if t2 > 0.0 { a2 * timer_hz / t2 } else { 0.0 };
        // δ = 2(a1/t1 − a2/t2)/(a1/t1 + a2/t2) = 2(a1·t2 − a2·t1)/(a1·t2 + a2·t1): the numerator
        // from exact integer ticks and an error-free product difference, never by subtracting
        // two speeds.
        let num = cross(a1, self.min.ticks, a2, self.max.ticks);
        let den = a1 * t2 + a2 * t1;
        let delta = if den > 0.0 { 2.0 * num / den } else { 0.0 };
        let omega_mean = if self.ticks > 0 {
            self.revs as f32 * core::f32::consts::TAU * timer_hz / u64_to_f32(self.ticks)
        } else {
            0.0
        };
        let spread = if omega_mean > 0.0 {
            (omega_max - omega_min) / omega_mean
        } else {
            0.0
        };
        let noise_floor = if self.sample_ticks > 0 {
            2.0 * self.samples as f32 / u64_to_f32(self.sample_ticks)
        } else {
            1.0
        };
        let steady = fault.is_none()
            && self.prev_mean > 0.0
            && (omega_mean - self.prev_mean).abs() < window.steady_tolerance * omega_mean;
        WindowReport {
            omega_max,
            omega_min,
            omega_mean,
            delta,
            spread,
            noise_floor,
            revolutions: self.revs,
            samples: self.samples,
            fault,
            steady,
        }
    }

    /// Feeds one edge's event; returns a report when a window ends (complete, or cut short by
    /// a fault: then invalid with that fault as its reason).
    pub fn on_event(
        &mut self,
        window: &Window,
        timer_hz: f32,
        ev: &EdgeEvent,
    ) -> Option<WindowReport> {
        if let Some(fault) = ev.fault {
            return self.abort(window, timer_hz, fault);
        }
        if !self.started {
            if ev.frame {
                self.restart();
            }
            return None;
        }
        if let Some((dt, _)) = ev.interval {
            // Bounded like the sample counts (see `take`): the wrapping add is exact.
            self.ticks = self.ticks.wrapping_add(dt as u64);
        }
        if let Some(s) = &ev.sample {
            self.take(s);
        }
        if ev.frame {
            self.revs = self.revs.saturating_add(1);
            if self.revs >= window.revolutions {
                let r = self.report(window, timer_hz, None);
                self.prev_mean = r.omega_mean;
                self.restart();
                return Some(r);
            }
        }
        None
    }

    /// Ends the window in progress as invalid with `fault` (e.g. a timeout found by polling).
    pub fn abort(&mut self, window: &Window, timer_hz: f32, fault: Fault) -> Option<WindowReport> {
        let was = self.started;
        self.started = false;
        self.prev_mean = 0.0;
        if was {
            Some(self.report(window, timer_hz, Some(fault)))
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn load_order_gives_whole_cycles() {
        assert_eq!(WindowLength::LoadOrder(0.125).revolutions(), Ok(8));
        assert_eq!(WindowLength::LoadOrder(1.0).revolutions(), Ok(1));
        assert_eq!(WindowLength::LoadOrder(2.0).revolutions(), Ok(1));
        assert_eq!(WindowLength::LoadOrder(1.5).revolutions(), Ok(2));
        assert_eq!(WindowLength::LoadOrder(2.0 / 3.0).revolutions(), Ok(3));
        assert_eq!(
            WindowLength::LoadOrder(f64::NAN).revolutions(),
            Err(ConfigError::NonFinite("window.load_order"))
        );
        assert_eq!(
            WindowLength::LoadOrder(1e-6).revolutions(),
            Err(ConfigError::OutOfRange("window.load_order"))
        );
        assert_eq!(
            WindowLength::Revolutions(0).revolutions(),
            Err(ConfigError::OutOfRange("window.revolutions"))
        );
    }

    #[test]
    fn cross_product_difference_matches_exact_f64() {
        // Products of f32 values are exact in f64; their difference is exact to 2^-53 of the
        // larger product. The split products must agree with it to one f32 rounding of the
        // result plus 2^-46 of the products, and cancel exactly for equal products.
        let mut seed = 0x2545_f491_u32;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed
        };
        for _ in 0..20_000 {
            let a1 = 1e-3 + (next() % 1_000_000) as f32 * 1e-7;
            let a2 = a1 * (1.0 + ((next() % 2001) as f32 - 1000.0) * 1e-5);
            // Counts on both sides of 2^24, where f32 stops holding them exactly.
            let t1 = 1_000 + next() % 50_000_000;
            let t2 = (t1 + next() % 20_001).saturating_sub(10_000).max(1);
            let exact = a1 as f64 * t2 as f64 - a2 as f64 * t1 as f64;
            let scale = (a1 as f64 * t2 as f64)
                .abs()
                .max((a2 as f64 * t1 as f64).abs());
            let got = cross(a1, t2, a2, t1) as f64;
            let bound = exact.abs() * f32::EPSILON as f64 + scale * 2f64.powi(-46);
            assert!(
                (got - exact).abs() <= bound,
                "{a1} {t2} {a2} {t1}: {got} vs {exact}"
            );
            assert_eq!(cross(a1, t1, a1, t1), 0.0);
        }
        // Equal products from different factors cancel too.
        assert_eq!(cross(0.5, 6, 1.5, 2), 0.0);
    }

    #[test]
    fn u64_conversion_matches_the_cast() {
        for x in [
            0u64,
            1,
            16_777_217,
            u32::MAX as u64,
            u32::MAX as u64 + 1,
            u64::MAX,
        ] {
            assert_eq!(u64_to_f32(x), x as f32);
        }
    }

    #[test]
    fn cross_product_difference_is_exact_for_close_speeds() {
        // Two samples differing by one tick in 1e7: δ = 2e-7 must not be lost in rounding;
        // nor one tick in 3e9, where each count rounds to a multiple of 256 in f32.
        let a = 0.006_135_923_f32;
        for (t1, t2) in [
            (10_000_000u32, 10_000_001u32),
            (3_000_000_001, 3_000_000_002),
        ] {
            let num = cross(a, t2, a, t1);
            let exact = a as f64 * 1.0;
            assert!(
                (num as f64 - exact).abs() <= 1e-7 * exact,
                "{num} vs {exact}"
            );
        }
    }
}
