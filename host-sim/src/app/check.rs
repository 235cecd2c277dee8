//! Validation of a whole scene before anything is simulated: every numeric key, whether the
//! scene's effects use it or not, against its documented range (README, "Limits"), each error
//! quoting the key and its value as written in the file.
//!
//! The ranges are wide enough for any machine the simulator models and narrow enough that no
//! product of two of them overflows f64 or the core's f32 paths: a value outside them is a
//! typing error or a unit mistake, and is refused before it can become an infinite load, a
//! NaN speed or an integration that never ends. Errors the core raises on values inside these
//! ranges (values that contradict each other) are turned into scene keys by [`core_keys`].

use crate::app::scene::{
    parse_wheel, AutobalancerSpec, BalancerKindSpec, EncoderSpec, FramingSpec, Harmonic, MotorSpec,
    Scene, SceneError,
};
use drive_monitor::ConfigError;
use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// Largest speed of any kind in a scene (prescribed, initial, no-load, service), rad/s: about
/// 955 000 rpm, above any machine the seeds describe.
pub const MAX_SPEED: f64 = 1e5;
/// Longest simulated time, s (a bound on the work of a run, see also [`crate::app::limits`]).
pub const MAX_DURATION: f64 = 1e6;
/// Largest mass of a platform, rotor or housing, kg.
pub const MAX_MASS: f64 = 1e9;
/// Largest stiffness, N/m.
pub const MAX_STIFFNESS: f64 = 1e15;
/// Largest damping or viscosity, N·s/m.
pub const MAX_DAMPING: f64 = 1e12;
/// Largest torque (motor breakdown torque, load mean and harmonic amplitudes), N·m.
pub const MAX_TORQUE: f64 = 1e9;
/// Largest inertia, kg·m².
pub const MAX_INERTIA: f64 = 1e9;
/// Largest axial coordinate or radius, m.
pub const MAX_LENGTH: f64 = 1e4;
/// Largest force or load per length (N, N/m).
pub const MAX_FORCE: f64 = 1e12;
/// Largest harmonic order, cycles per revolution (the core's [`drive_monitor::drive::MAX_ORDER`]
/// is wider; a higher order than this is faster than any encoder resolves).
pub const MAX_ORDER: f64 = 1e3;
/// Largest angle or phase, in the unit of its key (rad or degrees): beyond it f64 keeps no
/// fraction of a turn.
pub const MAX_ANGLE: f64 = 1e6;
/// Largest edge jitter, s.
pub const MAX_JITTER: f64 = 1e-3;
/// Largest edge fault probability (drops, glitches).
pub const MAX_FAULT_PROBABILITY: f64 = 0.5;
/// Encoder lines the simulator's monitor holds.
pub const MAX_LINES: u16 = crate::app::run::MAX_LINES as u16;

/// The text of each value as written in the scene file, by key path: `simulation.duration`,
/// `platform[2].mass` (arrays numbered from 1, as `between` numbers platforms),
/// `load.harmonics[1].order`, `rotor.support_load_limit[2]`.
#[derive(Debug, Clone, Default)]
pub struct Written {
    values: BTreeMap<String, (String, Option<std::ops::Range<usize>>)>,
    text: String,
}

impl Written {
    /// The values of `text` (empty when it is not TOML: the parser reports that).
    pub fn parse(text: &str) -> Written {
        let mut w = Written {
            values: BTreeMap::new(),
            text: text.to_string(),
        };
        if let Ok(doc) = text.parse::<toml_edit::ImDocument<String>>() {
            w.table("", doc.as_table());
        }
        w.text = String::new();
        w
    }

    /// The value at `key` as written, if the file gives it.
    pub fn get(&self, key: &str) -> Option<&str> {
        self.values.get(key).map(|(v, _)| v.as_str())
    }

    /// Every value: its key, its text as written and where that text is in the file (bytes).
    pub fn entries(&self) -> impl Iterator<Item = (&str, &str, Option<std::ops::Range<usize>>)> {
        self.values
            .iter()
            .map(|(k, (v, span))| (k.as_str(), v.as_str(), span.clone()))
    }

    fn table(&mut self, prefix: &str, t: &toml_edit::Table) {
        for (k, item) in t.iter() {
            let key = join(prefix, k);
            match item {
                toml_edit::Item::Value(v) => self.value(&key, v),
                toml_edit::Item::Table(t) => self.table(&key, t),
                toml_edit::Item::ArrayOfTables(a) => {
                    for (i, t) in a.iter().enumerate() {
                        self.table(&format!("{key}[{}]", i + 1), t);
                    }
                }
                toml_edit::Item::None => {}
            }
        }
    }

    fn value(&mut self, key: &str, v: &toml_edit::Value) {
        match v {
            toml_edit::Value::Array(a) => {
                for (i, v) in a.iter().enumerate() {
                    self.value(&format!("{key}[{}]", i + 1), v);
                }
            }
            toml_edit::Value::InlineTable(t) => {
                for (k, v) in t.iter() {
                    self.value(&join(key, k), v);
                }
            }
            _ => {
                // The value's own text in the file (its span), else toml_edit's rendering.
                let span = v.span();
                let written = span
                    .clone()
                    .and_then(|span| self.text.get(span))
                    .map(|t| t.trim().to_string())
                    .unwrap_or_else(|| {
                        let mut bare = v.clone();
                        bare.decor_mut().clear();
                        bare.to_string()
                    });
                self.values.insert(key.to_string(), (written, span));
            }
        }
    }
}

fn join(prefix: &str, key: &str) -> String {
    if prefix.is_empty() {
        key.to_string()
    } else {
        format!("{prefix}.{key}")
    }
}

/// A number in an allowed range: `1e9`, `0.5`, `0`.
fn num(x: f64) -> String {
    if x == 0.0 || (x.abs() >= 1e-3 && x.abs() < 1e5) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Builds the errors of one scene file.
pub struct Checker<'a> {
    file: &'a Path,
    written: &'a Written,
}

impl<'a> Checker<'a> {
    /// Errors of `file`, quoting `written`.
    pub fn new(file: &'a Path, written: &'a Written) -> Self {
        Checker { file, written }
    }

    /// `key`'s value as written (an array, of arrays too, from its elements, which
    /// [`Written`] keeps one by one), or `x` marked as the default.
    pub fn shown(&self, key: &str, x: impl std::fmt::Display) -> String {
        self.as_written(key, 2)
            .unwrap_or_else(|| format!("{x} (the default)"))
    }

    /// `key`'s value as written, if the file gives it: a value, or an array of them, nested
    /// up to `depth` deep (`gaps = [[0, 2]]` is two deep), element by element.
    fn as_written(&self, key: &str, depth: u32) -> Option<String> {
        if let Some(v) = self.written.get(key) {
            return Some(v.to_string());
        }
        let inner = depth.checked_sub(1)?;
        let elements: Vec<String> = (1..)
            .map_while(|i| self.as_written(&format!("{key}[{i}]"), inner))
            .collect();
        (!elements.is_empty()).then(|| format!("[{}]", elements.join(", ")))
    }

    /// The error for `key` (value `x`): `rule` says what is allowed.
    pub fn bad(&self, key: &str, x: impl std::fmt::Display, rule: impl Into<String>) -> SceneError {
        SceneError::Rule {
            file: self.file.to_path_buf(),
            key: key.to_string(),
            value: self.shown(key, x),
            rule: rule.into(),
        }
    }

    /// The error for the list `key` holding `n` `what` (tables, points) as the file gives
    /// them: `rule` says how many are allowed. (A count is the file's own, never a default.)
    pub fn bad_count(
        &self,
        key: &str,
        n: usize,
        what: &str,
        rule: impl Into<String>,
    ) -> SceneError {
        SceneError::Rule {
            file: self.file.to_path_buf(),
            key: key.to_string(),
            value: format!("{n} {what}"),
            rule: rule.into(),
        }
    }

    /// `x` finite and in `[lo, hi]` (`lo` excluded when `open`), in `unit`.
    pub fn range(
        &self,
        key: &str,
        x: f64,
        lo: f64,
        open: bool,
        hi: f64,
        unit: &str,
    ) -> Result<(), SceneError> {
        let above = if open { x > lo } else { x >= lo };
        // Subnormal numbers are refused too: they are not physical and lose their digits in the
        // first division (the core refuses them the same way).
        let subnormal = x != 0.0 && x.abs() < f64::MIN_POSITIVE;
        if x.is_finite() && above && x <= hi && !subnormal {
            return Ok(());
        }
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        let bracket = if open { "(" } else { "[" };
        let note = if subnormal { " (not subnormal)" } else { "" };
        Err(self.bad(
            key,
            x,
            format!("allowed {bracket}{}, {}]{unit}{note}", num(lo), num(hi)),
        ))
    }

    /// `x` in `(0, hi]`.
    pub fn positive(&self, key: &str, x: f64, hi: f64, unit: &str) -> Result<(), SceneError> {
        self.range(key, x, 0.0, true, hi, unit)
    }

    /// `x` in `[0, hi]`.
    pub fn non_negative(&self, key: &str, x: f64, hi: f64, unit: &str) -> Result<(), SceneError> {
        self.range(key, x, 0.0, false, hi, unit)
    }

    /// `|x| ≤ hi`.
    pub fn magnitude(&self, key: &str, x: f64, hi: f64, unit: &str) -> Result<(), SceneError> {
        self.range(key, x, -hi, false, hi, unit)
    }

    /// An integer `n` in `lo..=hi`.
    pub fn count(&self, key: &str, n: u64, lo: u64, hi: u64) -> Result<(), SceneError> {
        if (lo..=hi).contains(&n) {
            Ok(())
        } else {
            Err(self.bad(key, n, format!("allowed {lo} to {hi}")))
        }
    }

    /// The core's rejection of a configuration built from the scene's `section`, as an error
    /// naming the scene keys the core's parameter stands for, with their values as written.
    pub fn core(&self, scene: &Scene, section: &str, e: ConfigError) -> SceneError {
        let listed = core_keys(section, e.parameter());
        // Of the keys the parameter may stand for, the ones this file uses (or whose default
        // it relies on): a wheel given as `wheel = "36-2"` is not blamed on `encoder.teeth`.
        let used: Vec<String> = listed
            .iter()
            .filter(|k| {
                self.written.get(k).is_some()
                    || default_of(scene, k).is_some()
                    || self.written.entries().any(|(w, _, _)| {
                        w.strip_prefix(k.as_str())
                            .is_some_and(|rest| rest.starts_with('[') || rest.starts_with('.'))
                    })
            })
            .cloned()
            .collect();
        let keys = if used.is_empty() { listed } else { used };
        let mut quoted = String::new();
        for (i, k) in keys.iter().enumerate() {
            if i > 0 {
                quoted.push_str(", ");
            }
            let _ = match self.written.get(k) {
                Some(v) => write!(quoted, "`{k} = {v}`"),
                None => match (default_of(scene, k), implied_by(scene, k)) {
                    (Some(v), Some(by)) => write!(quoted, "`{k} = {v}` (implied by `{by}`)"),
                    (Some(v), None) => write!(quoted, "`{k} = {v}` (the default)"),
                    (None, _) => write!(quoted, "`{k}`"),
                },
            };
        }
        SceneError::Core {
            file: self.file.to_path_buf(),
            key: keys.first().cloned().unwrap_or_default(),
            keys: quoted,
            message: core_message(&e, keys.len() > 1),
        }
    }
}

fn core_message(e: &ConfigError, several: bool) -> String {
    match e {
        ConfigError::NonFinite(_) => "must be finite".into(),
        ConfigError::NotPositive(_) => "must be positive".into(),
        ConfigError::Negative(_) => "must not be negative".into(),
        ConfigError::OutOfRange(_) if several => {
            "out of the range these keys allow together".into()
        }
        ConfigError::OutOfRange(_) => "out of range".into(),
        ConfigError::Capacity(_) => "more than the fixed capacity holds".into(),
        ConfigError::Unsupported(_) => "not supported by this build of the core".into(),
        // What would be valid, where the core's parameter alone does not say it.
        ConfigError::Inconsistent("support_b") => format!(
            "contradict each other (the supports must be two distinct planes, at least {:e} of \
             the largest axial coordinate apart, in either order)",
            drive_monitor::supports::MIN_PLANE_SEPARATION
        ),
        ConfigError::Inconsistent("duplicate coupling") => {
            "contradict each other (two [[coupling]] tables join the same two platforms: give \
             one table per pair, with the sum of the stiffnesses and of the dampings)"
                .into()
        }
        // The core names what contradicts in parentheses: "pattern (rotationally symmetric)".
        ConfigError::Inconsistent(p) => match p.split_once(" (") {
            Some((_, why)) => format!("contradict each other ({}", why),
            None => "contradict each other".into(),
        },
    }
}

/// The scene keys a core configuration parameter stands for, the responsible key first: the
/// one place where the core's parameter names (`ConfigError::parameter`) meet the scene's
/// keys. `section` is the scene table the configuration was built from. A parameter the table
/// does not list is taken to be `section.parameter`.
pub fn core_keys(section: &str, parameter: &str) -> Vec<String> {
    let listed: &[&str] = match (section, parameter) {
        // drive_monitor::encoder::Encoder::new, from [encoder] and [monitor].
        ("encoder", "lines") => &["encoder.lines", "encoder.wheel"],
        // The wheel's pattern, however the scene gives it; the core's "pattern (...)" names
        // say what contradicts (uniform, rotationally symmetric, a pitch too close).
        ("encoder", p) if p.starts_with("pattern") => &[
            "encoder.wheel",
            "encoder.gaps",
            "encoder.teeth",
            "encoder.lines",
            "encoder.missing",
            "encoder.framing",
        ],
        ("encoder", "prescaler") => &["encoder.prescaler", "encoder.lines", "encoder.framing"],
        ("encoder", "tolerances.accept") => &["encoder.tolerances.accept"],
        ("encoder", "tolerances.glitch_fraction") => &["encoder.tolerances.glitch_fraction"],
        ("encoder", "tolerances.fault_margin") => &["encoder.tolerances.fault_margin"],
        ("encoder", "estimator.edges") => &[
            "encoder.estimator_edges",
            "encoder.lines",
            "encoder.wheel",
            "monitor.min_speed",
            "encoder.timer_hz",
        ],
        // The longest pitch at min_speed must last at least 2 ticks and fit the counter.
        ("encoder", "timer_hz" | "min_speed") => &[
            "monitor.min_speed",
            "encoder.timer_hz",
            "encoder.lines",
            "encoder.wheel",
            "encoder.missing",
            "encoder.gaps",
            "encoder.teeth",
            "encoder.counter_bits",
        ],
        ("encoder", "counter_bits") => &["encoder.counter_bits"],
        // The simulator's encoder (host_sim::engine::encoder), from [encoder] and [capture].
        ("encoder", "encoder.duty") => &["capture.duty", "encoder.teeth", "encoder.gaps"],
        ("encoder", "encoder.pitch_errors") => &["encoder.pitch_error", "encoder.runout"],
        // The speed profile of a cranking scene (host_sim::engine::cranking).
        ("shaft", "profile.points" | "profile.time" | "profile.speed") => &["motor.points"],
        ("shaft", "ripple.amplitude") => &["cranking.ripple"],
        ("shaft", "ripple.strokes") => &["cranking.strokes"],
        ("shaft", "ripple.phase") => &["cranking.phase"],
        // drive_monitor::irregularity::WindowConfig, from [monitor] and the load's orders.
        ("monitor", "window.revolutions") => &["monitor.window_revolutions"],
        ("monitor", "window.load_order") => &["load.harmonics", "monitor.window_revolutions"],
        ("monitor", "steady_tolerance") => &["monitor.steady_tolerance"],
        ("monitor", "delta_limit") => &["monitor.delta_limit"],
        // drive_monitor::drive, from [shaft], [motor] and [load].
        ("shaft", "inertia") => &["shaft.inertia"],
        ("shaft", "flywheel") => &["shaft.flywheel"],
        ("shaft", "shaft.harmonics") => &["shaft.inertia_harmonics", "shaft.inertia"],
        ("shaft", "inertia_harmonic.order" | "inertia_harmonic.phase" | "inertia_harmonics") => {
            &["shaft.inertia_harmonics"]
        }
        ("shaft", "inertia_harmonic.amplitude") => {
            &["shaft.inertia_harmonics", "shaft.inertia", "shaft.flywheel"]
        }
        ("shaft", "shaft.omega" | "shaft.omega0") => &["motor.speed", "shaft.initial_speed"],
        ("load.harmonics", "order") => &["load.harmonics"],
        // drive_monitor::balancer::MachineConfig, from [[platform]], [[coupling]] and
        // [autobalancer].
        ("autobalancer", "platform mass") => &["platform"],
        ("autobalancer", "platform stiffness") => &["platform"],
        ("autobalancer", "coupling between" | "duplicate coupling") => &["coupling"],
        ("autobalancer", "autobalancer platform") => &["autobalancer.platform"],
        ("autobalancer", "autobalancer loads" | "exciter mass" | "load viscosity") => &[
            "autobalancer.loads",
            "autobalancer.load_mass",
            "autobalancer.radius",
            "autobalancer.housing_mass",
            "autobalancer.viscosity",
            "platform",
        ],
        ("autobalancer", "load mass") => &["autobalancer.load_mass"],
        ("autobalancer", "radius") => &["autobalancer.radius"],
        ("autobalancer", "pendulum inertia") => &[
            "autobalancer.pendulum_inertia",
            "autobalancer.load_mass",
            "autobalancer.radius",
        ],
        ("monitor", "margin" | "hysteresis") => &["monitor.regime_margin"],
        // drive_monitor::supports, from [rotor], [[unbalance]] and [process_load].
        ("rotor", "grade") => &["rotor.grade", "rotor.mass", "rotor.service_speed"],
        ("rotor", "unbalances") => &["unbalance"],
        ("rotor", "support_b") => &["rotor.support_b", "rotor.support_a"],
        ("rotor", "mass") => &["rotor.mass"],
        ("rotor", "process_load.per_length") => &["process_load.per_length", "rotor.mass"],
        ("rotor", "process_load.to") => &["process_load.to", "process_load.from"],
        ("rotor", "support_load_limit.a") => &["rotor.support_load_limit[1]"],
        ("rotor", "support_load_limit.b") => &["rotor.support_load_limit[2]"],
        ("rotor", "warning_fraction") => &["monitor.warning_fraction"],
        _ => &[],
    };
    if listed.is_empty() {
        vec![format!("{section}.{parameter}")]
    } else {
        listed.iter().map(|k| k.to_string()).collect()
    }
}

/// The key whose value gives `key` its value where the file does not give it (the framing
/// a wheel implies), rather than a default.
fn implied_by(scene: &Scene, key: &str) -> Option<&'static str> {
    match key {
        "encoder.framing" => scene.encoder.as_ref()?.framing_implied_by(),
        _ => None,
    }
}

/// The value a key takes when the file does not give it (for the keys [`core_keys`] lists).
fn default_of(scene: &Scene, key: &str) -> Option<String> {
    let e = scene.encoder.as_ref();
    let m = scene.monitor.as_ref();
    match key {
        "encoder.missing" => e
            .filter(|e| e.framing() == FramingSpec::MissingTooth && e.wheel.is_none())
            .map(|e| e.missing.to_string()),
        "encoder.counter_bits" => e.map(|e| e.counter_bits.to_string()),
        "encoder.prescaler" => e.map(|e| e.prescaler.to_string()),
        "encoder.estimator_edges" => e.map(|e| e.estimator_edges.to_string()),
        "encoder.framing" => e.map(|e| format!("\"{}\"", e.framing().name())),
        "capture.duty" => Some(num(scene.capture.unwrap_or_default().duty)),
        "monitor.min_speed" => Some(num(m.and_then(|m| m.min_speed).unwrap_or(1.0))),
        "monitor.steady_tolerance" => Some(num(m.and_then(|m| m.steady_tolerance).unwrap_or(0.02))),
        _ => None,
    }
}

/// Checks every key of `scene` (see the module docs).
pub fn check(scene: &Scene, c: &Checker) -> Result<(), SceneError> {
    simulation(scene, c)?;
    drive(scene, c)?;
    if let Some(e) = &scene.encoder {
        encoder(e, c)?;
    }
    cranking_and_capture(scene, c)?;
    monitor(scene, c)?;
    vibration(scene, c)?;
    rotor(scene, c)?;
    structure(scene, c)
}

fn simulation(scene: &Scene, c: &Checker) -> Result<(), SceneError> {
    let s = &scene.simulation;
    c.positive("simulation.duration", s.duration, MAX_DURATION, "s")?;
    c.range("simulation.rtol", s.rtol, 1e-13, false, 0.1, "")?;
    c.range("simulation.atol", s.atol, 1e-15, false, 1.0, "")?;
    c.range("simulation.step", s.step, 1e-9, false, 10.0, "s")?;
    if let Some(t) = s.settle {
        if !(t.is_finite() && t >= 0.0 && t < s.duration) {
            return Err(c.bad(
                "simulation.settle",
                t,
                format!(
                    "allowed [0, duration) = [0, {}) s",
                    c.shown("simulation.duration", s.duration)
                ),
            ));
        }
    }
    Ok(())
}

fn harmonics(c: &Checker, key: &str, list: &[Harmonic], amplitude: f64) -> Result<(), SceneError> {
    // The core's fixed capacities: drive::MAX_HARMONICS, and MAX_INERTIA_HARMONICS for the
    // inertia's harmonics that are there (the core drops those of amplitude 0).
    let (most, n) = if key == "shaft.inertia_harmonics" {
        let there = list.iter().filter(|h| h.amplitude != 0.0).count();
        (drive_monitor::drive::MAX_INERTIA_HARMONICS, there)
    } else {
        (drive_monitor::drive::MAX_HARMONICS, list.len())
    };
    if n > most {
        return Err(c.bad_count(
            key,
            n,
            "harmonics",
            format!("at most {most} harmonics (the core's fixed capacity)"),
        ));
    }
    for (i, h) in list.iter().enumerate() {
        let k = format!("{key}[{}]", i + 1);
        c.positive(&format!("{k}.order"), h.order, MAX_ORDER, "per revolution")?;
        c.magnitude(&format!("{k}.amplitude"), h.amplitude, amplitude, "")?;
        c.magnitude(&format!("{k}.phase"), h.phase, MAX_ANGLE, "rad")?;
    }
    Ok(())
}

/// J(φ) = inertia + flywheel + Σ amplitude·cos(order·φ + phase) must stay positive: its least
/// value over the period as the core finds it ([`drive_monitor::drive::least_inertia`]), the
/// refusal saying where it reaches 0 and quoting the amplitudes.
fn least_inertia(
    c: &Checker,
    inertia: f64,
    flywheel: f64,
    list: &[Harmonic],
) -> Result<(), SceneError> {
    let j = inertia + flywheel;
    let swing: f64 = list.iter().map(|h| h.amplitude.abs()).sum();
    if swing < j {
        return Ok(());
    }
    let core: Vec<_> = list
        .iter()
        .filter_map(|h| {
            drive_monitor::drive::InertiaHarmonic::new(h.order, h.amplitude, h.phase).ok()
        })
        .collect();
    let why = match drive_monitor::drive::least_inertia(j, &core) {
        Some((_, least)) if least > 0.0 => return Ok(()),
        Some((phi, least)) => {
            let shown = if least == 0.0 {
                "0".to_string()
            } else if least.abs() >= 1e-3 {
                format!("{least:.4}")
            } else {
                format!("{least:.3e}")
            };
            format!(
                "J(φ) = inertia + flywheel + Σ amplitude·cos(order·φ + phase) falls to {shown} \
                 kg·m² at φ = {phi:.4} rad: the reduced inertia must stay positive (smaller \
                 amplitudes, or more inertia or flywheel)"
            )
        }
        None => format!(
            "the amplitudes' magnitudes add up to {} kg·m², at least inertia + flywheel = {} \
             kg·m², and the orders have no common period over which J(φ)'s least value could \
             be found (each a fraction with denominator ≤ {}, the period at most {} cycles of \
             the fastest order), so J(φ) may come as close to inertia + flywheel − Σ|amplitude| = {} kg·m² as it \
             likes: the reduced inertia must stay positive",
            num(swing),
            num(j),
            drive_monitor::drive::MAX_DENOMINATOR,
            drive_monitor::drive::MAX_SAMPLES / drive_monitor::drive::SAMPLES_PER_CYCLE,
            num(j - swing)
        ),
    };
    let amplitudes: Vec<String> = (1..=list.len())
        .map(|i| {
            let k = format!("shaft.inertia_harmonics[{i}].amplitude");
            c.written
                .get(&k)
                .map_or_else(|| num(list[i - 1].amplitude), str::to_string)
        })
        .collect();
    let keys = format!(
        "`shaft.inertia_harmonics` (amplitudes {}), `shaft.inertia = {}`, `shaft.flywheel = {}`",
        amplitudes.join(", "),
        c.shown("shaft.inertia", inertia),
        c.shown("shaft.flywheel", flywheel)
    );
    Err(SceneError::Core {
        file: c.file.to_path_buf(),
        key: "shaft.inertia_harmonics".into(),
        keys,
        message: why,
    })
}

fn drive(scene: &Scene, c: &Checker) -> Result<(), SceneError> {
    if let Some(s) = &scene.shaft {
        c.positive("shaft.inertia", s.inertia, MAX_INERTIA, "kg·m²")?;
        c.non_negative("shaft.flywheel", s.flywheel, MAX_INERTIA, "kg·m²")?;
        harmonics(
            c,
            "shaft.inertia_harmonics",
            &s.inertia_harmonics,
            MAX_INERTIA,
        )?;
        least_inertia(c, s.inertia, s.flywheel, &s.inertia_harmonics)?;
        if let Some(w) = s.initial_speed {
            c.magnitude("shaft.initial_speed", w, MAX_SPEED, "rad/s")?;
        }
    }
    match &scene.motor {
        Some(MotorSpec::Parabola {
            no_load_speed,
            breakdown_speed,
            breakdown_torque,
        }) => {
            c.positive("motor.no_load_speed", *no_load_speed, MAX_SPEED, "rad/s")?;
            c.non_negative(
                "motor.breakdown_speed",
                *breakdown_speed,
                MAX_SPEED,
                "rad/s",
            )?;
            if breakdown_speed >= no_load_speed {
                return Err(c.bad(
                    "motor.breakdown_speed",
                    breakdown_speed,
                    format!(
                        "must be below no_load_speed = {}",
                        c.shown("motor.no_load_speed", no_load_speed)
                    ),
                ));
            }
            c.positive(
                "motor.breakdown_torque",
                *breakdown_torque,
                MAX_TORQUE,
                "N·m",
            )?;
        }
        Some(MotorSpec::Kloss {
            synchronous_speed,
            breakdown_slip,
            breakdown_torque,
        }) => {
            c.positive(
                "motor.synchronous_speed",
                *synchronous_speed,
                MAX_SPEED,
                "rad/s",
            )?;
            c.range(
                "motor.breakdown_slip",
                *breakdown_slip,
                0.0,
                true,
                0.999,
                "",
            )?;
            c.positive(
                "motor.breakdown_torque",
                *breakdown_torque,
                MAX_TORQUE,
                "N·m",
            )?;
        }
        Some(MotorSpec::Speed { speed }) => {
            c.magnitude("motor.speed", *speed, MAX_SPEED, "rad/s")?;
        }
        Some(MotorSpec::Ramp { from, to, duration }) => {
            c.magnitude("motor.from", *from, MAX_SPEED, "rad/s")?;
            c.magnitude("motor.to", *to, MAX_SPEED, "rad/s")?;
            c.positive("motor.duration", *duration, MAX_DURATION, "s")?;
        }
        Some(MotorSpec::Profile { points }) => {
            let most = crate::engine::cranking::MAX_PROFILE_POINTS as u64;
            if points.is_empty() || points.len() as u64 > most {
                return Err(c.bad_count(
                    "motor.points",
                    points.len(),
                    "points",
                    format!("1 to {most} points [t, ω]"),
                ));
            }
            for (i, &[t, w]) in points.iter().enumerate() {
                let k = format!("motor.points[{}]", i + 1);
                c.magnitude(&format!("{k}[1]"), t, MAX_DURATION, "s")?;
                c.non_negative(&format!("{k}[2]"), w, MAX_SPEED, "rad/s")?;
                if i > 0 && t <= points[i - 1][0] {
                    return Err(c.bad(
                        &format!("{k}[1]"),
                        t,
                        "times must increase from point to point",
                    ));
                }
            }
        }
        None => {}
    }
    if let Some(l) = &scene.load {
        c.magnitude("load.mean", l.mean, MAX_TORQUE, "N·m")?;
        harmonics(c, "load.harmonics", &l.harmonics, MAX_TORQUE)?;
    }
    Ok(())
}

/// The wheel an `[encoder]` table describes, resolved from whichever keys give it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct WheelDesc {
    /// Grid positions (lines) per revolution.
    pub lines: u16,
    /// How revolutions are framed.
    pub framing: FramingSpec,
    /// Grid positions carrying a tooth, ascending (every position on an index or unframed
    /// disc).
    pub teeth: Vec<u16>,
}

impl WheelDesc {
    /// The core's wheel.
    pub fn core(&self) -> Result<drive_monitor::encoder::Wheel, ConfigError> {
        use drive_monitor::encoder::{Pattern, Wheel};
        Ok(match self.framing {
            FramingSpec::Index => Wheel::Indexed { lines: self.lines },
            FramingSpec::None => Wheel::Unframed { lines: self.lines },
            FramingSpec::MissingTooth | FramingSpec::Pattern => {
                let positions = u8::try_from(self.lines)
                    .map_err(|_| ConfigError::OutOfRange("pattern.positions"))?;
                let teeth: Vec<u8> = self.teeth.iter().map(|&t| t as u8).collect();
                Wheel::Pattern(Pattern::from_teeth(positions, &teeth)?)
            }
        })
    }
}

/// Most grid positions of a pattern wheel ([`drive_monitor::encoder::MAX_PATTERN_POSITIONS`]).
pub const MAX_PATTERN_LINES: u16 = drive_monitor::encoder::MAX_PATTERN_POSITIONS as u16;

/// Resolves the wheel of `e`: `wheel = "N-M"`, `lines` with `missing` (framing
/// `"missing-tooth"`), `lines` with `gaps` or `teeth` (a pattern), or `lines` alone (an index
/// or unframed disc). Keys that contradict each other are errors naming both.
pub fn wheel(e: &EncoderSpec, c: &Checker) -> Result<WheelDesc, SceneError> {
    let framing = e.framing();
    let both = |a: &str, b: &str, why: &str| {
        c.bad(
            b,
            "?",
            format!("not together with `{a} = {}`: {why}", c.shown(a, "?")),
        )
    };
    let wheel = match &e.wheel {
        Some(w) => {
            let (n, m) = parse_wheel(w).map_err(|why| c.bad("encoder.wheel", w, why))?;
            for key in ["encoder.gaps", "encoder.teeth"] {
                if c.written.get(&format!("{key}[1][1]")).is_some()
                    || c.written.get(&format!("{key}[1]")).is_some()
                {
                    return Err(both("encoder.wheel", key, "the wheel names its one gap"));
                }
            }
            if e.gaps.is_some() || e.teeth.is_some() {
                return Err(c.bad(
                    "encoder.wheel",
                    w,
                    "not together with gaps or teeth: the wheel names its one gap",
                ));
            }
            if e.missing != 0 {
                return Err(both(
                    "encoder.wheel",
                    "encoder.missing",
                    "the wheel names its gap",
                ));
            }
            if let Some(l) = e.lines.filter(|&l| l != n) {
                return Err(c.bad(
                    "encoder.lines",
                    l,
                    format!(
                        "contradicts wheel = {} ({n} positions)",
                        c.shown("encoder.wheel", w)
                    ),
                ));
            }
            if framing != FramingSpec::MissingTooth {
                return Err(both(
                    "encoder.wheel",
                    "encoder.framing",
                    "a wheel \"N-M\" is framed by its gap (framing = \"missing-tooth\")",
                ));
            }
            Some((n, m))
        }
        None => None,
    };
    let lines = match (wheel, e.lines) {
        (Some((n, _)), _) => n,
        (None, Some(l)) => l,
        (None, None) => {
            return Err(SceneError::Rule {
                file: c.file.to_path_buf(),
                key: "encoder.lines".into(),
                value: "(missing)".into(),
                rule: "the encoder needs lines (or a wheel such as wheel = \"36-2\")".into(),
            })
        }
    };
    let grid_max = match framing {
        FramingSpec::MissingTooth | FramingSpec::Pattern => MAX_PATTERN_LINES,
        FramingSpec::Index | FramingSpec::None => MAX_LINES,
    };
    let lines_key = if wheel.is_some() {
        "encoder.wheel"
    } else {
        "encoder.lines"
    };
    if !(2..=grid_max).contains(&lines) {
        let shown = c.shown(lines_key, lines);
        let rule = if grid_max == MAX_LINES {
            format!("allowed 2 to {MAX_LINES}")
        } else {
            format!(
                "a wheel framed by its pattern has 3 to {MAX_PATTERN_LINES} grid positions (framing = \"{}\"{})",
                framing.name(),
                e.framing_implied_by()
                    .map(|by| format!(", implied by `{by} = {}`", c.shown(by, "?")))
                    .unwrap_or_default()
            )
        };
        return Err(c.bad(lines_key, shown, rule));
    }
    let all: Vec<u16> = (0..lines).collect();
    let teeth =
        match framing {
            FramingSpec::Index | FramingSpec::None => {
                if e.missing != 0 {
                    return Err(c.bad(
                        "encoder.missing",
                        e.missing,
                        format!(
                            "only with framing = \"missing-tooth\" (framing = {} has no gap; \
                             without `framing` the missing teeth imply it)",
                            c.shown("encoder.framing", format!("\"{}\"", framing.name()))
                        ),
                    ));
                }
                for key in ["encoder.gaps", "encoder.teeth"] {
                    let given = if key == "encoder.gaps" {
                        e.gaps.is_some()
                    } else {
                        e.teeth.is_some()
                    };
                    if given {
                        return Err(c.bad(
                            key,
                            "[...]",
                            format!(
                                "only for a pattern wheel (framing = {} has no pattern)",
                                c.shown("encoder.framing", format!("\"{}\"", framing.name()))
                            ),
                        ));
                    }
                }
                all
            }
            FramingSpec::MissingTooth => {
                let (m, key) = match wheel {
                    Some((_, m)) => (m, "encoder.wheel"),
                    None => (e.missing, "encoder.missing"),
                };
                if e.gaps.is_some() || e.teeth.is_some() {
                    return Err(c.bad(
                        "encoder.framing",
                        "\"missing-tooth\"",
                        "gaps and teeth describe a pattern wheel: framing = \"pattern\"",
                    ));
                }
                if m == 0 || u16::from(m) + 3 > lines {
                    return Err(c.bad(
                        key,
                        m,
                        format!(
                            "missing teeth: 1 to {} on {lines} positions (3 teeth at least)",
                            lines.saturating_sub(3)
                        ),
                    ));
                }
                // The core numbers the gap at the end of the grid: the last M positions are absent.
                all[..usize::from(lines - u16::from(m))].to_vec()
            }
            FramingSpec::Pattern => {
                if e.missing != 0 {
                    return Err(both(
                        "encoder.framing",
                        "encoder.missing",
                        "a pattern wheel is given by gaps or teeth",
                    ));
                }
                match (&e.gaps, &e.teeth) {
                    (Some(_), Some(_)) => {
                        return Err(c.bad(
                            "encoder.teeth",
                            "[...]",
                            "not together with gaps: one description of the wheel",
                        ))
                    }
                    (Some(gaps), None) => {
                        let mut present = vec![true; usize::from(lines)];
                        // The gap each missing position belongs to.
                        let mut owner: Vec<Option<usize>> = vec![None; usize::from(lines)];
                        for (i, &[start, count]) in gaps.iter().enumerate() {
                            let k = format!("encoder.gaps[{}]", i + 1);
                            if start >= lines {
                                return Err(c.bad(
                                    &format!("{k}[1]"),
                                    start,
                                    format!("a gap starts at a grid position, 0 to {}", lines - 1),
                                ));
                            }
                            if count == 0 || count >= lines {
                                return Err(c.bad(
                                    &format!("{k}[2]"),
                                    count,
                                    format!("missing positions, 1 to {}", lines - 1),
                                ));
                            }
                            // Each gap once, with a tooth after it before the next: gaps
                            // that overlap or touch are one gap of another length, a
                            // different wheel than the list says.
                            let at = |p: u16| usize::from(p % lines);
                            let before = start + lines - 1;
                            let after = start + count;
                            let clash = (start..start + count)
                                .map(|p| (owner[at(p)], "overlaps"))
                                .chain([
                                    (owner[at(before)], "touches"),
                                    (owner[at(after)], "touches"),
                                ])
                                .find_map(|(o, how)| o.map(|j| (j, how)));
                            if let Some((j, how)) = clash {
                                return Err(c.bad(
                                    &k,
                                    format!("[{start}, {count}]"),
                                    format!(
                                        "{how} encoder.gaps[{}] = [{}, {}]: list each gap once, \
                                         with at least one tooth between two gaps (gaps that \
                                         meet are one gap of their positions together)",
                                        j + 1,
                                        gaps[j][0],
                                        gaps[j][1]
                                    ),
                                ));
                            }
                            for p in start..start + count {
                                present[at(p)] = false;
                                owner[at(p)] = Some(i);
                            }
                        }
                        all.into_iter()
                            .filter(|&p| present[usize::from(p)])
                            .collect()
                    }
                    (None, Some(teeth)) => {
                        let mut sorted = Vec::with_capacity(teeth.len());
                        for (i, &t) in teeth.iter().enumerate() {
                            let k = format!("encoder.teeth[{}]", i + 1);
                            if t >= lines {
                                return Err(c.bad(
                                    &k,
                                    t,
                                    format!("a grid position, 0 to {}", lines - 1),
                                ));
                            }
                            if sorted.contains(&t) {
                                return Err(c.bad(&k, t, "listed twice"));
                            }
                            sorted.push(t);
                        }
                        sorted.sort_unstable();
                        sorted
                    }
                    (None, None) => return Err(c.bad(
                        "encoder.framing",
                        "\"pattern\"",
                        "a pattern wheel needs its gaps = [[start, count], ...] or teeth = [...]",
                    )),
                }
            }
        };
    let most = drive_monitor::encoder::MAX_PATTERN_TEETH;
    if matches!(framing, FramingSpec::Pattern) && (teeth.len() < 3 || teeth.len() > most) {
        let key = if e.gaps.is_some() {
            "encoder.gaps"
        } else {
            "encoder.teeth"
        };
        return Err(c.bad(
            key,
            format!("{} teeth", teeth.len()),
            format!("a pattern wheel has 3 to {most} teeth"),
        ));
    }
    if matches!(framing, FramingSpec::MissingTooth) && teeth.len() > most {
        return Err(c.bad(
            lines_key,
            lines,
            format!("a missing-tooth wheel has at most {most} teeth"),
        ));
    }
    Ok(WheelDesc {
        lines,
        framing,
        teeth,
    })
}

fn encoder(e: &EncoderSpec, c: &Checker) -> Result<(), SceneError> {
    let w = wheel(e, c)?;
    c.range("encoder.timer_hz", e.timer_hz, 1.0, false, 1e10, "Hz")?;
    c.count("encoder.counter_bits", e.counter_bits.into(), 16, 32)?;
    if ![1, 2, 4, 8].contains(&e.prescaler) {
        return Err(c.bad("encoder.prescaler", e.prescaler, "allowed 1, 2, 4 or 8"));
    }
    // The core's rules (`drive_monitor::encoder::Encoder::new`), with their reasons.
    let framing = e.framing();
    let framed_by_pattern = matches!(framing, FramingSpec::MissingTooth | FramingSpec::Pattern);
    if e.prescaler != 1 && framed_by_pattern {
        let how = match e.framing_implied_by() {
            Some(by) => format!("implied by `{by} = {}`", c.shown(by, "?")),
            None => "as written".to_string(),
        };
        return Err(c.bad(
            "encoder.prescaler",
            e.prescaler,
            format!(
                "a wheel framed by its pattern (framing = \"{}\", {how}) is captured edge by \
                 edge, each tooth's pitch told apart: the prescaler is for uniform discs only \
                 (prescaler = 1 here)",
                framing.name()
            ),
        ));
    }
    let lines = w.teeth.len() as u64;
    let p = u64::from(e.prescaler);
    if e.prescaler != 1 && (lines % p != 0 || lines / p < 2) {
        return Err(c.bad(
            "encoder.prescaler",
            e.prescaler,
            format!(
                "the prescaler must divide the disc's {lines} lines into whole captures, at \
                 least 2 a revolution"
            ),
        ));
    }
    let edges = w.teeth.len() as u64 / u64::from(e.prescaler).max(1);
    let span = (drive_monitor::encoder::MAX_SPAN as u64).min(edges.max(1));
    c.count("encoder.estimator_edges", e.estimator_edges.into(), 1, span)?;
    let t = &e.tolerances;
    for (key, x, lo, hi) in [
        ("encoder.tolerances.accept", t.accept, 1.05, 2.0),
        (
            "encoder.tolerances.glitch_fraction",
            t.glitch_fraction,
            0.05,
            0.6,
        ),
        ("encoder.tolerances.fault_margin", t.fault_margin, 0.05, 2.0),
    ] {
        if let Some(x) = x {
            c.range(key, x, lo, false, hi, "")?;
        }
    }
    c.non_negative("encoder.jitter", e.jitter, MAX_JITTER, "s")?;
    c.range("encoder.runout", e.runout, 0.0, false, 0.5, "(e/r)")?;
    c.magnitude("encoder.runout_phase", e.runout_phase, MAX_ANGLE, "rad")?;
    c.non_negative("encoder.pitch_error", e.pitch_error, 0.1, "rad")?;
    for (key, p) in [
        ("encoder.drop_probability", e.drop_probability),
        ("encoder.glitch_probability", e.glitch_probability),
    ] {
        c.non_negative(key, p, MAX_FAULT_PROBABILITY, "")?;
    }
    if let Some([a, b]) = e.glitch_window {
        c.range(
            "encoder.glitch_window[1]",
            a,
            0.0,
            false,
            1.0,
            "of a tooth interval",
        )?;
        c.range(
            "encoder.glitch_window[2]",
            b,
            0.0,
            false,
            1.0,
            "of a tooth interval",
        )?;
        if b < a {
            return Err(c.bad(
                "encoder.glitch_window[2]",
                b,
                format!(
                    "must not be below glitch_window[1] = {}",
                    c.shown("encoder.glitch_window[1]", a)
                ),
            ));
        }
    }
    Ok(())
}

/// `[cranking]` and `[capture]`.
fn cranking_and_capture(scene: &Scene, c: &Checker) -> Result<(), SceneError> {
    if let Some(k) = &scene.cranking {
        c.range("cranking.ripple", k.ripple, 0.0, false, 0.9, "(relative)")?;
        c.range(
            "cranking.strokes",
            k.strokes,
            0.0,
            true,
            MAX_ORDER,
            "per revolution",
        )?;
        c.magnitude("cranking.phase", k.phase, MAX_ANGLE, "rad")?;
        if !matches!(
            scene.motor,
            Some(MotorSpec::Speed { .. } | MotorSpec::Ramp { .. } | MotorSpec::Profile { .. })
        ) {
            return Err(SceneError::Rule {
                file: c.file.to_path_buf(),
                key: "cranking".into(),
                value: "(table)".into(),
                rule: "a cranking ripple modulates a prescribed speed: [motor] model = \"speed\", \"ramp\" or \"profile\"".into(),
            });
        }
        // The ripple scales the mean speed by (1 + ripple·sin(strokes·φ + phase)), a function
        // of the angle: a shaft turning backwards has no such law. (Without [cranking] a
        // negative speed runs the shaft backwards.)
        let speeds: Vec<(String, f64)> = match &scene.motor {
            Some(MotorSpec::Speed { speed }) => vec![("motor.speed".into(), *speed)],
            Some(MotorSpec::Ramp { from, to, .. }) => {
                vec![("motor.from".into(), *from), ("motor.to".into(), *to)]
            }
            // (A profile's speeds are [0, 1e5] rad/s with or without [cranking].)
            _ => Vec::new(),
        };
        if let Some((key, w)) = speeds.into_iter().find(|(_, w)| *w < 0.0) {
            return Err(c.bad(
                &key,
                w,
                format!(
                    "a cranking ripple needs a forward speed: allowed [0, {}] rad/s with \
                     [cranking] (it modulates the speed by the shaft's angle; without \
                     [cranking] a negative speed runs the shaft backwards)",
                    num(MAX_SPEED)
                ),
            ));
        }
    }
    if let Some(k) = &scene.capture {
        c.range("capture.sample_rate", k.sample_rate, 1.0, false, 1e10, "Hz")?;
        if k.sample_rate.fract() != 0.0 {
            return Err(c.bad("capture.sample_rate", k.sample_rate, "a whole number of Hz"));
        }
        c.range("capture.duty", k.duty, 0.0, true, 0.99, "of a grid pitch")?;
        c.range("capture.noise_width", k.noise_width, 1e-12, false, 1.0, "s")?;
    }
    Ok(())
}

fn monitor(scene: &Scene, c: &Checker) -> Result<(), SceneError> {
    let Some(m) = &scene.monitor else {
        return Ok(());
    };
    if let Some(l) = m.delta_limit {
        // A limit finer than f64 resolves the speed can be neither designed for
        // (`DriveModel::flywheel_for`) nor monitored: one check for every command. δ reaches 2
        // only when the shaft stops once a cycle: a limit of 2 could never be exceeded (the
        // core's design refuses it).
        let lo = drive_monitor::drive::MIN_DELTA_TARGET;
        if !(l.is_finite() && (lo..2.0).contains(&l)) {
            let why = if l >= 2.0 {
                ": δ = 2(ω max − ω min)/(ω max + ω min) reaches 2 only when the shaft stops"
            } else if l > 0.0 && l < lo {
                ": a smaller δ is finer than f64 resolves the speed"
            } else {
                ""
            };
            return Err(c.bad(
                "monitor.delta_limit",
                l,
                format!("allowed [{}, 2){why}", num(lo)),
            ));
        }
    }
    if let Some(n) = m.window_revolutions {
        let max = drive_monitor::irregularity::MAX_WINDOW_REVS;
        c.count("monitor.window_revolutions", n.into(), 1, max.into())?;
    }
    if let Some(w) = m.min_speed {
        c.range("monitor.min_speed", w, 1e-6, false, MAX_SPEED, "rad/s")?;
    }
    if let Some(t) = m.steady_tolerance {
        c.range("monitor.steady_tolerance", t, 1e-6, false, 0.5, "")?;
    }
    if let Some(r) = m.regime_margin {
        c.range("monitor.regime_margin", r, 1e-4, false, 0.5, "")?;
    }
    if let Some(w) = m.warning_fraction {
        c.range("monitor.warning_fraction", w, 0.0, true, 1.0, "")?;
    }
    Ok(())
}

fn vibration(scene: &Scene, c: &Checker) -> Result<(), SceneError> {
    let n = scene.platform.len() as u64;
    for (i, p) in scene.platform.iter().enumerate() {
        let k = format!("platform[{}]", i + 1);
        c.range(&format!("{k}.mass"), p.mass, 1e-6, false, MAX_MASS, "kg")?;
        c.range(
            &format!("{k}.stiffness"),
            p.stiffness,
            1e-6,
            false,
            MAX_STIFFNESS,
            "N/m",
        )?;
        c.non_negative(&format!("{k}.damping"), p.damping, MAX_DAMPING, "N·s/m")?;
    }
    for (i, cp) in scene.coupling.iter().enumerate() {
        let k = format!("coupling[{}]", i + 1);
        for (j, b) in cp.between.iter().enumerate() {
            c.count(&format!("{k}.between[{}]", j + 1), (*b).into(), 1, n.max(1))?;
        }
        if cp.between[0] == cp.between[1] {
            return Err(c.bad(
                &format!("{k}.between"),
                format!("{:?}", cp.between),
                "two different platforms",
            ));
        }
        c.range(
            &format!("{k}.stiffness"),
            cp.stiffness,
            1e-6,
            false,
            MAX_STIFFNESS,
            "N/m",
        )?;
        c.non_negative(&format!("{k}.damping"), cp.damping, MAX_DAMPING, "N·s/m")?;
    }
    if let Some(ab) = &scene.autobalancer {
        autobalancer(ab, n, c)?;
        // Every platform joined to the balancer's through couplings: one the rotor cannot
        // move is no part of the machine (three platforms without a coupling had two modes
        // the rotor cannot excite listed as its resonances and additional speeds, with capture
        // lines copied from the first).
        let mut reached = vec![false; scene.platform.len()];
        if let Some(r) = reached.get_mut(usize::from(ab.platform).wrapping_sub(1)) {
            *r = true;
        }
        loop {
            let mut grew = false;
            for cp in &scene.coupling {
                let [a, b] = cp.between.map(|p| usize::from(p).wrapping_sub(1));
                if let (Some(&ra), Some(&rb)) = (reached.get(a), reached.get(b)) {
                    if ra != rb {
                        reached[a] = true;
                        reached[b] = true;
                        grew = true;
                    }
                }
            }
            if !grew {
                break;
            }
        }
        let apart: Vec<String> = (0..reached.len())
            .filter(|&i| !reached[i])
            .map(|i| format!("platform[{}]", i + 1))
            .collect();
        if !apart.is_empty() {
            return Err(c.bad(
                "autobalancer.platform",
                ab.platform,
                format!(
                    "{} {} joined to the balancer's platform by no [[coupling]]: the rotor \
                     cannot move {}, so {} no part of the machine (a forgotten coupling?); \
                     couple {} to the machine, or leave {} out",
                    apart.join(", "),
                    if apart.len() == 1 { "is" } else { "are" },
                    if apart.len() == 1 { "it" } else { "them" },
                    if apart.len() == 1 {
                        "it is"
                    } else {
                        "they are"
                    },
                    if apart.len() == 1 { "it" } else { "them" },
                    if apart.len() == 1 { "it" } else { "them" },
                ),
            ));
        }
    }
    Ok(())
}

fn autobalancer(ab: &AutobalancerSpec, platforms: u64, c: &Checker) -> Result<(), SceneError> {
    // Checked for every kind: a value given for a key the kind does not use is still read.
    if let Some(j) = ab.pendulum_inertia {
        c.non_negative("autobalancer.pendulum_inertia", j, MAX_INERTIA, "kg·m²")?;
        // Balls and rollers take their own inertia from the kind (κ = 7/5, 3/2): a pendulum
        // inertia given with them would be read and silently ignored.
        let kind = match ab.kind {
            BalancerKindSpec::Ball => Some("ball"),
            BalancerKindSpec::Roller => Some("roller"),
            BalancerKindSpec::Pendulum => None,
        };
        if let Some(kind) = kind {
            return Err(c.bad(
                "autobalancer.pendulum_inertia",
                j,
                format!(
                    "belongs to kind = \"pendulum\" only: a {kind}'s inertia is given by its kind \
                     (κ = 7/5 for balls, 3/2 for rollers); remove the key, or set kind = \"pendulum\""
                ),
            ));
        }
    }
    c.count(
        "autobalancer.platform",
        ab.platform.into(),
        1,
        platforms.max(1),
    )?;
    let max_loads = crate::engine::vibration::MAX_LOADS as u64;
    c.count("autobalancer.loads", ab.loads.into(), 2, max_loads)?;
    c.range(
        "autobalancer.load_mass",
        ab.load_mass,
        1e-9,
        false,
        MAX_MASS,
        "kg",
    )?;
    c.range(
        "autobalancer.radius",
        ab.radius,
        1e-6,
        false,
        MAX_LENGTH,
        "m",
    )?;
    c.non_negative("autobalancer.housing_mass", ab.housing_mass, MAX_MASS, "kg")?;
    c.range(
        "autobalancer.viscosity",
        ab.viscosity,
        1e-9,
        false,
        MAX_DAMPING,
        "N·s/m",
    )?;
    if let Some(d) = ab.rotor_unbalance {
        // More than the loads can balance (loads × load_mass × radius) is a machine to
        // simulate too: the loads then settle at their limit (judged `saturated`).
        c.non_negative(
            "autobalancer.rotor_unbalance",
            d,
            MAX_MASS * MAX_LENGTH,
            "kg·m",
        )?;
    }
    Ok(())
}

fn rotor(scene: &Scene, c: &Checker) -> Result<(), SceneError> {
    if let Some(r) = &scene.rotor {
        c.range("rotor.mass", r.mass, 1e-6, false, MAX_MASS, "kg")?;
        c.magnitude("rotor.centre_of_mass", r.centre_of_mass, MAX_LENGTH, "m")?;
        c.magnitude("rotor.support_a", r.support_a, MAX_LENGTH, "m")?;
        c.magnitude("rotor.support_b", r.support_b, MAX_LENGTH, "m")?;
        c.range("rotor.grade", r.grade, 1e-3, false, 1e4, "mm/s")?;
        c.range(
            "rotor.service_speed",
            r.service_speed,
            1e-3,
            false,
            MAX_SPEED,
            "rad/s",
        )?;
        if let Some(l) = r.support_load_limit {
            for (i, x) in l.iter().enumerate() {
                let key = format!("rotor.support_load_limit[{}]", i + 1);
                c.range(&key, *x, 1e-3, false, MAX_FORCE, "N")?;
            }
        }
    }
    for (i, u) in scene.unbalance.iter().enumerate() {
        let k = format!("unbalance[{}]", i + 1);
        c.magnitude(&format!("{k}.z"), u.z, MAX_LENGTH, "m")?;
        c.non_negative(&format!("{k}.amount"), u.amount, 1e6, "kg·m")?;
        c.magnitude(&format!("{k}.angle"), u.angle, MAX_ANGLE, "degrees")?;
    }
    if let Some(p) = &scene.process_load {
        c.non_negative("process_load.per_length", p.per_length, MAX_FORCE, "N/m")?;
        c.magnitude("process_load.from", p.from, MAX_LENGTH, "m")?;
        c.magnitude("process_load.to", p.to, MAX_LENGTH, "m")?;
        if p.to <= p.from {
            return Err(c.bad(
                "process_load.to",
                p.to,
                format!(
                    "must be above from = {}",
                    c.shown("process_load.from", p.from)
                ),
            ));
        }
        c.magnitude("process_load.angle", p.angle, MAX_ANGLE, "degrees")?;
    }
    Ok(())
}

/// Which tables go together.
fn structure(scene: &Scene, c: &Checker) -> Result<(), SceneError> {
    let missing = |key: &str, why: &str| SceneError::Rule {
        file: c.file.to_path_buf(),
        key: key.to_string(),
        value: "(missing)".into(),
        rule: why.to_string(),
    };
    if scene.platform.len() > drive_monitor::balancer::MAX_PLATFORMS {
        return Err(c.bad_count(
            "platform",
            scene.platform.len(),
            "tables",
            format!(
                "at most {} platforms",
                drive_monitor::balancer::MAX_PLATFORMS
            ),
        ));
    }
    if !scene.platform.is_empty() && scene.autobalancer.is_none() {
        return Err(missing(
            "autobalancer",
            "a vibration machine needs its auto-balancer",
        ));
    }
    if scene.autobalancer.is_some() && scene.platform.is_empty() {
        return Err(missing("platform", "the auto-balancer needs a platform"));
    }
    if (!scene.unbalance.is_empty() || scene.process_load.is_some()) && scene.rotor.is_none() {
        return Err(missing(
            "rotor",
            "unbalances and a process load need a [rotor]",
        ));
    }
    if scene.unbalance.len() > crate::app::predict::MAX_UNBALANCES {
        return Err(c.bad_count(
            "unbalance",
            scene.unbalance.len(),
            "tables",
            format!(
                "at most {} unbalances (the rotor's fixed capacity)",
                crate::app::predict::MAX_UNBALANCES
            ),
        ));
    }
    Ok(())
}

/// What would fit, for an encoder configuration the core refused because the speed range
/// does not fit the timer: the longest pitch at the minimum speed lasts more ticks than the
/// counter holds (`min_speed`), a `K`-edge sample of such pitches more than 32 bits
/// (`estimator.edges`), or fewer than 2 ticks (`timer_hz`). The bound is found by asking the
/// core itself (doubling, then bisecting the minimum speed or the timer clock, every other
/// field as given), so it is the core's own rule, and rounded to three significant digits on
/// the side that fits. `min_speed` and `timer_hz` name the two knobs as the user writes them
/// (scene keys or options), and `counter_bits` the counter's width. `None` for any other
/// error, or where no value fits.
pub fn speed_range_hint(
    config: &drive_monitor::encoder::EncoderConfig,
    e: ConfigError,
    min_speed: &str,
    timer_hz: &str,
    counter_bits: &str,
) -> Option<String> {
    use drive_monitor::encoder::{Encoder, EncoderConfig};
    let fits = |f: &dyn Fn(&mut EncoderConfig)| {
        let mut c = *config;
        f(&mut c);
        Encoder::new(c).is_ok()
    };
    // The bound on `x` between `bad` (refused) and `good` (accepted), to 1e-6 relative, rounded
    // to three significant digits towards `good`.
    let bound = |bad: f64, good: f64, set: &dyn Fn(&mut EncoderConfig, f64)| {
        let (mut bad, mut good) = (bad, good);
        while (good - bad).abs() > 1e-6 * good.abs() {
            let mid = 0.5 * (bad + good);
            if fits(&|c| set(c, mid)) {
                good = mid;
            } else {
                bad = mid;
            }
        }
        // Three significant digits, one step of the third towards `good` if rounding left it.
        let digits = |x: f64| format!("{x:.2e}").parse::<f64>().unwrap_or(x);
        let step = 10f64.powi(good.abs().log10().floor() as i32 - 2);
        let mut r = digits(good);
        if !fits(&|c| set(c, r)) {
            r = digits(if good > bad { r + step } else { r - step });
        }
        if fits(&|c| set(c, r)) {
            r
        } else {
            good
        }
    };
    // Doubles (`up`) or halves `x` from `start` until the core accepts it: the first value
    // accepted, if any within 60 steps.
    let search = |start: f64, up: bool, set: &dyn Fn(&mut EncoderConfig, f64)| {
        let mut x = start;
        for _ in 0..60 {
            let next = if up { x * 2.0 } else { x * 0.5 };
            if fits(&|c| set(c, next)) {
                return Some(bound(x, next, set));
            }
            x = next;
        }
        None
    };
    let set_speed = |c: &mut EncoderConfig, x: f64| c.min_speed = x;
    let set_timer = |c: &mut EncoderConfig, x: f64| c.timer_hz = x;
    match e {
        ConfigError::Inconsistent("min_speed") | ConfigError::Inconsistent("estimator.edges") => {
            let what = if e == ConfigError::Inconsistent("min_speed") {
                "the longest pitch at the minimum speed lasts more ticks than the counter holds"
            } else {
                "a sample of the estimator's edges at the minimum speed lasts more ticks than 32 bits hold"
            };
            let speed = search(config.min_speed, true, &set_speed)?;
            let mut hint = format!(
                "{what}: `{min_speed}` at least {} rad/s would fit",
                num(speed)
            );
            if let Some(t) = search(config.timer_hz, false, &set_timer) {
                let _ = write!(hint, ", or `{timer_hz}` at most {} Hz", num(t));
            }
            // A wider counter, where the counter is what is short.
            let wider = (config.counter_bits.saturating_add(1)..=32)
                .find(|&b| fits(&|c: &mut EncoderConfig| c.counter_bits = b));
            if let Some(b) = wider {
                let _ = write!(hint, ", or `{counter_bits}` = {b}");
            }
            Some(hint)
        }
        ConfigError::Inconsistent("timer_hz") => {
            let what =
                "the longest pitch at the minimum speed lasts fewer than 2 ticks of the timer";
            let timer = search(config.timer_hz, true, &set_timer)?;
            let speed = search(config.min_speed, false, &set_speed);
            Some(match speed {
                Some(s) => format!(
                    "{what}: `{timer_hz}` at least {} Hz would fit, or `{min_speed}` at most {} rad/s",
                    num(timer),
                    num(s)
                ),
                None => format!("{what}: `{timer_hz}` at least {} Hz would fit", num(timer)),
            })
        }
        _ => None,
    }
}
