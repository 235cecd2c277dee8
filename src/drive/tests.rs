//! Tests of the δ prediction against independent references: the paper's own D1/D2/D3 form,
//! a direct RK4 integration of eq. 1 in time, series expansions and brute-force searches.

use super::*;
use crate::error::ConfigError;
use crate::testutil::{drive, h, paper_terms, seed_motor, steady, J, M1, MM, W0, WM};
use core::f64::consts::PI;
use proptest::prelude::*;

fn seed() -> DriveModel {
    drive(&[h(0.125, 12.0, 0.0)], J)
}

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

#[test]
fn seed_case_reproduced() {
    let s = steady(&seed());
    assert!((s.omega_max - 136.311).abs() < 5e-4, "{}", s.omega_max);
    assert!((s.omega_min - 132.196).abs() < 5e-4, "{}", s.omega_min);
    assert!((s.delta - 0.030656).abs() < 5e-7, "{}", s.delta);
    assert_eq!(s.horizon, Horizon::ClosedForm);
    assert!(s.within_working_branch);
    // Eq. 12 in the paper's own coefficients agrees to rounding.
    let (ubar, amp) = paper_terms(12.0, 0.125, J);
    assert!(rel(s.omega_max, (ubar + amp).sqrt()) < 1e-14);
    assert!(rel(s.omega_min, (ubar - amp).sqrt()) < 1e-14);
    // The extremal angles are where the periodic solution peaks.
    let m = seed();
    let pmax = s.phi_max.unwrap();
    let pmin = s.phi_min.unwrap();
    assert!(rel(m.steady_omega(pmax).unwrap(), s.omega_max) < 1e-14);
    assert!(rel(m.steady_omega(pmin).unwrap(), s.omega_min) < 1e-14);
    assert!((0.0..16.0 * PI).contains(&pmax) && (0.0..16.0 * PI).contains(&pmin));
    // The paper's printed δ = 0.085 / 0.101 and ωmax = 145 do not follow from its parameters.
    assert!(s.delta < 0.05 && s.omega_max < 140.0);
    // Host summary.
    let irr = m.irregularity(Some(0.06)).unwrap();
    assert!(irr.steady_state);
    assert_eq!(irr.delta, s.delta);
    assert_eq!(irr.flywheel_for_limit, Some(0.0));
    assert_eq!(m.irregularity(None).unwrap().flywheel_for_limit, None);
}

/// RK4 integration of eq. 1 in time, `J·ω' = M_d(ω) − M_c(φ)`, from the no-load speed; after
/// `settle` radians, ωmax and ωmin over `period` radians, each refined by the vertex of the
/// parabola through the extreme step and its neighbours.
fn integrate(m: &DriveModel, settle: f64, period: f64, dt: f64) -> (f64, f64) {
    let (motor, load, j) = (m.motor(), m.load(), m.total_inertia());
    let acc = |phi: f64, w: f64| (motor.torque(w) - load.torque(phi)) / j;
    let step = |phi: f64, w: f64| {
        let (k1p, k1w) = (w, acc(phi, w));
        let (k2p, k2w) = (
            w + 0.5 * dt * k1w,
            acc(phi + 0.5 * dt * k1p, w + 0.5 * dt * k1w),
        );
        let (k3p, k3w) = (
            w + 0.5 * dt * k2w,
            acc(phi + 0.5 * dt * k2p, w + 0.5 * dt * k2w),
        );
        let (k4p, k4w) = (w + dt * k3w, acc(phi + dt * k3p, w + dt * k3w));
        (
            phi + dt / 6.0 * (k1p + 2.0 * k2p + 2.0 * k3p + k4p),
            w + dt / 6.0 * (k1w + 2.0 * k2w + 2.0 * k3w + k4w),
        )
    };
    let (mut phi, mut w) = (0.0, motor.model().no_load_speed());
    while phi < settle {
        (phi, w) = step(phi, w);
    }
    let end = phi + period;
    let first = w;
    let rest = core::iter::from_fn(move || {
        (phi < end + 0.01).then(|| {
            (phi, w) = step(phi, w);
            w
        })
    });
    vertex_extrema(core::iter::once(first).chain(rest))
}

/// Largest and smallest value of a sampled curve, each local extremum refined by the vertex
/// of the parabola through it and its two neighbours (`(f64::MIN, f64::MAX)` if none).
fn vertex_extrema(samples: impl IntoIterator<Item = f64>) -> (f64, f64) {
    let (mut max, mut min) = (f64::MIN, f64::MAX);
    let mut samples = samples.into_iter();
    let (Some(mut y0), Some(mut y1)) = (samples.next(), samples.next()) else {
        return (max, min);
    };
    for y2 in samples {
        let curv = y0 - 2.0 * y1 + y2;
        let vertex = if curv != 0.0 {
            y1 - (y0 - y2) * (y0 - y2) / (8.0 * curv)
        } else {
            y1
        };
        if y1 >= y0 && y1 >= y2 {
            max = max.max(vertex);
        }
        if y1 <= y0 && y1 <= y2 {
            min = min.min(vertex);
        }
        (y0, y1) = (y1, y2);
    }
    (max, min)
}

fn delta_of(wmax: f64, wmin: f64) -> f64 {
    2.0 * (wmax - wmin) / (wmax + wmin)
}

#[test]
fn matches_direct_integration_one_harmonic() {
    let m = seed();
    let s = steady(&m);
    let (wmax, wmin) = integrate(&m, 1500.0, 16.0 * PI, 1e-4);
    let d = delta_of(wmax, wmin);
    assert!(rel(d, s.delta) < 1e-8, "rk4 {d} model {}", s.delta);
    assert!(rel(wmax, s.omega_max) < 1e-8 && rel(wmin, s.omega_min) < 1e-8);
}

#[test]
fn matches_direct_integration_two_and_three_harmonics() {
    let two = drive(&[h(0.125, 12.0, 0.0), h(0.5, 6.0, 1.0)], J);
    let three = drive(
        &[h(0.125, 12.0, 0.0), h(0.5, 6.0, 1.0), h(1.0, 9.0, -0.4)],
        J,
    );
    for m in [two, three] {
        let s = steady(&m);
        let Horizon::Period { radians, samples } = s.horizon else {
            panic!("{:?}", s.horizon)
        };
        assert!((radians - 16.0 * PI).abs() < 1e-12);
        let (wmax, wmin) = integrate(&m, 1500.0, radians, 1e-4);
        let d = delta_of(wmax, wmin);
        assert!(
            rel(d, s.delta) < 1e-8,
            "rk4 {d} model {} ({samples})",
            s.delta
        );
    }
}

#[test]
fn several_harmonics_match_brute_force_search() {
    // Orders 1, 2, 3 with nearly equal competing peaks.
    let m = drive(
        &[h(1.0, 10.0, 0.0), h(2.0, 9.0, 0.3), h(3.0, 8.0, 2.0)],
        0.05,
    );
    let s = steady(&m);
    let n = 2_000_000;
    let (mut umax, mut umin) = (f64::MIN, f64::MAX);
    for i in 0..n {
        let u = m.omega_squared(2.0 * PI * i as f64 / n as f64);
        umax = umax.max(u);
        umin = umin.min(u);
    }
    // The brute force misses the extremum by at most ½·C·(step/2)²; the model must be at
    // least as extreme and no further off than that.
    let u = |w: f64| w * w;
    assert!(u(s.omega_max) >= umax - 1e-9 && u(s.omega_max) - umax < 1e-6);
    assert!(u(s.omega_min) <= umin + 1e-9 && umin - u(s.omega_min) < 1e-6);
    assert_eq!(
        s.horizon,
        Horizon::Period {
            radians: 2.0 * PI,
            samples: 96
        }
    );
}

#[test]
fn tiny_delta_keeps_full_precision() {
    for (j, expect) in [(1.065e5, 1e-7), (1.065e11, 1e-13)] {
        let s = steady(&drive(&[h(0.125, 12.0, 0.0)], j));
        let (ubar, r_amp) = paper_terms(12.0, 0.125, j);
        // Exact, cancellation-free reference: r = R/ū, δ = 2r/(1 + √(1 − r²)).
        let r = r_amp / ubar;
        let reference = 2.0 * r / (1.0 + (1.0 - r * r).sqrt());
        assert!(rel(s.delta, expect) < 0.01, "{}", s.delta);
        assert!(
            rel(s.delta, reference) < 1e-12,
            "{} vs {reference}",
            s.delta
        );
        // δ ≈ r + r³/4 (series): the same to rounding.
        assert!(rel(s.delta, r + r * r * r / 4.0) < 1e-12);
        // The textbook form subtracts two square roots and loses digits at δ ≈ 1e-13.
        let naive = delta_of(s.omega_max, s.omega_min);
        if expect < 1e-10 {
            assert!(rel(naive, reference) > 1e-6, "naive {naive}");
        }
    }
}

#[test]
fn large_inertia_gives_delta_proportional_to_one_over_j() {
    // δ → 2|M2|/(n·J·ū) as J → ∞.
    let ubar = W0 * W0 - 24.0 * (W0 * W0 - WM * WM) / MM;
    for j in [1e3, 1e5, 1e8] {
        let s = steady(&drive(&[h(0.125, 12.0, 0.0)], j));
        let asym = 2.0 * 12.0 / (0.125 * j * ubar);
        let a = MM / (W0 * W0 - WM * WM);
        // Relative corrections: (2a/(nJ))²/2 from the hypot, r²/4 from the series.
        let bound = 2.0 * (2.0 * a / (0.125 * j)).powi(2) + asym * asym;
        assert!(rel(s.delta, asym) < bound + 1e-14, "J {j}");
    }
}

#[test]
fn quasi_static_limit_and_order_zero() {
    // n → 0: u oscillates with amplitude M2/a (D3/D1), δ stays finite.
    let a = MM / (W0 * W0 - WM * WM);
    let ubar = W0 * W0 - 24.0 / a;
    let r = 12.0 / a / ubar;
    let quasi = 2.0 * r / (1.0 + (1.0 - r * r).sqrt());
    let s = steady(&drive(&[h(1e-9, 12.0, 0.0)], J));
    assert!(rel(s.delta, quasi) < 1e-12, "{} vs {quasi}", s.delta);
    // n = 0 exactly: a constant load offset M2·sin ψ, no oscillation at all.
    let m = drive(&[h(0.0, 12.0, 0.5)], J);
    let s0 = steady(&m);
    assert_eq!(s0.delta, 0.0);
    assert_eq!(s0.horizon, Horizon::Constant);
    let shifted = W0 * W0 - (24.0 + 12.0 * 0.5f64.sin()) / a;
    assert!(rel(s0.omega_max, shifted.sqrt()) < 1e-14);
    assert_eq!(s0.omega_max, s0.omega_min);
    assert!(m.sensitivity().unwrap().d_delta_d_inertia == 0.0);
    assert_eq!(m.flywheel_for(0.01), Ok(0.0));
    // An order-0 term next to a real harmonic equals a shifted mean.
    let with0 = steady(&drive(&[h(0.125, 12.0, 0.0), h(0.0, 3.0, PI / 2.0)], J));
    let shifted = DriveModel::new(
        seed_motor(),
        Load::new(27.0, &[h(0.125, 12.0, 0.0)]).unwrap(),
        J,
        0.0,
    )
    .unwrap();
    assert!(rel(with0.delta, steady(&shifted).delta) < 1e-14);
}

#[test]
fn same_order_harmonics_combine_into_one() {
    let split = steady(&drive(&[h(0.125, 7.0, 0.0), h(0.125, 5.0, 0.0)], J));
    assert_eq!(split.horizon, Horizon::ClosedForm);
    assert!(rel(split.delta, steady(&seed()).delta) < 1e-14);
    // Opposite phases cancel exactly.
    let none = steady(&drive(&[h(0.5, 4.0, 0.0), h(0.5, -4.0, 0.0)], J));
    assert_eq!(none.delta, 0.0);
}

#[test]
fn stalled_drive_is_reported_not_nan() {
    // Peak load beyond what the drive can carry through with this inertia.
    let m = drive(&[h(0.125, 400.0, 0.0)], J);
    let Prediction::Stalls(st) = m.predict() else {
        panic!("expected a stall")
    };
    assert!(st.u_mean > 0.0 && st.u_min <= 0.0);
    assert!(m.sensitivity().is_none());
    let irr = m.irregularity(Some(0.06)).unwrap();
    assert!(!irr.steady_state);
    assert_eq!((irr.omega_min, irr.delta), (0.0, 2.0));
    assert!(irr.omega_max.is_finite() && irr.omega_max > 0.0);
    // A flywheel carries it through: the closed form gives exactly δ = limit.
    let extra = irr.flywheel_for_limit.unwrap();
    assert!(extra > 0.0);
    let fixed = steady(&m.with_flywheel(extra).unwrap());
    assert!(rel(fixed.delta, 0.06) < 1e-12);
    // Mean load above the stall torque B: no steady state and no flywheel helps.
    let over = DriveModel::new(seed_motor(), Load::new(200.0, &[]).unwrap(), J, 0.0).unwrap();
    assert!(matches!(over.predict(), Prediction::Stalls(s) if s.u_mean <= 0.0));
    assert_eq!(
        over.flywheel_for(0.06),
        Err(DesignError::MeanLoadExceedsMotor)
    );
    let irr = over.irregularity(Some(0.06)).unwrap();
    assert_eq!(
        (irr.omega_max, irr.delta, irr.flywheel_for_limit),
        (0.0, 2.0, None)
    );
}

#[test]
fn flywheel_closed_form_and_bisection_agree() {
    let m = seed();
    assert_eq!(m.flywheel_for(0.06), Ok(0.0));
    let extra = m.flywheel_for(0.01).unwrap();
    let s = steady(&m.with_flywheel(extra).unwrap());
    assert!(rel(s.delta, 0.01) < 1e-12, "{}", s.delta);
    // The same load plus a negligible second order takes the bisection path.
    let m2 = drive(&[h(0.125, 12.0, 0.0), h(0.5, 1e-9, 0.0)], J);
    let extra2 = m2.flywheel_for(0.01).unwrap();
    assert!(rel(extra2, extra) < 1e-7, "{extra2} vs {extra}");
    // Two real orders: δ ≤ target at the answer, above it just below.
    let m3 = drive(&[h(0.125, 12.0, 0.0), h(0.5, 6.0, 1.0)], J);
    let e3 = m3.flywheel_for(0.01).unwrap();
    assert!(steady(&m3.with_flywheel(e3).unwrap()).delta <= 0.01);
    assert!(steady(&m3.with_flywheel(e3 * (1.0 - 1e-6)).unwrap()).delta > 0.01);
    // An existing flywheel is accounted for.
    let with = m.with_flywheel(0.1).unwrap();
    assert!((with.flywheel_for(0.01).unwrap() - (extra - 0.1)).abs() < 1e-12);
    for bad in [0.0, -0.1, 2.0, f64::NAN, f64::INFINITY] {
        assert_eq!(m.flywheel_for(bad), Err(DesignError::InvalidTarget));
        assert!(m.irregularity(Some(bad)).is_err());
    }
}

/// δ of the seed's motor with mean load M1 and `harmonics` (order, amplitude, phase) at total
/// inertia `j`, independent of the model: ω² in the paper's D-coefficients (eq. 11, summed
/// over the harmonics), its extrema by brute force over `samples` points of `period` with a
/// parabolic vertex at each local extremum, δ from the difference of squares. The brute force
/// misses an extremum by at most `½·C·(step/2)²` before the vertex refinement,
/// `C = Σ amplitude·n²` of ω².
fn reference_delta(harmonics: &[(f64, f64, f64)], j: f64, period: f64, samples: usize) -> f64 {
    let k = W0 * W0 - WM * WM;
    // D1 = M_m/(J·K), D2 = (M_m·ω0² − M1·K)/(J·K); J cancels from D2/D1 (and J·K would
    // overflow for the largest inertias).
    let d1 = MM / k / j;
    let ubar = (MM * W0 * W0 - M1 * k) / MM;
    let s = |phi: f64| -> f64 {
        harmonics
            .iter()
            .map(|&(n, m2, psi)| {
                let d3 = m2 / j;
                let th = n * phi + psi;
                2.0 * d3 * (n * th.cos() - 2.0 * d1 * th.sin()) / (4.0 * d1 * d1 + n * n)
            })
            .sum()
    };
    let step = period / samples as f64;
    let (smax, smin) = vertex_extrema(
        core::iter::once(-step)
            .chain((0..=samples).map(|i| i as f64 * step))
            .map(s),
    );
    let w = (ubar + smax).sqrt() + (ubar + smin).sqrt();
    2.0 * (smax - smin) / (w * w)
}

/// A load with orders 3 and 1000: a common period of 32 000 samples, the slowest prediction.
fn slow_drive() -> DriveModel {
    drive(&[h(3.0, 12.0, 0.0), h(1000.0, 6.0, 1.0)], J)
}

#[test]
fn flywheel_target_below_resolution_is_rejected() {
    let slow = slow_drive();
    assert_eq!(
        slow.horizon(),
        Horizon::Period {
            radians: 2.0 * PI,
            samples: 32_000
        }
    );
    // Tiny targets, subnormal ones included, and one just below the floor: an error naming
    // the target, before any search (these once doubled the inertia a thousand times).
    let below = MIN_DELTA_TARGET * (1.0 - f64::EPSILON);
    for m in [seed(), slow] {
        for tiny in [
            1e-308,
            1e-30,
            1e-310,
            f64::MIN_POSITIVE,
            5e-324,
            1e-17,
            below,
        ] {
            assert_eq!(
                m.flywheel_for(tiny),
                Err(DesignError::TargetBelowResolution),
                "{tiny}"
            );
            let e = m.irregularity(Some(tiny)).unwrap_err();
            assert_eq!(e.parameter(), "delta_limit", "{tiny}");
        }
    }
    let msg = DesignError::TargetBelowResolution.to_string();
    assert!(
        msg.contains("delta_target") && msg.contains("2.220446049250313e-16"),
        "{msg}"
    );
}

#[test]
fn flywheel_for_smallest_target_meets_it() {
    // The floor itself is accepted. Closed form: δ equals the target to rounding.
    let m = seed();
    let extra = m.flywheel_for(MIN_DELTA_TARGET).unwrap();
    let s = steady(&m.with_flywheel(extra).unwrap());
    assert!(rel(s.delta, MIN_DELTA_TARGET) < 1e-12, "{}", s.delta);
    // Bisection, 32 000-sample period: δ ≤ target at the answer and, the bracket being within
    // 1e-10 and δ ∝ 1/J this far out, within 1e-9 of it.
    let slow = slow_drive();
    let extra = slow.flywheel_for(MIN_DELTA_TARGET).unwrap();
    assert!(extra.is_finite() && extra > 1e10, "{extra}");
    let d = steady(&slow.with_flywheel(extra).unwrap()).delta;
    assert!(
        d <= MIN_DELTA_TARGET && rel(d, MIN_DELTA_TARGET) < 1e-9,
        "{d}"
    );
    // The same against the independent brute-force reference (orders 1 and 3, 2π period,
    // 200 000 points: vertex error far below 1e-9 of the swing).
    let harmonics = [(1.0, 12.0, 0.0), (3.0, 9.0, 2.0)];
    let hs: Vec<Harmonic> = harmonics.iter().map(|&(n, a, p)| h(n, a, p)).collect();
    let m = drive(&hs, J);
    assert!(steady(&m).delta > 0.004);
    for target in [0.004, 1e-9, MIN_DELTA_TARGET] {
        let extra = m.flywheel_for(target).unwrap();
        let reference = reference_delta(&harmonics, J + extra, 2.0 * PI, 200_000);
        assert!(rel(reference, target) < 1e-8, "{target}: {reference}");
        assert!(steady(&m.with_flywheel(extra).unwrap()).delta <= target);
    }
}

#[test]
fn flywheel_beyond_f64_is_unreachable() {
    // Harmonics of 1e300 N·m: the needed inertia grows like 1/δ, ≈ 1.1e307 kg·m² at
    // δ = 1e-11 (just inside f64), ≈ 1e309 at 1e-13 (beyond it).
    let harmonics = [(1.0, 1e300, 0.0), (3.0, 5e299, 2.0)];
    let hs: Vec<Harmonic> = harmonics.iter().map(|&(n, a, p)| h(n, a, p)).collect();
    let m = drive(&hs, J);
    assert!(m.predict().steady().is_none());
    let extra = m.flywheel_for(1e-11).unwrap();
    assert!(extra.is_finite() && extra > 1e307, "{extra}");
    let reference = reference_delta(&harmonics, J + extra, 2.0 * PI, 200_000);
    assert!(rel(reference, 1e-11) < 1e-8, "{reference}");
    // No f64 inertia reaches 1e-13: even the largest flywheel the model holds leaves δ above it.
    assert_eq!(m.flywheel_for(1e-13), Err(DesignError::Unreachable));
    // (n·J must stay finite: order 3 caps J below f64::MAX / 3.)
    let largest = m.with_flywheel(f64::MAX / 4.0).unwrap();
    assert!(steady(&largest).delta > 1e-13);
    assert_eq!(
        m.irregularity(Some(1e-13)).unwrap().flywheel_for_limit,
        None
    );
    // One order (closed form) likewise.
    let one = drive(&[h(1.0, 1e300, 0.0)], J);
    assert!(one.flywheel_for(1e-11).unwrap() > 1e307);
    assert_eq!(one.flywheel_for(1e-13), Err(DesignError::Unreachable));
}

/// Central differences with a relative step of 1e-5 (≈ ε^(1/3)·10 balances the O(h²)
/// truncation and the O(ε/h) rounding) against the analytic sensitivities.
fn check_sensitivity(m: &DriveModel) {
    let sens = m.sensitivity().unwrap();
    let dj = 1e-5 * m.total_inertia();
    let d = |x: &DriveModel| steady(x).delta;
    let with_j = |j: f64| DriveModel::new(*m.motor(), m.load().clone(), j, m.flywheel()).unwrap();
    let fd_j = (d(&with_j(m.inertia() + dj)) - d(&with_j(m.inertia() - dj))) / (2.0 * dj);
    let e = 1e-5;
    let mm = m.motor().model().breakdown_torque();
    let fd_m = (d(&m.with_motor(m.motor().scaled(1.0 + e).unwrap()).unwrap())
        - d(&m.with_motor(m.motor().scaled(1.0 - e).unwrap()).unwrap()))
        / (2.0 * e * mm);
    assert!(rel(sens.d_delta_d_inertia, fd_j) < 1e-6, "{sens:?} {fd_j}");
    assert!(
        rel(sens.d_delta_d_breakdown_torque, fd_m) < 1e-6,
        "{sens:?} {fd_m}"
    );
    assert!(sens.d_delta_d_inertia < 0.0 && sens.d_delta_d_breakdown_torque < 0.0);
}

#[test]
fn sensitivities_match_central_differences() {
    let fw = seed().with_flywheel(0.05).unwrap();
    check_sensitivity(&seed());
    check_sensitivity(&fw);
    check_sensitivity(&drive(&[h(0.125, 12.0, 0.0), h(0.5, 6.0, 1.0)], J));
    let irr = drive(&[h(0.125, 12.0, 0.0), h(2f64.sqrt(), 6.0, 1.0)], J);
    assert_eq!(irr.horizon(), Horizon::Unbounded);
    check_sensitivity(&irr);
    // Scaling the motor via its breakdown torque is the same as scaling the characteristic.
    let stronger: Motor = Parabola::new(W0, WM, MM * 1.1).unwrap().into();
    let a = seed().with_motor(stronger).unwrap();
    let b = seed()
        .with_motor(seed_motor().scaled(1.1).unwrap())
        .unwrap();
    assert!(rel(steady(&a).delta, steady(&b).delta) < 1e-14);
}

/// The load's period in whole revolutions is the lcm of the orders' denominators: the window
/// a monitor needs, not one cycle of the lowest order.
#[test]
fn period_in_revolutions() {
    assert_eq!(period_revolutions(&[1.0 / 3.0, 0.5]), Some(6));
    assert_eq!(period_revolutions(&[0.125, 0.5]), Some(8));
    assert_eq!(period_revolutions(&[2.0 / 3.0, 0.75]), Some(12));
    // Common period 1.5 revolutions: 3 whole revolutions hold two of it.
    assert_eq!(period_revolutions(&[2.0 / 3.0, 4.0 / 3.0]), Some(3));
    // Too many samples for the prediction's extrema (`Horizon::Unbounded`), a short window.
    assert_eq!(period_revolutions(&[3000.0, 0.125]), Some(8));
    assert_eq!(period_revolutions(&[1.0, 2f64.sqrt()]), None);
    assert_eq!(period_revolutions(&[]), Some(1));
    assert_eq!(period_revolutions(&[0.0, -0.25]), Some(4));
    assert_eq!(
        period_revolutions(&[1.0 / 1023.0, 1.0 / 1021.0]),
        Some(1023 * 1021)
    );
    // The model's: harmonics that are there, and the inertia's orders.
    let m = drive(
        &[h(1.0 / 3.0, 12.0, 0.0), h(0.5, 12.0, 1.0), h(0.2, 0.0, 0.0)],
        J,
    );
    assert_eq!(m.period_revolutions(), Some(6));
    let v = drive(&[h(0.5, 12.0, 0.0)], J)
        .with_inertia_harmonics(&[ih(1.0 / 3.0, 0.01, 0.0)])
        .unwrap();
    assert_eq!(v.period_revolutions(), Some(6));
    assert_eq!(drive(&[], J).period_revolutions(), Some(1));
}

#[test]
fn horizons() {
    let period = |orders: &[f64]| {
        let hs: Vec<Harmonic> = orders.iter().map(|&n| h(n, 1.0, 0.0)).collect();
        drive(&hs, J).horizon()
    };
    assert_eq!(
        period(&[0.125, 0.5]),
        Horizon::Period {
            radians: 16.0 * PI,
            samples: 128
        }
    );
    assert_eq!(
        period(&[2.0 / 3.0, 0.75]),
        Horizon::Period {
            radians: 24.0 * PI,
            samples: 32 * 9
        }
    );
    assert_eq!(period(&[1.0, 2f64.sqrt()]), Horizon::Unbounded);
    assert_eq!(period(&[3000.0, 0.125]), Horizon::Unbounded);
    assert_eq!(period(&[1.0 / 1023.0, 1.0 / 1021.0]), {
        Horizon::Period {
            radians: 2.0 * PI * 1023.0 * 1021.0,
            samples: 32 * 1023,
        }
    });
    // The unbounded bound is never below the extrema over a long common window.
    let m = drive(&[h(1.0, 5.0, 0.0), h(2f64.sqrt(), 3.0, 0.0)], J);
    let s = steady(&m);
    for i in 0..100_000 {
        let w = m.steady_omega(i as f64 * 0.01).unwrap();
        assert!(w <= s.omega_max && w >= s.omega_min);
    }
}

#[test]
fn invalid_inputs_are_typed_errors() {
    let load = || Load::new(24.0, &[h(0.125, 12.0, 0.0)]).unwrap();
    for x in crate::testutil::BAD {
        let e = DriveModel::new(seed_motor(), load(), x, 0.0).unwrap_err();
        assert_eq!(e.parameter(), "inertia");
        if x != 0.0 {
            let e = DriveModel::new(seed_motor(), load(), J, x).unwrap_err();
            assert_eq!(e.parameter(), "flywheel");
        }
    }
    assert!(DriveModel::new(seed_motor(), load(), J, 0.0).is_ok());
    assert_eq!(
        DriveModel::new(seed_motor(), load(), 1e308, 1e308),
        Err(ConfigError::OutOfRange("flywheel"))
    );
    // Amplitudes or means whose ω² overflows.
    assert_eq!(
        DriveModel::new(
            seed_motor(),
            Load::new(0.0, &[h(1e-6, 1e308, 0.0)]).unwrap(),
            1e-300,
            0.0
        ),
        Err(ConfigError::OutOfRange("harmonic.amplitude"))
    );
    let tiny: Motor = Parabola::new(1.0, 0.5, 1e-300).unwrap().into();
    assert_eq!(
        DriveModel::new(tiny, Load::new(-1e300, &[]).unwrap(), J, 0.0),
        Err(ConfigError::OutOfRange("load.mean"))
    );
}

#[test]
fn kloss_prediction_against_the_real_curve() {
    // A 4-pole 50 Hz motor, σm = 0.2, at a light load (M1 = 40 N·m ≈ 0.25·M_m). The
    // prediction integrates the Kloss curve itself (the `shooting` module), so it agrees with
    // a direct RK4 integration in time within 1e-9 (measured 1.8e-11) whichever parabola the
    // motor was built with; through those parabolas it was 0.013535 (tangent, −1.7 %) and
    // 0.019890 (breakdown, +44 %) against 0.013776.
    let k = Kloss::new(157.08, 0.2, 158.0).unwrap();
    let load = Load::new(40.0, &[h(0.125, 12.0, 0.0)]).unwrap();
    let at = |fit| DriveModel::new(Motor::kloss(k, fit).unwrap(), load.clone(), J, 0.0).unwrap();
    let tangent = at(KlossFit::SynchronousTangent);
    let breakdown = at(KlossFit::Breakdown);
    let (wmax, wmin) = integrate(&tangent, 1000.0, 16.0 * PI, 1e-4);
    let truth = delta_of(wmax, wmin);
    assert!((truth - 0.013776).abs() < 5e-7, "{truth}");
    let et = rel(steady(&tangent).delta, truth);
    let eb = rel(steady(&breakdown).delta, truth);
    assert!(et < 1e-9, "tangent start: error {et}");
    assert!(eb < 1e-9, "breakdown start: error {eb}");
    let through = |m: &DriveModel| {
        let p = DriveModel::new(Motor::parabola(*m.motor().model()), load.clone(), J, 0.0);
        steady(&p.unwrap()).delta
    };
    assert!(rel(through(&tangent), truth) > 0.015 && rel(through(&breakdown), truth) > 0.4);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Arbitrary parameters: either a typed error or a prediction with finite numbers.
    #[test]
    fn never_panics_never_nan(
        w0 in prop_oneof![any::<f64>(), 1.0..1e4f64],
        wm_frac in prop_oneof![any::<f64>(), 0.0..1.0f64],
        mm in prop_oneof![any::<f64>(), 1e-3..1e4f64],
        j in prop_oneof![any::<f64>(), 1e-4..1e3f64],
        jf in prop_oneof![any::<f64>(), 0.0..1e3f64],
        m1 in prop_oneof![any::<f64>(), -1e3..1e3f64],
        hs in proptest::collection::vec(
            (
                prop_oneof![any::<f64>(), Just(0.0), Just(0.125), Just(0.5), Just(1.0),
                            Just(3.0), 0.0..20.0f64],
                prop_oneof![any::<f64>(), -1e3..1e3f64],
                prop_oneof![any::<f64>(), -10.0..10.0f64],
            ),
            0..10,
        ),
        limit in prop_oneof![any::<f64>(), 1e-4..1.0f64],
    ) {
        let motor = Parabola::new(w0, wm_frac * w0, mm).map(Motor::from);
        let harmonics: Result<Vec<Harmonic>, _> =
            hs.iter().map(|&(n, a, p)| Harmonic::new(n, a, p)).collect();
        let (Ok(motor), Ok(harmonics)) = (motor, harmonics) else { return Ok(()); };
        let Ok(load) = Load::new(m1, &harmonics) else { return Ok(()); };
        let Ok(m) = DriveModel::new(motor, load, j, jf) else { return Ok(()); };
        match m.predict() {
            Prediction::Steady(s) => {
                prop_assert!(s.omega_max.is_finite() && s.omega_min > 0.0);
                prop_assert!(s.omega_min <= s.omega_max);
                prop_assert!(s.delta.is_finite() && (0.0..2.0).contains(&s.delta));
                if let Some(sens) = m.sensitivity() {
                    prop_assert!(!sens.d_delta_d_inertia.is_nan());
                    prop_assert!(!sens.d_delta_d_breakdown_torque.is_nan());
                }
            }
            Prediction::Stalls(st) => prop_assert!(st.u_min <= 0.0 && !st.u_mean.is_nan()),
        }
        if let Ok(irr) = m.irregularity(Some(limit)) {
            prop_assert!(irr.delta.is_finite() && irr.omega_max.is_finite());
            if let Some(f) = irr.flywheel_for_limit {
                prop_assert!(f.is_finite() && f >= 0.0);
            }
        }
        prop_assert!(!m.omega_squared(1.0).is_nan());
    }
}

fn ih(order: f64, amplitude: f64, phase: f64) -> InertiaHarmonic {
    InertiaHarmonic::new(order, amplitude, phase).unwrap()
}

/// The J(φ) path (trapezoid rule on one period, FFT, golden section on the series) run on
/// constant-inertia drives reproduces the closed form: δ, ωmax, ωmin and ω² at any angle
/// within 1e-12 relative (measured worst 1.9e-14 for δ, printed; down to a 1.7e-16 δ, whose swing the
/// split into mean and oscillating parts keeps), with the extrema at the same angles.
#[test]
fn varying_path_reproduces_the_constant_inertia_closed_form() {
    let loads: [&[Harmonic]; 6] = [
        &[h(0.125, 12.0, 0.0)],
        &[h(1.0, 12.0, 0.3), h(2.0, 5.0, 1.0), h(3.0, -2.0, 0.2)],
        &[h(0.125, 12.0, 0.0), h(0.5, 1e-9, 0.7)],
        &[h(2.0, 1e-12, 0.0)],
        &[h(0.0, 3.0, 0.4), h(1.5, 8.0, 2.0), h(0.5, 4.0, -1.0)],
        &[h(4.0, 20.0, 0.0), h(4.0, -20.0, 0.0), h(1.0, 1.0, 0.0)],
    ];
    let mut worst = 0.0f64;
    for (k, hs) in loads.iter().enumerate() {
        for j in [J, 0.05, 3.0] {
            let m = drive(hs, j);
            let v = m.on_varying_path().unwrap();
            assert!(matches!(v.horizon(), Horizon::Varying { .. }), "{k}");
            let (a, b) = (steady(&m), steady(&v));
            worst = worst.max(rel(b.delta, a.delta));
            assert!(
                rel(b.delta, a.delta) < 1e-12,
                "{k} {j}: {} {}",
                b.delta,
                a.delta
            );
            assert!(rel(b.omega_max, a.omega_max) < 1e-14, "{k} {j}");
            assert!(rel(b.omega_min, a.omega_min) < 1e-14, "{k} {j}");
            assert_eq!(b.omega_rms, a.omega_rms);
            let curve = v.steady_curve();
            for i in 0..50 {
                let phi = 0.37 * i as f64;
                assert!(rel(curve.omega_squared(phi), m.omega_squared(phi)) < 1e-14);
            }
            // The extremal angles lie where the closed form peaks.
            let (pmax, pmin) = (b.phi_max.unwrap(), b.phi_min.unwrap());
            assert!(
                rel(m.steady_omega(pmax).unwrap(), a.omega_max) < 1e-14,
                "{k} {j}"
            );
            assert!(
                rel(m.steady_omega(pmin).unwrap(), a.omega_min) < 1e-14,
                "{k} {j}"
            );
        }
    }
    // The figure README quotes (`-- --nocapture`).
    eprintln!("J(φ) path against the closed form: worst δ {worst:.1e}");
    // Inertia harmonics of amplitude 0 leave the constant-inertia model as it was.
    let m = seed();
    assert_eq!(m.with_inertia_harmonics(&[ih(2.0, 0.0, 1.0)]).unwrap(), m);
}

/// J(φ) is validated once, naming the bad value.
#[test]
fn inertia_harmonics_are_validated() {
    for x in [f64::NAN, f64::INFINITY] {
        assert_eq!(
            InertiaHarmonic::new(x, 0.1, 0.0),
            Err(ConfigError::NonFinite("inertia_harmonic.order"))
        );
        assert_eq!(
            InertiaHarmonic::new(1.0, x, 0.0),
            Err(ConfigError::NonFinite("inertia_harmonic.amplitude"))
        );
        assert_eq!(
            InertiaHarmonic::new(1.0, 0.1, x),
            Err(ConfigError::NonFinite("inertia_harmonic.phase"))
        );
    }
    for bad in [0.0, -1.0] {
        assert_eq!(
            InertiaHarmonic::new(bad, 0.1, 0.0),
            Err(ConfigError::NotPositive("inertia_harmonic.order"))
        );
    }
    assert_eq!(
        InertiaHarmonic::new(2e6, 0.1, 0.0),
        Err(ConfigError::OutOfRange("inertia_harmonic.order"))
    );
    let m = seed();
    // |a| adding up to J or more: J(φ) could reach 0.
    assert_eq!(
        m.with_inertia_harmonics(&[ih(2.0, 0.2, 0.0), ih(4.0, -0.123, 0.0)]),
        Err(ConfigError::Inconsistent("inertia_harmonic.amplitude"))
    );
    assert!(m
        .with_inertia_harmonics(&[ih(2.0, 0.1, 0.0), ih(4.0, -0.05, 0.0)])
        .is_ok());
    // J(φ) down to 7 % of its mean over 32 cycles of order 4 in the load's 16π period would
    // need more than MAX_NODES nodes.
    assert_eq!(
        m.with_inertia_harmonics(&[ih(2.0, 0.2, 0.0), ih(4.0, -0.1, 0.0)]),
        Err(ConfigError::OutOfRange("inertia_harmonics"))
    );
    // J(φ) down to 5 % of its mean still resolves, on more nodes.
    let deep = drive(&[], 1.0)
        .with_inertia_harmonics(&[ih(1.0, 0.95, 0.0)])
        .unwrap();
    let Horizon::Varying { nodes, .. } = deep.horizon() else {
        panic!()
    };
    assert!((512..=MAX_NODES as u32).contains(&nodes), "{nodes}");
    assert!(deep.predict().steady().is_some());
    // A flywheel makes room for larger amplitudes, and the harmonics survive with_flywheel.
    let f = m.with_flywheel(1.0).unwrap();
    let big = f.with_inertia_harmonics(&[ih(2.0, 1.0, 0.0)]).unwrap();
    assert_eq!(big.inertia_harmonics().len(), 1);
    assert_eq!(
        big.with_flywheel(0.0),
        Err(ConfigError::Inconsistent("inertia_harmonic.amplitude"))
    );
    assert_eq!(big.with_flywheel(2.0).unwrap().inertia_harmonics().len(), 1);
    // No common period with the load's order 1/8.
    assert_eq!(
        m.with_inertia_harmonics(&[ih(core::f64::consts::SQRT_2, 0.1, 0.0)]),
        Err(ConfigError::Inconsistent("inertia_harmonic.order"))
    );
    assert_eq!(
        m.with_inertia_harmonics(&[ih(1.0, 0.01, 0.0); MAX_INERTIA_HARMONICS + 1]),
        Err(ConfigError::Capacity("inertia_harmonics"))
    );
    // J(φ) within 1e-9 of zero: the periodic solution needs more than MAX_NODES nodes.
    let edge = drive(&[], 1.0).with_inertia_harmonics(&[ih(1.0, 1.0 - 1e-9, 0.0)]);
    assert_eq!(edge, Err(ConfigError::OutOfRange("inertia_harmonics")));
}

/// A motor stiff against the inertia's swing: the integrating factor of the J(φ) solution
/// would swing by more than e^12 over the period, and its cancellation would leave noise (a
/// stall with ω² of −1e11 s⁻² for a drive that runs at δ = 0.075, or ω max = ∞). Such a drive
/// is shot with the parabola instead, and refused, naming the inertia harmonics, where that
/// needs too many steps; below the bound the J(φ) path agrees with the shooting.
#[test]
fn a_motor_too_stiff_for_the_inertia_swing_is_shot_or_rejected() {
    // 4.7e260 N·m against 332 kg·m² swinging by 7e-252 of itself: ΔP̃ ≈ 83.
    let (w0, j) = (1009.9244741049496, 331.97392921331976);
    let motor = Parabola::new(w0, 0.24259202387234952 * w0, 4.730776675937407e260).unwrap();
    let m = DriveModel::new(motor.into(), Load::new(0.0, &[]).unwrap(), j, 0.0).unwrap();
    assert_eq!(
        m.with_inertia_harmonics(&[ih(0.5, -7.015711195067623e-252 * j, 0.0)]),
        Err(ConfigError::OutOfRange("inertia_harmonics"))
    );
    // Ordinary magnitudes: 1e7 N·m on 1 kg·m² swinging by 1 % at order 1 (ΔP̃ ≈ 27) is shot,
    // a steady state (it read as a stall); 2e6 N·m (ΔP̃ ≈ 5) is solved on the
    // J(φ) path, as the shooting predicts them.
    let at = |mm: f64| {
        let motor = Parabola::new(100.0, 50.0, mm).unwrap();
        let load = Load::new(0.0, &[h(1.0, 0.1 * mm, 0.0)]).unwrap();
        DriveModel::new(motor.into(), load, 1.0, 0.0)
            .unwrap()
            .with_inertia_harmonics(&[ih(1.0, 0.01, 0.0)])
    };
    let stiff = at(1e7).unwrap();
    assert!(matches!(stiff.horizon(), Horizon::Shooting { .. }));
    let s = steady(&stiff);
    assert!(s.delta > 0.0 && s.delta < 0.2, "{s:?}");
    let m = at(2e6).unwrap();
    assert!(matches!(m.horizon(), Horizon::Varying { .. }));
    let (a, b) = (steady(&m), steady(&m.on_shooting_path().unwrap()));
    assert!(rel(a.delta, b.delta) < 1e-10, "{} {}", a.delta, b.delta);
    assert!(rel(a.omega_max, b.omega_max) < 1e-10, "{a:?} {b:?}");
    assert!(rel(a.omega_min, b.omega_min) < 1e-10, "{a:?} {b:?}");
}

/// A press, J = 1 ± 0.4 kg·m² twice a revolution, constant load: the mean of ω² over φ is
/// ū = (B − M1)/a as with a constant inertia (the period mean of eq. 1 in w = J·ω²), and with a
/// motor weak against the inertia the swing is nearly the energy-conserving ω ∝ 1/√J:
/// δ ≈ 2(√(1.4/0.6) − 1)/(√(1.4/0.6) + 1) = 0.4165.
#[test]
fn a_press_swings_as_its_inertia_varies() {
    let motor = Motor::parabola(Parabola::new(160.0, 40.0, 300.0).unwrap());
    let m = DriveModel::new(motor, Load::new(50.0, &[]).unwrap(), 1.0, 0.0)
        .unwrap()
        .with_inertia_harmonics(&[ih(2.0, 0.4, 0.0)])
        .unwrap();
    let Horizon::Varying { radians, nodes } = m.horizon() else {
        panic!("{:?}", m.horizon());
    };
    assert_eq!(radians, PI);
    assert!(nodes <= 256, "{nodes}");
    let s = steady(&m);
    let r = (1.4f64 / 0.6).sqrt();
    let energy = 2.0 * (r - 1.0) / (r + 1.0);
    assert!(rel(s.delta, energy) < 0.01, "{} {energy}", s.delta);
    let curve = m.steady_curve();
    let n = 4096;
    let mean: f64 = (0..n)
        .map(|i| curve.omega_squared(PI * i as f64 / n as f64))
        .sum::<f64>()
        / n as f64;
    assert!(rel(mean, m.u_mean()) < 1e-13, "{mean} {}", m.u_mean());
    // The fastest speed where J is smallest (φ = π/2), the slowest near J's largest (φ = 0),
    // a little later for the motor's lag.
    assert!((s.phi_max.unwrap() - PI / 2.0).abs() < 0.05);
    let pmin = s.phi_min.unwrap();
    assert!(pmin.min(PI - pmin) < 0.05, "{pmin}");
    // A tiny variation keeps its relative precision: δ is linear in the amplitude.
    let tiny = |e: f64| steady(&m.with_inertia_harmonics(&[ih(2.0, e, 0.3)]).unwrap()).delta;
    let (d1, d2) = (tiny(1e-6), tiny(1e-12));
    assert!(rel(d2 * 1e6, d1) < 2e-6, "{d1:e} {d2:e}");
}

/// A small deterministic generator for the randomised drives.
pub(super) fn next(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 53) as f64
}

/// A random seed-motor drive with up to two load harmonics and one to three inertia harmonics
/// adding up to at most 40 % of J.
pub(super) fn random_varying(state: &mut u64) -> DriveModel {
    let mut u = |lo: f64, hi: f64| lo + (hi - lo) * next(state);
    let orders = [0.5, 1.0, 2.0, 3.0];
    let pick = |x: f64| orders[((x * 4.0) as usize).min(3)];
    let j = u(0.05, 2.0);
    let loads: Vec<Harmonic> = (0..(u(0.0, 2.99) as usize))
        .map(|_| h(pick(u(0.0, 1.0)), u(-12.0, 12.0), u(0.0, 6.0)))
        .collect();
    let count = u(1.0, 3.99) as usize;
    let budget = 0.4 * j * u(0.3, 1.0) / count as f64;
    let inertia: Vec<InertiaHarmonic> = (0..count)
        .map(|_| ih(pick(u(0.0, 1.0)), budget * u(-1.0, 1.0), u(0.0, 6.0)))
        .collect();
    drive(&loads, j).with_inertia_harmonics(&inertia).unwrap()
}

/// Flywheel sizing with J(φ): δ falls with the flywheel on a grid of 40 flywheels for each of
/// 12 random drives (checked, not assumed), and `flywheel_for` returns one that meets the
/// target while 1e-8 less misses it; `irregularity` reports it.
#[test]
fn flywheel_sizing_with_varying_inertia() {
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    for k in 0..12 {
        let m = random_varying(&mut state);
        let j = m.total_inertia();
        let mut last = f64::INFINITY;
        for i in 0..40 {
            let f = j * (1.25f64.powi(i) - 1.0);
            let d = steady(&m.with_flywheel(f).unwrap()).delta;
            assert!(d < last, "drive {k}: δ({f}) = {d} after {last}");
            last = d;
        }
        let d0 = steady(&m).delta;
        let target = d0 / 7.0;
        let extra = m.flywheel_for(target).unwrap();
        assert!(
            steady(&m.with_flywheel(extra).unwrap()).delta <= target,
            "{k}"
        );
        let less = m.with_flywheel(extra * (1.0 - 1e-8)).unwrap();
        assert!(steady(&less).delta > target, "{k}");
        assert_eq!(m.flywheel_for(d0 * 1.01), Ok(0.0));
        let irr = m.irregularity(Some(target)).unwrap();
        assert_eq!(irr.flywheel_for_limit, Some(extra));
        assert_eq!(irr.delta, d0);
    }
}

/// With J(φ) the sensitivities are central differences: on the J(φ) path of constant-inertia
/// drives they agree with the analytic ones within 1e-7 relative; with inertia harmonics a
/// flywheel lowers δ, and the derivative predicts a 1 % step to within a few 1e-4.
#[test]
fn sensitivity_with_varying_inertia() {
    for hs in [
        &[h(0.125, 12.0, 0.0)][..],
        &[h(1.0, 12.0, 0.3), h(2.0, 5.0, 1.0)][..],
    ] {
        let m = drive(hs, J);
        let (a, b) = (
            m.sensitivity().unwrap(),
            m.on_varying_path().unwrap().sensitivity().unwrap(),
        );
        assert!(
            rel(b.d_delta_d_inertia, a.d_delta_d_inertia) < 1e-7,
            "{a:?} {b:?}"
        );
        assert!(
            rel(b.d_delta_d_breakdown_torque, a.d_delta_d_breakdown_torque) < 1e-7,
            "{a:?} {b:?}"
        );
    }
    let mut state = 12345u64;
    for _ in 0..6 {
        let m = random_varying(&mut state);
        let s = m.sensitivity().unwrap();
        assert!(s.d_delta_d_inertia < 0.0);
        let dj = 0.01 * m.total_inertia();
        let step = steady(&m.with_flywheel(dj).unwrap()).delta - steady(&m).delta;
        assert!(rel(step, s.d_delta_d_inertia * dj) < 0.02, "{step} {s:?}");
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    /// Arbitrary J(φ): either a typed error or a prediction with finite numbers, a flywheel
    /// that meets the limit, finite sensitivities.
    #[test]
    fn varying_inertia_never_panics_never_nan(
        w0 in prop_oneof![1 => any::<f64>(), 4 => 1.0..1e4f64],
        wm_frac in 0.0..1.0f64,
        mm in prop_oneof![1 => any::<f64>(), 4 => 1e-3..1e4f64],
        j in prop_oneof![1 => any::<f64>(), 4 => 1e-4..1e3f64],
        m1 in -1e3..1e3f64,
        hs in proptest::collection::vec(
            (prop_oneof![Just(0.125), Just(1.0), Just(3.0)], -1e3..1e3f64, -10.0..10.0f64),
            0..3,
        ),
        js in proptest::collection::vec(
            (
                prop_oneof![1 => any::<f64>(), 4 => prop_oneof![Just(0.5), Just(1.0), Just(2.0),
                                                               Just(6.0)]],
                prop_oneof![1 => any::<f64>(), 4 => -0.33..0.33f64],
                -10.0..10.0f64,
            ),
            1..4,
        ),
        limit in 1e-4..1.0f64,
    ) {
        let motor = Parabola::new(w0, wm_frac * w0, mm).map(Motor::from);
        let harmonics: Result<Vec<Harmonic>, _> =
            hs.iter().map(|&(n, a, p)| Harmonic::new(n, a, p)).collect();
        let inertia: Result<Vec<InertiaHarmonic>, _> = js
            .iter()
            .map(|&(n, a, p)| InertiaHarmonic::new(n, a * j, p))
            .collect();
        let (Ok(motor), Ok(harmonics), Ok(inertia)) = (motor, harmonics, inertia) else {
            return Ok(());
        };
        let Ok(load) = Load::new(m1, &harmonics) else { return Ok(()); };
        let Ok(m) = DriveModel::new(motor, load, j, 0.0) else { return Ok(()); };
        let Ok(m) = m.with_inertia_harmonics(&inertia) else { return Ok(()); };
        finite_results(&m, limit)?;
        prop_assert!(!m.omega_squared(1.0).is_nan());
    }
}

/// What every drive the model accepts gives, whatever its path (J(φ), Kloss): a finite steady
/// state with ω min ≤ ω max and δ in [0, 2), or a stall; finite sensitivities; and a flywheel
/// for `limit` that is finite and meets it.
pub(super) fn finite_results(m: &DriveModel, limit: f64) -> Result<(), TestCaseError> {
    match m.predict() {
        Prediction::Steady(s) => {
            prop_assert!(s.omega_max.is_finite() && s.omega_min > 0.0);
            prop_assert!(s.omega_min <= s.omega_max);
            prop_assert!(s.delta.is_finite() && (0.0..2.0).contains(&s.delta));
            if let Some(sens) = m.sensitivity() {
                prop_assert!(sens.d_delta_d_inertia.is_finite());
                prop_assert!(sens.d_delta_d_breakdown_torque.is_finite());
            }
        }
        Prediction::Stalls(st) => prop_assert!(st.u_min <= 0.0 && !st.u_mean.is_nan()),
    }
    if let Ok(irr) = m.irregularity(Some(limit)) {
        prop_assert!(irr.delta.is_finite() && irr.omega_max.is_finite());
        if let Some(f) = irr.flywheel_for_limit {
            prop_assert!(f.is_finite() && f >= 0.0);
            let sized = m.with_flywheel(f).unwrap();
            prop_assert!(sized.predict().steady().is_some_and(|s| s.delta <= limit));
        }
    }
    Ok(())
}

/// A crank-slider's J(φ) = J_c + m·r²·(sin φ + λ/2·sin 2φ)² (J_c = 0.1, m·r² = 1, λ = 0.25) as its
/// cosine series: mean 0.6078125, magnitudes adding up to 0.7578125, more than the mean, yet
/// J(φ) ≥ J_c. The check was Σ|amplitude| < J0 and refused it; the least value over the
/// period decides now: 0.1 at φ = 0 (or π), 0.098 for 0.323 + 0.2·(cos φ + cos 2φ) at
/// cos φ = −1/4, and 0 at φ = π for 0.323·(1 + cos φ), which is still refused.
#[test]
fn the_least_inertia_decides_whether_j_stays_positive() {
    let crank = [
        ih(1.0, 0.125, 0.0),
        ih(2.0, 0.5, PI),
        ih(3.0, 0.125, PI),
        ih(4.0, 0.0078125, PI),
    ];
    let j0 = 0.6078125;
    // The series is the closed form.
    for i in 0..1000 {
        let phi = f64::from(i) * 2.0 * PI / 1000.0;
        let series: f64 = crank
            .iter()
            .map(|h| h.amplitude() * libm::cos(h.order() * phi + h.phase()))
            .sum::<f64>()
            + j0;
        let s = libm::sin(phi) + 0.125 * libm::sin(2.0 * phi);
        assert!((series - (0.1 + s * s)).abs() < 1e-14, "{phi}: {series}");
    }
    let (phi, least) = least_inertia(j0, &crank).unwrap();
    assert!((least - 0.1).abs() < 1e-14, "{least}");
    assert!(phi.abs() < 1e-6 || (phi - PI).abs() < 1e-6, "{phi}");
    let two = [ih(1.0, 0.2, 0.0), ih(2.0, 0.2, 0.0)];
    let (phi, least) = least_inertia(0.323, &two).unwrap();
    assert!((least - 0.098).abs() < 1e-14, "{least}");
    assert!((libm::cos(phi) + 0.25).abs() < 1e-7, "{phi}");
    let (phi, least) = least_inertia(0.323, &[ih(1.0, 0.323, 0.0)]).unwrap();
    assert_eq!(least, 0.0);
    assert!((phi - PI).abs() < 1e-6, "{phi}");
    // No common period: not searched.
    assert_eq!(
        least_inertia(
            1.0,
            &[ih(1.0, 0.6, 0.0), ih(core::f64::consts::SQRT_2, 0.6, 0.0)]
        ),
        None
    );
    // The drive model takes the positive ones and refuses the one that reaches 0.
    assert!(drive(&[], j0).with_inertia_harmonics(&crank).is_ok());
    let seed = seed();
    assert!(seed.with_inertia_harmonics(&two).is_ok());
    assert_eq!(
        seed.with_inertia_harmonics(&[ih(1.0, 0.323, 0.0)]),
        Err(ConfigError::Inconsistent("inertia_harmonic.amplitude"))
    );
}
