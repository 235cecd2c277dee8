//! Shared test harness: a fixed-step RK4 that drives an effect at a prescribed shaft law by
//! calling `Effect::eval` directly, and the seed-001 single-mass machine in physical units.
#![allow(dead_code, clippy::unwrap_used)]

use host_sim::engine::model::{Effect, Shaft};
use host_sim::engine::vibration::{
    InitialParams, LoadKind, RegimeSample, SeedSingleMass, VibrationMachine, VibrationMachineParams,
};

/// Classic RK4 on `f(t, y, dy)` from `t0` over `steps` steps of `dt`; `obs(t, y)` is called at
/// the start and after every step.
pub fn rk4(
    y: &mut [f64],
    t0: f64,
    dt: f64,
    steps: usize,
    mut f: impl FnMut(f64, &[f64], &mut [f64]),
    mut obs: impl FnMut(f64, &[f64]),
) {
    let n = y.len();
    let (mut k1, mut k2, mut k3, mut k4, mut tmp) = (
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
        vec![0.0; n],
    );
    obs(t0, y);
    for s in 0..steps {
        let t = t0 + s as f64 * dt;
        f(t, y, &mut k1);
        for i in 0..n {
            tmp[i] = y[i] + 0.5 * dt * k1[i];
        }
        f(t + 0.5 * dt, &tmp, &mut k2);
        for i in 0..n {
            tmp[i] = y[i] + 0.5 * dt * k2[i];
        }
        f(t + 0.5 * dt, &tmp, &mut k3);
        for i in 0..n {
            tmp[i] = y[i] + dt * k3[i];
        }
        f(t + dt, &tmp, &mut k4);
        for i in 0..n {
            y[i] += dt / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
        }
        obs(t0 + (s + 1) as f64 * dt, y);
    }
}

/// A run of the machine at a prescribed shaft law.
pub struct Run {
    /// Regime samples (every `sample_every` steps).
    pub samples: Vec<RegimeSample>,
    /// Final state.
    pub y: Vec<f64>,
}

/// Integrates `m` from its initial state over `[0, t_end]` with `steps_per_turn` RK4 steps per
/// rotor revolution at the largest speed of `law` (given as `omega_max`).
pub fn drive(
    m: &VibrationMachine,
    law: impl Fn(f64) -> Shaft,
    omega_max: f64,
    t_end: f64,
    steps_per_turn: f64,
) -> Run {
    let mut y = vec![0.0; m.dim()];
    m.init(&mut y);
    let dt0 = 2.0 * std::f64::consts::PI / omega_max / steps_per_turn;
    let steps = (t_end / dt0).ceil() as usize;
    let dt = t_end / steps as f64;
    let every = (steps / 2000).max(1);
    let mut samples = Vec::new();
    let mut count = 0usize;
    rk4(
        &mut y,
        0.0,
        dt,
        steps,
        |t, y, dy| {
            m.eval(t, law(t), y, dy);
        },
        |t, y| {
            if count % every == 0 || count == steps {
                samples.push(m.sample(t, law(t), y));
            }
            count += 1;
        },
    );
    Run { samples, y }
}

/// The seed's single-mass observation machine (SEED-NOTES): N = 2 balls, h = 0.1, ε = 0.05,
/// β = 2, in physical units: ω̃ = 30 rad/s, m = 0.5 kg, R = 0.1 m, M_c = 3 kg, so
/// M_Σ = N·m/(κ·ε) = 14.2857 kg, platform 10.2857 kg, k = 12 857 N/m, b = 85.71 N·s/m,
/// b_w = 2.1 N·s/m.
pub fn seed_single(rotor_unbalance: f64) -> SeedSingleMass {
    SeedSingleMass {
        h: 0.1,
        epsilon: 0.05,
        beta: 2.0,
        loads: 2,
        kind: LoadKind::Ball,
        omega_scale: 30.0,
        load_mass: 0.5,
        radius: 0.1,
        housing_mass: 3.0,
        rotor_unbalance,
    }
}

/// Builds the seed machine with the given initial conditions.
pub fn seed_machine(rotor_unbalance: f64, initial: InitialParams) -> VibrationMachine {
    let p = VibrationMachineParams::from_seed_single_mass(&seed_single(rotor_unbalance), initial)
        .unwrap();
    VibrationMachine::new(&p).unwrap()
}

/// Constant-speed shaft law `φ = ω·t`.
pub fn constant(omega: f64) -> impl Fn(f64) -> Shaft {
    move |t| Shaft {
        phi: omega * t,
        omega,
    }
}
