//! What the auto-balancer's loads did: balancing, gathering, stuck behind the rotor.
//!
//! The observable is the residual unbalance vector `U = D·e^{i(φ+θ)} + m·R·Σ_j e^{iφ_j}` (kg·m):
//! zero when the loads cancel the rotor unbalance (auto-balancing), `D + N·m·R` at most when
//! they sit together on the unbalance's side. A completed run is classified from samples
//! ([`RegimeSample`], taken by [`super::VibrationMachine::sample`]) over its final part:
//!
//! - **balancing** when `max |U|` over the final window is at most
//!   `residual_fraction · reference` (default 1 % of `D`, or of `N·m·R` when `D = 0`);
//!   for a balancer too small for its rotor (`D > N·m·R`, so `|U| ≥ floor = D − N·m·R`)
//!   **saturated** when `max |U|` stays within `residual_fraction · reference` of that floor
//!   (the loads together opposite the unbalance, as balanced as they can be); otherwise
//!   **gathering**;
//! - **gathered** when the loads' coherence `|Σ_j e^{iφ_j}|/N` (the seed's `s`, eq. 10) stays
//!   at least `gathered_coherence` (default 0.95, two loads within ±18°) over the window;
//! - the loads' mean angular speed `Ω` and the rotor's `ω` over the window, from the unwrapped
//!   angles; **lagging** when `Ω < (1 − lag_fraction)·ω`: the Sommerfeld capture, loads stuck
//!   near a resonance while the rotor turns faster.
//!
//! The auto-balancing positions: for `N = 2` the loads sit symmetric about the direction
//! opposite the unbalance at half-angle `γ` with `cos γ = D/(2·m·R)`
//! ([`balancing_angles_two`]); for any `N` an equally spaced fan about that direction with
//! spacing `δ` such that `m·R·Σ_k cos((k − (N−1)/2)·δ) = D` ([`balancing_fan`]; for `N = 2` it
//! is the same position, `δ = 2γ`).
//!
//! # What direct simulation shows (`tests/vibration.rs`)
//!
//! Seed single-mass machine, `N = 2`, `h = 0.1`, `ε = 0.05`, `β = 2`:
//!
//! - Loads released together (0.01 rad apart) at `n = 0.5, 0.8` stay gathered turning at
//!   `q = 0.497, 0.747`; at `n = 1.2, 1.5` they stay gathered and stuck below resonance at
//!   `q = 0.880, 0.922` while the rotor runs faster (Sommerfeld capture). Both follow the
//!   averaged torque balance of the gathered loads, `β·(n − q) = h·q⁵/((1 − q²)² + 4h²q²)`,
//!   within 2·10⁻³. At `n = 3` they part and balance (residual below 10⁻⁴·N·m·R by
//!   `ω̃·t = 300`, 10⁻¹² by 1000). Loads started exactly coincident never part: identical loads
//!   obey identical equations.
//! - Started at the balancing position with a small perturbation, the criterion's `q > 1` is
//!   not sufficient: the Floquet analysis of the model linearised about the balancing position
//!   ([`super::floquet`]), a hand reduction of eq. 4, and the full simulation find balancing
//!   unstable on `1.0874 < n < 1.4252` (stable on `1.0016 < n < 1.0874` and above `1.4252`).
//!   The band depends on `h` and `β` (it vanishes for `h = 0.2` or `β = 5`); the exact regime
//!   table ([`crate::app::regimes`]) is built on these boundaries, and `docs/criterion.md`
//!   measures them on random machines.

use serde::Serialize;

/// The regime a run ended in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Regime {
    /// The residual unbalance decayed below the threshold.
    Balancing,
    /// The balancer is too small for the rotor, and the residual settled on the least it can
    /// leave (`D − N·m·R`, every load opposite the unbalance).
    Saturated,
    /// It did not (loads gathered, stuck or still wandering).
    Gathering,
}

impl Regime {
    /// `"balancing"`, `"saturated"` or `"gathering"`, as in the simulator's JSON.
    pub fn as_str(&self) -> &'static str {
        match self {
            Regime::Balancing => "balancing",
            Regime::Saturated => "saturated",
            Regime::Gathering => "gathering",
        }
    }
}

/// The regime observables at one instant.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RegimeSample {
    /// Time, s.
    pub t: f64,
    /// `|U|`, the residual unbalance magnitude, kg·m.
    pub residual: f64,
    /// `|Σ_j e^{iφ_j}|/N`: 1 when the loads are together, 0 when they cancel each other.
    pub coherence: f64,
    /// Mean of the unwrapped load angles, rad.
    pub mean_load_angle: f64,
    /// Shaft angle φ, rad (unwrapped).
    pub rotor_angle: f64,
}

/// Balancing: the residual stays at most this fraction of the reference over the final window
/// ([`RegimeCriteria::residual_fraction`]'s default).
pub const BALANCED: f64 = 0.01;

/// Gathering: the residual reaches at least this fraction of the reference. A run started near
/// the balancing position begins below it (its perturbation leaves a few %), so a residual
/// between [`BALANCED`] and this is a run that has not shown its regime yet, whatever it is
/// called by [`classify`] (which knows only "balanced or not"); `run`, `sweep` and the
/// criterion study judge by both.
pub const AWAY: f64 = 0.1;

/// Thresholds of the classification (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RegimeCriteria {
    /// Unbalance the residual is measured against, kg·m
    /// ([`super::VibrationMachine::reference_unbalance`]).
    pub reference: f64,
    /// The least residual the loads can leave, kg·m
    /// ([`super::VibrationMachine::residual_floor`]; 0 when they can balance the rotor).
    pub floor: f64,
    /// Final part of the run judged, as a fraction of its duration (default 0.25).
    pub window_fraction: f64,
    /// Balancing when the residual stays at most this fraction of `reference` (default 0.01).
    pub residual_fraction: f64,
    /// Gathered when the coherence stays at least this (default 0.95).
    pub gathered_coherence: f64,
    /// Lagging when `Ω < (1 − lag_fraction)·ω` (default 0.02).
    pub lag_fraction: f64,
}

impl RegimeCriteria {
    /// The default thresholds for a reference unbalance `reference` (kg·m), loads able to
    /// balance it (floor 0).
    pub fn new(reference: f64) -> Self {
        RegimeCriteria {
            reference,
            floor: 0.0,
            window_fraction: 0.25,
            residual_fraction: BALANCED,
            gathered_coherence: 0.95,
            lag_fraction: 0.02,
        }
    }
}

/// The classification of a completed run.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct RegimeReport {
    /// Balancing, saturated or gathering.
    pub regime: Regime,
    /// Largest residual unbalance over the final window, kg·m.
    pub residual_max: f64,
    /// `residual_max / reference`.
    pub residual_relative: f64,
    /// Smallest residual unbalance over the final window, relative to the reference.
    pub residual_min_relative: f64,
    /// Residual unbalance at the first sample, kg·m.
    pub residual_initial: f64,
    /// `residual_initial` relative to the reference.
    pub residual_initial_relative: f64,
    /// Smallest coherence over the final window.
    pub coherence_min: f64,
    /// The loads stayed together over the final window.
    pub gathered: bool,
    /// Loads' mean angular speed Ω over the final window, rad/s.
    pub load_speed: f64,
    /// Rotor's mean angular speed ω over the final window, rad/s.
    pub rotor_speed: f64,
    /// The loads turned measurably slower than the rotor (Sommerfeld capture when gathered).
    pub lagging: bool,
    /// The residual's range was the same in each quarter of the final window (its least and
    /// largest values each within [`STEADY_SWING`] of its largest, every quarter sampled):
    /// a steady motion, not one still on its way. With the residual neither balanced nor
    /// gathered, a self-oscillation about the balancing position where that is unstable.
    pub steady: bool,
    /// The residual's largest value in the last quarter of the final window is below half of
    /// its largest in the first quarter: the loads were still on their way (a verdict of the
    /// run's end, not of the machine's).
    pub falling: bool,
}

/// How closely the residual's least and largest values must repeat, quarter by quarter of
/// the final window, for its motion to be steady: this fraction of its largest value.
pub const STEADY_SWING: f64 = 0.03;

/// Whether `win`'s residual has the same least and largest values (within
/// [`STEADY_SWING`] of the largest) in each quarter of its time span, each quarter holding
/// samples.
fn steady(win: &[RegimeSample], min: f64, max: f64) -> bool {
    let (Some(a), Some(b)) = (win.first(), win.last()) else {
        return false;
    };
    let span = b.t - a.t;
    let tol = STEADY_SWING * max;
    (0..4).all(|q| {
        let (lo, hi) = (
            a.t + span * q as f64 / 4.0,
            a.t + span * (q + 1) as f64 / 4.0,
        );
        let part = win.iter().filter(|s| s.t >= lo && s.t <= hi);
        let (n, pmin, pmax) = part.fold((0usize, f64::INFINITY, 0.0f64), |(n, lo, hi), s| {
            (n + 1, lo.min(s.residual), hi.max(s.residual))
        });
        n >= 2 && (pmax - max).abs() <= tol && (pmin - min).abs() <= tol
    })
}

/// Classifies a run from its samples (in time order). `None` when fewer than two samples fall
/// in the final window or the window has zero duration.
pub fn classify(samples: &[RegimeSample], c: &RegimeCriteria) -> Option<RegimeReport> {
    let first = samples.first()?;
    let last = samples.last()?;
    let t0 = last.t - c.window_fraction * (last.t - first.t);
    let start = samples.iter().position(|s| s.t >= t0)?;
    let win = samples.get(start..)?;
    let w0 = win.first()?;
    let dt = last.t - w0.t;
    if win.len() < 2 || dt.partial_cmp(&0.0) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let residual_max = win.iter().map(|s| s.residual).fold(0.0, f64::max);
    let residual_min = win.iter().map(|s| s.residual).fold(f64::INFINITY, f64::min);
    let coherence_min = win.iter().map(|s| s.coherence).fold(1.0, f64::min);
    let load_speed = (last.mean_load_angle - w0.mean_load_angle) / dt;
    let rotor_speed = (last.rotor_angle - w0.rotor_angle) / dt;
    let settled = residual_max <= c.floor + c.residual_fraction * c.reference;
    Some(RegimeReport {
        regime: match (settled, c.floor > 0.0) {
            (true, false) => Regime::Balancing,
            (true, true) => Regime::Saturated,
            (false, _) => Regime::Gathering,
        },
        residual_max,
        residual_relative: residual_max / c.reference,
        residual_min_relative: residual_min / c.reference,
        residual_initial: first.residual,
        residual_initial_relative: first.residual / c.reference,
        coherence_min,
        gathered: coherence_min >= c.gathered_coherence,
        load_speed,
        rotor_speed,
        lagging: load_speed.abs() < (1.0 - c.lag_fraction) * rotor_speed.abs(),
        steady: steady(win, residual_min, residual_max),
        falling: falling(win),
    })
}

/// Whether `win`'s residual peaks in its last quarter below half its peak in its first (see
/// [`RegimeReport::falling`]).
fn falling(win: &[RegimeSample]) -> bool {
    let (Some(a), Some(b)) = (win.first(), win.last()) else {
        return false;
    };
    let quarter = 0.25 * (b.t - a.t);
    let peak = |lo: f64, hi: f64| {
        win.iter()
            .filter(|s| s.t >= lo && s.t <= hi)
            .fold(f64::NAN, |m, s| m.max(s.residual))
    };
    peak(b.t - quarter, b.t) < 0.5 * peak(a.t, a.t + quarter)
}

/// The two auto-balancing positions' angles for `N = 2` loads of unbalance `load_unbalance`
/// (`m·R`, kg·m) against a rotor unbalance `rotor_unbalance` (`D`, kg·m) pointing at
/// `unbalance_angle` (rad): `unbalance_angle + π ± γ`, `cos γ = D/(2·m·R)`. `None` when
/// `D > 2·m·R` (the loads cannot balance it) or an input is not finite or `m·R ≤ 0`.
pub fn balancing_angles_two(
    load_unbalance: f64,
    rotor_unbalance: f64,
    unbalance_angle: f64,
) -> Option<[f64; 2]> {
    let c = rotor_unbalance / (2.0 * load_unbalance);
    if !(load_unbalance > 0.0 && unbalance_angle.is_finite() && (0.0..=1.0).contains(&c)) {
        return None;
    }
    let g = c.acos();
    let opposite = unbalance_angle + core::f64::consts::PI;
    Some([opposite + g, opposite - g])
}

/// An auto-balancing position for `n` (2 to [`super::MAX_LOADS`]) loads: an equally spaced fan
/// centred on the direction opposite the unbalance, its spacing `δ ∈ [0, 2π/n]` found by
/// bisection on `m·R·Σ_k cos((k − (n−1)/2)·δ) = D` (decreasing in `δ` there). The first `n`
/// entries are used. `None` when `D > n·m·R`, `n` is out of range (one load balances only `D = m·R`) or an
/// input is not finite.
pub fn balancing_fan(
    n: usize,
    load_unbalance: f64,
    rotor_unbalance: f64,
    unbalance_angle: f64,
) -> Option<[f64; super::MAX_LOADS]> {
    if !(2..=super::MAX_LOADS).contains(&n)
        || !load_unbalance.is_finite()
        || load_unbalance <= 0.0
        || !rotor_unbalance.is_finite()
        || rotor_unbalance < 0.0
        || !unbalance_angle.is_finite()
        || rotor_unbalance > n as f64 * load_unbalance
    {
        return None;
    }
    let centre = (n as f64 - 1.0) / 2.0;
    let sum = |d: f64| -> f64 {
        (0..n).map(|k| ((k as f64 - centre) * d).cos()).sum::<f64>() * load_unbalance
    };
    let (mut lo, mut hi) = (0.0, 2.0 * core::f64::consts::PI / n as f64);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if sum(mid) > rotor_unbalance {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-15 * hi {
            break;
        }
    }
    let d = 0.5 * (lo + hi);
    let opposite = unbalance_angle + core::f64::consts::PI;
    let mut out = [0.0; super::MAX_LOADS];
    for (k, a) in out.iter_mut().take(n).enumerate() {
        *a = opposite + (k as f64 - centre) * d;
    }
    Some(out)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn residual(angles: &[f64], mr: f64, d: f64, a: f64) -> f64 {
        let mut u = [d * a.cos(), d * a.sin()];
        for x in angles {
            u[0] += mr * x.cos();
            u[1] += mr * x.sin();
        }
        u[0].hypot(u[1])
    }

    #[test]
    fn a_swing_is_steady_only_where_it_repeats_in_every_quarter() {
        // 100 s sampled at 100 Hz, judged over the last 25 s: a residual swinging with a
        // period of 3.7 s between 0.05 and 0.45, then the same growing by half over the run (an eighth over the window judged).
        let run = |growth: f64| -> Vec<RegimeSample> {
            (0..10_000)
                .map(|i| {
                    let t = f64::from(i) * 0.01;
                    let swing = 0.25 + 0.2 * (core::f64::consts::TAU * t / 3.7).sin();
                    RegimeSample {
                        t,
                        residual: swing * (1.0 + growth * t / 100.0),
                        coherence: 0.3,
                        mean_load_angle: 80.0 * t,
                        rotor_angle: 80.0 * t,
                    }
                })
                .collect()
        };
        let c = RegimeCriteria::new(1.0);
        let r = classify(&run(0.0), &c).unwrap();
        assert!(r.steady && r.regime == Regime::Gathering && !r.gathered && !r.lagging);
        assert!(!classify(&run(0.5), &c).unwrap().steady);
    }

    #[test]
    fn two_load_position_cancels_the_unbalance() {
        for &(mr, d, a) in &[(0.01, 0.0, 0.0), (0.01, 0.013, 0.7), (0.02, 0.04, -2.0)] {
            let p = balancing_angles_two(mr, d, a).unwrap();
            assert!(
                residual(&p, mr, d, a) < 1e-15 * (1.0 + d / mr),
                "{mr} {d} {a}"
            );
            // Symmetric about the direction opposite the unbalance.
            let mid = 0.5 * (p[0] + p[1]);
            assert!((mid - (a + core::f64::consts::PI)).abs() < 1e-15 * 10.0);
        }
        assert!(balancing_angles_two(0.01, 0.0201, 0.0).is_none());
        assert!(balancing_angles_two(0.0, 0.0, 0.0).is_none());
    }

    #[test]
    fn fan_matches_the_closed_form_for_two_and_balances_any_n() {
        let (mr, d, a) = (0.01, 0.013, 0.7);
        let fan = balancing_fan(2, mr, d, a).unwrap();
        let two = balancing_angles_two(mr, d, a).unwrap();
        // Fan order is [opposite − γ, opposite + γ].
        assert!((fan[0] - two[1]).abs() < 1e-12 && (fan[1] - two[0]).abs() < 1e-12);
        for n in 2..=super::super::MAX_LOADS {
            for &d in &[0.0, 0.3 * mr, 0.99 * n as f64 * mr] {
                let f = balancing_fan(n, mr, d, a).unwrap();
                let r = residual(&f[..n], mr, d, a);
                assert!(r < 1e-12 * mr * n as f64, "n={n} d={d} r={r}");
            }
        }
        assert!(balancing_fan(3, mr, 3.01 * mr, 0.0).is_none());
        assert!(balancing_fan(1, mr, mr, 0.0).is_none());
    }

    #[test]
    fn classify_reads_the_final_window() {
        let mk = |t: f64, residual: f64, coherence: f64, w: f64, big_w: f64| RegimeSample {
            t,
            residual,
            coherence,
            mean_load_angle: big_w * t,
            rotor_angle: w * t,
        };
        // Residual decays as e^{-t}; loads in step with the rotor.
        let s: Vec<_> = (0..=100)
            .map(|i| {
                let t = i as f64 * 0.1;
                mk(t, (-t).exp(), 0.0, 10.0, 10.0)
            })
            .collect();
        let r = classify(&s, &RegimeCriteria::new(1.0)).unwrap();
        assert_eq!(r.regime, Regime::Balancing);
        assert!((r.residual_max - (-7.5f64).exp()).abs() < 1e-12);
        assert!(!r.gathered && !r.lagging);
        // Gathered, loads turning at 8.5 against 10: stuck.
        let s: Vec<_> = (0..=100)
            .map(|i| mk(i as f64 * 0.1, 2.0, 0.99, 10.0, 8.5))
            .collect();
        let r = classify(&s, &RegimeCriteria::new(1.0)).unwrap();
        assert_eq!(r.regime, Regime::Gathering);
        assert!(r.gathered && r.lagging);
        assert!((r.load_speed - 8.5).abs() < 1e-12 && (r.rotor_speed - 10.0).abs() < 1e-12);
        assert!(classify(&s[..1], &RegimeCriteria::new(1.0)).is_none());
        // A balancer too small for its rotor: residual settled at the floor 0.4 (within 1 % of
        // the reference 2): saturated; 3 % above it: gathering.
        let c = RegimeCriteria {
            floor: 0.4,
            ..RegimeCriteria::new(2.0)
        };
        let at = |r: f64| -> Vec<RegimeSample> {
            (0..=100)
                .map(|i| mk(i as f64 * 0.1, r, 0.99, 10.0, 10.0))
                .collect()
        };
        assert_eq!(classify(&at(0.415), &c).unwrap().regime, Regime::Saturated);
        assert_eq!(classify(&at(0.46), &c).unwrap().regime, Regime::Gathering);
    }
}
