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
    AutobalancerSpec, EncoderSpec, FramingSpec, Harmonic, MotorSpec, Scene, SceneError,
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

    /// `key`'s value as written, or `x` marked as the default.
    pub fn shown(&self, key: &str, x: impl std::fmt::Display) -> String {
        match self.written.get(key) {
            Some(v) => v.to_string(),
            None => format!("{x} (the default)"),
        }
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
        let keys = core_keys(section, e.parameter());
        let mut quoted = String::new();
        for (i, k) in keys.iter().enumerate() {
            if i > 0 {
                quoted.push_str(", ");
            }
            let _ = match self.written.get(k) {
                Some(v) => write!(quoted, "`{k} = {v}`"),
                None => match default_of(scene, k) {
                    Some(v) => write!(quoted, "`{k} = {v}` (the default)"),
                    None => write!(quoted, "`{k}`"),
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
        ConfigError::Inconsistent(_) => "contradict each other".into(),
    }
}

/// The scene keys a core configuration parameter stands for, the responsible key first: the
/// one place where the core's parameter names (`ConfigError::parameter`) meet the scene's
/// keys. `section` is the scene table the configuration was built from. A parameter the table
/// does not list is taken to be `section.parameter`.
pub fn core_keys(section: &str, parameter: &str) -> Vec<String> {
    let listed: &[&str] = match (section, parameter) {
        // drive_monitor::encoder::Encoder::new, from [encoder] and [monitor].
        ("encoder", "lines") => &["encoder.lines"],
        ("encoder", "pattern.positions" | "pattern.teeth") => {
            &["encoder.lines", "encoder.missing", "encoder.framing"]
        }
        ("encoder", "estimator.edges") => &[
            "encoder.estimator_edges",
            "encoder.lines",
            "monitor.min_speed",
            "encoder.timer_hz",
        ],
        // The longest pitch at min_speed must last at least 2 ticks and fit the counter.
        ("encoder", "timer_hz" | "min_speed") => &[
            "monitor.min_speed",
            "encoder.timer_hz",
            "encoder.lines",
            "encoder.missing",
            "encoder.counter_bits",
        ],
        ("encoder", "counter_bits") => &["encoder.counter_bits"],
        // drive_monitor::irregularity::WindowConfig, from [monitor] and the load's orders.
        ("monitor", "window.revolutions") => &["monitor.window_revolutions"],
        ("monitor", "window.load_order") => &["load.harmonics", "monitor.window_revolutions"],
        ("monitor", "steady_tolerance") => &["monitor.steady_tolerance"],
        ("monitor", "delta_limit") => &["monitor.delta_limit"],
        // drive_monitor::drive, from [shaft], [motor] and [load].
        ("shaft", "inertia") => &["shaft.inertia"],
        ("shaft", "flywheel") => &["shaft.flywheel"],
        ("shaft", "shaft.harmonics") => &["shaft.inertia_harmonics", "shaft.inertia"],
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

/// The value a key takes when the file does not give it (for the keys [`core_keys`] lists).
fn default_of(scene: &Scene, key: &str) -> Option<String> {
    let e = scene.encoder.as_ref();
    let m = scene.monitor.as_ref();
    match key {
        "encoder.missing" => e.map(|e| e.missing.to_string()),
        "encoder.counter_bits" => e.map(|e| e.counter_bits.to_string()),
        "encoder.estimator_edges" => e.map(|e| e.estimator_edges.to_string()),
        "encoder.framing" => e.map(|e| format!("{:?}", e.framing)),
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
    for (i, h) in list.iter().enumerate() {
        let k = format!("{key}[{}]", i + 1);
        c.positive(&format!("{k}.order"), h.order, MAX_ORDER, "per revolution")?;
        c.magnitude(&format!("{k}.amplitude"), h.amplitude, amplitude, "")?;
        c.magnitude(&format!("{k}.phase"), h.phase, MAX_ANGLE, "rad")?;
    }
    Ok(())
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
        None => {}
    }
    if let Some(l) = &scene.load {
        c.magnitude("load.mean", l.mean, MAX_TORQUE, "N·m")?;
        harmonics(c, "load.harmonics", &l.harmonics, MAX_TORQUE)?;
    }
    Ok(())
}

fn encoder(e: &EncoderSpec, c: &Checker) -> Result<(), SceneError> {
    c.count("encoder.lines", e.lines.into(), 2, MAX_LINES.into())?;
    c.range("encoder.timer_hz", e.timer_hz, 1.0, false, 1e10, "Hz")?;
    c.count("encoder.counter_bits", e.counter_bits.into(), 16, 32)?;
    match e.framing {
        FramingSpec::MissingTooth => {
            c.count("encoder.missing", e.missing.into(), 1, 3)?;
            let room = 2 * u64::from(e.missing) + 2;
            if u64::from(e.lines) < u64::from(e.missing) + room {
                return Err(c.bad(
                    "encoder.lines",
                    e.lines,
                    format!(
                        "too few for missing = {}: at least {} lines",
                        c.shown("encoder.missing", e.missing),
                        u64::from(e.missing) + room
                    ),
                ));
            }
        }
        FramingSpec::Index | FramingSpec::None if e.missing != 0 => {
            return Err(c.bad(
                "encoder.missing",
                e.missing,
                "only with framing = \"missing-tooth\" (this encoder has no gap)",
            ));
        }
        _ => {}
    }
    let edges = u64::from(e.lines) - u64::from(e.missing);
    let span = (drive_monitor::encoder::MAX_SPAN as u64).min(edges);
    c.count("encoder.estimator_edges", e.estimator_edges.into(), 1, span)?;
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
    Ok(())
}

fn monitor(scene: &Scene, c: &Checker) -> Result<(), SceneError> {
    let Some(m) = &scene.monitor else {
        return Ok(());
    };
    if let Some(l) = m.delta_limit {
        // A limit finer than f64 resolves the speed can be neither designed for
        // (`DriveModel::flywheel_for`) nor monitored: one check for every command.
        c.range(
            "monitor.delta_limit",
            l,
            drive_monitor::drive::MIN_DELTA_TARGET,
            false,
            2.0,
            "",
        )?;
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
    }
    Ok(())
}

fn autobalancer(ab: &AutobalancerSpec, platforms: u64, c: &Checker) -> Result<(), SceneError> {
    // Checked for every kind: a value given for a key the kind does not use is still read.
    if let Some(j) = ab.pendulum_inertia {
        c.non_negative("autobalancer.pendulum_inertia", j, MAX_INERTIA, "kg·m²")?;
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
        return Err(c.bad(
            "platform",
            format!("{} tables", scene.platform.len()),
            "at most 3 platforms",
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
        return Err(c.bad(
            "unbalance",
            format!("{} tables", scene.unbalance.len()),
            format!("at most {} unbalances", crate::app::predict::MAX_UNBALANCES),
        ));
    }
    Ok(())
}
