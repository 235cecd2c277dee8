//! Design-time results of a scene, computed by the core (no simulation): predicted δ and the
//! flywheel for the limit, the support unbalances and limits, the auto-balancer's zones.

use crate::app::kloss_period;
use crate::app::scene::{BalancerKindSpec, MotorSpec, Scene, SceneError};
use drive_monitor::balancer::{
    AutoBalancer, BalancerKind, Coupling, Machine, MachineConfig, Platform, SearchOptions,
};
use drive_monitor::drive::{
    DriveModel, Harmonic, InertiaHarmonic, Kloss, KlossFit, Load, Motor, Parabola,
};
use drive_monitor::supports::{Limits, ProcessLoad, Rotor, SupportAnalysis, Unbalance};
use drive_monitor::ConfigError;
use serde::Serialize;
use std::path::Path;

/// Largest number of unbalances a scene may give.
pub const MAX_UNBALANCES: usize = 32;

/// Turns a core configuration error into a scene error naming the scene key the core's
/// parameter stands for ([`crate::app::check::core_keys`]), without the values.
pub fn value_error(file: &Path, section: &str, e: ConfigError) -> SceneError {
    let key = crate::app::check::core_keys(section, e.parameter()).remove(0);
    SceneError::value(file, &key, e.to_string())
}

/// Turns a core configuration error for `scene` into a scene error naming every scene key
/// the core's parameter stands for, with its value as written.
pub fn core_error(scene: &Scene, file: &Path, section: &str, e: ConfigError) -> SceneError {
    scene.checker(file).core(scene, section, e)
}

/// The drive model of a scene with a torque motor and a load (`None` for a prescribed speed
/// or without a `[load]`), with J(φ) from `[shaft] inertia_harmonics`. Where the core does
/// not predict that J(φ) ([`irregularity_not_predicted`] says why) the model has the constant
/// inertia, for what does not depend on it (the motor, the mean of ω²); so does a Kloss drive
/// whose J(φ) the host integrates instead ([`long_period_inertia`], [`long_kloss`]).
pub fn drive_model(scene: &Scene, file: &Path) -> Result<Option<DriveModel>, SceneError> {
    let Some(base) = constant_inertia_model(scene, file)? else {
        return Ok(None);
    };
    match with_inertia(scene, &base) {
        Ok(m) => Ok(Some(m)),
        Err(e) if not_covered(e).is_some() => Ok(Some(base)),
        Err(e) => Err(core_error(scene, file, "shaft", e)),
    }
}

/// The scene's inertia harmonics on `base` (`base` itself without any).
fn with_inertia(scene: &Scene, base: &DriveModel) -> Result<DriveModel, ConfigError> {
    let harmonics = scene_inertia(scene)?;
    if harmonics.is_empty() {
        return Ok(base.clone());
    }
    base.with_inertia_harmonics(&harmonics)
}

/// The scene's inertia harmonics as the core validates them (none where every amplitude is 0).
fn scene_inertia(scene: &Scene) -> Result<Vec<InertiaHarmonic>, ConfigError> {
    let Some(shaft) = &scene.shaft else {
        return Ok(Vec::new());
    };
    if shaft.inertia_harmonics.iter().all(|h| h.amplitude == 0.0) {
        return Ok(Vec::new());
    }
    shaft
        .inertia_harmonics
        .iter()
        .map(|h| InertiaHarmonic::new(h.order, h.amplitude, h.phase))
        .collect()
}

/// The scene's J(φ) harmonics that the host integrates with a Kloss drive ([`long_kloss`]):
/// where the core refuses them because the common period of the load and inertia orders holds
/// more cycles of the fastest order than its shooting samples (more than
/// [`drive_monitor::drive::MAX_SAMPLES`] samples at 32 a cycle), and that period is one the host
/// integrates (within [`kloss_period::MAX_STEPS`] steps). Empty otherwise: a constant inertia,
/// a J(φ) the core predicts, or one neither does ([`irregularity_not_predicted`] says why).
/// [`drive_model`] gives such a scene the constant part of the inertia; the host integrates
/// eq. 1 with the whole J(φ).
pub fn long_period_inertia(scene: &Scene) -> Vec<InertiaHarmonic> {
    match constant_inertia_build(scene, Path::new("scene")) {
        Ok(Some(Ok(base))) => long_period_inertia_of(scene, &base).unwrap_or_default(),
        _ => Vec::new(),
    }
}

fn long_period_inertia_of(scene: &Scene, base: &DriveModel) -> Option<Vec<InertiaHarmonic>> {
    let k = *base.motor().kloss_curve()?;
    // The core checks J(φ) > 0 before the period: refused for the period, J(φ) is positive.
    if !matches!(
        with_inertia(scene, base).err()?,
        ConfigError::Inconsistent("inertia_harmonic.order")
    ) {
        return None;
    }
    let harmonics = scene_inertia(scene).ok()?;
    let period = kloss_period::common_period(&long_orders(base.load(), &harmonics))?;
    let drive = kloss_period::Drive::new(k, base.total_inertia(), base.load())
        .with_inertia_harmonics(&harmonics);
    drive.fits(&period).then_some(harmonics)
}

/// The orders the host's periodic solution repeats over: every load harmonic that is there
/// (order and amplitude non-zero) and every inertia harmonic.
fn long_orders(load: &Load, inertia: &[InertiaHarmonic]) -> Vec<f64> {
    load.harmonics()
        .iter()
        .filter(|h| h.amplitude() != 0.0)
        .map(|h| h.order())
        .chain(
            inertia
                .iter()
                .filter(|h| h.amplitude() != 0.0)
                .map(|h| h.order()),
        )
        .collect()
}

/// Why the core does not predict a J(φ) it rejected with `e`, if `e` is such a limit of the
/// core's J(φ) path rather than an invalid scene.
fn not_covered(e: ConfigError) -> Option<String> {
    match e {
        ConfigError::Inconsistent("inertia_harmonic.order") => Some(format!(
            "shaft.inertia_harmonics: its orders and the load's have no common period the core \
             handles (each a fraction with denominator ≤ {}, the period at most {} cycles of \
             the fastest order)",
            drive_monitor::drive::MAX_DENOMINATOR,
            drive_monitor::drive::MAX_SAMPLES / drive_monitor::drive::SAMPLES_PER_CYCLE
        )),
        ConfigError::OutOfRange("inertia_harmonics") => Some(format!(
            "shaft.inertia_harmonics: J(φ) comes so close to 0, or the common period holds so \
             many of its cycles, that the periodic solution needs more than {} trapezoid nodes; \
             or the motor is so stiff against the inertia's swing that neither that solution \
             (its integrating factor would swing by more than e^12 over the period) nor the \
             shooting with the parabola (too many steps) resolves it",
            drive_monitor::drive::MAX_NODES
        )),
        ConfigError::OutOfRange("inertia") => Some(format!(
            "shaft.inertia: the Kloss drive is so stiff against its inertia that one period \
             needs more than {} Runge–Kutta steps",
            drive_monitor::drive::MAX_STEPS
        )),
        ConfigError::OutOfRange("load.harmonics") => Some(
            "load.harmonics: no attracting periodic steady state was found for the Kloss drive \
             (its speed swings far past the breakdown point)"
                .to_string(),
        ),
        ConfigError::Capacity("inertia_harmonics") => Some(format!(
            "shaft.inertia_harmonics: more than {} harmonics",
            drive_monitor::drive::MAX_INERTIA_HARMONICS
        )),
        _ => None,
    }
}

/// The drive model with the constant part of the inertia only.
/// `None` where the core does not predict the drive (a Kloss drive it refuses:
/// [`irregularity_not_predicted`] says why).
fn constant_inertia_model(scene: &Scene, file: &Path) -> Result<Option<DriveModel>, SceneError> {
    match constant_inertia_build(scene, file)? {
        None => Ok(None),
        Some(Ok(m)) => Ok(Some(m)),
        Some(Err(e)) if not_covered(e).is_some() => Ok(None),
        Some(Err(e)) => Err(core_error(scene, file, "shaft", e)),
    }
}

/// The drive model with the constant part of the inertia only, and the core's error when it
/// refuses the drive as a whole.
#[allow(clippy::type_complexity)]
fn constant_inertia_build(
    scene: &Scene,
    file: &Path,
) -> Result<Option<Result<DriveModel, ConfigError>>, SceneError> {
    Ok(
        drive_parts_of(scene, file)?.map(|(motor, load, inertia, flywheel)| {
            let model = DriveModel::new(motor, load, inertia, flywheel)?;
            Ok(at_operating_point(model))
        }),
    )
}

/// A Kloss drive the core predicts through a parabola ([`Horizon::Unbounded`]: load orders
/// with no common period, or one too long for its samples) rebuilt with the parabola fitted at
/// the operating point ([`Kloss::operating_point_fit`]) in place of the tangent at synchronous
/// speed, which puts a loaded drive too fast (3.5 % at a mean load of 0.9·M_m); the parabola is
/// also `run`'s start. Any other drive, or one whose mean load no speed carries, as it is.
///
/// [`Horizon::Unbounded`]: drive_monitor::drive::Horizon::Unbounded
fn at_operating_point(model: DriveModel) -> DriveModel {
    let Some(k) = model.motor().kloss_curve().copied() else {
        return model;
    };
    if !matches!(model.horizon(), drive_monitor::drive::Horizon::Unbounded) {
        return model;
    }
    let mean =
        crate::app::kloss_period::Drive::new(k, model.total_inertia(), model.load()).mean_load();
    let Ok(p) = k.operating_point_fit(mean) else {
        return model;
    };
    DriveModel::new(
        Motor::kloss_with(k, p),
        model.load().clone(),
        model.inertia(),
        model.flywheel(),
    )
    .unwrap_or(model)
}

/// What a simulation of a scene's motor-driven shaft needs: the motor, the load and the square
/// of a start speed (the predicted mean of ω²).
#[derive(Debug, Clone)]
pub struct DriveParts {
    /// The motor.
    pub motor: Motor,
    /// The load torque.
    pub load: Load,
    /// ω² to start from, s⁻².
    pub u_start: f64,
}

/// The motor and load of a scene for simulation: those of its drive model, or, for a Kloss
/// drive whose steady state the core refuses to predict ([`irregularity_not_predicted`]),
/// the scene's own, started at the tangent parabola's mean speed. `None` without a torque motor
/// and a load.
pub fn drive_parts(
    scene: &Scene,
    file: &Path,
    model: Option<&DriveModel>,
) -> Result<Option<DriveParts>, SceneError> {
    if let Some(m) = model {
        return Ok(Some(DriveParts {
            motor: *m.motor(),
            load: m.load().clone(),
            u_start: m.u_mean(),
        }));
    }
    Ok(drive_parts_of(scene, file)?.map(|(motor, load, ..)| {
        let p = motor.model();
        let u_start = (p.b() - load.mean()) / -p.a();
        DriveParts {
            motor,
            load,
            u_start,
        }
    }))
}

/// The scene's motor, load, inertia and flywheel as the core validates them.
fn drive_parts_of(
    scene: &Scene,
    file: &Path,
) -> Result<Option<(Motor, Load, f64, f64)>, SceneError> {
    let (Some(motor), Some(load)) = (&scene.motor, &scene.load) else {
        return Ok(None);
    };
    let motor = match motor {
        MotorSpec::Parabola {
            no_load_speed,
            breakdown_speed,
            breakdown_torque,
        } => Motor::parabola(
            Parabola::new(*no_load_speed, *breakdown_speed, *breakdown_torque)
                .map_err(|e| core_error(scene, file, "motor", e))?,
        ),
        MotorSpec::Kloss {
            synchronous_speed,
            breakdown_slip,
            breakdown_torque,
        } => {
            let k = Kloss::new(*synchronous_speed, *breakdown_slip, *breakdown_torque)
                .map_err(|e| core_error(scene, file, "motor", e))?;
            Motor::kloss(k, KlossFit::SynchronousTangent)
                .map_err(|e| core_error(scene, file, "motor", e))?
        }
        MotorSpec::Speed { .. } | MotorSpec::Ramp { .. } | MotorSpec::Profile { .. } => {
            return Ok(None)
        }
    };
    let mut harmonics = Vec::with_capacity(load.harmonics.len());
    for h in &load.harmonics {
        harmonics.push(
            Harmonic::new(h.order, h.amplitude, h.phase)
                .map_err(|e| core_error(scene, file, "load.harmonics", e))?,
        );
    }
    let load = Load::new(load.mean, &harmonics).map_err(|e| core_error(scene, file, "load", e))?;
    let Some(shaft) = &scene.shaft else {
        return Err(SceneError::value(
            file,
            "shaft",
            "missing: a motor-driven scene needs [shaft] inertia",
        ));
    };
    Ok(Some((motor, load, shaft.inertia, shaft.flywheel)))
}

/// What the core's speed samples do to the predicted δ: each sample is the angle of
/// `encoder.estimator_edges` edges over their time, the mean speed over that angle, so a load
/// cycle not much longer than the samples' span is averaged away (entirely when the span is a
/// whole number of load cycles: 16-edge samples on a 16-line disc see no order-1 ripple); and
/// the samples start only at the teeth, so a ripple with few teeth a cycle is read between its
/// peaks, by how much depending on the load's phase against the teeth
/// ([`crate::app::sampled`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledDelta {
    /// Edges per speed sample (`encoder.estimator_edges`).
    pub edges: u16,
    /// Shaft angle one sample spans, rad (on a pattern wheel, K mean pitches).
    pub span: f64,
    /// The least δ of the predicted steady state the samples read, over the load's phase
    /// against the teeth: what the δ alarm can count on.
    pub least: f64,
    /// The most they read over that phase.
    pub most: f64,
    /// What they read with the teeth where the scene has them (the simulator's wheel, its
    /// tooth 0 at the load's φ = 0): what `run` measures.
    pub at_scene_phase: f64,
    /// The most edges per sample whose least keeps 99 % of the predicted δ (`None` when even
    /// one edge does not).
    pub edges_for_99_percent: Option<u16>,
}

/// The edges the core samples on a scene's wheel: a uniform disc's lines, one in `prescaler`
/// from line 0, or a pattern wheel's teeth.
pub fn sample_wheel(
    e: &crate::app::scene::EncoderSpec,
    wheel: &crate::app::check::WheelDesc,
) -> crate::app::sampled::SampleWheel {
    use crate::app::scene::FramingSpec;
    match wheel.framing {
        FramingSpec::Index | FramingSpec::None => crate::app::sampled::SampleWheel::uniform(
            u32::from(wheel.lines),
            u32::from(e.prescaler),
        ),
        FramingSpec::MissingTooth | FramingSpec::Pattern => crate::app::sampled::SampleWheel {
            positions: u32::from(wheel.lines),
            teeth: wheel.teeth.iter().map(|&t| u32::from(t)).collect(),
        },
    }
}

/// [`SampledDelta`] of a scene's drive through its encoder's speed samples (`None` without a
/// prediction, an `[encoder]`, or when [`crate::app::sampled::delta_through_samples`] gives
/// none: a load without a common period, or one too long to tabulate).
pub fn sampled_delta(
    scene: &Scene,
    file: &Path,
    model: &DriveModel,
) -> Result<Option<SampledDelta>, SceneError> {
    use crate::app::sampled::SteadyTime;
    if scene.encoder.is_none() {
        return Ok(None);
    }
    let Some(predicted) = model.predict().steady().map(|s| s.delta) else {
        return Ok(None);
    };
    sampled_delta_of(scene, file, predicted, || SteadyTime::new(model))
}

/// [`SampledDelta`] of a scene's steady state of δ `predicted` whose time over the angle
/// `time` tabulates (asked for only with an `[encoder]`, after its wheel is checked; `None`
/// from it: none given).
pub fn sampled_delta_of(
    scene: &Scene,
    file: &Path,
    predicted: f64,
    time: impl FnOnce() -> Option<crate::app::sampled::SteadyTime>,
) -> Result<Option<SampledDelta>, SceneError> {
    use crate::app::sampled::{sampled_range, SCAN_BUDGET};
    let Some(e) = &scene.encoder else {
        return Ok(None);
    };
    let desc = crate::app::check::wheel(e, &scene.checker(file))?;
    let wheel = sample_wheel(e, &desc);
    // Edges per revolution the core sees: the wheel's teeth, one in `prescaler` captured.
    let pitch = std::f64::consts::TAU / wheel.teeth.len().max(1) as f64;
    let span = |k: u16| f64::from(k) * pitch;
    let Some(time) = time() else {
        return Ok(None);
    };
    let Some(range) = sampled_range(&time, &wheel, e.estimator_edges, SCAN_BUDGET) else {
        return Ok(None);
    };
    let keeps = |d: f64| d >= 0.99 * predicted;
    let edges_for_99_percent = if keeps(range.least) {
        Some(e.estimator_edges)
    } else {
        // A coarser scan of the offsets for each candidate: up to 31 of them.
        (1..e.estimator_edges).rev().find(|&k| {
            sampled_range(&time, &wheel, k, SCAN_BUDGET / 4).is_some_and(|r| keeps(r.least))
        })
    };
    Ok(Some(SampledDelta {
        edges: e.estimator_edges,
        span: span(e.estimator_edges),
        least: range.least,
        most: range.most,
        at_scene_phase: range.at_zero,
        edges_for_99_percent,
    }))
}

/// The line a report adds when the speed samples can read more than 1 % less than the
/// predicted δ, at the least over the load's phase against the teeth (`None` otherwise).
pub fn sampled_delta_warning(predicted: f64, s: &SampledDelta) -> Option<String> {
    if s.least >= 0.99 * predicted {
        return None;
    }
    let advice = match s.edges_for_99_percent {
        Some(k) => format!("encoder.estimator_edges = {k} or fewer keeps 99 % of it"),
        None => {
            "even one edge per sample loses more than 1 % (a finer encoder would not)".to_string()
        }
    };
    let shown = |d: f64| fmt_sampled(d, predicted);
    let pct = |d: f64| 100.0 * (d / predicted - 1.0);
    let read = if sampled_spread(predicted, s.least, s.most) {
        format!(
            "they show {} to {} ({:+.1} % to {:+.1} %), the least and most over the load's \
             phase against the teeth ({} with the teeth where this scene has them), and the \
             δ alarm can count only on the least",
            shown(s.least),
            shown(s.most),
            pct(s.least),
            pct(s.most),
            shown(s.at_scene_phase)
        )
    } else {
        format!(
            "they show {} ({:+.1} %), and the δ alarm sees only that",
            shown(s.least),
            pct(s.least)
        )
    };
    Some(format!(
        "WARNING: speed samples over encoder.estimator_edges = {} edges span {:.3} revolution, \
         start only at the teeth and average the load ripple: of the predicted δ {} {read}; \
         {advice}",
        s.edges,
        s.span / std::f64::consts::TAU,
        fmt_delta(predicted),
    ))
}

/// A δ through the speed samples as text: "none" below 1e-9 of the `predicted` δ (the
/// rounding of a ripple averaged away exactly), else [`fmt_delta`].
pub fn fmt_sampled(d: f64, predicted: f64) -> String {
    if d < 1e-9 * predicted {
        "none".to_string()
    } else {
        fmt_delta(d)
    }
}

/// Whether the least and most δ through the samples differ enough (0.1 % of the `predicted`
/// δ) for a report to give both.
pub fn sampled_spread(predicted: f64, least: f64, most: f64) -> bool {
    most - least > 1e-3 * predicted
}

/// A δ as text: six decimals, or four significant digits below 0.001 (where six decimals
/// would keep one digit or none).
pub fn fmt_delta(d: f64) -> String {
    if d != 0.0 && d.abs() < 1e-3 {
        format!("{d:.3e}")
    } else {
        format!("{d:.6}")
    }
}

/// The rotor on two supports and its limits (`None` without `[rotor]`).
pub fn rotor(
    scene: &Scene,
    file: &Path,
) -> Result<Option<(Rotor<MAX_UNBALANCES>, Limits)>, SceneError> {
    let Some(r) = &scene.rotor else {
        return Ok(None);
    };
    let unbalances: Vec<Unbalance> = scene
        .unbalance
        .iter()
        .map(|u| Unbalance::new(u.z, u.amount, u.angle.to_radians()))
        .collect();
    if unbalances.len() > MAX_UNBALANCES {
        return Err(SceneError::value(
            file,
            "unbalance",
            format!("at most {MAX_UNBALANCES} unbalances"),
        ));
    }
    let process = scene.process_load.map(|p| ProcessLoad {
        per_length: p.per_length,
        from: p.from,
        to: p.to,
        angle: p.angle.to_radians(),
    });
    let rotor = Rotor::new(
        r.mass,
        r.centre_of_mass,
        r.support_a,
        r.support_b,
        &unbalances,
        process,
    )
    .map_err(|e| core_error(scene, file, "rotor", e))?;
    let warning = scene
        .monitor
        .as_ref()
        .and_then(|m| m.warning_fraction)
        .unwrap_or(0.8);
    let limits = Limits::new(r.grade, r.service_speed, r.support_load_limit, warning)
        .map_err(|e| core_error(scene, file, "rotor", e))?;
    Ok(Some((rotor, limits)))
}

/// The support analysis of a scene's rotor against its limits.
pub fn analysis(
    scene: &Scene,
    rotor: &Rotor<MAX_UNBALANCES>,
    limits: &Limits,
    file: &Path,
) -> Result<SupportAnalysis, SceneError> {
    SupportAnalysis::new(rotor, limits).map_err(|e| core_error(scene, file, "rotor", e))
}

/// The vibration machine with its auto-balancer (`None` without platforms).
pub fn machine(scene: &Scene, file: &Path) -> Result<Option<Machine>, SceneError> {
    let Some(ab) = &scene.autobalancer else {
        return Ok(None);
    };
    let platforms: Vec<Platform> = scene
        .platform
        .iter()
        .map(|p| Platform {
            mass: p.mass,
            stiffness: p.stiffness,
            damping: p.damping,
        })
        .collect();
    let couplings: Vec<Coupling> = scene
        .coupling
        .iter()
        .map(|c| Coupling {
            between: c.between,
            stiffness: c.stiffness,
            damping: c.damping,
        })
        .collect();
    let kind = match ab.kind {
        BalancerKindSpec::Ball => BalancerKind::Ball,
        BalancerKindSpec::Roller => BalancerKind::Roller,
        BalancerKindSpec::Pendulum => BalancerKind::Pendulum {
            inertia: ab.pendulum_inertia.ok_or_else(|| {
                SceneError::value(
                    file,
                    "autobalancer.pendulum_inertia",
                    "missing: a pendulum auto-balancer needs its pendulum inertia",
                )
            })?,
        },
    };
    let balancer = AutoBalancer {
        kind,
        platform: ab.platform,
        loads: ab.loads as u16,
        load_mass: ab.load_mass,
        radius: ab.radius,
        housing_mass: ab.housing_mass,
        viscosity: ab.viscosity,
    };
    let config = MachineConfig::new(&platforms, &couplings, balancer)
        .map_err(|e| core_error(scene, file, "autobalancer", e))?;
    Machine::new(config, SearchOptions::default())
        .map(Some)
        .map_err(|e| core_error(scene, file, "autobalancer", e))
}

/// One zone of the regime map.
#[derive(Debug, Clone, Serialize)]
pub struct ZoneOut {
    /// Lower end, rad/s.
    pub from: f64,
    /// Upper end, rad/s (null for the last, open zone).
    pub to: Option<f64>,
    /// "balancing" or "gathering".
    pub regime: &'static str,
}

/// A speed interval where gathered loads can be captured below the rotor speed.
#[derive(Debug, Clone, Serialize)]
pub struct CaptureOut {
    /// Lowest rotor speed of the window, rad/s.
    pub from: f64,
    /// Rotor speed above which capture is impossible, rad/s.
    pub until: f64,
    /// Load speed at the upper end, rad/s.
    pub at: f64,
}

impl From<&drive_monitor::balancer::CaptureWindow> for CaptureOut {
    fn from(c: &drive_monitor::balancer::CaptureWindow) -> Self {
        CaptureOut {
            from: c.from,
            until: c.until,
            at: c.at,
        }
    }
}

/// A change of stability of the balancing position (Floquet).
#[derive(Debug, Clone, Serialize)]
pub struct StabilityBoundaryOut {
    /// Speed, rad/s (placed to 1e-7 relative).
    pub speed: f64,
    /// Stable above, unstable below.
    pub stable_above: bool,
}

/// `autobalancer.stability` of `predict --json`: where the balancing position is stable.
#[derive(Debug, Clone, Serialize)]
pub struct StabilityOut {
    /// Speeds scanned, rad/s (the classes at the ends extend beyond).
    pub scanned: [f64; 2],
    /// Stable at the lowest speed scanned.
    pub stable_at_start: bool,
    /// Changes of stability, ascending.
    pub boundaries: Vec<StabilityBoundaryOut>,
    /// Each criterion boundary beside the nearest exact boundary of its kind.
    pub criterion: Vec<crate::app::regimes::Comparison>,
    /// Monodromy matrices integrated.
    pub evaluations: usize,
    /// Where the multiplier of the loads' slow drift along the balancing positions (neutral at
    /// D = 0) lay within the integration's resolution of 1 and was treated as neutral, as at
    /// D = 0 (absent: nowhere).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drift_treated_as_neutral: Option<crate::engine::vibration::floquet::Unresolved>,
    /// Where the spectral radius lay within the integration's resolution of 1 (the motion
    /// grows or decays by less than the resolution a revolution: an undamped one at every speed,
    /// or a slow crossing of 1 over a band) and the balancing position was taken as stable, a
    /// boundary there placed at the band's unstable edge (absent: nowhere).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub neutral_within_resolution: Option<crate::engine::vibration::floquet::Unresolved>,
    /// The scan starts above a quarter of the lowest resonance because a revolution below
    /// would take too many integration steps; below `speed` the regime table follows the
    /// criterion (absent: the scan starts where it would).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub criterion_below: Option<crate::app::regimes::CriterionBelow>,
}

/// One segment of the regime table.
#[derive(Debug, Clone, Serialize)]
pub struct SegmentOut {
    /// Lower edge, rad/s (the segment runs to the next one's).
    pub from: f64,
    /// "balancing", "gathering" or "bistable".
    pub regime: &'static str,
    /// Why bistable: "capture" or "coexisting".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<&'static str>,
}

/// `autobalancer` member of `predict --json`.
#[derive(Debug, Clone, Serialize)]
pub struct AutobalancerOut {
    /// `N·m·R`: the largest unbalance the loads can balance, kg·m.
    pub capacity: f64,
    /// The rotor unbalance the loads are to balance (`[autobalancer] rotor_unbalance`, default
    /// half the capacity), kg·m.
    pub rotor_unbalance: f64,
    /// Whether the scene left `rotor_unbalance` out (half the capacity assumed).
    pub rotor_unbalance_assumed: bool,
    /// `max(0, D − N·m·R)`: the least residual unbalance the loads can leave, kg·m (non-zero:
    /// the balancer is too small for its rotor; the loads at their limit, all opposite the
    /// unbalance, leave this much).
    pub residual_floor: f64,
    /// Exact stability of the balancing position (absent without one: a balancer too small).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability: Option<StabilityOut>,
    /// The regime table the run-time classifier is built from (margin not applied).
    pub regime_table: Vec<SegmentOut>,
    /// "exact" (from the stability above) or "criterion" (without a balancing position).
    pub regime_table_source: &'static str,
    /// Undamped resonant speeds the rotor excites, ascending, rad/s
    /// ([`crate::app::regimes::excited_speeds`]).
    pub resonant_speeds: Vec<f64>,
    /// Undamped additional speeds, ascending, rad/s, less those cancelled against a
    /// resonance.
    pub additional_speeds: Vec<f64>,
    /// Speeds where a resonance and an additional speed cancel: a mode with a node at the
    /// balancer's platform, which the rotor does not excite (absent when none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub unexcited_speeds: Vec<f64>,
    /// Zones with the scene's damping.
    pub zones: Vec<ZoneOut>,
    /// Sommerfeld capture windows (balancing locally stable, capture also possible).
    pub capture: Vec<CaptureOut>,
    /// Capture at every resonance, with or without a gathering zone of the criterion ending
    /// there ([`crate::app::regimes::resonance_captures`]): the exact table says bistable in
    /// these too.
    pub resonance_capture: Vec<CaptureOut>,
}

/// `irregularity` member of `predict --json`.
#[derive(Debug, Clone, Serialize)]
pub struct IrregularityOut {
    /// Largest steady-state speed, rad/s (null without a steady state).
    pub omega_max: Option<f64>,
    /// Smallest steady-state speed, rad/s (null without a steady state).
    pub omega_min: Option<f64>,
    /// δ = 2(ωmax − ωmin)/(ωmax + ωmin) (null without a steady state: the drive stalls).
    pub delta: Option<f64>,
    /// Whether a steady state exists (false: the motor stalls under the peak load).
    pub steady_state: bool,
    /// Extra flywheel for `[monitor] delta_limit`, kg·m² (0 if already within; absent
    /// without a limit; null when no flywheel within `shaft.flywheel`'s range reaches it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flywheel_for_limit: Option<Option<f64>>,
    /// Without a steady state, why: the mean load alone exceeds the motor's stall torque (no
    /// flywheel helps), or the peak load stalls it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stall: Option<&'static str>,
    /// ω min below the motor's breakdown speed: off the working branch the characteristic
    /// stands for (a real motor's torque falls past its breakdown point).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub working_branch_warning: Option<String>,
    /// ω max above the motor's no-load speed (a Kloss motor's synchronous speed): there the
    /// load drives the shaft and the motor brakes it as a generator ([`generator_note`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub generator_note: Option<String>,
    /// The δ alarm could judge no window: the noise floor at the predicted speed is above the
    /// fraction of `delta_limit` the core's alarm requires (its `floor_fraction`, 0.2).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub alarm_floor_warning: Option<String>,
    /// The predicted ω min is below the encoder's `monitor.min_speed`: the core would take
    /// those intervals for a standstill and measure nothing there.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub min_speed_warning: Option<String>,
    /// A harmonic's phase beyond a turn, likely meant in degrees ([`phase_warning`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase_warning: Option<String>,
    /// The scene also has a vibration machine (`[[platform]]`, `[autobalancer]`): the drive
    /// prediction leaves out the torque it puts on the shaft, which `run` simulates
    /// ([`machine_torque_warning`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub machine_torque_warning: Option<String>,
    /// The flywheel the limit would need when it is beyond `shaft.flywheel`'s range (up to
    /// 1e9 kg·m²), kg·m².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flywheel_beyond_range: Option<f64>,
    /// ∂δ/∂J, per kg·m².
    pub d_delta_d_inertia: Option<f64>,
    /// ∂δ/∂M_m, per N·m.
    pub d_delta_d_breakdown_torque: Option<f64>,
    /// The most δ of the steady state the core's speed samples (`encoder.estimator_edges`
    /// edges each, starting at the teeth) can show, over the load's phase against the teeth
    /// (absent without an `[encoder]`; [`sampled_delta`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_through_samples: Option<f64>,
    /// The least δ those samples show over the load's phase against the teeth: what the δ
    /// alarm can count on (the WARNING is judged on it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_through_samples_least: Option<f64>,
    /// What those samples show with the teeth where the scene has them (the simulator's
    /// wheel: tooth 0 at the load's φ = 0): what `run` measures.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub delta_through_samples_at_scene_phase: Option<f64>,
    /// The report's warning when those samples lose more than 1 % of δ.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sampling_warning: Option<String>,
    /// Why δ through the speed samples is not given for a steady state the host integrated
    /// over a long period, where the scene has an `[encoder]` ([`long_kloss_sampled`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sampling_note: Option<String>,
    /// For a Kloss motor: the prediction's parabola against the Kloss curve over the
    /// predicted speeds ([`kloss_note`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub motor_note: Option<String>,
    /// The steady state integrates the Kloss curve itself ([`kloss_note`]; text only).
    #[serde(skip)]
    pub kloss_curve: bool,
    /// ω max, ω min, δ, the flywheel and the sensitivities are approximate: a Kloss motor
    /// predicted through the parabola at its operating point, where the load's orders have no
    /// common period or one beyond what the host integrates (`motor_note` says which and
    /// why; [`kloss_note`]). Absent (false) where the curve itself or a parabola motor's own
    /// characteristic is integrated.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub approximate: bool,
    /// With `[shaft] inertia_harmonics`: how the J(φ) steady state was computed (absent for a
    /// constant inertia).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inertia_note: Option<String>,
}

/// How a J(φ) steady state was computed (`None` for a constant inertia).
pub fn inertia_note(model: &DriveModel) -> Option<String> {
    use drive_monitor::drive::Horizon;
    let (radians, nodes) = match model.horizon() {
        Horizon::Varying { radians, nodes } => (radians, nodes),
        Horizon::Shooting { radians, .. } if !model.inertia_harmonics().is_empty() => {
            let n = model.inertia_harmonics().len();
            let curve = if model.motor().kloss_curve().is_some() {
                "the Kloss curve"
            } else {
                "the parabola (the motor is so stiff against the inertia's swing that the \
                 trapezoid solution's integrating factor would swing by more than e^12)"
            };
            return Some(format!(
                "J(φ) from shaft.inertia_harmonics ({n} harmonic{}): eq. 1 in w = J·ω² with \
                 {curve}, integrated over its period of {radians:.4} rad (see the motor line); \
                 ∂δ/∂J and ∂δ/∂M_m by central differences",
                if n == 1 { "" } else { "s" }
            ));
        }
        _ => return None,
    };
    Some(format!(
        "J(φ) from shaft.inertia_harmonics ({} harmonic{}): eq. 1, linear in w = J·ω², solved \
         over its period of {:.4} rad by the trapezoid rule on {nodes} nodes; ∂δ/∂J and \
         ∂δ/∂M_m by central differences",
        model.inertia_harmonics().len(),
        if model.inertia_harmonics().len() == 1 {
            ""
        } else {
            "s"
        },
        radians
    ))
}

/// The note for a J(φ) the host integrates with the Kloss curve over a long common period
/// ([`long_period_inertia`]; `None` without one).
fn long_inertia_note(inertia: &[InertiaHarmonic]) -> Option<String> {
    let n = inertia.iter().filter(|h| h.amplitude() != 0.0).count();
    (n > 0).then(|| {
        format!(
            "J(φ) from shaft.inertia_harmonics ({n} harmonic{}): eq. 1 in w = J·ω² with the \
             Kloss curve, integrated on the host over the common period of the load and \
             inertia orders (see the motor line; the core's shooting takes the same equation \
             over shorter periods); ∂δ/∂J (on the constant part of J) and ∂δ/∂M_m by central \
             differences",
            if n == 1 { "" } else { "s" }
        )
    })
}

/// The note for a steady state that runs above the motor's no-load speed (the synchronous
/// speed of a Kloss motor), where its torque is negative: the load (a negative mean, or a
/// harmonic's swing) drives the shaft and the motor brakes it as a generator. The parabola
/// is fitted between breakdown and no-load speed and continues past it; the Kloss curve
/// has its generator branch. `None` when ω max is at most that speed.
pub fn generator_note(model: &DriveModel, omega_min: f64, omega_max: f64) -> Option<String> {
    let motor = model.motor();
    let (speed, name, branch) = match motor.kloss_curve() {
        Some(k) => (
            k.synchronous_speed(),
            "synchronous speed",
            "the Kloss curve's generator branch",
        ),
        None => (
            motor.model().no_load_speed(),
            "no-load speed",
            "the parabola continued past its no-load point (it is fitted between breakdown \
             and no-load speed)",
        ),
    };
    if omega_max.partial_cmp(&speed) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let part = if omega_min > speed {
        "throughout the period"
    } else {
        "for part of the period"
    };
    let mean = model.load().mean();
    let active = if mean < 0.0 {
        format!(" (the mean load {mean} N·m is negative: an active torque that drives the shaft)")
    } else {
        String::new()
    };
    Some(format!(
        "NOTE: ω max {omega_max:.3} rad/s is above the motor's {name} {speed:.3} rad/s: \
         {part} the load drives the shaft and the motor brakes it as a generator{active}; \
         its torque there is {branch}"
    ))
}

/// The note for a run whose shaft turned backwards under a motor and a load: the load is
/// modelled as an active torque (it keeps its sign at any speed, as a hoist's weight does), so
/// where it exceeds the motor's torque at standstill it turns the shaft backwards; a reactive
/// load (friction, kneading, a fan) would stall it instead. `None` without a torque motor and
/// a load, or when the load's peak (its mean and every amplitude) stays below that torque.
pub fn active_load_note(scene: &Scene, file: &Path) -> Option<String> {
    let (motor, load, ..) = drive_parts_of(scene, file).ok()??;
    let peak = load.mean()
        + load
            .harmonics()
            .iter()
            .map(|h| h.amplitude().abs())
            .sum::<f64>();
    let standstill = motor.torque(0.0);
    if peak.partial_cmp(&standstill) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let which = if load.mean() > standstill {
        format!("the mean load {} N·m", load.mean())
    } else {
        format!("the load's peak {peak:.4} N·m")
    };
    Some(format!(
        "NOTE: {which} exceeds the motor's torque at standstill, {standstill:.4} N·m, and the \
         load is modelled as an active torque (its sign whatever the speed, as a hoist's \
         weight): where it exceeds the motor's torque it turns the shaft backwards; a reactive \
         load (friction, kneading, a fan) would stall the shaft instead"
    ))
}

/// How `predict` took a Kloss drive the core predicts through a parabola
/// ([`drive_monitor::drive::Horizon::Unbounded`], constant inertia), or whose J(φ) it refuses
/// for a common period of the load and inertia orders too long for its shooting
/// ([`long_period_inertia`]).
#[derive(Debug, Clone)]
pub enum LongKloss {
    /// The load's orders have a common period the core does not sample (more than
    /// [`drive_monitor::drive::MAX_SAMPLES`] samples): the curve itself integrated on the host
    /// over the whole period ([`crate::app::kloss_period`]).
    Integrated {
        /// The period.
        period: kloss_period::Period,
        /// The periodic steady state.
        steady: kloss_period::Steady,
    },
    /// No steady state at all: the mean load is at or beyond the curve's breakdown torque
    /// (`|M1| ≥ M_m`), no speed carries it.
    MeanLoad,
    /// No steady state on the host's integration over the period: the drive falls to
    /// standstill from above every periodic solution, it stalls under the peak load (more
    /// flywheel can help).
    Stalls {
        /// The period.
        period: kloss_period::Period,
        /// `ω̄²`, the square of the speed that carries the mean load, s⁻².
        u_mean: f64,
    },
    /// Predicted through the parabola at the operating point (approximate): why.
    Approximate(Approximation),
}

/// Why a Kloss drive's steady state was not integrated.
#[derive(Debug, Clone, Copy)]
pub enum Approximation {
    /// The load's orders have no common period (not rationals with denominator ≤
    /// [`drive_monitor::drive::MAX_DENOMINATOR`]): no periodic solution exists.
    NoCommonPeriod,
    /// The common period needs more than [`kloss_period::MAX_STEPS`] steps.
    TooLong(kloss_period::Period),
    /// The host's integration over the period found no attracting steady state.
    Failed(kloss_period::Period, kloss_period::Failure),
}

/// The host's drive for `model` with the J(φ) harmonics `inertia` (none: `model`'s constant
/// inertia); `None` without a Kloss motor.
fn long_drive(model: &DriveModel, inertia: &[InertiaHarmonic]) -> Option<kloss_period::Drive> {
    let k = *model.motor().kloss_curve()?;
    Some(
        kloss_period::Drive::new(k, model.total_inertia(), model.load())
            .with_inertia_harmonics(inertia),
    )
}

/// The host's integration of a Kloss drive the core leaves to a parabola, when it can be done
/// ([`LongKloss`]): `model` with a constant inertia and [`Horizon::Unbounded`] and `inertia`
/// empty, or `model` the constant part of a J(φ) drive and `inertia` its harmonics
/// ([`long_period_inertia`]). `None` for any other drive (a parabola motor, one the core
/// integrates).
///
/// [`Horizon::Unbounded`]: drive_monitor::drive::Horizon::Unbounded
pub fn long_kloss(model: &DriveModel, inertia: &[InertiaHarmonic]) -> Option<LongKloss> {
    let k = *model.motor().kloss_curve()?;
    if !model.inertia_harmonics().is_empty()
        || (inertia.is_empty()
            && !matches!(model.horizon(), drive_monitor::drive::Horizon::Unbounded))
    {
        return None;
    }
    let drive = long_drive(model, inertia)?;
    if drive.mean_load().is_nan() || drive.mean_load().abs() >= k.breakdown_torque() {
        return Some(LongKloss::MeanLoad);
    }
    let orders = long_orders(model.load(), inertia);
    let Some(period) = kloss_period::common_period(&orders) else {
        return Some(LongKloss::Approximate(Approximation::NoCommonPeriod));
    };
    Some(match drive.solve(&period, Some(model.omega_squared(0.0))) {
        Ok(steady) => LongKloss::Integrated { period, steady },
        Err(kloss_period::Failure::MeanLoad) => LongKloss::MeanLoad,
        Err(kloss_period::Failure::Stalls) => LongKloss::Stalls {
            period,
            u_mean: model.u_mean(),
        },
        Err(kloss_period::Failure::Steps) => LongKloss::Approximate(Approximation::TooLong(period)),
        Err(e) => LongKloss::Approximate(Approximation::Failed(period, e)),
    })
}

/// The δ `predict` gives for `model`'s steady state (`None` without one): the core's, or for a
/// Kloss drive the core leaves to a parabola, the host's integration over a long common period
/// ([`long_kloss`], with the J(φ) harmonics `inertia` of [`long_period_inertia`]); `run`
/// compares its measurement with this.
pub fn predicted_delta(model: &DriveModel, inertia: &[InertiaHarmonic]) -> Option<f64> {
    predicted_delta_of(model, inertia, long_kloss(model, inertia).as_ref())
}

/// [`predicted_delta`] with the host's outcome `long` at hand.
fn predicted_delta_of(
    model: &DriveModel,
    inertia: &[InertiaHarmonic],
    long: Option<&LongKloss>,
) -> Option<f64> {
    match long {
        Some(LongKloss::Integrated { steady, .. }) => Some(steady.delta),
        Some(LongKloss::MeanLoad | LongKloss::Stalls { .. }) => None,
        // A J(φ) the host did not solve: the constant part's δ is not this drive's.
        Some(LongKloss::Approximate(_)) if !inertia.is_empty() => None,
        Some(LongKloss::Approximate(_)) | None => model.predict().steady().map(|s| s.delta),
    }
}

/// The δ `predict` gives (as [`predicted_delta`]) and what the speed samples read of it (as
/// `predict` gives them: [`sampled_delta`], or for the host's integration
/// [`long_kloss_sampled`]), for `run`'s report.
pub fn predicted_and_sampled(
    scene: &Scene,
    file: &Path,
    model: &DriveModel,
) -> Result<(Option<f64>, Option<SampledDelta>), SceneError> {
    let inertia = long_period_inertia(scene);
    let long = long_kloss(model, &inertia);
    let delta = predicted_delta_of(model, &inertia, long.as_ref());
    let sampled = match &long {
        Some(LongKloss::Integrated { period, steady }) => {
            long_kloss_sampled(scene, file, model, &inertia, period, steady)?.0
        }
        Some(LongKloss::MeanLoad | LongKloss::Stalls { .. }) => None,
        Some(LongKloss::Approximate(_)) if !inertia.is_empty() => None,
        Some(LongKloss::Approximate(_)) | None => sampled_delta(scene, file, model)?,
    };
    Ok((delta, sampled))
}

/// The time over the angle of the host's periodic steady state `steady` of `model` with the
/// J(φ) harmonics `inertia` over `period` ([`crate::app::sampled::SteadyTime::tabulate`],
/// ω from the integration's own steps: [`kloss_period::Drive::cursor`]), or why there is none.
pub fn long_kloss_time(
    model: &DriveModel,
    inertia: &[InertiaHarmonic],
    period: &kloss_period::Period,
    steady: &kloss_period::Steady,
) -> Result<crate::app::sampled::SteadyTime, String> {
    use crate::app::sampled::{SteadyTime, MAX_SAMPLED_POINTS};
    let drive = long_drive(model, inertia).ok_or("no Kloss motor")?;
    let fastest = long_orders(model.load(), inertia)
        .into_iter()
        .map(f64::abs)
        .fold(0.0f64, f64::max);
    // The period, Q/G revolutions, divides the whole revolutions Q: the table spans it.
    if SteadyTime::points(period.radians, fastest).is_none() {
        return Err(format!(
            "the time over the period, {} cycles of its fastest order at 512 values of ω a \
             cycle, would take more than the {MAX_SAMPLED_POINTS} values the table holds",
            period.cycles
        ));
    }
    let mut cursor = drive.cursor(period, steady).map_err(|e| format!("{e:?}"))?;
    SteadyTime::tabulate(period.radians, period.whole_revolutions, fastest, |phi| {
        cursor.omega(phi)
    })
    .ok_or_else(|| "the integration stalled between its steps".to_string())
}

/// [`SampledDelta`] of the host's periodic steady state ([`long_kloss_time`]) through the
/// scene's speed samples, and, where the scene has an `[encoder]` and none is given, the line
/// that says why.
pub fn long_kloss_sampled(
    scene: &Scene,
    file: &Path,
    model: &DriveModel,
    inertia: &[InertiaHarmonic],
    period: &kloss_period::Period,
    steady: &kloss_period::Steady,
) -> Result<(Option<SampledDelta>, Option<String>), SceneError> {
    if scene.encoder.is_none() {
        return Ok((None, None));
    }
    let mut why = None;
    let sampled = sampled_delta_of(scene, file, steady.delta, || {
        long_kloss_time(model, inertia, period, steady)
            .map_err(|e| why = Some(e))
            .ok()
    })?;
    let note = match (&sampled, why) {
        (Some(_), _) => None,
        (None, Some(why)) => Some(why),
        (None, None) => Some(format!(
            "the encoder's edges over the common period of the load and the revolution \
             ({} revolutions) are more than the {} the samples are enumerated over",
            period.whole_revolutions,
            crate::app::sampled::MAX_EDGES
        )),
    };
    Ok((
        sampled,
        note.map(|n| {
            format!(
                "NOTE: δ through the speed samples is not given for this steady state, \
                 integrated on the host: {n}"
            )
        }),
    ))
}

/// Relative step of the host's central differences (the core's).
const SENSITIVITY_STEP: f64 = 1e-4;

/// ∂δ/∂J and ∂δ/∂M_m of a drive the host integrates, by central differences with the core's
/// relative step 1e-4 (the total inertia; the whole curve scaled with M_m), as the core does
/// them for `Horizon::Shooting`. `None` when a stepped drive has no steady state.
pub fn long_kloss_sensitivity(
    model: &DriveModel,
    inertia: &[InertiaHarmonic],
    period: &kloss_period::Period,
) -> Option<drive_monitor::drive::Sensitivity> {
    let k = *model.motor().kloss_curve()?;
    let drive = long_drive(model, inertia)?;
    // Each from the start the operating point's parabola gives the stepped drive.
    let delta = |d: Option<kloss_period::Drive>, m: Option<DriveModel>| {
        let start = m.map(|m| m.omega_squared(0.0));
        d?.solve(period, start).ok().map(|s| s.delta)
    };
    let j = drive.inertia();
    let h = SENSITIVITY_STEP * j;
    let fly = |x: f64| model.with_flywheel(model.flywheel() + x).ok();
    let d_inertia = (delta(Some(drive.with_inertia(j + h)), fly(h))?
        - delta(Some(drive.with_inertia(j - h)), fly(-h))?)
        / (2.0 * h);
    let scaled = |f: f64| {
        model
            .motor()
            .scaled(f)
            .and_then(|m| model.with_motor(m).ok())
    };
    let d_torque = (delta(
        drive.scaled(1.0 + SENSITIVITY_STEP),
        scaled(1.0 + SENSITIVITY_STEP),
    )? - delta(
        drive.scaled(1.0 - SENSITIVITY_STEP),
        scaled(1.0 - SENSITIVITY_STEP),
    )?) / (2.0 * SENSITIVITY_STEP * k.breakdown_torque());
    (d_inertia.is_finite() && d_torque.is_finite()).then_some(drive_monitor::drive::Sensitivity {
        d_delta_d_inertia: d_inertia,
        d_delta_d_breakdown_torque: d_torque,
    })
}

/// The extra flywheel (kg·m²) that brings the host-integrated δ of `model` to `limit` (0 if
/// within), as the core sizes it on `Horizon::Shooting`: the upper end of a bracket of the
/// added inertia within 1e-10 relative where δ ≤ `limit` holds (`delta` infinite for a drive
/// that stalls). The bracket's upper end starts from δ ∝ 1/J and doubles until the limit is
/// met; it is narrowed by regula falsi (Illinois)
/// on `1/δ`, nearly linear in J, then bisection where that stalls. `None` when no flywheel up
/// to 2⁶⁰ times the inertia reaches it, or a solution fails.
pub fn long_kloss_flywheel(
    model: &DriveModel,
    inertia: &[InertiaHarmonic],
    period: &kloss_period::Period,
    delta: f64,
    limit: f64,
) -> Option<f64> {
    let drive = long_drive(model, inertia)?;
    let j = drive.inertia();
    if delta <= limit {
        return Some(0.0);
    }
    // f(x) = 1/δ − 1/limit at J + x: negative below the answer (a stall as δ = ∞).
    let f = |x: f64| -> Option<f64> {
        let start = model
            .with_flywheel(model.flywheel() + x)
            .ok()
            .map(|m| m.omega_squared(0.0));
        match drive.with_inertia(j + x).solve(period, start) {
            Ok(s) => Some(1.0 / s.delta - 1.0 / limit),
            Err(kloss_period::Failure::Stalls) => Some(-1.0 / limit),
            Err(_) => None,
        }
    };
    let (mut lo, mut f_lo) = (0.0, 1.0 / delta - 1.0 / limit);
    // From δ ∝ 1/J; a stalled drive (δ = ∞) from doubling its inertia.
    let mut hi = if delta.is_finite() {
        j * (delta / limit - 1.0) * 1.01
    } else {
        j
    };
    let mut f_hi = f(hi)?;
    let mut doublings = 0;
    while f_hi < 0.0 {
        (lo, f_lo) = (hi, f_hi);
        hi *= 2.0;
        doublings += 1;
        if doublings > 60 {
            return None;
        }
        f_hi = f(hi)?;
    }
    // Illinois: the end kept twice in a row has its value halved.
    let mut side = 0i8;
    for _ in 0..200 {
        if hi - lo <= 1e-10 * (j + hi) {
            break;
        }
        let x = if f_hi > f_lo {
            lo + (hi - lo) * (-f_lo / (f_hi - f_lo))
        } else {
            f64::NAN
        };
        let x = if x > lo && x < hi {
            x
        } else {
            lo + (hi - lo) / 2.0
        };
        let fx = f(x)?;
        if fx >= 0.0 {
            (hi, f_hi) = (x, fx);
            if side == 1 {
                f_lo *= 0.5;
            }
            side = 1;
        } else {
            (lo, f_lo) = (x, fx);
            if side == -1 {
                f_hi *= 0.5;
            }
            side = -1;
        }
    }
    Some(hi)
}

/// What a Kloss motor's prediction stands on. With a common period of the load (and
/// inertia) orders the core integrates the Kloss curve itself over one period
/// ([`drive_monitor::drive::Horizon::Shooting`]: eq. 1 in `w = J·ω²`, sixth-order Runge–Kutta,
/// Newton on the periodic start), the same curve `run` integrates; the note says so, with the
/// step count. A common period too long for the core's samples is integrated on the host over
/// the whole period (`long` is [`LongKloss::Integrated`]: [`crate::app::kloss_period`]); the
/// note gives the period, the steps and the settling, or says that the drive stalls
/// ([`LongKloss::Stalls`]). Without a common period (no periodic
/// solution exists), or one beyond the host's [`kloss_period::MAX_STEPS`], the Kloss curve is
/// replaced by the parabola through its operating point with its slope there
/// ([`Kloss::operating_point_fit`]), the result is marked approximate (`approximate` in the
/// JSON), and the note says why, with the largest difference between the parabola and the
/// curve over the predicted speeds `[omega_min, omega_max]` (65 points), in N·m and in % of the
/// curve's torque there. `None` for a parabola motor.
pub fn kloss_note(
    model: &DriveModel,
    omega_min: f64,
    omega_max: f64,
    long: Option<&LongKloss>,
    inertia: &[InertiaHarmonic],
) -> Option<String> {
    use drive_monitor::drive::Horizon;
    let motor = model.motor();
    let k = motor.kloss_curve()?;
    // The host's outcome first: with J(φ) the model is its constant part, which the core may
    // integrate over the load's own (shorter) period.
    let horizon = if long.is_some() {
        Horizon::Unbounded
    } else {
        model.horizon()
    };
    let whose = if inertia.is_empty() {
        "the load's"
    } else {
        "the load and inertia orders'"
    };
    match horizon {
        Horizon::Shooting { radians, steps } if steps > 0 => {
            return Some(format!(
                "the Kloss motor is predicted with its curve itself (eq. 1 in w = J·ω² \
                 integrated over the period of {radians:.4} rad, sixth-order Runge–Kutta on \
                 {steps} steps, Newton on the periodic start; `run` integrates the same \
                 curve; ∂δ/∂J and ∂δ/∂M_m by central differences)"
            ))
        }
        Horizon::Shooting { .. } | Horizon::Constant => {
            return Some(
                "the Kloss motor is predicted with its curve itself (`run` integrates the same \
                 curve)"
                    .to_string(),
            )
        }
        _ => {}
    }
    let revolutions = |p: &kloss_period::Period| {
        if p.revolutions == p.whole_revolutions as f64 {
            format!("{} revolutions", p.whole_revolutions)
        } else {
            format!(
                "{:.3} revolutions ({} in whole revolutions)",
                p.revolutions, p.whole_revolutions
            )
        }
    };
    let why = match long {
        Some(LongKloss::Integrated { period, steady }) => {
            return Some(format!(
                "the Kloss motor is predicted with its curve itself over {whose} whole common \
                 period, {} ({} cycles of the fastest order: {} samples at 32 a cycle, more \
                 than the core's {}): eq. 1 in w = J·ω² integrated on the host by sixth-order \
                 Runge–Kutta on {} steps a period ({} a cycle of the fastest order), settled \
                 over {} steps ({:.0} e-foldings of its damping) before the period, {} \
                 period{} of Newton on the periodic start (|y(T) − y(0)| {:.1e} of the largest \
                 |y|); `run` integrates the same curve; ∂δ/∂J and ∂δ/∂M_m by central \
                 differences, the flywheel by bracketing",
                revolutions(period),
                period.cycles,
                period
                    .cycles
                    .saturating_mul(drive_monitor::drive::SAMPLES_PER_CYCLE),
                drive_monitor::drive::MAX_SAMPLES,
                steady.steps,
                steady.steps / period.cycles.max(1),
                steady.settle_steps,
                kloss_period::SETTLE_FOLDS,
                steady.periods,
                if steady.periods == 1 { "" } else { "s" },
                steady.residual
            ))
        }
        Some(LongKloss::MeanLoad) => {
            return Some(format!(
                "the mean load is at or beyond the Kloss curve's breakdown torque M_m = {} N·m: \
                 no speed carries it",
                k.breakdown_torque()
            ))
        }
        Some(LongKloss::Stalls { period, .. }) => {
            return Some(format!(
                "the Kloss motor's curve, integrated on the host over {whose} whole common \
                 period, {} ({} cycles of the fastest order), falls to standstill even from \
                 above every periodic solution (from ω_s·(1 + σ_m)): no periodic steady state \
                 exists; `run` integrates the same curve",
                revolutions(period),
                period.cycles
            ))
        }
        Some(LongKloss::Approximate(Approximation::TooLong(p))) => format!(
            "the load's common period, {}, holds {} cycles of the fastest order, more than \
             the {} steps the host integrates over, so its periodic steady state is not \
             integrated",
            revolutions(p),
            p.cycles,
            kloss_period::MAX_STEPS
        ),
        Some(LongKloss::Approximate(Approximation::Failed(p, e))) => format!(
            "the host's integration over the load's common period, {}, found no attracting \
             periodic steady state ({e:?})",
            revolutions(p)
        ),
        _ => "the load's orders have no common period, so no periodic steady state exists to \
              integrate"
            .to_string(),
    };
    let p = motor.model();
    let tangent = k
        .fit(drive_monitor::drive::KlossFit::SynchronousTangent)
        .ok()
        .is_some_and(|t| t == *p);
    let head = if tangent {
        format!(
            "{why}: APPROXIMATE, the Kloss motor is predicted through its tangent parabola at \
             synchronous speed (A = {:.5e} N·m·s², B = {:.3} N·m; `run` integrates the curve \
             itself); this is no bound for the Kloss drive: at a loaded drive's slip the curve \
             lies below the parabola and is softer, so the drive runs slower than predicted and \
             its δ can be larger",
            p.a(),
            p.b()
        )
    } else {
        format!(
            "{why}: APPROXIMATE, the Kloss motor is predicted through the parabola with the \
             curve's torque and slope at the operating point, the speed where the curve \
             carries the mean load (A = {:.5e} N·m·s², B = {:.3} N·m; `run` integrates the \
             curve itself), with the parabola's extrema ū ± Σ R_k over an unbounded horizon: \
             the mean speed and the damping are the curve's to first order in the swing, the \
             curve's bend over the swing is left out",
            p.a(),
            p.b()
        )
    };
    let caveat = "; `run` with a `[monitor] window_revolutions` of many load cycles measures \
                  the drive";
    if !(omega_min > 0.0 && omega_max >= omega_min) {
        return Some(format!("{head}{caveat}"));
    }
    let (mut worst, mut at) = (0.0f64, omega_min);
    for i in 0..=64 {
        let w = omega_min + (omega_max - omega_min) * f64::from(i) / 64.0;
        let d = p.torque(w) - k.torque(w);
        if d.abs() > worst.abs() {
            (worst, at) = (d, w);
        }
    }
    let curve = k.torque(at);
    let share = if curve != 0.0 {
        format!(
            " ({:+.2} % of the curve's {curve:.3} N·m)",
            100.0 * worst / curve
        )
    } else {
        String::new()
    };
    // Four decimals, or four significant digits below 0.01 N·m (the operating point's
    // parabola stays that close to the curve over a small swing).
    let worst = if worst.abs() >= 0.01 || worst == 0.0 {
        format!("{worst:+.4}")
    } else {
        format!("{worst:+.3e}")
    };
    Some(format!(
        "{head}; over the predicted speeds the parabola differs from the curve by at most \
         {worst} N·m at {at:.3} rad/s{share}{caveat}"
    ))
}

/// `supports` member of `predict --json`.
#[derive(Debug, Clone, Serialize)]
pub struct SupportsOut {
    /// |D_A|, kg·m.
    pub unbalance_a: f64,
    /// |D_B|, kg·m.
    pub unbalance_b: f64,
    /// Permissible residual unbalance allocated to A, kg·m.
    pub permissible_a: f64,
    /// Permissible residual unbalance allocated to B, kg·m.
    pub permissible_b: f64,
    /// Largest safe speed, rad/s (null without load limits, or when no unbalance limits it:
    /// `max_speed_status` tells the two apart).
    pub max_speed: Option<f64>,
    /// What `max_speed` is: "limited" (the support loads reach their limits at it; it may
    /// exceed the 1e5 rad/s any scene can turn), "not_limited" (load limits given, and no
    /// speed brings the loads to them: no unbalance) or "no_load_limit" (no
    /// `rotor.support_load_limit` given: not computed).
    pub max_speed_status: &'static str,
    /// Why `max_speed` is 0: the supports whose static load alone reaches their limit, each
    /// named with both figures ([`static_overload`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub no_safe_speed: Option<String>,
    /// Static support loads (weight and process load), N.
    pub static_load: [f64; 2],
    /// Peak support loads over one turn at the service speed, N.
    pub peak_load_at_service_speed: [f64; 2],
    /// Each plane's unbalance against its permissible share: "normal" | "warning" | "over"
    /// (warning above `rotor.warning_fraction` of it).
    pub unbalance_level: [&'static str; 2],
    /// Each peak load at the service speed against `support_load_limit` (null without).
    pub load_level: Option<[&'static str; 2]>,
    /// The predicted drive's ω max, rad/s, where the supports are judged as `run` judges them
    /// at its window's ω max (absent without a predicted steady state of the drive).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub predicted_speed: Option<f64>,
    /// `predicted_speed` is the top speed a prescribed drive (`model = "speed"`, `"ramp"`,
    /// `"profile"`, a cranking ripple's peak included) puts the shaft at, not a prediction.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub speed_prescribed: bool,
    /// Peak support loads over one turn at `predicted_speed`, N.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_load_at_predicted_speed: Option<[f64; 2]>,
    /// Each peak load at `predicted_speed` against `support_load_limit`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub load_level_at_predicted_speed: Option<[&'static str; 2]>,
    /// The WARNING when `predicted_speed` is above the service speed
    /// ([`crate::app::run::above_service_speed`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub above_service_speed: Option<String>,
    /// How the permissible unbalance was allotted to the planes: "inboard" (ISO 21940-11's
    /// lever rule, shares held within 30–70 %) or "overhung" (this product's rule:
    /// `supports::Allocation::Overhung`).
    pub allocation: &'static str,
    /// The scene also has an auto-balancer, which the support analysis leaves out
    /// ([`balancer_supports_warning`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub balancer_warning: Option<String>,
    /// The unbalances imply an eccentricity longer than the rotor ([`unbalance_warning`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub unbalance_warning: Option<String>,
}

/// The WARNING when the scene's unbalances, all in one direction, would put the rotor's centre
/// of mass farther off its axis than the rotor is long (the extent of its supports, centre of
/// mass, unbalance planes and process load along the axis): no rotor is that eccentric, and
/// it is the mark of a unit slip (ISO 21940 quotes unbalance in g·mm, 1e-6 of the kg·m a
/// scene takes: 2000 g·mm entered as 2000 kg·m). Such a scene is still analysed, as given.
/// `None` without a rotor or when the eccentricity is within that length.
pub fn unbalance_warning(scene: &Scene) -> Option<String> {
    let rotor = scene.rotor.as_ref()?;
    let total: f64 = scene.unbalance.iter().map(|u| u.amount.abs()).sum();
    let eccentricity = total / rotor.mass;
    let axial = [rotor.support_a, rotor.support_b, rotor.centre_of_mass]
        .into_iter()
        .chain(scene.unbalance.iter().map(|u| u.z))
        .chain(scene.process_load.iter().flat_map(|p| [p.from, p.to]));
    let (lo, hi) = axial.fold((f64::MAX, f64::MIN), |(lo, hi), z| (lo.min(z), hi.max(z)));
    let length = hi - lo;
    if eccentricity.partial_cmp(&length) != Some(core::cmp::Ordering::Greater) {
        return None;
    }
    let (k, largest) = scene
        .unbalance
        .iter()
        .enumerate()
        .max_by(|a, b| a.1.amount.abs().total_cmp(&b.1.amount.abs()))?;
    Some(format!(
        "WARNING: the unbalances add up to {total:.4e} kg·m, an eccentricity of {eccentricity:.4e} m \
         of the {} kg rotor, more than its {length:.4} m along the axis: no rotor is that \
         eccentric; a unit slip? `unbalance[{}].amount = {}` is in kg·m (ISO 21940 quotes \
         g·mm: 1 g·mm = 1e-6 kg·m)",
        rotor.mass,
        k + 1,
        largest.amount
    ))
}

/// Why the supports allow no speed at all: each support whose static load (weight and
/// process load) alone reaches its `rotor.support_load_limit`, where any unbalance load puts
/// it over ([`drive_monitor::supports::max_safe_speed`] is 0 there). `None` when some speed is
/// safe or there are no limits.
pub fn static_overload(a: &drive_monitor::supports::SupportAnalysis) -> Option<String> {
    let (limit, speed) = (a.load_limit?, a.max_speed?);
    let over: Vec<String> = (0..2)
        .filter(|&k| speed[k] == 0.0)
        .map(|k| {
            let load = a.static_load[k].norm();
            format!(
                "support {}'s static load alone, {} N, {} its limit `rotor.support_load_limit[{}]` \
                 = {} N{}",
                ["A", "B"][k],
                crate::app::report::fmt_force(load),
                if load > limit[k] { "exceeds" } else { "reaches" },
                k + 1,
                crate::app::report::fmt_force(limit[k]),
                if load > limit[k] {
                    " (over at standstill)"
                } else {
                    " (any unbalance load puts it over)"
                }
            )
        })
        .collect();
    (!over.is_empty()).then(|| format!("{}: no speed is safe", over.join("; ")))
}

/// The warning when the noise floor a window of `scene` reports at the predicted speed
/// ([`drive_monitor::encoder::Encoder::noise_floor_at`], `2·ω̄/(K·timer_hz·pitch)` for
/// `K = encoder.estimator_edges` edges of `pitch` rad each) is above the fraction of the limit
/// (0.2) under which the core's alarm judges every window: above it the alarm judges only a δ
/// farther than the floor from the limit, and the warning says whether the predicted δ is.
fn alarm_floor_warning(
    scene: &Scene,
    file: &Path,
    limit: Option<f64>,
    prediction: &drive_monitor::drive::Prediction,
) -> Result<Option<String>, SceneError> {
    let (Some(limit), Some(steady)) = (limit, prediction.steady()) else {
        return Ok(None);
    };
    let Some(encoder) = crate::app::run::core_encoder(scene, file)? else {
        return Ok(None);
    };
    let floor = f64::from(encoder.noise_floor_at(steady.omega_rms as f32));
    let alarm = drive_monitor::alarm::AlarmConfig::new(limit as f32);
    let fraction = alarm.floor_fraction;
    let clearing = limit * (1.0 - f64::from(alarm.hysteresis));
    let delta = steady.delta;
    // As the core judges a window whose floor is large against the limit (`DeltaAlarm::judge`).
    let verdict = if delta - floor > limit {
        format!("the predicted δ {delta:.4} is over it by more than the floor: judged over")
    } else if delta + floor < clearing {
        format!(
            "the predicted δ {delta:.4} is under the clearing level {clearing:.4} by more than \
             the floor: judged within"
        )
    } else {
        format!(
            "the predicted δ {delta:.4} lies within the floor of the limit: the core's alarm \
             would judge few windows or none"
        )
    };
    Ok((floor > f64::from(fraction) * limit).then(|| {
        format!(
            "WARNING: at the predicted mean speed a window's noise floor is {floor:.2e}, above \
             {fraction} of the δ limit {limit}: the alarm judges such a window only where its δ \
             lies farther than the floor from the limit, and {verdict} (a faster \
             `encoder.timer_hz` or more `encoder.estimator_edges` lower the floor)"
        )
    }))
}

/// The warning when the predicted ω min is below the slowest speed the encoder's monitor takes
/// for running (`monitor.min_speed`, 1 rad/s by default): a kiln-like drive at 0.46–0.54 rad/s
/// was predicted without a word, and `run` then measured nothing.
fn min_speed_warning(
    scene: &Scene,
    file: &Path,
    prediction: &drive_monitor::drive::Prediction,
) -> Result<Option<String>, SceneError> {
    let Some(steady) = prediction.steady() else {
        return Ok(None);
    };
    let Some(encoder) = crate::app::run::core_encoder(scene, file)? else {
        return Ok(None);
    };
    let min_speed = encoder.config().min_speed;
    let given = scene.monitor.as_ref().and_then(|m| m.min_speed).is_some();
    Ok((steady.omega_min < min_speed).then(|| {
        format!(
            "WARNING: monitor.min_speed = {min_speed} rad/s{} is above the predicted ω min \
             {:.4} rad/s: the core takes an interval slower than it for a standstill, and \
             measures {} (set monitor.min_speed below the ω min)",
            if given { "" } else { " (the default)" },
            steady.omega_min,
            if steady.omega_max < min_speed {
                "nothing at all"
            } else {
                "no window across the slow part of each cycle"
            }
        )
    }))
}

/// The WARNING for phases (in radians) beyond a turn: `load.harmonics[k].phase`,
/// `shaft.inertia_harmonics[k].phase` and `cranking.phase` are radians where the rotor's angles
/// (`[[unbalance]] angle`, `[process_load] angle`) are degrees, and `phase = 90` was read as 90
/// rad without a word (with two harmonics, δ depends on it). `None` when every phase is within
/// ±2π.
pub fn phase_warning(scene: &Scene) -> Option<String> {
    // Every harmonic phase of the scene, with its key (numbered from 1 within its table).
    let numbered = |table: &'static str, phases: Vec<f64>| {
        phases
            .into_iter()
            .enumerate()
            .map(move |(k, phase)| (format!("{table}[{}].phase", k + 1), phase))
    };
    let load = scene
        .load
        .iter()
        .flat_map(|l| l.harmonics.iter().map(|h| h.phase));
    let inertia = scene
        .shaft
        .iter()
        .flat_map(|s| s.inertia_harmonics.iter().map(|h| h.phase));
    let over: Vec<String> = numbered("load.harmonics", load.collect())
        .chain(numbered("shaft.inertia_harmonics", inertia.collect()))
        .chain(
            scene
                .cranking
                .map(|c| ("cranking.phase".to_string(), c.phase)),
        )
        .filter(|(_, phase)| phase.abs() > std::f64::consts::TAU)
        .map(|(key, phase)| format!("`{key} = {phase}`"))
        .collect();
    (!over.is_empty()).then(|| {
        format!(
            "WARNING: {} more than a turn: phases are in radians (the rotor's angles are \
             degrees), so a phase meant in degrees is read as that many radians (90° is \
             1.5708 rad)",
            if over.len() == 1 {
                format!("{} is", over[0])
            } else {
                format!("{} are", over.join(", "))
            }
        )
    })
}

/// The fastest speed a prescribed drive puts the shaft at, rad/s (`model = "speed"`, the larger
/// end of a `"ramp"`, the fastest point of a `"profile"`; with a cranking ripple its peak,
/// ω̄·(1 + ripple)); `None` for a torque drive or none.
fn prescribed_top_speed(scene: &Scene) -> Option<f64> {
    let top = scene.motor.as_ref()?.prescribed_top()?;
    Some(top * (1.0 + scene.cranking.map_or(0.0, |c| c.ripple)))
}

/// "normal" up to `fraction·limit`, "warning" up to `limit`, "over" above (in f64, as the
/// design computes them).
pub(crate) fn level_of(value: f64, fraction: f64, limit: f64) -> &'static str {
    if value > limit {
        "over"
    } else if value > fraction * limit {
        "warning"
    } else {
        "normal"
    }
}

/// All design-time results of a scene.
#[derive(Debug, Clone, Serialize, Default)]
pub struct Prediction {
    /// Predicted irregularity (scenes with a torque motor and a load).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub irregularity: Option<IrregularityOut>,
    /// Why a scene with a torque motor and a load has no `irregularity`
    /// ([`irregularity_not_predicted`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub irregularity_not_predicted: Option<String>,
    /// The δ monitor's default window cannot hold the load's whole period
    /// ([`crate::app::run::window_warning`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub window_warning: Option<String>,
    /// Support unbalances and limits (scenes with a rotor).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub supports: Option<SupportsOut>,
    /// Auto-balancer characteristic speeds and zones (vibration-machine scenes).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub autobalancer: Option<AutobalancerOut>,
}

impl Prediction {
    /// Whether the scene gave nothing to predict (no drive model, rotor or vibration machine).
    pub fn is_empty(&self) -> bool {
        self.irregularity.is_none()
            && self.irregularity_not_predicted.is_none()
            && self.window_warning.is_none()
            && self.supports.is_none()
            && self.autobalancer.is_none()
    }
}

/// Why the steady-state δ of a scene's drive is not predicted, when it is not. A J(φ) from
/// `[shaft] inertia_harmonics` is predicted by the core (eq. 1 solved in `w = J·ω²` over one
/// common period); what its J(φ) path does not cover is named here: orders without a common
/// period, a J(φ) so close to 0 that the solution needs more nodes than the core holds, more
/// harmonics than it holds. A constant-inertia prediction would silently leave the variation
/// out (its ½·ω²·dJ/dφ term alone makes ω swing), so none is given; `run` simulates the drive.
/// A Kloss drive the core refuses is named here too: one so stiff against its inertia that a
/// period needs more than [`drive_monitor::drive::MAX_STEPS`] steps, or one with no attracting
/// periodic steady state found. A Kloss drive's J(φ) that the core refuses only for a common
/// period too long for its shooting is integrated on the host ([`long_period_inertia`]) and is
/// not named here.
pub fn irregularity_not_predicted(scene: &Scene) -> Option<String> {
    let base = match constant_inertia_build(scene, Path::new("scene")).ok()?? {
        Ok(base) => base,
        Err(e) => {
            let why = not_covered(e)?;
            return Some(format!(
                "{why}; δ is not predicted for this drive (`drive-sim run` simulates it)"
            ));
        }
    };
    let e = with_inertia(scene, &base).err()?;
    // A Kloss drive's J(φ) over a common period too long for the core: the host integrates it.
    if long_period_inertia_of(scene, &base).is_some() {
        return None;
    }
    let why = not_covered(e)?;
    Some(format!(
        "{why}; δ is not predicted for this J(φ) (`drive-sim run` simulates it)"
    ))
}

/// Computes the design-time results of `scene`.
pub fn predict(scene: &Scene, file: &Path) -> Result<Prediction, SceneError> {
    let mut p = Prediction::default();
    let model = drive_model(scene, file)?;
    if model.is_some() || scene.motor.is_some() {
        p.irregularity_not_predicted = irregularity_not_predicted(scene);
        p.window_warning = crate::app::run::window_warning(scene);
    }
    // A Kloss drive the core leaves to a parabola (or whose J(φ) it refuses for a common
    // period too long for it): integrated here over a long common period, or a stall where no
    // speed carries the mean load.
    let inertia = if p.irregularity_not_predicted.is_none() {
        long_period_inertia(scene)
    } else {
        Vec::new()
    };
    let long = model
        .as_ref()
        .filter(|_| p.irregularity_not_predicted.is_none())
        .and_then(|m| long_kloss(m, &inertia));
    if let (false, Some(LongKloss::Approximate(a))) = (inertia.is_empty(), &long) {
        // No parabola stands in for a J(φ): its constant part's δ is not this drive's.
        let why = match a {
            Approximation::Failed(period, e) => format!(
                "the host's integration of the Kloss drive with J(φ) over the common period \
                 of the load and inertia orders, {} revolutions, found no attracting periodic \
                 steady state ({e:?})",
                period.whole_revolutions
            ),
            _ => "the host does not integrate this Kloss drive with J(φ)".to_string(),
        };
        p.irregularity_not_predicted = Some(format!(
            "{why}; δ is not predicted for this J(φ) (`drive-sim run` simulates it)"
        ));
    }
    if let Some(model) = model.filter(|_| p.irregularity_not_predicted.is_none()) {
        let limit = scene.monitor.as_ref().and_then(|m| m.delta_limit);
        let mut irr = model
            .irregularity(limit)
            .map_err(|e| core_error(scene, file, "monitor", e))?;
        let mut sens = model.sensitivity();
        let (sampled, sampling_note) = match &long {
            Some(LongKloss::Integrated { period, steady }) => {
                long_kloss_sampled(scene, file, &model, &inertia, period, steady)?
            }
            Some(LongKloss::MeanLoad | LongKloss::Stalls { .. }) => (None, None),
            _ => (sampled_delta(scene, file, &model)?, None),
        };
        let mut prediction = model.predict();
        match &long {
            Some(LongKloss::Integrated { period, steady }) => {
                irr = drive_monitor::drive::Irregularity {
                    omega_max: steady.omega_max,
                    omega_min: steady.omega_min,
                    delta: steady.delta,
                    steady_state: true,
                    flywheel_for_limit: limit.and_then(|l| {
                        long_kloss_flywheel(&model, &inertia, period, steady.delta, l)
                    }),
                };
                sens = long_kloss_sensitivity(&model, &inertia, period);
                let breakdown = model
                    .motor()
                    .kloss_curve()
                    .map_or(0.0, |k| k.breakdown_speed());
                prediction =
                    drive_monitor::drive::Prediction::Steady(drive_monitor::drive::SteadyState {
                        omega_max: steady.omega_max,
                        omega_min: steady.omega_min,
                        delta: steady.delta,
                        omega_rms: steady.omega_rms,
                        phi_max: Some(steady.phi_max),
                        phi_min: Some(steady.phi_min),
                        horizon: drive_monitor::drive::Horizon::Shooting {
                            radians: period.radians,
                            steps: u32::try_from(steady.steps).unwrap_or(u32::MAX),
                        },
                        within_working_branch: steady.omega_min >= breakdown,
                    });
            }
            Some(LongKloss::MeanLoad) => {
                irr = drive_monitor::drive::Irregularity {
                    omega_max: 0.0,
                    omega_min: 0.0,
                    delta: 2.0,
                    steady_state: false,
                    flywheel_for_limit: None,
                };
                sens = None;
                prediction =
                    drive_monitor::drive::Prediction::Stalls(drive_monitor::drive::Stall {
                        u_mean: 0.0,
                        u_min: 0.0,
                    });
            }
            Some(LongKloss::Stalls { period, u_mean }) => {
                irr = drive_monitor::drive::Irregularity {
                    omega_max: 0.0,
                    omega_min: 0.0,
                    delta: 2.0,
                    steady_state: false,
                    flywheel_for_limit: limit.and_then(|l| {
                        long_kloss_flywheel(&model, &inertia, period, f64::INFINITY, l)
                    }),
                };
                sens = None;
                prediction =
                    drive_monitor::drive::Prediction::Stalls(drive_monitor::drive::Stall {
                        u_mean: *u_mean,
                        u_min: 0.0,
                    });
            }
            Some(LongKloss::Approximate(_)) | None => {}
        }
        let stall = match prediction {
            drive_monitor::drive::Prediction::Stalls(s)
                if s.u_mean <= 0.0 && model.motor().kloss_curve().is_some() =>
            {
                Some(
                    "the mean load is beyond the motor's breakdown torque M_m (or below −M_m): \
                     no speed and no flywheel carry it",
                )
            }
            drive_monitor::drive::Prediction::Stalls(s) if s.u_mean <= 0.0 => Some(
                "the mean load exceeds the motor's torque at standstill: no speed and no \
                 flywheel carry it (`run` models the load as an active torque, which turns the \
                 shaft backwards)",
            ),
            drive_monitor::drive::Prediction::Stalls(_) => Some(
                "the motor stalls under the peak load (it carries the mean load: more \
                 flywheel can help)",
            ),
            _ => None,
        };
        let kloss_curve = model.motor().kloss_curve().is_some()
            && (matches!(
                model.horizon(),
                drive_monitor::drive::Horizon::Shooting { .. }
                    | drive_monitor::drive::Horizon::Constant
            ) || matches!(
                long,
                Some(LongKloss::Integrated { .. } | LongKloss::Stalls { .. } | LongKloss::MeanLoad)
            ));
        let approximate = matches!(long, Some(LongKloss::Approximate(_)));
        let working_branch_warning = prediction
            .steady()
            .filter(|s| !s.within_working_branch)
            .map(|s| {
                let why = if kloss_curve {
                    "for part of the period the drive runs past the Kloss curve's breakdown \
                     point, where its torque falls with the speed (the prediction integrates the \
                     curve and its periodic state attracts; a little more load or less inertia \
                     can tip it into a stall)"
                } else {
                    "the characteristic stands for a real motor only above it (past its \
                     breakdown point a real motor's torque falls, and it may stall)"
                };
                format!(
                    "WARNING: ω min {:.3} rad/s is below the motor's breakdown speed {:.3} rad/s: \
                     {why}",
                    s.omega_min,
                    model.motor().model().working_min_speed()
                )
            });
        let generator_note = prediction
            .steady()
            .and_then(|s| generator_note(&model, s.omega_min, s.omega_max));
        let alarm_floor_warning = alarm_floor_warning(scene, file, limit, &prediction)?;
        let min_speed_warning = min_speed_warning(scene, file, &prediction)?;
        p.irregularity = Some(IrregularityOut {
            alarm_floor_warning,
            min_speed_warning,
            phase_warning: phase_warning(scene),
            machine_torque_warning: None,
            stall,
            working_branch_warning,
            generator_note,
            delta_through_samples: sampled.map(|s| s.most),
            delta_through_samples_least: sampled.map(|s| s.least),
            delta_through_samples_at_scene_phase: sampled.map(|s| s.at_scene_phase),
            sampling_warning: sampled.and_then(|s| sampled_delta_warning(irr.delta, &s)),
            sampling_note,
            inertia_note: inertia_note(&model).or_else(|| long_inertia_note(&inertia)),
            kloss_curve,
            approximate,
            motor_note: kloss_note(
                &model,
                irr.omega_min,
                if irr.steady_state { irr.omega_max } else { 0.0 },
                long.as_ref(),
                &inertia,
            ),
            // Without a steady state the core's numbers describe the stall, not a δ.
            omega_max: irr.steady_state.then_some(irr.omega_max),
            omega_min: irr.steady_state.then_some(irr.omega_min),
            delta: irr.steady_state.then_some(irr.delta),
            steady_state: irr.steady_state,
            // A flywheel no scene may hold is no design: "none within range", and how much.
            flywheel_for_limit: limit.map(|_| {
                irr.flywheel_for_limit
                    .filter(|&j| j <= crate::app::check::MAX_INERTIA)
            }),
            flywheel_beyond_range: irr
                .flywheel_for_limit
                .filter(|&j| limit.is_some() && j > crate::app::check::MAX_INERTIA),
            d_delta_d_inertia: sens.map(|s| s.d_delta_d_inertia),
            d_delta_d_breakdown_torque: sens.map(|s| s.d_delta_d_breakdown_torque),
        });
    }
    if let Some((rotor, limits)) = rotor(scene, file)? {
        let a = analysis(scene, &rotor, &limits, file)?;
        let r = a.report();
        let loads = rotor.loads(limits.service_speed());
        // The drive's own prediction puts the shaft at up to ω max, a prescribed drive at its
        // top speed: judged there too, as `run` judges at the fastest ω max it measures (a
        // prescribed 200 rad/s, over the safe speed, was judged at the service speed alone).
        let predicted = p.irregularity.as_ref().and_then(|i| i.omega_max);
        let prescribed = prescribed_top_speed(scene).filter(|w| *w > 0.0);
        let predicted_speed = predicted.or(prescribed);
        let at_predicted = predicted_speed.map(|w| rotor.loads(w));
        let load_level_at = |loads: [drive_monitor::supports::LoadRange; 2]| {
            limits
                .support_load_limit()
                .map(|l| [0, 1].map(|i| level_of(loads[i].peak, limits.warning_fraction(), l[i])))
        };
        p.supports = Some(SupportsOut {
            unbalance_a: r.unbalance_a,
            unbalance_b: r.unbalance_b,
            permissible_a: r.permissible_a,
            permissible_b: r.permissible_b,
            max_speed: r.max_speed.filter(|v| v.is_finite()),
            max_speed_status: match (limits.support_load_limit(), r.max_speed) {
                (None, _) => "no_load_limit",
                (Some(_), Some(v)) if v.is_finite() => "limited",
                (Some(_), _) => "not_limited",
            },
            no_safe_speed: static_overload(&a),
            static_load: [a.static_load[0].norm(), a.static_load[1].norm()],
            peak_load_at_service_speed: [loads[0].peak, loads[1].peak],
            unbalance_level: [
                level_of(r.unbalance_a, limits.warning_fraction(), r.permissible_a),
                level_of(r.unbalance_b, limits.warning_fraction(), r.permissible_b),
            ],
            load_level: load_level_at(loads),
            predicted_speed,
            speed_prescribed: predicted.is_none() && prescribed.is_some(),
            peak_load_at_predicted_speed: at_predicted.map(|l| [l[0].peak, l[1].peak]),
            load_level_at_predicted_speed: at_predicted.and_then(load_level_at),
            above_service_speed: predicted_speed
                .and_then(|w| crate::app::run::above_service_speed(w, limits.service_speed())),
            allocation: match a.permissible.allocation {
                drive_monitor::supports::Allocation::Inboard => "inboard",
                drive_monitor::supports::Allocation::Overhung => "overhung",
            },
            balancer_warning: balancer_supports_warning(scene),
            unbalance_warning: unbalance_warning(scene),
        });
    }
    if let Some(m) = machine(scene, file)? {
        let Some(design) = crate::app::regimes::design(scene, file, &m)? else {
            return Err(SceneError::value(file, "autobalancer", "missing"));
        };
        let stability = design.exact.as_ref().map(|e| StabilityOut {
            scanned: [e.map.options.from, e.map.options.to],
            stable_at_start: e.map.stable_at_from,
            boundaries: e
                .map
                .boundaries
                .iter()
                .map(|b| StabilityBoundaryOut {
                    speed: b.speed,
                    stable_above: b.stable_above,
                })
                .collect(),
            criterion: e.comparison.clone(),
            evaluations: e.map.evaluations,
            drift_treated_as_neutral: e.map.unresolved,
            neutral_within_resolution: e.map.marginal,
            criterion_below: e.criterion_below.clone(),
        });
        let segment = |from: f64, r: drive_monitor::balancer::Regime| SegmentOut {
            from,
            regime: r.name(),
            reason: r.reason().map(|x| x.name()),
        };
        let regime_table: Vec<SegmentOut> = match &design.exact {
            Some(e) => e.segments.iter().map(|&(f, r)| segment(f, r)).collect(),
            None => drive_monitor::balancer::Classifier::new(&m, 0.0, 0.0)
                .map_err(|e| value_error(file, "autobalancer", e))?
                .segments()
                .map(|s| segment(f64::from(s.from), s.regime))
                .collect(),
        };
        let excited = crate::app::regimes::excited_speeds(&m);
        p.autobalancer = Some(AutobalancerOut {
            capacity: design.capacity,
            rotor_unbalance: design.rotor_unbalance,
            rotor_unbalance_assumed: scene
                .autobalancer
                .as_ref()
                .is_some_and(|a| a.rotor_unbalance.is_none()),
            residual_floor: design.residual_floor,
            stability,
            regime_table,
            regime_table_source: if design.exact.is_some() {
                "exact"
            } else {
                "criterion"
            },
            resonant_speeds: excited.resonant,
            additional_speeds: excited.additional,
            unexcited_speeds: excited.cancelled,
            zones: m
                .zones()
                .iter()
                .map(|z| ZoneOut {
                    from: z.from,
                    to: z.to,
                    regime: z.kind.name(),
                })
                .collect(),
            capture: m.capture_windows().iter().map(CaptureOut::from).collect(),
            resonance_capture: crate::app::regimes::resonance_captures(&m)
                .iter()
                .map(CaptureOut::from)
                .collect(),
        });
    }
    // The drive's δ beside a vibration machine: said what it leaves out, with the regime
    // table's segments the predicted speeds fall in where the loads need not balance.
    if scene.autobalancer.is_some() {
        let table = p.autobalancer.as_ref().map(|a| a.regime_table.as_slice());
        if let Some(i) = p.irregularity.as_mut() {
            if let (Some(lo), Some(hi), Some(_)) = (i.omega_min, i.omega_max, i.delta) {
                i.machine_torque_warning =
                    Some(machine_torque_warning(table.unwrap_or_default(), lo, hi));
            }
        }
    }
    Ok(p)
}

/// The WARNING of a drive prediction on a scene that also has a vibration machine: the
/// prediction (seed 000's eq. 1: motor, `[load]`, `[shaft]`) leaves out the torque the machine
/// puts on the shaft, `τ = Σ_j b_w·R²·(φ̇_j − ω) − D·Ÿ_e·cos(φ + θ)`
/// (`host-sim/src/engine/vibration`), which vanishes only while the loads balance and the
/// platforms are still; `run` integrates it with the drive. The segments of the machine's
/// regime table that the predicted speeds `[omega_min, omega_max]` fall in and that are not
/// *balancing* are named.
pub fn machine_torque_warning(table: &[SegmentOut], omega_min: f64, omega_max: f64) -> String {
    let ends = crate::app::report::fmt_speeds(
        &table
            .iter()
            .map(|g| g.from)
            .chain([f64::INFINITY])
            .collect::<Vec<_>>(),
    );
    let segments: Vec<String> = table
        .iter()
        .enumerate()
        .filter_map(|(k, seg)| {
            let to = table.get(k + 1).map_or(f64::INFINITY, |n| n.from);
            let overlaps = seg.from <= omega_max && to > omega_min;
            (overlaps && seg.regime != "balancing").then(|| {
                format!(
                    "{}{} ({} – {} rad/s)",
                    seg.regime,
                    seg.reason.map_or(String::new(), |r| format!(" ({r})")),
                    ends[k],
                    ends[k + 1]
                )
            })
        })
        .collect();
    let (lo, hi) = crate::app::report::fmt_speed_pair(omega_min, omega_max);
    let speeds = if lo == hi {
        format!("{hi} rad/s")
    } else {
        format!("{lo} – {hi} rad/s")
    };
    let here = if segments.is_empty() {
        String::new()
    } else {
        format!(
            "; the predicted speed {speeds} lies where the regime table says {}: there the \
             loads need not balance",
            segments.join(", ")
        )
    };
    format!(
        "WARNING: this δ is the drive's alone ([motor], [load], [shaft]): it leaves out the \
         torque the vibration machine ([[platform]], [autobalancer]) puts on the shaft, the \
         drag of the auto-balancer's loads slipping against the rotor and the moment of the \
         rotor unbalance's inertial force on the vibrating platform; ω max, ω min, δ, the \
         flywheel for the limit and ∂δ/∂J, ∂δ/∂M_m hold only while the loads balance and the \
         platforms are still, and where the loads gather or lag the rotor that torque swings \
         the speed, so δ can be much larger{here}; `drive-sim run` simulates the drive \
         and the machine coupled and measures δ with it"
    )
}

/// The WARNING of a scene with both a rotor on supports (`[rotor]`, `[[unbalance]]`) and an
/// auto-balancer: the support analysis (seed 002) and the balancer (seed 001) are independent
/// models. `None` without both.
pub fn balancer_supports_warning(scene: &Scene) -> Option<String> {
    let ab = scene.autobalancer.as_ref()?;
    scene.rotor.as_ref()?;
    let capacity = f64::from(ab.loads) * ab.load_mass * ab.radius;
    Some(format!(
        "WARNING: the support analysis ([rotor], [[unbalance]]) leaves out the auto-balancer \
         ([autobalancer], [[platform]]): its loads and unbalance levels are those of the \
         [[unbalance]] list on rigid supports, as if no balancer were on the rotor, so neither \
         the unbalance the balancer cancels when it balances nor the one its loads add when \
         they gather (up to N·m·R = {capacity:.4e} kg·m) is in them, and the platforms' \
         vibration does not reach the supports; the balancer's regimes are for \
         `autobalancer.rotor_unbalance`, which [[unbalance]] does not set: the two are \
         independent models of the rotor"
    ))
}
