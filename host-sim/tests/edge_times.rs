//! Edge times against closed forms: prescribed and integrated shafts, forward and backward.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use core::f64::consts::TAU;

use host_sim::engine::effects::{ConstantTorque, ViscousFriction};
use host_sim::engine::encoder::{Direction, Edge, EncoderConfig};
use host_sim::engine::ode::Integrator;
use host_sim::engine::system::{DynamicShaft, ShaftModel, Simulation, SpeedLaw, System};

const LINES: u32 = 256;

fn edges_of(
    shaft: ShaftModel,
    effects: Vec<Box<dyn host_sim::engine::model::Effect>>,
    integrator: Integrator,
    duration: f64,
) -> Vec<Edge> {
    let system = System::new(shaft, effects).unwrap();
    let mut sim = Simulation::new(system, integrator, EncoderConfig::ideal(LINES, 1e9)).unwrap();
    let mut v = Vec::new();
    sim.run(duration, |e| v.push(*e)).unwrap();
    v
}

/// Mark angle of an edge (ideal disc).
fn theta(e: &Edge) -> f64 {
    TAU * (e.revolution as f64 + f64::from(e.tooth) / f64::from(LINES))
}

/// Constant acceleration from ω0: t(θ) = 2θ/(ω0 + √(ω0² + 2αθ)).
fn t_const_accel(omega0: f64, alpha: f64, th: f64) -> f64 {
    // Rationalised root: no cancellation when α·θ is small against ω0².
    2.0 * th / (omega0 + (omega0 * omega0 + 2.0 * alpha * th).sqrt())
}

fn max_error(edges: &[Edge], exact: impl Fn(f64) -> f64) -> f64 {
    edges
        .iter()
        .map(|e| (e.true_time - exact(theta(e))).abs())
        .fold(0.0, f64::max)
}

fn check_sequence(edges: &[Edge], expected: usize) {
    assert_eq!(edges.len(), expected);
    for (k, e) in edges.iter().enumerate() {
        // Every mark in order, none skipped or repeated.
        assert_eq!(theta(e), TAU * (k + 1) as f64 / f64::from(LINES));
        assert_eq!(e.direction, Direction::Forward);
    }
}

const RK4: Integrator = Integrator::Rk4 { step: 1e-3 };
const DP5: Integrator = Integrator::Dopri5 {
    rtol: 1e-10,
    atol: 1e-10,
    max_step: None,
};
const DP8: Integrator = Integrator::Dop853 {
    rtol: 1e-12,
    atol: 1e-12,
    max_step: None,
};

#[test]
fn prescribed_constant_speed_is_exact() {
    let omega = 97.3;
    let edges = edges_of(
        ShaftModel::Prescribed(SpeedLaw::Constant { omega, phi0: 0.0 }),
        vec![],
        RK4,
        2.0,
    );
    let n = (2.0 * omega / TAU * f64::from(LINES)).floor() as usize;
    check_sequence(&edges, n);
    let err = max_error(&edges, |th| th / omega);
    // Rounding of t (≤ 2 s) and of the mark angle: a few ulp.
    assert!(err < 2e-15, "max edge-time error {err:e} s");
}

#[test]
fn prescribed_ramp_is_exact_and_crosses_chunks() {
    let (omega0, alpha) = (3.0, 40.0);
    let edges = edges_of(
        ShaftModel::Prescribed(SpeedLaw::Ramp {
            omega0,
            alpha,
            phi0: 0.0,
        }),
        vec![],
        RK4,
        1.5,
    );
    let phi_end = 1.5 * omega0 + 0.5 * alpha * 1.5 * 1.5;
    check_sequence(&edges, (phi_end / TAU * f64::from(LINES)).floor() as usize);
    let err = max_error(&edges, |th| t_const_accel(omega0, alpha, th));
    assert!(err < 2e-15, "max edge-time error {err:e} s");
}

#[test]
fn ramp_to_speed_follows_both_pieces() {
    let (omega0, omega1, tr) = (10.0, 60.0, 0.4);
    let edges = edges_of(
        ShaftModel::Prescribed(SpeedLaw::RampTo {
            omega0,
            omega1,
            ramp_time: tr,
            phi0: 0.0,
        }),
        vec![],
        RK4,
        1.0,
    );
    let alpha = (omega1 - omega0) / tr;
    let phi_r = tr * (omega0 + omega1) / 2.0;
    let exact = |th: f64| {
        if th <= phi_r {
            t_const_accel(omega0, alpha, th)
        } else {
            tr + (th - phi_r) / omega1
        }
    };
    let phi_end = phi_r + 0.6 * omega1;
    check_sequence(&edges, (phi_end / TAU * f64::from(LINES)).floor() as usize);
    assert!(max_error(&edges, exact) < 2e-15);
}

#[test]
fn prescribed_reversal_gives_mirrored_backward_edges() {
    // ω = 20 − 20 t: forward until t = 1, back to φ = 0 at t = 2.
    let edges = edges_of(
        ShaftModel::Prescribed(SpeedLaw::Ramp {
            omega0: 20.0,
            alpha: -20.0,
            phi0: 0.0,
        }),
        vec![],
        RK4,
        2.0 - 1e-9,
    );
    let fwd: Vec<&Edge> = edges
        .iter()
        .filter(|e| e.direction == Direction::Forward)
        .collect();
    let bwd: Vec<&Edge> = edges
        .iter()
        .filter(|e| e.direction == Direction::Reverse)
        .collect();
    // Peak φ = 10 rad; marks 1 … ⌊10·256/2π⌋ forward, the same back down (mark 0 at t = 2 is
    // beyond the run).
    let marks = (10.0 / TAU * f64::from(LINES)).floor() as usize;
    assert_eq!(fwd.len(), marks);
    assert_eq!(bwd.len(), marks);
    assert!(fwd.iter().all(|e| e.true_time < 1.0) && bwd.iter().all(|e| e.true_time > 1.0));
    for (f, b) in fwd.iter().zip(bwd.iter().rev()) {
        assert_eq!((f.tooth, f.revolution), (b.tooth, b.revolution));
        assert!((f.true_time + b.true_time - 2.0).abs() < 1e-12);
    }
}

/// J·ω' = M from ω0: φ is quadratic, which every method here integrates exactly; the error
/// left is rounding.
#[test]
fn dynamic_constant_torque_matches_constant_acceleration() {
    let (j, m, omega0) = (0.5, 10.0, 5.0);
    let alpha = m / j;
    let mut shaft = DynamicShaft::constant(j);
    shaft.omega0 = omega0;
    for integrator in [RK4, DP5, DP8] {
        let edges = edges_of(
            ShaftModel::Dynamic(shaft.clone()),
            vec![Box::new(ConstantTorque { torque: m })],
            integrator.clone(),
            2.0,
        );
        let phi_end = 2.0 * omega0 + 0.5 * alpha * 4.0;
        check_sequence(&edges, (phi_end / TAU * f64::from(LINES)).floor() as usize);
        let err = max_error(&edges, |th| t_const_accel(omega0, alpha, th));
        // Rounding accumulated over up to 2000 steps of φ ≈ 50 rad: ≈ √N·ε·φ/ω.
        assert!(
            err < 5e-13,
            "{}: max edge-time error {err:e} s",
            integrator.name()
        );
    }
}

/// Constant torque against viscous friction: ω relaxes exponentially, so the dense output's
/// interpolation error is what is measured. Stated tolerances: DOPRI5 at rtol 1e-10 locates every
/// edge within 1e-11 s; DOP853 at rtol 1e-12 and RK4 at h = 1 ms (τ = 2 s) within 1e-12 s.
#[test]
fn dynamic_exponential_speed_within_stated_tolerance() {
    let (j, m, c, omega0) = (0.2, 20.0, 0.1, 30.0);
    let tau = j / c;
    let w_inf = m / c;
    let phi = |t: f64| w_inf * t - (omega0 - w_inf) * tau * (-t / tau).exp_m1();
    let omega = |t: f64| w_inf + (omega0 - w_inf) * (-t / tau).exp();
    // Exact edge time by Newton on the closed form.
    let exact = |th: f64| {
        let mut t = th / omega0;
        for _ in 0..50 {
            let dt = (phi(t) - th) / omega(t);
            t -= dt;
            if dt.abs() < 1e-16 {
                break;
            }
        }
        t
    };
    let mut shaft = DynamicShaft::constant(j);
    shaft.omega0 = omega0;
    for (integrator, tol) in [(DP5, 1e-11), (DP8, 1e-12), (RK4, 1e-12)] {
        let edges = edges_of(
            ShaftModel::Dynamic(shaft.clone()),
            vec![
                Box::new(ConstantTorque { torque: m }),
                Box::new(ViscousFriction { coefficient: c }),
            ],
            integrator.clone(),
            3.0,
        );
        let err = max_error(&edges, exact);
        assert!(
            err < tol,
            "{}: max edge-time error {err:e} s",
            integrator.name()
        );
        assert!(edges.len() > 13_000);
    }
}
