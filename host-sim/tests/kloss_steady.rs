//! The Kloss prediction of the core (`DriveModel` with a Kloss motor: eq. 1 with the Kloss
//! curve itself, shooting over one period) against direct integration of eq. 1 by the
//! simulator (DOP853, rtol = atol = 1e-12) on random drives run to their steady state; the
//! approach of `varying_inertia.rs`.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod drive_common;

use drive_monitor::drive::{
    DriveModel, Harmonic, Horizon, InertiaHarmonic, Kloss, KlossFit, Load, Motor,
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
        let sim = drive_common::simulate(&model, predicted.omega_rms, settle, window);
        let (hi, lo) = (sim.omega_max, sim.omega_min);
        let delta = sim.delta();
        let rel = (delta / predicted.delta - 1.0).abs();
        let ext = (hi / predicted.omega_max - 1.0)
            .abs()
            .max((lo / predicted.omega_min - 1.0).abs());
        eprintln!(
            "drive {k}: δ predicted {:.12} simulated {delta:.12} (rel {rel:.1e}), ω extremes \
             {ext:.1e}, ω worst {:.1e}, {} load harmonics, {} inertia harmonics, {steps} steps",
            predicted.delta,
            sim.worst,
            model.load().harmonics().len(),
            model.inertia_harmonics().len(),
        );
        worst_omega = worst_omega.max(sim.worst);
        worst_delta = worst_delta.max(rel);
        worst_ext = worst_ext.max(ext);
        assert!(sim.worst < 1e-10, "drive {k}: ω off by {:e}", sim.worst);
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
