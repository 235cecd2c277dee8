//! `drive-sim run`: simulate a scene, feed its encoder edges to the core, report.
//!
//! The system is assembled from the effects the scene calls for (motor, load, vibration
//! machine, rotor loads); the encoder turns the shaft's motion into capture timestamps; the
//! core's [`DeltaMonitor`] (the code that runs on the target) measures δ from them, and the
//! core's classifiers judge the measured speed. The report puts the core's measurements next
//! to the design-time prediction and to what the simulation itself did.

use crate::app::logic::{CaptureFormat, CaptureSettings, CaptureWriter};
use crate::app::predict::{self, core_error};
use crate::app::scene::{
    BalancerKindSpec, FramingSpec, IntegratorKind, MotorSpec, Scene, SceneError,
};
use crate::engine::cranking::{Ripple, SpeedProfile};
use crate::engine::encoder::{EncoderConfig as SimEncoder, Reference, Runout};
use crate::engine::model::Effect;
use crate::engine::ode::Integrator;
use crate::engine::rotor_loads::{RotorLoads, RotorLoadsParams, StaticLoadParams, UnbalanceParams};
use crate::engine::system::{
    DynamicShaft, InertiaHarmonic, Observer, ShaftModel, Simulation, SpeedLaw, StepView, System,
};
use crate::engine::vibration::regime::{AWAY, BALANCED};
use crate::engine::vibration::{
    classify, AutoBalancerParams, CouplingParams, InitialParams, LoadKind, LoadPlacement,
    PlatformParams, Regime as SimRegime, RegimeCriteria, RegimeReport, RegimeSample,
    VibrationMachine, VibrationMachineParams,
};
use drive_monitor::alarm::{AlarmConfig, AlarmEvent, Verdict};
#[cfg(doc)]
use drive_monitor::balancer::DEFAULT_MARGIN;
use drive_monitor::balancer::{Classifier, Machine, RegimeTracker};
use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator, Tolerances, Wheel};
use drive_monitor::irregularity::{Measurement, WindowConfig, WindowLength, WindowReport};
use drive_monitor::monitor::{fault_name, DeltaMonitor};
use drive_monitor::supports::Level;
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

/// How the alarm judged the windows: only those it counts can raise or clear it.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct AlarmJudged {
    /// Counted (valid, steady, floor well below the limit), of which `over` over the limit.
    pub counted: u32,
    /// Counted windows whose δ was over the limit.
    pub over: u32,
    /// Not counted: the noise floor above `floor_fraction` of the limit (δ cannot be told
    /// from the limit).
    pub floor_near_limit: u32,
    /// Not counted: the speed was not steady.
    pub unsteady: u32,
    /// Not counted: the window was invalid.
    pub invalid: u32,
    /// The fraction of the limit the floor must stay below (the core's default).
    pub floor_fraction: f32,
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
    /// Speed the loads are judged at, rad/s: the fastest the core measured in any valid window
    /// of the run (ω max; the unbalance load peaks there), null when it measured none.
    pub speed: Option<f64>,
    /// The mean speed of that window, rad/s.
    pub speed_mean: Option<f64>,
    /// When that window ended, s.
    pub speed_at: Option<f64>,
    /// Peak support loads per turn from the core at that speed, N (null without a measured
    /// speed, or beyond f32).
    pub peak_load: [Option<f64>; 2],
    /// Largest support reaction seen in the simulation over the whole run (sampled every
    /// [`REACTION_ANGLE`] of shaft rotation), N.
    pub simulated_peak_reaction: [f64; 2],
    /// When each of them was seen, s.
    pub simulated_peak_at: [f64; 2],
    /// When the run turned the shaft less than a revolution: its reactions may miss their peak.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reactions_note: Option<String>,
    /// Level of each support load: "normal" | "warning" | "over" | "unknown".
    pub load_level: [&'static str; 2],
    /// Level of each plane's unbalance against its permissible share.
    pub unbalance_level: [&'static str; 2],
    /// Largest safe speed, rad/s.
    pub max_safe_speed: Option<f64>,
    /// The simulated reactions against the scene's load limits ("normal" | "warning" |
    /// "over"), null without limits.
    pub simulated_reaction_level: Option<[&'static str; 2]>,
    /// When the fastest measured speed is above the service speed the permissible unbalance
    /// was allotted for: the warning the report prints.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub above_service_speed: Option<String>,
    /// The scene also has an auto-balancer, which the support analysis and the simulated
    /// reactions leave out ([`predict::balancer_supports_warning`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub balancer_warning: Option<String>,
    /// The unbalances imply an eccentricity longer than the rotor
    /// ([`predict::unbalance_warning`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unbalance_warning: Option<String>,
}

/// What a run produced.
#[derive(Debug, Clone, Serialize, Default)]
pub struct RunReport {
    /// The scene file.
    pub scene: String,
    /// How the shaft moves: "motor-driven" (integrated under `effects`' torques),
    /// "prescribed" (`[motor]` model `speed`, `ramp` or `profile`, or the sweep's speed), or
    /// "prescribed with a cranking ripple" (`[cranking]`, integrated as φ from ω(φ, t)).
    pub shaft: &'static str,
    /// Effects simulated, in assembly order (a prescribed shaft is none).
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
    /// Rising edges generated (line, index and glitch); 0 without an `[encoder]`.
    pub edges: u64,
    /// Of them, the rising edges on the encoder's line channel, noise pulses included (what
    /// `analyze` of the run's capture counts as the channel's edges).
    pub line_edges: u64,
    /// Of the line edges, the noise pulses (`encoder.glitch_probability`).
    pub noise_pulses: u64,
    /// Of them, the index pulses (an index disc's own channel).
    pub index_pulses: u64,
    /// Median δ of the valid steady windows after the settling time.
    pub delta_measured: Option<f64>,
    /// δ predicted by the drive model, as `predict` gives it ([`predict::predicted_delta`]).
    pub delta_predicted: Option<f64>,
    /// The predicted δ as the core's speed samples (`encoder.estimator_edges` edges each,
    /// starting at the teeth) show it with the teeth where the scene has them (the
    /// simulator's wheel: tooth 0 at the load's φ = 0; [`predict::sampled_delta`]): what the
    /// measurement is to be compared with.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_predicted_through_samples: Option<f64>,
    /// The least δ those samples show over the load's phase against the teeth.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_predicted_through_samples_least: Option<f64>,
    /// The most δ those samples show over the load's phase against the teeth.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_predicted_through_samples_most: Option<f64>,
    /// How the core's speed samples read the scene's `[cranking]` ripple (with an
    /// `[encoder]`): a prescribed speed has no prediction to compare the measured δ with, so
    /// the share of the ripple's own δ the samples show is given, and a WARNING under the δ
    /// line where they read less than [`RIPPLE_READ_SHARE`] of it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cranking_ripple: Option<RippleRead>,
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
    /// How the alarm judged the windows (with a δ limit).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alarm_judged: Option<AlarmJudged>,
    /// Edges the core rejected or found missing: glitches, missing edges, extra edges.
    pub rejected_edges: [u32; 3],
    /// Times the core's standstill check found the shaft stopped (as `analyze` counts them).
    pub timeouts: u32,
    /// Mean speed measured by the core over the last window, rad/s.
    pub speed_measured: Option<f64>,
    /// The fastest speed the core measured in any valid window of the run (its ω max), rad/s:
    /// an excursion anywhere in the run, not only in the last window.
    pub speed_peak_measured: Option<f64>,
    /// When the window of [`RunReport::speed_peak_measured`] ended, s.
    pub speed_peak_at: Option<f64>,
    /// That window's mean speed, rad/s.
    pub speed_peak_mean: Option<f64>,
    /// Why the core measured nothing: no valid window, or no `[encoder]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub no_measurement: Option<String>,
    /// The default δ window cannot hold the load's whole period ([`window_warning`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub window_warning: Option<String>,
    /// Tables of the scene that take no part in the run, each with why (e.g. `[load]` under a
    /// prescribed speed).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_simulated: Vec<String>,
    /// What the models of the run leave out of what the scene asks for, each a WARNING (a
    /// cranking ripple on a vibration machine: [`cranking_warning`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub model_warnings: Vec<String>,
    /// What the comparison of the measured δ with the predicted one leaves out, each a WARNING
    /// or NOTE printed under it: the vibration machine's torque on the shaft, which the
    /// prediction omits and the run simulates ([`machine_torque_note`]); the scene's encoder
    /// errors, in the measured δ and not in its noise floor ([`encoder_errors_note`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub delta_notes: Vec<String>,
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
    /// `regime_class` comes from the speed's history, not the last speed alone: the table
    /// says bistable there, and the measured speed came from a balancing segment through
    /// segments where the balancing position stays stable, so the loads that balanced there
    /// still do (`balancer::RegimeTracker`, fed every valid window's speed).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub regime_by_history: bool,
    /// Why `regime_simulated` is "unsettled": the run ended before the loads' regime showed.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_unsettled: Option<String>,
    /// The core's committed class and the settled simulation disagree: why that can be.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_mismatch: Option<String>,
    /// The loads met to within rounding and moved as one, where the balancing position is
    /// stable (simulated "coincident": no verdict, the model has no contact between loads).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_coincident: Option<String>,
    /// The loads settled into a steady oscillation about the balancing position (simulated
    /// "gathering": not balancing, the residual reaching 10 % of the rotor's and back), with
    /// its residual range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_swing: Option<String>,
    /// What the loads did in the simulation: "balancing" | "saturated" (a balancer too small
    /// for its rotor, settled on the least residual it can leave) | "gathering" | "unsettled"
    /// | "coincident" (see `regime_coincident`).
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
    /// The capture file written (`--capture`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capture_file: Option<String>,
    /// Rows written to it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capture_rows: Option<u64>,
    /// What the capture's sampling did to each channel: the level changes of the signal and
    /// those the file lacks (merged within a sample period).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub capture_channels: Vec<crate::app::logic::ChannelSampling>,
    /// A WARNING when the file lacks level changes of the signal: how many, on which channel,
    /// and the sample rate that would keep them.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub capture_warning: Option<String>,
    /// Every edge the encoder produced ([`RunOptions::keep_edges`]).
    #[serde(skip)]
    pub edge_list: Vec<crate::engine::encoder::Edge>,
    /// Settling time, s.
    #[serde(skip)]
    pub settle: f64,
    /// δ limit (`[monitor] delta_limit`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_limit: Option<f64>,
}

/// How the core's speed samples read a `[cranking]` ripple ω̄·(1 + ripple·sin(strokes·φ +
/// phase)) at a steady mean speed, by [`predict::sampled_delta_of`] (the machinery `predict`
/// and `run` take the predicted δ through the samples with): each sample is the mean speed
/// over `encoder.estimator_edges` edges and starts only at a tooth, so a ripple of a few
/// cycles a revolution is averaged away or read between its peaks.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct RippleRead {
    /// The ripple's own δ, 2·ripple (ω̄·(1 ± ripple): 2(ω_max − ω_min)/(ω_max + ω_min)).
    pub delta: f64,
    /// Its order, cycles a revolution (`cranking.strokes`).
    pub order: f64,
    /// Edges per speed sample (`encoder.estimator_edges`).
    pub estimator_edges: u16,
    /// δ the samples show with the teeth where the scene has them (the simulator's wheel,
    /// tooth 0 at φ = 0): what the run measures, to the ripple's change of mean speed.
    pub through_samples: f64,
    /// The least δ they show over the ripple's phase against the teeth.
    pub through_samples_least: f64,
    /// The most δ they show over that phase.
    pub through_samples_most: f64,
    /// `through_samples / delta`: the share of the ripple's δ the measured δ is.
    pub share: f64,
    /// The most edges per sample whose least over the phase reads [`RIPPLE_READ_SHARE`] of
    /// the ripple's δ (`null` when even one edge does not).
    pub edges_for_95_percent: Option<u16>,
    /// The least share of the ripple's δ one-edge samples read over the phase: the most any
    /// number of edges a sample can count on, on this wheel.
    pub share_one_edge: f64,
}

/// Below this share of a `[cranking]` ripple's δ read through the samples (at the scene's
/// phase, or the least over the phase), `run` WARNs under its δ line (`analyze` states its
/// ripple table below the same share).
pub const RIPPLE_READ_SHARE: f64 = 0.95;

/// [`RippleRead`] of the scene's `[cranking]` ripple: `None` without a ripple or an
/// `[encoder]`, or where the strokes have no period of whole revolutions the samples can be
/// tabulated over.
pub fn cranking_ripple_read(scene: &Scene, file: &Path) -> Result<Option<RippleRead>, SceneError> {
    use crate::app::sampled::{sampled_range, SteadyTime, SCAN_BUDGET};
    let Some(c) = scene.cranking.filter(|c| c.ripple > 0.0 && c.strokes > 0.0) else {
        return Ok(None);
    };
    let Some(e) = &scene.encoder else {
        return Ok(None);
    };
    let Some(revolutions) = drive_monitor::drive::period_revolutions(&[c.strokes]) else {
        return Ok(None);
    };
    let delta = 2.0 * c.ripple;
    // δ does not depend on the mean speed: ω̄ = 1.
    let omega = |phi: f64| Some(1.0 + c.ripple * (c.strokes * phi + c.phase).sin());
    let Some(time) = SteadyTime::tabulate(
        std::f64::consts::TAU / c.strokes,
        revolutions,
        c.strokes,
        omega,
    ) else {
        return Ok(None);
    };
    let Some(s) = predict::sampled_delta_of(scene, file, delta, || Some(time.clone()))? else {
        return Ok(None);
    };
    // Fewer edges a sample: the least each reads over the phase, as `sampled_delta_of` scans
    // them for the predicted δ.
    let wheel = predict::sample_wheel(e, &crate::app::check::wheel(e, &scene.checker(file))?);
    let least = |k: u16| {
        if k == e.estimator_edges {
            Some(s.least)
        } else {
            sampled_range(&time, &wheel, k, SCAN_BUDGET / 4).map(|r| r.least)
        }
    };
    let edges_for_95_percent = (1..=e.estimator_edges)
        .rev()
        .find(|&k| least(k).is_some_and(|d| d >= RIPPLE_READ_SHARE * delta));
    Ok(Some(RippleRead {
        delta,
        order: c.strokes,
        estimator_edges: e.estimator_edges,
        through_samples: s.at_scene_phase,
        through_samples_least: s.least,
        through_samples_most: s.most,
        share: s.at_scene_phase / delta,
        edges_for_95_percent,
        share_one_edge: least(1).unwrap_or(0.0) / delta,
    }))
}

/// The WARNING under `run`'s δ line where the samples read less than [`RIPPLE_READ_SHARE`] of
/// the `[cranking]` ripple's δ (at the scene's phase or at the least over it): the measured δ
/// is that share, not the shaft's, and fewer edges per sample read more of it.
pub fn cranking_ripple_warning(r: &RippleRead) -> Option<String> {
    let low = RIPPLE_READ_SHARE * r.delta;
    if r.through_samples >= low && r.through_samples_least >= low {
        return None;
    }
    let over_phase =
        if predict::sampled_spread(r.delta, r.through_samples_least, r.through_samples_most) {
            format!(
                ", {:.3}–{:.3} of it over the ripple's phase against the teeth",
                r.through_samples_least / r.delta,
                r.through_samples_most / r.delta
            )
        } else {
            String::new()
        };
    let share = 100.0 * RIPPLE_READ_SHARE;
    let more = match r.edges_for_95_percent {
        Some(k) => format!(
            "`encoder.estimator_edges = {k}` or fewer reads {share:.0} % of it at any phase \
             (fewer edges a sample raise the noise floor)"
        ),
        None if r.estimator_edges > 1 => format!(
            "fewer edges a sample read more of it (`encoder.estimator_edges = 1` reads {:.3} at \
             the least over the phase), and a wheel with more teeth a ripple cycle more still",
            r.share_one_edge
        ),
        None => "a wheel with more teeth a ripple cycle reads more of it".to_string(),
    };
    Some(format!(
        "WARNING: the core's speed samples of `encoder.estimator_edges = {}` edges read only \
         {:.3} of the [cranking] ripple's δ with the teeth where this scene has them{over_phase}: \
         the ripple (±{} %, order {}) has δ {}, the samples show about {}, and the δ measured is \
         theirs, not the shaft's; {more}",
        r.estimator_edges,
        r.share,
        100.0 * r.delta / 2.0,
        r.order,
        predict::fmt_delta(r.delta),
        predict::fmt_delta(r.through_samples),
    ))
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
        .map_err(|e| core_error(scene, file, "rotor", e))
}

/// The core's encoder configuration for the scene's `[encoder]` (and `[monitor] min_speed`),
/// validated by the core: the wheel however the scene gives it, the timer, the prescaler, the
/// estimator and the tolerances. `None` without an `[encoder]`.
pub fn core_encoder(scene: &Scene, file: &Path) -> Result<Option<Encoder>, SceneError> {
    let Some(e) = &scene.encoder else {
        return Ok(None);
    };
    let c = scene.checker(file);
    let w = crate::app::check::wheel(e, &c)?;
    let wheel = w
        .core()
        .map_err(|er| core_error(scene, file, "encoder", er))?;
    let mut cfg = match wheel {
        Wheel::Indexed { lines } => EncoderConfig::indexed(lines, e.timer_hz),
        Wheel::Unframed { lines } => EncoderConfig::unframed(lines, e.timer_hz),
        Wheel::Pattern(p) => EncoderConfig::pattern(p, e.timer_hz),
    };
    cfg.counter_bits = e.counter_bits;
    cfg.prescaler = e.prescaler;
    cfg.estimator = Estimator::Edges(e.estimator_edges);
    let t = e.tolerances;
    let d = Tolerances::default();
    cfg.tolerances = Tolerances {
        accept: t.accept.map_or(d.accept, |x| x as f32),
        glitch_fraction: t.glitch_fraction.map_or(d.glitch_fraction, |x| x as f32),
        fault_margin: t.fault_margin.map_or(d.fault_margin, |x| x as f32),
    };
    cfg.min_speed = scene
        .monitor
        .as_ref()
        .and_then(|m| m.min_speed)
        .unwrap_or(1.0);
    Encoder::new(cfg).map(Some).map_err(|er| {
        let mut err = core_error(scene, file, "encoder", er);
        let hint = crate::app::check::speed_range_hint(
            &cfg,
            er,
            "monitor.min_speed",
            "encoder.timer_hz",
            "encoder.counter_bits",
        );
        if let (SceneError::Core { message, .. }, Some(h)) = (&mut err, hint) {
            message.push_str(": ");
            message.push_str(&h);
        }
        err
    })
}

/// The δ window of a scene: `[monitor] window_revolutions`, else the load's period (the
/// smallest whole number of revolutions holding a whole number of cycles of every load and
/// inertia order, [`drive_monitor::drive::period_revolutions`], as the prediction finds it),
/// else one revolution. Where the orders have no common period within
/// [`MAX_WINDOW_REVS`](drive_monitor::irregularity::MAX_WINDOW_REVS) revolutions, one cycle
/// of the lowest order, or the longest window where that cycle is longer (an order below
/// 1/1024), which [`window_warning`] says.
pub fn window_config(scene: &Scene) -> WindowConfig {
    let m = scene.monitor.clone().unwrap_or_default();
    WindowConfig {
        length: default_window(scene).0,
        steady_tolerance: m.steady_tolerance.unwrap_or(0.02) as f32,
    }
}

/// The WARNING for a δ window that does not hold the load's whole period (`None` where it
/// does): the default window where no window can (the orders, the window chosen and why δ may
/// be read low in it), a `[monitor] window_revolutions` that is no whole number of periods,
/// or one shorter than a cycle of the lowest order where no window holds the period.
pub fn window_warning(scene: &Scene) -> Option<String> {
    default_window(scene).1
}

/// The orders the load's period is made of: the load's and the inertia's harmonics that are
/// there (order and amplitude non-zero), as the prediction takes them.
fn periodic_orders(scene: &Scene) -> Vec<f64> {
    let load = scene.load.iter().flat_map(|l| l.harmonics.iter());
    let inertia = scene.shaft.iter().flat_map(|s| s.inertia_harmonics.iter());
    let mut orders: Vec<f64> = load
        .chain(inertia)
        .filter(|h| h.order != 0.0 && h.amplitude != 0.0)
        .map(|h| h.order.abs())
        .collect();
    orders.sort_by(f64::total_cmp);
    orders.dedup();
    orders
}

/// The window [`window_config`] takes and [`window_warning`]'s text.
fn default_window(scene: &Scene) -> (WindowLength, Option<String>) {
    let given = scene.monitor.as_ref().and_then(|m| m.window_revolutions);
    window_for(
        scene,
        given.map(|n| (n, format!("`monitor.window_revolutions = {n}`"))),
    )
}

/// The WARNING for a window of `revolutions` set by `given` (an option's words, e.g.
/// `` `--window-revolutions 3` ``) on the scene's load: `None` where it holds the load's
/// whole period.
pub fn window_warning_for(scene: &Scene, revolutions: u16, given: &str) -> Option<String> {
    window_for(scene, Some((revolutions, given.to_string()))).1
}

/// The window for the scene's load, `given` a window's revolutions and the words that set it
/// (else the default), and the WARNING where it does not hold the load's whole period.
fn window_for(scene: &Scene, given: Option<(u16, String)>) -> (WindowLength, Option<String>) {
    use drive_monitor::irregularity::MAX_WINDOW_REVS;
    let longest = f64::from(MAX_WINDOW_REVS);
    let orders = periodic_orders(scene);
    let period = drive_monitor::drive::period_revolutions(&orders);
    let held = period.filter(|&p| p <= u64::from(MAX_WINDOW_REVS));
    let (Some(&lowest), None) = (orders.first(), held) else {
        // A window holds the load's whole period (or there is no load cycle).
        let Some((n, what)) = given else {
            let n = held.map_or(1, |p| p as u16);
            return (WindowLength::Revolutions(n), None);
        };
        // A window set that is no whole number of load periods sees part of the load cycle
        // in each window, as the lowest order's did: said.
        let warning = held.filter(|&p| u64::from(n) % p != 0).map(|p| {
            format!(
                "WARNING: {what} is not a whole number of the load's period ({p} revolutions), \
                 so each δ window sees part of the load cycle: δ may be read low in it and the \
                 δ alarm may stay silent; a multiple of {p} holds it"
            )
        });
        return (WindowLength::Revolutions(n), warning);
    };
    // No window holds the load's whole period.
    // Six decimals, trailing zeros dropped: 0.333333, 1.414214, 0.5.
    let short = |o: f64| {
        let t = format!("{o:.6}");
        t.trim_end_matches('0').trim_end_matches('.').to_string()
    };
    let list = orders
        .iter()
        .map(|&o| short(o))
        .collect::<Vec<_>>()
        .join(", ");
    // One cycle of the lowest order, in revolutions: 2000, 3.333333.
    let cycle = 1.0 / lowest;
    let cycle_text = if (cycle - cycle.round()).abs() <= 1e-9 * cycle {
        format!("{cycle:.0}")
    } else {
        short(cycle)
    };
    let too_long = cycle > longest * (1.0 + 1e-9);
    let why = match period {
        Some(n) => format!(
            "the load's orders {list} repeat only every {n} revolutions, more than the longest \
             δ window ({MAX_WINDOW_REVS})"
        ),
        None if orders.len() == 1 && too_long => format!(
            "one cycle of the load's order {list} is {cycle_text} revolutions, more than the \
             longest δ window ({MAX_WINDOW_REVS})"
        ),
        None if orders.len() == 1 => format!(
            "the load's order {list} is no fraction with denominator ≤ {}, so no whole number \
             of revolutions holds a whole number of its cycles",
            drive_monitor::drive::MAX_DENOMINATOR
        ),
        None => format!(
            "the load's orders {list} have no common period (that needs each to be a fraction \
             with denominator ≤ {})",
            drive_monitor::drive::MAX_DENOMINATOR
        ),
    };
    // "one cycle of the lowest order 0.3 (3.333333 revolutions)", or "that cycle" where `why`
    // has said it.
    let of_cycle = if orders.len() == 1 && too_long {
        "that cycle".to_string()
    } else {
        format!(
            "one cycle of the lowest order {} ({cycle_text} revolutions)",
            short(lowest)
        )
    };
    let read_low = "so δ may be read low in it and the δ alarm may stay silent";
    if let Some((n, what)) = given {
        // One that holds at least a cycle of the lowest order is how the default's WARNING is
        // answered (not said again); a shorter one sees a part of even that cycle: said, with
        // how much it holds.
        let part = f64::from(n) * lowest;
        let warning = (part < 1.0 - 1e-4).then(|| {
            let way = if too_long {
                format!(
                    "the longest window, {MAX_WINDOW_REVS} revolutions, holds {:.3} of it",
                    longest * lowest
                )
            } else {
                format!("a window of at least {} revolutions holds it", cycle.ceil())
            };
            format!(
                "WARNING: {why}, so no δ window holds the load's whole cycle, and {what} holds \
                 only {part:.3} of {of_cycle}, {read_low}; {way}"
            )
        });
        return (WindowLength::Revolutions(n), warning);
    }
    // The default: one cycle of the lowest order where a window holds it, else the longest
    // window (or the nearest whole number of revolutions to that cycle); said.
    let (length, window) = match WindowLength::LoadOrder(lowest).revolutions() {
        Ok(w) => (
            WindowLength::LoadOrder(lowest),
            format!(
                "one cycle of the lowest order {} ({w} revolution{})",
                short(lowest),
                if w == 1 { "" } else { "s" }
            ),
        ),
        Err(_) if too_long => (
            WindowLength::Revolutions(MAX_WINDOW_REVS),
            format!(
                "the longest, {MAX_WINDOW_REVS} revolutions, which holds {:.3} of {of_cycle}",
                longest * lowest
            ),
        ),
        Err(_) => {
            let w = cycle.round().clamp(1.0, longest) as u16;
            (
                WindowLength::Revolutions(w),
                format!("{w} revolutions, the nearest to {of_cycle}"),
            )
        }
    };
    let way = if too_long {
        String::new()
    } else {
        "; `[monitor] window_revolutions` sets a longer window".to_string()
    };
    let warning = format!(
        "WARNING: {why}, so no δ window holds the load's whole cycle: the default window is \
         {window}; it sees only part of the load cycle, {read_low}{way}"
    );
    (length, Some(warning))
}

/// The core's monitor for the scene's encoder.
fn core_monitor(scene: &Scene, file: &Path) -> Result<Option<DeltaMonitor<MAX_LINES>>, SceneError> {
    let Some(enc) = core_encoder(scene, file)? else {
        return Ok(None);
    };
    let m = scene.monitor.clone().unwrap_or_default();
    let alarm = m.delta_limit.map(|l| AlarmConfig::new(l as f32));
    DeltaMonitor::new(enc, window_config(scene), alarm)
        .map(Some)
        .map_err(|er| core_error(scene, file, "monitor", er))
}

/// The simulator's encoder for the scene: the same wheel as the core's (one description, the
/// teeth of [`crate::app::check::wheel`]), the index channel of an index disc, the scene's
/// errors and faults, and with `capture` the falling edges of every pulse.
fn sim_encoder(scene: &Scene, file: &Path, capture: bool) -> Result<SimEncoder, SceneError> {
    let Some(e) = &scene.encoder else {
        // Without an encoder table the simulation still needs one to advance; use a coarse one
        // whose edges are ignored.
        return Ok(SimEncoder::ideal(4, 1e6));
    };
    let w = crate::app::check::wheel(e, &scene.checker(file))?;
    let mut c = SimEncoder::ideal(u32::from(w.lines), e.timer_hz);
    match w.framing {
        FramingSpec::Index => c.reference = Reference::Index,
        FramingSpec::None => {}
        FramingSpec::MissingTooth | FramingSpec::Pattern => {
            c.teeth = Some(w.teeth.iter().map(|&t| u32::from(t)).collect());
        }
    }
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
    if let Some(g) = e.glitch_window {
        c.glitch_window = g;
    }
    if capture {
        c.duty = Some(scene.capture.unwrap_or_default().duty);
    }
    c.seed = scene.simulation.seed;
    // Dropped edges reach the collector as ground truth; it passes them on to nothing else.
    c.emit_dropped = true;
    crate::engine::encoder::Encoder::new(c.clone())
        .map_err(|er| core_error(scene, file, "encoder", er))?;
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

/// Shaft rotation between two samples of the simulated support reactions, rad (0.25°): a
/// rotating load's peak is then missed by at most 1 − cos(0.125°) ≈ 2.4e-6 of it.
pub const REACTION_ANGLE: f64 = 0.25 * std::f64::consts::PI / 180.0;

/// Most encoder edges one run may produce (about a minute of work in release).
pub const MAX_EDGES: f64 = 2e8;
/// Most integrator steps one run may take.
pub const MAX_STEPS: u64 = 50_000_000;

/// Where `drive-sim run --capture` writes the encoder signal.
#[derive(Debug, Clone, PartialEq)]
pub struct CaptureTarget {
    /// The capture file.
    pub path: std::path::PathBuf,
    /// Its format.
    pub format: CaptureFormat,
}

/// How a run is carried out (not what it simulates).
#[derive(Debug, Clone)]
pub struct RunOptions {
    /// Show a progress bar on stderr once the run has taken a second (never when stderr is
    /// not a terminal).
    pub progress: bool,
    /// Keep every δ window ([`RunReport::window_list`], for plots). Without it a run keeps only
    /// δ and the noise floor of the counted windows (for their medians), 8 bytes per window.
    pub keep_windows: bool,
    /// Write the encoder signal as a logic analyzer records it ([`crate::app::logic`]): the
    /// scene's `[capture]` settings, every edge (both of every pulse, noise pulses; not the
    /// dropped ones), the index on a second channel.
    pub capture: Option<CaptureTarget>,
    /// Keep every edge the encoder produced, dropped ones included, in
    /// [`RunReport::edge_list`] (the ground truth of a test; memory grows with the run).
    pub keep_edges: bool,
    /// The largest capture file a run writes, bytes: a sigrok file of every sample estimated
    /// larger is refused before anything is simulated ([`CAPTURE_MAX_BYTES`] by default).
    pub capture_max_bytes: f64,
}

/// The largest capture file `run` writes unasked, bytes (`--capture-max-bytes` raises it):
/// the kneader's 30 s as sigrok rows at 50 MHz had written 23.4 GB without a word.
pub const CAPTURE_MAX_BYTES: f64 = 1e9;

impl Default for RunOptions {
    fn default() -> Self {
        RunOptions {
            progress: false,
            keep_windows: true,
            capture: None,
            keep_edges: false,
            capture_max_bytes: CAPTURE_MAX_BYTES,
        }
    }
}

/// Why a run stopped before its duration.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Stop {
    Edges,
    Steps,
    Capture,
}

/// The regime classification's reductions over the run, kept as the samples arrive so that
/// memory does not grow with the duration: the same numbers
/// [`crate::engine::vibration::classify`] computes from the whole list of samples.
struct RegimeStream {
    first: Option<RegimeSample>,
    last: Option<RegimeSample>,
    /// Samples whose membership of the judged final part is decided only by the last sample's
    /// time (those near `window_fraction` of the way).
    undecided: Vec<RegimeSample>,
    /// Earliest time that certainly lies in the judged part, and the reductions from it on.
    sure_from: f64,
    sure_first: Option<RegimeSample>,
    residual_max: f64,
    residual_min: f64,
    coherence_min: f64,
    /// Earliest time that may lie in the judged part.
    maybe_from: f64,
    /// The judged part's least and largest residual samples in each eighth of it from
    /// `sure_from` to `end` (whether the residual's swing is steady: `classify` looks at
    /// quarters, each of which holds an eighth whole).
    parts: [Option<(RegimeSample, RegimeSample)>; 8],
    end: f64,
}

impl RegimeStream {
    /// For a run of `duration` s sampled every `every` s, judged over its final
    /// `window_fraction`.
    fn new(duration: f64, every: f64, window_fraction: f64) -> Self {
        // The last sample lies in (duration − 2·every, duration]; the judged part starts at
        // (1 − window_fraction) of the last sample's time.
        let keep = 1.0 - window_fraction;
        RegimeStream {
            first: None,
            last: None,
            undecided: Vec::new(),
            sure_from: keep * duration,
            sure_first: None,
            residual_max: 0.0,
            residual_min: f64::INFINITY,
            coherence_min: 1.0,
            maybe_from: keep * (duration - 2.0 * every),
            parts: [None; 8],
            end: duration,
        }
    }

    fn push(&mut self, s: RegimeSample) {
        if self.first.is_none() {
            self.first = Some(s);
        }
        if s.t > self.sure_from {
            if self.sure_first.is_none() {
                self.sure_first = Some(s);
            }
            self.residual_max = self.residual_max.max(s.residual);
            self.residual_min = self.residual_min.min(s.residual);
            self.coherence_min = self.coherence_min.min(s.coherence);
            let at = (s.t - self.sure_from) / (self.end - self.sure_from) * 8.0;
            let part = &mut self.parts[(at.max(0.0) as usize).min(7)];
            *part = Some(match *part {
                None => (s, s),
                Some((lo, hi)) => (
                    if s.residual < lo.residual { s } else { lo },
                    if s.residual > hi.residual { s } else { hi },
                ),
            });
        } else if s.t >= self.maybe_from {
            self.undecided.push(s);
        }
        self.last = Some(s);
    }

    /// The samples `classify` needs, in time order: the first (the initial residual), every
    /// sample that may begin the judged part, two stand-ins for the part certainly judged (its
    /// first sample, with that part's largest and with its smallest residual, and its smallest
    /// coherence: `classify` only folds those) and the last.
    fn samples(&self) -> Vec<RegimeSample> {
        let (Some(first), Some(last)) = (self.first, self.last) else {
            return Vec::new();
        };
        let mut out = vec![first];
        out.extend(self.undecided.iter().copied().filter(|s| s.t > first.t));
        if let Some(s) = self.sure_first.filter(|s| s.t > first.t) {
            for residual in [self.residual_max, self.residual_min] {
                out.push(RegimeSample {
                    residual,
                    coherence: self.coherence_min,
                    ..s
                });
            }
            // Each eighth's extremes where they were, for the steadiness of the swing.
            let sure = out.len();
            for &(lo, hi) in self.parts.iter().flatten() {
                out.extend([lo, hi].into_iter().filter(|x| x.t > s.t));
            }
            out[sure..].sort_by(|a, b| a.t.total_cmp(&b.t));
        }
        if out.last().is_some_and(|s| last.t > s.t) {
            out.push(last);
        }
        out
    }
}

/// What the run keeps of the vibration machine's motion.
enum Samples {
    /// Every sample (the capture analysis of loads started together needs the whole run).
    All(Vec<RegimeSample>),
    /// Only the regime classification's reductions.
    Stream(Box<RegimeStream>),
}

struct Collector<'a> {
    monitor: Option<DeltaMonitor<MAX_LINES>>,
    capture: Option<CaptureWriter<std::io::BufWriter<std::fs::File>>>,
    capture_error: Option<std::io::Error>,
    edge_list: Option<Vec<crate::engine::encoder::Edge>>,
    keep_windows: bool,
    windows: Vec<WindowOut>,
    /// δ and noise floor of the counted windows (valid, steady, after `settle`).
    counted: Vec<(f32, f32)>,
    settle: f64,
    window_count: u32,
    invalid_reasons: BTreeMap<&'static str, u32>,
    alarms: Vec<AlarmOut>,
    judged: AlarmJudged,
    trace: Vec<(f64, f64)>,
    trace_every: u64,
    /// The capture's input prescaler (one capture in this many line edges) and the edges it
    /// has counted since its last capture.
    prescaler: u32,
    prescaled: u32,
    /// Edges captured and fed to the core.
    edges: u64,
    all_edges: u64,
    reverse_edges: u64,
    /// The firmware's periodic standstill check, as `analyze` makes it
    /// ([`crate::app::analyze::poll_interval`]): its interval and the core's timeout, s, the
    /// timer's rate, Hz, and counter mask (`None` without a monitor).
    poll: Option<(f64, f64, f64, u64)>,
    /// The last event fed to the core (a capture or an index pulse) and the last poll, s.
    last_event: Option<f64>,
    last_poll: f64,
    /// When the shaft first turned backwards (a line edge in reverse), s, with or without a
    /// scene `[encoder]` (the run's internal one sees it too).
    reversed_at: Option<f64>,
    steps: u64,
    stop: Option<Stop>,
    last_window: Option<Measurement>,
    /// Mean speed of every valid window, in order: the history the regime tracker is fed.
    window_speeds: Vec<f32>,
    vibration: Option<(&'a VibrationMachine, std::ops::Range<usize>)>,
    samples: Samples,
    sample_every: f64,
    next_sample: f64,
    rotor: Option<RotorLoads>,
    /// The largest simulated reaction at each support, and when.
    reactions: [(f64, f64); 2],
    /// The shaft angle the reactions were sampled over, rad.
    reactions_turned: f64,
    /// The valid window whose ω max is the fastest, and when it ended.
    fastest_window: Option<(Measurement, f64)>,
    state: Vec<f64>,
    progress: Progress,
}

/// A progress bar over simulated time that appears once the run has taken a second.
struct Progress {
    bar: indicatif::ProgressBar,
    show: bool,
    shown: bool,
    started: Instant,
}

impl Progress {
    fn new(duration: f64, show: bool) -> Self {
        // Hidden until the run has taken a second; a hidden bar has no length of its own.
        let len = (duration * 1e3) as usize;
        let bar = crate::app::progress::progress_bar(len, "ms simulated", false);
        bar.set_length(len as u64);
        Progress {
            bar,
            show,
            shown: false,
            started: Instant::now(),
        }
    }

    fn at(&mut self, t: f64) {
        if !self.show {
            return;
        }
        if !self.shown && self.started.elapsed().as_secs_f64() > 1.0 {
            self.bar
                .set_draw_target(indicatif::ProgressDrawTarget::stderr());
            self.shown = true;
        }
        if self.shown {
            self.bar.set_position((t * 1e3) as u64);
        }
    }
}

impl Drop for Progress {
    fn drop(&mut self) {
        self.bar.finish_and_clear();
    }
}

impl Collector<'_> {
    /// The core's periodic standstill check up to `t` (s, exclusive) since the last event, as
    /// firmware's periodic task and `analyze` make it: only the polls around the timeout,
    /// where one can find something. Without it a shaft that stopped left its window in
    /// progress unjudged and no timeout, where `analyze` of the run's capture found them.
    fn polls_until(&mut self, t: f64) {
        let (Some((every, timeout, hz, mask)), Some(t0)) = (self.poll, self.last_event) else {
            return;
        };
        let mut p = self.last_poll.max(t0 + timeout - 2.0 * every).max(t0) + every;
        while p < t && p <= t0 + timeout + 2.0 * every {
            self.last_poll = p;
            self.poll_at(p, hz, mask);
            p += every;
        }
    }

    /// One poll of the core at `p`, s.
    fn poll_at(&mut self, p: f64, hz: f64, mask: u64) {
        // A real timer latches the count of whole ticks elapsed.
        let ticks = ((p * hz).floor() as i64 as u64 & mask) as u32;
        if let Some(o) = self.monitor.as_mut().and_then(|m| m.poll(ticks)) {
            self.outcome(p, o);
        }
    }

    /// The end of the run at `end`, s: the polls up to it and one there.
    fn polls_to_end(&mut self, end: f64) {
        self.polls_until(end);
        if let (Some((_, _, hz, mask)), Some(_)) = (self.poll, self.last_event) {
            self.poll_at(end, hz, mask);
        }
    }

    /// A window the core returned at time `t`, s, and its alarm event.
    fn outcome(&mut self, t: f64, o: drive_monitor::monitor::WindowOutcome) {
        self.window(t, o.report);
        let j = &mut self.judged;
        match o.verdict {
            Some(Verdict::Over) => {
                j.counted += 1;
                j.over += 1;
            }
            Some(Verdict::Within) => j.counted += 1,
            Some(Verdict::FloorNearLimit) => j.floor_near_limit += 1,
            Some(Verdict::Unsteady) => j.unsteady += 1,
            Some(Verdict::Invalid) => j.invalid += 1,
            None => {}
        }
        if let Some(e) = o.event {
            self.alarms.push(AlarmOut {
                time: t,
                event: match e {
                    AlarmEvent::Raised => "raised",
                    AlarmEvent::Cleared => "cleared",
                },
            });
        }
    }

    fn window(&mut self, time: f64, report: WindowReport) {
        self.window_count += 1;
        let m = report.measurement().copied();
        let w = WindowOut {
            time,
            delta: m.map_or(0.0, |m| f64::from(m.delta)),
            omega_mean: m.map_or(0.0, |m| f64::from(m.omega_mean)),
            noise_floor: m.map_or(0.0, |m| f64::from(m.noise_floor)),
            valid: report.valid(),
            steady: m.is_some_and(|m| m.steady),
            fault: report.fault().map(fault_name),
        };
        if !w.valid {
            *self
                .invalid_reasons
                .entry(w.fault.unwrap_or("unknown"))
                .or_default() += 1;
        }
        if let Some(r) = m {
            if r.steady && w.time >= self.settle {
                self.counted.push((r.delta, r.noise_floor));
            }
            self.last_window = Some(r);
            if w.valid
                && self
                    .fastest_window
                    .is_none_or(|(f, _)| r.omega_max > f.omega_max)
            {
                self.fastest_window = Some((r, w.time));
            }
            self.window_speeds.push(r.omega_mean);
        }
        if self.keep_windows {
            self.windows.push(w);
        }
    }
}

impl Observer for Collector<'_> {
    fn edge(&mut self, edge: &crate::engine::encoder::Edge) {
        if let Some(list) = &mut self.edge_list {
            list.push(*edge);
        }
        if edge.dropped {
            return;
        }
        if let Some(w) = &mut self.capture {
            if let Err(e) = w.edge(edge) {
                self.capture_error = Some(e);
                self.capture = None;
            }
        }
        self.all_edges += 1;
        // The capture unit is set to the rising edges.
        if !edge.rising {
            return;
        }
        if !edge.index
            && edge.direction == crate::engine::encoder::Direction::Reverse
            && self.reversed_at.is_none()
        {
            self.reversed_at = Some(edge.true_time);
        }
        if self.monitor.is_none() {
            return;
        }
        if edge.index {
            self.polls_until(edge.seen_time);
            self.last_event = Some(edge.seen_time);
            if let Some(m) = self.monitor.as_mut() {
                m.on_index(edge.ticks);
            }
            return;
        }
        // The timer's input prescaler: one capture in `prescaler` line edges, the first at the
        // prescaler-th (a noise pulse's edge counts like any other).
        self.prescaled += 1;
        if self.prescaled < self.prescaler {
            return;
        }
        self.prescaled = 0;
        self.polls_until(edge.seen_time);
        self.last_event = Some(edge.seen_time);
        let Some(m) = self.monitor.as_mut() else {
            return;
        };
        self.edges += 1;
        if edge.direction == crate::engine::encoder::Direction::Reverse {
            self.reverse_edges += 1;
        }
        let outcome = m.on_edge(edge.ticks, Some(edge.direction));
        let speed = m.speed();
        if let Some(o) = outcome {
            self.outcome(edge.true_time, o);
        }
        // The trace starts with the first speed sample (0 before it is "no sample yet").
        if self.edges % self.trace_every == 0 && (speed > 0.0 || !self.trace.is_empty()) {
            self.trace.push((edge.true_time, speed as f64));
        }
    }

    fn step(&mut self, step: &StepView<'_>) {
        self.steps += 1;
        if let Some((vm, range)) = &self.vibration {
            while self.next_sample <= step.t1() {
                let t = self.next_sample.max(step.t0());
                step.state_into(t, &mut self.state);
                let shaft = step.shaft(t);
                let sample = vm.sample(t, shaft, &self.state[range.clone()]);
                match &mut self.samples {
                    Samples::All(v) => v.push(sample),
                    Samples::Stream(s) => s.push(sample),
                }
                self.next_sample += self.sample_every;
            }
        }
        if let Some(r) = &self.rotor {
            let (t0, t1) = (step.t0(), step.t1());
            {
                // A step can span many turns (a prescribed speed takes long steps): sample
                // the reactions every REACTION_ANGLE of shaft rotation, so that the peak of
                // the rotating load is not missed between step ends.
                let turned = (step.shaft(t1).phi - step.shaft(t0).phi).abs();
                self.reactions_turned += turned;
                let n = (turned / REACTION_ANGLE).ceil().clamp(1.0, 1e9) as u64;
                for i in 0..=n {
                    let t = if i == n {
                        t1
                    } else {
                        t0 + (t1 - t0) * (i as f64 / n as f64)
                    };
                    let f = r.reactions(step.shaft(t));
                    for (peak, v) in self.reactions.iter_mut().zip(f) {
                        let load = v[0].hypot(v[1]);
                        if load > peak.0 {
                            *peak = (load, t);
                        }
                    }
                }
            }
        }
        if self.capture_error.is_some() {
            self.stop = Some(Stop::Capture);
        } else if self.all_edges as f64 > MAX_EDGES {
            self.stop = Some(Stop::Edges);
        } else if self.steps > MAX_STEPS {
            self.stop = Some(Stop::Steps);
        }
        self.progress.at(step.t1());
    }

    fn proceed(&self) -> bool {
        self.stop.is_none()
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

/// The machine a run simulates: the system and what the report needs to know of it.
struct Assembly {
    system: System,
    /// How the shaft moves ([`RunReport::shaft`]).
    law: &'static str,
    names: Vec<&'static str>,
    vib_params: Option<VibrationMachineParams>,
    vib_machine: Option<VibrationMachine>,
    rotor: Option<RotorLoads>,
}

/// The shaft of `scene`: a prescribed law (the override's or the scene's speed, or its ramp),
/// or a dynamic shaft driven by the motor, whose effect is appended to `effects`.
fn shaft_model(
    scene: &Scene,
    file: &Path,
    model: Option<&predict::DriveParts>,
    over: Overrides,
    effects: &mut Vec<Box<dyn Effect>>,
    names: &mut Vec<&'static str>,
) -> Result<ShaftModel, SceneError> {
    if let Some(profile) = speed_profile(scene, over) {
        // A prescribed shaft, not an effect: `names` lists the effects only.
        return Ok(ShaftModel::Profile(profile));
    }
    let prescribed = over.speed.or(match &scene.motor {
        Some(MotorSpec::Speed { speed }) => Some(*speed),
        _ => None,
    });
    match (prescribed, &scene.motor) {
        (Some(omega), _) => Ok(ShaftModel::Prescribed(SpeedLaw::Constant {
            omega,
            phi0: 0.0,
        })),
        (None, Some(MotorSpec::Ramp { from, to, duration })) => {
            Ok(ShaftModel::Prescribed(SpeedLaw::RampTo {
                omega0: *from,
                omega1: *to,
                ramp_time: *duration,
                phi0: 0.0,
            }))
        }
        (None, Some(_)) => {
            let Some(model) = model else {
                return Err(SceneError::value(
                    file,
                    "load",
                    "missing: a motor-driven scene needs [load]",
                ));
            };
            let shaft = scene.shaft.as_ref().ok_or_else(|| {
                SceneError::value(file, "shaft", "missing: a motor-driven scene needs [shaft]")
            })?;
            effects.push(Box::new(model.motor));
            names.push("motor");
            // Start at the predicted mean speed (or the given one) to shorten the transient.
            let omega0 = shaft
                .initial_speed
                .unwrap_or_else(|| model.u_start.max(0.0).sqrt());
            // A default start at the drive model's mean speed is where a speed carries the
            // load; a given start, or none carrying it, is checked.
            let checked = shaft.initial_speed.is_some() || model.u_start <= 0.0;
            if let Some(why) = driven_backwards(scene, &model.motor, omega0).filter(|_| checked) {
                return Err(scene.checker(file).bad(
                    "load.mean",
                    scene.load.as_ref().map_or(0.0, |l| l.mean),
                    why,
                ));
            }
            Ok(ShaftModel::Dynamic(DynamicShaft {
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
            }))
        }
        (None, None) => Err(SceneError::value(
            file,
            "motor",
            "missing: a scene to run needs [motor] (a torque model or a prescribed speed)",
        )),
    }
}

/// Why a motor-driven shaft started at `omega0` rad/s would be driven backwards (`None` where
/// it would not, to the mean load): the mean load is at least the motor's torque at standstill
/// and the motor's torque stays below it at every speed from standstill up to the start, so
/// the shaft slows to a stop and the load, an active torque (its sign whatever the speed),
/// turns it backwards ever faster. `run` does not simulate that: the parabola continued to
/// negative speeds falls without bound and the speed runs away in finite time (the kneader at
/// a mean load of 200 N·m, started at 130 rad/s, failed at 1.83 s with a step size underflow
/// that named the inertias), and the Kloss curve's braking branch leaves the load's excess to
/// accelerate the shaft backwards without limit (22 M reverse edges in 10 s, reported as a
/// standstill). The same for every motor kind, with or without an `[encoder]`.
pub fn driven_backwards(
    scene: &Scene,
    motor: &drive_monitor::drive::Motor,
    omega0: f64,
) -> Option<String> {
    let mean = scene.load.as_ref().map_or(0.0, |l| l.mean);
    let standstill = motor.torque(0.0);
    if mean.partial_cmp(&standstill) == Some(std::cmp::Ordering::Less) || mean.is_nan() {
        return None;
    }
    // The motor's torque over [0, ω0] (smooth and single-peaked: 4096 points find where it
    // reaches the load).
    const POINTS: u32 = 4096;
    let grid = |top: f64| (0..=POINTS).map(move |i| top * f64::from(i) / f64::from(POINTS));
    if grid(omega0.max(0.0)).any(|w| motor.torque(w) > mean) {
        return None;
    }
    // The lowest speed where the motor's torque exceeds the mean load, up to its no-load
    // (synchronous) speed: a start above it reaches the working point.
    let top = motor
        .kloss_curve()
        .map_or(motor.model().no_load_speed(), |k| k.synchronous_speed());
    let above = grid(top).find(|&w| motor.torque(w) > mean);
    let given = scene.shaft.as_ref().and_then(|s| s.initial_speed);
    let start_text = match given {
        _ if omega0 <= 0.0 => format!(
            "the shaft starts at rest ({}), where the motor's torque is below it",
            if given.is_some() {
                "`shaft.initial_speed = 0`"
            } else {
                "no `shaft.initial_speed`, and no speed of the drive model carries the load"
            }
        ),
        Some(w) => format!(
            "from `shaft.initial_speed = {w}` rad/s down to standstill the motor's torque stays \
             below it: the shaft would slow to a stop"
        ),
        None => format!(
            "from the start at {omega0:.3} rad/s (the drive model's mean speed) down to \
             standstill the motor's torque stays below it: the shaft would slow to a stop"
        ),
    };
    let cure = match above {
        // Rounded up: the start is above the point.
        Some(w) => format!(
            "a mean load below {standstill:.4} N·m runs, and a start above {:.3} rad/s \
             (`shaft.initial_speed`), where the motor's torque first exceeds the mean load, can \
             reach the motor's working point (the load's ripple may still turn it back, which \
             the run then says)",
            (w * 1e3).ceil() / 1e3
        ),
        None => format!(
            "no speed of the motor carries it (its torque peaks at {:.4} N·m): a mean load \
             below {standstill:.4} N·m, or a stronger motor, runs",
            grid(top)
                .map(|w| motor.torque(w))
                .fold(f64::NEG_INFINITY, f64::max)
        ),
    };
    Some(format!(
        "the mean load {mean} N·m is at least the motor's torque at standstill ({standstill:.4} \
         N·m), and {start_text}, and the load, modelled as an active torque (its sign whatever \
         the speed, as a hoist's weight), would turn it backwards ever faster, which `run` does \
         not simulate (a reactive load, friction or kneading, would stall it \
         instead; `drive-sim predict` shows the drive); {cure}"
    ))
}

/// The speed profile of a scene whose prescribed speed is a profile (`[motor] model =
/// "profile"`) or carries a cranking ripple (`[cranking]`); `None` otherwise.
fn speed_profile(scene: &Scene, over: Overrides) -> Option<SpeedProfile> {
    let mean = match (over.speed, &scene.motor) {
        (Some(w), _) if scene.cranking.is_some() => vec![(0.0, w)],
        (Some(_), _) => return None,
        (None, Some(MotorSpec::Profile { points })) => {
            points.iter().map(|p| (p[0], p[1])).collect()
        }
        (None, Some(MotorSpec::Speed { speed })) if scene.cranking.is_some() => {
            vec![(0.0, *speed)]
        }
        (None, Some(MotorSpec::Ramp { from, to, duration })) if scene.cranking.is_some() => {
            vec![(0.0, *from), (*duration, *to)]
        }
        _ => return None,
    };
    Some(SpeedProfile {
        mean,
        ripple: scene.cranking.map(|c| Ripple {
            amplitude: c.ripple,
            strokes: c.strokes,
            phase: c.phase,
        }),
    })
}

/// The system of `scene`: its shaft and the effects it calls for, in assembly order (motor,
/// load, vibration machine, rotor loads).
fn assemble(
    scene: &Scene,
    file: &Path,
    model: Option<&predict::DriveParts>,
    over: Overrides,
) -> Result<Assembly, SceneError> {
    let mut effects: Vec<Box<dyn Effect>> = Vec::new();
    let mut names = Vec::new();
    let shaft = shaft_model(scene, file, model, over, &mut effects, &mut names)?;
    if let (Some(model), true) = (model, matches!(shaft, ShaftModel::Dynamic(_))) {
        effects.push(Box::new(model.load.clone()));
        names.push("load");
    }
    let law = match &shaft {
        ShaftModel::Dynamic(_) => "motor-driven",
        ShaftModel::Profile(p) if p.ripple.is_some_and(|r| r.amplitude > 0.0) => {
            "prescribed with a cranking ripple"
        }
        _ => "prescribed",
    };
    let rotor_speed0 = match &shaft {
        ShaftModel::Prescribed(law) => law.shaft(0.0).omega,
        ShaftModel::Dynamic(d) => d.omega0,
        ShaftModel::Profile(p) => p.omega(0.0, 0.0),
    };
    let vib_params = vibration_params(scene, over.loads_together, rotor_speed0);
    let vib_machine = match &vib_params {
        Some(p) => {
            Some(VibrationMachine::new(p).map_err(|e| core_error(scene, file, "autobalancer", e))?)
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
    let system = System::new(shaft, effects).map_err(|e| core_error(scene, file, "shaft", e))?;
    Ok(Assembly {
        system,
        law,
        names,
        vib_params,
        vib_machine,
        rotor,
    })
}

/// The largest shaft speed the run can reach, rad/s, as far as the scene tells before it is
/// simulated: the prescribed speeds, or for a motor its no-load (synchronous) speed, twice
/// over for the transient, or the initial speed.
fn speed_bound(scene: &Scene, over: Overrides) -> f64 {
    let initial = scene
        .shaft
        .as_ref()
        .and_then(|s| s.initial_speed)
        .unwrap_or(0.0)
        .abs();
    let motor = match &scene.motor {
        _ if over.speed.is_some() => over.speed.unwrap_or(0.0).abs(),
        Some(
            m @ (MotorSpec::Speed { .. } | MotorSpec::Ramp { .. } | MotorSpec::Profile { .. }),
        ) => m.prescribed_top().unwrap_or(0.0),
        Some(MotorSpec::Parabola { no_load_speed, .. }) => 2.0 * no_load_speed,
        Some(MotorSpec::Kloss {
            synchronous_speed, ..
        }) => 2.0 * synchronous_speed,
        None => 0.0,
    };
    let ripple = scene.cranking.map_or(0.0, |c| c.ripple);
    motor.max(initial) * (1.0 + ripple)
}

/// The shaft speed beyond which an unresolved fixed step is taken as diverging, rad/s
/// ([`Simulation::with_speed_limit`]): ten times [`speed_bound`], and at least 100 rad/s.
/// A diverging RK4 step goes far beyond it at once (the kneader at `step = 2`: from 197 to
/// about 2e8 rad/s in one step), and a resolved step is never stopped by it.
fn divergence_speed(scene: &Scene, over: Overrides) -> f64 {
    (10.0 * speed_bound(scene, over)).max(100.0)
}

/// A fixed step that would not diverge where `step` (s) did, from the system's fastest
/// linearised rate there (1/s): half of its time scale 1/rate (RK4 is stable on it up to about
/// 2.8 of it), and at most half of `step`; two significant digits, rounded down.
fn suggested_step(step: f64, rate: Option<f64>) -> f64 {
    let h = rate
        .filter(|r| r.is_finite() && *r > 0.0)
        .map_or(step / 10.0, |r| 0.5 / r)
        .min(step / 2.0);
    let unit = 10f64.powf(h.log10().floor() - 1.0);
    (h / unit).floor() * unit
}

/// Refuses, before anything is simulated, a run that would produce more than [`MAX_EDGES`]
/// edges or take more than [`MAX_STEPS`] integrator steps of the largest size allowed.
fn check_work(
    scene: &Scene,
    file: &Path,
    over: Overrides,
    integ: &Integrator,
) -> Result<(), SceneError> {
    let c = scene.checker(file);
    let duration = scene.simulation.duration;
    let speed_key = match (&scene.motor, over.speed) {
        (_, Some(_)) => "the sweep's speed",
        (Some(MotorSpec::Speed { .. }), _) => "motor.speed",
        (Some(MotorSpec::Ramp { .. }), _) => "motor.from/to",
        (Some(MotorSpec::Profile { .. }), _) => "motor.points",
        (Some(MotorSpec::Parabola { .. }), _) => "motor.no_load_speed",
        (Some(MotorSpec::Kloss { .. }), _) => "motor.synchronous_speed",
        (None, _) => "motor",
    };
    if let Some(e) = &scene.encoder {
        let edges =
            speed_bound(scene, over) * duration / std::f64::consts::TAU * f64::from(e.grid_lines());
        if edges > MAX_EDGES {
            return Err(c.bad(
                "simulation.duration",
                duration,
                format!(
                    "with {speed_key} and encoder.lines = {} the run would produce about {edges:.2e} edges, \
                     more than the limit of {MAX_EDGES:.0e} (shorten the duration)",
                    c.shown("encoder.lines", e.grid_lines())
                ),
            ));
        }
    }
    let (largest_step, key) = match integ {
        Integrator::Rk4 { step } => (*step, "simulation.step"),
        Integrator::Dopri5 { max_step, .. } | Integrator::Dop853 { max_step, .. } => {
            (max_step.unwrap_or(f64::INFINITY), "simulation.step (× 100)")
        }
    };
    let steps = duration / largest_step;
    if steps > MAX_STEPS as f64 {
        return Err(c.bad(
            "simulation.duration",
            duration,
            format!(
                "needs at least {steps:.2e} integrator steps of {key}, more than the limit of {MAX_STEPS}"
            ),
        ));
    }
    Ok(())
}

/// Simulates `scene` and reports, keeping every window and without a progress bar.
pub fn run(scene: &Scene, file: &Path, over: Overrides) -> Result<RunReport, SceneError> {
    run_with(scene, file, over, RunOptions::default())
}

/// Simulates `scene` and reports. The work is bounded up front ([`MAX_EDGES`], [`MAX_STEPS`],
/// checked again while running); memory grows with the duration only by what `options`
/// keeps for plots and by 8 bytes per counted δ window.
pub fn run_with(
    scene: &Scene,
    file: &Path,
    over: Overrides,
    options: RunOptions,
) -> Result<RunReport, SceneError> {
    let started = Instant::now();
    let model = predict::drive_model(scene, file)?;
    let parts = predict::drive_parts(scene, file, model.as_ref())?;
    let Assembly {
        system,
        law,
        names,
        vib_params,
        vib_machine,
        rotor,
    } = assemble(scene, file, parts.as_ref(), over)?;
    let vib_range = names
        .iter()
        .position(|n| *n == "vibration")
        .map(|k| system.effect_range(k));
    let dim = system.dim();
    let integ = integrator(scene);
    integ
        .validate()
        .map_err(|e| core_error(scene, file, "simulation", e))?;
    check_work(scene, file, over, &integ)?;
    let encoder = sim_encoder(scene, file, options.capture.is_some())?;
    if options.capture.is_some() {
        check_capture(
            scene,
            file,
            over,
            &encoder,
            parts.as_ref().map(|p| p.u_start),
        )?;
    }
    let mut sim = Simulation::new(system, integ.clone(), encoder)
        .map_err(|e| SceneError::value(file, "simulation", e.to_string()))?;
    if matches!(integ, Integrator::Rk4 { .. }) {
        sim = sim.with_speed_limit(divergence_speed(scene, over));
    }
    let duration = scene.simulation.duration;
    let settle = scene.simulation.settle.unwrap_or(duration / 3.0);
    let lines = scene
        .encoder
        .as_ref()
        .map_or(1, |e| u64::from(e.grid_lines()));
    let prescaler = scene
        .encoder
        .as_ref()
        .map_or(1, |e| u32::from(e.prescaler.max(1)));
    let expected_edges = parts
        .as_ref()
        .map_or(1e3, |m| m.u_start.max(1.0).sqrt())
        .max(over.speed.unwrap_or(0.0))
        * duration
        / std::f64::consts::TAU
        * lines as f64
        / f64::from(prescaler);
    // 4000 samples a run, and at least 100 a second (a capture's slip beats need them).
    let sample_every = (duration / 4000.0).min(0.01);
    let together = vib_params
        .as_ref()
        .is_some_and(|p| matches!(p.initial.loads, LoadPlacement::Together { .. }));
    let capture = match &options.capture {
        Some(t) => Some(open_capture(scene, file, t, options.capture_max_bytes)?),
        None => None,
    };
    let monitor = core_monitor(scene, file)?;
    let poll = monitor.as_ref().zip(scene.encoder.as_ref()).map(|(m, e)| {
        let enc = m.encoder();
        (
            crate::app::analyze::poll_interval(enc),
            f64::from(enc.timeout_ticks()) / e.timer_hz,
            e.timer_hz,
            u64::from(enc.mask()),
        )
    });
    let mut col = Collector {
        monitor,
        poll,
        last_event: None,
        last_poll: f64::NEG_INFINITY,
        capture,
        capture_error: None,
        edge_list: options.keep_edges.then(Vec::new),
        keep_windows: options.keep_windows,
        windows: Vec::new(),
        counted: Vec::new(),
        settle,
        window_count: 0,
        invalid_reasons: BTreeMap::new(),
        alarms: Vec::new(),
        judged: AlarmJudged::default(),
        trace: Vec::new(),
        trace_every: ((expected_edges / 4000.0) as u64).max(1),
        prescaler,
        prescaled: 0,
        edges: 0,
        all_edges: 0,
        reverse_edges: 0,
        reversed_at: None,
        steps: 0,
        stop: None,
        last_window: None,
        window_speeds: Vec::new(),
        vibration: vib_machine.as_ref().zip(vib_range),
        samples: if together {
            Samples::All(Vec::new())
        } else {
            let fraction = RegimeCriteria::new(1.0).window_fraction;
            Samples::Stream(Box::new(RegimeStream::new(
                duration,
                sample_every,
                fraction,
            )))
        },
        sample_every,
        next_sample: 0.0,
        rotor,
        reactions: [(0.0, 0.0); 2],
        reactions_turned: 0.0,
        fastest_window: None,
        state: vec![0.0; dim],
        progress: Progress::new(duration, options.progress),
    };
    let stats = match sim.run_observed(duration, &mut col) {
        Ok(stats) => stats,
        Err(e) => return Err(integration_error(scene, file, &e, col.reversed_at)),
    };
    drop(std::mem::replace(
        &mut col.progress,
        Progress::new(0.0, false),
    ));
    if let Some(e) = col.capture_error.take() {
        let t = options
            .capture
            .as_ref()
            .map(|t| t.path.display().to_string());
        return Err(SceneError::value(
            file,
            "capture",
            format!("cannot write {}: {e}", t.unwrap_or_default()),
        ));
    }
    if let Some(stop) = col.stop {
        return Err(stopped(scene, file, stop, stats.time));
    }
    let mut capture_rows = None;
    let mut capture_channels = Vec::new();
    if let (Some(w), Some(t)) = (col.capture.take(), &options.capture) {
        let written = w.finish(stats.time).map_err(|e| {
            SceneError::value(
                file,
                "capture",
                format!("cannot write {}: {e}", t.path.display()),
            )
        })?;
        capture_rows = Some(written.rows);
        capture_channels = written.channels;
    }
    let capture_warning = capture_loss_warning(scene, file, &capture_channels);
    let step_warning = fixed_step_warning(scene, file, sim.fixed_step_error());
    let mut report = RunReport {
        scene: file.display().to_string(),
        shaft: law,
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
        // Without an [encoder] the simulation's internal coarse encoder is no scene's.
        edges: if scene.encoder.is_some() {
            stats.encoder.edges
        } else {
            0
        },
        line_edges: if scene.encoder.is_some() {
            stats.encoder.edges - stats.encoder.index_pulses
        } else {
            0
        },
        noise_pulses: stats.encoder.glitches,
        index_pulses: stats.encoder.index_pulses,
        settle,
        capture_file: options
            .capture
            .as_ref()
            .map(|t| t.path.display().to_string()),
        capture_rows,
        capture_channels,
        capture_warning,
        delta_limit: scene.monitor.as_ref().and_then(|m| m.delta_limit),
        not_simulated: not_simulated(scene, over),
        model_warnings: cranking_warning(scene)
            .into_iter()
            .chain(cranking_mean_note(scene))
            .chain(predict::phase_warning(scene))
            .chain(step_warning)
            .collect(),
        window_warning: scene.encoder.as_ref().and_then(|_| window_warning(scene)),
        ..Default::default()
    };
    if let Some(model) = model
        .as_ref()
        .filter(|_| predict::irregularity_not_predicted(scene).is_none())
    {
        let (delta, sampled) = predict::predicted_and_sampled(scene, file, model)?;
        report.delta_predicted = delta;
        report.delta_predicted_through_samples = sampled.map(|s| s.at_scene_phase);
        report.delta_predicted_through_samples_least = sampled.map(|s| s.least);
        report.delta_predicted_through_samples_most = sampled.map(|s| s.most);
    }
    report.cranking_ripple = cranking_ripple_read(scene, file)?;
    let samples = match std::mem::replace(&mut col.samples, Samples::All(Vec::new())) {
        Samples::All(v) => v,
        Samples::Stream(s) => s.samples(),
    };
    // The end of the run: a window held for the edge after its frame is released as it is,
    // and a second window the last edge ended (handed by the next call).
    col.polls_to_end(stats.time);
    while let Some(o) = col.monitor.as_mut().and_then(|m| m.release_held()) {
        col.outcome(stats.time, o);
    }
    measurement(&mut report, &mut col);
    // A motor-driven shaft the load turned backwards (its peak beyond the motor's torque at
    // standstill), said with or without an [encoder].
    if let (Some(t), "motor-driven") = (col.reversed_at, report.shaft) {
        report.model_warnings.extend(
            predict::active_load_note(scene, file)
                .map(|n| format!("{n} (this run: backwards first at t = {t:.4} s)")),
        );
    }
    // The vibration machine's torque is in the run (a motor-driven shaft integrates it) and
    // not in the prediction; the encoder's errors are in the measured δ and not its floor.
    let coupled = vib_machine.is_some() && over.speed.is_none();
    report.delta_notes = [
        report
            .delta_predicted
            .filter(|_| coupled)
            .map(|_| machine_torque_note()),
        report
            .delta_measured
            .and(scene.encoder.as_ref())
            .and_then(encoder_errors_note),
        report
            .delta_measured
            .and(model.as_ref())
            .filter(|_| over.speed.is_none())
            .and_then(|m| settle_note(m, settle, scene.simulation.settle.is_none())),
        report
            .cranking_ripple
            .filter(|_| report.delta_measured.is_some())
            .as_ref()
            .and_then(cranking_ripple_warning),
    ]
    .into_iter()
    .flatten()
    .collect();
    regime(
        scene,
        file,
        &mut report,
        vib_machine.as_ref(),
        &samples,
        &col.window_speeds,
    )?;
    report.capture = capture_analysis(scene, file, vib_params.as_ref(), &samples)?;
    supports(scene, file, &mut report, col.reactions)?;
    if let Some(s) = report.supports.as_mut() {
        // Less than a revolution: the unbalance's rotating load may not have come round to
        // the static load, where the reaction peaks (0.57 revolution of the auger read 3520 N
        // against the 3662 N it reaches).
        let revolutions = col.reactions_turned / std::f64::consts::TAU;
        s.reactions_note = (revolutions < 1.0).then(|| {
            format!(
                "NOTE: the simulated reactions cover {revolutions:.2} revolution, less than one: \
                 their peak may be missed (lengthen simulation.duration)"
            )
        });
    }
    report.alarms = col.alarms;
    report.alarm_judged = report.delta_limit.map(|l| AlarmJudged {
        floor_fraction: AlarmConfig::new(l as f32).floor_fraction,
        ..col.judged
    });
    report.window_list = col.windows;
    report.speed_trace = col.trace;
    report.edge_list = col.edge_list.take().unwrap_or_default();
    report.wall_seconds = started.elapsed().as_secs_f64();
    Ok(report)
}

/// The NOTE under `run`'s δ line when the windows counted after `settle` (s; `default`: a
/// third of the duration, not the scene's) may still carry the start's transient: the drive's
/// deviations from its steady state decay as e^(−t/τ), τ = J / (−∂M_d/∂ω) at the predicted
/// mean speed (the load's torque does not change with the speed), and `settle` is under 3τ
/// (5 % left). A heavy drive on a stiff-enough motor can take tens of seconds (J = 305 kg·m²
/// on a parabola motor: τ 17 s, and δ read 0.56 % high after a default settle of 3.5 s).
/// `None` without a steady state, or on a motor branch whose torque rises with the speed.
pub fn settle_note(
    model: &drive_monitor::drive::DriveModel,
    settle: f64,
    default: bool,
) -> Option<String> {
    model.predict().steady()?;
    let omega = model.u_mean().sqrt();
    let h = 1e-4 * omega;
    let motor = model.motor();
    // Central difference of the characteristic (the Kloss curve itself where it is one).
    let stiffness = (motor.torque(omega - h) - motor.torque(omega + h)) / (2.0 * h);
    let tau = model.total_inertia() / stiffness;
    if !(tau > 0.0 && tau.is_finite() && settle < 3.0 * tau) {
        return None;
    }
    let given = if default {
        "the default settle, a third of the duration,"
    } else {
        "simulation.settle ="
    };
    Some(format!(
        "NOTE: the drive's deviations from its steady state decay with a time constant of \
         {tau:.3} s (J / −∂M_d/∂ω at the mean speed {omega:.3} rad/s): the windows after \
         {given} {settle:.3} s still carry {:.0} % of the start's; a `simulation.settle` of 3τ = \
         {:.3} s leaves 5 % (with a duration beyond it)",
        100.0 * (-settle / tau).exp(),
        3.0 * tau
    ))
}

/// The WARNING under `run`'s δ line for a drive prediction beside a vibration machine whose
/// torque on the shaft the run integrates: the prediction leaves it out
/// ([`predict::machine_torque_warning`] says the same in `predict`).
pub fn machine_torque_note() -> String {
    "WARNING: the predicted δ is the drive's alone ([motor], [load], [shaft]): it leaves out \
     the torque the vibration machine ([[platform]], [autobalancer]) puts on the shaft, the \
     drag of the auto-balancer's loads and the moment of the rotor unbalance on the vibrating \
     platform, which this run integrates with the drive: the measured δ includes it, so where \
     the loads do not balance the difference from the prediction is that torque's, not the \
     drive model's error"
        .to_string()
}

/// The NOTE under `run`'s δ line when the scene's encoder has run-out, pitch error or jitter
/// (`None` without any): they displace the edges the core's speed samples are read from, so
/// the measured δ includes them, while the noise floor it quotes is the timer's quantization
/// alone (no bound on their share is computed).
pub fn encoder_errors_note(e: &crate::app::scene::EncoderSpec) -> Option<String> {
    let set: Vec<String> = [
        ("encoder.runout", e.runout, ""),
        ("encoder.pitch_error", e.pitch_error, " rad"),
        ("encoder.jitter", e.jitter, " s"),
    ]
    .into_iter()
    .filter(|&(_, x, _)| x > 0.0)
    .map(|(k, x, unit)| format!("{k} = {x:e}{unit}"))
    .collect();
    if set.is_empty() {
        return None;
    }
    Some(format!(
        "NOTE: the scene's encoder errors ({}) displace the edges the core reads its speed \
         samples from, so the measured δ includes them, while the noise floor quoted is the \
         timer's quantization alone; their share of δ is not computed, so a difference from \
         the prediction may be theirs, not the drive's (the scene without them measures the \
         drive alone)",
        set.join(", ")
    ))
}

/// The WARNING for a `[cranking]` ripple on a vibration machine's rotor (`None` without a
/// ripple or a machine): the machine's model leaves out every term in the shaft's angular
/// acceleration ω̇ (`host-sim/src/engine/vibration`), chief among them the rotor unbalance's
/// tangential force `D·ω̇·cos(φ + θ)` beside its centrifugal `D·ω²`. Under the ripple
/// `ω = ω̄·(1 + a·sin(s·φ + ψ))` at a steady mean `ω̄`, `ω̇ = ω·dω/dφ`, so
/// `ω̇/ω² = a·s·cos(s·φ + ψ)/(1 + a·sin(s·φ + ψ))`, whose largest magnitude, where
/// `sin = −a`, is `a·s/√(1 − a²)`: the ratio the warning gives (a changing mean speed adds its
/// own slope).
pub fn cranking_warning(scene: &Scene) -> Option<String> {
    let c = scene.cranking.filter(|c| c.ripple > 0.0)?;
    scene.autobalancer.as_ref()?;
    let ratio = c.ripple * c.strokes / (1.0 - c.ripple * c.ripple).sqrt();
    Some(format!(
        "WARNING: [cranking] (ripple = {}, strokes = {}) swings the rotor speed of the \
         vibration machine ([[platform]], [autobalancer]), whose model leaves out every term in \
         the shaft's angular acceleration ω̇: the rotor unbalance's tangential force \
         D·ω̇·cos(φ + θ) on the platform and, for balls and rollers, the loads' rolling coupling \
         to ω̇ with its reaction on the shaft. The ripple alone makes |ω̇| reach \
         ripple·strokes/√(1 − ripple²) = {ratio:.3} of ω² (at a steady mean speed), so that \
         force reaches {ratio:.3} of the centrifugal D·ω² at the same instant: the platform \
         motion, residual unbalance and regime simulated are the model's, not the machine's at \
         this ripple, and the regime table and the criterion, computed at a constant speed, do \
         not describe it",
        c.ripple, c.strokes
    ))
}

/// The tables a prescribed speed leaves out: the load torque and the shaft's inertia move
/// nothing when the speed is imposed (said, not dropped in silence).
fn not_simulated(scene: &Scene, over: Overrides) -> Vec<String> {
    let by = match (over.speed, &scene.motor) {
        (Some(w), _) => format!("the speed is prescribed ({w} rad/s for this run)"),
        (None, Some(MotorSpec::Speed { .. })) => "[motor] model = \"speed\"".to_string(),
        (None, Some(MotorSpec::Ramp { .. })) => "[motor] model = \"ramp\"".to_string(),
        (None, Some(MotorSpec::Profile { .. })) => "[motor] model = \"profile\"".to_string(),
        _ => return Vec::new(),
    };
    let by = if over.speed.is_some() {
        by
    } else {
        format!("the speed is prescribed ({by})")
    };
    let drive = "a \"parabola\" or \"kloss\" motor simulates the drive with it";
    let mut out = Vec::new();
    if scene.load.is_some() {
        let window = scene
            .monitor
            .as_ref()
            .and_then(|m| m.window_revolutions)
            .is_none();
        out.push(format!(
            "[load]: {by}, so its torque moves nothing{}; {drive}",
            if window {
                " (its harmonic orders still set the δ window: one load period)"
            } else {
                ""
            }
        ));
    }
    if scene.shaft.is_some() {
        out.push(format!(
            "[shaft]: {by}, so its inertia moves nothing; {drive}"
        ));
    }
    out
}

/// Samples a capture takes of the shortest level of the encoder signal at the least: with
/// fewer than one a level can fall between two samples and vanish from the file, and two keep
/// every level with a sample to spare for the run's speed swings and the edges' jitter.
pub const CAPTURE_SAMPLES_PER_LEVEL: f64 = 2.0;

/// A speed the shaft is sure to reach in the run, rad/s, and where the scene gives it: the
/// prescribed speed (the largest a ramp or a profile reaches within the duration; the mean of
/// a cranking ripple, whose peaks are faster), or the speed a motor-driven shaft starts at.
/// `u_start` is the drive model's mean ω², where a motor-driven shaft starts by default.
fn sure_speed(scene: &Scene, over: Overrides, u_start: Option<f64>) -> Option<(f64, String)> {
    let d = scene.simulation.duration;
    let (w, from) = match (&scene.motor, over.speed) {
        (_, Some(w)) => (w.abs(), "the sweep's speed".to_string()),
        (Some(MotorSpec::Speed { speed }), None) => (speed.abs(), "`motor.speed`".to_string()),
        (Some(MotorSpec::Ramp { from, to, duration }), None) => {
            let reached = from + (to - from) * (d / duration).min(1.0);
            (
                from.abs().max(reached.abs()),
                "the ramp of `motor.from` and `motor.to`".to_string(),
            )
        }
        (Some(MotorSpec::Profile { points }), None) => {
            // ω̄ is linear between the points: its largest within the run is at a point or
            // at an end.
            let profile = SpeedProfile {
                mean: points.iter().map(|p| (p[0], p[1])).collect(),
                ripple: None,
            };
            let inside = points
                .iter()
                .filter(|p| p[0] > 0.0 && p[0] < d)
                .map(|p| p[1]);
            let w = inside
                .chain([profile.mean_at(0.0), profile.mean_at(d)])
                .map(f64::abs)
                .fold(0.0, f64::max);
            (w, "`motor.points`".to_string())
        }
        (Some(MotorSpec::Parabola { .. } | MotorSpec::Kloss { .. }), None) => {
            match scene.shaft.as_ref().and_then(|s| s.initial_speed) {
                Some(w) => (
                    w.abs(),
                    "`shaft.initial_speed`, where the run starts".into(),
                ),
                None => (
                    u_start?.max(0.0).sqrt(),
                    "the drive model's mean speed, where the run starts".into(),
                ),
            }
        }
        (None, None) => return None,
    };
    (w.is_finite() && w > 0.0).then_some((w, from))
}

/// The shortest level of the encoder signal a capture records, as a shaft angle, rad, and
/// what it is: each channel's marks in turn round the disc (both edges of every pulse, with
/// the disc's pitch errors and run-out).
fn shortest_level(encoder: &SimEncoder) -> Option<(f64, &'static str)> {
    let e = crate::engine::encoder::Encoder::new(encoder.clone()).ok()?;
    let mut shortest: Option<(f64, &'static str)> = None;
    for index in [false, true] {
        let marks: Vec<_> = e.marks().iter().filter(|m| m.index == index).collect();
        for (i, m) in marks.iter().enumerate() {
            let next = marks
                .get(i + 1)
                .map_or(marks[0].angle + std::f64::consts::TAU, |n| n.angle);
            let what = match (index, m.rising) {
                (false, true) => "a tooth's pulse",
                (false, false) => "the low level between two teeth",
                (true, true) => "the index pulse",
                (true, false) => "the low level between index pulses",
            };
            let held = next - m.angle;
            if shortest.is_none_or(|(s, _)| held < s) {
                shortest = Some((held, what));
            }
        }
    }
    shortest
}

/// Refuses, before anything is simulated, a capture of a scene without `[encoder]` (there is no
/// signal to record: the run's internal encoder is no scene's), and one whose `[capture]
/// sample_rate` takes fewer than [`CAPTURE_SAMPLES_PER_LEVEL`] samples of the encoder signal's
/// shortest level at a speed the run is sure to reach ([`sure_speed`]): its pulses would fall
/// between samples and vanish from the file. (Faster speeds reached only as the run goes are
/// counted as the file is written: [`capture_loss_warning`].)
fn check_capture(
    scene: &Scene,
    file: &Path,
    over: Overrides,
    encoder: &SimEncoder,
    u_start: Option<f64>,
) -> Result<(), SceneError> {
    let Some(e) = &scene.encoder else {
        return Err(SceneError::value(
            file,
            "encoder",
            "missing: `--capture` records the encoder's signal, and the scene has no [encoder] \
             table",
        ));
    };
    let (Some((w, from)), Some((angle, what))) =
        (sure_speed(scene, over, u_start), shortest_level(encoder))
    else {
        return Ok(());
    };
    let spec = scene.capture.unwrap_or_default();
    let held = angle / w;
    let needed = CAPTURE_SAMPLES_PER_LEVEL / held;
    if spec.sample_rate >= needed {
        return Ok(());
    }
    let c = scene.checker(file);
    let pitch = std::f64::consts::TAU / f64::from(e.grid_lines().max(1));
    Err(c.bad(
        "capture.sample_rate",
        spec.sample_rate,
        format!(
            "too slow for the encoder signal: its shortest level, {what} ({:.3} of a grid pitch: \
             encoder.lines = {}, capture.duty = {}), lasts {:.3e} s at {w:.4} rad/s ({from}), so \
             the capture needs at least {} Hz ({CAPTURE_SAMPLES_PER_LEVEL} samples a level); \
             slower, pulses fall between samples and vanish from the file",
            angle / pitch,
            c.shown("encoder.lines", e.grid_lines()),
            c.shown("capture.duty", spec.duty),
            held,
            needed.ceil()
        ),
    ))
}

/// The WARNING of a capture file that lacks level changes of the signal (merged within a
/// sample period as the file was written): how many, on which channel, and the sample rate
/// that keeps the shortest level the signal held.
fn capture_loss_warning(
    scene: &Scene,
    file: &Path,
    channels: &[crate::app::logic::ChannelSampling],
) -> Option<String> {
    let lossy: Vec<_> = channels.iter().filter(|c| c.lost > 0).collect();
    if lossy.is_empty() {
        return None;
    }
    let rate = scene.capture.unwrap_or_default().sample_rate;
    let each: Vec<String> = lossy
        .iter()
        .map(|c| {
            format!(
                "{} of the {} level changes of channel `{}`",
                c.lost, c.changes, c.channel
            )
        })
        .collect();
    let shortest = lossy
        .iter()
        .filter_map(|c| c.shortest_level)
        .fold(f64::INFINITY, f64::min);
    let keep = if shortest.is_finite() && shortest > 0.0 {
        format!(
            "; the shortest level lasted {shortest:.3e} s: at least {} Hz \
             ({CAPTURE_SAMPLES_PER_LEVEL} samples a level) keeps every change",
            (CAPTURE_SAMPLES_PER_LEVEL / shortest).ceil()
        )
    } else {
        String::new()
    };
    Some(format!(
        "WARNING capture: {} fell within one sample period of another at `capture.sample_rate = \
         {}` and are not in the file (a pulse shorter than a sample vanishes, and is not \
         counted by what reads the file){keep}",
        each.join(" and "),
        scene.checker(file).shown("capture.sample_rate", rate)
    ))
}

/// The capture writer of a run: the scene's `[capture]` settings (or their defaults).
fn open_capture(
    scene: &Scene,
    file: &Path,
    target: &CaptureTarget,
    max_bytes: f64,
) -> Result<CaptureWriter<std::io::BufWriter<std::fs::File>>, SceneError> {
    let spec = scene.capture.unwrap_or_default();
    let index = matches!(
        scene.encoder.as_ref().map(|e| e.framing()),
        Some(FramingSpec::Index)
    );
    let settings = CaptureSettings {
        format: target.format,
        sample_rate: spec.sample_rate,
        noise_width: spec.noise_width,
        dedup: spec.dedup,
        index,
    };
    let fail = |e: std::io::Error| {
        SceneError::value(
            file,
            "capture",
            format!("cannot write {}: {e}", target.path.display()),
        )
    };
    // A file of every sample grows with the duration and the rate, not the edges: its size
    // is known before anything is written.
    let duration = scene.simulation.duration;
    let estimate = CaptureWriter::new(Vec::new(), settings)
        .map_err(fail)?
        .every_sample_bytes(duration);
    if let Some(bytes) = estimate.filter(|&b| b > max_bytes) {
        return Err(SceneError::value(
            file,
            "capture",
            format!(
                "{} would be about {:.3e} bytes ({:.3e} rows, a row for every sample of {} s at \
                 `capture.sample_rate = {}`), more than the {max_bytes:.0e} bytes `run` writes \
                 unasked: `[capture] dedup = true` writes only the rows where a level changes, a \
                 shorter `simulation.duration` or a lower `capture.sample_rate` fewer rows, \
                 another --capture-format (saleae, plain, vcd) only the changes, and \
                 `--capture-max-bytes {:.0}` accepts it",
                target.path.display(),
                bytes,
                (duration * spec.sample_rate).ceil() + 1.0,
                duration,
                scene
                    .checker(file)
                    .shown("capture.sample_rate", spec.sample_rate),
                bytes.ceil()
            ),
        ));
    }
    let f = std::fs::File::create(&target.path).map_err(fail)?;
    CaptureWriter::new(std::io::BufWriter::new(f), settings).map_err(fail)
}

/// The NOTE on a cranking ripple's mean speed: the scene's ω̄ in ω(φ, t) = ω̄(t)·(1 + ripple·
/// sin(strokes·φ + phase)) is the mean over the shaft's angle; over time the shaft turns
/// 2π in ∫dφ/ω = 2π/(ω̄·√(1 − ripple²)), so its mean speed (what a tachometer reads, and the
/// run's) is ω̄·√(1 − ripple²): 91.65 rad/s for a prescribed 100 at ripple 0.4, unsaid before.
fn cranking_mean_note(scene: &Scene) -> Option<String> {
    let c = scene.cranking?;
    let factor = (1.0 - c.ripple * c.ripple).sqrt();
    (c.ripple > 0.0).then(|| {
        format!(
            "NOTE: with [cranking] ripple = {}, the prescribed speed is the mean over the shaft's \
             angle; over time the shaft turns at √(1 − ripple²) = {factor:.4} of it on average \
             (the mean speed below)",
            c.ripple
        )
    })
}

/// The WARNING for a fixed RK4 step too long for the scene's motion: its largest local error
/// estimate ([`crate::engine::ode::Solver::fixed_step_error`]) above its scale, `None` within
/// it (and for the adaptive methods, which keep their own tolerance).
fn fixed_step_warning(scene: &Scene, file: &Path, error: Option<(f64, f64)>) -> Option<String> {
    let (ratio, t) = error.filter(|&(r, _)| r > 1.0)?;
    let step = scene.simulation.step;
    // The estimate is the third-order companion's error, ∝ h⁴: a step shorter by ratio^¼
    // brings it to the scale.
    let shorter = step / ratio.powf(0.25);
    Some(format!(
        "WARNING: simulation.step = {} s with integrator = \"rk4\": a step's local error, estimated from its \
         stages, reached {ratio:.3e} times {:e} of the state (the step from t = {t:.4} s): the \
         fixed step does not resolve the scene's motion, and the run's figures hold the \
         integration's error; take simulation.step at most {shorter:.2e} s, or the adaptive \
         dp5 (the default)",
        scene.checker(file).shown("simulation.step", step),
        crate::engine::ode::RK4_RTOL
    ))
}

/// An integration failure, with the scene keys that set the integration up; where the shaft
/// had turned backwards (at `reversed_at`, s) under a motor, that is said first: a load beyond
/// the motor's torque runs the shaft away backwards (the parabola continued to negative speeds
/// without bound, in finite time), which no tolerance resolves.
fn integration_error(
    scene: &Scene,
    file: &Path,
    e: &crate::engine::system::SimError,
    reversed_at: Option<f64>,
) -> SceneError {
    let c = scene.checker(file);
    let s = &scene.simulation;
    if let crate::engine::system::SimError::Diverged {
        t,
        speed,
        limit,
        rate,
    } = *e
    {
        let reached = if speed.is_finite() {
            format!(
                "left the shaft turning at {speed:.3e} rad/s, beyond {limit:.3e} rad/s (ten \
                 times the fastest speed the scene's motor or initial speed gives), with its \
                 local error estimate beyond its scale"
            )
        } else {
            "left a state that is no longer finite".to_string()
        };
        let scale = rate
            .filter(|r| r.is_finite() && *r > 0.0)
            .map(|r| {
                format!(
                    " (the scene's fastest rate, linearised at the start and where it diverged, \
                     is {r:.3} 1/s)"
                )
            })
            .unwrap_or_default();
        return c.bad(
            "simulation.step",
            s.step,
            format!(
                "the fixed step with integrator = \"rk4\" diverged: the step from t = {t:.4} s \
                 {reached}; the run was stopped there: take simulation.step at most {:.2e} s{scale}, \
                 or the adaptive dp5 (the default)",
                suggested_step(s.step, rate)
            ),
        );
    }
    if let (Some(t), Some(note)) = (
        reversed_at,
        reversed_at.and_then(|_| predict::active_load_note(scene, file)),
    ) {
        return SceneError::value(
            file,
            "simulation",
            format!(
                "{e}: the shaft turned backwards at t = {t:.4} s and ran away ({}); the \
                 integration's settings are not the cause",
                note.trim_start_matches("NOTE: ")
            ),
        );
    }
    if s.integrator == IntegratorKind::Rk4 {
        // A fixed step: rtol and atol play no part.
        return SceneError::value(
            file,
            "simulation",
            format!(
                "{e}: the fixed step simulation.step = {} s with integrator = \"rk4\" does not resolve the scene's \
                 fastest motion: take a shorter simulation.step, or the adaptive dp5 (the \
                 default)",
                c.shown("simulation.step", s.step)
            ),
        );
    }
    SceneError::value(
        file,
        "simulation",
        format!(
            "{e}: the scene's time scales are beyond what the integrator resolves with \
             simulation.rtol = {}, atol = {}, step = {}; check the inertias, masses, stiffnesses \
             and speeds of the scene against each other",
            c.shown("simulation.rtol", s.rtol),
            c.shown("simulation.atol", s.atol),
            c.shown("simulation.step", s.step)
        ),
    )
}

/// A run ended by the limits while running (their estimate up front was too low).
fn stopped(scene: &Scene, file: &Path, stop: Stop, t: f64) -> SceneError {
    let c = scene.checker(file);
    let what = match stop {
        Stop::Edges => format!("more than {MAX_EDGES:.0e} encoder edges"),
        Stop::Steps => format!("more than {MAX_STEPS} integrator steps"),
        Stop::Capture => "a capture file that could not be written".to_string(),
    };
    c.bad(
        "simulation.duration",
        scene.simulation.duration,
        format!("stopped at t = {t:.3} s: the run produced {what} (shorten the duration)"),
    )
}

/// What the core measured: windows, rejected edges, δ, and why nothing was measured.
fn measurement(report: &mut RunReport, col: &mut Collector) {
    let Some(m) = &col.monitor else {
        report.no_measurement = Some(
            "the scene has no [encoder] (lines and timer_hz), so the core had no edges to measure"
                .to_string(),
        );
        return;
    };
    let d = m.diagnostics();
    report.windows = d.valid_windows + d.invalid_windows;
    report.invalid_windows = d.invalid_windows;
    report.rejected_edges = [d.edges.glitches, d.edges.missing, d.edges.extra];
    report.timeouts = d.edges.timeouts;
    report.invalid_reasons = std::mem::take(&mut col.invalid_reasons);
    report.delta_measured = median(
        &mut col
            .counted
            .iter()
            .map(|w| f64::from(w.0))
            .collect::<Vec<_>>(),
    );
    report.noise_floor = median(
        &mut col
            .counted
            .iter()
            .map(|w| f64::from(w.1))
            .collect::<Vec<_>>(),
    );
    report.speed_measured = col.last_window.map(|w| w.omega_mean as f64);
    report.speed_peak_measured = col.fastest_window.map(|(w, _)| w.omega_max as f64);
    report.speed_peak_at = col.fastest_window.map(|(_, t)| t);
    report.speed_peak_mean = col.fastest_window.map(|(w, _)| w.omega_mean as f64);
    if d.valid_windows == 0 {
        let min_speed = m.encoder().config().min_speed;
        let why = nothing_measured(report, col, &d.edges, min_speed);
        report.no_measurement = Some(why);
    }
}

/// Why the core measured no valid window, from what the run saw and the core counted
/// (`min_speed` the core's, rad/s).
fn nothing_measured(
    r: &RunReport,
    col: &Collector,
    core: &drive_monitor::speed::EdgeCounters,
    min_speed: f64,
) -> String {
    let (edges, reverse) = (col.edges, col.reverse_edges);
    let mut why = Vec::new();
    if edges == 0 {
        why.push("the encoder produced no edge (the shaft did not turn)".to_string());
    }
    if reverse > 0 {
        why.push(format!(
            "{reverse} of {edges} edges came in reverse (the shaft turned backwards)"
        ));
    }
    let rejected: u64 = r.rejected_edges.iter().map(|&n| u64::from(n)).sum();
    if edges > 0 && rejected > 0 {
        why.push(format!(
            "{rejected} of {edges} edges were rejected ({} as glitches, {} missing, {} extra): \
             edges too close for the timer, or too much jitter",
            r.rejected_edges[0], r.rejected_edges[1], r.rejected_edges[2]
        ));
    }
    if r.invalid_windows > 0 {
        let reasons: Vec<String> = r
            .invalid_reasons
            .iter()
            .map(|(k, v)| format!("{v} {k}"))
            .collect();
        why.push(format!(
            "all {} windows were invalid ({})",
            r.invalid_windows,
            reasons.join(", ")
        ));
    } else if edges > 0 && reverse == edges {
        // Reverse edges are no forward time reference: the core measures forward rotation.
        why.push(
            "no window was completed: the core measures δ of forward rotation, and every edge \
             came in reverse"
                .to_string(),
        );
    } else if edges > 0 && core.accepted == 0 {
        // Edges slower than the minimum speed allows are a shaft at rest: no window completes,
        // and the run is not too short.
        why.push(format!(
            "no window was completed: the core took no edge as running, every interval between \
             edges was longer than the standstill timeout `monitor.min_speed = {min_speed}` rad/s \
             sets"
        ));
    } else if edges > 0 {
        why.push("no window was completed (the run is shorter than one window, or never framed a revolution)".to_string());
    }
    if core.accepted > 0 && core.timeouts > 0 {
        why.push(format!(
            "the core timed out {} time(s), taking the shaft for stopped: it turned slower than \
             `monitor.min_speed = {min_speed}` rad/s between edges",
            core.timeouts
        ));
    }
    format!("no valid δ window: {}", why.join("; "))
}

/// The regime the core predicts at the measured speed and what the loads did.
fn regime(
    scene: &Scene,
    file: &Path,
    report: &mut RunReport,
    vib_machine: Option<&VibrationMachine>,
    samples: &[RegimeSample],
    speeds: &[f32],
) -> Result<(), SceneError> {
    if let (Some(machine), Some(w)) = (predict::machine(scene, file)?, report.speed_measured) {
        let (classifier, _) = regime_classifier(scene, file, &machine)?;
        // The tracker fed every valid window's speed, as firmware would: outside the margin
        // band its segment is the one `classify` gives at the last speed (the hysteresis is
        // half the margin), and it knows whether the loads arrived balanced.
        let mut tracker = RegimeTracker::new();
        let mut status = None;
        for &s in speeds {
            status = Some(tracker.update(&classifier, s));
        }
        let class = match status {
            Some(st) if !st.near_characteristic => st.regime,
            _ => classifier.classify(w as f32),
        };
        report.regime_by_history = status.is_some_and(|st| st.by_history && class == st.regime);
        report.regime_class = Some(class.name());
        report.regime_reason = class.reason().map(|r| r.name());
        // The criterion's own zone at the measured speed (no margin, no capture check).
        report.regime_predicted = Some(machine.zone_kind_at(w).name());
    }
    if let Some(vm) = vib_machine {
        report.capacity = Some(vm.capacity());
        report.rotor_unbalance = Some(vm.rotor_unbalance());
        report.residual_floor = Some(vm.residual_floor());
        let criteria = vm.regime_criteria();
        if let Some(r) = classify(samples, &criteria) {
            report.regime_simulated = Some(r.regime.as_str());
            report.residual_relative = Some(r.residual_relative);
            // A verdict the run is too short for: the residual between the thresholds, or
            // still under 1 % where the balancing position is unstable and the run is shorter
            // than ten e-foldings of its growth (`drive-sim sweep` runs such speeds longer).
            let sigma = if r.regime == SimRegime::Balancing {
                balancing_growth_rate(vm, r.rotor_speed.abs())
            } else {
                None
            };
            let duration = scene.simulation.duration;
            // Not balancing is gathering only once the residual reaches 10 % in the final
            // quarter: a run started near the balancing position begins below that, and one
            // that never got there may just not have moved yet (a growth or decay of 1/4700 s
            // left a 200 s run's residual at its starting offset, steady to 3 %).
            let reached = r.residual_relative >= AWAY;
            // A residual that reaches 10 % and comes back below it, swinging alike in every
            // quarter of the final window, has settled: a self-oscillation about an unstable
            // balancing position, which a longer run leaves as it is.
            let swinging = r.regime == SimRegime::Gathering
                && reached
                && r.residual_min_relative < AWAY
                && r.steady
                && !r.gathered
                && !r.lagging;
            if swinging {
                report.regime_swing = Some(format!(
                    "the loads settled into a steady oscillation about the balancing position \
                     (a self-oscillation where it is unstable): the residual unbalance swings \
                     from {:.2e} to {:.2e} of the rotor's alike in each quarter of the final \
                     quarter of the run, the loads turning with the rotor, not together \
                     (gathered loads leave up to {:.2e})",
                    r.residual_min_relative,
                    r.residual_relative,
                    (vm.rotor_unbalance() + vm.capacity())
                        / vm.rotor_unbalance().max(f64::MIN_POSITIVE),
                ));
            }
            // Not balancing, not lagging the rotor, where the balancing position is stable: a
            // verdict of the run that may not be the machine's (loads that lag are captured,
            // merged or not: a user's reference with the loads apart kept one captured where
            // the simulator's merged pair was, and that stays gathering).
            let free = r.regime == SimRegime::Gathering
                && !r.lagging
                && report.regime_class.is_some_and(|c| c != "gathering");
            // Identical loads that met to within rounding move as one for good (the model has
            // no contact between loads), which real loads, touching and parting at any
            // imperfection, do not (a run-up's capture merged the bundled one-mass machine's
            // loads bit for bit, and after the release they stayed together opposite the
            // unbalance; parted by 0.01 rad they balance within seconds).
            let coincident = free && vm.loads() >= 2 && r.coherence_min >= COINCIDENT;
            if coincident {
                report.regime_coincident = Some(format!(
                    "the loads met and move as one with the rotor (within 1e-6 rad of each other \
                     over the final quarter of the run, the residual {:.2e} of the rotor's): the \
                     model has no contact between loads, so identical loads that meet stay \
                     together for good, which real loads, which touch and part at any \
                     imperfection, do not; where the balancing position is stable, as here, \
                     this is not the machine's regime",
                    r.residual_relative
                ));
            }
            // Loads whose residual still falls over the final quarter are on their way (two
            // machines held 60 s after a run-up read gathering at 0.85 and 0.18 of the rotor's
            // unbalance, and balanced to 1e-8 when held 600 s).
            let converging = free && r.falling;
            report.regime_unsettled = match r.regime {
                SimRegime::Gathering if converging => Some(format!(
                    "the residual unbalance was still falling over the final quarter of the run \
                     (its peak in the last quarter of that window under half of its peak in the \
                     first; {:.2e} of the rotor's at most) where the balancing position is \
                     stable: the loads were still on their way (lengthen simulation.duration)",
                    r.residual_relative
                )),
                SimRegime::Gathering if !reached => Some(short_of_away(vm, &r, duration)),
                SimRegime::Gathering if r.residual_min_relative < AWAY && !swinging => {
                    Some(format!(
                        "the residual unbalance over the final quarter went from {:.2e} to \
                         {:.2e} of the rotor's: up to {:.0} % and more, and back below it, \
                         changing from quarter to quarter of that window: the run ended \
                         before the loads settled (lengthen simulation.duration)",
                        r.residual_min_relative,
                        r.residual_relative,
                        100.0 * AWAY,
                    ))
                }
                SimRegime::Balancing
                    if sigma.is_some_and(|g| {
                        g > 0.0 && duration < crate::app::regimes::settle_time(g)
                    }) =>
                {
                    let g = sigma.unwrap_or(0.0);
                    Some(format!(
                        "the balancing position is unstable at {:.2} rad/s (growth rate {g:.3e} \
                         1/s), and the {duration} s run is shorter than ten e-foldings of it \
                         ({:.0} s): the residual may still grow (lengthen simulation.duration)",
                        r.rotor_speed.abs(),
                        crate::app::regimes::settle_time(g)
                    ))
                }
                _ => None,
            };
            if report.regime_unsettled.is_some() {
                report.regime_simulated = Some("unsettled");
            } else if coincident {
                report.regime_simulated = Some("coincident");
            }
            // A committed class the settled simulation contradicts is said, not left side by
            // side with it (firmware reading the class would report it).
            if let (Some(class), Some(sim)) = (report.regime_class, report.regime_simulated) {
                let committed = class == "balancing" || class == "gathering";
                let judged = matches!(sim, "balancing" | "gathering" | "saturated");
                if committed && judged && !crate::studies::sweep::agrees(class, sim) {
                    report.regime_mismatch = Some(if class == "balancing" {
                        "the balancing position is stable here and nothing else is known to \
                         persist, but the loads ended elsewhere: still on their way (a longer \
                         simulation.duration tells), or in a state the exact table does not \
                         describe (loads started together can keep slipping past the balancing \
                         position on a few machines; docs/criterion.md)"
                            .to_string()
                    } else {
                        "the balancing position is unstable here, yet the loads balanced over \
                         the run: a growth too slow to show in it (lengthen \
                         simulation.duration)"
                            .to_string()
                    });
                }
            }
            report.regime_detail = Some(r);
        }
    }
    Ok(())
}

/// The growth rate σ (1/s) of the least stable perturbation of two loads' balancing position
/// at `speed` rad/s ([`fan_growth_rate`]). `None` for three or more loads, which can balance
/// at another member of their family than the fan analysed, and where there is no balancing
/// position.
fn balancing_growth_rate(vm: &VibrationMachine, speed: f64) -> Option<f64> {
    (vm.loads() == 2)
        .then(|| fan_growth_rate(vm, speed))
        .flatten()
}

/// The growth rate σ (1/s) of the least stable perturbation of the balancing position the
/// simulator starts the loads near (for three or more loads, the fan) at `speed` rad/s
/// (Floquet, one monodromy at the stability map's tolerance). `None` where there is no
/// balancing position.
fn fan_growth_rate(vm: &VibrationMachine, speed: f64) -> Option<f64> {
    use crate::engine::vibration::floquet::{Floquet, ScanOptions};
    if speed.is_nan() || speed <= 0.0 {
        return None;
    }
    let f = Floquet::new(vm).ok()?;
    let rtol = ScanOptions::new(1.0, 2.0).rtol;
    f.multipliers(speed, rtol).ok().map(|m| m.growth_rate())
}

/// Why run `r` of `duration` seconds, its residual above [`BALANCED`] and below [`AWAY`] of
/// the rotor's throughout the final quarter, shows no regime: where it stayed against where
/// it started and, with the balancing position's growth rate σ ([`fan_growth_rate`]), how
/// many e-foldings `1/|σ|` the run spans.
fn short_of_away(vm: &VibrationMachine, r: &RegimeReport, duration: f64) -> String {
    use std::fmt::Write as _;
    let mut why = format!(
        "the residual unbalance over the final quarter of the run stayed between {:.2e} and \
         {:.2e} of the rotor's, above the {:.0} % balancing allows and under the {:.0} % \
         gathering needs, its largest {:.2} times the {:.2e} it started at",
        r.residual_min_relative,
        r.residual_relative,
        100.0 * BALANCED,
        100.0 * AWAY,
        r.residual_relative / r.residual_initial_relative,
        r.residual_initial_relative,
    );
    let speed = r.rotor_speed.abs();
    if let Some(g) = fan_growth_rate(vm, speed).filter(|g| g.is_finite() && *g != 0.0) {
        let _ = write!(
            why,
            "; at {speed:.2} rad/s the balancing position's least stable perturbation {} \
             (Floquet growth rate {g:.2e} 1/s): one e-folding takes {:.0} s, and the \
             {duration} s run spans {:.2} of them (ten take {:.0} s)",
            if g > 0.0 { "grows" } else { "decays" },
            1.0 / g.abs(),
            duration * g.abs(),
            crate::app::regimes::settle_time(g),
        );
    }
    why.push_str(
        ": the run ended before the loads showed where they go (lengthen simulation.duration)",
    );
    why
}

/// Loads whose coherence stays at least this over the final quarter of a run lie within about
/// 1e-6 rad of each other (two loads: `cos(Δ/2) ≥ 1 − 1e-13`): met, moving as one.
const COINCIDENT: f64 = 1.0 - 1e-13;

/// The warning for a shaft measured above the service speed: the permissible residual
/// unbalance (ISO 21940-11, `U_per = 1000·G·m/ω`) was allotted for the service speed, and at a
/// higher speed the grade allows proportionally less, which the unbalance levels do not show.
pub fn above_service_speed(speed: f64, service: f64) -> Option<String> {
    (speed > service * 1.001).then(|| {
        format!(
            "WARNING: the shaft runs at {speed:.2} rad/s, above the service speed {service} rad/s \
             the permissible unbalance was allotted for (rotor.service_speed); at {speed:.2} \
             rad/s the grade allows {:.1} % of it, so the unbalance levels are judged too \
             leniently",
            100.0 * service / speed
        )
    })
}

/// The supports judged by the core at the measured speed, beside the simulated reactions.
/// Without a measured speed the core's levels are unknown: the reactions are then judged
/// against the scene's load limits directly.
fn supports(
    scene: &Scene,
    file: &Path,
    report: &mut RunReport,
    peaks: [(f64, f64); 2],
) -> Result<(), SceneError> {
    let (reactions, reactions_at) = (peaks.map(|(load, _)| load), peaks.map(|(_, t)| t));
    let Some((rotor, limits)) = predict::rotor(scene, file)? else {
        return Ok(());
    };
    let analysis = predict::analysis(scene, &rotor, &limits, file)?;
    let monitor = analysis
        .monitor()
        .map_err(|e| core_error(scene, file, "rotor", e))?;
    let finite = |v: f32| Some(f64::from(v)).filter(|v| v.is_finite());
    // The simulated reactions against the load limits, whatever the core measured.
    let reaction_level = limits
        .support_load_limit()
        .map(|l| [0, 1].map(|k| predict::level_of(reactions[k], limits.warning_fraction(), l[k])));
    let out = match report.speed_peak_measured {
        // The unbalance load |D|·ω² peaks at the fastest speed a window measured: judged there
        // (at the mean, a drive with δ = 0.34 had its peak loads read 10 % low, "normal" for a
        // bearing over its limit every load cycle; at the last window's, a 0.4 s excursion to
        // 3.3 times the service speed earlier in the run, 2682 N on a support of 2650, went
        // unsaid).
        Some(speed) => {
            let status = monitor.update(speed as f32);
            SupportsRunOut {
                speed: Some(speed),
                speed_mean: report.speed_peak_mean,
                speed_at: report.speed_peak_at,
                peak_load: status.peak_load.map(finite),
                simulated_peak_reaction: reactions,
                simulated_peak_at: reactions_at,
                reactions_note: None,
                load_level: status.load.map(level),
                unbalance_level: status.unbalance.map(level),
                max_safe_speed: status.max_safe_speed.and_then(finite),
                simulated_reaction_level: reaction_level,
                above_service_speed: above_service_speed(speed, limits.service_speed()),
                balancer_warning: predict::balancer_supports_warning(scene),
                unbalance_warning: predict::unbalance_warning(scene),
            }
        }
        None => {
            let status = monitor.update(0.0);
            SupportsRunOut {
                speed: None,
                speed_mean: None,
                speed_at: None,
                peak_load: [None; 2],
                simulated_peak_reaction: reactions,
                simulated_peak_at: reactions_at,
                reactions_note: None,
                load_level: ["unknown"; 2],
                unbalance_level: status.unbalance.map(level),
                max_safe_speed: status.max_safe_speed.and_then(finite),
                simulated_reaction_level: reaction_level,
                above_service_speed: None,
                balancer_warning: predict::balancer_supports_warning(scene),
                unbalance_warning: predict::unbalance_warning(scene),
            }
        }
    };
    report.supports = Some(out);
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The streamed reductions give `classify` exactly what it computes from every sample, for
    /// runs whose last sample falls anywhere in the last two sampling intervals.
    #[test]
    fn streamed_regime_equals_the_whole_list() {
        let criteria = RegimeCriteria::new(0.05);
        for (duration, every, jiggle) in
            [(40.0, 0.01, 0.0), (7.3, 0.01, 0.004), (1.0, 0.00025, 0.0)]
        {
            let mut all = Vec::new();
            let mut stream = RegimeStream::new(duration, every, criteria.window_fraction);
            let mut t = 0.0;
            let mut k = 0u32;
            while t <= duration - jiggle {
                // A residual with a peak early in the judged part and a coherence dip late.
                let x = f64::from(k);
                let s = RegimeSample {
                    t,
                    residual: 1e-3 * (1.0 + (0.37 * x).sin()) + if k == 3100 { 0.2 } else { 0.0 },
                    coherence: 0.5 + 0.4 * (0.11 * x).cos(),
                    mean_load_angle: 0.9 * t + 0.01 * (x * 0.7).sin(),
                    rotor_angle: 100.0 * t,
                };
                all.push(s);
                stream.push(s);
                t += every;
                k += 1;
            }
            let whole = classify(&all, &criteria).unwrap();
            let streamed = classify(&stream.samples(), &criteria).unwrap();
            assert_eq!(
                format!("{whole:?}"),
                format!("{streamed:?}"),
                "{duration} {every}"
            );
            // A bounded number whatever the duration: the first and last, those near the
            // judged part's start, two stand-ins and each eighth's two extremes.
            assert!(stream.samples().len() < 40);
        }
    }
}
