//! Running irregularity δ over one load cycle, from framed speed samples.
//!
//! δ must be taken over a window that is one period of the load cycle: the seed's kneader load
//! has order 1/8, so its cycle is 8 revolutions and a per-revolution δ would see only part of
//! the swing. A window starts at a frame (tooth 0) and ends after `W` whole revolutions, so the
//! mean speed is exact: ω_mean = W·2π / (sum of the window's intervals), the intervals summed
//! as integers (no drift over any run length).
//!
//! Reported per window: where it starts and ends (accepted-edge numbers and capture ticks), and
//! either its [`Measurement`] — ωmax, ωmin, ω_mean, δ = 2(ωmax − ωmin)/(ωmax + ωmin) (seed 000,
//! eq. 13), the spread (ωmax − ωmin)/ω_mean, the quantization noise floor and whether the
//! speed was steady — or the fault that cut it short (an invalid window carries no numbers).
//! No filtering happens before δ: a low-pass would remove exactly the ripple δ measures.
//!
//! The extremes are kept as exact samples (angle units over ticks, see [`crate::encoder`])
//! and compared by 64-bit cross products, so the per-edge work is integer compares; δ is formed
//! once per window from the exact products.

// The per-edge path runs through this module: no integer operation here may overflow or
// divide by zero, and no index may fail, in a debug build either (`panic-free.sh dev` in
// examples/qemu checks the image).
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::indexing_slicing)
)]

use crate::error::{positive, positive_f32, tri, ConfigError};
use crate::math;
use crate::speed::{Fault, Sample, Tooth};

/// Largest window, in revolutions.
pub const MAX_WINDOW_REVS: u16 = 1024;

/// How long a δ window is.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum WindowLength {
    /// A fixed number of revolutions. For a load of several orders, their common period:
    /// [`crate::drive::period_revolutions`] (or [`crate::drive::DriveModel::period_revolutions`]).
    Revolutions(u16),
    /// One load order (cycles per revolution, e.g. 0.125 for one load cycle per 8
    /// revolutions). The window is the smallest whole number of revolutions holding a whole
    /// number of its cycles (order within 1e-4 relative of a fraction with denominator ≤ 1024).
    /// That is the load's period when the load has this one order, or when every other order
    /// is a whole multiple of it: for other loads give their fundamental order (1/6 for orders
    /// 1/3 and 1/2, which repeat every 6 revolutions), or their period as
    /// [`Revolutions`](Self::Revolutions). A window of the lowest order alone is shorter than
    /// such a load's period and reads δ low.
    LoadOrder(f64),
}

impl WindowLength {
    /// The window in revolutions.
    pub const fn revolutions(self) -> Result<u16, ConfigError> {
        match self {
            WindowLength::Revolutions(n) => {
                if n == 0 || n > MAX_WINDOW_REVS {
                    Err(ConfigError::OutOfRange("window.revolutions"))
                } else {
                    Ok(n)
                }
            }
            WindowLength::LoadOrder(order) => {
                let order = tri!(positive("window.load_order", order));
                let mut w = 1u16;
                while w <= MAX_WINDOW_REVS {
                    let cycles = order * w as f64;
                    let whole = math::round(cycles);
                    let off = cycles - whole;
                    if whole >= 1.0 && off <= 1e-4 * cycles && -off <= 1e-4 * cycles {
                        return Ok(w);
                    }
                    w = w.wrapping_add(1);
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
    pub const fn validate(self) -> Result<Window, ConfigError> {
        let revolutions = tri!(self.length.revolutions());
        let t = tri!(positive_f32("steady_tolerance", self.steady_tolerance));
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
    /// The window of an unconfigured monitor (one revolution); `configure` replaces it.
    pub(crate) const UNCONFIGURED: Window = Window {
        revolutions: 1,
        steady_tolerance: 0.02,
    };

    /// Revolutions per window.
    pub const fn revolutions(&self) -> u16 {
        self.revolutions
    }
}

/// What a valid window measured.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Measurement {
    /// Largest speed sample, rad/s.
    pub omega_max: f32,
    /// Smallest speed sample, rad/s (never above `omega_max`).
    pub omega_min: f32,
    /// Mean speed, angle over time, rad/s.
    pub omega_mean: f32,
    /// δ = 2(ωmax − ωmin)/(ωmax + ωmin).
    pub delta: f32,
    /// (ωmax − ωmin)/ω_mean.
    pub spread: f32,
    /// Bound on the error of δ from timer quantization: 1/t_max + 1/t_min, the ticks of the
    /// fastest and the slowest speed sample (on a steady shaft 2 / (ticks per sample)).
    pub noise_floor: f32,
    /// Speed samples taken.
    pub samples: u32,
    /// The mean speed was within the steady tolerance of the previous valid window's.
    pub steady: bool,
}

/// One window: where it lies and what it measured, or why it is invalid.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WindowReport {
    /// Number of the accepted edge the window starts at (the tracker's running count).
    pub start_edge: u32,
    /// Number of the last accepted edge in the window.
    pub end_edge: u32,
    /// Capture time of the start edge, ticks.
    pub start_ticks: u32,
    /// Capture time of the end (the last edge, or where the fault was found), ticks.
    pub end_ticks: u32,
    /// Whole revolutions covered (the configured count for a valid window).
    pub revolutions: u16,
    /// The measurement, or the fault that cut the window short.
    pub result: Result<Measurement, Fault>,
}

impl WindowReport {
    /// A complete window with no fault.
    pub fn valid(&self) -> bool {
        self.result.is_ok()
    }
    /// The measurement of a valid window.
    pub fn measurement(&self) -> Option<&Measurement> {
        self.result.as_ref().ok()
    }
    /// The fault of an invalid window.
    pub fn fault(&self) -> Option<Fault> {
        self.result.err()
    }
}

/// Per-window accumulation state.
#[derive(Debug, Clone)]
pub struct WindowState {
    started: bool,
    revs: u16,
    /// Sum of the window's intervals, ticks.
    ticks: u64,
    start_edge: u32,
    start_ticks: u32,
    max: Sample,
    min: Sample,
    /// Mean speed of the previous valid window (0 when none).
    prev_mean: f32,
}

impl Default for WindowState {
    fn default() -> Self {
        Self::new()
    }
}

/// `x as f32` from the FPU's 32-bit conversions: exact rounding when `x` fits in 32 bits, and
/// within about one unit in the last place above (high and low words converted and joined;
/// the software 64-bit conversion would cost some 50 instructions on a 32-bit core). Once
/// per window result: out of line, one copy for its six uses.
#[inline(never)]
fn u64_to_f32(x: u64) -> f32 {
    match u32::try_from(x) {
        Ok(x) => x as f32,
        Err(_) => ((x >> 32) as u32) as f32 * 4_294_967_296.0 + (x as u32) as f32,
    }
}

const NO_SAMPLE: Sample = Sample { span: 0, ticks: 0 };
/// The extremes a window starts from: slower and faster than any sample (speed 0 and ∞), so
/// the first sample replaces both without a separate first-sample test per edge.
const SLOWEST: Sample = Sample {
    span: 0,
    ticks: u32::MAX,
};
const FASTEST: Sample = Sample { span: 1, ticks: 0 };

impl WindowState {
    /// No window in progress.
    pub const fn new() -> Self {
        WindowState {
            started: false,
            revs: 0,
            ticks: 0,
            start_edge: 0,
            start_ticks: 0,
            max: NO_SAMPLE,
            min: NO_SAMPLE,
            prev_mean: 0.0,
        }
    }

    /// Back to [`WindowState::new`] in place without a call of `memset` (its 40 bytes are
    /// zeros: see [`crate::speed::EdgeCounters::clear`]).
    /// `z` is an opaque zero (see [`crate::speed::EdgeCounters::clear`]).
    pub(crate) fn clear(&mut self, z: u32) {
        let none = Sample { span: z, ticks: z };
        *self = WindowState {
            started: false,
            revs: 0,
            ticks: u64::from(z),
            start_edge: z,
            start_ticks: z,
            max: none,
            min: none,
            prev_mean: 0.0,
        };
    }

    /// Whether a window is in progress.
    pub fn started(&self) -> bool {
        self.started
    }

    #[inline(never)] // once a window: one copy for its callers (code size)
    fn restart(&mut self, edge: u32, ticks: u32) {
        self.started = true;
        self.revs = 0;
        self.ticks = 0;
        self.start_edge = edge;
        self.start_ticks = ticks;
        self.max = SLOWEST;
        self.min = FASTEST;
    }

    /// Takes one speed sample: integer compares, no division (the extremes are exact). With
    /// `uniform` spans (every sample the same angle) only the tick counts are compared.
    #[inline(always)]
    fn take(&mut self, s: Sample, uniform: bool) {
        if uniform {
            if s.ticks < self.max.ticks {
                self.max = s;
            }
            if s.ticks > self.min.ticks {
                self.min = s;
            }
            return;
        }
        // Cross products, exact in 64 bits (two u32 factors: no wrap).
        let cross = |a: u32, b: u32| u64::from(a).wrapping_mul(u64::from(b));
        if cross(s.span, self.max.ticks) > cross(self.max.span, s.ticks) {
            self.max = s;
        }
        if cross(s.span, self.min.ticks) < cross(self.min.span, s.ticks) {
            self.min = s;
        }
    }

    /// Adds an ordinary tooth (not a frame) of `dt` ticks with its sample to the window in
    /// progress, if any: the per-edge work of a window. Every accepted edge of a running
    /// window brings a sample (a window whose first edge after its frame brings none, the
    /// `K`-edge ring not full again after a fault or the sync, does not run: it starts at the
    /// next frame), so the window's samples are its edges.
    #[inline(always)]
    pub(crate) fn add(&mut self, dt: u32, sample: Option<Sample>, uniform: bool) {
        // Before a window starts this accumulates nothing that matters: a start resets it all.
        // Bounded like the sample count: the wrapping add is exact.
        self.ticks = self.ticks.wrapping_add(u64::from(dt));
        if let Some(s) = sample {
            self.take(s, uniform);
        }
    }

    /// The window's extremes as tick counts of samples of equal span (uniform discs): the
    /// slowest and the fastest.
    #[inline]
    pub(crate) fn uniform_extremes(&self) -> (u32, u32) {
        (self.min.ticks, self.max.ticks)
    }

    /// Folds a run of ordinary teeth into the window: `ticks` more, extremes now `(slowest,
    /// fastest)` as tick counts of samples spanning `span` units each.
    #[inline]
    pub(crate) fn add_run(&mut self, ticks: u64, (slowest, fastest): (u32, u32), span: u32) {
        self.ticks = self.ticks.wrapping_add(ticks);
        self.min = Sample {
            span,
            ticks: slowest,
        };
        self.max = Sample {
            span,
            ticks: fastest,
        };
    }

    fn measurement(
        &self,
        window: &Window,
        end_edge: u32,
        unit_rad: f32,
        timer_hz: f32,
    ) -> Measurement {
        let (a1, t1) = (u64::from(self.max.span), u64::from(self.max.ticks));
        let (a2, t2) = (u64::from(self.min.span), u64::from(self.min.ticks));
        // δ = 2(a1/t1 − a2/t2)/(a1/t1 + a2/t2) = 2(a1·t2 − a2·t1)/(a1·t2 + a2·t1), from the
        // exact integer products: never a difference of two rounded speeds.
        // (Products of two u32: no wrap; with spans ≤ 2^30 their sum is below 2^63.)
        let p1 = a1.wrapping_mul(t2);
        let p2 = a2.wrapping_mul(t1);
        let num = p1.saturating_sub(p2);
        let den = p1.wrapping_add(p2);
        let delta = if den > 0 {
            2.0 * (u64_to_f32(num) / u64_to_f32(den))
        } else {
            0.0
        };
        let omega_max = if t1 > 0 {
            a1 as f32 * unit_rad * timer_hz / t1 as f32
        } else {
            0.0
        };
        // ωmin = ωmax·(a2·t1)/(a1·t2): the ratio of the exact products is at most 1 and stays
        // so through monotone rounding, so ωmin never exceeds ωmax (no negative spread).
        let omega_min = if p1 > 0 {
            omega_max * (u64_to_f32(p2) / u64_to_f32(p1))
        } else {
            0.0
        };
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
        let samples = end_edge.wrapping_sub(self.start_edge);
        // Each sample's ticks are off by less than one (a difference of two latched times), so
        // δ is off by less than 1/t1 + 1/t2 to first order (dδ/d ln x ≤ 1 for x = a1·t2/(a2·t1)):
        // the two extreme samples' own ticks, not the window's mean per sample, which a wheel's
        // gap (one sample over three pitches) raised above the ordinary teeth's, so that timer
        // rounding alone exceeded the floor.
        let noise_floor = if t1 > 0 && t2 > 0 {
            1.0 / t1 as f32 + 1.0 / t2 as f32
        } else {
            1.0
        };
        let steady = self.prev_mean > 0.0
            && (omega_mean - self.prev_mean).abs() < window.steady_tolerance * omega_mean;
        Measurement {
            omega_max,
            omega_min,
            omega_mean,
            delta,
            spread,
            noise_floor,
            samples,
            steady,
        }
    }

    fn report(
        &self,
        end_edge: u32,
        end_ticks: u32,
        result: Result<Measurement, Fault>,
    ) -> WindowReport {
        WindowReport {
            start_edge: self.start_edge,
            end_edge,
            start_ticks: self.start_ticks,
            end_ticks,
            revolutions: self.revs,
            result,
        }
    }

    /// Feeds one accepted edge; returns a report when a window ends. `uniform`: every sample
    /// spans the same angle (a uniform disc at its nominal pitches). `unit_rad`, `timer_hz` and `k` are the encoder's (see
    /// [`crate::encoder::Encoder`]).
    ///
    /// One copy for each kind of sample, picked inline: a caller that knows the kind at
    /// compile time (the monitor) links only its own (a DMA-fed firmware's window code was
    /// 772 bytes with both kinds in one copy, 704 with its own; the window's measurement is
    /// then out of line).
    #[inline(always)]
    pub fn on_tooth(
        &mut self,
        window: &Window,
        tooth: &Tooth,
        unit_rad: f32,
        timer_hz: f32,
        uniform: bool,
    ) -> Option<WindowReport> {
        let mut ended = None;
        self.on_tooth_to(window, tooth, (unit_rad, timer_hz), uniform, &mut ended);
        ended
    }

    /// [`WindowState::on_tooth`], the report of a window that ends written to `ended` (left
    /// as it is otherwise): the monitor's slot for it, with no copy through a return value.
    #[inline(always)]
    pub(crate) fn on_tooth_to(
        &mut self,
        window: &Window,
        tooth: &Tooth,
        (unit_rad, timer_hz): (f32, f32),
        uniform: bool,
        ended: &mut Option<WindowReport>,
    ) {
        if uniform {
            self.on_tooth_in::<true>(window, tooth, unit_rad, timer_hz, ended)
        } else {
            self.on_tooth_in::<false>(window, tooth, unit_rad, timer_hz, ended)
        }
    }

    #[inline(never)]
    fn on_tooth_in<const UNIFORM: bool>(
        &mut self,
        window: &Window,
        tooth: &Tooth,
        unit_rad: f32,
        timer_hz: f32,
        ended: &mut Option<WindowReport>,
    ) {
        let uniform = UNIFORM;
        if !tooth.synced {
            return;
        }
        if !self.started {
            if tooth.frame {
                self.restart(tooth.index, tooth.time);
            }
            return;
        }
        if tooth.sample.is_none() {
            // The ring of the last K intervals was not full again by the start: a fault (a
            // glitch, a lost tooth, reported with the window it cut) or the sync within K
            // edges before the frame. The window's first samples would be missing, its δ
            // over the rest too low (a user's 12-1 wheel, K = 8: 0.068 for 0.216): it starts
            // at the next frame instead. (Within a window, a tooth without a sample comes only
            // after a fault, which has ended the window already.)
            self.started = false;
            return;
        }
        self.add(tooth.dt, tooth.sample, uniform);
        if tooth.frame {
            self.revs = self.revs.saturating_add(1);
            if self.revs >= window.revolutions {
                let m = self.measurement(window, tooth.index, unit_rad, timer_hz);
                *ended = Some(self.report(tooth.index, tooth.time, Ok(m)));
                self.prev_mean = m.omega_mean;
                self.restart(tooth.index, tooth.time);
            }
        }
    }

    /// Ends the window in progress as invalid with `fault`, found at `time` after the
    /// accepted edge numbered `last_edge`.
    pub fn abort(&mut self, fault: Fault, time: u32, last_edge: u32) -> Option<WindowReport> {
        let was = self.started;
        self.started = false;
        self.prev_mean = 0.0;
        if was {
            Some(self.report(last_edge, time, Err(fault)))
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
    fn u64_conversion_is_the_cast_below_2_32_and_within_an_ulp_above() {
        for x in [0u64, 1, 16_777_217, u32::MAX as u64] {
            assert_eq!(u64_to_f32(x), x as f32);
        }
        // Above 32 bits: against the correctly rounded cast, over magnitudes 2^32 … 2^64
        // with low words that round both ways.
        let mut x = 0x9E37_79B9_7F4A_7C15u64;
        for shift in 0..32 {
            for _ in 0..200 {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                let v = (x >> shift) | (1u64 << (63 - shift));
                let (got, want) = (u64_to_f32(v), v as f32);
                let ulp = f32::from_bits(want.to_bits() + 1) - want;
                assert!((got - want).abs() <= ulp, "{v}: {got} against {want}");
            }
        }
        assert_eq!(u64_to_f32(u64::MAX), u64::MAX as f32);
    }

    fn window(revs: u16) -> Window {
        WindowConfig {
            length: WindowLength::Revolutions(revs),
            steady_tolerance: 0.02,
        }
        .validate()
        .unwrap()
    }

    fn tooth(index: u32, time: u32, dt: u32, frame: bool, sample: Option<Sample>) -> Tooth {
        Tooth {
            index,
            time,
            dt,
            tooth: 0,
            synced: true,
            frame,
            sample,
        }
    }

    #[test]
    fn delta_is_exact_for_close_speeds() {
        // Two samples one tick apart in 1e7 (δ = 2e-7) and in 3e9 (each count rounds to a
        // multiple of 256 in f32): δ comes from the exact products, not from rounded speeds.
        let w = window(1);
        for (t1, t2) in [
            (10_000_000u32, 10_000_001u32),
            (3_000_000_001, 3_000_000_002),
        ] {
            let mut st = WindowState::new();
            let span = 1 << 20;
            st.on_tooth(&w, &tooth(0, 0, 0, true, None), 1e-6, 1e6, false);
            st.on_tooth(
                &w,
                &tooth(1, 1, 1, false, Some(Sample { span, ticks: t1 })),
                1e-6,
                1e6,
                false,
            );
            let r = st
                .on_tooth(
                    &w,
                    &tooth(2, 2, 1, true, Some(Sample { span, ticks: t2 })),
                    1e-6,
                    1e6,
                    false,
                )
                .unwrap();
            let m = r.measurement().unwrap();
            let exact = 2.0 * (f64::from(t2) - f64::from(t1)) / (f64::from(t2) + f64::from(t1));
            assert!(
                (f64::from(m.delta) / exact - 1.0).abs() < 1e-6,
                "{m:?} {exact}"
            );
            assert!(m.omega_min <= m.omega_max);
            assert_eq!((r.start_edge, r.end_edge, r.revolutions), (0, 2, 1));
        }
    }

    #[test]
    fn equal_speeds_from_different_spans_give_no_negative_spread() {
        // 3 units in 7 ticks and 6 in 14: the same speed, compared exactly; the minimum is
        // never reported above the maximum however the f32 conversions round.
        let w = window(1);
        let mut seed = 0x9e37_79b9_u32;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 17;
            seed ^= seed << 5;
            seed
        };
        for _ in 0..2000 {
            let a = 1 + next() % (1 << 20);
            let t = 1 + next() % (1 << 20);
            let m = 1 + next() % 1000;
            let mut st = WindowState::new();
            st.on_tooth(&w, &tooth(0, 0, 0, true, None), 1.0e-5, 84e6, false);
            st.on_tooth(
                &w,
                &tooth(1, 1, t, false, Some(Sample { span: a, ticks: t })),
                1.0e-5,
                84e6,
                false,
            );
            let r = st
                .on_tooth(
                    &w,
                    &tooth(
                        2,
                        2,
                        t,
                        true,
                        Some(Sample {
                            span: a * m,
                            ticks: t * m,
                        }),
                    ),
                    1.0e-5,
                    84e6,
                    false,
                )
                .unwrap();
            let m = r.measurement().unwrap();
            assert_eq!(m.delta, 0.0);
            assert!(m.omega_min <= m.omega_max && m.spread >= 0.0, "{m:?}");
        }
    }

    #[test]
    fn an_aborted_window_carries_its_span_and_no_numbers() {
        let w = window(4);
        let mut st = WindowState::new();
        st.on_tooth(&w, &tooth(7, 100, 0, true, None), 1e-6, 1e6, false);
        st.on_tooth(
            &w,
            &tooth(
                8,
                200,
                100,
                false,
                Some(Sample {
                    span: 1,
                    ticks: 100,
                }),
            ),
            1e-6,
            1e6,
            false,
        );
        let r = st.abort(Fault::Glitch, 250, 8).unwrap();
        assert_eq!(r.result, Err(Fault::Glitch));
        assert_eq!(
            (r.start_edge, r.end_edge, r.start_ticks, r.end_ticks),
            (7, 8, 100, 250)
        );
        assert!(r.measurement().is_none());
        assert!(st.abort(Fault::Glitch, 260, 8).is_none());
    }
}
