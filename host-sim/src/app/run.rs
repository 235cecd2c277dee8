//! `drive-sim run`: simulate a scene, feed its encoder edges to the core, report.
//!
//! The system is assembled from the effects the scene calls for (motor, load, vibration
//! machine, rotor loads); the encoder turns the shaft's motion into capture timestamps; the
//! core's [`DeltaMonitor`] (the code that runs on the target) measures δ from them, and the
//! core's classifiers judge the measured speed. The report puts the core's measurements next
//! to the design-time prediction and to what the simulation itself did.

use crate::app::predict::{self, value_error};
use crate::app::scene::{
    BalancerKindSpec, FramingSpec, IntegratorKind, MotorSpec, Scene, SceneError,
};
use crate::engine::encoder::{EncoderConfig as SimEncoder, Reference, Runout};
use crate::engine::model::Effect;
use crate::engine::ode::Integrator;
use crate::engine::rotor_loads::{RotorLoads, RotorLoadsParams, StaticLoadParams, UnbalanceParams};
use crate::engine::system::{
    DynamicShaft, InertiaHarmonic, Observer, ShaftModel, Simulation, SpeedLaw, StepView, System,
};
use crate::engine::vibration::{
    classify, AutoBalancerParams, CouplingParams, InitialParams, LoadKind, LoadPlacement,
    PlatformParams, RegimeReport, RegimeSample, VibrationMachine, VibrationMachineParams,
};
use drive_monitor::alarm::{AlarmConfig, AlarmEvent};
#[cfg(doc)]
use drive_monitor::balancer::DEFAULT_MARGIN;
use drive_monitor::balancer::{Classifier, Machine};
use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator, Framing};
use drive_monitor::irregularity::{WindowConfig, WindowLength, WindowReport};
use drive_monitor::monitor::{fault_name, DeltaMonitor};
use drive_monitor::supports::{Level, SupportAnalysis};
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::Path;
use std::time::Instant;

/// Largest disc the simulator's monitor holds (edges per revolution).
pub const MAX_LINES: usize = 8192;

/// One δ window as reported by the core, with the simulated time it ended at.
#[derive(Debug, Clone, Serialize)]
pub struct WindowOut {
    /// Simulated time at the window's last edge, s.
    pub time: f64,
    /// δ.
    pub delta: f64,
    /// Mean speed, rad/s.
    pub omega_mean: f64,
    /// Quantization floor of δ.
    pub noise_floor: f64,
    /// Valid (complete, no fault).
    pub valid: bool,
    /// Steady speed.
    pub steady: bool,
    /// Fault name when invalid.
    pub fault: Option<&'static str>,
}

/// An alarm transition.
#[derive(Debug, Clone, Serialize)]
pub struct AlarmOut {
    /// Simulated time, s.
    pub time: f64,
    /// "raised" or "cleared".
    pub event: &'static str,
}

/// Support results at the measured speed.
#[derive(Debug, Clone, Serialize)]
pub struct SupportsRunOut {
    /// Speed the core measured, rad/s.
    pub speed: f64,
    /// Peak support loads per turn from the core at that speed, N.
    pub peak_load: [f64; 2],
    /// Largest support reaction seen in the simulation over the last second, N.
    pub simulated_peak_reaction: [f64; 2],
    /// Level of each support load: "normal" | "warning" | "over" | "unknown".
    pub load_level: [&'static str; 2],
    /// Level of each plane's unbalance against its permissible share.
    pub unbalance_level: [&'static str; 2],
    /// Largest safe speed, rad/s.
    pub max_safe_speed: Option<f64>,
}

/// What a run produced.
#[derive(Debug, Clone, Serialize, Default)]
pub struct RunReport {
    /// The scene file.
    pub scene: String,
    /// Effects simulated, in assembly order.
    pub effects: Vec<&'static str>,
    /// Integrator used.
    pub integrator: &'static str,
    /// Simulated time, s.
    pub simulated_seconds: f64,
    /// Wall time of the simulation and the core together, s.
    pub wall_seconds: f64,
    /// Right-hand-side evaluations of the whole system.
    pub rhs_evaluations: u64,
    /// Evaluations per component.
    pub component_evaluations: BTreeMap<&'static str, u64>,
    /// Accepted and rejected integrator steps.
    pub steps: [u64; 2],
    /// Edges generated (line, index and glitch).
    pub edges: u64,
    /// Median δ of the valid steady windows after the settling time.
    pub delta_measured: Option<f64>,
    /// δ predicted by the drive model.
    pub delta_predicted: Option<f64>,
    /// Windows reported by the core.
    pub windows: u32,
    /// Of which invalid.
    pub invalid_windows: u32,
    /// Invalid windows by reason.
    pub invalid_reasons: BTreeMap<&'static str, u32>,
    /// Median noise floor of the counted windows.
    pub noise_floor: Option<f64>,
    /// Alarm transitions.
    pub alarms: Vec<AlarmOut>,
    /// Edges the core rejected or found missing: glitches, missing edges, extra edges.
    pub rejected_edges: [u32; 3],
    /// Mean speed measured by the core over the last window, rad/s.
    pub speed_measured: Option<f64>,
    /// The seed criterion's zone at the measured speed: "balancing" | "gathering".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_predicted: Option<&'static str>,
    /// The core's class from the machine's regime table (exact unless the balancer is too
    /// small for its rotor): "balancing" | "gathering" | "bistable" | "near-characteristic".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_class: Option<&'static str>,
    /// Why bistable: "capture" | "coexisting".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_reason: Option<&'static str>,
    /// What the loads did in the simulation: "balancing" | "saturated" (a balancer too small
    /// for its rotor, settled on the least residual it can leave) | "gathering".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_simulated: Option<&'static str>,
    /// `N·m·R`: the largest unbalance the loads can balance, kg·m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capacity: Option<f64>,
    /// The rotor unbalance `D` simulated, kg·m.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotor_unbalance: Option<f64>,
    /// `max(0, D − N·m·R)`: the least residual unbalance the loads can leave, kg·m (non-zero
    /// for a balancer too small for its rotor: every load at its limit, opposite the
    /// unbalance).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_floor: Option<f64>,
    /// Residual unbalance at the end relative to the rotor unbalance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub residual_relative: Option<f64>,
    /// The whole classification of what the loads did (initial residual, coherence, speeds).
    #[serde(skip)]
    pub regime_detail: Option<RegimeReport>,
    /// Support results.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub supports: Option<SupportsRunOut>,
    /// Sommerfeld capture of loads started together ([`crate::app::capture`]): where they were
    /// captured and released, against the core's capture window.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capture: Option<crate::app::capture::CaptureReport>,
    /// Every window (for plots).
    #[serde(skip)]
    pub window_list: Vec<WindowOut>,
    /// Speed the core measured against time, decimated (for plots).
    #[serde(skip)]
    pub speed_trace: Vec<(f64, f64)>,
    /// Settling time, s.
    #[serde(skip)]
    pub settle: f64,
    /// δ limit.
    #[serde(skip)]
    pub delta_limit: Option<f64>,
}

/// How a run may deviate from the scene (the sweep's knobs).
#[derive(Debug, Clone, Copy, Default)]
pub struct Overrides {
    /// Prescribed rotor speed, rad/s, instead of the scene's motor.
    pub speed: Option<f64>,
    /// Start the loads together at rest (for the Sommerfeld capture) instead of near the
    /// balancing position.
    pub loads_together: bool,
}

fn integrator(scene: &Scene) -> Integrator {
    let s = &scene.simulation;
    match s.integrator {
        IntegratorKind::Rk4 => Integrator::Rk4 { step: s.step },
        IntegratorKind::Dp5 => Integrator::Dopri5 {
            rtol: s.rtol,
            atol: s.atol,
            max_step: Some(s.step.max(1e-6) * 100.0),
        },
        IntegratorKind::Dop853 => Integrator::Dop853 {
            rtol: s.rtol,
            atol: s.atol,
            max_step: Some(s.step.max(1e-6) * 100.0),
        },
    }
}

/// The vibration machine of a scene, in the simulator's terms (checked when the caller builds
/// the [`VibrationMachine`] from it). `rotor_speed` is the shaft's speed at `t = 0`, rad/s:
/// loads started near the balancing position turn with the rotor (the balancing position is
/// a co-rotating state); loads started together are at rest. The loads start together when
/// the scene asks for it (`[autobalancer] start = "together"`) or `together` forces it.
pub fn vibration_params(
    scene: &Scene,
    together: bool,
    rotor_speed: f64,
) -> Option<VibrationMachineParams> {
    let ab = scene.autobalancer.as_ref()?;
    let together = together || ab.start == crate::app::scene::LoadStart::Together;
    let kind = match ab.kind {
        BalancerKindSpec::Ball => LoadKind::Ball,
        BalancerKindSpec::Roller => LoadKind::Roller,
        BalancerKindSpec::Pendulum => LoadKind::Pendulum {
            centroidal_inertia: ab.pendulum_inertia.unwrap_or(0.0),
        },
    };
    let capacity = ab.loads as f64 * ab.load_mass * ab.radius;
    let loads = if together {
        LoadPlacement::Together {
            angle: 0.0,
            spread: 0.01,
        }
    } else {
        LoadPlacement::Balanced { perturbation: 0.05 }
    };
    Some(VibrationMachineParams {
        platforms: scene
            .platform
            .iter()
            .map(|p| PlatformParams {
                mass: p.mass,
                stiffness: p.stiffness,
                damping: p.damping,
            })
            .collect(),
        couplings: scene
            .coupling
            .iter()
            .map(|c| CouplingParams {
                between: [
                    (c.between[0] as usize).wrapping_sub(1),
                    (c.between[1] as usize).wrapping_sub(1),
                ],
                stiffness: c.stiffness,
                damping: c.damping,
            })
            .collect(),
        balancer: AutoBalancerParams {
            platform: Some((ab.platform as usize).wrapping_sub(1)),
            loads: ab.loads as usize,
            load_mass: ab.load_mass,
            radius: ab.radius,
            kind,
            housing_mass: ab.housing_mass,
            load_viscosity: ab.viscosity,
            // Default: half of what the loads can balance, so a balancing position exists.
            rotor_unbalance: ab.rotor_unbalance.unwrap_or(0.5 * capacity),
            rotor_unbalance_angle: 0.0,
        },
        initial: InitialParams {
            loads,
            load_speed: if together { 0.0 } else { rotor_speed },
            rotor_angle: 0.0,
        },
    })
}

fn rotor_loads(scene: &Scene, file: &Path) -> Result<Option<RotorLoads>, SceneError> {
    let Some(r) = &scene.rotor else {
        return Ok(None);
    };
    let mut static_loads = vec![StaticLoadParams::Point {
        force: [0.0, -9.80665 * r.mass],
        z: r.centre_of_mass,
    }];
    if let Some(p) = &scene.process_load {
        let a = p.angle.to_radians();
        static_loads.push(StaticLoadParams::Distributed {
            intensity: [p.per_length * a.cos(), p.per_length * a.sin()],
            from: p.from,
            to: p.to,
        });
    }
    let params = RotorLoadsParams {
        support_a: r.support_a,
        support_b: r.support_b,
        unbalances: scene
            .unbalance
            .iter()
            .map(|u| UnbalanceParams {
                amount: u.amount,
                angle: u.angle.to_radians(),
                z: u.z,
            })
            .collect(),
        static_loads,
    };
    RotorLoads::new(&params)
        .map(Some)
        .map_err(|e| value_error(file, "rotor", e))
}

/// The core's monitor for the scene's encoder.
fn core_monitor(scene: &Scene, file: &Path) -> Result<Option<DeltaMonitor<MAX_LINES>>, SceneError> {
    let Some(e) = &scene.encoder else {
        return Ok(None);
    };
    let mut c = EncoderConfig::new(e.lines, e.timer_hz);
    c.framing = match e.framing {
        FramingSpec::Index => Framing::Index,
        FramingSpec::MissingTooth => Framing::MissingTooth { missing: e.missing },
        FramingSpec::None => Framing::None,
    };
    c.counter_bits = e.counter_bits;
    c.estimator = Estimator::Edges(e.estimator_edges);
    let m = scene.monitor.clone().unwrap_or_default();
    c.min_speed = m.min_speed.unwrap_or(1.0);
    let enc = Encoder::new(c).map_err(|er| value_error(file, "encoder", er))?;
    let revs = match m.window_revolutions {
        Some(n) => WindowLength::Revolutions(n),
        None => {
            // One load cycle: the lowest non-zero order of the load's harmonics.
            let lowest = scene.load.as_ref().and_then(|l| {
                l.harmonics
                    .iter()
                    .map(|h| h.order.abs())
                    .filter(|o| *o > 0.0)
                    .reduce(f64::min)
            });
            match lowest {
                Some(o) => WindowLength::LoadOrder(o),
                None => WindowLength::Revolutions(1),
            }
        }
    };
    let window = WindowConfig {
        length: revs,
        steady_tolerance: m.steady_tolerance.unwrap_or(0.02) as f32,
    };
    let alarm = m.delta_limit.map(|l| AlarmConfig::new(l as f32));
    DeltaMonitor::new(enc, window, alarm)
        .map(Some)
        .map_err(|er| value_error(file, "monitor", er))
}

fn sim_encoder(scene: &Scene, file: &Path) -> Result<SimEncoder, SceneError> {
    let Some(e) = &scene.encoder else {
        // Without an encoder table the simulation still needs one to advance; use a coarse one
        // whose edges are ignored.
        return Ok(SimEncoder::ideal(4, 1e6));
    };
    let mut c = SimEncoder::ideal(e.lines as u32, e.timer_hz);
    c.reference = match e.framing {
        FramingSpec::Index => Reference::Index,
        FramingSpec::MissingTooth => Reference::MissingTeeth {
            count: e.missing as u32,
        },
        FramingSpec::None => Reference::None,
    };
    c.counter_bits = e.counter_bits as u32;
    c.jitter = e.jitter;
    c.pitch_error_std = e.pitch_error;
    if e.runout > 0.0 {
        c.runout = Some(Runout {
            eccentricity: e.runout,
            radius: 1.0,
            phase: e.runout_phase,
        });
    }
    c.drop_probability = e.drop_probability;
    c.glitch_probability = e.glitch_probability;
    c.seed = scene.simulation.seed;
    crate::engine::encoder::Encoder::new(c.clone())
        .map_err(|er| value_error(file, "encoder", er))?;
    Ok(c)
}

fn level(l: Level) -> &'static str {
    match l {
        Level::Normal => "normal",
        Level::Warning => "warning",
        Level::Over => "over",
        Level::Unknown => "unknown",
    }
}

fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    Some(v[v.len() / 2])
}

struct Collector<'a> {
    monitor: Option<DeltaMonitor<MAX_LINES>>,
    windows: Vec<WindowOut>,
    alarms: Vec<AlarmOut>,
    trace: Vec<(f64, f64)>,
    trace_every: u64,
    edges: u64,
    last_window: Option<WindowReport>,
    vibration: Option<(&'a VibrationMachine, std::ops::Range<usize>)>,
    samples: Vec<RegimeSample>,
    sample_every: f64,
    next_sample: f64,
    rotor: Option<RotorLoads>,
    reactions: [f64; 2],
    reactions_from: f64,
    state: Vec<f64>,
}

impl Observer for Collector<'_> {
    fn edge(&mut self, edge: &crate::engine::encoder::Edge) {
        let Some(m) = self.monitor.as_mut() else {
            return;
        };
        if edge.index {
            m.on_index();
            return;
        }
        self.edges += 1;
        if let Some(o) = m.on_edge(edge.ticks, Some(edge.direction)) {
            let r = o.report;
            self.windows.push(WindowOut {
                time: edge.true_time,
                delta: r.delta as f64,
                omega_mean: r.omega_mean as f64,
                noise_floor: r.noise_floor as f64,
                valid: r.valid(),
                steady: r.steady,
                fault: r.fault.map(fault_name),
            });
            if r.valid() {
                self.last_window = Some(r);
            }
            if let Some(e) = o.event {
                self.alarms.push(AlarmOut {
                    time: edge.true_time,
                    event: match e {
                        AlarmEvent::Raised => "raised",
                        AlarmEvent::Cleared => "cleared",
                    },
                });
            }
        }
        // The trace starts with the first speed sample (0 before it is "no sample yet").
        if self.edges % self.trace_every == 0 && (m.speed() > 0.0 || !self.trace.is_empty()) {
            self.trace.push((edge.true_time, m.speed() as f64));
        }
    }

    fn step(&mut self, step: &StepView<'_>) {
        if let Some((vm, range)) = &self.vibration {
            while self.next_sample <= step.t1() {
                let t = self.next_sample.max(step.t0());
                step.state_into(t, &mut self.state);
                let shaft = step.shaft(t);
                self.samples
                    .push(vm.sample(t, shaft, &self.state[range.clone()]));
                self.next_sample += self.sample_every;
            }
        }
        if let Some(r) = &self.rotor {
            if step.t1() >= self.reactions_from {
                let f = r.reactions(step.shaft(step.t1()));
                for (peak, v) in self.reactions.iter_mut().zip(f) {
                    *peak = peak.max(v[0].hypot(v[1]));
                }
            }
        }
    }
}

/// The capture analysis of a run whose loads started together (`None` otherwise).
fn capture_analysis(
    scene: &Scene,
    file: &Path,
    params: Option<&VibrationMachineParams>,
    samples: &[RegimeSample],
) -> Result<Option<crate::app::capture::CaptureReport>, SceneError> {
    let together =
        params.is_some_and(|p| matches!(p.initial.loads, LoadPlacement::Together { .. }));
    if !together {
        return Ok(None);
    }
    Ok(predict::machine(scene, file)?.and_then(|m| crate::app::capture::analyse(samples, &m)))
}

/// The scene's file name without its extension ("scene" if it has none): the stem of the
/// pages and plots written for it.
pub fn scene_stem(path: &Path) -> String {
    path.file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene")
        .to_string()
}

/// The core's regime classifier for `machine`: from the exact table of the scene's machine
/// when it has one ([`crate::app::regimes`]), else from the criterion; with the scene's
/// `[monitor] regime_margin` (default [`DEFAULT_MARGIN`]) and half of it as hysteresis. Returns
/// the classifier and that margin.
pub fn regime_classifier(
    scene: &Scene,
    file: &Path,
    machine: &Machine,
) -> Result<(Classifier, f32), SceneError> {
    let design = crate::app::regimes::design(scene, file, machine)?;
    let (c, margin, _) = crate::app::regimes::classifier(scene, file, machine, design.as_ref())?;
    Ok((c, margin))
}

/// Simulates `scene` and reports.
pub fn run(scene: &Scene, file: &Path, over: Overrides) -> Result<RunReport, SceneError> {
    let started = Instant::now();
    let model = predict::drive_model(scene, file)?;
    let mut effects: Vec<Box<dyn Effect>> = Vec::new();
    let mut names = Vec::new();
    let prescribed = over.speed.or(match &scene.motor {
        Some(MotorSpec::Speed { speed }) => Some(*speed),
        _ => None,
    });
    let shaft = match (prescribed, &scene.motor) {
        (Some(omega), _) => ShaftModel::Prescribed(SpeedLaw::Constant { omega, phi0: 0.0 }),
        (None, Some(MotorSpec::Ramp { from, to, duration })) => {
            ShaftModel::Prescribed(SpeedLaw::RampTo {
                omega0: *from,
                omega1: *to,
                ramp_time: *duration,
                phi0: 0.0,
            })
        }
        (None, Some(_)) => {
            let Some(model) = &model else {
                return Err(SceneError::value(
                    file,
                    "load",
                    "missing: a motor-driven scene needs [load]",
                ));
            };
            let shaft = scene.shaft.as_ref().ok_or_else(|| {
                SceneError::value(file, "shaft", "missing: a motor-driven scene needs [shaft]")
            })?;
            effects.push(Box::new(*model.motor()));
            names.push("motor");
            // Start at the predicted mean speed (or the given one) to shorten the transient.
            let omega0 = shaft
                .initial_speed
                .unwrap_or_else(|| model.u_mean().max(0.0).sqrt());
            ShaftModel::Dynamic(DynamicShaft {
                inertia: shaft.inertia,
                flywheel: shaft.flywheel,
                harmonics: shaft
                    .inertia_harmonics
                    .iter()
                    .map(|h| InertiaHarmonic {
                        amplitude: h.amplitude,
                        order: h.order,
                        phase: h.phase,
                    })
                    .collect(),
                phi0: 0.0,
                omega0,
            })
        }
        (None, None) => {
            return Err(SceneError::value(
                file,
                "motor",
                "missing: a scene to run needs [motor] (a torque model or a prescribed speed)",
            ))
        }
    };
    if let (Some(model), true) = (&model, matches!(shaft, ShaftModel::Dynamic(_))) {
        effects.push(Box::new(model.load().clone()));
        names.push("load");
    }
    let rotor_speed0 = match &shaft {
        ShaftModel::Prescribed(law) => law.shaft(0.0).omega,
        ShaftModel::Dynamic(d) => d.omega0,
    };
    let vib_params = vibration_params(scene, over.loads_together, rotor_speed0);
    let vib_machine = match &vib_params {
        Some(p) => {
            Some(VibrationMachine::new(p).map_err(|e| value_error(file, "autobalancer", e))?)
        }
        None => None,
    };
    if let Some(vm) = &vib_machine {
        effects.push(Box::new(vm.clone()));
        names.push("vibration");
    }
    let rotor = rotor_loads(scene, file)?;
    if let Some(r) = &rotor {
        effects.push(Box::new(*r));
        names.push("rotor-loads");
    }
    let system = System::new(shaft, effects).map_err(|e| value_error(file, "shaft", e))?;
    let vib_range = names
        .iter()
        .position(|n| *n == "vibration")
        .map(|k| system.effect_range(k));
    let dim = system.dim();
    let integ = integrator(scene);
    integ
        .validate()
        .map_err(|e| value_error(file, "simulation", e))?;
    let mut sim = Simulation::new(system, integ.clone(), sim_encoder(scene, file)?)
        .map_err(|e| SceneError::value(file, "simulation", e.to_string()))?;
    let duration = scene.simulation.duration;
    let lines = scene.encoder.as_ref().map_or(1, |e| e.lines as u64);
    let expected_edges = model
        .as_ref()
        .map_or(1e3, |m| m.u_mean().max(1.0).sqrt())
        .max(over.speed.unwrap_or(0.0))
        * duration
        / std::f64::consts::TAU
        * lines as f64;
    let mut col = Collector {
        monitor: core_monitor(scene, file)?,
        windows: Vec::new(),
        alarms: Vec::new(),
        trace: Vec::new(),
        trace_every: ((expected_edges / 4000.0) as u64).max(1),
        edges: 0,
        last_window: None,
        vibration: vib_machine.as_ref().zip(vib_range),
        samples: Vec::new(),
        // 4000 samples a run, and at least 100 a second (a capture's slip beats need them).
        sample_every: (duration / 4000.0).min(0.01),
        next_sample: 0.0,
        rotor,
        reactions: [0.0; 2],
        reactions_from: (duration - 1.0).max(0.0),
        state: vec![0.0; dim],
    };
    let stats = sim
        .run_observed(duration, &mut col)
        .map_err(|e| SceneError::value(file, "simulation", e.to_string()))?;
    let settle = scene.simulation.settle.unwrap_or(duration / 3.0);
    let mut report = RunReport {
        scene: file.display().to_string(),
        effects: names,
        integrator: integ.name(),
        simulated_seconds: stats.time,
        rhs_evaluations: stats.solver.rhs_evals,
        component_evaluations: stats
            .evaluations
            .iter()
            .map(|c| (c.name, c.evals))
            .collect(),
        steps: [stats.solver.accepted_steps, stats.solver.rejected_steps],
        edges: stats.encoder.edges,
        settle,
        delta_limit: scene.monitor.as_ref().and_then(|m| m.delta_limit),
        ..Default::default()
    };
    if let Some(model) = &model {
        report.delta_predicted = model.predict().steady().map(|s| s.delta);
    }
    if let Some(m) = &col.monitor {
        let d = m.diagnostics();
        report.windows = d.valid_windows + d.invalid_windows;
        report.invalid_windows = d.invalid_windows;
        report.rejected_edges = [d.edges.glitches, d.edges.missing, d.edges.extra];
        for w in col.windows.iter().filter(|w| !w.valid) {
            *report
                .invalid_reasons
                .entry(w.fault.unwrap_or("unknown"))
                .or_default() += 1;
        }
        let counted: Vec<&WindowOut> = col
            .windows
            .iter()
            .filter(|w| w.valid && w.steady && w.time >= settle)
            .collect();
        report.delta_measured = median(&mut counted.iter().map(|w| w.delta).collect::<Vec<_>>());
        report.noise_floor = median(&mut counted.iter().map(|w| w.noise_floor).collect::<Vec<_>>());
        report.speed_measured = col.last_window.map(|w| w.omega_mean as f64);
    }
    if let (Some(machine), Some(w)) = (predict::machine(scene, file)?, report.speed_measured) {
        let (classifier, _) = regime_classifier(scene, file, &machine)?;
        let class = classifier.classify(w as f32);
        report.regime_class = Some(class.name());
        report.regime_reason = class.reason().map(|r| r.name());
        // The criterion's own zone at the measured speed (no margin, no capture check).
        report.regime_predicted = Some(machine.zone_kind_at(w).name());
    }
    if let Some(vm) = &vib_machine {
        report.capacity = Some(vm.capacity());
        report.rotor_unbalance = Some(vm.rotor_unbalance());
        report.residual_floor = Some(vm.residual_floor());
        let criteria = vm.regime_criteria();
        if let Some(r) = classify(&col.samples, &criteria) {
            report.regime_simulated = Some(r.regime.as_str());
            report.residual_relative = Some(r.residual_relative);
            report.regime_detail = Some(r);
        }
    }
    report.capture = capture_analysis(scene, file, vib_params.as_ref(), &col.samples)?;
    if let Some((rotor, limits)) = predict::rotor(scene, file)? {
        let analysis = SupportAnalysis::new(&rotor, &limits);
        let speed = report.speed_measured.unwrap_or(limits.service_speed());
        let status = analysis.monitor().update(speed as f32);
        report.supports = Some(SupportsRunOut {
            speed,
            peak_load: status.peak_load.map(f64::from),
            simulated_peak_reaction: col.reactions,
            load_level: status.load.map(level),
            unbalance_level: status.unbalance.map(level),
            max_safe_speed: status
                .max_safe_speed
                .map(f64::from)
                .filter(|v| v.is_finite()),
        });
    }
    report.alarms = col.alarms;
    report.window_list = col.windows;
    report.speed_trace = col.trace;
    report.wall_seconds = started.elapsed().as_secs_f64();
    Ok(report)
}
