//! Scene files: a machine described in TOML, SI units throughout.
//!
//! Every table is optional except what the effects present need; an effect is simulated only
//! when its table is present. Unknown keys are errors (a misspelt key must not be silently
//! ignored), and so are missing required keys and impossible values; every error names the
//! file and the key.

use serde::Deserialize;
use std::path::{Path, PathBuf};

/// An error in a scene file, naming the file and the key.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read.
    #[error("{file}: cannot read: {source}")]
    Io {
        /// The scene file.
        file: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// TOML syntax, an unknown or missing key, or a value of the wrong type.
    #[error("{file}: {message}")]
    Parse {
        /// The scene file.
        file: PathBuf,
        /// The parser's message (names the key and the line).
        message: String,
    },
    /// A value outside what its key allows, quoted as written.
    #[error("{file}: `{key} = {value}`: {rule}")]
    Rule {
        /// The scene file.
        file: PathBuf,
        /// The key, e.g. `platform[2].mass`.
        key: String,
        /// Its value as written in the file.
        value: String,
        /// What is allowed.
        rule: String,
    },
    /// Values the core rejected together, each key quoted with its value as written
    /// ([`crate::app::check::core_keys`]).
    #[error("{file}: {keys}: {message}")]
    Core {
        /// The scene file.
        file: PathBuf,
        /// The key most likely responsible.
        key: String,
        /// Every key involved, with its value.
        keys: String,
        /// What the core found.
        message: String,
    },
    /// A value that parses but is impossible.
    #[error("{file}: `{key}`: {message}")]
    Value {
        /// The scene file.
        file: PathBuf,
        /// The offending key, e.g. `encoder.timer_hz`.
        key: String,
        /// What is wrong with it.
        message: String,
    },
}

impl SceneError {
    /// An impossible value at `key` of `file`.
    pub fn value(file: &Path, key: &str, message: impl Into<String>) -> SceneError {
        SceneError::Value {
            file: file.to_path_buf(),
            key: key.to_string(),
            message: message.into(),
        }
    }
}

/// A whole scene.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct Scene {
    /// One-line description.
    #[serde(default)]
    pub description: Option<String>,
    /// Simulation settings.
    #[serde(default)]
    pub simulation: SimulationSpec,
    /// The drive shaft's inertia.
    pub shaft: Option<ShaftSpec>,
    /// The motor (or a prescribed speed).
    pub motor: Option<MotorSpec>,
    /// The load torque.
    pub load: Option<LoadSpec>,
    /// Engine-like cranking: a compression ripple on the prescribed speed.
    pub cranking: Option<CrankingSpec>,
    /// How `drive-sim run --capture` writes the signal a logic analyzer records.
    pub capture: Option<CaptureSpec>,
    /// The encoder and capture timer.
    pub encoder: Option<EncoderSpec>,
    /// Monitor settings.
    pub monitor: Option<MonitorSpec>,
    /// Vibration-machine platforms (1 to 3).
    #[serde(default)]
    pub platform: Vec<PlatformSpec>,
    /// Couplings between platforms.
    #[serde(default)]
    pub coupling: Vec<CouplingSpec>,
    /// The auto-balancer.
    pub autobalancer: Option<AutobalancerSpec>,
    /// A rotor on two supports (seed 002).
    pub rotor: Option<RotorSpec>,
    /// Unbalances of that rotor.
    #[serde(default)]
    pub unbalance: Vec<UnbalanceSpec>,
    /// A distributed process load on that rotor.
    pub process_load: Option<ProcessLoadSpec>,
    /// The values as written in the file, for errors.
    #[serde(skip)]
    pub written: crate::app::check::Written,
}

/// How to integrate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum IntegratorKind {
    /// Fixed-step classical Runge–Kutta 4.
    Rk4,
    /// Adaptive Dormand–Prince 5(4) with dense output.
    #[default]
    Dp5,
    /// Adaptive Dormand–Prince 8(5,3) with dense output.
    Dop853,
}

/// `[simulation]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SimulationSpec {
    /// Simulated time, s.
    #[serde(default = "default_duration")]
    pub duration: f64,
    /// Integrator.
    #[serde(default)]
    pub integrator: IntegratorKind,
    /// Relative tolerance (adaptive integrators).
    #[serde(default = "default_rtol")]
    pub rtol: f64,
    /// Absolute tolerance (adaptive integrators).
    #[serde(default = "default_atol")]
    pub atol: f64,
    /// Step of RK4, s; the adaptive integrators cap their step at 100 times this.
    #[serde(default = "default_step")]
    pub step: f64,
    /// Seed of every random effect (jitter, faults, perturbations).
    #[serde(default, deserialize_with = "seed")]
    pub seed: u64,
    /// Time to let transients settle before δ windows are counted as steady state, s.
    #[serde(default)]
    pub settle: Option<f64>,
}

fn default_duration() -> f64 {
    30.0
}
fn default_rtol() -> f64 {
    1e-9
}
fn default_atol() -> f64 {
    1e-9
}
fn default_step() -> f64 {
    1e-3
}

impl Default for SimulationSpec {
    fn default() -> Self {
        SimulationSpec {
            duration: default_duration(),
            integrator: IntegratorKind::default(),
            rtol: default_rtol(),
            atol: default_atol(),
            step: default_step(),
            seed: 0,
            settle: None,
        }
    }
}

/// `[shaft]`: inertia reduced to the shaft.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShaftSpec {
    /// Reduced inertia J, kg·m².
    pub inertia: f64,
    /// Added flywheel, kg·m².
    #[serde(default)]
    pub flywheel: f64,
    /// Position-dependent inertia J(φ) = inertia + flywheel + Σ amplitude·cos(order·φ + phase),
    /// positive for every φ (the amplitudes may add up to more than inertia + flywheel where
    /// J(φ)'s least value stays positive, as a crank-slider's series does).
    #[serde(default)]
    pub inertia_harmonics: Vec<Harmonic>,
    /// Initial speed, rad/s (default: the drive model's mean speed, where the motor carries
    /// the mean load; without one, a run needs it).
    #[serde(default)]
    pub initial_speed: Option<f64>,
}

/// A harmonic term `amplitude·sin(order·φ + phase)` (cos for inertia).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Harmonic {
    /// Cycles per revolution.
    pub order: f64,
    /// Amplitude (N·m for torque, kg·m² for inertia).
    pub amplitude: f64,
    /// Phase, rad.
    #[serde(default)]
    pub phase: f64,
}

/// `[motor]`. Read through [`MotorTable`], so that an error names the key inside the table
/// (a tagged enum would report only the table).
#[derive(Debug, Clone, Deserialize)]
#[serde(try_from = "MotorTable")]
pub enum MotorSpec {
    /// Parabolic characteristic through (ω0, 0) and (ω_m, M_m) (seed 000, eq. 3–4).
    Parabola {
        /// ω0, rad/s.
        no_load_speed: f64,
        /// ω_m, rad/s.
        breakdown_speed: f64,
        /// M_m, N·m.
        breakdown_torque: f64,
    },
    /// Kloss characteristic (seed 000, eq. 2).
    Kloss {
        /// Synchronous speed ω_s, rad/s.
        synchronous_speed: f64,
        /// Breakdown slip σ_m.
        breakdown_slip: f64,
        /// Breakdown torque M_m, N·m.
        breakdown_torque: f64,
    },
    /// A prescribed constant speed (no torque balance).
    Speed {
        /// ω, rad/s.
        speed: f64,
    },
    /// A prescribed linear speed ramp.
    Ramp {
        /// Speed at t = 0, rad/s.
        from: f64,
        /// Speed at `duration`, rad/s (held after).
        to: f64,
        /// Ramp time, s.
        duration: f64,
    },
    /// A prescribed piecewise-linear speed through `[t, ω]` points (held after the last).
    Profile {
        /// `[t, ω]` points, s and rad/s, in increasing time.
        points: Vec<[f64; 2]>,
    },
}

impl MotorSpec {
    /// The fastest |ω̄| a prescribed model gives, rad/s (`speed`, the larger end of a `ramp`,
    /// a `profile`'s fastest point), before any cranking ripple; `None` for a torque drive.
    pub fn prescribed_top(&self) -> Option<f64> {
        match self {
            MotorSpec::Speed { speed } => Some(speed.abs()),
            MotorSpec::Ramp { from, to, .. } => Some(from.abs().max(to.abs())),
            MotorSpec::Profile { points } => {
                Some(points.iter().map(|p| p[1].abs()).fold(0.0, f64::max))
            }
            MotorSpec::Parabola { .. } | MotorSpec::Kloss { .. } => None,
        }
    }
}

/// An array of exactly `N` values: more are refused as fewer are (serde's arrays read the first
/// `N` of a TOML array and drop the rest unsaid: `support_load_limit = [8000, 1, 2]` ran with
/// B's limit 1 N).
fn exact<'de, D, T, const N: usize>(d: D) -> Result<[T; N], D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    let values = Vec::<T>::deserialize(d)?;
    let n = values.len();
    values.try_into().map_err(|_| {
        serde::de::Error::invalid_length(n, &format!("an array of length {N}").as_str())
    })
}

/// An integer key held in a narrower type than the TOML integer it is read as. A value beyond
/// the type (negative, or above its largest) is held as the type's largest, which is outside
/// every such key's allowed range, so that the scene's checks refuse it with the key, the value
/// as written and the range (`` `encoder.lines = 70000`: allowed 2 to 8192 ``), where serde
/// alone said "invalid value: integer `70000`, expected u16"
/// (`scene_integers_beyond_their_type_are_refused_with_their_range`).
pub trait Whole: Sized + TryFrom<i64> {
    /// What a value beyond the type is held as.
    const BEYOND: Self;
    /// `v` as the type, or [`Whole::BEYOND`].
    fn saturate(v: i64) -> Self {
        Self::try_from(v).unwrap_or(Self::BEYOND)
    }
}

impl Whole for u8 {
    const BEYOND: Self = u8::MAX;
}

impl Whole for u16 {
    const BEYOND: Self = u16::MAX;
}

/// A TOML integer, any sign ("expected a whole number" for anything else).
struct Integer(i64);

impl<'de> Deserialize<'de> for Integer {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl serde::de::Visitor<'_> for V {
            type Value = Integer;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a whole number")
            }
            fn visit_i64<E: serde::de::Error>(self, v: i64) -> Result<Integer, E> {
                Ok(Integer(v))
            }
            fn visit_u64<E: serde::de::Error>(self, v: u64) -> Result<Integer, E> {
                Ok(Integer(i64::try_from(v).unwrap_or(i64::MAX)))
            }
        }
        d.deserialize_i64(V)
    }
}

/// An integer key read as [`Whole`].
fn whole<'de, D, T: Whole>(d: D) -> Result<T, D::Error>
where
    D: serde::Deserializer<'de>,
{
    Integer::deserialize(d).map(|Integer(v)| T::saturate(v))
}

/// [`whole`] for a key that may be left out (with `#[serde(default)]`).
fn whole_some<'de, D, T: Whole>(d: D) -> Result<Option<T>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    whole(d).map(Some)
}

/// A list of integers read as [`Whole`], for a key that may be left out.
fn whole_each<'de, D, T: Whole>(d: D) -> Result<Option<Vec<T>>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    let list = Vec::<Integer>::deserialize(d)?;
    Ok(Some(
        list.into_iter().map(|Integer(v)| T::saturate(v)).collect(),
    ))
}

/// Two integers read as [`Whole`] ([`exact`]ly two).
fn whole_pair<'de, D, T: Whole>(d: D) -> Result<[T; 2], D::Error>
where
    D: serde::Deserializer<'de>,
{
    exact::<D, Integer, 2>(d).map(|p| p.map(|Integer(v)| T::saturate(v)))
}

/// A list of pairs of integers read as [`Whole`] (see [`exact_each`]).
fn whole_pairs<'de, D, T: Whole>(d: D) -> Result<Option<Vec<[T; 2]>>, D::Error>
where
    D: serde::Deserializer<'de>,
{
    let list = exact_each::<D, Integer, 2>(d)?.unwrap_or_default();
    Ok(Some(
        list.into_iter()
            .map(|p| p.map(|Integer(v)| T::saturate(v)))
            .collect(),
    ))
}

/// `simulation.seed`: any integer from 0 (a TOML integer is at most 2⁶³ − 1); a negative one
/// is refused naming the key and the range.
fn seed<'de, D>(d: D) -> Result<u64, D::Error>
where
    D: serde::Deserializer<'de>,
{
    let Integer(v) = Integer::deserialize(d)?;
    u64::try_from(v).map_err(|_| {
        serde::de::Error::custom(format!(
            "`simulation.seed = {v}`: allowed 0 to {} (a whole number)",
            i64::MAX
        ))
    })
}

/// [`exact`] for a key that may be left out (with `#[serde(default)]`).
fn exact_some<'de, D, T, const N: usize>(d: D) -> Result<Option<[T; N]>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    exact(d).map(Some)
}

/// A list of arrays of exactly `N` values each (see [`exact`]), for a key that may be left
/// out (with `#[serde(default)]`).
fn exact_each<'de, D, T, const N: usize>(d: D) -> Result<Option<Vec<[T; N]>>, D::Error>
where
    D: serde::Deserializer<'de>,
    T: Deserialize<'de>,
{
    #[derive(Deserialize)]
    #[serde(bound = "T: Deserialize<'de>")]
    struct Exact<T, const N: usize>(#[serde(deserialize_with = "exact")] [T; N]);
    let list = Vec::<Exact<T, N>>::deserialize(d)?;
    Ok(Some(list.into_iter().map(|Exact(a)| a).collect()))
}

/// `[motor] model`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum MotorModel {
    /// [`MotorSpec::Parabola`].
    Parabola,
    /// [`MotorSpec::Kloss`].
    Kloss,
    /// [`MotorSpec::Speed`].
    Speed,
    /// [`MotorSpec::Ramp`].
    Ramp,
    /// [`MotorSpec::Profile`].
    Profile,
}

/// `[motor]` as written: the model and every key any model has, each with its own type.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotorTable {
    /// The model.
    pub model: MotorModel,
    /// Parabola: ω0.
    pub no_load_speed: Option<f64>,
    /// Parabola: ω_m.
    pub breakdown_speed: Option<f64>,
    /// Parabola and Kloss: M_m.
    pub breakdown_torque: Option<f64>,
    /// Kloss: ω_s.
    pub synchronous_speed: Option<f64>,
    /// Kloss: σ_m.
    pub breakdown_slip: Option<f64>,
    /// Speed: ω.
    pub speed: Option<f64>,
    /// Ramp: start speed.
    pub from: Option<f64>,
    /// Ramp: end speed.
    pub to: Option<f64>,
    /// Ramp: ramp time.
    pub duration: Option<f64>,
    /// Profile: `[t, ω]` points.
    #[serde(default, deserialize_with = "exact_each")]
    pub points: Option<Vec<[f64; 2]>>,
}

impl TryFrom<MotorTable> for MotorSpec {
    type Error = String;

    fn try_from(t: MotorTable) -> Result<Self, String> {
        let (model, keys): (&str, &[&str]) = match t.model {
            MotorModel::Parabola => (
                "parabola",
                &["no_load_speed", "breakdown_speed", "breakdown_torque"],
            ),
            MotorModel::Kloss => (
                "kloss",
                &["synchronous_speed", "breakdown_slip", "breakdown_torque"],
            ),
            MotorModel::Speed => ("speed", &["speed"]),
            MotorModel::Ramp => ("ramp", &["from", "to", "duration"]),
            MotorModel::Profile => ("profile", &["points"]),
        };
        if t.points.is_some() && t.model != MotorModel::Profile {
            return Err(format!(
                "`motor.points` does not belong to model = \"{model}\" (its keys: {})",
                keys.join(", ")
            ));
        }
        let given = [
            ("no_load_speed", t.no_load_speed),
            ("breakdown_speed", t.breakdown_speed),
            ("breakdown_torque", t.breakdown_torque),
            ("synchronous_speed", t.synchronous_speed),
            ("breakdown_slip", t.breakdown_slip),
            ("speed", t.speed),
            ("from", t.from),
            ("to", t.to),
            ("duration", t.duration),
        ];
        for (key, value) in given {
            if value.is_some() && !keys.contains(&key) {
                return Err(format!(
                    "`motor.{key}` does not belong to model = \"{model}\" (its keys: {})",
                    keys.join(", ")
                ));
            }
        }
        let get = |key: &str| -> Result<f64, String> {
            given
                .iter()
                .find(|(k, _)| *k == key)
                .and_then(|(_, v)| *v)
                .ok_or_else(|| format!("missing key `motor.{key}` (model = \"{model}\")"))
        };
        Ok(match t.model {
            MotorModel::Parabola => MotorSpec::Parabola {
                no_load_speed: get("no_load_speed")?,
                breakdown_speed: get("breakdown_speed")?,
                breakdown_torque: get("breakdown_torque")?,
            },
            MotorModel::Kloss => MotorSpec::Kloss {
                synchronous_speed: get("synchronous_speed")?,
                breakdown_slip: get("breakdown_slip")?,
                breakdown_torque: get("breakdown_torque")?,
            },
            MotorModel::Speed => MotorSpec::Speed {
                speed: get("speed")?,
            },
            MotorModel::Ramp => MotorSpec::Ramp {
                from: get("from")?,
                to: get("to")?,
                duration: get("duration")?,
            },
            MotorModel::Profile => MotorSpec::Profile {
                points: t.points.ok_or_else(|| {
                    "missing key `motor.points` (model = \"profile\")".to_string()
                })?,
            },
        })
    }
}

/// `[load]`: M_c(φ) = mean + Σ amplitude·sin(order·φ + phase).
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadSpec {
    /// Mean load torque M1, N·m.
    pub mean: f64,
    /// Harmonics.
    #[serde(default)]
    pub harmonics: Vec<Harmonic>,
}

/// Revolution framing of the encoder.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum FramingSpec {
    /// Index pulse once per revolution.
    #[default]
    Index,
    /// Missing-tooth gap (`missing` positions, or `wheel = "N-M"`).
    MissingTooth,
    /// A general tooth pattern (`gaps` or `teeth`).
    Pattern,
    /// No marker.
    None,
}

impl FramingSpec {
    /// The value as written in a scene file.
    pub fn name(self) -> &'static str {
        match self {
            FramingSpec::Index => "index",
            FramingSpec::MissingTooth => "missing-tooth",
            FramingSpec::Pattern => "pattern",
            FramingSpec::None => "none",
        }
    }
}

/// `[encoder] tolerances`: the core's edge-check tolerances (`drive_monitor::encoder::Tolerances`;
/// each defaults to the core's).
#[derive(Debug, Clone, Copy, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct TolerancesSpec {
    /// Swing taken at once (1.05 to 2).
    pub accept: Option<f64>,
    /// Fraction of the expected interval below which an edge is a glitch outright (0.05 to 0.6).
    pub glitch_fraction: Option<f64>,
    /// How much better a fault must explain the intervals than a clean tooth (0.05 to 2).
    pub fault_margin: Option<f64>,
}

/// `[encoder]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderSpec {
    /// Tooth positions per revolution (lines; the grid of a pattern). Required unless `wheel`
    /// gives it.
    #[serde(default, deserialize_with = "whole_some")]
    pub lines: Option<u16>,
    /// A missing-tooth wheel in the usual notation, `"N-M"`: N positions, M missing in one gap
    /// (`"36-2"`, `"60-2"`, `"8-1"`).
    #[serde(default)]
    pub wheel: Option<String>,
    /// Gaps of a pattern wheel on the grid of `lines`: `[first missing position, count]` each.
    #[serde(default, deserialize_with = "whole_pairs")]
    pub gaps: Option<Vec<[u16; 2]>>,
    /// Teeth of a pattern wheel: the grid positions (0 … lines−1) that carry a tooth.
    #[serde(default, deserialize_with = "whole_each")]
    pub teeth: Option<Vec<u16>>,
    /// Capture timer clock, Hz.
    pub timer_hz: f64,
    /// Counter width, bits.
    #[serde(default = "default_bits", deserialize_with = "whole")]
    pub counter_bits: u8,
    /// Input prescaler of the capture (1, 2, 4 or 8; uniform discs only).
    #[serde(default = "default_prescaler", deserialize_with = "whole")]
    pub prescaler: u8,
    /// Framing (default: `index`, or what `wheel`, `missing`, `gaps` or `teeth` imply).
    #[serde(default)]
    pub framing: Option<FramingSpec>,
    /// Missing positions (missing-tooth framing, which `missing` implies).
    #[serde(default, deserialize_with = "whole")]
    pub missing: u8,
    /// Edges averaged per speed sample (16 by default; 1 to 32, and at most the edges captured
    /// per revolution, the wheel's teeth over `prescaler`): a sample spanning a good part of a
    /// load cycle averages its ripple away (`predict` warns when more than 1 % of δ is lost).
    #[serde(default = "default_estimator_edges", deserialize_with = "whole")]
    pub estimator_edges: u16,
    /// The core's edge-check tolerances.
    #[serde(default)]
    pub tolerances: TolerancesSpec,
    /// Edge jitter, standard deviation, s.
    #[serde(default)]
    pub jitter: f64,
    /// Disc run-out over radius, e/r (angle error amplitude, rad).
    #[serde(default)]
    pub runout: f64,
    /// Run-out phase, rad.
    #[serde(default)]
    pub runout_phase: f64,
    /// Random pitch error per line, standard deviation, rad.
    #[serde(default)]
    pub pitch_error: f64,
    /// Probability that a tooth's edge is lost.
    #[serde(default)]
    pub drop_probability: f64,
    /// Probability per edge of a spurious extra edge (a noise pulse).
    #[serde(default)]
    pub glitch_probability: f64,
    /// Where a noise pulse falls between two teeth, as fractions of the tooth interval
    /// `[from, to]` (default `[0, 1]`, anywhere).
    #[serde(default, deserialize_with = "exact_some")]
    pub glitch_window: Option<[f64; 2]>,
}

impl EncoderSpec {
    /// Grid positions per revolution: `lines`, or the N of `wheel = "N-M"` (0 when neither
    /// reads: validation reports it).
    pub fn grid_lines(&self) -> u16 {
        self.lines
            .or_else(|| {
                self.wheel
                    .as_deref()
                    .and_then(|w| parse_wheel(w).ok())
                    .map(|(n, _)| n)
            })
            .unwrap_or(0)
    }

    /// The framing the keys ask for: `framing` if given, else what the wheel keys imply.
    pub fn framing(&self) -> FramingSpec {
        // (`framing_implied_by` names the key that implies it.)
        match self.framing {
            Some(f) => f,
            None if self.wheel.is_some() || self.missing != 0 => FramingSpec::MissingTooth,
            None if self.gaps.is_some() || self.teeth.is_some() => FramingSpec::Pattern,
            None => FramingSpec::Index,
        }
    }
}

impl EncoderSpec {
    /// The key that implies [`Self::framing`] where the file does not give `framing`
    /// (`encoder.wheel`, `encoder.missing`, `encoder.gaps` or `encoder.teeth`); `None` where
    /// it is given or is the default (`index`).
    pub fn framing_implied_by(&self) -> Option<&'static str> {
        match self.framing {
            Some(_) => None,
            None if self.wheel.is_some() => Some("encoder.wheel"),
            None if self.missing != 0 => Some("encoder.missing"),
            None if self.gaps.is_some() => Some("encoder.gaps"),
            None if self.teeth.is_some() => Some("encoder.teeth"),
            None => None,
        }
    }
}

/// `wheel = "N-M"` read as (N, M), or why not.
pub fn parse_wheel(text: &str) -> Result<(u16, u8), String> {
    let t = text.trim();
    if t.contains('+') {
        return Err(
            "\"N+1\" is ambiguous (an index on its own channel, or an extra tooth on the wheel): \
             an index is N lines with index framing (`--lines N --framing index`, or in a scene \
             lines = N with framing = \"index\"), an extra tooth the wheel's teeth in a scene \
             (lines and teeth, given to analyze by --scene)"
                .to_string(),
        );
    }
    let parts: Vec<&str> = t.split('-').collect();
    let [n, m] = parts.as_slice() else {
        return Err(
            "expected \"N-M\" (N positions, M missing in one gap, e.g. \"36-2\"); a wheel with \
             several gaps is described by lines and gaps"
                .to_string(),
        );
    };
    // Read whole, as the integer keys are ([`Whole`]): too many positions or missing teeth
    // are refused with the wheel's allowed range, not the storage type's.
    let n: u16 = n
        .trim()
        .parse::<i64>()
        .map(Whole::saturate)
        .map_err(|_| format!("`{n}` is not a number of positions"))?;
    let m: u8 = m
        .trim()
        .parse::<i64>()
        .map(Whole::saturate)
        .map_err(|_| format!("`{m}` is not a number of missing teeth"))?;
    Ok((n, m))
}

/// `[cranking]`: a compression ripple on the prescribed speed (`[motor]` model `speed`,
/// `ramp` or `profile`): ω = ω̄(t)·(1 + ripple·sin(strokes·φ + phase)).
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrankingSpec {
    /// Relative ripple per stroke (0.4: ±40 %), 0 to 0.9.
    pub ripple: f64,
    /// Compression strokes per revolution (2 for four cylinders, four strokes).
    pub strokes: f64,
    /// Phase, rad.
    #[serde(default)]
    pub phase: f64,
}

/// Capture file formats (`drive-sim run --capture-format`, `drive-sim analyze --format`).
pub use crate::app::logic::CaptureFormat;

/// `[capture]`: the logic analyzer `drive-sim run --capture` emulates.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CaptureSpec {
    /// Sample rate, Hz (whole Hz): transitions are recorded at the first sample after them.
    #[serde(default = "default_sample_rate")]
    pub sample_rate: f64,
    /// Width of a tooth's pulse (and of the index pulse), in grid pitches (0 < duty < 1).
    #[serde(default = "default_duty")]
    pub duty: f64,
    /// Width of a noise pulse, s.
    #[serde(default = "default_noise_width")]
    pub noise_width: f64,
    /// Write only the rows where a level changes in the sigrok format (its `dedup` option);
    /// default: every sample, as sigrok writes by default.
    #[serde(default)]
    pub dedup: bool,
}

impl Default for CaptureSpec {
    fn default() -> Self {
        CaptureSpec {
            sample_rate: default_sample_rate(),
            duty: default_duty(),
            noise_width: default_noise_width(),
            dedup: false,
        }
    }
}

fn default_sample_rate() -> f64 {
    50e6
}
fn default_duty() -> f64 {
    0.5
}
fn default_noise_width() -> f64 {
    2e-6
}
fn default_prescaler() -> u8 {
    1
}

fn default_bits() -> u8 {
    32
}
fn default_estimator_edges() -> u16 {
    16
}

/// `[monitor]`.
#[derive(Debug, Clone, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct MonitorSpec {
    /// Permissible δ.
    pub delta_limit: Option<f64>,
    /// δ window in revolutions, 1 to 1024 (default: the load's period, from all its and the
    /// inertia's orders; where no window holds that period, one cycle of the lowest order or,
    /// where that is longer, 1024, with a WARNING).
    #[serde(default, deserialize_with = "whole_some")]
    pub window_revolutions: Option<u16>,
    /// Slowest running speed, rad/s (standstill below).
    pub min_speed: Option<f64>,
    /// Steady-speed tolerance between windows (fraction).
    pub steady_tolerance: Option<f64>,
    /// Relative margin band about each boundary of the auto-balancer's regime table (default
    /// `drive_monitor::balancer::TABLE_MARGIN`, 1 %, for the exact table; for a balancer too
    /// small for its rotor, which has the criterion's table,
    /// `drive_monitor::balancer::DEFAULT_MARGIN`, 5 %; both sized in `docs/criterion.md`).
    pub regime_margin: Option<f64>,
    /// Warning band of the support limits, as a fraction of each limit.
    pub warning_fraction: Option<f64>,
}

/// `[[platform]]`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlatformSpec {
    /// Mass, kg (without the auto-balancer).
    pub mass: f64,
    /// Support stiffness to ground, N/m.
    pub stiffness: f64,
    /// Support damping, N·s/m (required: 0 for an undamped support is written, not assumed).
    pub damping: f64,
}

/// `[[coupling]]`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingSpec {
    /// The two platforms (1-based).
    #[serde(deserialize_with = "whole_pair")]
    pub between: [u8; 2],
    /// Stiffness, N/m.
    pub stiffness: f64,
    /// Damping, N·s/m (required: 0 for an undamped coupling is written, not assumed).
    pub damping: f64,
}

/// Auto-balancer kind.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BalancerKindSpec {
    /// Balls, κ = 7/5.
    Ball,
    /// Rollers, κ = 3/2.
    Roller,
    /// Pendulums, κ = 1 + J_c/(m R²).
    Pendulum,
}

/// `[autobalancer]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AutobalancerSpec {
    /// Kind.
    pub kind: BalancerKindSpec,
    /// Pendulum inertia about its own centre, kg·m² (pendulum only).
    #[serde(default)]
    pub pendulum_inertia: Option<f64>,
    /// Platform carrying it (1-based).
    #[serde(deserialize_with = "whole")]
    pub platform: u8,
    /// Number of loads.
    #[serde(deserialize_with = "whole")]
    pub loads: u8,
    /// Mass of each load, kg.
    pub load_mass: f64,
    /// Radius of the loads' track, m.
    pub radius: f64,
    /// Housing mass, kg (required: 0 for a housing left out of the model is written, not
    /// assumed).
    pub housing_mass: f64,
    /// Viscosity of load motion relative to the housing, N·s/m.
    pub viscosity: f64,
    /// Rotor static unbalance the loads are to balance, kg·m.
    #[serde(default)]
    pub rotor_unbalance: Option<f64>,
    /// Where the loads start: `"balanced"` (the default: near the balancing position, load 1
    /// turned 0.05 rad forward) or `"together"` (gathered within 0.01 rad at rest, for the
    /// Sommerfeld capture of a run-up). The run's `loads_together` override (`sweep
    /// --together`) forces `"together"`.
    #[serde(default)]
    pub start: LoadStart,
}

/// `[autobalancer] start`: where the loads are at `t = 0` (near the balancing position turning
/// with the rotor, or together at rest).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum LoadStart {
    /// Near the auto-balancing position with a small perturbation, turning with the rotor.
    #[default]
    Balanced,
    /// Gathered together (within 0.01 rad) on the unbalance's side, at rest.
    Together,
}

/// `[rotor]`.
#[derive(Debug, Clone, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorSpec {
    /// Mass, kg.
    pub mass: f64,
    /// Axial position of the centre of mass, m.
    pub centre_of_mass: f64,
    /// Axial position of support A, m.
    pub support_a: f64,
    /// Axial position of support B, m.
    pub support_b: f64,
    /// ISO 21940-11 balance quality grade G, mm/s.
    pub grade: f64,
    /// Service speed, rad/s.
    pub service_speed: f64,
    /// Allowed dynamic load at A and B, N.
    #[serde(default, deserialize_with = "exact_some")]
    pub support_load_limit: Option<[f64; 2]>,
}

/// `[[unbalance]]`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnbalanceSpec {
    /// Axial position, m.
    pub z: f64,
    /// Amount, kg·m.
    pub amount: f64,
    /// Angle, degrees.
    pub angle: f64,
}

/// `[process_load]`.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ProcessLoadSpec {
    /// Load per length, N/m.
    pub per_length: f64,
    /// Start of the loaded interval, m.
    pub from: f64,
    /// End of the loaded interval, m.
    pub to: f64,
    /// Direction of the load, degrees.
    pub angle: f64,
}

impl Scene {
    /// Reads and parses a scene file of at most [`MAX_SCENE_BYTES`].
    pub fn load(path: &Path) -> Result<Scene, SceneError> {
        use std::io::Read;
        let io = |source| SceneError::Io {
            file: path.to_path_buf(),
            source,
        };
        let file = std::fs::File::open(path).map_err(io)?;
        // Read one byte past the limit, so a larger file (or an endless one: /dev/zero) is
        // refused after at most that much.
        let mut bytes = Vec::new();
        file.take(MAX_SCENE_BYTES + 1)
            .read_to_end(&mut bytes)
            .map_err(io)?;
        if bytes.len() as u64 > MAX_SCENE_BYTES {
            return Err(io(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("larger than the limit of {MAX_SCENE_BYTES} bytes for a scene file"),
            )));
        }
        let text = String::from_utf8(bytes).map_err(|e| {
            io(std::io::Error::new(
                std::io::ErrorKind::InvalidData,
                format!("not UTF-8 text ({e})"),
            ))
        })?;
        Scene::parse(&text, path)
    }

    /// Parses scene text; `path` names the file in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
        let blank = text
            .lines()
            .map(str::trim)
            .all(|l| l.is_empty() || l.starts_with('#'));
        if blank {
            return Err(SceneError::Parse {
                file: path.to_path_buf(),
                message: "the file is empty: a scene needs at least one table (see `drive-sim scenes` for examples)".into(),
            });
        }
        let mut scene: Scene = toml::from_str(text).map_err(|e| SceneError::Parse {
            file: path.to_path_buf(),
            message: e.to_string().trim_end().replace('\n', "\n  "),
        })?;
        scene.written = crate::app::check::Written::parse(text);
        crate::app::check::check(&scene, &scene.checker(path))?;
        Ok(scene)
    }

    /// The errors of this scene's file `path`, quoting its values as written.
    pub fn checker<'a>(&'a self, path: &'a Path) -> crate::app::check::Checker<'a> {
        crate::app::check::Checker::new(path, &self.written)
    }
}

/// The scenes bundled with the simulator: (file name, text).
pub const BUNDLED: &[(&str, &str)] = &[
    ("kneader.toml", include_str!("../../scenes/kneader.toml")),
    ("auger.toml", include_str!("../../scenes/auger.toml")),
    (
        "auger-overhung.toml",
        include_str!("../../scenes/auger-overhung.toml"),
    ),
    ("one-mass.toml", include_str!("../../scenes/one-mass.toml")),
    (
        "one-mass-runup.toml",
        include_str!("../../scenes/one-mass-runup.toml"),
    ),
    (
        "one-mass-undersized.toml",
        include_str!("../../scenes/one-mass-undersized.toml"),
    ),
    (
        "one-mass-motor-runup.toml",
        include_str!("../../scenes/one-mass-motor-runup.toml"),
    ),
    ("two-mass.toml", include_str!("../../scenes/two-mass.toml")),
    (
        "three-mass.toml",
        include_str!("../../scenes/three-mass.toml"),
    ),
];

/// The default scene of `drive-sim` without arguments.
pub const DEFAULT_SCENE: &str = "kneader";

/// Largest scene file read, bytes (the bundled scenes are about 1 kB).
pub const MAX_SCENE_BYTES: u64 = 1 << 20;

/// The bundled scene called `name` (its file name without `.toml`, as `drive-sim scenes`
/// lists it): (file name, text).
pub fn bundled(name: &str) -> Option<(&'static str, &'static str)> {
    BUNDLED
        .iter()
        .find(|(n, _)| n.strip_suffix(".toml") == Some(name))
        .copied()
}

/// Loads `name`: a bundled scene when `name` is one of their names (`kneader`, as `drive-sim
/// scenes` lists them), else the scene file at the path `name`. A path that does not exist is
/// an error, never a bundled scene of the same file name. Returns the scene and the path
/// errors should name.
pub fn resolve(name: &str) -> Result<(Scene, PathBuf), SceneError> {
    if let Some((n, text)) = bundled(name) {
        let shown = PathBuf::from(format!("host-sim/scenes/{n}"));
        return Ok((Scene::parse(text, &shown)?, shown));
    }
    let path = Path::new(name);
    if !path.exists() {
        let stem = path.file_stem().and_then(|s| s.to_str()).unwrap_or("");
        let hint = match bundled(stem) {
            Some(_) => format!(
                "no such file (the bundled scene `{stem}` is asked for by its name alone: `drive-sim run {stem}`)"
            ),
            None => "no such file, and no bundled scene of that name (see `drive-sim scenes`)"
                .to_string(),
        };
        return Err(SceneError::Io {
            file: path.to_path_buf(),
            source: std::io::Error::new(std::io::ErrorKind::NotFound, hint),
        });
    }
    Ok((Scene::load(path)?, path.to_path_buf()))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(text: &str) -> String {
        Scene::parse(text, Path::new("bad.toml"))
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn bundled_scenes_parse() {
        for (file, _) in BUNDLED {
            let name = file.strip_suffix(".toml").unwrap();
            let (scene, path) = resolve(name).unwrap();
            assert!(path.ends_with(file));
            assert!(scene.description.is_some(), "{name}");
        }
        assert!(resolve("kneader").is_ok());
        assert!(resolve("no-such-scene").is_err());
    }

    #[test]
    fn errors_name_the_file_and_key() {
        let e = err("[shaft]\ninertia = 0.3\nflywhel = 1.0\n");
        assert!(e.contains("bad.toml") && e.contains("flywhel"), "{e}");
        let e = err("[motor]\nmodel = \"parabola\"\nno_load_speed = 145.0\n");
        assert!(e.contains("breakdown_speed"), "{e}");
        let e = err("[simulation]\nduration = -1.0\n");
        assert!(e.contains("simulation.duration") && e.contains("-1"), "{e}");
        let e = err("[encoder]\nlines = 100\ntimer_hz = 1e6\ndrop_probability = 2.0\n");
        assert!(e.contains("encoder.drop_probability"), "{e}");
        let e = err("[shaft]\ninertia = \"heavy\"\n");
        assert!(e.contains("inertia"), "{e}");
    }
}
