//! Direct integration of eq. 1 by the simulator (DOP853, rtol = atol = 1e-12) to a drive's
//! steady state, compared with the core's predicted curve: shared by the J(φ) and Kloss
//! prediction tests.
#![allow(clippy::unwrap_used, clippy::expect_used, dead_code)]

use drive_monitor::drive::{DriveModel, SteadyCurve};
use host_sim::engine::encoder::EncoderConfig;
use host_sim::engine::ode::Integrator;
use host_sim::engine::system::{
    DynamicShaft, InertiaHarmonic as SimHarmonic, Observer, ShaftModel, Simulation, StepView,
    System,
};

/// Dense-output samples per step for the simulated extremes.
const SAMPLES_PER_STEP: u32 = 64;

/// After `from` seconds: the largest relative difference of the simulated ω from the
/// predicted curve at 8 points of every step, and the simulated (φ, ω) at 64.
struct Compare<'a> {
    from: f64,
    curve: &'a SteadyCurve<'a>,
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

/// What a simulation to the steady state saw.
pub struct Simulated {
    /// The largest relative difference of ω from the predicted curve after the settling time.
    pub worst: f64,
    /// ω max and ω min: extreme samples refined by the parabola through their neighbours.
    pub omega_max: f64,
    pub omega_min: f64,
}

impl Simulated {
    /// δ = 2(ωmax − ωmin)/(ωmax + ωmin).
    pub fn delta(&self) -> f64 {
        2.0 * (self.omega_max - self.omega_min) / (self.omega_max + self.omega_min)
    }
}

/// `model`'s drive simulated from speed `omega0` at φ = 0 for `settle + window` seconds, the
/// part after `settle` compared with the model's predicted curve.
pub fn simulate(model: &DriveModel, omega0: f64, settle: f64, window: f64) -> Simulated {
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
        omega0,
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
    let samples = &cmp.samples;
    let interior = 1..samples.len() - 1;
    let imax = interior
        .clone()
        .max_by(|&i, &j| samples[i].1.total_cmp(&samples[j].1))
        .unwrap();
    let imin = interior
        .min_by(|&i, &j| samples[i].1.total_cmp(&samples[j].1))
        .unwrap();
    Simulated {
        worst: cmp.worst,
        omega_max: vertex(samples, imax),
        omega_min: vertex(samples, imin),
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
