//! Assembly of a scene's effects into one ODE, and the simulation loop that integrates it and
//! feeds the shaft angle to the encoder.
//!
//! State vector: `[φ, ω]` when the shaft is dynamic, followed by each effect's own states in
//! the order the effects were given. A prescribed shaft contributes no states: φ and ω come
//! from its [`SpeedLaw`], and the encoder's edges are located on that exact law. The
//! right-hand side calls every effect exactly once per evaluation and counts evaluations per
//! component, so a scene that does not list an effect never pays for it (and the counts show
//! it). A prescribed shaft whose effects have no states needs no integration at all: the run
//! evaluates no right-hand side.
//!
//! Dynamic shaft (seed 000, eq. 1): J(φ)·ω' + ½·ω²·dJ/dφ = Σ effect torques, with
//! J(φ) = J₀ + J_flywheel + Σ J_k·cos(k·φ + ψ_k).
//!
//! ```
//! use drive_monitor::drive::{Harmonic, Load, Motor, Parabola};
//! use host_sim::engine::encoder::EncoderConfig;
//! use host_sim::engine::ode::Integrator;
//! use host_sim::engine::system::{DynamicShaft, ShaftModel, Simulation, System};
//!
//! let shaft = ShaftModel::Dynamic(DynamicShaft::constant(0.323));
//! let motor = Motor::parabola(Parabola::new(145.0, 36.0, 158.0)?);
//! let load = Load::new(24.0, &[Harmonic::new(0.125, 12.0, 0.0)?])?;
//! let system = System::new(shaft, vec![Box::new(motor), Box::new(load)])?;
//! let integrator = Integrator::Dopri5 { rtol: 1e-8, atol: 1e-8, max_step: None };
//! let mut sim = Simulation::new(system, integrator, EncoderConfig::ideal(1024, 170e6))?;
//! let mut edges = 0u64;
//! let stats = sim.run(1.0, |_edge| edges += 1)?;
//! assert_eq!(stats.encoder.edges, edges);
//! assert_eq!(stats.evaluations_of("load"), stats.solver.rhs_evals);
//! # Ok::<(), host_sim::engine::system::SimError>(())
//! ```

use core::f64::consts::TAU;

use serde::Deserialize;

use drive_monitor::error::{finite, non_negative, positive, ConfigError};

use crate::engine::cranking::SpeedProfile;
use crate::engine::encoder::{Edge, Encoder, EncoderConfig, EncoderStats};
use crate::engine::model::{Effect, Shaft};
use crate::engine::ode::{
    fastest_rate, ComponentPoly, DenseOutput, Integrator, OdeError, OdeSystem, Solver, SolverStats,
};

/// A kinematic law for a prescribed shaft.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(tag = "law", rename_all = "snake_case", deny_unknown_fields)]
pub enum SpeedLaw {
    /// ω constant.
    Constant {
        /// Speed, rad/s.
        omega: f64,
        /// Angle at t = 0, rad.
        #[serde(default)]
        phi0: f64,
    },
    /// ω = ω0 + α·t for all t (may pass through zero and reverse).
    Ramp {
        /// Speed at t = 0, rad/s.
        omega0: f64,
        /// Acceleration α, rad/s².
        alpha: f64,
        /// Angle at t = 0, rad.
        #[serde(default)]
        phi0: f64,
    },
    /// ω linear from ω0 to ω1 over `ramp_time`, then constant ω1.
    RampTo {
        /// Speed at t = 0, rad/s.
        omega0: f64,
        /// Final speed, rad/s.
        omega1: f64,
        /// Duration of the ramp, s.
        ramp_time: f64,
        /// Angle at t = 0, rad.
        #[serde(default)]
        phi0: f64,
    },
}

impl SpeedLaw {
    /// Angle at t = 0, rad.
    fn phi0(&self) -> f64 {
        match *self {
            SpeedLaw::Constant { phi0, .. }
            | SpeedLaw::Ramp { phi0, .. }
            | SpeedLaw::RampTo { phi0, .. } => phi0,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), ConfigError> {
        match *self {
            SpeedLaw::Constant { omega, .. } => {
                finite("shaft.omega", omega)?;
            }
            SpeedLaw::Ramp { omega0, alpha, .. } => {
                finite("shaft.omega0", omega0)?;
                finite("shaft.alpha", alpha)?;
            }
            SpeedLaw::RampTo {
                omega0,
                omega1,
                ramp_time,
                ..
            } => {
                finite("shaft.omega0", omega0)?;
                finite("shaft.omega1", omega1)?;
                positive("shaft.ramp_time", ramp_time)?;
            }
        }
        finite("shaft.phi0", self.phi0())?;
        Ok(())
    }

    /// (φ0, ω0, α) of the piece containing t, with the piece's start time.
    fn piece(&self, t: f64) -> (f64, f64, f64, f64) {
        let phi0 = self.phi0();
        match *self {
            SpeedLaw::Constant { omega, .. } => (0.0, phi0, omega, 0.0),
            SpeedLaw::Ramp { omega0, alpha, .. } => (0.0, phi0, omega0, alpha),
            SpeedLaw::RampTo {
                omega0,
                omega1,
                ramp_time,
                ..
            } => {
                let alpha = (omega1 - omega0) / ramp_time;
                if t <= ramp_time {
                    (0.0, phi0, omega0, alpha)
                } else {
                    let phi_end = phi0 + ramp_time * (omega0 + 0.5 * alpha * ramp_time);
                    (ramp_time, phi_end, omega1, 0.0)
                }
            }
        }
    }

    /// Shaft state at time t.
    pub fn shaft(&self, t: f64) -> Shaft {
        let (ts, phi, omega, alpha) = self.piece(t);
        let s = t - ts;
        Shaft {
            phi: phi + s * (omega + 0.5 * alpha * s),
            omega: omega + alpha * s,
        }
    }

    /// The time where the law changes form, if any.
    pub fn breakpoint(&self) -> Option<f64> {
        match *self {
            SpeedLaw::RampTo { ramp_time, .. } => Some(ramp_time),
            _ => None,
        }
    }

    /// φ on [t0, t1] as a polynomial in θ = (t − t0)/(t1 − t0); [t0, t1] must not contain the
    /// breakpoint in its interior.
    pub fn segment(&self, t0: f64, t1: f64) -> ComponentPoly {
        let mid = 0.5 * (t0 + t1);
        let (ts, phi, omega, alpha) = self.piece(mid);
        let s = t0 - ts;
        let h = t1 - t0;
        let mut coeffs = [0.0; crate::engine::ode::MAX_DENSE_DEGREE];
        coeffs[0] = (omega + alpha * s) * h;
        coeffs[1] = 0.5 * alpha * h * h;
        ComponentPoly {
            t0,
            h,
            base: phi + s * (omega + 0.5 * alpha * s),
            degree: 2,
            coeffs,
        }
    }
}

/// One harmonic of the reduced inertia, J_k·cos(k·φ + ψ_k).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InertiaHarmonic {
    /// Amplitude J_k, kg·m².
    pub amplitude: f64,
    /// Order k (per revolution; may be fractional).
    pub order: f64,
    /// Phase ψ_k, rad.
    #[serde(default)]
    pub phase: f64,
}

/// A shaft integrated from the torques acting on it.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DynamicShaft {
    /// Constant part of the reduced inertia J₀, kg·m².
    pub inertia: f64,
    /// Flywheel inertia added to J₀, kg·m².
    #[serde(default)]
    pub flywheel: f64,
    /// Harmonics of J(φ).
    #[serde(default)]
    pub harmonics: Vec<InertiaHarmonic>,
    /// Initial angle, rad.
    #[serde(default)]
    pub phi0: f64,
    /// Initial speed, rad/s.
    #[serde(default)]
    pub omega0: f64,
}

impl DynamicShaft {
    /// Constant inertia J, starting at rest at φ = 0.
    pub fn constant(inertia: f64) -> Self {
        DynamicShaft {
            inertia,
            flywheel: 0.0,
            harmonics: Vec::new(),
            phi0: 0.0,
            omega0: 0.0,
        }
    }

    /// Checks the parameters: J(φ) must stay positive for every φ.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let j = positive("shaft.inertia", self.inertia)?
            + non_negative("shaft.flywheel", self.flywheel)?;
        let mut swing = 0.0;
        for h in &self.harmonics {
            swing += finite("shaft.harmonics.amplitude", h.amplitude)?.abs();
            positive("shaft.harmonics.order", h.order)?;
            finite("shaft.harmonics.phase", h.phase)?;
        }
        // J(φ) > 0 for every φ: certain when the amplitudes' magnitudes add up to less than J,
        // else the least value of J(φ) over the period decides, as the core's drive model
        // finds it (orders with no common period: refused, as J(φ) may come as close to
        // J − Σ|amplitude| as it likes).
        if swing >= j {
            let core: Result<Vec<_>, _> = self
                .harmonics
                .iter()
                .map(|h| drive_monitor::drive::InertiaHarmonic::new(h.order, h.amplitude, h.phase))
                .collect();
            let least = core
                .ok()
                .and_then(|c| drive_monitor::drive::least_inertia(j, &c))
                .map(|(_, least)| least);
            if !least.is_some_and(|l| l > 0.0) {
                return Err(ConfigError::Inconsistent("shaft.harmonics"));
            }
        }
        finite("shaft.phi0", self.phi0)?;
        finite("shaft.omega0", self.omega0)?;
        Ok(())
    }

    /// J(φ) and dJ/dφ.
    pub fn inertia_at(&self, phi: f64) -> (f64, f64) {
        let mut j = self.inertia + self.flywheel;
        let mut dj = 0.0;
        for h in &self.harmonics {
            let (s, c) = (h.order * phi + h.phase).sin_cos();
            j += h.amplitude * c;
            dj -= h.order * h.amplitude * s;
        }
        (j, dj)
    }
}

/// How the drive shaft moves.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum ShaftModel {
    /// Kinematic law; φ and ω are not integrated.
    Prescribed(SpeedLaw),
    /// Integrated from the torques of all effects.
    Dynamic(DynamicShaft),
    /// A prescribed speed ω(φ, t) (cranking: a mean speed with a compression ripple); φ is
    /// integrated from it (one state), the effects' torques do not move it.
    #[serde(skip)]
    Profile(SpeedProfile),
}

impl ShaftModel {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), ConfigError> {
        match self {
            ShaftModel::Prescribed(l) => l.validate(),
            ShaftModel::Dynamic(d) => d.validate(),
            ShaftModel::Profile(p) => p.validate(),
        }
    }

    /// States the shaft itself owns: φ and ω when dynamic, φ for a profile.
    fn dim(&self) -> usize {
        match self {
            ShaftModel::Prescribed(_) => 0,
            ShaftModel::Dynamic(_) => 2,
            ShaftModel::Profile(_) => 1,
        }
    }
}

/// Right-hand-side evaluations of one component.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ComponentEvals {
    /// Component name ("shaft", or the effect's [`Effect::name`]).
    pub name: &'static str,
    /// Evaluations.
    pub evals: u64,
}

/// A shaft model and the effects acting on it, as one ODE.
pub struct System {
    shaft: ShaftModel,
    effects: Vec<Box<dyn Effect>>,
    /// Start of each effect's slice, plus the total dimension at the end.
    offsets: Vec<usize>,
    effect_evals: Vec<u64>,
    shaft_evals: u64,
}

impl core::fmt::Debug for System {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("System")
            .field("shaft", &self.shaft)
            .field(
                "effects",
                &self.effects.iter().map(|e| e.name()).collect::<Vec<_>>(),
            )
            .field("dim", &self.dim())
            .finish()
    }
}

impl System {
    /// Assembles the system (validates the shaft model; effects validate themselves when
    /// built).
    pub fn new(shaft: ShaftModel, effects: Vec<Box<dyn Effect>>) -> Result<Self, ConfigError> {
        shaft.validate()?;
        let mut offsets = Vec::with_capacity(effects.len() + 1);
        let mut o = shaft.dim();
        for e in &effects {
            offsets.push(o);
            o += e.dim();
        }
        offsets.push(o);
        let n = effects.len();
        Ok(System {
            shaft,
            effects,
            offsets,
            effect_evals: vec![0; n],
            shaft_evals: 0,
        })
    }

    /// Dimension of the state vector.
    pub fn dim(&self) -> usize {
        self.offsets.last().copied().unwrap_or(0)
    }

    /// The shaft model.
    pub fn shaft_model(&self) -> &ShaftModel {
        &self.shaft
    }

    /// Whether φ and ω are state variables (0 and 1).
    pub fn is_dynamic(&self) -> bool {
        matches!(self.shaft, ShaftModel::Dynamic(_))
    }

    /// Whether φ is state variable 0 (a dynamic shaft or a speed profile): the encoder reads
    /// it from the integrator's dense output.
    pub fn integrates_angle(&self) -> bool {
        self.shaft.dim() > 0
    }

    /// Names of the effects, in state order.
    pub fn effect_names(&self) -> Vec<&'static str> {
        self.effects.iter().map(|e| e.name()).collect()
    }

    /// Range of the state vector owned by effect `k`.
    pub fn effect_range(&self, k: usize) -> core::ops::Range<usize> {
        self.offsets[k]..self.offsets[k + 1]
    }

    /// The initial state vector.
    pub fn initial_state(&self) -> Vec<f64> {
        let mut y = vec![0.0; self.dim()];
        if let ShaftModel::Dynamic(d) = &self.shaft {
            y[0] = d.phi0;
            y[1] = d.omega0;
        }
        // A profile starts at φ = 0 (y is zeroed).
        for (k, e) in self.effects.iter().enumerate() {
            e.init(&mut y[self.offsets[k]..self.offsets[k + 1]]);
        }
        y
    }

    /// The shaft state at time t for state vector y.
    pub fn shaft_state(&self, t: f64, y: &[f64]) -> Shaft {
        match &self.shaft {
            ShaftModel::Dynamic(_) => Shaft {
                phi: y[0],
                omega: y[1],
            },
            ShaftModel::Prescribed(l) => l.shaft(t),
            ShaftModel::Profile(p) => Shaft {
                phi: y[0],
                omega: p.omega(y[0], t),
            },
        }
    }

    /// Evaluations per component so far: "shaft" first when the shaft is dynamic, then one
    /// entry per effect in order.
    pub fn evaluations(&self) -> Vec<ComponentEvals> {
        let mut v = Vec::with_capacity(self.effects.len() + 1);
        if self.integrates_angle() {
            v.push(ComponentEvals {
                name: "shaft",
                evals: self.shaft_evals,
            });
        }
        for (e, &n) in self.effects.iter().zip(&self.effect_evals) {
            v.push(ComponentEvals {
                name: e.name(),
                evals: n,
            });
        }
        v
    }
}

impl OdeSystem for System {
    fn dim(&self) -> usize {
        System::dim(self)
    }

    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]) {
        let shaft = self.shaft_state(t, y);
        let mut torque = 0.0;
        for (k, e) in self.effects.iter().enumerate() {
            let (a, b) = (self.offsets[k], self.offsets[k + 1]);
            torque += e.eval(t, shaft, &y[a..b], &mut dy[a..b]);
            self.effect_evals[k] += 1;
        }
        match &self.shaft {
            ShaftModel::Dynamic(d) => {
                let (j, dj) = d.inertia_at(shaft.phi);
                dy[0] = shaft.omega;
                dy[1] = (torque - 0.5 * shaft.omega * shaft.omega * dj) / j;
                self.shaft_evals += 1;
            }
            ShaftModel::Profile(_) => {
                dy[0] = shaft.omega;
                self.shaft_evals += 1;
            }
            ShaftModel::Prescribed(_) => {}
        }
    }

    fn error_reference(&self, i: usize) -> Option<f64> {
        // φ grows without bound: measure its error against one revolution.
        (i == 0 && self.integrates_angle()).then_some(TAU)
    }
}

/// Why a simulation could not be built or run.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A parameter was rejected.
    #[error("invalid parameter: {0}")]
    Config(#[from] ConfigError),
    /// The integrator failed.
    #[error("integration failed: {0}")]
    Ode(#[from] OdeError),
    /// A fixed step diverged ([`Simulation::with_speed_limit`]): the step from `t` left the
    /// shaft turning at `speed` (rad/s; infinite for a state that is no longer finite), beyond
    /// `limit`, while its own error estimate said it was not resolved. `rate` is the fastest
    /// rate of the system linearised at the run's start and at that step's start
    /// ([`crate::engine::ode::fastest_rate`]), 1/s, where it could be evaluated.
    #[error("the fixed step diverged from t = {t} s: the shaft's speed reached {speed:.3e} rad/s, beyond {limit:.3e} rad/s")]
    Diverged {
        /// Start of the step, s.
        t: f64,
        /// The shaft's speed it reached, rad/s.
        speed: f64,
        /// The limit it passed, rad/s.
        limit: f64,
        /// The system's fastest linearised rate, 1/s.
        rate: Option<f64>,
    },
}

/// Cumulative work and output of a [`Simulation`].
#[derive(Debug, Clone, PartialEq)]
pub struct RunStats {
    /// Simulated time reached, s.
    pub time: f64,
    /// Integrator counters (right-hand-side evaluations, accepted and rejected steps).
    pub solver: SolverStats,
    /// Evaluations per component.
    pub evaluations: Vec<ComponentEvals>,
    /// Edges produced.
    pub encoder: EncoderStats,
}

impl RunStats {
    /// Total evaluations of the components named `name` (0 if the scene has none).
    pub fn evaluations_of(&self, name: &str) -> u64 {
        self.evaluations
            .iter()
            .filter(|c| c.name == name)
            .map(|c| c.evals)
            .sum()
    }
}

/// One step of a run, as seen by an [`Observer`]: the interval and the continuous solution
/// on it.
#[derive(Debug, Clone, Copy)]
pub struct StepView<'a> {
    t0: f64,
    t1: f64,
    dense: Option<&'a DenseOutput>,
    system: &'a System,
}

impl StepView<'_> {
    /// Start of the step, s.
    pub fn t0(&self) -> f64 {
        self.t0
    }

    /// End of the step, s.
    pub fn t1(&self) -> f64 {
        self.t1
    }

    /// Shaft state at t ∈ [t0, t1] (from the dense output, or the exact law).
    pub fn shaft(&self, t: f64) -> Shaft {
        match (&self.system.shaft, self.dense) {
            (ShaftModel::Dynamic(_), Some(d)) => Shaft {
                phi: d.eval(0, t),
                omega: d.eval(1, t),
            },
            (ShaftModel::Prescribed(l), _) => l.shaft(t),
            (ShaftModel::Profile(p), Some(d)) => {
                let phi = d.eval(0, t);
                Shaft {
                    phi,
                    omega: p.omega(phi, t),
                }
            }
            (ShaftModel::Dynamic(_) | ShaftModel::Profile(_), None) => Shaft {
                phi: f64::NAN,
                omega: f64::NAN,
            },
        }
    }

    /// The whole state vector at t ∈ [t0, t1] into `out` (length [`System::dim`]).
    pub fn state_into(&self, t: f64, out: &mut [f64]) {
        if let Some(d) = self.dense {
            d.eval_into(t, out);
        }
    }

    /// The system (names, ranges of effect states).
    pub fn system(&self) -> &System {
        self.system
    }
}

/// Receives a run's output.
pub trait Observer {
    /// Called for every edge, in time order.
    fn edge(&mut self, edge: &Edge);
    /// Called after every step, after that step's edges.
    fn step(&mut self, _step: &StepView<'_>) {}
    /// Asked after every step: `false` ends the run there (the observer keeps the reason; the
    /// run returns its counters as usual).
    fn proceed(&self) -> bool {
        true
    }
}

struct EdgeFn<F>(F);

impl<F: FnMut(&Edge)> Observer for EdgeFn<F> {
    fn edge(&mut self, edge: &Edge) {
        (self.0)(edge)
    }
}

/// Length of the time chunks in which a prescribed shaft without states is swept, s (it does
/// not affect accuracy: the law is exact).
const CHUNK: f64 = 0.05;

/// A system, its integrator and its encoder, advanced together.
pub struct Simulation {
    system: System,
    integrator: Integrator,
    solver: Solver,
    encoder: Encoder,
    t: f64,
    /// See [`Simulation::with_speed_limit`].
    speed_limit: Option<f64>,
    /// The state at the start of the step being taken (kept with a speed limit only).
    before: Vec<f64>,
}

impl core::fmt::Debug for Simulation {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("Simulation")
            .field("system", &self.system)
            .field("integrator", &self.integrator)
            .field("t", &self.t)
            .finish()
    }
}

impl Simulation {
    /// Validates the integrator and the encoder and sets the system's initial state at t = 0.
    pub fn new(
        system: System,
        integrator: Integrator,
        encoder: EncoderConfig,
    ) -> Result<Self, SimError> {
        integrator.validate()?;
        let encoder = Encoder::new(encoder)?;
        let mut solver = Solver::new(&integrator, system.dim());
        solver.reset(0.0, &system.initial_state());
        Ok(Simulation {
            system,
            integrator,
            solver,
            encoder,
            t: 0.0,
            speed_limit: None,
            before: Vec::new(),
        })
    }

    /// For a fixed step (RK4): a step whose state is no longer finite, or on a dynamic shaft a
    /// step that leaves the shaft turning faster than `limit` (rad/s, at its end or on average
    /// over it) while its estimated local error exceeds its scale
    /// ([`Solver::last_step_error`]), ends the run with [`SimError::Diverged`] before that step's edges are made (a diverging
    /// step can turn the shaft through more angle than any edge budget). Adaptive methods hold
    /// their tolerance and are not checked.
    pub fn with_speed_limit(mut self, limit: f64) -> Self {
        self.speed_limit = Some(limit);
        self
    }

    /// The [`SimError::Diverged`] of the step from the state in `before` at `t0`.
    fn diverged(&mut self, t0: f64, speed: f64, limit: f64) -> SimError {
        let start = self.system.initial_state();
        let before = std::mem::take(&mut self.before);
        let dim = self.system.dim();
        let rate = [(0.0, start.as_slice()), (t0, before.as_slice())]
            .into_iter()
            .filter(|(_, y)| y.len() == dim)
            .filter_map(|(t, y)| fastest_rate(&mut self.system, t, y))
            .reduce(f64::max);
        self.before = before;
        SimError::Diverged {
            t: t0,
            speed,
            limit,
            rate,
        }
    }

    /// Simulated time so far, s.
    pub fn time(&self) -> f64 {
        self.t
    }

    /// Current state vector.
    pub fn state(&self) -> &[f64] {
        self.solver.y()
    }

    /// Current shaft state.
    pub fn shaft(&self) -> Shaft {
        self.system.shaft_state(self.t, self.solver.y())
    }

    /// The assembled system.
    pub fn system(&self) -> &System {
        &self.system
    }

    /// The encoder (mark table, counters).
    pub fn encoder(&self) -> &Encoder {
        &self.encoder
    }

    /// The integrator in use.
    pub fn integrator(&self) -> &Integrator {
        &self.integrator
    }

    /// The fixed-step RK4's largest estimated local error so far over its scale, and when
    /// ([`crate::engine::ode::Solver::fixed_step_error`]); `None` for adaptive methods.
    pub fn fixed_step_error(&self) -> Option<(f64, f64)> {
        self.solver.fixed_step_error()
    }

    /// Counters so far.
    pub fn stats(&self) -> RunStats {
        RunStats {
            time: self.t,
            solver: self.solver.stats(),
            evaluations: self.system.evaluations(),
            encoder: self.encoder.stats(),
        }
    }

    /// Advances by `duration` seconds, calling `on_edge` for every edge in time order.
    /// May be called repeatedly to continue a run. Returns the cumulative counters.
    pub fn run<F: FnMut(&Edge)>(
        &mut self,
        duration: f64,
        on_edge: F,
    ) -> Result<RunStats, SimError> {
        self.run_observed(duration, &mut EdgeFn(on_edge))
    }

    /// Like [`Simulation::run`], also reporting every step to `observer` (for sampling the
    /// state); ends early when [`Observer::proceed`] says so.
    pub fn run_observed<O: Observer + ?Sized>(
        &mut self,
        duration: f64,
        observer: &mut O,
    ) -> Result<RunStats, SimError> {
        non_negative("duration", duration)?;
        let t_end = self.t + duration;
        while self.t < t_end {
            let (t0, t1) = if self.system.dim() > 0 {
                // A profile's corners are stepped onto, never across.
                let corner = match &self.system.shaft {
                    ShaftModel::Profile(p) => p.breakpoints().find(|&tb| tb > self.t),
                    _ => None,
                };
                let limit = corner.map_or(t_end, |tb| tb.min(t_end));
                // A fixed step with a speed limit: kept for the divergence checks.
                let guard = self
                    .speed_limit
                    .filter(|_| self.solver.last_step_error().is_some());
                if guard.is_some() {
                    self.before.clear();
                    self.before.extend_from_slice(self.solver.y());
                }
                let t0 = self.solver.t();
                match (self.solver.step(&mut self.system, limit), guard) {
                    (Err(OdeError::NonFinite { .. }), Some(speed_limit)) => {
                        return Err(self.diverged(t0, f64::INFINITY, speed_limit));
                    }
                    (r, _) => r?,
                }
                let d = self.solver.dense();
                let (t0, t1) = (d.t0(), d.t1());
                let dynamic = matches!(self.system.shaft, ShaftModel::Dynamic(_));
                if let Some(speed_limit) = guard.filter(|_| dynamic) {
                    let y = self.solver.y();
                    let mean = (y[0] - self.before[0]).abs() / (t1 - t0);
                    let speed = y[1].abs().max(mean);
                    let unresolved = self.solver.last_step_error().is_some_and(|r| r > 1.0);
                    if unresolved && (!speed.is_finite() || speed > speed_limit) {
                        return Err(self.diverged(t0, speed, speed_limit));
                    }
                }
                (t0, t1)
            } else {
                (self.t, (self.t + CHUNK).min(t_end))
            };
            let mut emit = |e: &Edge| observer.edge(e);
            match &self.system.shaft {
                ShaftModel::Dynamic(_) | ShaftModel::Profile(_) => {
                    let seg = self.solver.dense().component(0);
                    self.encoder.process(&seg, &mut emit);
                }
                ShaftModel::Prescribed(law) => match law.breakpoint() {
                    Some(tb) if tb > t0 && tb < t1 => {
                        self.encoder.process(&law.segment(t0, tb), &mut emit);
                        self.encoder.process(&law.segment(tb, t1), &mut emit);
                    }
                    _ => self.encoder.process(&law.segment(t0, t1), &mut emit),
                },
            }
            self.t = t1;
            let view = StepView {
                t0,
                t1,
                dense: (self.system.dim() > 0).then(|| self.solver.dense()),
                system: &self.system,
            };
            observer.step(&view);
            if !observer.proceed() {
                break;
            }
        }
        Ok(self.stats())
    }
}
