//! Steady state of the drive (seed 000, eq. 11–13), its irregularity δ, flywheel sizing and
//! sensitivities. A reduced inertia that depends on φ ([`DriveModel::with_inertia_harmonics`])
//! takes the path of the `varying` module (eq. 1 solved exactly in `w = J·ω²` over one
//! period); a Kloss motor, with a constant inertia or J(φ), the path of the `shooting` module
//! (eq. 1 with the Kloss curve itself, integrated over one period by a sixth-order Runge–Kutta
//! method, Newton on the periodic start: [`Horizon::Shooting`]); what follows is the
//! constant-inertia parabola form, which both paths reproduce.
//!
//! ## Derivation
//! With constant reduced inertia `J` (machine plus flywheel), eq. 1 reads
//! `J·ω·dω/dφ = A·ω² + B − M_c(φ)`. In `u = ω²` it is linear:
//! `du/dφ + 2·D1·u = 2·D2 − 2·Σ D3k·sin(n_k·φ + ψ_k)` with `a = −A`, `K = ω0² − ω_m²`,
//! `D1 = a/J = M_m/(J·K)`, `D2 = (B − M1)/J`, `D3k = M2k/J`. Its periodic solution, to which
//! every solution converges like `exp(−2·D1·φ)`, superposes exactly:
//!
//! `u(φ) = D2/D1 + Σ_k 2·D3k·(n_k·cos θ_k − 2·D1·sin θ_k)/(4·D1² + n_k²)`, `θ_k = n_k·φ + ψ_k`
//!
//! (eq. 11 for one harmonic). In the form used here, `ū = D2/D1 = (B − M1)/a` and
//! `s_k(φ) = (2·M2k/h_k)·((n_k·J/h_k)·cos θ_k − (2a/h_k)·sin θ_k)`, `h_k = hypot(2a, n_k·J)`,
//! of amplitude `R_k = 2·|M2k|/h_k`. An order-0 harmonic is a constant and joins the mean.
//!
//! δ = 2(ωmax − ωmin)/(ωmax + ωmin) (eq. 13) is evaluated as
//! `2·(smax − smin)/(ωmax + ωmin)²`: the difference of squares, with `smax − smin` taken from
//! the oscillating part alone, so δ keeps full relative precision down to 1e-15 and below.
//!
//! ## The seed's case and its published numbers
//! ω0 = 145 s⁻¹, ω_m = 36 s⁻¹, M_m = 158 N·m, J = 0.323 kg·m², M_c = 24 + 12·sin(φ/8) N·m
//! gives ωmax = 136.311 s⁻¹, ωmin = 132.196 s⁻¹, δ = 0.030656 (unit test
//! `seed_case_reproduced`, confirmed by direct integration of eq. 1). The paper prints
//! δ = 0.085 / 0.101 with ωmax = 145 s⁻¹; those figures do not follow from its own parameters
//! (145 s⁻¹ is the no-load speed, which a loaded drive cannot reach) and are not reproduced.
//! Its claim that 0.177 kg·m² of extra flywheel brings δ to 0.06 is moot for the same reason:
//! δ is already below 0.06 without a flywheel.

use super::load::{Harmonic, Load, MAX_HARMONICS};
use super::motor::Motor;
use super::shooting::{Characteristic, Failure, Shooter, Shot};
use super::varying::{
    self, InertiaHarmonic, Solution, MAX_INERTIA_HARMONICS, MAX_NODES, SMALL_NODES,
};
use crate::error::{non_negative, positive, ConfigError};
use core::cell::Cell;
use core::f64::consts::PI;
use core::num::NonZeroU16;

/// Samples per period of the fastest harmonic when the extrema are searched numerically.
pub const SAMPLES_PER_CYCLE: u64 = 32;
/// Largest number of samples over one common period; a longer common period is treated as
/// unbounded ([`Horizon::Unbounded`]).
pub const MAX_SAMPLES: u64 = 1 << 16;
/// Largest denominator accepted when an order is recognised as a rational number.
pub const MAX_DENOMINATOR: u64 = 1024;
/// Golden-section iterations per refined extremum (bracket shrinks by 0.618⁶⁴ ≈ 4e-14).
const GOLDEN_ITERATIONS: u32 = 64;
/// Smallest target δ that [`DriveModel::flywheel_for`] accepts: `f64::EPSILON` ≈ 2.2e-16.
/// Below it ωmax and ωmin would differ by less than about two units in the last place of ω
/// itself, and the oscillation of ω² would be smaller than the rounding of its mean ū: no f64
/// computation could tell whether such a target is met.
pub const MIN_DELTA_TARGET: f64 = f64::EPSILON;
/// Doublings of the closed-form upper inertia bound allowed in [`DriveModel::flywheel_for`]
/// before it gives up (the bound is rigorous; they only absorb rounding).
const MAX_CONFIRM_DOUBLINGS: u32 = 8;
/// Bisection steps in [`DriveModel::flywheel_for`] at most.
const MAX_BISECTIONS: u32 = 200;
/// Doublings of the added flywheel in [`DriveModel::flywheel_for`] on the J(φ) path at most:
/// from any inertia, 1100 doublings pass the f64 range.
const MAX_VARYING_DOUBLINGS: u32 = 1100;

/// Over which range of φ the extrema of ω were taken.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Horizon {
    /// The load has no oscillating harmonic: ω is constant.
    Constant,
    /// One distinct order: extrema in closed form (eq. 12).
    ClosedForm,
    /// Several commensurate orders: extrema searched over one common period of this many
    /// radians, sampled `samples` times (32 per cycle of the fastest order) and refined by
    /// golden section to within about 1e-13 of the oscillation amplitude.
    Period {
        /// Common period of all harmonics, rad.
        radians: f64,
        /// Number of samples over that period.
        samples: u32,
    },
    /// Orders with no common period (not rationals with denominators ≤ [`MAX_DENOMINATOR`]) or
    /// one longer than [`MAX_SAMPLES`] samples: the extrema are `ū ± Σ R_k` of the parabola
    /// motor. For that motor it is the exact supremum over an unbounded horizon for rationally
    /// independent orders (Kronecker), and a conservative bound (δ too large, flywheel too big)
    /// for commensurate ones. A Kloss motor is not shot for here and is predicted through the
    /// parabola it was built with: the tangent at synchronous speed
    /// ([`KlossFit::SynchronousTangent`](crate::drive::KlossFit)) is no bound for it (at a
    /// loaded drive's slip the curve lies below the parabola and is flatter in `w = J·ω²`, so
    /// the drive runs slower than predicted and its δ can be larger); the host builds such a
    /// drive with the parabola at the operating point instead
    /// ([`Kloss::operating_point_fit`](crate::drive::Kloss::operating_point_fit),
    /// [`Motor::kloss_with`](crate::drive::Motor::kloss_with)), right to first order in the
    /// swing, and integrates the curve itself over a common period too long for the samples.
    Unbounded,
    /// The inertia depends on φ ([`DriveModel::with_inertia_harmonics`]): the periodic
    /// solution of eq. 1 in `w = J·ω²` over one common period of the load and inertia orders,
    /// by the trapezoid rule on `nodes` nodes (see the `varying` module docs), its extrema
    /// found on the nodes and refined by golden section on the series.
    Varying {
        /// Common period of all load and inertia harmonics, rad.
        radians: f64,
        /// Trapezoid nodes over that period (a power of two, at most
        /// [`MAX_NODES`](crate::drive::MAX_NODES)).
        nodes: u32,
    },
    /// A Kloss motor: the periodic solution of eq. 1 with the Kloss curve itself, by shooting
    /// over one common period of the load (and inertia) orders with a sixth-order Runge–Kutta
    /// method on `steps` equal steps and Newton's method on the start (see the `shooting`
    /// module docs); its extrema found on the steps and refined by golden section.
    Shooting {
        /// Common period of all load and inertia harmonics, rad.
        radians: f64,
        /// Runge–Kutta steps over that period (at most
        /// [`MAX_STEPS`](crate::drive::MAX_STEPS)).
        steps: u32,
    },
}

/// A periodic steady state.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SteadyState {
    /// Maximum shaft speed ωmax, rad/s.
    pub omega_max: f64,
    /// Minimum shaft speed ωmin, rad/s.
    pub omega_min: f64,
    /// Irregularity δ = 2(ωmax − ωmin)/(ωmax + ωmin).
    pub delta: f64,
    /// RMS speed `√ū` (ū is the mean of ω² over the period), rad/s.
    pub omega_rms: f64,
    /// Shaft angle of ωmax within the period, rad (`None` for [`Horizon::Unbounded`] and
    /// [`Horizon::Constant`], and for an order below about 3.5e-308, whose period 2π/n is
    /// beyond f64).
    pub phi_max: Option<f64>,
    /// Shaft angle of ωmin, rad (as `phi_max`).
    pub phi_min: Option<f64>,
    /// How the extrema were found.
    pub horizon: Horizon,
    /// `ωmin ≥` the motor's breakdown speed: the speed stays on the motor's stable working
    /// branch, where the parabola stands for the real characteristic (see the motor module)
    /// and a Kloss motor's period map contracts.
    pub within_working_branch: bool,
}

/// The periodic solution would need `ω² ≤ 0`: the motor stalls under the peak load.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Stall {
    /// Mean of ω² over the period, `ū = (B − M1)/a`, s⁻²; `≤ 0` means the mean load alone
    /// exceeds the motor's stall torque `B` and no flywheel can help. For a Kloss motor, the
    /// square of the speed that carries the mean load, or 0 when the mean load is at or beyond
    /// the breakdown torque `M_m` (or at or below `−M_m`).
    pub u_mean: f64,
    /// The minimum of the periodic ω², s⁻² (`≤ 0`); 0 for a Kloss motor, whose speed falls
    /// to 0 with no periodic solution to take a minimum of.
    pub u_min: f64,
}

/// Outcome of the steady-state prediction.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Prediction {
    /// A periodic steady state exists.
    Steady(SteadyState),
    /// No steady state: the motor stalls under the peak load.
    Stalls(Stall),
}

impl Prediction {
    /// The steady state, if there is one.
    pub fn steady(&self) -> Option<&SteadyState> {
        match self {
            Prediction::Steady(s) => Some(s),
            Prediction::Stalls(_) => None,
        }
    }
}

/// Sensitivities of δ at the current design point.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sensitivity {
    /// ∂δ/∂J, per kg·m² (the same for machine inertia and flywheel).
    pub d_delta_d_inertia: f64,
    /// ∂δ/∂M_m, per N·m: the whole motor characteristic scaled with its breakdown torque at
    /// fixed speeds (the "drive moment" of the seed).
    pub d_delta_d_breakdown_torque: f64,
}

/// Why no flywheel could be sized.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum DesignError {
    /// The target δ is not a finite number in (0, 2).
    InvalidTarget,
    /// The target δ is below [`MIN_DELTA_TARGET`]: finer than f64 resolves the speed.
    TargetBelowResolution,
    /// The mean load exceeds the motor's stall torque: no inertia gives a steady state.
    MeanLoadExceedsMotor,
    /// No finite inertia reaches the target (an order-0-only load cannot oscillate, so this
    /// means the needed inertia is beyond the f64 range).
    Unreachable,
}

impl core::fmt::Display for DesignError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            DesignError::InvalidTarget => {
                write!(f, "`delta_target` must be a finite number in (0, 2)")
            }
            DesignError::TargetBelowResolution => write!(
                f,
                "`delta_target` is below {MIN_DELTA_TARGET:e}, finer than f64 resolves the speed"
            ),
            DesignError::MeanLoadExceedsMotor => write!(
                f,
                "the mean load exceeds the motor's stall torque: no flywheel gives a steady state"
            ),
            DesignError::Unreachable => write!(
                f,
                "`delta_target` needs a flywheel beyond the f64 range of the inertia"
            ),
        }
    }
}

impl core::error::Error for DesignError {}

/// What the host reports as the `irregularity` member of `predict --json`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Irregularity {
    /// ωmax, rad/s; with no steady state, `√max(ū + smax, 0)`.
    pub omega_max: f64,
    /// ωmin, rad/s; 0 with no steady state.
    pub omega_min: f64,
    /// δ; 2 with no steady state (the value of the definition when the shaft stops).
    pub delta: f64,
    /// Whether a periodic steady state exists.
    pub steady_state: bool,
    /// Extra flywheel inertia, kg·m², that brings δ to the limit (0 if already within);
    /// `None` without a limit or when no flywheel can help.
    pub flywheel_for_limit: Option<f64>,
}

/// One oscillating order of `u(φ) − ū = Σ c·cos(nφ) + d·sin(nφ)`, with the derivatives of
/// `(c, d)` with respect to the total inertia `J` and to `a = −A`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Component {
    order: f64,
    /// `(p, q)` with `order = p/q`, if the order is such a rational.
    /// (The denominator as a `NonZeroU16`, at most [`MAX_DENOMINATOR`]: 16 bytes, not 24.)
    ratio: Option<(u64, NonZeroU16)>,
    c: f64,
    d: f64,
    dc_dj: f64,
    dd_dj: f64,
    dc_da: f64,
    dd_da: f64,
}

impl Component {
    fn amplitude(&self) -> f64 {
        libm::hypot(self.c, self.d)
    }
    fn value(&self, phi: f64) -> f64 {
        self.wave(self.c, self.d, phi)
    }
    /// `x·cos(nφ) + y·sin(nφ)` at this order: the term itself for `(c, d)`, a derivative of it
    /// for a pair of derivatives.
    fn wave(&self, x: f64, y: f64, phi: f64) -> f64 {
        let t = self.order * phi;
        x * libm::cos(t) + y * libm::sin(t)
    }
}

/// Which way the steady state is computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Path {
    /// Closed form for a parabola motor with constant inertia, the J(φ) solution for a parabola
    /// with inertia harmonics, shooting for a Kloss motor.
    Auto,
    /// The J(φ) solution even for a constant inertia (tests).
    Varying,
    /// Shooting with the parabola (tests).
    ShootingParabola,
}

/// The shooting's outcome, computed when the model is built.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
struct Exact {
    /// Shot with the motor's parabola (tests) rather than its Kloss curve.
    parabola: bool,
    /// The periodic solution; `None`: the drive stalls (`Stall { u_mean, u_min: 0 }`).
    shot: Option<Shot>,
}

/// What the steady state is computed from: the closed form's oscillating orders, or the
/// shooting's outcome (one or the other, in the same storage, so that the parabola's model
/// does not grow by the shooting's results: it is moved by value).
// Sharing the storage is the point (no allocation to box the larger variant into).
#[allow(clippy::large_enum_variant)]
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
enum Body {
    Closed(heapless::Vec<Component, MAX_HARMONICS>),
    Exact(Exact),
}

/// The validated drive: motor, load, reduced inertia and flywheel, with the steady-state
/// coefficients computed once.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct DriveModel {
    motor: Motor,
    load: Load,
    inertia: f64,
    flywheel: f64,
    /// `ū = (B − M1 − Σ order-0 terms)/a`, s⁻².
    u_mean: f64,
    /// The mean load including order-0 harmonics, N·m.
    mean_load: f64,
    /// The closed form's orders, or the periodic solution by shooting ([`Horizon::Shooting`];
    /// a Kloss motor).
    body: Body,
    horizon: Horizon,
    /// The harmonics of J(φ) with a non-zero amplitude (empty: constant inertia).
    inertia_harmonics: heapless::Vec<InertiaHarmonic, MAX_INERTIA_HARMONICS>,
}

impl DriveModel {
    /// A drive with reduced machine `inertia` (kg·m², > 0) and an added `flywheel`
    /// (kg·m², ≥ 0). Rejects parameter combinations whose steady-state coefficients
    /// overflow f64. A Kloss motor's steady state is computed here (by shooting, see
    /// [`Horizon::Shooting`]); rejected are a Kloss drive so stiff against its inertia that one
    /// period needs more than [`MAX_STEPS`](crate::drive::MAX_STEPS) steps
    /// (`OutOfRange("inertia")`) and one with no attracting periodic solution found
    /// (`OutOfRange("load.harmonics")`).
    pub fn new(motor: Motor, load: Load, inertia: f64, flywheel: f64) -> Result<Self, ConfigError> {
        Self::build(motor, load, inertia, flywheel, &[], Path::Auto)
    }

    /// The same drive with a reduced inertia that depends on the shaft angle,
    /// `J(φ) = inertia + flywheel + Σ amplitude·cos(order·φ + phase)` (a crank mechanism),
    /// replacing any harmonics given before. Harmonics of amplitude 0 are dropped; with none
    /// left the drive is the constant-inertia one.
    ///
    /// Rejected: more than [`MAX_INERTIA_HARMONICS`] harmonics (`Capacity`); a J(φ) that
    /// reaches 0 or below, its least value over the period ([`least_inertia`]) not positive
    /// (`Inconsistent("inertia_harmonic.amplitude")`, the simulator's own condition; amplitudes
    /// whose magnitudes add up to less than `inertia + flywheel` are accepted without the
    /// search, and more than that with orders that have no common period are rejected);
    /// orders with no common period with each other and with the load's
    /// (`Inconsistent("inertia_harmonic.order")`: rationals with denominators up to
    /// [`MAX_DENOMINATOR`] and a period of at most [`MAX_SAMPLES`]/32 cycles of the fastest
    /// order are accepted); and a drive whose periodic solution needs more than
    /// [`MAX_NODES`](crate::drive::MAX_NODES) trapezoid nodes or overflows f64 (`OutOfRange("inertia_harmonics")`:
    /// J(φ) nearly reaching 0). A motor so stiff against the inertia's swing that the
    /// integrating factor `e^{−∫2a(1/J − mean 1/J)}` swings by more than `e^12` over the
    /// period, `4a·|J̃|/(J0²·n) ≳ 12` for one harmonic `J̃` of order `n` (its cancellation
    /// would leave less than about ten of f64's digits in ω², and from about `e^30` none; see
    /// the `varying` module), is shot with the parabola instead, and refused the same way
    /// where that needs too many steps.
    pub fn with_inertia_harmonics(
        &self,
        harmonics: &[InertiaHarmonic],
    ) -> Result<Self, ConfigError> {
        Self::build(
            self.motor,
            self.load.clone(),
            self.inertia,
            self.flywheel,
            harmonics,
            self.path(),
        )
    }

    /// The harmonics of J(φ) (empty for a constant inertia).
    pub fn inertia_harmonics(&self) -> &[InertiaHarmonic] {
        &self.inertia_harmonics
    }

    /// The same drive on the J(φ) path even with a constant inertia, for the tests that check
    /// it against the closed form.
    #[cfg(test)]
    pub(super) fn on_varying_path(&self) -> Result<Self, ConfigError> {
        self.rebuilt_on(self.motor, self.inertia, self.flywheel, Path::Varying)
    }

    /// The same drive by shooting with its parabola, for the tests that check the shooting
    /// against the closed form.
    #[cfg(test)]
    pub(super) fn on_shooting_path(&self) -> Result<Self, ConfigError> {
        self.rebuilt_on(
            self.motor,
            self.inertia,
            self.flywheel,
            Path::ShootingParabola,
        )
    }

    fn is_varying(&self) -> bool {
        matches!(self.horizon, Horizon::Varying { .. })
    }

    /// Rebuilds with other motor and inertias, keeping the inertia harmonics and the path.
    fn rebuilt(&self, motor: Motor, inertia: f64, flywheel: f64) -> Result<Self, ConfigError> {
        self.rebuilt_on(motor, inertia, flywheel, self.path())
    }

    /// The same drive's load and inertia harmonics with these parts, on `path`.
    fn rebuilt_on(
        &self,
        motor: Motor,
        inertia: f64,
        flywheel: f64,
        path: Path,
    ) -> Result<Self, ConfigError> {
        let h = self.inertia_harmonics.clone();
        Self::build(motor, self.load.clone(), inertia, flywheel, &h, path)
    }

    fn build(
        motor: Motor,
        load: Load,
        inertia: f64,
        flywheel: f64,
        inertia_harmonics: &[InertiaHarmonic],
        path: Path,
    ) -> Result<Self, ConfigError> {
        let inertia = positive("inertia", inertia)?;
        let flywheel = non_negative("flywheel", flywheel)?;
        let j = inertia + flywheel;
        if !j.is_finite() {
            return Err(ConfigError::OutOfRange("flywheel"));
        }
        let a = -motor.model().a();
        let mut mean_load = load.mean();
        for h in load.harmonics().iter().filter(|h| h.order() == 0.0) {
            mean_load += h.amplitude() * libm::sin(h.phase());
        }
        let u_mean = (motor.model().b() - mean_load) / a;
        if !(mean_load.is_finite() && u_mean.is_finite()) {
            return Err(ConfigError::OutOfRange("load.mean"));
        }
        let mut components: heapless::Vec<Component, MAX_HARMONICS> = heapless::Vec::new();
        for h in load.harmonics().iter().filter(|h| h.order() > 0.0) {
            let k = component(h, a, j).ok_or(ConfigError::OutOfRange("harmonic.amplitude"))?;
            match components.iter_mut().find(|c| same_order(c, &k)) {
                Some(c) => {
                    c.c += k.c;
                    c.d += k.d;
                    c.dc_dj += k.dc_dj;
                    c.dd_dj += k.dd_dj;
                    c.dc_da += k.dc_da;
                    c.dd_da += k.dd_da;
                }
                // Cannot fail: at most as many components as harmonics.
                None => components
                    .push(k)
                    .map_err(|_| ConfigError::Capacity("harmonics"))?,
            }
        }
        components.retain(|c| c.amplitude() > 0.0);
        let total: f64 = components.iter().map(Component::amplitude).sum();
        if !(total.is_finite() && (u_mean + total).is_finite()) {
            return Err(ConfigError::OutOfRange("harmonic.amplitude"));
        }
        let mut kept: heapless::Vec<InertiaHarmonic, MAX_INERTIA_HARMONICS> = heapless::Vec::new();
        let mut swing = 0.0;
        for h in inertia_harmonics.iter().filter(|h| h.amplitude() != 0.0) {
            swing += libm::fabs(h.amplitude());
            kept.push(*h)
                .map_err(|_| ConfigError::Capacity("inertia_harmonics"))?;
        }
        // J(φ) > 0 for every φ: certain when the amplitudes' magnitudes add up to less than
        // `j`, else J(φ)'s least value over the period decides (an overflowed `swing`, +∞, is
        // rejected too; `j` is finite).
        if swing >= j && !least_inertia(j, &kept).is_some_and(|(_, least)| least > 0.0) {
            return Err(ConfigError::Inconsistent("inertia_harmonic.amplitude"));
        }
        let mut model = Self {
            motor,
            load,
            inertia,
            flywheel,
            u_mean,
            mean_load,
            body: Body::Closed(components),
            horizon: Horizon::Constant,
            inertia_harmonics: kept,
        };
        let curve = match path {
            Path::Auto => model.motor.kloss_curve().map(|k| Characteristic::Kloss(*k)),
            Path::ShootingParabola => Some(Characteristic::Parabola(*model.motor.model())),
            Path::Varying => None,
        };
        if let Some(curve) = curve {
            if model.shoot(curve)? {
                return Ok(model);
            }
        }
        model.horizon = if model.inertia_harmonics.is_empty() && path != Path::Varying {
            horizon(model.components())
        } else {
            match model.varying_horizon()? {
                Some(h) => h,
                None => {
                    // A motor too stiff against the inertia's swing for the J(φ) solution,
                    // whose integrating factor would leave the result to rounding: shot with
                    // the parabola, which has no such factor (it agrees to 1e-10 where both
                    // apply). A drive neither solves (J(φ) near 0, far too many steps), or one
                    // held to the J(φ) path, is refused as that path refused it.
                    let curve = Characteristic::Parabola(*model.motor.model());
                    let shot = path == Path::Auto && matches!(model.shoot(curve), Ok(true));
                    return if shot {
                        Ok(model)
                    } else {
                        Err(ConfigError::OutOfRange("inertia_harmonics"))
                    };
                }
            }
        };
        Ok(model)
    }

    /// The steady state by shooting with `curve`; `Ok(false)` (the closed form stands in) for
    /// a constant inertia and load orders with no common period, where no periodic solution
    /// exists: the motor's parabola's [`Horizon::Unbounded`] bound is used then. Out of line:
    /// design-time code, off the parabola's path.
    #[inline(never)]
    fn shoot(&mut self, curve: Characteristic) -> Result<bool, ConfigError> {
        let parabola = matches!(curve, Characteristic::Parabola(_));
        let orders = self.periodic_orders();
        let any = orders.clone().next().is_some();
        let Some((radians, cycles)) = common_period(orders).filter(|_| any) else {
            if !self.inertia_harmonics.is_empty() {
                return Err(ConfigError::Inconsistent("inertia_harmonic.order"));
            }
            if any {
                return Ok(false);
            }
            // No oscillation at all: ω is the speed that carries the mean load.
            self.horizon = Horizon::Constant;
            self.u_mean = match Shooter::new(
                curve,
                self.total_inertia(),
                &[],
                &[],
                self.mean_load,
                2.0 * PI,
                1,
            ) {
                Ok(s) => s.omega_ref() * s.omega_ref(),
                Err(_) => 0.0,
            };
            return Ok(true);
        };
        let shooter = Shooter::new(
            curve,
            self.total_inertia(),
            &self.inertia_harmonics,
            self.load.harmonics(),
            self.mean_load,
            radians,
            cycles,
        );
        let shooter = match shooter {
            Ok(s) => s,
            Err(Failure::Steps) => return Err(ConfigError::OutOfRange("inertia")),
            Err(_) => {
                // No speed carries the mean load: no inertia helps.
                self.u_mean = 0.0;
                self.horizon = Horizon::Shooting { radians, steps: 0 };
                self.body = Body::Exact(Exact {
                    parabola,
                    shot: None,
                });
                return Ok(true);
            }
        };
        // The start: the tangent parabola's oscillation at φ = 0 about the shooting's
        // reference speed (for a constant inertia; with J(φ), the reference itself).
        let guess = if self.inertia_harmonics.is_empty() {
            self.total_inertia() * self.oscillation(0.0)
        } else {
            0.0
        };
        let omega_ref = shooter.omega_ref();
        match shooter.solve(guess) {
            Ok(shot) => {
                self.u_mean = shot.centre() + shot.s_mean;
                self.horizon = Horizon::Shooting {
                    radians,
                    steps: shooter.steps(),
                };
                self.body = Body::Exact(Exact {
                    parabola,
                    shot: Some(shot),
                });
            }
            Err(Failure::Stalls) => {
                self.u_mean = omega_ref * omega_ref;
                self.horizon = Horizon::Shooting { radians, steps: 0 };
                self.body = Body::Exact(Exact {
                    parabola,
                    shot: None,
                });
            }
            Err(Failure::Steps) => return Err(ConfigError::OutOfRange("inertia")),
            Err(Failure::MeanLoad | Failure::NoAttractingState) => {
                return Err(ConfigError::OutOfRange("load.harmonics"))
            }
        }
        Ok(true)
    }

    /// The closed form's oscillating orders (none on the shooting path).
    fn components(&self) -> &[Component] {
        match &self.body {
            Body::Closed(c) => c,
            Body::Exact(_) => &[],
        }
    }

    /// The shooting's outcome, on its path.
    fn exact(&self) -> Option<&Exact> {
        match &self.body {
            Body::Exact(e) => Some(e),
            Body::Closed(_) => None,
        }
    }

    /// The path a rebuilt drive takes: this one's.
    fn path(&self) -> Path {
        if self.is_varying() {
            Path::Varying
        } else if self.exact().is_some_and(|e| e.parabola) {
            Path::ShootingParabola
        } else {
            Path::Auto
        }
    }

    /// The shooting setup of the converged solution (`None` unless there is one).
    fn shooter(&self) -> Option<(Shooter<'_>, Shot)> {
        let (
            Some(Exact {
                shot: Some(shot),
                parabola,
            }),
            Horizon::Shooting { radians, steps },
        ) = (self.exact().copied(), self.horizon)
        else {
            return None;
        };
        let curve = match (parabola, self.motor.kloss_curve()) {
            (false, Some(k)) => Characteristic::Kloss(*k),
            _ => Characteristic::Parabola(*self.motor.model()),
        };
        let shooter = Shooter::again(
            curve,
            &shot,
            self.total_inertia(),
            &self.inertia_harmonics,
            self.load.harmonics(),
            radians,
            steps,
        );
        Some((shooter, shot))
    }

    /// The load's period in whole revolutions, the δ window its monitor needs: the
    /// [`period_revolutions`] of every load harmonic that is there (order and amplitude
    /// non-zero) and every inertia harmonic, the orders the periodic solution repeats over.
    pub fn period_revolutions(&self) -> Option<u64> {
        whole_revolutions(self.periodic_orders())
    }

    /// The orders the periodic solution has to repeat over: every load harmonic that is
    /// there (order and amplitude non-zero) and every inertia harmonic.
    fn periodic_orders(&self) -> impl Iterator<Item = f64> + Clone + '_ {
        self.load
            .harmonics()
            .iter()
            .filter(|h| h.order() > 0.0 && h.amplitude() != 0.0)
            .map(Harmonic::order)
            .chain(self.inertia_harmonics.iter().map(InertiaHarmonic::order))
    }

    /// The common period of the load and inertia orders and the trapezoid nodes that resolve
    /// the periodic solution over it (out of line: see [`Self::varying_state`]).
    #[inline(never)]
    /// `None`: the motor is too stiff against the inertia's swing for the solution (its
    /// integrating factor swings by more than `e^MAX_FACTOR_SWING`).
    fn varying_horizon(&self) -> Result<Option<Horizon>, ConfigError> {
        let orders = self.periodic_orders();
        let bad_order = ConfigError::Inconsistent("inertia_harmonic.order");
        let (radians, cycles) = common_period(orders).ok_or(bad_order)?;
        let start = varying::initial_nodes(cycles).ok_or(bad_order)?;
        let out_of_range = ConfigError::OutOfRange("inertia_harmonics");
        let drive = self.varying_drive(radians);
        // The small solution first (4 KiB of stack); the large one only for a drive that needs
        // more nodes.
        let nodes = match resolved_nodes::<SMALL_NODES>(drive, start) {
            Err(varying::Unresolved::Nodes) => {
                resolved_nodes::<MAX_NODES>(drive, start.max(2 * SMALL_NODES))
            }
            r => r,
        };
        match nodes {
            Ok(nodes) => Ok(Some(Horizon::Varying {
                radians,
                nodes: nodes as u32,
            })),
            Err(varying::Unresolved::Stiff) => Ok(None),
            Err(_) => Err(out_of_range),
        }
    }

    fn varying_drive(&self, period: f64) -> varying::Drive<'_> {
        varying::Drive {
            a: -self.motor.model().a(),
            q_mean: 2.0 * (self.motor.model().b() - self.mean_load),
            j0: self.total_inertia(),
            inertia: &self.inertia_harmonics,
            load: self.load.harmonics(),
            period,
        }
    }

    /// The J(φ) solution on the model's nodes, held in `N` (`None` on the constant-inertia
    /// path, or when the nodes are more than `N`; the constructor computed the same solution,
    /// so it does not fail otherwise).
    fn varying_solution<const N: usize>(&self) -> Option<Solution<'_, N>> {
        match self.horizon {
            Horizon::Varying { radians, nodes } => {
                Solution::solve(self.varying_drive(radians), nodes as usize, false).ok()
            }
            _ => None,
        }
    }

    /// Whether the J(φ) solution fits the small buffer.
    fn small_solution(&self) -> bool {
        matches!(self.horizon, Horizon::Varying { nodes, .. } if nodes as usize <= SMALL_NODES)
    }

    /// The steady-state curve, for evaluating ω at many angles: on the J(φ) path it holds the
    /// solution's spectrum (about 64 KiB), each evaluation `O(nodes)`.
    pub fn steady_curve(&self) -> SteadyCurve<'_> {
        SteadyCurve {
            model: self,
            solution: self.varying_solution::<MAX_NODES>(),
            shooter: self.shooter(),
            from: Cell::new((0.0, f64::NAN)),
        }
    }

    /// The same drive with a different added flywheel inertia.
    pub fn with_flywheel(&self, flywheel: f64) -> Result<Self, ConfigError> {
        self.rebuilt(self.motor, self.inertia, flywheel)
    }

    /// The same drive with a different motor.
    pub fn with_motor(&self, motor: Motor) -> Result<Self, ConfigError> {
        self.rebuilt(motor, self.inertia, self.flywheel)
    }

    /// The motor.
    pub fn motor(&self) -> &Motor {
        &self.motor
    }

    /// The load.
    pub fn load(&self) -> &Load {
        &self.load
    }

    /// Reduced machine inertia, kg·m².
    pub fn inertia(&self) -> f64 {
        self.inertia
    }

    /// Added flywheel inertia, kg·m².
    pub fn flywheel(&self) -> f64 {
        self.flywheel
    }

    /// Total inertia `J` (machine plus flywheel), kg·m².
    pub fn total_inertia(&self) -> f64 {
        self.inertia + self.flywheel
    }

    /// How the extrema are found for this load.
    pub fn horizon(&self) -> Horizon {
        self.horizon
    }

    /// Mean of ω² over the steady period (over the shaft angle), `ū = (B − M1)/a`, s⁻²;
    /// with J(φ) too (the mean of eq. 1 in `w = J·ω²` over the period).
    pub fn u_mean(&self) -> f64 {
        self.u_mean
    }

    /// ω² of the periodic solution at shaft angle `phi`, s⁻² (may be ≤ 0 where the drive
    /// would stall). NaN in, NaN out. On the J(φ) path each call solves the drive anew: use
    /// [`Self::steady_curve`] for many angles.
    pub fn omega_squared(&self, phi: f64) -> f64 {
        if self.is_varying() {
            self.varying_omega_squared(phi)
        } else if self.exact().is_some() {
            self.steady_curve().omega_squared(phi)
        } else {
            self.u_mean + self.oscillation(phi)
        }
    }

    /// Out of line, so that the solution's stack stays off the constant-inertia path, and in
    /// the small buffer when the nodes fit it.
    fn varying_omega_squared(&self, phi: f64) -> f64 {
        if self.small_solution() {
            self.varying_omega_squared_in::<SMALL_NODES>(phi)
        } else {
            self.varying_omega_squared_in::<MAX_NODES>(phi)
        }
    }

    #[inline(never)]
    fn varying_omega_squared_in<const N: usize>(&self, phi: f64) -> f64 {
        self.varying_solution::<N>()
            .map_or(f64::NAN, |s| s.omega_squared(phi))
    }

    /// Steady-state speed at shaft angle `phi`, rad/s, for plots and for comparison with a
    /// simulation; `None` where the periodic solution has `ω² ≤ 0` (check [`Self::predict`]
    /// for whether the steady state exists at all) or for non-finite `phi`. On the J(φ) path
    /// each call solves the drive anew: use [`Self::steady_curve`] for many angles.
    pub fn steady_omega(&self, phi: f64) -> Option<f64> {
        let u = self.omega_squared(phi);
        if u > 0.0 && u.is_finite() {
            Some(libm::sqrt(u))
        } else {
            None
        }
    }

    /// `ω² = centre + s` and the extrema of `s`: `ū` and the closed-form oscillation for a
    /// constant inertia, `w̄/J0` and the J(φ) swing otherwise.
    fn state(&self) -> (f64, Extremes) {
        if self.is_varying() {
            self.varying_state()
        } else if let Some(e) = self.exact() {
            match e.shot {
                Some(s) => (
                    s.centre(),
                    Extremes {
                        s_max: s.s_max,
                        s_min: s.s_min,
                        phi_max: Some(s.phi_max),
                        phi_min: Some(s.phi_min),
                    },
                ),
                None => (
                    self.u_mean,
                    Extremes {
                        s_max: 0.0,
                        s_min: -self.u_mean,
                        phi_max: None,
                        phi_min: None,
                    },
                ),
            }
        } else {
            (self.u_mean, self.extremes())
        }
    }

    /// [`Self::state`] on the J(φ) path: in the small buffer when the nodes fit it.
    fn varying_state(&self) -> (f64, Extremes) {
        if self.small_solution() {
            self.varying_state_in::<SMALL_NODES>()
        } else {
            self.varying_state_in::<MAX_NODES>()
        }
    }

    /// Out of line, one copy per buffer, so that the solution's stack (4 or 64 KiB) stays off
    /// the constant-inertia path and the small buffer's callers.
    #[inline(never)]
    fn varying_state_in<const N: usize>(&self) -> (f64, Extremes) {
        match self.varying_solution::<N>() {
            Some(mut sol) => {
                let e = sol.extremes();
                (
                    e.centre,
                    Extremes {
                        s_max: e.s_max,
                        s_min: e.s_min,
                        phi_max: Some(e.phi_max),
                        phi_min: Some(e.phi_min),
                    },
                )
            }
            // Not reached (the constructor solved the same drive); NaN reads as a stall.
            None => (
                f64::NAN,
                Extremes {
                    s_max: f64::NAN,
                    s_min: f64::NAN,
                    phi_max: None,
                    phi_min: None,
                },
            ),
        }
    }

    /// The steady state and its δ, or the stall.
    pub fn predict(&self) -> Prediction {
        let (centre, ex) = match &self.body {
            Body::Closed(_) if !self.is_varying() => (self.u_mean, self.extremes()),
            Body::Exact(Exact { shot: None, .. }) => {
                return Prediction::Stalls(Stall {
                    u_mean: self.u_mean,
                    u_min: 0.0,
                })
            }
            _ => self.state(),
        };
        let u_min = centre + ex.s_min;
        if !exceeds(u_min, 0.0) {
            return Prediction::Stalls(Stall {
                u_mean: self.u_mean,
                u_min,
            });
        }
        let w_max = libm::sqrt(centre + ex.s_max);
        let w_min = libm::sqrt(u_min);
        let w = w_max + w_min;
        // δ from the difference of squares: (ωmax − ωmin) = (smax − smin)/(ωmax + ωmin).
        let delta = 2.0 * ((ex.s_max - ex.s_min) / w) / w;
        Prediction::Steady(SteadyState {
            omega_max: w_max,
            omega_min: w_min,
            delta,
            omega_rms: libm::sqrt(self.u_mean),
            phi_max: ex.phi_max,
            phi_min: ex.phi_min,
            horizon: self.horizon,
            within_working_branch: w_min >= self.motor.model().working_min_speed(),
        })
    }

    /// ∂δ/∂J and ∂δ/∂M_m at the current design, analytic (envelope theorem: the derivative of
    /// an extremum is the partial derivative at the extremal angle). `None` without a steady
    /// state, or when the parameters are so extreme that the derivatives overflow f64.
    ///
    /// With J(φ) or a Kloss motor the phases of the extrema move with the parameters in no
    /// closed form: both derivatives are central differences of the computed δ with a relative
    /// step of 1e-4 (about 8 significant digits), the inertia step taken on the constant part
    /// of J, the torque step scaling the whole characteristic (the Kloss curve's `M_m`);
    /// `None` also when a stepped drive cannot be built or stalls.
    pub fn sensitivity(&self) -> Option<Sensitivity> {
        if self.is_varying() || self.exact().is_some() {
            return self.varying_sensitivity();
        }
        let ex = self.extremes();
        let (x2, y2) = (self.u_mean + ex.s_max, self.u_mean + ex.s_min);
        if !exceeds(y2, 0.0) {
            return None;
        }
        let (x, y) = (libm::sqrt(x2), libm::sqrt(y2));
        let w = x + y;
        let dd = ex.s_max - ex.s_min;
        let g = 2.0 / (w * w);
        let d_smax = g * (1.0 - dd / (w * x));
        let d_smin = -g * (1.0 + dd / (w * y));
        let d_umean = -(2.0 * dd / (w * w * w)) * (1.0 / x + 1.0 / y);
        let (smax_j, smax_a, smin_j, smin_a) = match (ex.phi_max, ex.phi_min) {
            (Some(pmax), Some(pmin)) => {
                // ∂s/∂J or ∂s/∂a at φ, from each component's pair of derivatives.
                let slope = |phi: f64, pair: fn(&Component) -> (f64, f64)| {
                    self.components()
                        .iter()
                        .map(|c| {
                            let (x, y) = pair(c);
                            c.wave(x, y, phi)
                        })
                        .sum::<f64>()
                };
                let dj = |c: &Component| (c.dc_dj, c.dd_dj);
                let da = |c: &Component| (c.dc_da, c.dd_da);
                (
                    slope(pmax, dj),
                    slope(pmax, da),
                    slope(pmin, dj),
                    slope(pmin, da),
                )
            }
            _ => {
                // smax = Σ R_k, smin = −Σ R_k (or both 0): derivative of each |(c, d)|.
                let (mut rj, mut ra) = (0.0, 0.0);
                for c in self.components() {
                    let r = c.amplitude();
                    // A vanishing (or underflowed) amplitude has no direction to differentiate.
                    if r.is_nan() || r <= 0.0 {
                        continue;
                    }
                    rj += (c.c * c.dc_dj + c.d * c.dd_dj) / r;
                    ra += (c.c * c.dc_da + c.d * c.dd_da) / r;
                }
                (rj, ra, -rj, -ra)
            }
        };
        let d_inertia = d_smax * smax_j + d_smin * smin_j;
        // Scaling the motor by λ multiplies a and B by λ: ∂ū/∂λ = M1/a, ∂s/∂λ = a·∂s/∂a.
        let a = -self.motor.model().a();
        let d_lambda = a * (d_smax * smax_a + d_smin * smin_a) + d_umean * (self.mean_load / a);
        let d_torque = d_lambda / self.motor.model().breakdown_torque();
        // Parameters near the f64 range can overflow the intermediate products.
        if !(d_inertia.is_finite() && d_torque.is_finite()) {
            return None;
        }
        Some(Sensitivity {
            d_delta_d_inertia: d_inertia,
            d_delta_d_breakdown_torque: d_torque,
        })
    }

    /// The extra flywheel inertia (kg·m², on top of the current flywheel) that brings δ down
    /// to `delta_target`; 0 if δ is already within.
    ///
    /// `delta_target` must be finite, below 2 and at least [`MIN_DELTA_TARGET`] (≈ 2.2e-16):
    /// a smaller δ asks for a speed ripple below the f64 resolution of the speed itself and is
    /// rejected with [`DesignError::TargetBelowResolution`]. A target that needs more inertia
    /// than f64 holds is [`DesignError::Unreachable`], never a huge or infinite number.
    ///
    /// One oscillating order: closed form. With `r = δ/(1 + δ²/4)` (the inverse of
    /// `δ = 2r/(1 + √(1 − r²))`, `r = R/ū`) the needed amplitude is `R = r·ū`, and
    /// `R = 2|M2|/√(4a² + n²J²)` gives `J = √((2|M2|/R − 2a)(2|M2|/R + 2a))/n`, since `ū`
    /// does not depend on `J`.
    ///
    /// Several orders: bisection in J between the current inertia, where the target is missed,
    /// and an upper end where it is met for certain, found in closed form: each order's
    /// amplitude `R_k = 2|M2k|/√(4a² + n_k²J²)` is at most `2|M2k|/(n_k·J)`, and the
    /// conservative extrema `ū ± Σ R_k` (those of [`Horizon::Unbounded`]) bound δ from above,
    /// so the inertia that brings `Σ R_k` to `r·ū` (less 1e-6 for rounding) meets the target
    /// whatever the phases. Bisection returns the upper end of the bracket, where δ ≤ target
    /// holds, once the bracket is within 1e-10 relative. δ(J) falls monotonically for one order
    /// and for [`Horizon::Unbounded`]; with several commensurate orders the phases also move
    /// with J, and the answer is the first crossing the bracket finds.
    ///
    /// Cost, for any input: at most 210 steady-state predictions (1 at the current inertia, up
    /// to 9 to confirm the upper end, up to 200 bisection steps), each a search over at most
    /// [`MAX_SAMPLES`] samples; typically 36. The upper end is confirmed at the first try
    /// unless rounding defeats the bound (up to 8 doublings absorb that; past them the target
    /// counts as unreachable). Bisection stops once the bracket is within 1e-10 relative, after
    /// about `log2(upper end / answer) + 34` steps; the bound is within a small factor of the
    /// answer except where δ barely depends on J, so 200 steps are reached only when the
    /// answer is below about 2⁻¹⁶⁶ of the upper end, and then the returned flywheel still
    /// meets the target, a little oversized.
    ///
    /// With J(φ) or a Kloss motor no closed-form bound exists: the upper end is found by
    /// doubling an added flywheel from the current total inertia (at most 1100 doublings, past
    /// the f64 range), then bisected as above. δ falls with the flywheel (both the load's and
    /// the inertia's share of the swing shrink like 1/J for a large flywheel; the randomised
    /// tests check monotonicity on a grid, for J(φ) and for Kloss drives), and where it might
    /// not, the answer is the first crossing the bracket finds, which meets the target.
    pub fn flywheel_for(&self, delta_target: f64) -> Result<f64, DesignError> {
        if !(delta_target.is_finite() && delta_target > 0.0 && delta_target < 2.0) {
            return Err(DesignError::InvalidTarget);
        }
        if delta_target < MIN_DELTA_TARGET {
            return Err(DesignError::TargetBelowResolution);
        }
        if !exceeds(self.u_mean, 0.0) {
            return Err(DesignError::MeanLoadExceedsMotor);
        }
        let meets = |m: &DriveModel| match m.predict() {
            Prediction::Steady(s) => s.delta <= delta_target,
            Prediction::Stalls(_) => false,
        };
        if meets(self) {
            return Ok(0.0);
        }
        let at = |extra: f64| self.with_flywheel(self.flywheel + extra).ok();
        let j = self.total_inertia();
        let a = -self.motor.model().a();
        // The oscillation amplitude that gives δ = target with symmetric extrema ū ± R.
        let r = delta_target / (1.0 + delta_target * delta_target / 4.0);
        if let ([c], Horizon::ClosedForm) = (self.components(), self.horizon) {
            let n = c.order;
            let h = libm::hypot(2.0 * a, n * j);
            // |Σ M2k·e^{iψk}| of the harmonics of this order: R·h/2.
            let m2 = c.amplitude() * h / 2.0;
            let h_needed = 2.0 * m2 / (r * self.u_mean);
            if !exceeds(h_needed, 2.0 * a) {
                return Ok(0.0);
            }
            // As two roots: the product overflows beyond 1.3e154.
            let j_needed = libm::sqrt(h_needed - 2.0 * a) * libm::sqrt(h_needed + 2.0 * a) / n;
            let extra = j_needed - j;
            // n·J stays below h_needed, so the model holds this inertia if it is finite.
            return if !(self.inertia + (self.flywheel + extra)).is_finite() {
                Err(DesignError::Unreachable)
            } else if extra <= 0.0 {
                Ok(0.0)
            } else {
                Ok(extra)
            };
        }
        // J(φ) and the shooting (after the closed form, which neither takes).
        if self.is_varying() || self.exact().is_some() {
            let mut hi = self.total_inertia();
            let mut lo = 0.0;
            let mut found = false;
            for _ in 0..MAX_VARYING_DOUBLINGS {
                match at(hi) {
                    Some(m) if meets(&m) => {
                        found = true;
                        break;
                    }
                    Some(_) => {
                        lo = hi;
                        hi *= 2.0;
                        if !(self.flywheel + hi).is_finite() {
                            break;
                        }
                    }
                    None => break,
                }
            }
            if !found {
                return Err(DesignError::Unreachable);
            }
            return bisect(lo, hi, |x| at(x).map(|m| meets(&m)));
        }
        // Upper end of the bracket: with `S = Σ 2|M2k|/n_k` and the budget `B = r·ū`, order k
        // gets the share `(2|M2k|/n_k)/S` of B, reached where `√(4a² + n_k²J²) = n_k·S/B`,
        // i.e. at `J_k = √((S/B)² − (2a/n_k)²)`; at `max_k J_k` every share holds, so
        // `Σ R_k ≤ B`. `2|M2k| = R_k·h_k` at the current inertia.
        let budget = r * self.u_mean * (1.0 - 1e-6);
        let s: f64 = self
            .components()
            .iter()
            .map(|c| c.amplitude() * (libm::hypot(2.0 * a, c.order * j) / c.order))
            .sum();
        let x = s / budget;
        let j_bound = self
            .components()
            .iter()
            .map(|c| {
                let y = 2.0 * a / c.order;
                if x > y {
                    libm::sqrt(x - y) * libm::sqrt(x + y)
                } else {
                    0.0
                }
            })
            .fold(0.0, f64::max);
        // Beyond f64: start from the largest flywheel the model can hold (n·J must stay
        // finite); no larger than J through rounding: from J itself.
        let n_max = self
            .components()
            .iter()
            .map(|c| c.order)
            .fold(1.0, f64::max);
        let cap = f64::MAX / 4.0 / n_max;
        let mut hi = if !j_bound.is_finite() || j_bound > cap {
            cap
        } else if j_bound > j {
            j_bound - j
        } else {
            j
        };
        let mut lo = 0.0;
        let mut doublings = 0;
        loop {
            match at(hi) {
                Some(m) if meets(&m) => break,
                Some(_) if doublings < MAX_CONFIRM_DOUBLINGS => {
                    lo = hi;
                    hi *= 2.0;
                    doublings += 1;
                }
                _ => return Err(DesignError::Unreachable),
            }
        }
        bisect(lo, hi, |x| at(x).map(|m| meets(&m)))
    }

    /// ∂δ/∂J and ∂δ/∂M_m by central differences (J(φ) path).
    fn varying_sensitivity(&self) -> Option<Sensitivity> {
        const STEP: f64 = 1e-4;
        let delta = |m: Result<DriveModel, ConfigError>| -> Option<f64> {
            m.ok()?.predict().steady().map(|s| s.delta)
        };
        self.predict().steady()?;
        let h = STEP * self.total_inertia();
        let (up, down) = if self.flywheel >= h {
            (
                self.rebuilt(self.motor, self.inertia, self.flywheel + h),
                self.rebuilt(self.motor, self.inertia, self.flywheel - h),
            )
        } else {
            (
                self.rebuilt(self.motor, self.inertia + h, self.flywheel),
                self.rebuilt(self.motor, self.inertia - h, self.flywheel),
            )
        };
        let d_inertia = (delta(up)? - delta(down)?) / (2.0 * h);
        // The whole characteristic scaled by 1 ± STEP: M_m moves by ±STEP·M_m.
        let scaled = |f: f64| {
            self.motor
                .scaled(f)
                .ok_or(ConfigError::OutOfRange("breakdown_torque"))
                .and_then(|m| self.rebuilt(m, self.inertia, self.flywheel))
        };
        let mm = self.motor.model().breakdown_torque();
        let d_torque =
            (delta(scaled(1.0 + STEP))? - delta(scaled(1.0 - STEP))?) / (2.0 * STEP * mm);
        if !(d_inertia.is_finite() && d_torque.is_finite()) {
            return None;
        }
        Some(Sensitivity {
            d_delta_d_inertia: d_inertia,
            d_delta_d_breakdown_torque: d_torque,
        })
    }

    /// The `irregularity` summary the host prints, with the flywheel for `delta_limit` when
    /// one is given (it must be finite, at least [`MIN_DELTA_TARGET`] and below 2).
    pub fn irregularity(&self, delta_limit: Option<f64>) -> Result<Irregularity, ConfigError> {
        if let Some(l) = delta_limit {
            let l = positive("delta_limit", l)?;
            if !(MIN_DELTA_TARGET..2.0).contains(&l) {
                return Err(ConfigError::OutOfRange("delta_limit"));
            }
        }
        let flywheel_for_limit = delta_limit.and_then(|l| self.flywheel_for(l).ok());
        Ok(match self.predict() {
            Prediction::Steady(s) => Irregularity {
                omega_max: s.omega_max,
                omega_min: s.omega_min,
                delta: s.delta,
                steady_state: true,
                flywheel_for_limit,
            },
            Prediction::Stalls(_) => {
                let (centre, ex) = self.state();
                let u_max = centre + ex.s_max;
                Irregularity {
                    omega_max: if u_max > 0.0 { libm::sqrt(u_max) } else { 0.0 },
                    omega_min: 0.0,
                    delta: 2.0,
                    steady_state: false,
                    flywheel_for_limit,
                }
            }
        })
    }

    fn oscillation(&self, phi: f64) -> f64 {
        self.components().iter().map(|c| c.value(phi)).sum()
    }

    fn extremes(&self) -> Extremes {
        match (self.horizon, self.components()) {
            (Horizon::ClosedForm, [c]) => {
                // c·cos(nφ) + d·sin(nφ) = R·cos(nφ − α).
                let r = c.amplitude();
                let period = 2.0 * PI / c.order;
                let mut alpha = libm::atan2(c.d, c.c);
                if alpha < 0.0 {
                    alpha += 2.0 * PI;
                }
                let phi_max = alpha / c.order;
                // Half a period back or forward, never beyond the period (no overflow); an
                // order so slow that 2π/n overflows f64 has no representable angle at all.
                let half = period / 2.0;
                let phi_min = if phi_max >= half {
                    phi_max - half
                } else {
                    phi_max + half
                };
                let angles = period.is_finite() && phi_max.is_finite() && phi_min.is_finite();
                Extremes {
                    s_max: r,
                    s_min: -r,
                    phi_max: angles.then_some(phi_max),
                    phi_min: angles.then_some(phi_min),
                }
            }
            (Horizon::Period { radians, samples }, _) => self.search(radians, samples),
            (Horizon::Unbounded, _) => {
                let r: f64 = self.components().iter().map(Component::amplitude).sum();
                Extremes {
                    s_max: r,
                    s_min: -r,
                    phi_max: None,
                    phi_min: None,
                }
            }
            _ => Extremes {
                s_max: 0.0,
                s_min: 0.0,
                phi_max: None,
                phi_min: None,
            },
        }
    }

    /// Extrema of the oscillation over one common period: sample, then refine by golden
    /// section every sample that could lie next to the global extremum. A sample within h/2
    /// of the true maximum is below it by at most `½·C·(h/2)²`, `C = Σ R_k·n_k² ≥ |s''|`;
    /// every sample within `½·C·h²` of the best one is refined on its two neighbouring
    /// intervals.
    fn search(&self, period: f64, samples: u32) -> Extremes {
        let n = samples.max(3);
        let h = period / n as f64;
        let at = |i: i64| self.oscillation(h * i as f64);
        let (mut best_max, mut best_min) = (f64::NEG_INFINITY, f64::INFINITY);
        let (mut i_max, mut i_min) = (0i64, 0i64);
        for i in 0..n as i64 {
            let v = at(i);
            if v > best_max {
                best_max = v;
                i_max = i;
            }
            if v < best_min {
                best_min = v;
                i_min = i;
            }
        }
        let curvature: f64 = self
            .components()
            .iter()
            .map(|c| c.amplitude() * c.order * c.order)
            .sum();
        let amplitude: f64 = self.components().iter().map(Component::amplitude).sum();
        let margin = 0.5 * curvature * h * h + 8.0 * f64::EPSILON * amplitude;
        let mut out = Extremes {
            s_max: best_max,
            s_min: best_min,
            phi_max: Some(h * i_max as f64),
            phi_min: Some(h * i_min as f64),
        };
        let (mut prev, mut cur) = (at(-1), at(0));
        for i in 0..n as i64 {
            let next = at(i + 1);
            let (lo, hi) = (h * (i - 1) as f64, h * (i + 1) as f64);
            if cur >= best_max - margin && (cur >= prev || cur >= next) {
                let (phi, v) = golden(|p| self.oscillation(p), lo, hi, 1.0);
                if v > out.s_max {
                    out.s_max = v;
                    out.phi_max = Some(wrap(phi, period));
                }
            }
            if cur <= best_min + margin && (cur <= prev || cur <= next) {
                let (phi, v) = golden(|p| self.oscillation(p), lo, hi, -1.0);
                if v < out.s_min {
                    out.s_min = v;
                    out.phi_min = Some(wrap(phi, period));
                }
            }
            prev = cur;
            cur = next;
        }
        out
    }
}

/// The nodes that resolve `drive`'s J(φ) solution from `start` on, within a buffer of `N`
/// (out of line, one copy per buffer: only a drive that needs more than the small buffer
/// takes the large one's stack).
#[inline(never)]
fn resolved_nodes<const N: usize>(
    drive: varying::Drive<'_>,
    start: usize,
) -> Result<usize, varying::Unresolved> {
    Solution::<N>::solve(drive, start, true).map(|s| s.nodes())
}

/// The steady state as a curve over φ ([`DriveModel::steady_curve`]).
pub struct SteadyCurve<'a> {
    model: &'a DriveModel,
    solution: Option<Solution<'a, MAX_NODES>>,
    shooter: Option<(Shooter<'a>, Shot)>,
    /// The last shooting point evaluated, `(φ within the period, y)`: evaluations at rising
    /// angles continue from it.
    from: Cell<(f64, f64)>,
}

impl SteadyCurve<'_> {
    /// ω² of the periodic solution at `phi`, s⁻² (as [`DriveModel::omega_squared`]). For a
    /// Kloss motor each evaluation integrates from the previous one when `phi` (within the
    /// period) lies after it, else from the period's start: `O(steps)` at most, and no more
    /// over a sweep of rising angles than one period.
    pub fn omega_squared(&self, phi: f64) -> f64 {
        if let Some((shooter, shot)) = &self.shooter {
            let period = shooter.period();
            let p = phi - period * libm::floor(phi / period);
            if !(p.is_finite() && (0.0..=period).contains(&p)) {
                return f64::NAN;
            }
            let last = self.from.get();
            let start = if last.0 <= p && last.1.is_finite() {
                last
            } else {
                (0.0, shot.y0)
            };
            let (s, y) = shooter.swing_from(start, p);
            self.from.set((p, y));
            return shot.centre() + s;
        }
        match (&self.solution, self.model.is_varying()) {
            (Some(s), _) => s.omega_squared(phi),
            (None, false) => self.model.u_mean + self.model.oscillation(phi),
            (None, true) => f64::NAN,
        }
    }

    /// Steady speed at `phi`, rad/s (as [`DriveModel::steady_omega`]).
    pub fn steady_omega(&self, phi: f64) -> Option<f64> {
        let u = self.omega_squared(phi);
        if u > 0.0 && u.is_finite() {
            Some(libm::sqrt(u))
        } else {
            None
        }
    }
}

/// Bisection between `lo` (target missed) and `hi` (met): the upper end once the bracket is
/// within 1e-10 relative, after at most [`MAX_BISECTIONS`] steps.
fn bisect(
    mut lo: f64,
    mut hi: f64,
    meets: impl Fn(f64) -> Option<bool>,
) -> Result<f64, DesignError> {
    for _ in 0..MAX_BISECTIONS {
        let mid = lo + (hi - lo) / 2.0;
        if hi - lo <= 1e-10 * hi || mid <= lo || mid >= hi {
            break;
        }
        match meets(mid) {
            Some(true) => hi = mid,
            Some(false) => lo = mid,
            None => return Err(DesignError::Unreachable),
        }
    }
    Ok(hi)
}

struct Extremes {
    s_max: f64,
    s_min: f64,
    phi_max: Option<f64>,
    phi_min: Option<f64>,
}

/// `x > y`, false when either is NaN.
fn exceeds(x: f64, y: f64) -> bool {
    x > y
}

pub(super) fn wrap(phi: f64, period: f64) -> f64 {
    if phi < 0.0 {
        phi + period
    } else if phi >= period {
        phi - period
    } else {
        phi
    }
}

/// Golden-section search for the maximum of `sign·f` on `[lo, hi]`; returns the best point
/// seen and `f` there.
pub(super) fn golden(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64, sign: f64) -> (f64, f64) {
    const R: f64 = 0.618_033_988_749_894_8;
    let mut x1 = hi - R * (hi - lo);
    let mut x2 = lo + R * (hi - lo);
    let (mut f1, mut f2) = (sign * f(x1), sign * f(x2));
    for _ in 0..GOLDEN_ITERATIONS {
        if f1 >= f2 {
            hi = x2;
            x2 = x1;
            f2 = f1;
            x1 = hi - R * (hi - lo);
            f1 = sign * f(x1);
        } else {
            lo = x1;
            x1 = x2;
            f1 = f2;
            x2 = lo + R * (hi - lo);
            f2 = sign * f(x2);
        }
    }
    if f1 >= f2 {
        (x1, sign * f1)
    } else {
        (x2, sign * f2)
    }
}

/// The oscillating term of one harmonic as `c·cos(nφ) + d·sin(nφ)`, with derivatives;
/// `None` if it overflows.
fn component(h: &Harmonic, a: f64, j: f64) -> Option<Component> {
    let n = h.order();
    let nj = n * j;
    let hy = libm::hypot(2.0 * a, nj);
    let (u1, u2) = (nj / hy, 2.0 * a / hy);
    let g = 2.0 * (h.amplitude() / hy);
    // s = P·cos θ + Q·sin θ, θ = nφ + ψ.
    let (p, q) = (g * u1, -g * u2);
    let dp_dj = (n / hy) * (g - 2.0 * p * u1);
    let dq_dj = -q * 2.0 * n * u1 / hy;
    let dp_da = -p * 4.0 * u2 / hy;
    let dq_da = -2.0 * g / hy - q * 4.0 * u2 / hy;
    let (sp, cp) = (libm::sin(h.phase()), libm::cos(h.phase()));
    // P·cos(nφ + ψ) + Q·sin(nφ + ψ) = (P cos ψ + Q sin ψ)·cos nφ + (Q cos ψ − P sin ψ)·sin nφ.
    let rot = |p: f64, q: f64| (p * cp + q * sp, q * cp - p * sp);
    let (c, d) = rot(p, q);
    let (dc_dj, dd_dj) = rot(dp_dj, dq_dj);
    let (dc_da, dd_da) = rot(dp_da, dq_da);
    let all = [c, d, dc_dj, dd_dj, dc_da, dd_da];
    if all.iter().all(|x| x.is_finite()) {
        Some(Component {
            order: n,
            ratio: rational(n).and_then(|(p, q)| Some((p, NonZeroU16::new(q as u16)?))),
            c,
            d,
            dc_dj,
            dd_dj,
            dc_da,
            dd_da,
        })
    } else {
        None
    }
}

fn same_order(a: &Component, b: &Component) -> bool {
    match (a.ratio, b.ratio) {
        (Some(x), Some(y)) => x == y,
        _ => a.order == b.order,
    }
}

/// `(p, q)` with the smallest `q ≤ MAX_DENOMINATOR` such that `p/q` rounds to `x` within
/// 2 ulp; `None` if there is none.
fn rational(x: f64) -> Option<(u64, u64)> {
    for q in 1..=MAX_DENOMINATOR {
        let pf = libm::round(x * q as f64);
        if !(1.0..=9.0e15).contains(&pf) {
            continue;
        }
        if libm::fabs(pf / q as f64 - x) <= 2.0 * f64::EPSILON * x {
            return Some((pf as u64, q));
        }
    }
    None
}

const fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        let t = a % b;
        a = b;
        b = t;
    }
    a
}

/// With orders `n_k = m_k/Q` (`Q` the lcm of the denominators), the common period is
/// `2π·Q/G`, `G = gcd(m_k)`, and it holds `max(m_k)/G` cycles of the fastest order.
fn horizon(components: &[Component]) -> Horizon {
    match components.len() {
        0 => return Horizon::Constant,
        1 => return Horizon::ClosedForm,
        _ => {}
    }
    let mut q_all: u64 = 1;
    for c in components {
        let Some((_, q)) = c.ratio else {
            return Horizon::Unbounded;
        };
        let q = u64::from(q.get());
        match (q_all / gcd(q_all, q)).checked_mul(q) {
            Some(l) => q_all = l,
            None => return Horizon::Unbounded,
        }
    }
    let (mut g, mut m_max) = (0u64, 0u64);
    for c in components {
        let Some((p, q)) = c.ratio else {
            return Horizon::Unbounded;
        };
        let q = u64::from(q.get());
        let Some(m) = p.checked_mul(q_all / q) else {
            return Horizon::Unbounded;
        };
        g = gcd(g, m);
        m_max = m_max.max(m);
    }
    if g == 0 {
        return Horizon::Unbounded;
    }
    match (m_max / g).checked_mul(SAMPLES_PER_CYCLE) {
        Some(n) if n <= MAX_SAMPLES => Horizon::Period {
            radians: 2.0 * PI * q_all as f64 / g as f64,
            samples: n as u32,
        },
        _ => Horizon::Unbounded,
    }
}

/// The least value of the reduced inertia `J(φ) = j + Σ amplitude·cos(order·φ + phase)` of
/// `harmonics` and an angle where J(φ) takes it, `(φ, least)` with φ in `[0, period)`; a least
/// value within the rounding of the sum, `4·ε·(j + Σ|amplitude|)`, is returned as 0 (J(φ)
/// reaches 0 there as far as f64 can tell). J(φ) is sampled [`SAMPLES_PER_CYCLE`] times a cycle
/// of the fastest order over the orders' common period, and every sampled local minimum that
/// can hide the least value (within `J''max·h²/8` of the least sample, `h` the spacing and
/// `J''max = Σ|amplitude|·order²`) is refined by golden section. Without harmonics `(0, j)`.
/// `None` where the orders have no common period (each a rational with denominator ≤
/// [`MAX_DENOMINATOR`]) or it holds more than `MAX_SAMPLES/SAMPLES_PER_CYCLE` cycles of the
/// fastest order. [`DriveModel::with_inertia_harmonics`] takes a J(φ) whose least value is
/// positive.
#[inline(never)]
pub fn least_inertia(j: f64, harmonics: &[InertiaHarmonic]) -> Option<(f64, f64)> {
    let at = |phi: f64| inertia_at(j, harmonics, phi);
    let there = harmonics.iter().filter(|h| h.amplitude() != 0.0);
    if there.clone().next().is_none() {
        return Some((0.0, j));
    }
    let (radians, cycles) = common_period(there.clone().map(InertiaHarmonic::order))?;
    let n = cycles * SAMPLES_PER_CYCLE;
    let h = radians / n as f64;
    let (mut curvature, mut swing) = (0.0, 0.0);
    for k in there {
        let a = libm::fabs(k.amplitude());
        curvature += a * k.order() * k.order();
        swing += a;
    }
    let slack = curvature * h * h / 8.0;
    let mut least = (0.0, at(0.0));
    for i in 1..n {
        let phi = i as f64 * h;
        let v = at(phi);
        if v < least.1 {
            least = (phi, v);
        }
    }
    let bound = least.1 + slack;
    let mut best = least;
    let (mut before, mut here) = (at(-h), at(0.0));
    for i in 0..n {
        let phi = i as f64 * h;
        let after = at(phi + h);
        if here <= before && here <= after && here <= bound {
            let (x, v) = golden(at, phi - h, phi + h, -1.0);
            if v < best.1 {
                best = (x, v);
            }
        }
        before = here;
        here = after;
    }
    let phi = libm::fmod(best.0, radians);
    let phi = if phi < 0.0 { phi + radians } else { phi };
    let least = if best.1 <= 4.0 * f64::EPSILON * (j + swing) {
        best.1.min(0.0)
    } else {
        best.1
    };
    Some((phi, least))
}

/// `J(φ) = j + Σ amplitude·cos(order·φ + phase)` (out of line: [`least_inertia`] calls it from
/// its scans and its refinement, and firmware that builds a drive model links it).
#[inline(never)]
fn inertia_at(j: f64, harmonics: &[InertiaHarmonic], phi: f64) -> f64 {
    harmonics.iter().fold(j, |sum, h| {
        sum + h.amplitude() * libm::cos(h.order() * phi + h.phase())
    })
}

/// The common period of `orders` (each a rational with denominator ≤ [`MAX_DENOMINATOR`]) and
/// how many cycles of the fastest one it holds; `None` without one, or when it holds more than
/// `MAX_SAMPLES/SAMPLES_PER_CYCLE` cycles, or with no orders at all.
fn common_period(orders: impl Iterator<Item = f64> + Clone) -> Option<(f64, u64)> {
    let Multiples { q_all, g, m_max } = multiples(orders)?;
    if m_max / g > MAX_SAMPLES / SAMPLES_PER_CYCLE {
        return None;
    }
    Some((2.0 * PI * q_all as f64 / g as f64, m_max / g))
}

/// Orders `n_k = m_k/Q` as whole multiples of `1/Q` (see [`horizon`]).
struct Multiples {
    /// `Q`, the lcm of the orders' denominators: the smallest whole number of revolutions
    /// that holds a whole number of cycles of every order.
    q_all: u64,
    /// `G = gcd(m_k)`: the common period is `Q/G` revolutions.
    g: u64,
    /// `max(m_k)`.
    m_max: u64,
}

/// `orders` as [`Multiples`]; `None` with no orders at all, when one is not a rational with
/// denominator ≤ [`MAX_DENOMINATOR`], or when `Q` or an `m_k` overflows.
fn multiples(orders: impl Iterator<Item = f64> + Clone) -> Option<Multiples> {
    let mut q_all: u64 = 1;
    let mut any = false;
    for o in orders.clone() {
        let (_, q) = rational(o)?;
        q_all = (q_all / gcd(q_all, q)).checked_mul(q)?;
        any = true;
    }
    if !any {
        return None;
    }
    let (mut g, mut m_max) = (0u64, 0u64);
    for o in orders {
        let (p, q) = rational(o)?;
        let m = p.checked_mul(q_all / q)?;
        g = gcd(g, m);
        m_max = m_max.max(m);
    }
    (g != 0).then_some(Multiples { q_all, g, m_max })
}

/// The load's period in whole revolutions: the smallest whole number of revolutions that holds
/// a whole number of cycles of every one of `orders` (cycles per revolution), the lcm of their
/// denominators. That is the δ window a monitor needs
/// ([`WindowLength::Revolutions`](crate::irregularity::WindowLength::Revolutions)): δ is
/// defined over the whole load period, and a window of one cycle of the lowest order alone
/// reads it low (orders 1/3 and 1/2 repeat every 6 revolutions, not 3). The orders are
/// recognised as the prediction recognises them (rationals with denominator ≤
/// [`MAX_DENOMINATOR`]); an order 0 (a constant) holds any window, and `1` is returned
/// without any other. `None` when the orders have no common period (1 and √2) or it
/// overflows `u64`. The result may exceed
/// [`MAX_WINDOW_REVS`](crate::irregularity::MAX_WINDOW_REVS), the longest window the monitor
/// takes.
pub fn period_revolutions(orders: &[f64]) -> Option<u64> {
    whole_revolutions(orders.iter().copied())
}

/// [`period_revolutions`] of an iterator.
fn whole_revolutions(orders: impl Iterator<Item = f64> + Clone) -> Option<u64> {
    let oscillating = orders.map(libm::fabs).filter(|o| *o != 0.0);
    if oscillating.clone().next().is_none() {
        return Some(1);
    }
    multiples(oscillating).map(|m| m.q_all)
}
