//! Tests of the shooting solution (Kloss motor): against the closed form with the parabola
//! plugged in, against the tangent parabola where the curves coincide, step halving, stalls,
//! flywheel sizing and sensitivities, and arbitrary inputs.

use super::shooting::{Characteristic, Shooter, STEPS_PER_CYCLE};
use super::tests::{finite_results, next, random_varying};
use super::*;
use crate::testutil::{h, steady};
use core::f64::consts::PI;
use proptest::prelude::*;

fn rel(a: f64, b: f64) -> f64 {
    ((a - b) / b).abs()
}

fn kloss_drive(ws: f64, sm: f64, mm: f64, harmonics: &[Harmonic], m1: f64, j: f64) -> DriveModel {
    let k = Kloss::new(ws, sm, mm).unwrap();
    let motor = Motor::kloss(k, KlossFit::SynchronousTangent).unwrap();
    DriveModel::new(motor, Load::new(m1, harmonics).unwrap(), j, 0.0).unwrap()
}

/// The Kloss drive of finding 10 (M1 = 140 N·m of M_m = 158 N·m, J = 0.05 kg·m²): an
/// independent integration of the Kloss drive gives δ = 0.05245 and a mean speed of
/// 132.97 rad/s; the tangent parabola predicted 0.036375.
#[test]
fn heavily_loaded_kloss_drive() {
    let m = kloss_drive(157.08, 0.25, 158.0, &[h(1.0, 25.0, 0.0)], 140.0, 0.05);
    let s = steady(&m);
    assert!(matches!(m.horizon(), Horizon::Shooting { steps: 128, .. }));
    assert!((s.delta - 0.05245).abs() < 5e-5, "{s:?}");
    assert!(s.within_working_branch);
    // The mean speed over time, 2π over the period's duration, against 132.97.
    let curve = m.steady_curve();
    let n = 4096;
    let hh = 2.0 * PI / f64::from(n);
    let time: f64 = (0..n)
        .map(|i| hh / curve.steady_omega((f64::from(i) + 0.5) * hh).unwrap())
        .sum();
    assert!(
        (2.0 * PI / time - 132.97).abs() < 5e-3,
        "{}",
        2.0 * PI / time
    );
    // The curve passes through the extrema, at rising angles and after a step back.
    for phi in [s.phi_max.unwrap(), s.phi_min.unwrap(), s.phi_max.unwrap()] {
        let w = curve.steady_omega(phi).unwrap();
        assert!(
            rel(w, s.omega_max) < 1e-15 || rel(w, s.omega_min) < 1e-15,
            "{w}"
        );
    }
    assert!(
        rel(
            m.steady_omega(s.phi_min.unwrap() + 2.0 * PI).unwrap(),
            s.omega_min
        ) < 1e-14
    );
    assert!(m.omega_squared(f64::NAN).is_nan());
    assert!(rel(s.omega_rms * s.omega_rms, m.u_mean()) < 1e-15);
}

/// A random parabola drive: seed-like motor, 1–3 load harmonics of orders from a list with
/// fractional ones, random inertia.
fn random_parabola(state: &mut u64) -> DriveModel {
    let mut u = |lo: f64, hi: f64| lo + (hi - lo) * next(state);
    let w0 = u(100.0, 300.0);
    let motor = Motor::parabola(Parabola::new(w0, w0 * u(0.2, 0.7), u(50.0, 500.0)).unwrap());
    let mm = motor.model().breakdown_torque();
    let orders = [0.125, 0.5, 1.0, 1.5, 2.0, 3.0];
    let m1 = mm * u(0.05, 0.5);
    let hs: Vec<Harmonic> = (0..(u(1.0, 3.99) as usize))
        .map(|_| {
            h(
                orders[(u(0.0, 5.99)) as usize],
                m1 * u(-0.5, 0.5),
                u(0.0, 6.0),
            )
        })
        .collect();
    let j = u(0.02, 3.0);
    DriveModel::new(motor, Load::new(m1, &hs).unwrap(), j, 0.0).unwrap()
}

/// The shooting with the parabola plugged in against the closed form (constant J) and the
/// J(φ) path's trapezoid solution: δ within 1e-10 relative, ω max and ω min within 1e-13
/// (measured worst over 40 drives: printed).
#[test]
fn shooting_with_the_parabola_matches_the_closed_form() {
    let mut state = 0x2545_F491_4F6C_DD1Du64;
    let (mut wd, mut ww) = (0.0f64, 0.0f64);
    for k in 0..40 {
        let a = random_parabola(&mut state);
        let b = a.on_shooting_path().unwrap();
        assert!(matches!(b.horizon(), Horizon::Shooting { .. }), "{k}");
        let (sa, sb) = (steady(&a), steady(&b));
        let d = rel(sb.delta, sa.delta);
        let w = rel(sb.omega_max, sa.omega_max).max(rel(sb.omega_min, sa.omega_min));
        assert!(
            d < 1e-10 && w < 1e-13,
            "drive {k}: δ {d:e}, ω {w:e}, {:?}",
            a.horizon()
        );
        assert!(rel(sb.omega_rms, sa.omega_rms) < 1e-13, "{k}");
        (wd, ww) = (wd.max(d), ww.max(w));
    }
    // With J(φ): against the trapezoid solution.
    let mut state = 0x9E37_79B9_7F4A_7C15u64;
    for k in 0..12 {
        let a = random_varying(&mut state);
        let b = a.on_shooting_path().unwrap();
        let (sa, sb) = (steady(&a), steady(&b));
        let d = rel(sb.delta, sa.delta);
        let w = rel(sb.omega_max, sa.omega_max).max(rel(sb.omega_min, sa.omega_min));
        assert!(d < 1e-10 && w < 1e-13, "J(φ) drive {k}: δ {d:e}, ω {w:e}");
        (wd, ww) = (wd.max(d), ww.max(w));
    }
    eprintln!("shooting with the parabola: worst δ {wd:.2e}, ω {ww:.2e}");
}

/// Halving the step changes δ by less than 2e-10 relative on Kloss drives (the sixth-order
/// method's error at 128 steps per cycle; measured worst printed).
#[test]
fn shooting_step_halving() {
    let mut state = 77u64;
    let mut worst = 0.0f64;
    for _ in 0..16 {
        let m = random_kloss(&mut state);
        let Some(s) = m.predict().steady().copied() else {
            continue;
        };
        let Horizon::Shooting { radians, steps } = m.horizon() else {
            panic!("{:?}", m.horizon());
        };
        let shooter = Shooter::new(
            Characteristic::Kloss(*m.motor().kloss_curve().unwrap()),
            m.total_inertia(),
            &[],
            m.load().harmonics(),
            m.load().mean(),
            radians,
            u64::from(steps) * 2 / STEPS_PER_CYCLE,
        )
        .unwrap();
        assert_eq!(shooter.steps(), 2 * steps);
        let fine = shooter.solve(0.0).unwrap();
        let w = |x: f64| libm::sqrt(fine.centre() + x);
        let (hi, lo) = (w(fine.s_max), w(fine.s_min));
        let delta = 2.0 * ((fine.s_max - fine.s_min) / (hi + lo)) / (hi + lo);
        worst = worst.max(rel(delta, s.delta));
    }
    eprintln!("step halving: worst δ change {worst:.2e}");
    assert!(worst < 2e-10);
}

/// A Kloss curve that barely differs from its tangent parabola over the speeds the drive
/// runs at (a light load, slip far below the breakdown slip): δ agrees with the parabola's
/// closed form within the largest relative difference of the two slopes over those speeds
/// (δ scales with the slope's reciprocal at most), and that difference is below 2e-3.
#[test]
fn kloss_near_synchronous_speed_matches_its_tangent_parabola() {
    for (m1, amp, j) in [(0.5, 0.05, 0.3), (2.0, 0.2, 0.3), (0.02, 0.002, 1.0)] {
        let m = kloss_drive(157.08, 0.2, 158.0, &[h(1.0, amp, 0.0)], m1, j);
        let k = *m.motor().kloss_curve().unwrap();
        let p = *m.motor().model();
        let parabola = DriveModel::new(Motor::parabola(p), m.load().clone(), j, 0.0).unwrap();
        let (a, b) = (steady(&m), steady(&parabola));
        let slope = |f: &dyn Fn(f64) -> f64, w: f64| (f(w + 1e-3) - f(w - 1e-3)) / 2e-3;
        let diff = (0..=16)
            .map(|i| a.omega_min + (a.omega_max - a.omega_min) * f64::from(i) / 16.0)
            .map(|w| rel(slope(&|x| p.torque(x), w), slope(&|x| k.torque(x), w)))
            .fold(0.0, f64::max);
        assert!(diff < 2e-3, "{diff}");
        assert!(
            rel(a.delta, b.delta) < diff,
            "{m1}: {} {diff}",
            rel(a.delta, b.delta)
        );
    }
}

/// A random Kloss drive: M_m, σ_m, ω_s, a mean load up to 0.8·M_m with 1–3 harmonics (some of
/// fractional order), inertia.
fn random_kloss(state: &mut u64) -> DriveModel {
    let mut u = |lo: f64, hi: f64| lo + (hi - lo) * next(state);
    let (ws, sm, mm) = (u(50.0, 400.0), u(0.05, 0.4), u(20.0, 500.0));
    let orders = [0.5, 1.0, 1.5, 2.0, 3.0];
    let m1 = mm * u(0.05, 0.8);
    let hs: Vec<Harmonic> = (0..(u(1.0, 3.99) as usize))
        .map(|_| {
            h(
                orders[(u(0.0, 4.99)) as usize],
                (mm - m1) * u(-0.3, 0.3),
                u(0.0, 6.0),
            )
        })
        .collect();
    let j = u(0.02, 2.0);
    kloss_drive(ws, sm, mm, &hs, m1, j)
}

/// δ falls with the flywheel for random Kloss drives (checked on a grid of 30 flywheels);
/// `flywheel_for` gives one that meets the target while 1e-8 less misses; a mean load at or
/// beyond M_m stalls whatever the flywheel; a peak load beyond it stalls until a flywheel
/// carries the drive through; the sensitivities predict a 1 % step.
#[test]
fn kloss_flywheel_sizing_stalls_and_sensitivity() {
    let mut state = 4242u64;
    for k in 0..8 {
        let m = random_kloss(&mut state);
        let Some(s0) = m.predict().steady().copied() else {
            continue;
        };
        let j = m.total_inertia();
        let mut last = f64::INFINITY;
        for i in 0..30 {
            let f = j * (1.3f64.powi(i) - 1.0);
            let d = steady(&m.with_flywheel(f).unwrap()).delta;
            assert!(d < last, "drive {k}: δ({f}) = {d} after {last}");
            last = d;
        }
        let target = s0.delta / 5.0;
        let extra = m.flywheel_for(target).unwrap();
        assert!(steady(&m.with_flywheel(extra).unwrap()).delta <= target);
        let less = m.with_flywheel(extra * (1.0 - 1e-8)).unwrap();
        assert!(steady(&less).delta > target, "{k}");
        assert_eq!(
            m.irregularity(Some(target)).unwrap().flywheel_for_limit,
            Some(extra)
        );
        let sens = m.sensitivity().unwrap();
        let dj = 0.01 * j;
        let step = steady(&m.with_flywheel(dj).unwrap()).delta - s0.delta;
        assert!(
            rel(step, sens.d_delta_d_inertia * dj) < 0.03,
            "{step} {sens:?}"
        );
        let scaled = m.with_motor(m.motor().scaled(1.01).unwrap()).unwrap();
        let step = steady(&scaled).delta - s0.delta;
        let mm = m.motor().kloss_curve().unwrap().breakdown_torque();
        assert!(
            rel(step, sens.d_delta_d_breakdown_torque * 0.01 * mm) < 0.05,
            "{step} {sens:?}"
        );
    }
    // Mean load beyond the breakdown torque: no flywheel helps.
    let m = kloss_drive(157.08, 0.25, 158.0, &[h(1.0, 5.0, 0.0)], 158.0, 0.05);
    assert!(matches!(m.predict(), Prediction::Stalls(s) if s.u_mean <= 0.0));
    assert_eq!(m.flywheel_for(0.01), Err(DesignError::MeanLoadExceedsMotor));
    assert!(m.sensitivity().is_none());
    let irr = m.irregularity(Some(0.01)).unwrap();
    assert!(!irr.steady_state && irr.delta == 2.0 && irr.omega_max.is_finite());
    // Peak load beyond it with a small inertia: a stall that a flywheel cures.
    let m = kloss_drive(157.08, 0.25, 158.0, &[h(1.0, 60.0, 0.0)], 120.0, 0.005);
    let Prediction::Stalls(st) = m.predict() else {
        panic!("{:?}", m.predict());
    };
    assert!(st.u_mean > 0.0 && st.u_min <= 0.0);
    let extra = m.flywheel_for(0.05).unwrap();
    let sized = steady(&m.with_flywheel(extra).unwrap());
    assert!(sized.delta <= 0.05);
    // The Kloss curve with J(φ): shooting too.
    let j = [InertiaHarmonic::new(2.0, 0.01, 0.3).unwrap()];
    let m = kloss_drive(157.08, 0.25, 158.0, &[h(1.0, 25.0, 0.0)], 100.0, 0.05);
    let v = m.with_inertia_harmonics(&j).unwrap();
    assert!(matches!(v.horizon(), Horizon::Shooting { .. }));
    assert!(steady(&v).delta != steady(&m).delta);
    // Orders with no common period: the tangent parabola's bound, as before.
    let m = kloss_drive(
        157.08,
        0.25,
        158.0,
        &[h(1.0, 5.0, 0.0), h(PI, 5.0, 0.0)],
        50.0,
        0.05,
    );
    assert_eq!(m.horizon(), Horizon::Unbounded);
    // No ripple at all: the speed that carries the mean load.
    let m = kloss_drive(157.08, 0.25, 158.0, &[], 50.0, 0.05);
    let s = steady(&m);
    assert!(s.delta == 0.0 && rel(m.motor().torque(s.omega_max), 50.0) < 1e-13);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Arbitrary Kloss drives: either a typed error or a prediction with finite numbers,
    /// finite sensitivities and a flywheel that meets the limit.
    #[test]
    fn kloss_never_panics_never_nan(
        ws in prop_oneof![1 => any::<f64>(), 4 => 1.0..1e4f64],
        sm in prop_oneof![1 => any::<f64>(), 4 => 0.01..1.0f64],
        mm in prop_oneof![1 => any::<f64>(), 4 => 1e-3..1e4f64],
        j in prop_oneof![1 => any::<f64>(), 4 => 1e-4..1e3f64],
        m1_frac in -1.5..1.5f64,
        hs in proptest::collection::vec(
            (prop_oneof![Just(0.125), Just(1.0), Just(2.5), Just(3.0)], -1.0..1.0f64,
             -10.0..10.0f64),
            0..3,
        ),
        limit in 1e-4..1.0f64,
    ) {
        let Ok(k) = Kloss::new(ws, sm, mm) else { return Ok(()); };
        let Ok(motor) = Motor::kloss(k, KlossFit::SynchronousTangent) else { return Ok(()); };
        let harmonics: Result<Vec<Harmonic>, _> =
            hs.iter().map(|&(n, a, p)| Harmonic::new(n, a * mm, p)).collect();
        let Ok(harmonics) = harmonics else { return Ok(()); };
        let Ok(load) = Load::new(m1_frac * mm, &harmonics) else { return Ok(()); };
        let Ok(m) = DriveModel::new(motor, load, j, 0.0) else { return Ok(()); };
        finite_results(&m, limit)?;
        prop_assert!(!m.omega_squared(1.0).is_nan() || m.predict().steady().is_none());
    }
}

/// Near the boundary between stalling and running (a ripple of 120 N·m on a mean load of 140
/// N·m, M_m = 158 N·m): the prediction says stall or steady as a direct RK4 integration in
/// time from synchronous speed shows it (20 s, dt = 1e-5 s), and where it runs, ω min agrees
/// within 1e-6 relative (the time integration's minimum over its steps after 10 s). Newton from
/// the tangent parabola fails on the drive with 0.0203 kg·m² of flywheel; the descent from above
/// finds the stall. A flywheel for δ ≤ 0.06 is found from the stalled drive.
#[test]
fn stall_boundary_agrees_with_time_integration() {
    let base = kloss_drive(157.08, 0.25, 158.0, &[h(1.0, 120.0, 0.0)], 140.0, 0.005);
    for (f, runs) in [(0.0203, false), (0.025, false), (0.03, true), (0.033, true)] {
        let m = base.with_flywheel(f).unwrap();
        let (motor, load, j) = (m.motor(), m.load(), m.total_inertia());
        let acc = |phi: f64, w: f64| (motor.torque(w) - load.torque(phi)) / j;
        let (mut phi, mut w, dt) = (0.0f64, 157.08f64, 1e-5);
        let (mut t, mut w_min) = (0.0, f64::INFINITY);
        while t < 20.0 && w > 1.0 {
            let k1 = (w, acc(phi, w));
            let k2 = (
                w + 0.5 * dt * k1.1,
                acc(phi + 0.5 * dt * k1.0, w + 0.5 * dt * k1.1),
            );
            let k3 = (
                w + 0.5 * dt * k2.1,
                acc(phi + 0.5 * dt * k2.0, w + 0.5 * dt * k2.1),
            );
            let k4 = (w + dt * k3.1, acc(phi + dt * k3.0, w + dt * k3.1));
            phi += dt / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
            w += dt / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
            t += dt;
            if t > 10.0 {
                w_min = w_min.min(w);
            }
        }
        match m.predict() {
            Prediction::Steady(s) => {
                assert!(
                    runs && w > 1.0,
                    "{f}: predicted steady, integration stalled"
                );
                assert!(
                    rel(w_min, s.omega_min) < 1e-6,
                    "{f}: {w_min} {}",
                    s.omega_min
                );
            }
            Prediction::Stalls(st) => {
                assert!(!runs && w <= 1.0, "{f}: predicted stall, integration runs");
                assert!(st.u_mean > 0.0 && st.u_min == 0.0);
            }
        }
    }
    let extra = base.flywheel_for(0.06).unwrap();
    assert!(steady(&base.with_flywheel(extra).unwrap()).delta <= 0.06);
}
