//! What simulation accuracy costs: error against wall time for each integrator setting on
//! scenes with a known answer, and how a run's cost scales with duration, encoder lines and
//! effects.
//!
//! - Kneader (seed 000): the steady state is exact in closed form (ω² = u(φ), eq. 11), so the
//!   error is max |ω²/u(φ) − 1| over the steady part, sampled at step ends and mid-steps (the
//!   dense output is what edge location uses).
//! - Two-mass auto-balancer at a prescribed 100 rad/s: no closed form; the reference is a
//!   DOP853 run at rtol 1e-13, and the error is the largest deviation of any state from it at
//!   200 instants, relative to that state's largest magnitude.
//!
//! Wall times are the minimum of three runs on the machine at hand (stated in the output).

use crate::app::run::{run, Overrides};
use crate::app::scene::{resolve, Scene};
use crate::engine::encoder::{EncoderConfig, Reference};
use crate::engine::model::Effect;
use crate::engine::ode::Integrator;
use crate::engine::system::{
    DynamicShaft, Observer, ShaftModel, Simulation, SpeedLaw, StepView, System,
};
use crate::engine::vibration::VibrationMachine;
use drive_monitor::drive::DriveModel;
use serde::Serialize;
use std::path::Path;
use std::time::Instant;

/// One integrator setting on one scene.
#[derive(Debug, Clone, Serialize)]
pub struct ParetoRow {
    /// Scene.
    pub scene: &'static str,
    /// Integrator and setting, e.g. `dp5 rtol=1e-9`.
    pub setting: String,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Wall time, ms (minimum of three runs).
    pub wall_ms: f64,
    /// Error (see the module docs).
    pub error: f64,
    /// On the Pareto front of its scene (no other setting is both faster and more accurate).
    pub pareto: bool,
}

/// Integrator settings swept for each scene.
fn settings(fine_step: f64) -> Vec<(String, Integrator)> {
    let mut v = Vec::new();
    for k in 0..4 {
        let step = fine_step * f64::powi(2.0, 3 - k);
        v.push((format!("rk4 h={step:.2e}"), Integrator::Rk4 { step }));
    }
    for rtol in [1e-6, 1e-8, 1e-10, 1e-12] {
        v.push((
            format!("dp5 rtol={rtol:.0e}"),
            Integrator::Dopri5 {
                rtol,
                atol: rtol * 1e-2,
                max_step: None,
            },
        ));
    }
    for rtol in [1e-8, 1e-10, 1e-12] {
        v.push((
            format!("dop853 rtol={rtol:.0e}"),
            Integrator::Dop853 {
                rtol,
                atol: rtol * 1e-2,
                max_step: None,
            },
        ));
    }
    v
}

/// Runs every setting of [`settings`]`(fine_step)` on `scene` through `run` (best of three,
/// which returns the right-hand-side evaluations and the error) and marks the Pareto front.
fn pareto_sweep<F>(
    scene: &'static str,
    fine_step: f64,
    mut run: F,
) -> Result<Vec<ParetoRow>, String>
where
    F: FnMut(Integrator) -> Result<(u64, f64), String>,
{
    let mut rows = Vec::new();
    for (setting, integ) in settings(fine_step) {
        let (wall_ms, (rhs_evals, error)) = best_of_three(|| run(integ.clone()))
            .map_err(|e| format!("{scene} with {setting}: {e}"))?;
        rows.push(ParetoRow {
            scene,
            setting,
            rhs_evals,
            wall_ms,
            error,
            pareto: false,
        });
    }
    mark_pareto(&mut rows);
    Ok(rows)
}

fn mark_pareto(rows: &mut [ParetoRow]) {
    let copy: Vec<(f64, f64)> = rows.iter().map(|r| (r.wall_ms, r.error)).collect();
    for r in rows.iter_mut() {
        r.pareto = !copy.iter().any(|&(t, e)| t < r.wall_ms && e < r.error);
    }
}

/// Runs `f` three times: the shortest wall time in ms, and the last result.
fn best_of_three<T, F: FnMut() -> Result<T, String>>(mut f: F) -> Result<(f64, T), String> {
    let mut best = f64::INFINITY;
    let mut value = None;
    for _ in 0..3 {
        let start = Instant::now();
        value = Some(f()?);
        best = best.min(start.elapsed().as_secs_f64() * 1e3);
    }
    value.map(|v| (best, v)).ok_or_else(|| "no run".to_string())
}

fn kneader_model() -> Result<DriveModel, String> {
    let (scene, path) = resolve("kneader").map_err(|e| e.to_string())?;
    crate::app::predict::drive_model(&scene, &path)
        .map_err(|e| e.to_string())?
        .ok_or_else(|| "the kneader scene has no drive model".to_string())
}

/// |ω²/u(φ) − 1|: the deviation from the kneader's exact steady state (seed 000 eq. 11), the
/// error of every kneader table here.
fn steady_error(model: &DriveModel, phi: f64, omega: f64) -> f64 {
    (omega * omega / model.omega_squared(phi) - 1.0).abs()
}

struct KneaderError<'a> {
    model: &'a DriveModel,
    from: f64,
    worst: f64,
}

impl Observer for KneaderError<'_> {
    fn edge(&mut self, _edge: &crate::engine::encoder::Edge) {}
    fn step(&mut self, step: &StepView<'_>) {
        if step.t1() < self.from {
            return;
        }
        for t in [0.5 * (step.t0() + step.t1()), step.t1()] {
            let s = step.shaft(t);
            self.worst = self.worst.max(steady_error(self.model, s.phi, s.omega));
        }
    }
}

fn kneader_simulation(
    model: &DriveModel,
    integrator: Integrator,
    lines: u32,
) -> Result<Simulation, String> {
    let effects: Vec<Box<dyn Effect>> =
        vec![Box::new(*model.motor()), Box::new(model.load().clone())];
    let shaft = ShaftModel::Dynamic(DynamicShaft {
        inertia: model.inertia(),
        flywheel: model.flywheel(),
        harmonics: Vec::new(),
        phi0: 0.0,
        omega0: model.u_mean().sqrt(),
    });
    let system = System::new(shaft, effects).map_err(|e| e.to_string())?;
    let mut enc = EncoderConfig::ideal(lines, 84e6);
    enc.reference = Reference::Index;
    Simulation::new(system, integrator, enc).map_err(|e| e.to_string())
}

/// Error against wall time on the kneader scene (30 s, 1024 lines, edges generated).
pub fn kneader_pareto() -> Result<Vec<ParetoRow>, String> {
    let model = kneader_model()?;
    pareto_sweep("kneader", 1.25e-4, |integ| {
        let mut obs = KneaderError {
            model: &model,
            from: 10.0,
            worst: 0.0,
        };
        let mut sim = kneader_simulation(&model, integ, 1024)?;
        let stats = sim
            .run_observed(30.0, &mut obs)
            .map_err(|e| e.to_string())?;
        Ok((stats.solver.rhs_evals, obs.worst))
    })
}

struct Sampler {
    times: Vec<f64>,
    next: usize,
    out: Vec<Vec<f64>>,
    buf: Vec<f64>,
}

impl Observer for Sampler {
    fn edge(&mut self, _edge: &crate::engine::encoder::Edge) {}
    fn step(&mut self, step: &StepView<'_>) {
        while self.next < self.times.len() && self.times[self.next] <= step.t1() {
            step.state_into(self.times[self.next], &mut self.buf);
            self.out.push(self.buf.clone());
            self.next += 1;
        }
    }
}

fn balancer_states(
    scene: &Scene,
    integ: Integrator,
    duration: f64,
) -> Result<(u64, Vec<Vec<f64>>), String> {
    let params = crate::app::run::vibration_params(scene, false, 100.0)
        .ok_or_else(|| "the scene has no vibration machine".to_string())?;
    let vm = VibrationMachine::new(&params).map_err(|e| e.to_string())?;
    let system = System::new(
        ShaftModel::Prescribed(SpeedLaw::Constant {
            omega: 100.0,
            phi0: 0.0,
        }),
        vec![Box::new(vm)],
    )
    .map_err(|e| e.to_string())?;
    let dim = system.dim();
    let mut sim =
        Simulation::new(system, integ, EncoderConfig::ideal(4, 1e6)).map_err(|e| e.to_string())?;
    let n = 200;
    let mut obs = Sampler {
        times: (1..=n).map(|k| duration * k as f64 / n as f64).collect(),
        next: 0,
        out: Vec::new(),
        buf: vec![0.0; dim],
    };
    let stats = sim
        .run_observed(duration, &mut obs)
        .map_err(|e| e.to_string())?;
    Ok((stats.solver.rhs_evals, obs.out))
}

/// Error against wall time on the two-mass auto-balancer at 100 rad/s (10 s), against a
/// DOP853 rtol 1e-13 reference.
pub fn balancer_pareto() -> Result<Vec<ParetoRow>, String> {
    let (scene, _) = resolve("two-mass").map_err(|e| e.to_string())?;
    let duration = 10.0;
    let reference = Integrator::Dop853 {
        rtol: 1e-13,
        atol: 1e-16,
        max_step: None,
    };
    let (_, reference) = balancer_states(&scene, reference, duration)?;
    let dim = reference.first().map_or(0, Vec::len);
    let scale: Vec<f64> = (0..dim)
        .map(|i| {
            reference
                .iter()
                .map(|y| y[i].abs())
                .fold(0.0, f64::max)
                .max(1e-300)
        })
        .collect();
    pareto_sweep("two-mass", 2.5e-5, |integ| {
        let (evals, states) = balancer_states(&scene, integ, duration)?;
        if states.len() != reference.len() {
            return Ok((evals, f64::INFINITY));
        }
        let mut worst: f64 = 0.0;
        for (y, r) in states.iter().zip(&reference) {
            for i in 0..dim {
                worst = worst.max((y[i] - r[i]).abs() / scale[i]);
            }
        }
        Ok((evals, worst))
    })
}

/// One point of a scaling series.
#[derive(Debug, Clone, Serialize)]
pub struct ScalingRow {
    /// What is varied: "duration", "lines" or "effects".
    pub series: &'static str,
    /// Its value (s, lines, or the effect list).
    pub value: String,
    /// Edges generated.
    pub edges: u64,
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Wall time of the whole run (simulation and core), ms, minimum of three.
    pub wall_ms: f64,
    /// Wall time per edge, ns.
    pub ns_per_edge: f64,
}

fn scaled_run(series: &'static str, value: String, text: &str) -> Result<ScalingRow, String> {
    let file = Path::new("scaling.toml");
    let scene = Scene::parse(text, file).map_err(|e| e.to_string())?;
    let (wall_ms, (edges, evals)) = best_of_three(|| {
        run(&scene, file, Overrides::default())
            .map(|r| (r.edges, r.rhs_evaluations))
            .map_err(|e| e.to_string())
    })?;
    Ok(ScalingRow {
        series,
        value,
        edges,
        rhs_evals: evals,
        wall_ms,
        ns_per_edge: wall_ms * 1e6 / edges.max(1) as f64,
    })
}

/// Cost of the kneader run against simulated duration, encoder lines and added effects.
pub fn scaling() -> Result<Vec<ScalingRow>, String> {
    let base = crate::app::scene::BUNDLED
        .iter()
        .find(|(n, _)| *n == "kneader.toml")
        .map(|(_, t)| *t)
        .ok_or("no bundled kneader scene")?;
    let mut rows = Vec::new();
    for d in [7.5, 15.0, 30.0, 60.0] {
        let text = base
            .replace("duration = 30.0", &format!("duration = {d}"))
            .replace("settle = 10.0", &format!("settle = {}", d / 3.0));
        rows.push(scaled_run("duration", format!("{d} s"), &text)?);
    }
    for lines in [256, 1024, 4096] {
        let text = base.replace("lines = 1024", &format!("lines = {lines}"));
        rows.push(scaled_run("lines", format!("{lines}"), &text)?);
    }
    let rotor = "\n[rotor]\nmass = 350.0\ncentre_of_mass = 1.9\nsupport_a = 0.0\nsupport_b = 4.0\ngrade = 6.3\nservice_speed = 134.0\n[[unbalance]]\nz = 1.2\namount = 2e-3\nangle = 30.0\n";
    let vibration = "\n[[platform]]\nmass = 100.0\nstiffness = 4.0e5\ndamping = 200.0\n[autobalancer]\nkind = \"ball\"\nplatform = 1\nloads = 2\nload_mass = 0.5\nradius = 0.1\nhousing_mass = 5.0\nviscosity = 10.0\n";
    rows.push(scaled_run("effects", "motor, load".into(), base)?);
    rows.push(scaled_run(
        "effects",
        "motor, load, rotor-loads".into(),
        &format!("{base}{rotor}"),
    )?);
    rows.push(scaled_run(
        "effects",
        "motor, load, vibration, rotor-loads".into(),
        &format!("{base}{rotor}{vibration}"),
    )?);
    Ok(rows)
}

/// The own DOPRI5 against the `ode_solvers` crate's on the same problem at the same
/// tolerances.
#[derive(Debug, Clone, Serialize)]
pub struct CrateRow {
    /// Which stepper.
    pub stepper: &'static str,
    /// Relative tolerance (absolute = rtol·1e-2).
    pub rtol: f64,
    /// Wall time, ms (minimum of three).
    pub wall_ms: f64,
    /// max |ω²/u(φ) − 1| at the 1 ms output points after 10 s.
    pub error: f64,
}

struct KneaderOde {
    model: DriveModel,
}

impl ode_solvers::System<f64, ode_solvers::Vector2<f64>> for KneaderOde {
    fn system(&self, _t: f64, y: &ode_solvers::Vector2<f64>, dy: &mut ode_solvers::Vector2<f64>) {
        let (phi, omega) = (y[0], y[1]);
        dy[0] = omega;
        dy[1] = (self.model.motor().torque(omega) - self.model.load().torque(phi))
            / self.model.total_inertia();
    }
}

struct Every {
    dt: f64,
    next: f64,
    from: f64,
    model: DriveModel,
    worst: f64,
}

impl Observer for Every {
    fn edge(&mut self, _edge: &crate::engine::encoder::Edge) {}
    fn step(&mut self, step: &StepView<'_>) {
        while self.next <= step.t1() {
            if self.next >= self.from {
                let s = step.shaft(self.next);
                self.worst = self.worst.max(steady_error(&self.model, s.phi, s.omega));
            }
            self.next += self.dt;
        }
    }
}

/// The kneader ODE for 30 s with output every 1 ms: the own DOPRI5 (dense output sampled at
/// the same instants) against `ode_solvers::Dopri5` (its dense output), per tolerance.
pub fn crate_comparison() -> Result<Vec<CrateRow>, String> {
    let model = kneader_model()?;
    let omega0 = model.u_mean().sqrt();
    let mut rows = Vec::new();
    for rtol in [1e-6, 1e-8, 1e-10] {
        let atol = rtol * 1e-2;
        let (wall_ms, error) = best_of_three(|| {
            let mut solver = ode_solvers::Dopri5::new(
                KneaderOde {
                    model: model.clone(),
                },
                0.0,
                30.0,
                1e-3,
                ode_solvers::Vector2::new(0.0, omega0),
                rtol,
                atol,
            );
            solver.integrate().map_err(|e| e.to_string())?;
            let mut worst: f64 = 0.0;
            for (t, y) in solver.x_out().iter().zip(solver.y_out()) {
                if *t >= 10.0 {
                    worst = worst.max(steady_error(&model, y[0], y[1]));
                }
            }
            Ok(worst)
        })
        .map_err(|e| format!("ode_solvers at rtol {rtol}: {e}"))?;
        rows.push(CrateRow {
            stepper: "ode_solvers::Dopri5",
            rtol,
            wall_ms,
            error,
        });
        let (wall_ms, error) = best_of_three(|| {
            let integ = Integrator::Dopri5 {
                rtol,
                atol,
                max_step: None,
            };
            let mut obs = Every {
                dt: 1e-3,
                next: 0.0,
                from: 10.0,
                model: model.clone(),
                worst: 0.0,
            };
            // One line per revolution: the encoder is all but idle, as in the crate's run.
            let mut sim = kneader_simulation(&model, integ, 1)?;
            sim.run_observed(30.0, &mut obs)
                .map_err(|e| e.to_string())?;
            Ok(obs.worst)
        })
        .map_err(|e| format!("own dp5 at rtol {rtol}: {e}"))?;
        rows.push(CrateRow {
            stepper: "host-sim dp5",
            rtol,
            wall_ms,
            error,
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(wall_ms: f64, error: f64) -> ParetoRow {
        ParetoRow {
            scene: "t",
            setting: String::new(),
            rhs_evals: 0,
            wall_ms,
            error,
            pareto: false,
        }
    }

    #[test]
    fn pareto_front_keeps_only_undominated_settings() {
        let mut rows = vec![
            row(1.0, 1e-3),
            row(2.0, 1e-6),
            row(3.0, 1e-5),
            row(0.5, 1e-2),
        ];
        mark_pareto(&mut rows);
        let front: Vec<bool> = rows.iter().map(|r| r.pareto).collect();
        // (3 ms, 1e-5) is beaten by (2 ms, 1e-6) on both counts.
        assert_eq!(front, vec![true, true, false, true]);
    }
}
