//! Hard cases: inputs where a naive evaluation of a formula loses its digits, divides by zero
//! or returns NaN, each checked through the public API against a more careful reference with a
//! stated tolerance (issue 8). Sections: predicted δ, measured δ and timing, characteristic
//! speeds of auto-balancer machines, support unbalance, validation, and totality of every
//! runtime entry point.
//!
//! Every test comment names the case, the reference, the tolerance and why that tolerance.

#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::needless_range_loop
)]

#[path = "../src/testutil.rs"]
mod testutil;

use drive_monitor::alarm::AlarmConfig;
use drive_monitor::balancer::{
    AutoBalancer, BalancerKind, Classifier, Coupling, Machine, MachineConfig, Platform, Regime,
    RegimeTracker, SearchOptions, ZoneKind,
};
use drive_monitor::drive::{DriveModel, Harmonic, Horizon, Kloss, Load, Parabola, Prediction};
use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator, Wheel};
use drive_monitor::irregularity::{Measurement, WindowConfig, WindowLength, WindowReport};
use drive_monitor::learn::ToothLearner;
use drive_monitor::monitor::DeltaMonitor;
use drive_monitor::pitch::Corrected;
use drive_monitor::speed::{Direction, Fault};
use drive_monitor::supports::{
    equivalent_planes, Level, Limits, ProcessLoad, Rotor, SupportAnalysis, Unbalance, Vec2,
};
use drive_monitor::{ConfigError, Libm, Micromath};
use proptest::prelude::*;
use std::collections::VecDeque;
use std::f64::consts::{PI, TAU};
use testutil::{
    compare_with_scan, coupling, drive, h, paper_terms, platform, reference_speeds, scaled_config,
    seed_motor, steady, BAD, BAD_F32, BAD_F32_NON_NEGATIVE, BAD_NON_NEGATIVE, J, M1, MM, W0, WM,
};

/// Unit roundoff of f32 (half an ulp of 1).
const U32: f64 = f32::EPSILON as f64 / 2.0;
/// Unit roundoff of f64.
const U64: f64 = f64::EPSILON / 2.0;

fn rel(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / b.abs()
    }
}

// =============================================================================================
// Predicted δ (drive model, seed 000 eq. 11–13)
// =============================================================================================

/// δ from r = R/ū without cancellation: ωmax,min = √ū·√(1 ± r), so
/// δ = 2(√(1+r) − √(1−r))/(√(1+r) + √(1−r)) = 2r/(1 + √(1 − r²)).
fn delta_of_r(r: f64) -> f64 {
    2.0 * r / (1.0 + ((1.0 - r) * (1.0 + r)).sqrt())
}

/// Case: tiny predicted δ (1e-7 … 1e-13) where ωmax − ωmin cancels, reached by a small load
/// amplitude M2 (not by a large J, which the unit tests cover).
/// Reference: the cancellation-free exact form 2r/(1 + √(1 − r²)) on the paper's coefficients.
/// Tolerance 1e-12 relative: both sides are a handful of correctly rounded f64 operations on
/// the same inputs, with no subtraction of nearly equal numbers (the model takes ωmax − ωmin
/// as (smax − smin)/(ωmax + ωmin)); 1e-12 leaves 4 decades above f64 rounding.
/// Second check, several orders (a searched, not closed-form, extremum): scaling every
/// amplitude by λ scales the oscillation of ω² exactly by λ, so δ·(ωmax + ωmin)²/2 = λ·Δs₁
/// with Δs₁ = ωmax² − ωmin² at λ = 1 (no cancellation there, δ ≈ 0.04); 1e-12 again.
#[test]
fn predicted_tiny_delta_keeps_its_digits() {
    let seed_delta = steady(&drive(&[h(0.125, 12.0, 0.0)], J)).delta;
    for target in [1e-7, 1e-10, 1e-13] {
        let m2 = 12.0 * target / seed_delta;
        let s = steady(&drive(&[h(0.125, m2, 0.0)], J));
        let (ubar, r_amp) = paper_terms(m2, 0.125, J);
        let reference = delta_of_r(r_amp / ubar);
        assert!(rel(s.delta, target) < 1e-3, "{} vs {target}", s.delta);
        assert!(
            rel(s.delta, reference) < 1e-12,
            "δ {} vs {reference}",
            s.delta
        );
    }
    let hs = |lambda: f64| {
        [
            h(0.125, 12.0 * lambda, 0.0),
            h(0.5, 6.0 * lambda, 1.0),
            h(1.0, 9.0 * lambda, -0.4),
        ]
    };
    let one = steady(&drive(&hs(1.0), J));
    assert!(matches!(one.horizon, Horizon::Period { .. }));
    let ds1 = one.omega_max.powi(2) - one.omega_min.powi(2);
    for lambda in [1e-5, 1e-8, 1e-11] {
        let s = steady(&drive(&hs(lambda), J));
        let w = s.omega_max + s.omega_min;
        let ds = s.delta * w * w / 2.0;
        assert!(
            rel(ds, lambda * ds1) < 1e-12,
            "λ {lambda}: {ds} vs {}",
            lambda * ds1
        );
    }
}

/// Case: a drive at the edge of stalling (no steady state): the peak load amplitude crosses
/// M2* = ū·√(4a² + n²J²)/2, where the periodic ω² first touches zero.
/// Reference: M2* from the paper's coefficients (R(M2*) = ū exactly), and δ from 2r/(1+√(1−r²)).
/// Tolerances: the prediction switches from `Steady` to `Stalls` between M2*·(1 − 1e-9) and
/// M2*·(1 + 1e-9) (1e-9 is 10⁷ ulps: far above the rounding of either M2* computation, far
/// below any physical meaning). Just below, δ is within 1e-9 relative of the reference: the
/// problem's condition number there is 1/√(1 − r²) ≈ 2·10⁴, so f64 rounding allows ~1e-11.
/// Every number stays finite (no NaN from √ of a negative ω²), the host summary reports δ = 2
/// and ωmin = 0, sensitivities are absent, and the closed-form flywheel makes δ exactly the
/// limit again (1e-12).
#[test]
fn stalled_drive_is_a_state_not_a_nan() {
    let n = 0.125;
    let (ubar, r1) = paper_terms(1.0, n, J);
    let m2_star = ubar / r1;
    let below = drive(&[h(n, m2_star * (1.0 - 1e-9), 0.0)], J);
    let above = drive(&[h(n, m2_star * (1.0 + 1e-9), 0.0)], J);
    let s = steady(&below);
    assert!(s.omega_min > 0.0 && s.omega_min.is_finite());
    let (_, r_amp) = paper_terms(m2_star * (1.0 - 1e-9), n, J);
    let reference = delta_of_r(r_amp / ubar);
    assert!(rel(s.delta, reference) < 1e-9, "{} vs {reference}", s.delta);
    assert!(s.delta < 2.0 && s.delta > 1.999);
    let Prediction::Stalls(st) = above.predict() else {
        panic!("expected a stall above M2*")
    };
    assert!(st.u_min <= 0.0 && st.u_min > -1e-7 * ubar && st.u_mean.is_finite());
    assert!(above.sensitivity().is_none());
    let irr = above.irregularity(Some(0.06)).unwrap();
    assert!(!irr.steady_state);
    assert_eq!((irr.omega_min, irr.delta), (0.0, 2.0));
    assert!(irr.omega_max.is_finite() && irr.omega_max > 0.0);
    for phi in [0.0, 1.0, 1e6, f64::MAX] {
        assert!(!above.omega_squared(phi).is_nan());
    }
    let extra = above.flywheel_for(0.06).unwrap();
    let fixed = steady(&above.with_flywheel(extra).unwrap());
    assert!(rel(fixed.delta, 0.06) < 1e-12, "{}", fixed.delta);
    // The mean load above the motor's stall torque B: u_mean ≤ 0, no flywheel helps.
    let b = seed_motor().model().b();
    let over = DriveModel::new(
        seed_motor(),
        Load::new(b * (1.0 + 1e-12), &[]).unwrap(),
        J,
        0.0,
    )
    .unwrap();
    assert!(matches!(over.predict(), Prediction::Stalls(s) if s.u_mean <= 0.0));
}

/// Case: J → ∞ in eq. 11 (a huge flywheel), J from 10³ to 10³⁰⁰ kg·m².
/// Reference: the asymptote δ∞ = 2·M2/(n·J·ū) with its two known relative corrections:
/// −(2a/(nJ))²/2 from √(4a² + n²J²) and +r²/4 from the δ(r) series, so
/// |δ/δ∞ − 1| ≤ (2a/(nJ))² + r² (a safe bound on both) plus 1e-13 for rounding.
/// Nothing may underflow to 0 or overflow on the way (δ ≈ 1e-302 at J = 1e300 is still a
/// normal f64), and the angles of the extremes stay finite.
#[test]
fn huge_inertia_limit_of_eq_11() {
    let a = MM / (W0 * W0 - WM * WM);
    let ubar = W0 * W0 - M1 / a;
    for e in [3, 6, 12, 24, 50, 100, 200, 300] {
        let j = 10f64.powi(e);
        let s = steady(&drive(&[h(0.125, 12.0, 0.0)], j));
        let asym = 2.0 * 12.0 / (0.125 * j * ubar);
        let bound = (2.0 * a / (0.125 * j)).powi(2) + asym * asym + 1e-13;
        assert!(s.delta > 0.0 && s.delta.is_normal(), "J {j}: {}", s.delta);
        assert!(rel(s.delta, asym) < bound, "J {j}: {} vs {asym}", s.delta);
        assert!(s.phi_max.unwrap().is_finite() && s.phi_min.unwrap().is_finite());
    }
}

/// Case: n → 0 in eq. 11 (a quasi-static load: the harmonic is so slow that the drive follows
/// the torque balance), n from 1e-2 down to the smallest normal f64.
/// Reference: the quasi-static limit, u = ū − (M2/a)·sin(nφ), i.e. r = M2/(a·ū) and
/// δ = 2r/(1 + √(1 − r²)), whose relative correction is (nJ/(2a))²·(…) ≤ (nJ/2a)²·10;
/// tolerance that bound plus 1e-13 (rounding). The extremal angles scale like 1/n and must
/// come out finite or absent, never NaN (2π/n overflows for n < 3.5e-308), and the
/// sensitivities must still exist.
#[test]
fn quasi_static_limit_of_eq_11() {
    let a = MM / (W0 * W0 - WM * WM);
    let ubar = W0 * W0 - M1 / a;
    let quasi = delta_of_r(12.0 / a / ubar);
    for n in [
        1e-2,
        1e-4,
        1e-8,
        1e-30,
        1e-200,
        1e-300,
        1e-307,
        f64::MIN_POSITIVE,
    ] {
        let m = drive(&[h(n, 12.0, 0.3)], J);
        let s = steady(&m);
        let bound = 10.0 * (n * J / (2.0 * a)).powi(2) + 1e-13;
        assert!(rel(s.delta, quasi) < bound, "n {n}: {} vs {quasi}", s.delta);
        for p in [s.phi_max, s.phi_min].into_iter().flatten() {
            assert!(p.is_finite() && p >= 0.0, "n {n}: {s:?}");
        }
        let sens = m.sensitivity().expect("steady state has sensitivities");
        assert!(sens.d_delta_d_inertia.is_finite() && sens.d_delta_d_breakdown_torque.is_finite());
    }
}

// =============================================================================================
// Measured δ and timing: exact pulse trains
// =============================================================================================

/// What a window of an exact pulse train must report, computed from the integer timestamps in
/// f64 (every quantity below is exact integer arithmetic followed by one or two roundings).
#[derive(Debug, Clone, Copy)]
struct Exact {
    delta: f64,
    omega_max: f64,
    omega_min: f64,
    omega_mean: f64,
    noise_floor: f64,
    samples: usize,
}

/// Exact reference for a uniform disc with an index pulse: the last `positions·revs` accepted
/// edges form the window; a speed sample spans `k` edges (all spans are the same angle, so
/// δ = 2(Smax − Smin)/(Smax + Smin) in the integer K-edge sums S).
struct ExactTrain {
    positions: usize,
    revs: usize,
    k: usize,
    timer_hz: f64,
    hist: VecDeque<u64>,
}

impl ExactTrain {
    fn new(positions: usize, revs: usize, k: usize, timer_hz: f64) -> Self {
        ExactTrain {
            positions,
            revs,
            k,
            timer_hz,
            hist: VecDeque::new(),
        }
    }

    fn push(&mut self, t: u64) {
        self.hist.push_back(t);
        // A window and its first sample's start, and the edges after its frame (a window is
        // returned with the edge after its frame).
        if self.hist.len() > self.positions * self.revs + self.k + 3 {
            self.hist.pop_front();
        }
    }

    /// How many edges after its frame edge (at `end_ticks`, the counter masked by `mask`) a
    /// window was returned: it is held for the edge after the frame.
    fn lag(&self, mask: u64, end_ticks: u32, what: &str) -> usize {
        (0..3)
            .find(|&l| {
                self.hist
                    .len()
                    .checked_sub(1 + l)
                    .is_some_and(|i| self.hist[i] & mask == u64::from(end_ticks))
            })
            .unwrap_or_else(|| panic!("{what}: no frame edge at {end_ticks} among the last 3"))
    }

    /// The window that ends `lag` edges before the newest.
    fn window(&self, lag: usize) -> Exact {
        let n = self.positions * self.revs;
        let h = &self.hist;
        let last = h.len() - 1 - lag;
        let (mut smax, mut smin) = (0u64, u64::MAX);
        for j in last + 1 - n..=last {
            let s = h[j] - h[j - self.k];
            smax = smax.max(s);
            smin = smin.min(s);
        }
        let span = self.k as f64 * TAU / self.positions as f64;
        let f = self.timer_hz;
        Exact {
            delta: 2.0 * (smax - smin) as f64 / (smax + smin) as f64,
            omega_max: span * f / smin as f64,
            omega_min: span * f / smax as f64,
            omega_mean: self.revs as f64 * TAU * f / (h[last] - h[last - n]) as f64,
            // One tick at each end of the two extreme samples: 1/t_fast + 1/t_slow.
            noise_floor: 1.0 / smin as f64 + 1.0 / smax as f64,
            samples: n,
        }
    }
}

/// A window report against the exact values of its train, at f32 precision.
/// Speeds: five f32 roundings at most (angle or 2π, timer rate, tick count, product, quotient):
/// 5·2⁻²⁴ = 3.0e-7. δ: computed as 2·(a·t2 − a·t1)/(a·t2 + a·t1) from exact integer ticks,
/// the difference of products error-free (FMA) — a few roundings relative to δ itself
/// (tolerance 8 roundings, 4.8e-7), however small δ is.
fn assert_matches_exact(r: &WindowReport, e: &Exact, what: &str) {
    let Some(r) = r.measurement() else {
        panic!("{what}: {r:?}");
    };
    assert_eq!(r.samples as usize, e.samples, "{what}");
    let speed_tol = 5.0 * U32 * 1.0001;
    assert!(
        rel(r.omega_mean as f64, e.omega_mean) <= speed_tol,
        "{what}: mean {} vs {}",
        r.omega_mean,
        e.omega_mean
    );
    assert!(
        rel(r.omega_max as f64, e.omega_max) <= speed_tol,
        "{what}: max {} vs {}",
        r.omega_max,
        e.omega_max
    );
    assert!(
        rel(r.omega_min as f64, e.omega_min) <= speed_tol,
        "{what}: min {} vs {}",
        r.omega_min,
        e.omega_min
    );
    assert!(
        (r.delta as f64 - e.delta).abs() <= 8.0 * U32 * e.delta,
        "{what}: δ {} vs exact {} (rel {:e})",
        r.delta,
        e.delta,
        rel(r.delta as f64, e.delta)
    );
    assert!(
        rel(r.noise_floor as f64, e.noise_floor) <= 3.0 * U32,
        "{what}: floor"
    );
}

fn encoder_config(
    positions: u16,
    timer_hz: f64,
    bits: u8,
    k: u16,
    min_speed: f64,
) -> EncoderConfig {
    let mut c = EncoderConfig::indexed(positions, timer_hz);
    c.counter_bits = bits;
    c.estimator = Estimator::Edges(k);
    c.min_speed = min_speed;
    c
}

fn monitor<const N: usize>(c: EncoderConfig, revs: u16) -> DeltaMonitor<N> {
    let w = WindowConfig {
        length: WindowLength::Revolutions(revs),
        steady_tolerance: 0.02,
    };
    DeltaMonitor::new(Encoder::new(c).unwrap(), w, None).unwrap()
}

/// Feeds `edges` edges (index pulse before every tooth 0, edge 0 is tooth 0) at the unwrapped
/// integer timestamps `t(k)`, offset by `start` and masked to the counter; every valid window
/// is checked against the exact train. Returns the reports.
#[allow(clippy::too_many_arguments)]
/// A window is returned with the edge after its frame edge: a stream that is to end a window
/// feeds one edge past its frame.
fn run_exact<const N: usize>(
    m: &mut DeltaMonitor<N>,
    k: usize,
    edges: u64,
    start: u64,
    mask: u64,
    mut t: impl FnMut(u64) -> u64,
    what: &str,
) -> Vec<(Measurement, Exact)> {
    let positions = m.encoder().edges() as usize;
    let revs = m.window_revolutions() as usize;
    let timer_hz = m.encoder().config().timer_hz;
    let mut exact = ExactTrain::new(positions, revs, k, timer_hz);
    let mut out = Vec::new();
    for e in 0..edges {
        let tk = t(e) + start;
        exact.push(tk);
        if e % positions as u64 == 0 {
            m.on_index((tk.wrapping_sub(1) & mask) as u32);
        }
        if let Some(o) = m.on_edge((tk & mask) as u32, Some(Direction::Forward)) {
            let x = exact.window(exact.lag(mask, o.report.end_ticks, what));
            assert_matches_exact(&o.report, &x, what);
            out.push((*o.report.measurement().unwrap(), x));
        }
    }
    out
}

/// Unwrapped integer timestamps from a periodic integer interval pattern.
fn pattern_times(intervals: &[u64]) -> impl FnMut(u64) -> u64 + '_ {
    let period: u64 = intervals.iter().sum();
    let mut prefix = vec![0u64; intervals.len()];
    for i in 1..intervals.len() {
        prefix[i] = prefix[i - 1] + intervals[i];
    }
    move |e: u64| {
        let n = intervals.len() as u64;
        (e / n) * period + prefix[(e % n) as usize]
    }
}

/// Capture times (s) of the edges of a uniform `positions`-line disc within one period of the
/// speed ω(φ) = ω̄·(1 + ε·sin(order·φ)), edge 0 at φ = 0: t(φ) = ∫dφ/ω by Simpson's rule,
/// 16 panels per pitch (truncation error ~1e-16 of a pitch's time: far below a tick).
/// Returns the times of edges 0..E (E edges per period) and the period.
fn ripple_times(positions: usize, omega: f64, eps: f64, order: f64) -> (Vec<f64>, f64) {
    let per_period = (positions as f64 / order).round() as usize;
    let pitch = TAU / positions as f64;
    let inv = |phi: f64| 1.0 / (omega * (1.0 + eps * (order * phi).sin()));
    let mut t = vec![0.0; per_period + 1];
    for i in 0..per_period {
        let (a, n) = (i as f64 * pitch, 16);
        let hh = pitch / n as f64;
        let mut s = inv(a) + inv(a + pitch);
        for j in 1..n {
            s += if j % 2 == 1 { 4.0 } else { 2.0 } * inv(a + j as f64 * hh);
        }
        t[i + 1] = t[i] + s * hh / 3.0;
    }
    let period = t[per_period];
    t.truncate(per_period);
    (t, period)
}

/// Integer capture timestamps (floor of time × rate, as a capture timer counts) of a shaft
/// running at ω(φ) = ω̄(1 + ε·sin(order·φ)).
fn shaft_ticks(
    positions: usize,
    omega: f64,
    eps: f64,
    order: f64,
    timer_hz: f64,
) -> impl FnMut(u64) -> u64 {
    let (t, period) = ripple_times(positions, omega, eps, order);
    move |e: u64| {
        let n = t.len() as u64;
        (((e / n) as f64 * period + t[(e % n) as usize]) * timer_hz).floor() as u64
    }
}

/// Case: a tiny measured δ (1e-5 … 1e-7) with a very fast timer (1 GHz and 200 MHz) and long
/// intervals (K-edge sums of 4·10⁷ … 2·10⁸ ticks, beyond f32's 2²⁴ exact integers), where
/// ωmax − ωmin cancels in f32 and each tick count rounds when converted to f32.
/// Reference: the exact δ of the integer pulse train, 2(Smax − Smin)/(Smax + Smin).
/// Tolerance (see `assert_matches_exact`): 8 f32 roundings relative to δ itself. The reported
/// quantization floor 2/S must be far below δ (resolvable): checked at < δ/4.
#[test]
fn measured_tiny_delta_equals_the_exact_delta_of_the_train() {
    // 16 lines, K = 4, one-revolution windows; interval pattern T0 + round(A·sin(2πi/16)).
    for (timer_hz, t0, amps) in [
        (1e9, 50_000_000u64, [300.0, 28.0, 3.0]),
        (200e6, 10_000_000u64, [60.0, 6.0, 3.0]),
    ] {
        for amp in amps {
            let intervals: Vec<u64> = (0..16)
                .map(|i| (t0 as f64 + (amp * (TAU * i as f64 / 16.0).sin()).round()) as u64)
                .collect();
            let c = encoder_config(16, timer_hz, 32, 4, 1.0);
            let mut m = monitor::<16>(c, 1);
            let what = format!("{timer_hz} Hz, A = {amp}");
            let out = run_exact(
                &mut m,
                4,
                16 * 6 + 2,
                0,
                u32::MAX as u64,
                pattern_times(&intervals),
                &what,
            );
            assert_eq!(out.len(), 5, "{what}");
            let (r, x) = out[4];
            assert!(x.delta > 0.0 && x.delta < 3e-5, "{what}: {x:?}");
            assert!(r.noise_floor < (x.delta / 4.0) as f32, "{what}: {r:?}");
        }
    }
}

/// Case: δ over a long run: 2 hours at 100 rad/s on a 64-line disc (7.3 million edges, 84 MHz
/// 32-bit timer wrapping 140 times), load order 1/8 (8-revolution windows), δ = 0.02, with the
/// capture timer's own rounding (timestamps are floor(t·f) of the exact time, so intervals
/// are not a repeating pattern).
/// Reference: each window's exact values from its integer timestamps (`assert_matches_exact`,
/// f32 precision), and the first window: after 2 hours the mean speed must equal the first
/// window's to 2 f32 ulps (the exact means differ by ≤ 1 tick in 4.3·10⁷), and δ within the
/// reported quantization floor. A running f32 sum of time would have drifted by whole
/// percent; integer interval sums cannot.
#[test]
fn delta_after_two_hours_equals_delta_at_the_start() {
    let (positions, omega, timer_hz) = (64usize, 100.0, 84e6);
    let edges = (7200.0 * omega / TAU * positions as f64) as u64;
    let edges = edges - edges % (8 * 64);
    let c = encoder_config(64, timer_hz, 32, 8, 10.0);
    let w = WindowConfig {
        length: WindowLength::LoadOrder(0.125),
        steady_tolerance: 0.02,
    };
    let mut m =
        DeltaMonitor::<64>::new(Encoder::new(c).unwrap(), w, Some(AlarmConfig::new(0.06))).unwrap();
    let t = shaft_ticks(positions, omega, 0.01, 0.125, timer_hz);
    let out = run_exact(&mut m, 8, edges, 0, u32::MAX as u64, t, "2 h run");
    assert_eq!(out.len() as u64, edges / 512 - 1);
    assert_eq!(m.diagnostics().invalid_windows, 0);
    let (first, _) = out[0];
    let (last, _) = *out.last().unwrap();
    assert!(rel(last.omega_mean as f64, first.omega_mean as f64) <= 4.0 * U32);
    assert!((last.delta - first.delta).abs() <= last.noise_floor);
    // The true δ of the shaft is 2ε = 0.02; sampling 8 of 512 edges and the floor bound it.
    assert!((last.delta as f64 - 0.02).abs() < 2e-5 + last.noise_floor as f64);
    assert!(out.iter().skip(1).all(|(r, _)| r.steady));
}

/// Case: the capture counter wraps at 2¹⁶ (every three edges) and at 2³² (once, mid-window).
/// Reference: the same integer intervals fed without any wrap (32-bit counter starting at 0).
/// Tolerance: none — the reports must be identical, since intervals are taken modulo the
/// counter before anything else. Each run is also checked against the exact train.
#[test]
fn counter_wrap_inside_a_window_changes_nothing() {
    // 32 lines at 10 MHz: ~20 000-tick intervals, δ ≈ 0.01, windows of 2 revolutions, K = 4.
    let intervals: Vec<u64> = (0..64)
        .map(|i| 20_000 + (100.0 * (TAU * i as f64 / 64.0).sin()).round() as u64)
        .collect();
    let run = |bits: u8, start: u64| {
        let c = encoder_config(32, 10e6, bits, 4, 40.0);
        let mut m = monitor::<32>(c, 2);
        let mask = (1u64 << bits) - 1;
        let out = run_exact(
            &mut m,
            4,
            32 * 20,
            start,
            mask,
            pattern_times(&intervals),
            "wrap",
        );
        (
            out.into_iter().map(|(r, _)| r).collect::<Vec<_>>(),
            m.diagnostics(),
        )
    };
    let (plain, d0) = run(32, 0);
    assert_eq!(plain.len(), 9);
    // The 2³² wrap lands inside the 5th window (between edges 300 and 301).
    let period: u64 = intervals.iter().sum();
    let t300 = 4 * period + intervals[..44].iter().sum::<u64>();
    let wrapped32 = run(32, (1u64 << 32) - t300 - 7_000);
    let wrapped16 = run(16, 12_345);
    assert_eq!(plain, wrapped32.0);
    assert_eq!(plain, wrapped16.0);
    assert_eq!(d0, wrapped32.1);
    assert_eq!(d0, wrapped16.1);
}

/// Case: a one-tick interval (a glitch one tick after a real edge), and a zero-tick one.
/// Reference: the glitch is rejected and counted, the window holding it is invalid with
/// `Fault::Glitch`, and the next real interval is measured from the last real edge, so every
/// later valid window matches the exact train of the real edges (f32 precision, as above).
#[test]
fn one_tick_interval_is_a_counted_glitch() {
    let intervals: Vec<u64> = (0..32)
        .map(|i| 50_000 + (300.0 * (TAU * i as f64 / 32.0).sin()).round() as u64)
        .collect();
    for extra in [1u64, 0] {
        let c = encoder_config(32, 10e6, 32, 4, 10.0);
        let mut m = monitor::<32>(c, 1);
        let mut t = pattern_times(&intervals);
        let mut exact = ExactTrain::new(32, 1, 4, 10e6);
        let (mut faults, mut valid) = (Vec::new(), 0);
        for e in 0..32 * 12u64 {
            let tk = t(e);
            exact.push(tk);
            if e % 32 == 0 {
                m.on_index((tk as u32).wrapping_sub(1));
            }
            for (ticks, real) in [(tk, true), (tk + extra, false)] {
                if !real && e != 32 * 5 + 7 {
                    continue;
                }
                if let Some(o) = m.on_edge(ticks as u32, Some(Direction::Forward)) {
                    match o.report.fault() {
                        None => {
                            let lag = exact.lag(u64::from(u32::MAX), o.report.end_ticks, "glitch");
                            assert_matches_exact(&o.report, &exact.window(lag), "after glitch");
                            valid += 1;
                        }
                        Some(f) => faults.push(f),
                    }
                }
            }
        }
        assert_eq!(faults, [Fault::Glitch], "extra {extra}");
        assert_eq!(m.diagnostics().edges.glitches, 1);
        assert_eq!(m.diagnostics().edges.accepted, 32 * 12 - 1);
        assert_eq!(valid, 9, "extra {extra}");
    }
}

/// Case: an interval of nearly the whole counter range, on a 16-bit counter at 1 MHz (65 000 of
/// 65 535 ticks) and a 32-bit counter at 1 GHz (4.29·10⁹ of 4.295·10⁹), with `min_speed` set just
/// low enough for the timeout to fit the counter.
/// Reference: exact train (f32 precision). One tick more than the timeout is a standstill
/// (`Fault::Timeout`), never an aliased short interval; a `min_speed` whose timeout would
/// exceed the counter is a typed error.
#[test]
fn interval_of_nearly_the_whole_counter_range() {
    // 8 lines at 1 MHz on 16 bits: timeout = (2π/8)/12 rad/s·1e6 = 65 450 ticks < 65 535.
    let c16 = encoder_config(8, 1e6, 16, 1, 12.0);
    assert_eq!(Encoder::new(c16).unwrap().timeout_ticks(), 65_450);
    let intervals: Vec<u64> = (0..8).map(|i| 65_000 + 50 * (i % 3)).collect();
    let mut m = monitor::<8>(c16, 1);
    let out = run_exact(
        &mut m,
        1,
        8 * 6,
        999,
        0xFFFF,
        pattern_times(&intervals),
        "16 bit",
    );
    assert_eq!(out.len(), 4);
    let mut bad = c16;
    bad.min_speed = 11.9;
    assert_eq!(
        Encoder::new(bad).unwrap_err(),
        ConfigError::Inconsistent("min_speed")
    );
    // 4 lines at 1 GHz on 32 bits: min_speed 0.3658 rad/s gives a timeout of 4.2941e9 ticks.
    let c32 = encoder_config(4, 1e9, 32, 1, 0.3658);
    let intervals: Vec<u64> = vec![4_290_000_000, 4_280_000_000, 4_294_000_000, 4_285_000_000];
    let mut m = monitor::<4>(c32, 1);
    let out = run_exact(
        &mut m,
        1,
        4 * 5,
        0,
        u32::MAX as u64,
        pattern_times(&intervals),
        "32 bit",
    );
    assert_eq!(out.len(), 3);
    // Past the timeout: standstill, counted; the window in progress is cut short.
    let mut m = monitor::<8>(c16, 1);
    let mut t = 0u64;
    for e in 0..20 {
        t += 65_000;
        if e % 8 == 0 {
            m.on_index(((t - 1) & 0xFFFF) as u32);
        }
        m.on_edge((t & 0xFFFF) as u32, Some(Direction::Forward));
    }
    let o = m.on_edge(((t + 65_451) & 0xFFFF) as u32, Some(Direction::Forward));
    assert_eq!(o.map(|o| o.report.fault()), Some(Some(Fault::Timeout)));
    assert_eq!(m.diagnostics().edges.timeouts, 1);
}

/// Case: very slow and very fast shafts, 1 rpm and 30 000 rpm, on a 1024-line disc, with 1 kHz,
/// 1 MHz, 84 MHz and 200 MHz timers on 16- and 32-bit counters; `min_speed` is half the shaft
/// speed, speed ripple δ = 0.01 (order 1, one-revolution windows), K = 16.
/// Rejected with a typed error: configurations whose timeout does not fit the counter
/// (`Inconsistent("min_speed")`: 1 rpm on 16 bits from 1 MHz up) and whose timer cannot
/// time one pitch at the minimum speed (`Inconsistent("timer_hz")`: 30 000 rpm at 1 kHz, a
/// pitch lasts 0.002 ticks).
/// Accepted ones are checked (1) against the exact train at f32 precision and (2) against the
/// true shaft: |δ − 0.01| ≤ reported floor + 1e-3·δ (K = 16 of 1024 edges attenuates the
/// ripple by (16π/1024)²/6 = 4e-4 relative), mean speed within one tick per revolution plus
/// 5 f32 roundings.
#[test]
fn one_rpm_and_thirty_thousand_rpm_from_1_khz_to_200_mhz() {
    let rpm = |n: f64| n * TAU / 60.0;
    let mut accepted = Vec::new();
    for speed in [rpm(1.0), rpm(30_000.0)] {
        for timer_hz in [1e3, 1e6, 84e6, 200e6] {
            for bits in [16u8, 32] {
                let c = encoder_config(1024, timer_hz, bits, 16, speed / 2.0);
                let case = format!("{:.0} rpm, {timer_hz:e} Hz, {bits} bit", speed * 60.0 / TAU);
                let enc = Encoder::new(c);
                let slow_pitch_ticks = TAU / 1024.0 / (speed / 2.0) * timer_hz;
                let expect = if slow_pitch_ticks < 2.0 {
                    Err(ConfigError::Inconsistent("timer_hz"))
                } else if slow_pitch_ticks >= ((1u64 << bits) - 1) as f64 {
                    Err(ConfigError::Inconsistent("min_speed"))
                } else {
                    Ok(())
                };
                assert_eq!(enc.as_ref().map(|_| ()).map_err(|e| *e), expect, "{case}");
                if enc.is_err() {
                    continue;
                }
                accepted.push(case.clone());
                let mut m = monitor::<1024>(c, 1);
                let mask = (1u64 << bits) - 1;
                let t = shaft_ticks(1024, speed, 0.005, 1.0, timer_hz);
                let out = run_exact(&mut m, 16, 1024 * 4 + 2, 0, mask, t, &case);
                assert_eq!(out.len(), 3, "{case}: {:?}", m.diagnostics());
                assert_eq!(m.diagnostics().invalid_windows, 0, "{case}");
                for (r, _) in out {
                    let floor = r.noise_floor as f64;
                    assert!(
                        (r.delta as f64 - 0.01).abs() <= floor + 1e-5,
                        "{case}: δ {} floor {floor}",
                        r.delta
                    );
                    let true_mean = speed * (1.0 - 0.005f64 * 0.005).sqrt();
                    let rev_ticks = TAU / speed * timer_hz;
                    assert!(
                        rel(r.omega_mean as f64, true_mean) <= 1.0 / rev_ticks + 5.0 * U32,
                        "{case}: mean {}",
                        r.omega_mean
                    );
                }
            }
        }
    }
    assert_eq!(accepted.len(), 11, "{accepted:?}");
}

// =============================================================================================
// Characteristic speeds of auto-balancer machines (seed 001)
// =============================================================================================

/// Two balls of 0.5 kg on radius 0.1 m, no housing: the exciter platform moves 1 kg more than
/// its own mass.
fn balancer(platform: u8) -> AutoBalancer {
    AutoBalancer {
        kind: BalancerKind::Ball,
        platform,
        loads: 2,
        load_mass: 0.5,
        radius: 0.1,
        housing_mass: 0.0,
        viscosity: 0.01,
    }
}

/// Zone search with a 1e-14 bisection bracket, so the search's own resolution is negligible
/// next to the tolerances below.
fn fine() -> SearchOptions {
    SearchOptions::new(4.0, 256, 1e-14).unwrap()
}

fn machine(p: &[Platform], c: &[Coupling], b: AutoBalancer) -> Machine {
    Machine::new(MachineConfig::new(p, c, b).unwrap(), fine()).unwrap()
}

fn boundaries(m: &Machine) -> Vec<f64> {
    m.zones().iter().skip(1).map(|z| z.from).collect()
}

fn sorted(mut v: Vec<f64>) -> Vec<f64> {
    v.sort_by(f64::total_cmp);
    v
}

fn assert_all_close(got: &[f64], want: &[f64], tol: f64, what: &str) {
    assert_eq!(got.len(), want.len(), "{what}: {got:?} vs {want:?}");
    for (g, w) in got.iter().zip(want) {
        assert!(
            rel(*g, *w) <= tol,
            "{what}: {got:?} vs {want:?} (tol {tol:e})"
        );
    }
}

/// Case: zero coupling. Platform 3 is attached to nothing (a coupling of zero stiffness and
/// damping), so it must not change what the exciter platform sees.
/// Reference: the two-platform machine without it, plus √(k3/M3) as an extra resonance and an
/// extra additional speed. Tolerances: √(k3/M3) to 2 f64 roundings (a diagonal matrix entry
/// and its square root: the zero coupling must give an exactly diagonal problem); the other
/// speeds 4 roundings; receptances 1e-13 (the 3×3 bordered determinant has a few more
/// roundings than the 2×2); zone boundaries 1e-12 (bisection to 1e-14 on criteria that differ
/// by the positive factor |Z33|²).
#[test]
fn zero_coupling_is_exact() {
    let p = [
        platform(80.0, 3e5, 30.0),
        platform(99.0, 4e5, 50.0),
        platform(30.0, 5e5, 10.0),
    ];
    let c12 = coupling(1, 2, 1e5, 20.0);
    let three = machine(&p, &[c12, coupling(2, 3, 0.0, 0.0)], balancer(2));
    let two = machine(&p[..2], &[c12], balancer(2));
    let w3 = (5e5f64 / 30.0).sqrt();
    let with_w3 = |v: &[f64]| sorted(v.iter().copied().chain([w3]).collect());
    assert_all_close(
        three.resonant_speeds(),
        &with_w3(two.resonant_speeds()),
        4.0 * U64,
        "resonant",
    );
    assert_all_close(
        three.additional_speeds(),
        &with_w3(two.additional_speeds()),
        4.0 * U64,
        "additional",
    );
    assert!(three
        .resonant_speeds()
        .iter()
        .any(|&w| rel(w, w3) <= 2.0 * U64));
    for w in [5.0, 40.0, 63.0, 70.0, 129.0, 500.0] {
        let (a, b) = (three.receptance(w), two.receptance(w));
        assert!(rel(a.0, b.0) < 1e-13 && rel(a.1, b.1) < 1e-13, "ω {w}");
    }
    assert_all_close(&boundaries(&three), &boundaries(&two), 1e-12, "zones");
}

/// Case: equal partial frequencies, coupling from 1 down to 1e-12 of the supports and 0:
/// (a) two equal platforms: eigenvalues s/M and (s + 2k)/M, additional (s + k)/M;
/// (b) three equal platforms coupled all to all: s/M and a double (s + 3k)/M, additional
///     (s + k)/M and (s + 3k)/M. A cubic or the quadratic formula loses half the digits of a
///     double root; the core must not.
/// Reference: those closed forms. Tolerances: each speed 8 f64 roundings; the splitting
/// ω₂² − ω₁² = 2k/M (3k/M) to 20ε·s/k (the roundings of eigenvalues of size s/M, relative to
/// a splitting of size k/M); with k = 0, a single boundary (two zones).
/// Undamped zones of (b) at k = s/10 and s/1000: boundaries at √(s/M), √((s + k)/M),
/// √((s + 3k)/M) (the double pole at (s + 3k)/M cancels against the zero there, leaving a
/// simple pole), to 1e-12.
#[test]
fn equal_partial_frequencies_double_roots() {
    let (s, mass) = (4e5, 100.0);
    for rho in [1.0, 1e-3, 1e-6, 1e-9, 1e-12, 0.0] {
        let k = s * rho;
        // Two platforms (exciter 2: 99 kg + 1 kg of balls).
        let p = [platform(mass, s, 0.0), platform(mass - 1.0, s, 0.0)];
        let m2 = machine(&p, &[coupling(1, 2, k, 0.0)], balancer(2));
        let want = [(s / mass).sqrt(), ((s + 2.0 * k) / mass).sqrt()];
        assert_all_close(m2.resonant_speeds(), &want, 8.0 * U64, "two");
        assert_all_close(
            m2.additional_speeds(),
            &[((s + k) / mass).sqrt()],
            8.0 * U64,
            "two, additional",
        );
        let r = m2.resonant_speeds();
        if k > 0.0 {
            let split = (r[1] * r[1] - r[0] * r[0]) / (2.0 * k / mass);
            assert!(
                (split - 1.0).abs() <= 20.0 * f64::EPSILON / rho,
                "ρ {rho}: {split}"
            );
        } else {
            assert_eq!(m2.zones().len(), 2);
        }
        // Three platforms, all pairs coupled (exciter 2).
        let p3 = [
            platform(mass, s, 0.0),
            platform(mass - 1.0, s, 0.0),
            platform(mass, s, 0.0),
        ];
        let cs = [
            coupling(1, 2, k, 0.0),
            coupling(2, 3, k, 0.0),
            coupling(1, 3, k, 0.0),
        ];
        let m3 = machine(&p3, &cs, balancer(2));
        let d = ((s + 3.0 * k) / mass).sqrt();
        assert_all_close(
            m3.resonant_speeds(),
            &[(s / mass).sqrt(), d, d],
            8.0 * U64,
            "three",
        );
        assert_all_close(
            m3.additional_speeds(),
            &[((s + k) / mass).sqrt(), d],
            8.0 * U64,
            "three, additional",
        );
        let r = m3.resonant_speeds();
        if k > 0.0 {
            let split = (r[1] * r[1] - r[0] * r[0]) / (3.0 * k / mass);
            assert!(
                (split - 1.0).abs() <= 20.0 * f64::EPSILON / rho,
                "ρ {rho}: {split}"
            );
        }
        if rho == 1e-3 || rho == 1.0 {
            let want = [(s / mass).sqrt(), ((s + k) / mass).sqrt(), d];
            assert_all_close(&boundaries(&m3), &want, 1e-12, "three, zones");
        }
    }
}

/// Case: a platform mass 10⁶ times another's (both ways, exciter heavy or light), with weak and
/// strong couplings, two and three platforms.
/// Reference: the inertia-bisection eigenvalues (an independent method). Tolerance 1e-13:
/// both methods are accurate relative to each eigenvalue for these graded problems (the
/// reference brackets to adjacent doubles in a backward-stable factorisation); 1e-13 allows a
/// condition number of ~500. Also: Cauchy interlacing q1 ≤ q̃1 ≤ q2 ≤ q̃2 ≤ q3 and, with zero
/// damping, zone boundaries at exactly those speeds (1e-12).
#[test]
fn platform_mass_a_million_times_another() {
    for (what, cfg) in mass_ratio_machines() {
        let m = Machine::new(cfg, fine()).unwrap();
        let (res, add) = reference_speeds(&cfg);
        assert_all_close(m.resonant_speeds(), &res, 1e-13, &what);
        assert_all_close(m.additional_speeds(), &add, 1e-13, &what);
        let all = sorted(res.iter().chain(&add).copied().collect());
        for (i, w) in all.windows(2).enumerate() {
            assert!(w[0] <= w[1] * (1.0 + 1e-15), "{what}: interlacing {i}");
        }
        // Distinct speeds bound zones; coinciding ones (weak coupling) may cancel.
        if all.windows(2).all(|w| rel(w[0], w[1]) > 1e-6) {
            assert_all_close(&boundaries(&m), &all, 1e-12, &what);
        }
    }
}

/// Undamped two- and three-platform machines with one platform mass 10⁶ times another, over
/// couplings from 1e-2 to 1e6 N/m, each named.
fn mass_ratio_machines() -> Vec<(String, MachineConfig)> {
    let mut out = Vec::new();
    for (m1, m2, m3) in [
        (1e6, 1.0, 30.0),
        (1.0, 1e6, 1.0),
        (1e-3, 1e3, 1e3),
        (1e3, 1e-3, 1e-3),
    ] {
        for kc in [1e-2, 1e3, 1e6] {
            let p = [
                platform(m1, 1e4, 0.0),
                platform(m2, 2e4, 0.0),
                platform(m3, 5e3, 0.0),
            ];
            let cs = [
                coupling(1, 2, kc, 0.0),
                coupling(2, 3, 0.5 * kc, 0.0),
                coupling(1, 3, 0.3 * kc, 0.0),
            ];
            let mut b = balancer(2);
            b.load_mass = 1e-6;
            for n in 2..=3 {
                out.push((
                    format!("{m1} {m2} {m3}, kc {kc}, {n} platforms"),
                    MachineConfig::new(&p[..n], &cs[..2 * n - 3], b).unwrap(),
                ));
            }
        }
    }
    out
}

/// The sign function of Re H_ee for two platforms (exciter e, other a), written out as a real
/// cubic in x = ω² (derived by hand, independent of the core's complex arithmetic), for an
/// undamped exciter platform (its damping would add terms in Ce):
/// g(x) = (T − Wx)·((u − vx)² + x·Ca²) − (u − vx)·(kc² − x·cc²) − 2x·Ca·kc·cc,
/// T = k_e + kc, W = M_e, u = k_a + kc, v = m_a, Ca = c_a + cc. Returns its coefficients
/// (c3, c2, c1, c0), in units of the given stiffness and mass scales.
fn two_platform_cubic(
    (ke, me): (f64, f64),
    (ka, ca, ma): (f64, f64, f64),
    (kc, cc): (f64, f64),
) -> [f64; 4] {
    let (t, w, u, v) = (ke + kc, me, ka + kc, ma);
    let big_ca = ca + cc;
    // (T − Wx)(u² + (Ca² − 2uv)x + v²x²) − (u − vx)(kc² − x cc²) − 2x Ca kc cc
    let c3 = -w * v * v;
    let c2 = t * v * v - w * (big_ca * big_ca - 2.0 * u * v) - v * cc * cc;
    let c1 = t * (big_ca * big_ca - 2.0 * u * v) - w * u * u + u * cc * cc + v * kc * kc
        - 2.0 * big_ca * kc * cc;
    let c0 = t * u * u - u * kc * kc;
    [c3, c2, c1, c0]
}

/// The positive roots of the cubic `c` (x from 1e-4 to 1e4, a 20 000-point log grid, each sign
/// change bisected to adjacent doubles).
fn positive_roots(c: [f64; 4]) -> Vec<f64> {
    let g = |x: f64| ((c[0] * x + c[1]) * x + c[2]) * x + c[3];
    let n = 20_000;
    let (lo, hi): (f64, f64) = (1e-4, 1e4);
    let mut roots = Vec::new();
    let mut prev = (0.0, g(0.0));
    for i in 0..=n {
        let x = lo * (hi / lo).powf(i as f64 / n as f64);
        let gx = g(x);
        if (gx > 0.0) != (prev.1 > 0.0) {
            let (mut a, mut b) = (prev.0, x);
            loop {
                let mid = 0.5 * (a + b);
                if mid <= a || mid >= b {
                    break;
                }
                if (g(mid) > 0.0) == (prev.1 > 0.0) {
                    a = mid;
                } else {
                    b = mid;
                }
            }
            roots.push(0.5 * (a + b));
        }
        prev = (x, gx);
    }
    roots
}

fn discriminant([a, b, c, d]: [f64; 4]) -> f64 {
    18.0 * a * b * c * d - 4.0 * b * b * b * d + b * b * c * c
        - 4.0 * a * c * c * c
        - 27.0 * a * a * d * d
}

/// Case: damping → 0 and damping large enough to erase a zone, on a two-platform machine
/// (exciter undamped; the other platform's support and the coupling damped).
/// Reference: the sign changes of the hand-derived real cubic g(x) above (x = ω², in units of
/// 1e5 N/m and 100 kg), bisected to adjacent doubles; the critical damping where two zones
/// vanish is the zero of the cubic's discriminant. Tolerances: boundaries 1e-10 (the core
/// brackets to 1e-14 but evaluates a complex product; both are limited by the roots'
/// condition, ~ε·Σ|terms|/|g'|, ≤ 1e-12 here); damping → 0 must converge to the undamped
/// speeds (closed form: x = u/v and the roots of (T − Wx)(u − vx) = kc²) with error ≤ 1e-12 at
/// damping 1e-8 of nominal, monotonically. Zones: 4 at c*·(1 − 1e-3), 2 at c*·(1 + 1e-3).
#[test]
fn damping_to_zero_and_damping_that_erases_a_zone() {
    let (ks, ms): (f64, f64) = (1e5, 100.0);
    let cs = (ks * ms).sqrt();
    let build = |ca: f64, cc: f64| {
        let p = [platform(150.0, 3e5, ca), platform(99.0, 4e5, 0.0)];
        machine(&p, &[coupling(1, 2, 1e5, cc)], balancer(2))
    };
    let cubic = |ca: f64, cc: f64| {
        two_platform_cubic(
            (4e5 / ks, 100.0 / ms),
            (3e5 / ks, ca / cs, 150.0 / ms),
            (1e5 / ks, cc / cs),
        )
    };
    let omega = |x: f64| (x * ks / ms).sqrt();
    // Undamped closed form (in scaled units): additional u/v, resonances by Vieta.
    let (t, w, u, v, kc): (f64, f64, f64, f64, f64) = (5.0, 1.0, 4.0, 1.5, 1.0);
    let (qa, qb, qc) = (w * v, t * v + w * u, t * u - kc * kc);
    let big = (qb + (qb * qb - 4.0 * qa * qc).sqrt()) / (2.0 * qa);
    let undamped = sorted(vec![omega(qc / (qa * big)), omega(u / v), omega(big)]);
    let mut prev_err = f64::INFINITY;
    for f in [1.0, 1e-2, 1e-4, 1e-8, 0.0] {
        let (ca, cc) = (800.0 * f, 300.0 * f);
        let m = build(ca, cc);
        let want: Vec<f64> = positive_roots(cubic(ca, cc))
            .into_iter()
            .map(omega)
            .collect();
        assert_all_close(&boundaries(&m), &want, 1e-10, &format!("damping ×{f}"));
        let err = boundaries(&m)
            .iter()
            .zip(&undamped)
            .map(|(a, b)| rel(*a, *b))
            .fold(0.0, f64::max);
        assert!(err <= prev_err, "×{f}: {err} after {prev_err}");
        prev_err = err;
        if f <= 1e-8 {
            assert!(err <= 1e-12, "×{f}: {err}");
        }
    }
    // Erasing: the support damping of platform 1 that merges the two middle boundaries.
    let disc = |ca: f64| discriminant(cubic(ca, 0.0));
    // Δ > 0 at light damping (three positive roots) and < 0 past c* (one real root); far
    // beyond, Δ > 0 again with two negative roots, so the bracket stops at 1e4 N·s/m.
    let (mut lo, mut hi) = (1.0, 1e4);
    assert!(disc(lo) > 0.0 && disc(hi) < 0.0);
    for _ in 0..200 {
        let mid = (lo * hi).sqrt();
        if disc(mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let c_star = lo;
    let before = build(c_star * (1.0 - 1e-3), 0.0);
    let after = build(c_star * (1.0 + 1e-3), 0.0);
    assert_eq!(
        before.zones().len(),
        4,
        "c* = {c_star}: {:?}",
        before.zones()
    );
    assert_eq!(after.zones().len(), 2, "c* = {c_star}: {:?}", after.zones());
    let want: Vec<f64> = positive_roots(cubic(c_star * (1.0 - 1e-3), 0.0))
        .into_iter()
        .map(omega)
        .collect();
    assert_all_close(&boundaries(&before), &want, 1e-9, "just before erasing");
    let want: Vec<f64> = positive_roots(cubic(c_star * (1.0 + 1e-3), 0.0))
        .into_iter()
        .map(omega)
        .collect();
    assert_all_close(&boundaries(&after), &want, 1e-10, "just after erasing");
}

/// A machine with every mass ×`ms`, stiffness ×`ks` and damping (and load viscosity) ×`cs`.
fn scaled_machine(cfg: &MachineConfig, ms: f64, ks: f64, cs: f64) -> Machine {
    Machine::new(scaled_config(cfg, ms, ks, cs), fine()).unwrap()
}

/// Case: parameters scaled by 10^±6 and by 2^±20. (i) masses, stiffness, damping and load
/// viscosity all ×s: every speed is unchanged; (ii) stiffness ×s², damping and viscosity ×s:
/// every speed ×s (Z(sω) = s²·Z(ω)).
/// Reference: the unscaled machine. Tolerances: for powers of two, none — every result must
/// be bit-identical (all operations scale exactly); for 10^±6, 1e-12 relative on resonant and
/// additional speeds, zone boundaries and capture limits (`until`), and 1e-6 on the location
/// of a capture maximum (`at`: the argument of a flat maximum is determined only to about
/// √ε of its value's precision).
#[test]
fn scaling_by_a_million_scales_the_results_exactly() {
    let p = [
        platform(100.0, 4e5, 200.0),
        platform(99.0, 4e5, 200.0),
        platform(150.0, 3e5, 100.0),
    ];
    let cs = [coupling(1, 2, 1e5, 50.0), coupling(2, 3, 1e5, 50.0)];
    for n in 1..=3 {
        let cfg = MachineConfig::new(&p[..n], &cs[..n - 1], balancer(if n == 1 { 1 } else { 2 }))
            .unwrap();
        let base = Machine::new(cfg, fine()).unwrap();
        for s in [1e6, 1e-6, 1048576.0, 1.0 / 1048576.0] {
            let exact = s == 1048576.0 || s == 1.0 / 1048576.0;
            for (ms, ks, cs, speed) in [(s, s, s, 1.0), (1.0, s * s, s, s)] {
                let m = scaled_machine(&cfg, ms, ks, cs);
                let what = format!("{n} platforms, s = {s:e}, speed ×{speed:e}");
                let scale = |v: &[f64]| v.iter().map(|x| x * speed).collect::<Vec<_>>();
                let tol = if exact { 0.0 } else { 1e-12 };
                assert_all_close(
                    m.resonant_speeds(),
                    &scale(base.resonant_speeds()),
                    tol,
                    &what,
                );
                assert_all_close(
                    m.additional_speeds(),
                    &scale(base.additional_speeds()),
                    tol,
                    &what,
                );
                assert_all_close(&boundaries(&m), &scale(&boundaries(&base)), tol, &what);
                assert_eq!(m.capture_windows().len(), base.capture_windows().len());
                for (a, b) in m.capture_windows().iter().zip(base.capture_windows()) {
                    assert!(rel(a.until, b.until * speed) <= tol, "{what}: {a:?} {b:?}");
                    let at_tol = if exact { 0.0 } else { 1e-6 };
                    assert!(rel(a.at, b.at * speed) <= at_tol, "{what}: {a:?} {b:?}");
                }
                let (d, d0) = (m.config().dimensionless(), cfg.dimensionless());
                assert!(
                    rel(d.epsilon, d0.epsilon) <= 4.0 * U64 && rel(d.beta, d0.beta) <= 4.0 * U64
                );
            }
        }
    }
}

/// Case: every machine of the cases above (zero coupling; equal partial frequencies, couplings
/// from 1 down to 0 of the supports; a mass 10⁶ times another; damping from nominal to zero
/// and across the value that erases two zones; every scaling), analysed by the polynomial-root
/// search of `Machine::new` and by the scan it replaced (`Machine::new_scanned`), both with
/// the 1e-14 bracket above.
/// Reference: the scan. Tolerances (`testutil::compare_with_scan`): the same zones and capture
/// windows, boundaries to 1e-9, capture `until` to 1e-9 plus what the boundary's own
/// difference moves it, `at` to 1e-7, and where the scan missed a maximum just below a zone's
/// end, the fast value attained in the zone and no lower than a dense search's.
#[test]
fn fast_search_matches_the_scan_on_the_hard_machines() {
    let mut configs = Vec::new();
    // Zero coupling.
    let p = [
        platform(80.0, 3e5, 30.0),
        platform(99.0, 4e5, 50.0),
        platform(30.0, 5e5, 10.0),
    ];
    let c12 = coupling(1, 2, 1e5, 20.0);
    configs.push(MachineConfig::new(&p, &[c12, coupling(2, 3, 0.0, 0.0)], balancer(2)).unwrap());
    configs.push(MachineConfig::new(&p[..2], &[c12], balancer(2)).unwrap());
    // Equal partial frequencies.
    let (s, mass) = (4e5, 100.0);
    for rho in [1.0, 1e-3, 1e-6, 1e-9, 1e-12, 0.0] {
        let k = s * rho;
        let p = [platform(mass, s, 0.0), platform(mass - 1.0, s, 0.0)];
        configs.push(MachineConfig::new(&p, &[coupling(1, 2, k, 0.0)], balancer(2)).unwrap());
        let p3 = [
            platform(mass, s, 0.0),
            platform(mass - 1.0, s, 0.0),
            platform(mass, s, 0.0),
        ];
        let cs = [
            coupling(1, 2, k, 0.0),
            coupling(2, 3, k, 0.0),
            coupling(1, 3, k, 0.0),
        ];
        configs.push(MachineConfig::new(&p3, &cs, balancer(2)).unwrap());
    }
    // A mass 10⁶ times another.
    configs.extend(mass_ratio_machines().into_iter().map(|(_, cfg)| cfg));
    // Damping to zero, and the support damping of platform 1 across the value (about
    // 1.4e3 N·s/m) that merges two boundaries and erases two zones.
    let two = |ca: f64, cc: f64| {
        let p = [platform(150.0, 3e5, ca), platform(99.0, 4e5, 0.0)];
        MachineConfig::new(&p, &[coupling(1, 2, 1e5, cc)], balancer(2)).unwrap()
    };
    for f in [1.0, 1e-2, 1e-4, 1e-8, 0.0] {
        configs.push(two(800.0 * f, 300.0 * f));
    }
    for i in 0..=40 {
        configs.push(two(10f64.powf(2.0 + 2.0 * f64::from(i) / 40.0), 0.0));
    }
    // Scaling by 10^±6 and 2^±20.
    let p = [
        platform(100.0, 4e5, 200.0),
        platform(99.0, 4e5, 200.0),
        platform(150.0, 3e5, 100.0),
    ];
    let cs = [coupling(1, 2, 1e5, 50.0), coupling(2, 3, 1e5, 50.0)];
    for n in 1..=3 {
        let cfg = MachineConfig::new(&p[..n], &cs[..n - 1], balancer(if n == 1 { 1 } else { 2 }))
            .unwrap();
        configs.push(cfg);
        for s in [1e6, 1e-6, 1048576.0, 1.0 / 1048576.0] {
            configs.push(scaled_config(&cfg, s, s, s));
            configs.push(scaled_config(&cfg, 1.0, s * s, s));
        }
    }
    let mut missed = 0;
    for cfg in &configs {
        let fast = Machine::new(*cfg, fine()).unwrap();
        let scan = Machine::new_scanned(*cfg, fine()).unwrap();
        missed += compare_with_scan(&fast, &scan, &format!("{cfg:?}")).scan_missed;
    }
    println!(
        "{} hard machines agree with the scan; it missed {missed} capture maxima",
        configs.len()
    );
}

// =============================================================================================
// Supports: unbalance split onto two planes (seed 002)
// =============================================================================================

/// Double-double number hi + lo (about 106 bits), for the exact-ish references.
#[derive(Debug, Clone, Copy)]
struct Dd(f64, f64);

impl Dd {
    fn new(x: f64) -> Dd {
        Dd(x, 0.0)
    }
    fn two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let bp = s - a;
        Dd(s, (a - (s - bp)) + (b - bp))
    }
    fn norm(hi: f64, lo: f64) -> Dd {
        let s = hi + lo;
        Dd(s, lo - (s - hi))
    }
    fn add(self, o: Dd) -> Dd {
        let s = Dd::two_sum(self.0, o.0);
        let t = Dd::two_sum(self.1, o.1);
        let s = Dd::norm(s.0, s.1 + t.0);
        Dd::norm(s.0, s.1 + t.1)
    }
    fn neg(self) -> Dd {
        Dd(-self.0, -self.1)
    }
    fn sub(self, o: Dd) -> Dd {
        self.add(o.neg())
    }
    fn mul(self, o: Dd) -> Dd {
        let p = self.0 * o.0;
        let e = self.0.mul_add(o.0, -p) + (self.0 * o.1 + self.1 * o.0);
        Dd::norm(p, e)
    }
    fn div(self, o: Dd) -> Dd {
        let q1 = self.0 / o.0;
        let r = self.sub(o.mul(Dd::new(q1)));
        let q2 = r.0 / o.0;
        let r = r.sub(o.mul(Dd::new(q2)));
        let q3 = r.0 / o.0;
        Dd::norm(q1, q2).add(Dd::new(q3))
    }
    fn f64(self) -> f64 {
        self.0 + self.1
    }
}

/// Reference for the equivalent of `(z_i, v_i)` in planes z1, z2, by a second method: moments
/// about the origin, M = Σ z_i·v_i, then E2 = (M − z1·F)/(z2 − z1), E1 = F − E2, all in
/// double-double (the core sums lever arms (z2 − z_i) instead, in compensated f64).
fn dd_split(items: &[(f64, Vec2)], z1: f64, z2: f64) -> [Vec2; 2] {
    let comp = |pick: fn(&Vec2) -> f64| {
        let mut f = Dd::new(0.0);
        let mut m = Dd::new(0.0);
        for (z, v) in items {
            f = f.add(Dd::new(pick(v)));
            m = m.add(Dd::new(*z).mul(Dd::new(pick(v))));
        }
        let e2 = m.sub(Dd::new(z1).mul(f)).div(Dd::new(z2).sub(Dd::new(z1)));
        (f.sub(e2).f64(), e2.f64())
    };
    let (x1, x2) = comp(|v| v.x);
    let (y1, y2) = comp(|v| v.y);
    [Vec2::new(x1, y1), Vec2::new(x2, y2)]
}

/// Per component: |got − want| ≤ tol·|want| (so an exactly zero component must be zero).
fn assert_vec_rel(got: [Vec2; 2], want: [Vec2; 2], tol: f64, what: &str) {
    for (g, w) in got.iter().zip(&want) {
        for (a, b) in [(g.x, w.x), (g.y, w.y)] {
            assert!(
                (a - b).abs() <= tol * b.abs(),
                "{what}: {got:?} vs {want:?} (rel {:e})",
                rel(a, b)
            );
        }
    }
}

fn pairs(us: &[Unbalance]) -> Vec<(f64, Vec2)> {
    us.iter().map(|u| (u.z, u.vector())).collect()
}

/// Case: nearly coincident support planes, 2.5e-6 m apart on a model 2 m long (the separation
/// limit is 1e-6 of the largest coordinate: 2e-6 m), and 1.9e-6 m (rejected).
/// Reference: the double-double moment method. Tolerance 6 f64 roundings per component,
/// relative to the component: the split's condition number (2 m / 2.5 µm ≈ 10⁶) must not
/// appear, because the core's lever arms and sums are exact before the final division.
#[test]
fn nearly_coincident_support_planes() {
    let (za, zb) = (1.0, 1.0 + 2.5e-6);
    let us = [
        Unbalance::new(0.37, 1e-3, 0.4),
        Unbalance::new(1.7, 2e-3, -2.0),
        Unbalance::new(2.0, 5e-4, 3.0),
    ];
    let r = Rotor::<3>::new(10.0, 1.2, za, zb, &us, None).unwrap();
    assert_vec_rel(
        r.support_unbalance(),
        dd_split(&pairs(&us), za, zb),
        6.0 * U64,
        "supports",
    );
    assert_eq!(
        Rotor::<3>::new(10.0, 1.2, za, 1.0 + 1.9e-6, &us, None).unwrap_err(),
        ConfigError::Inconsistent("support_b")
    );
    // The same two planes as correction planes of a rotor on a normal span.
    let r = Rotor::<3>::new(10.0, 1.2, 0.0, 2.0, &us, None).unwrap();
    assert_vec_rel(
        r.equivalent_in(za, zb).unwrap(),
        dd_split(&pairs(&us), za, zb),
        6.0 * U64,
        "correction planes",
    );
}

/// Case: unbalances at three different planes whose resultant and moment cancel to about
/// 1e-15 of their size (x components exact, the y component that of a·sin(π) ≈ 1.2e-16·a).
/// Reference: the double-double moment method on the same f64 vectors and positions.
/// Tolerance 6 roundings relative to each (tiny) result: a lever arm z_B − z_i rounded once
/// would already be off by 1e-16 of a term 10¹⁵ times larger than the result.
#[test]
fn unbalances_cancelling_to_1e_15_keep_their_digits() {
    let (z1, z2, z3) = (0.3, 1.7, 2.9);
    let a = 0.61;
    let b = a * (z3 - z1) / (z3 - z2);
    let c = a * (z2 - z1) / (z3 - z2) * (1.0 + 4.0 * f64::EPSILON);
    let us = [
        Unbalance::new(z1, a, 0.0),
        Unbalance::new(z2, b, PI),
        Unbalance::new(z3, c, 0.0),
    ];
    let r = Rotor::<3>::new(50.0, 2.0, 0.0, 4.0, &us, None).unwrap();
    let want = dd_split(&pairs(&us), 0.0, 4.0);
    let size = want.iter().map(|v| v.norm()).fold(0.0, f64::max);
    assert!(size < 1e-14 * a && size > 1e-17 * a, "{want:?}");
    assert_vec_rel(r.support_unbalance(), want, 6.0 * U64, "cancelling");
    // The resultant and the moment unbalance, too (compensated sums of exact products).
    let f = want[0] + want[1];
    let st = r.static_unbalance();
    assert!(
        (st.x - f.x).abs() <= 6.0 * U64 * f.x.abs() + 1e-40,
        "{st:?} vs {f:?}"
    );
    let m_ref = {
        let mut m = Dd::new(0.0);
        for (z, v) in pairs(&us) {
            m = m.add(Dd::new(z).sub(Dd::new(2.0)).mul(Dd::new(v.x)));
        }
        m.f64()
    };
    let m = r.moment_unbalance();
    assert!(
        (m.x - m_ref).abs() <= 6.0 * U64 * m_ref.abs(),
        "{m:?} vs {m_ref}"
    );
}

/// Case: a pure couple, ±v exactly opposite at z = −3 m and z = 5 m, both outside the span
/// [0, 1] (one on each side), split onto the support planes.
/// Reference: the double-double moment method. The static part is exactly zero, so
/// E_A = −E_B to 2 roundings of E_A; each to 4 roundings of itself.
#[test]
fn pure_couple_outside_the_span() {
    let v = Vec2::from_polar(3e-3, 0.7);
    let items = [(-3.0, v), (5.0, -v)];
    let e = equivalent_planes(&items, [0.0, 1.0]).unwrap();
    assert_vec_rel(e, dd_split(&items, 0.0, 1.0), 4.0 * U64, "couple");
    let sum = e[0] + e[1];
    assert!(sum.norm() <= 2.0 * U64 * e[0].norm(), "{e:?}");
    assert!(rel(e[0].norm(), 8.0 * 3e-3) <= 4.0 * U64);
}

/// Case: overhung planes far outside the span: an unbalance 10⁵ spans beyond supports 1 m
/// apart (the separation limit is then 0.1 m: accepted), 2·10⁶ spans (rejected: planes closer
/// than 1e-6 of the coordinates are the same plane), and correction planes 10⁴ m away on the
/// other side.
/// Reference: the double-double moment method (4 roundings per component); the corrections
/// must cancel the rotor's resultant and moment to 4 roundings of the largest term.
#[test]
fn overhung_planes_far_outside_the_span() {
    let u = Unbalance::new(1e5, 1e-3, 0.3);
    let r = Rotor::<1>::new(10.0, 0.5, 0.0, 1.0, &[u], None).unwrap();
    assert_vec_rel(
        r.support_unbalance(),
        dd_split(&pairs(&[u]), 0.0, 1.0),
        4.0 * U64,
        "far",
    );
    let far = Unbalance::new(2e6, 1e-3, 0.3);
    assert_eq!(
        Rotor::<1>::new(10.0, 0.5, 0.0, 1.0, &[far], None).unwrap_err(),
        ConfigError::Inconsistent("support_b")
    );
    let (p1, p2) = (-1e4, -1e4 + 2.0);
    let [c1, c2] = r.corrections(p1, p2).unwrap();
    for pick in [|v: &Vec2| v.x, |v: &Vec2| v.y] {
        let terms = [(1e5, pick(&u.vector())), (p1, pick(&c1)), (p2, pick(&c2))];
        let (mut f, mut m, mut scale_f, mut scale_m) = (Dd::new(0.0), Dd::new(0.0), 0.0, 0.0);
        for (z, x) in terms {
            f = f.add(Dd::new(x));
            m = m.add(Dd::new(z).mul(Dd::new(x)));
            scale_f += x.abs();
            scale_m += (z * x).abs();
        }
        assert!(f.f64().abs() <= 4.0 * U64 * scale_f, "force {f:?}");
        assert!(m.f64().abs() <= 4.0 * U64 * scale_m, "moment {m:?}");
    }
}

// =============================================================================================
// Validation: every public constructor names the bad parameter
// =============================================================================================

/// What a parameter accepts.
#[derive(Clone, Copy, PartialEq)]
enum Domain {
    /// Finite, > 0, not subnormal: every value of `BAD` is rejected.
    Positive,
    /// Finite, ≥ 0, not subnormal: all of `BAD` but 0.
    NonNegative,
    /// Any finite value (a coordinate, an angle, a signed torque): NaN and ±∞ only.
    Finite,
}

type Check = Box<dyn Fn(f64) -> Result<(), ConfigError>>;
type Check32 = Box<dyn Fn(f32) -> Result<(), ConfigError>>;

fn ok<T>(r: Result<T, ConfigError>) -> Result<(), ConfigError> {
    r.map(|_| ())
}

fn rejected(domain: Domain, x: f64) -> bool {
    match domain {
        Domain::Positive => BAD.iter().any(|b| b.to_bits() == x.to_bits()),
        Domain::NonNegative => BAD_NON_NEGATIVE.iter().any(|b| b.to_bits() == x.to_bits()),
        Domain::Finite => !x.is_finite(),
    }
}

/// Every f64 parameter of every public constructor, with its domain and the name its error
/// must carry.
fn f64_parameters() -> Vec<(&'static str, Domain, Check)> {
    use Domain::*;
    let enc = |f: fn(&mut EncoderConfig, f64)| -> Check {
        Box::new(move |x| {
            let mut c = EncoderConfig::indexed(64, 1e6);
            f(&mut c, x);
            ok(Encoder::new(c))
        })
    };
    let machine_cfg =
        |f: fn(&mut [Platform; 2], &mut [Coupling; 1], &mut AutoBalancer, f64)| -> Check {
            Box::new(move |x| {
                let mut p = [platform(100.0, 4e5, 200.0), platform(99.0, 4e5, 200.0)];
                let mut c = [coupling(1, 2, 1e5, 50.0)];
                let mut b = balancer(2);
                f(&mut p, &mut c, &mut b, x);
                ok(MachineConfig::new(&p, &c, b))
            })
        };
    let u = Unbalance::new(1.0, 1e-3, 0.5);
    let pl = ProcessLoad {
        per_length: 100.0,
        from: 0.5,
        to: 3.5,
        angle: 1.0,
    };
    let rotor = move |m: f64, zm: f64, za: f64, zb: f64, u: Unbalance, p: Option<ProcessLoad>| {
        ok(Rotor::<2>::new(m, zm, za, zb, &[u], p))
    };
    let base = move || Rotor::<2>::new(10.0, 2.0, 0.0, 4.0, &[u], None).unwrap();
    let process = move |f: fn(&mut ProcessLoad, f64)| -> Check {
        Box::new(move |x| {
            let mut p = pl;
            f(&mut p, x);
            rotor(10.0, 2.0, 0.0, 4.0, u, Some(p))
        })
    };
    let model = |x: f64, fly: f64| {
        ok(DriveModel::new(
            seed_motor(),
            Load::new(M1, &[h(0.125, 12.0, 0.0)]).unwrap(),
            x,
            fly,
        ))
    };
    vec![
        ("timer_hz", Positive, enc(|c, x| c.timer_hz = x)),
        ("min_speed", Positive, enc(|c, x| c.min_speed = x)),
        (
            "window.load_order",
            Positive,
            Box::new(|x| {
                ok(WindowConfig {
                    length: WindowLength::LoadOrder(x),
                    steady_tolerance: 0.02,
                }
                .validate())
            }),
        ),
        (
            "no_load_speed",
            Positive,
            Box::new(|x| ok(Parabola::new(x, 36.0, MM))),
        ),
        (
            "breakdown_speed",
            NonNegative,
            Box::new(|x| ok(Parabola::new(W0, x, MM))),
        ),
        (
            "breakdown_torque",
            Positive,
            Box::new(|x| ok(Parabola::new(W0, WM, x))),
        ),
        (
            "synchronous_speed",
            Positive,
            Box::new(|x| ok(Kloss::new(x, 0.2, MM))),
        ),
        (
            "breakdown_slip",
            Positive,
            Box::new(|x| ok(Kloss::new(157.0, x, MM))),
        ),
        (
            "breakdown_torque",
            Positive,
            Box::new(|x| ok(Kloss::new(157.0, 0.2, x))),
        ),
        (
            "harmonic.order",
            NonNegative,
            Box::new(|x| ok(Harmonic::new(x, 1.0, 0.0))),
        ),
        (
            "harmonic.amplitude",
            Finite,
            Box::new(|x| ok(Harmonic::new(1.0, x, 0.0))),
        ),
        (
            "harmonic.phase",
            Finite,
            Box::new(|x| ok(Harmonic::new(1.0, 1.0, x))),
        ),
        ("load.mean", Finite, Box::new(|x| ok(Load::new(x, &[])))),
        ("inertia", Positive, Box::new(move |x| model(x, 0.0))),
        ("flywheel", NonNegative, Box::new(move |x| model(J, x))),
        (
            "delta_limit",
            Positive,
            Box::new(|x| ok(drive(&[h(0.125, 12.0, 0.0)], J).irregularity(Some(x)))),
        ),
        (
            "platform mass",
            Positive,
            machine_cfg(|p, _, _, x| p[0].mass = x),
        ),
        (
            "platform stiffness",
            Positive,
            machine_cfg(|p, _, _, x| p[1].stiffness = x),
        ),
        (
            "platform damping",
            NonNegative,
            machine_cfg(|p, _, _, x| p[0].damping = x),
        ),
        (
            "coupling stiffness",
            NonNegative,
            machine_cfg(|_, c, _, x| c[0].stiffness = x),
        ),
        (
            "coupling damping",
            NonNegative,
            machine_cfg(|_, c, _, x| c[0].damping = x),
        ),
        (
            "load mass",
            Positive,
            machine_cfg(|_, _, b, x| b.load_mass = x),
        ),
        ("radius", Positive, machine_cfg(|_, _, b, x| b.radius = x)),
        (
            "housing mass",
            NonNegative,
            machine_cfg(|_, _, b, x| b.housing_mass = x),
        ),
        (
            "load viscosity",
            Positive,
            machine_cfg(|_, _, b, x| b.viscosity = x),
        ),
        (
            "pendulum inertia",
            NonNegative,
            machine_cfg(|_, _, b, x| b.kind = BalancerKind::Pendulum { inertia: x }),
        ),
        (
            "max_factor",
            Positive,
            Box::new(|x| ok(SearchOptions::new(x, 256, 1e-12))),
        ),
        (
            "rel_tol",
            Positive,
            Box::new(|x| ok(SearchOptions::new(4.0, 256, x))),
        ),
        (
            "mass",
            Positive,
            Box::new(move |x| rotor(x, 2.0, 0.0, 4.0, u, None)),
        ),
        (
            "centre_of_mass",
            Finite,
            Box::new(move |x| rotor(10.0, x, 0.0, 4.0, u, None)),
        ),
        (
            "support_a",
            Finite,
            Box::new(move |x| rotor(10.0, 2.0, x, 4.0, u, None)),
        ),
        (
            "support_b",
            Finite,
            Box::new(move |x| rotor(10.0, 2.0, -4.0, x, u, None)),
        ),
        (
            "unbalance.z",
            Finite,
            Box::new(move |x| rotor(10.0, 2.0, 0.0, 4.0, Unbalance::new(x, 1e-3, 0.5), None)),
        ),
        (
            "unbalance.amount",
            NonNegative,
            Box::new(move |x| rotor(10.0, 2.0, 0.0, 4.0, Unbalance::new(1.0, x, 0.5), None)),
        ),
        (
            "unbalance.angle",
            Finite,
            Box::new(move |x| rotor(10.0, 2.0, 0.0, 4.0, Unbalance::new(1.0, 1e-3, x), None)),
        ),
        (
            "process_load.per_length",
            NonNegative,
            process(|p, x| p.per_length = x),
        ),
        (
            "process_load.from",
            Finite,
            process(|p, x| {
                p.from = x;
                p.to = 1e300;
            }),
        ),
        (
            "process_load.to",
            Finite,
            process(|p, x| {
                p.from = -1e300;
                p.to = x;
            }),
        ),
        ("process_load.angle", Finite, process(|p, x| p.angle = x)),
        (
            "gravity",
            NonNegative,
            Box::new(move |x| ok(base().with_gravity(x, 0.0))),
        ),
        (
            "gravity.angle",
            Finite,
            Box::new(move |x| ok(base().with_gravity(9.8, x))),
        ),
        (
            "correction_plane_1",
            Finite,
            Box::new(move |x| ok(base().equivalent_in(x, 1e300))),
        ),
        (
            "correction_plane_2",
            Finite,
            Box::new(move |x| ok(base().equivalent_in(-1e300, x))),
        ),
        (
            "grade",
            Positive,
            Box::new(|x| ok(Limits::new(x, 60.0, None, 0.8))),
        ),
        (
            "service_speed",
            Positive,
            Box::new(|x| ok(Limits::new(6.3, x, None, 0.8))),
        ),
        (
            "support_load_limit.a",
            Positive,
            Box::new(|x| ok(Limits::new(6.3, 60.0, Some([x, 1.0]), 0.8))),
        ),
        (
            "support_load_limit.b",
            Positive,
            Box::new(|x| ok(Limits::new(6.3, 60.0, Some([1.0, x]), 0.8))),
        ),
        (
            "warning_fraction",
            Positive,
            Box::new(|x| ok(Limits::new(6.3, 60.0, None, x))),
        ),
    ]
}

/// Every f32 parameter of every public constructor (tuning values of the run-time paths).
fn f32_parameters() -> Vec<(&'static str, Domain, Check32)> {
    use Domain::*;
    let m = machine(
        &[platform(100.0, 4e5, 200.0), platform(99.0, 4e5, 200.0)],
        &[coupling(1, 2, 1e5, 50.0)],
        balancer(2),
    );
    let m2 = m;
    let enc = |f: fn(&mut EncoderConfig, f32)| -> Check32 {
        Box::new(move |x| {
            let mut c = EncoderConfig::indexed(64, 1e6);
            f(&mut c, x);
            ok(Encoder::new(c))
        })
    };
    let alarm = |f: fn(&mut AlarmConfig, f32)| -> Check32 {
        Box::new(move |x| {
            let mut a = AlarmConfig::new(0.06);
            f(&mut a, x);
            ok(a.validate())
        })
    };
    vec![
        (
            "tolerances.glitch_fraction",
            Positive,
            enc(|c, x| c.tolerances.glitch_fraction = x),
        ),
        (
            "tolerances.accept",
            Positive,
            enc(|c, x| c.tolerances.accept = x),
        ),
        (
            "tolerances.fault_margin",
            Positive,
            enc(|c, x| c.tolerances.fault_margin = x),
        ),
        (
            "steady_tolerance",
            Positive,
            Box::new(|x| {
                let e = Encoder::new(EncoderConfig::indexed(64, 1e6)).unwrap();
                ok(ToothLearner::<64>::new(&e, x))
            }),
        ),
        (
            "steady_tolerance",
            Positive,
            Box::new(|x| {
                ok(WindowConfig {
                    length: WindowLength::Revolutions(8),
                    steady_tolerance: x,
                }
                .validate())
            }),
        ),
        ("delta_limit", Positive, alarm(|a, x| a.limit = x)),
        ("hysteresis", NonNegative, alarm(|a, x| a.hysteresis = x)),
        (
            "floor_fraction",
            Positive,
            alarm(|a, x| a.floor_fraction = x),
        ),
        (
            "margin",
            NonNegative,
            Box::new(move |x| ok(Classifier::new(&m, x, 0.01))),
        ),
        (
            "hysteresis",
            NonNegative,
            Box::new(move |x| ok(Classifier::new(&m2, 0.03, x))),
        ),
        (
            "pitches",
            Positive,
            Box::new(|x| {
                let e = Encoder::new(EncoderConfig::indexed(8, 1e6)).unwrap();
                let mut t = [(TAU / 8.0) as f32; 8];
                t[3] = x;
                ok(drive_monitor::pitch::deviations(&e, &t, &mut [0i16; 8]))
            }),
        ),
    ]
}

/// Case: every public constructor fed NaN, ±∞, zero, a negative and a subnormal value (1e-310
/// as f64, 1e-40 as f32) in each of its numeric parameters.
/// Reference: the parameter's domain. Each value outside it must be a typed `ConfigError`
/// whose `parameter()` names exactly that parameter (nothing may panic, nothing may be
/// accepted silently); the values inside a wider domain (0 for a non-negative parameter, any
/// finite value for a coordinate) must not be rejected in that parameter's name.
#[test]
fn every_constructor_rejects_bad_numbers_by_name() {
    for (name, domain, check) in f64_parameters() {
        for x in BAD {
            let r = check(x);
            if rejected(domain, x) {
                let e = r.expect_err(&format!("{name} = {x:e} accepted"));
                assert_eq!(e.parameter(), name, "{name} = {x:e}: {e:?}");
            } else if let Err(e) = r {
                assert_ne!(
                    e.parameter(),
                    name,
                    "{name} = {x:e} is in its domain: {e:?}"
                );
            }
        }
    }
    for (name, domain, check) in f32_parameters() {
        for x in BAD_F32 {
            let r = check(x);
            let out = match domain {
                Domain::Positive => true,
                _ => BAD_F32_NON_NEGATIVE
                    .iter()
                    .any(|b| b.to_bits() == x.to_bits()),
            };
            if out {
                let e = r.expect_err(&format!("{name} = {x:e} accepted"));
                assert_eq!(e.parameter(), name, "{name} = {x:e}: {e:?}");
            } else {
                assert!(r.is_ok(), "{name} = {x:e}: {r:?}");
            }
        }
    }
}

// =============================================================================================
// Totality: no public function panics, on arbitrary inputs
// =============================================================================================

/// f64 values that break formulas: specials, extremes, and log-uniform magnitudes of both signs.
fn nasty_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(f64::NEG_INFINITY),
        Just(0.0),
        Just(-0.0),
        Just(1e-310),
        Just(f64::MAX),
        Just(f64::MIN_POSITIVE),
        any::<f64>(),
        (-300.0..300.0f64, any::<bool>()).prop_map(|(e, neg)| if neg {
            -(10f64.powf(e))
        } else {
            10f64.powf(e)
        }),
    ]
}

/// A magnitude 10^lo … 10^hi, log-uniform.
fn magnitude(lo: f64, hi: f64) -> impl Strategy<Value = f64> {
    (lo..hi).prop_map(|e| 10f64.powf(e))
}

#[derive(Debug, Clone)]
enum Op {
    /// `revs` whole revolutions as the disc produces them (index pulse or gap, every edge),
    /// with a speed ripple of relative amplitude `ripple` per revolution.
    Revs(u8, f64),
    /// An edge `f` nominal intervals after the previous one, with a direction input.
    Edge(f64, Option<bool>),
    /// An edge `dt` ticks after the previous one (any u32: wraps, zero, huge).
    RawEdge(u32, Option<bool>),
    Index,
    Poll(u32),
    Pitches(Vec<f32>),
    Learn(f32),
    Finish(u16),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        12 => (1u8..6, 0.0f64..0.2).prop_map(|(r, a)| Op::Revs(r, a)),
        2 => (0.0f64..3.0, proptest::option::of(any::<bool>())).prop_map(|(f, d)| Op::Edge(f, d)),
        1 => (any::<u32>(), proptest::option::of(any::<bool>())).prop_map(|(t, d)| Op::RawEdge(t, d)),
        2 => Just(Op::Index),
        1 => any::<u32>().prop_map(Op::Poll),
        1 => proptest::collection::vec(any::<f32>(), 0..40).prop_map(Op::Pitches),
        1 => any::<f32>().prop_map(Op::Learn),
        1 => any::<u16>().prop_map(Op::Finish),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 192, ..ProptestConfig::default() })]

    /// `DeltaMonitor::on_edge`, `poll`, `on_index` (and the learning and pitch-table calls) on
    /// arbitrary configurations — every one either a typed error or a monitor — and arbitrary
    /// streams: nothing panics, the speed is always finite and ≥ 0, every valid window has
    /// finite numbers with 0 ≤ δ < 2 and ωmin ≤ ωmax.
    #[test]
    fn delta_monitor_is_total(
        positions in prop_oneof![1 => 0u16..40, 8 => 4u16..32],
        wheel in 0u8..3,
        missing in 0u8..5,
        timer_hz in prop_oneof![1 => nasty_f64(), 6 => magnitude(3.0, 9.5)],
        bits in prop_oneof![1 => 14u8..34, 3 => Just(32u8), 2 => Just(16u8), 1 => Just(24u8)],
        k in prop_oneof![1 => 0u16..70, 6 => 1u16..5],
        min_speed in proptest::option::weighted(0.15, nasty_f64()),
        glitch in prop_oneof![1 => any::<f32>(), 6 => 0.05f32..0.6],
        steady in prop_oneof![1 => any::<f32>(), 6 => 0.001f32..0.5],
        limit in prop_oneof![1 => any::<f32>(), 6 => 0.001f32..0.5],
        revs in 0u16..4,
        nominal in 20u32..20_000,
        ops in proptest::collection::vec(op(), 0..40),
    ) {
        let mut c = match wheel {
            0 => EncoderConfig::unframed(positions, timer_hz),
            1 => EncoderConfig::indexed(positions, timer_hz),
            _ => EncoderConfig::missing_teeth(positions as u8, missing, timer_hz),
        };
        c.counter_bits = bits;
        c.estimator = Estimator::Edges(k);
        // By default the timeout is twice the longest nominal interval (a gap spans 4 at most).
        c.min_speed = min_speed.unwrap_or(TAU / f64::from(positions.max(1)) * timer_hz / (8.0 * f64::from(nominal)));
        c.tolerances.glitch_fraction = glitch;
        let Ok(enc) = Encoder::new(c) else { return Ok(()); };
        let w = WindowConfig { length: WindowLength::Revolutions(revs), steady_tolerance: steady };
        let Ok(mut m) = DeltaMonitor::<32, Corrected<32>>::new(enc, w, Some(AlarmConfig::new(limit))) else {
            return Ok(());
        };
        let mut learner: Option<ToothLearner<32>> = None;
        let mut t = 0u32;
        let missing = match c.wheel {
            Wheel::Pattern(_) => u32::from(missing),
            _ => 0,
        };
        let mut windows = Vec::new();
        for o in ops {
            let out = match o {
                Op::Revs(revs, ripple) => {
                    for r in 0..u32::from(revs) {
                        for tooth in missing..u32::from(positions) {
                            let phase = TAU * (tooth as f64 / positions as f64 + r as f64 * 0.37);
                            let f = 1.0 + ripple * phase.sin();
                            let gap = if tooth == missing { missing + 1 } else { 1 };
                            if tooth == missing && wheel == 1 {
                                m.on_index(t.wrapping_add(1));
                            }
                            let dt = (nominal as f64 * gap as f64 / f) as u32;
                            t = t.wrapping_add(dt);
                            match learner.as_mut() {
                                Some(l) => windows.extend(m.on_edge_observed(t, Some(Direction::Forward), l)),
                                None => windows.extend(m.on_edge(t, Some(Direction::Forward))),
                            }
                        }
                    }
                    windows.pop()
                }
                Op::Edge(f, d) => {
                    t = t.wrapping_add((f * f64::from(nominal)) as u32);
                    let d = d.map(|f| if f { Direction::Forward } else { Direction::Reverse });
                    m.on_edge(t, d)
                }
                Op::RawEdge(dt, d) => {
                    t = t.wrapping_add(dt);
                    let d = d.map(|f| if f { Direction::Forward } else { Direction::Reverse });
                    m.on_edge(t, d)
                }
                Op::Index => {
                    m.on_index(t);
                    None
                }
                Op::Poll(dt) => m.poll(t.wrapping_add(dt)),
                Op::Pitches(p) => {
                    let _ = m.set_pitches(&p);
                    None
                }
                Op::Learn(tol) => {
                    learner = ToothLearner::new(m.encoder(), tol).ok();
                    None
                }
                Op::Finish(n) => {
                    let mut table = [0.0f32; 32];
                    if let Some(l) = learner.take() {
                        if let Ok(p) = l.pitches(n, &mut table) {
                            let _ = m.set_pitches(p);
                        }
                    }
                    None
                }
            };
            prop_assert!(m.speed().is_finite() && m.speed() >= 0.0);
            for o in windows.drain(..).chain(out) {
                if let Some(r) = o.report.measurement() {
                    prop_assert!(r.delta.is_finite() && (0.0..2.0).contains(&r.delta), "{:?}", r);
                    prop_assert!(r.omega_min >= 0.0 && r.omega_min <= r.omega_max, "{:?}", r);
                    prop_assert!(r.omega_max.is_finite() && r.omega_mean.is_finite(), "{:?}", r);
                    prop_assert!(r.noise_floor.is_finite() && r.noise_floor >= 0.0);
                }
            }
        }
        let d = m.diagnostics();
        prop_assert!(d.alarms_raised <= d.valid_windows);
    }

    /// `Classifier::classify`/`advice` and `RegimeTracker::update` (and the `Machine` queries)
    /// on arbitrary valid machines (1–3 platforms, masses 1e-3…1e3 kg, stiffness 1…1e8 N/m,
    /// damping 0 or 1e-3…1e4, any coupling pattern and exciter platform) and arbitrary f32
    /// speeds and settings: typed errors or results, `Unknown` exactly for non-finite speeds,
    /// the regime independent of the sign of the speed, bands with from < to.
    #[test]
    fn regime_classification_is_total(
        n in 1usize..=3,
        exciter in 1u8..=3,
        ps in proptest::collection::vec(
            (magnitude(-3.0, 3.0), magnitude(0.0, 8.0),
             prop_oneof![Just(0.0), magnitude(-3.0, 4.0)]), 3),
        cs in proptest::collection::vec(
            (prop_oneof![Just(0.0), magnitude(0.0, 8.0)], prop_oneof![Just(0.0), magnitude(-3.0, 4.0)]), 3),
        pattern in 0u8..8,
        kind in 0u8..3,
        margin in prop_oneof![any::<f32>(), 0.0f32..0.4],
        hysteresis in prop_oneof![any::<f32>(), 0.0f32..0.4],
        speeds in proptest::collection::vec(any::<u32>(), 1..24),
        probe in nasty_f64(),
    ) {
        let platforms: Vec<Platform> = ps.iter().take(n).map(|&(m, k, c)| platform(m, k, c)).collect();
        let pairs = [(1u8, 2u8), (2, 3), (1, 3)];
        let couplings: Vec<Coupling> = pairs
            .iter()
            .zip(&cs)
            .enumerate()
            .filter(|(i, ((a, b), _))| pattern & (1 << i) != 0 && (*a as usize) <= n && (*b as usize) <= n)
            .map(|(_, ((a, b), &(k, c)))| coupling(*a, *b, k, c))
            .collect();
        let mut b = balancer(exciter.min(n as u8));
        b.kind = match kind {
            0 => BalancerKind::Ball,
            1 => BalancerKind::Roller,
            _ => BalancerKind::Pendulum { inertia: 1e-3 },
        };
        let cfg = MachineConfig::new(&platforms, &couplings, b);
        prop_assert!(cfg.is_ok(), "{:?}", cfg);
        let Ok(m) = Machine::new(cfg.unwrap(), SearchOptions::default()) else { return Ok(()); };
        prop_assert!(m.zones().first().map(|z| z.kind) == Some(ZoneKind::Gathering));
        let _ = (m.zone_kind_at(probe), m.receptance(probe), m.capture_lag(probe), m.capture_speed(probe));
        let Ok(c) = Classifier::new(&m, margin, hysteresis) else { return Ok(()); };
        let mut t = RegimeTracker::new();
        for bits in speeds {
            let x = f32::from_bits(bits);
            let r = c.classify(x);
            prop_assert_eq!(r == Regime::Unknown, !x.is_finite());
            prop_assert_eq!(c.classify(-x), r);
            let a = c.advice(x);
            if let Some(band) = a.exciter_band {
                prop_assert!(band.from < band.to);
            }
            let st = t.update(&c, x);
            prop_assert_eq!(st.regime == Regime::Unknown, !x.is_finite());
        }
    }

    /// `Classifier::from_table` on arbitrary tables (any f32 speeds, any regimes, any length)
    /// and settings: a typed error or a classifier that is total on any f32 speed, `Unknown`
    /// exactly for non-finite speeds, bands with from < to; a table that validates gives a
    /// classifier returning its segments unchanged.
    #[test]
    fn regime_table_classification_is_total(
        segs in proptest::collection::vec((any::<u32>(), 0u8..6), 0..20),
        sorted in any::<bool>(),
        margin in prop_oneof![any::<f32>(), 0.0f32..0.4],
        hysteresis in prop_oneof![any::<f32>(), 0.0f32..0.4],
        speeds in proptest::collection::vec(any::<u32>(), 1..24),
    ) {
        use drive_monitor::balancer::{BistableReason, RegimeSegment, RegimeTable};
        let mut segments: Vec<RegimeSegment> = segs
            .iter()
            .map(|&(bits, r)| RegimeSegment {
                from: if sorted { f32::from_bits(bits).abs() } else { f32::from_bits(bits) },
                regime: match r {
                    0 => Regime::Balancing,
                    1 => Regime::Gathering,
                    2 => Regime::Bistable(BistableReason::Capture),
                    3 => Regime::Bistable(BistableReason::Coexisting),
                    4 => Regime::NearCharacteristic,
                    _ => Regime::Unknown,
                },
            })
            .collect();
        if sorted {
            segments.sort_by(|a, b| a.from.total_cmp(&b.from));
            if let Some(f) = segments.first_mut() {
                f.from = 0.0;
            }
        }
        let table = RegimeTable { segments: &segments };
        let Ok(c) = Classifier::from_table(&table, margin, hysteresis) else { return Ok(()); };
        prop_assert!(table.validate().is_ok());
        let back: Vec<RegimeSegment> = c.segments().collect();
        prop_assert_eq!(&back, &segments);
        let mut t = RegimeTracker::new();
        for bits in speeds {
            let x = f32::from_bits(bits);
            let r = c.classify(x);
            prop_assert_eq!(r == Regime::Unknown, !x.is_finite());
            prop_assert_eq!(c.classify(-x), r);
            if let Some(band) = c.advice(x).exciter_band {
                prop_assert!(band.from < band.to);
            }
            let st = t.update(&c, x);
            prop_assert_eq!(st.regime == Regime::Unknown, !x.is_finite());
            // History only ever turns a bistable segment into balancing.
            prop_assert!(!st.by_history || st.regime == Regime::Balancing);
        }
    }

    /// `SupportMonitor::update` and `set_unbalance` (both math backends), and the rotor's
    /// queries, on arbitrary rotors and limits (every f64 nasty) and arbitrary f32 speeds:
    /// typed errors or results; `speed_valid` exactly when the speed is not NaN; for a finite
    /// speed with finite loads, peak ≥ min ≥ 0; `set_unbalance` accepts exactly finite,
    /// non-negative values.
    #[test]
    fn support_monitor_is_total(
        mass in prop_oneof![1 => nasty_f64(), 6 => magnitude(-2.0, 5.0)],
        coords in proptest::collection::vec(prop_oneof![1 => nasty_f64(), 12 => -10.0..10.0f64], 4),
        amount in prop_oneof![1 => nasty_f64(), 6 => magnitude(-9.0, 0.0)],
        angle in prop_oneof![1 => nasty_f64(), 6 => -7.0..7.0f64],
        q in prop_oneof![1 => nasty_f64(), 6 => magnitude(0.0, 4.0)],
        limits in proptest::collection::vec(prop_oneof![1 => nasty_f64(), 12 => magnitude(-1.0, 6.0)], 4),
        w in any::<u32>(),
        a in any::<u32>(),
        b in any::<u32>(),
    ) {
        let u = Unbalance::new(coords[3], amount, angle);
        let p = ProcessLoad { per_length: q, from: coords[0].min(coords[3]), to: coords[0].max(coords[3]) + 1.0, angle };
        let Ok(r) = Rotor::<2>::new(mass, coords[0], coords[1], coords[2], &[u, u], Some(p)) else {
            return Ok(());
        };
        let _ = (r.loads(f64::from(f32::from_bits(w))), r.plane_split(), r.equivalent_in(coords[3], angle));
        let Ok(l) = Limits::new(limits[0], limits[1], Some([limits[2], limits[3]]), 0.8) else {
            return Ok(());
        };
        let Ok(an) = SupportAnalysis::new(&r, &l) else {
            return Ok(());
        };
        let _ = an.report();
        let mut mon = an.monitor().expect("an analysis always gives a monitor");
        let (w, a, b) = (f32::from_bits(w), f32::from_bits(a), f32::from_bits(b));
        for k in 0..2 {
            let accepted = if k == 0 { mon.set_unbalance::<Libm>(a, b) } else { mon.set_unbalance::<Micromath>(a, b) };
            prop_assert_eq!(accepted, a.is_finite() && b.is_finite() && a >= 0.0 && b >= 0.0);
            let st = mon.update(w);
            prop_assert_eq!(st.speed_valid, !w.is_nan());
            for i in 0..2 {
                let (pk, mn) = (st.peak_load[i], st.min_load[i]);
                if w.is_finite() && pk.is_finite() && mn.is_finite() {
                    prop_assert!(pk >= mn && mn >= 0.0, "{:?}", st);
                }
                if st.speed_valid && !pk.is_nan() {
                    prop_assert!(st.load[i] != Level::Unknown);
                }
            }
            if let Some(s) = mon.max_safe_speed() {
                prop_assert!(s >= 0.0);
            }
        }
    }

    /// `DriveModel::predict`, `flywheel_for`, `sensitivity`, `irregularity` and the steady
    /// speed on arbitrary valid models (speeds 1e-3…1e6 rad/s, torques and inertias over 12
    /// decades, up to four harmonics of mixed orders) and arbitrary targets: a steady state
    /// has finite speeds 0 < ωmin ≤ ωmax and 0 ≤ δ < 2 agreeing with eq. 13 from those speeds
    /// (1e-9 where δ > 1e-6: no cancellation there); a stall has ω²min ≤ 0; a flywheel found
    /// is finite, ≥ 0 and meets the target (1e-9).
    #[test]
    fn drive_prediction_is_total(
        w0 in magnitude(-3.0, 6.0),
        wm_frac in 0.0..0.999f64,
        mm in magnitude(-6.0, 6.0),
        load_frac in -2.0..1.5f64,
        j in magnitude(-6.0, 6.0),
        fly in prop_oneof![Just(0.0), magnitude(-6.0, 6.0)],
        hs in proptest::collection::vec(
            (prop_oneof![Just(0.0), Just(0.125), Just(0.5), Just(1.0), Just(3.0),
                         Just(std::f64::consts::SQRT_2), Just(1e-6), Just(1e3)],
             -1.5..1.5f64, -7.0..7.0f64), 0..4),
        target in prop_oneof![nasty_f64(), 1e-6..1.5f64],
        phi in nasty_f64(),
    ) {
        let Ok(p) = Parabola::new(w0, wm_frac * w0, mm) else { return Ok(()); };
        let b = p.b();
        let hs: Vec<Harmonic> = hs.iter().map(|&(n, a, ph)| h(n, a * b, ph)).collect();
        let Ok(m) = DriveModel::new(p.into(), Load::new(load_frac * b, &hs).unwrap(), j, fly) else {
            return Ok(());
        };
        match m.predict() {
            Prediction::Steady(s) => {
                prop_assert!(s.omega_max.is_finite() && s.omega_min > 0.0 && s.omega_min <= s.omega_max, "{:?}", s);
                prop_assert!(s.delta.is_finite() && (0.0..2.0).contains(&s.delta), "{:?}", s);
                if s.delta > 1e-6 {
                    let naive = 2.0 * (s.omega_max - s.omega_min) / (s.omega_max + s.omega_min);
                    prop_assert!(rel(s.delta, naive) < 1e-9, "{:?} vs {}", s, naive);
                }
                if let Some(sens) = m.sensitivity() {
                    prop_assert!(sens.d_delta_d_inertia.is_finite() && sens.d_delta_d_breakdown_torque.is_finite());
                }
            }
            Prediction::Stalls(st) => prop_assert!(st.u_min <= 0.0 && !st.u_mean.is_nan(), "{:?}", st),
        }
        if let Ok(extra) = m.flywheel_for(target) {
            prop_assert!(extra.is_finite() && extra >= 0.0);
            if extra > 0.0 {
                if let Ok(fixed) = m.with_flywheel(m.flywheel() + extra) {
                    let s = fixed.predict();
                    let d = s.steady().map(|s| s.delta);
                    prop_assert!(d.is_some_and(|d| d <= target * (1.0 + 1e-9)), "{:?} for {}", s, target);
                }
            }
        }
        if let Ok(irr) = m.irregularity(Some(target)) {
            prop_assert!(irr.delta.is_finite() && irr.omega_max.is_finite());
        }
        let _ = (m.steady_omega(phi), m.omega_squared(phi));
    }
}
