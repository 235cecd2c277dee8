//! The Kloss prediction of the core (`DriveModel` with a Kloss motor: eq. 1 with the Kloss
//! curve itself, shooting over one period) against direct integration of eq. 1 by the
//! simulator (DOP853, rtol = atol = 1e-12) on random drives run to their steady state; the
//! approach of `varying_inertia.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use drive_monitor::drive::{
    DriveModel, Harmonic, Horizon, InertiaHarmonic, Kloss, KlossFit, Load, Motor,
};
use host_sim::engine::encoder::EncoderConfig;
use host_sim::engine::ode::Integrator;
use host_sim::engine::system::{
    DynamicShaft, InertiaHarmonic as SimHarmonic, Observer, ShaftModel, Simulation, StepView,
    System,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::f64::consts::TAU;

/// A random Kloss drive: M_m, σ_m, ω_s, a mean load of 5–70 % of M_m with 1–3 harmonics
/// (orders 0.5, 1, 1.5, 2, 3) of magnitudes adding up to at most 30 % of the margin to M_m,
/// an inertia that makes the damping at the mean speed 0.03–0.3 per radian (a settled
/// transient within ~1000 rad), and every third drive 1–2 inertia harmonics up to 30 % of J.
/// Returns the drive and its slowest damping rate over the predicted speeds, per radian.
fn random_drive(rng: &mut ChaCha8Rng, k: usize) -> (DriveModel, f64) {
    let ws = rng.gen_range(80.0..320.0);
    let sm = rng.gen_range(0.08..0.35);
    let mm = rng.gen_range(50.0..500.0);
    let kloss = Kloss::new(ws, sm, mm).unwrap();
    let motor = Motor::kloss(kloss, KlossFit::SynchronousTangent).unwrap();
    let m1 = mm * rng.gen_range(0.05..0.7);
    let orders = [0.5, 1.0, 1.5, 2.0, 3.0];
    let count = rng.gen_range(1..=3);
    let harmonics: Vec<Harmonic> = (0..count)
        .map(|_| {
            let n = orders[rng.gen_range(0..orders.len())];
            let amp = 0.3 * (mm - m1) / f64::from(count) * rng.gen_range(-1.0..1.0);
            Harmonic::new(n, amp, rng.gen_range(0.0..TAU)).unwrap()
        })
        .collect();
    let load = Load::new(m1, &harmonics).unwrap();
    // Mean speed: σ̄ on the working branch where the curve gives M1.
    let sbar = sm * m1 / (mm + ((mm - m1) * (mm + m1)).sqrt());
    let wbar = ws * (1.0 - sbar);
    let slope = |w: f64| (kloss.torque(w - 1e-4) - kloss.torque(w + 1e-4)) / 2e-4;
    let j0 = slope(wbar) / wbar / rng.gen_range(0.03..0.3);
    let model = DriveModel::new(motor, load, j0, 0.0).unwrap();
    let model = if k % 3 == 2 {
        let inertia: Vec<InertiaHarmonic> = (0..rng.gen_range(1..=2))
            .map(|_| {
                let n = [1.0, 2.0, 3.0][rng.gen_range(0..3)];
                InertiaHarmonic::new(
                    n,
                    0.15 * j0 * rng.gen_range(-1.0..1.0),
                    rng.gen_range(0.0..TAU),
                )
                .unwrap()
            })
            .collect();
        model.with_inertia_harmonics(&inertia).unwrap()
    } else {
        model
    };
    let s = *model.predict().steady().expect("steady state");
    let swing: f64 = model
        .inertia_harmonics()
        .iter()
        .map(|h| h.amplitude().abs())
        .sum();
    let rate = (0..=16)
        .map(|i| s.omega_min + (s.omega_max - s.omega_min) * f64::from(i) / 16.0)
        .map(|w| slope(w) / ((j0 + swing) * w))
        .fold(f64::INFINITY, f64::min);
    (model, rate)
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

/// ωmax and ωmin of the simulation: extreme samples refined by the parabola through their
/// neighbours.
fn simulated_extremes(samples: &[(f64, f64)]) -> (f64, f64) {
    let interior = 1..samples.len() - 1;
    let imax = interior
        .clone()
        .max_by(|&i, &j| samples[i].1.total_cmp(&samples[j].1))
        .unwrap();
    let imin = interior
        .min_by(|&i, &j| samples[i].1.total_cmp(&samples[j].1))
        .unwrap();
    (vertex(samples, imax), vertex(samples, imin))
}

/// 24 random Kloss drives (seed 11; 8 of them with J(φ)), each integrated from its predicted
/// mean speed until the transient has decayed below 1e-13 at the slowest damping rate over the
/// predicted speeds, then over two common periods: the simulated ω follows the predicted curve
/// within 1e-10 relative at every dense-output point, ω max and ω min agree within 1e-10 and δ
/// within 1e-8 relative plus 4e-12 (measured worst: ω 4.2e-12, extremes 5.4e-11, δ 8.5e-9 on
/// a drive of δ = 5.5e-4, where 1e-12 of ω is 4e-9 of δ; the simulated extremes are parabolas
/// through dense-output samples 1/64 step apart).
#[test]
fn kloss_prediction_matches_the_simulation() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let (mut worst_omega, mut worst_delta, mut worst_ext) = (0.0f64, 0.0f64, 0.0f64);
    for k in 0..24 {
        let (model, rate) = random_drive(&mut rng, k);
        let predicted = *model.predict().steady().expect("steady state");
        let Horizon::Shooting { radians, steps } = model.horizon() else {
            panic!("drive {k}: {:?}", model.horizon());
        };
        let settle_rad = 13.0 * std::f64::consts::LN_10 / rate;
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
            omega0: predicted.omega_rms,
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
        let (hi, lo) = simulated_extremes(&cmp.samples);
        let delta = 2.0 * (hi - lo) / (hi + lo);
        let rel = (delta / predicted.delta - 1.0).abs();
        let ext = (hi / predicted.omega_max - 1.0)
            .abs()
            .max((lo / predicted.omega_min - 1.0).abs());
        eprintln!(
            "drive {k}: δ predicted {:.12} simulated {delta:.12} (rel {rel:.1e}), ω extremes \
             {ext:.1e}, ω worst {:.1e}, {} load harmonics, {} inertia harmonics, {steps} steps",
            predicted.delta,
            cmp.worst,
            model.load().harmonics().len(),
            model.inertia_harmonics().len(),
        );
        worst_omega = worst_omega.max(cmp.worst);
        worst_delta = worst_delta.max(rel);
        worst_ext = worst_ext.max(ext);
        assert!(cmp.worst < 1e-10, "drive {k}: ω off by {:e}", cmp.worst);
        assert!(ext < 1e-10, "drive {k}: extremes off by {ext:e}");
        // 1e-8 relative, plus what 1e-12 relative errors of the two simulated extremes make
        // of δ (4e-12): the simulation's own floor for the smallest swings.
        assert!(
            (delta - predicted.delta).abs() < 1e-8 * predicted.delta + 4e-12,
            "drive {k}: δ {delta} against {}",
            predicted.delta
        );
    }
    eprintln!("worst ω {worst_omega:.2e}, ω extremes {worst_ext:.2e}, δ {worst_delta:.2e}");
}
