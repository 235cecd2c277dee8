//! The J(φ) prediction of the core (`DriveModel::with_inertia_harmonics`: eq. 1 solved in
//! `w = J·ω²` by the trapezoid rule over one period) against direct integration of eq. 1 by
//! the simulator (DOP853, rtol = atol = 1e-12) on random drives run to their steady state.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use drive_monitor::drive::{DriveModel, Harmonic, InertiaHarmonic, Load, Motor, Parabola};
use host_sim::engine::encoder::EncoderConfig;
use host_sim::engine::ode::Integrator;
use host_sim::engine::system::{
    DynamicShaft, InertiaHarmonic as SimHarmonic, Observer, ShaftModel, Simulation, StepView,
    System,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// A random drive: parabola motor, a mean load with 0–2 harmonics, 1–3 inertia harmonics of
/// magnitudes adding up to at most 40 % of the mean inertia (so J(φ) ≥ 0.6·J0).
fn random_drive(rng: &mut ChaCha8Rng) -> DriveModel {
    let w0 = rng.gen_range(100.0..300.0);
    let wm = w0 * rng.gen_range(0.2..0.7);
    let mm = rng.gen_range(50.0..500.0);
    let motor = Motor::parabola(Parabola::new(w0, wm, mm).unwrap());
    let a = -motor.model().a();
    let m1 = mm * rng.gen_range(0.05..0.3);
    let load_orders = [0.5, 1.0, 2.0, 3.0];
    let harmonics: Vec<Harmonic> = (0..rng.gen_range(0..=2))
        .map(|_| {
            let n = load_orders[rng.gen_range(0..load_orders.len())];
            Harmonic::new(n, m1 * rng.gen_range(-0.5..0.5), rng.gen_range(0.0..TAU)).unwrap()
        })
        .collect();
    let load = Load::new(m1, &harmonics).unwrap();
    // Damping 2a/J0 between 0.03 and 0.3 per radian: a settled transient within ~1000 rad.
    let j0 = 2.0 * a / rng.gen_range(0.03..0.3);
    let count = rng.gen_range(1..=3);
    let budget = 0.4 * j0 * rng.gen_range(0.3..1.0);
    let inertia_orders = [1.0, 2.0, 3.0, 4.0];
    let inertia: Vec<InertiaHarmonic> = (0..count)
        .map(|_| {
            let n = inertia_orders[rng.gen_range(0..inertia_orders.len())];
            let amp = budget / f64::from(count) * rng.gen_range(-1.0..1.0);
            InertiaHarmonic::new(n, amp, rng.gen_range(0.0..TAU)).unwrap()
        })
        .collect();
    DriveModel::new(motor, load, j0, 0.0)
        .unwrap()
        .with_inertia_harmonics(&inertia)
        .unwrap()
}

/// Dense-output samples per step for the simulated extremes.
const SAMPLES_PER_STEP: u32 = 64;

/// After `from` seconds: the largest relative difference of the simulated ω from the
/// predicted curve at 8 points of every step, and the simulated (φ, ω) at 64.
struct Compare<'a> {
    from: f64,
    curve: &'a drive_monitor::drive::SteadyCurve<'a>,
    worst: f64,
    samples: Vec<(f64, f64)>,
}

impl Observer for Compare<'_> {
    fn edge(&mut self, _e: &host_sim::engine::encoder::Edge) {}
    fn step(&mut self, s: &StepView<'_>) {
        if s.t0() < self.from {
            return;
        }
        for i in 1..=SAMPLES_PER_STEP {
            let t = s.t0() + (s.t1() - s.t0()) * f64::from(i) / f64::from(SAMPLES_PER_STEP);
            let sh = s.shaft(t);
            if i % 8 == 0 {
                let want = self.curve.steady_omega(sh.phi).unwrap();
                self.worst = self.worst.max((sh.omega / want - 1.0).abs());
            }
            self.samples.push((sh.phi, sh.omega));
        }
    }
}

/// The extreme of the parabola through three samples around the extreme sample.
fn vertex(p: &[(f64, f64)], i: usize) -> f64 {
    let ((x0, y0), (x1, y1), (x2, y2)) = (p[i - 1], p[i], p[i + 1]);
    let d01 = (y1 - y0) / (x1 - x0);
    let d12 = (y2 - y1) / (x2 - x1);
    let c2 = (d12 - d01) / (x2 - x0);
    let c1 = d01 - c2 * (x0 + x1);
    if c2 == 0.0 {
        return y1;
    }
    let xv = -c1 / (2.0 * c2);
    y0 + d01 * (xv - x0) + c2 * (xv - x0) * (xv - x1)
}

/// δ of the simulation: extreme samples refined by the parabola through their neighbours.
fn simulated_delta(samples: &[(f64, f64)]) -> f64 {
    let interior = 1..samples.len() - 1;
    let imax = interior
        .clone()
        .max_by(|&i, &j| samples[i].1.total_cmp(&samples[j].1))
        .unwrap();
    let imin = interior
        .min_by(|&i, &j| samples[i].1.total_cmp(&samples[j].1))
        .unwrap();
    let (hi, lo) = (vertex(samples, imax), vertex(samples, imin));
    2.0 * (hi - lo) / (hi + lo)
}

/// 24 random drives (seed 7), each integrated from ω = √ū until its transient has decayed
/// below 1e-13 (`exp(p̄·φ)`, `|p̄| ≥ 2a/J0`), then over two common periods: the simulated ω
/// follows the predicted curve within 1e-10 relative at every dense-output point, and δ agrees
/// within 1e-8 relative (measured worst over the 24: 1.7e-11 for ω, 1.9e-9 for δ, the latter
/// limited by the simulated extremes, parabolas through dense-output samples 1/64 step apart).
#[test]
fn predicted_delta_with_varying_inertia_matches_the_simulation() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (mut worst_omega, mut worst_delta) = (0.0f64, 0.0f64);
    for k in 0..24 {
        let model = random_drive(&mut rng);
        let predicted = *model.predict().steady().expect("steady state");
        let drive_monitor::drive::Horizon::Varying { radians, .. } = model.horizon() else {
            panic!("drive {k}: {:?}", model.horizon());
        };
        let a = -model.motor().model().a();
        let settle_rad = 13.0 * std::f64::consts::LN_10 / (2.0 * a / model.total_inertia());
        let mean_speed = model.u_mean().sqrt();
        let settle = settle_rad / predicted.omega_min;
        let window = 2.0 * radians / predicted.omega_min;
        let shaft = DynamicShaft {
            inertia: model.inertia(),
            flywheel: model.flywheel(),
            harmonics: model
                .inertia_harmonics()
                .iter()
                .map(|h| SimHarmonic {
                    amplitude: h.amplitude(),
                    order: h.order(),
                    phase: h.phase(),
                })
                .collect(),
            phi0: 0.0,
            omega0: mean_speed,
        };
        let system = System::new(
            ShaftModel::Dynamic(shaft),
            vec![Box::new(*model.motor()), Box::new(model.load().clone())],
        )
        .unwrap();
        let mut sim = Simulation::new(
            system,
            Integrator::Dop853 {
                rtol: 1e-12,
                atol: 1e-12,
                max_step: None,
            },
            EncoderConfig::ideal(16, 1e6),
        )
        .unwrap();
        let curve = model.steady_curve();
        let mut cmp = Compare {
            from: settle,
            curve: &curve,
            worst: 0.0,
            samples: Vec::new(),
        };
        sim.run_observed(settle + window, &mut cmp).unwrap();
        let delta = simulated_delta(&cmp.samples);
        let rel = (delta / predicted.delta - 1.0).abs();
        eprintln!(
            "drive {k}: δ predicted {:.12} simulated {delta:.12} (rel {rel:.1e}), ω worst {:.1e}, \
             {} inertia harmonics, nodes {:?}",
            predicted.delta,
            cmp.worst,
            model.inertia_harmonics().len(),
            model.horizon()
        );
        worst_omega = worst_omega.max(cmp.worst);
        worst_delta = worst_delta.max(rel);
        assert!(cmp.worst < 1e-10, "drive {k}: ω off by {:e}", cmp.worst);
        assert!(
            rel < 1e-8,
            "drive {k}: δ {delta} against {}",
            predicted.delta
        );
    }
    eprintln!("worst ω {worst_omega:.2e}, worst δ {worst_delta:.2e}");
}
