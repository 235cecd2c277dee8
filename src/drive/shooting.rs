//! The periodic steady state for a motor characteristic that is not a parabola (the Kloss
//! curve itself), by shooting over one period (seed 000, eq. 1).
//!
//! ## Derivation
//! Eq. 1, `J(φ)·ω·dω/dφ + ½·ω²·dJ/dφ = M_d(ω) − M_c(φ)`, has on its left `½·d(J·ω²)/dφ`
//! (`d(J·ω²)/dφ = ω²·dJ/dφ + 2·J·ω·dω/dφ`), so in `w = J(φ)·ω²` it reads exactly
//! `dw/dφ = 2·(M_d(√(w/J(φ))) − M_c(φ))`: one first-order equation, periodic in φ over the
//! common period `T` of the load and inertia orders, for any characteristic `M_d`.
//!
//! It is integrated in the deviation `y = w − J(φ)·ω̄²` from the constant-speed reference
//! `ω̄`, the working-branch speed at which the motor carries the mean load (`M_d(ω̄) = M1`;
//! for the Kloss curve `σ̄ = σ_m·M1/(M_m + √((M_m − M1)(M_m + M1)))`, no root exists for
//! `|M1| ≥ M_m`, and then no steady state does either, as the mean of `M_d` over the period
//! must equal `M1` and `M_d ≤ M_m`):
//!
//! `dy/dφ = 2·(M_d(ω) − M_d(ω̄)) + 2·(M_d(ω̄) − M1) − 2·M̃_c(φ) − J'(φ)·ω̄²`,
//! `ω² − ω̄² = y/J`, `ω − ω̄ = (y/J)/(ω + ω̄)`,
//!
//! with `M̃_c` the load's oscillating part and `M_d(ω) − M_d(ω̄)` formed from `ω − ω̄` without
//! cancellation (for the Kloss curve `2·M_m·σ_m·(σ − σ̄)·(σ_m² − σ·σ̄)/((σ² + σ_m²)(σ̄² + σ_m²))`).
//! Every term is of the size of the swing, so the swing keeps its relative precision however
//! small it is, and `δ = 2·(s_max − s_min)/(ω_max + ω_min)²` with `s = ω² − ω̄²` as on the
//! closed-form path.
//!
//! ## Method
//! The period map `y(0) ↦ y(T)` is evaluated by Butcher's sixth-order, seven-stage explicit
//! Runge–Kutta method (rational coefficients, nodes 0, 1/3, 2/3, 1/3, 1/2, 1/2, 1) on `N`
//! equal steps, `N = 128` per cycle of the fastest order, raised so that `h·λ ≤ 1/4` for the
//! largest rate `λ = |∂F/∂y| = |M_d'(ω)|/(J·ω)` the motor can have down to half the reference
//! speed (sixth order: a step 1/128 of a cycle leaves a global error near 1e-13 of the swing,
//! unit test `shooting_step_halving`), at most [`MAX_STEPS`]. Along with `y` it integrates
//! `L = ∫∂F/∂y dφ`, the logarithm of the map's derivative `μ = e^L` (the variational equation
//! of a scalar equation). Newton's method on `y(T) − y(0)`, with the step
//! `(y(T) − y(0))/(1 − μ)` and `1 − μ = −expm1(L)` (exact also for a weakly damped drive),
//! starts from the tangent parabola's solution; where `μ ≥ 1` (the trajectory spends long
//! below the breakdown speed) it takes the map's own step `y(T) − y(0)`, which moves towards
//! an attracting periodic solution, as a scalar periodic equation's map is increasing. A step
//! whose trajectory reaches `ω² ≤ 0` is halved.
//!
//! On the working branch `M_d' < 0`, so `L < 0`: the map contracts, its fixed point is unique
//! and attracting, and the simulation converges to it. Where Newton stalls, does not converge
//! or converges to a repelling fixed point (`L ≥ 0`: no simulation settles on it), the highest
//! fixed point is approached from above instead, from a start past the Kloss curve's
//! generating breakdown point: the map is increasing, so its own step from above a fixed point
//! stays above it; Newton steps are taken where they are no lower than that, and bisection once
//! a start below the fixed point brackets it. A trajectory that stalls from the map's own step
//! means that no periodic solution exists: a stall (the unit test
//! `stall_boundary_agrees_with_time_integration` checks the boundary against a time
//! integration). No convergence there within 400 steps, or a repelling limit, is refused
//! ([`Failure::NoAttractingState`]), never reported as a δ.
//!
//! ## Extrema
//! The converged period is integrated once more; the node values of `s = y/J` are scanned and
//! every node that is a local extremum within the scan's resolution of the best (8 each way at
//! most) is refined by golden section on `s(φ)`, each evaluation a partial Runge–Kutta step
//! from the neighbouring node (so the refined value carries the integration's own accuracy).
//!
//! ## Cost
//! No allocation, a few hundred bytes of stack. One solution: about 4 to 8 period maps (each
//! `7·N` evaluations of the characteristic and the load), one scan and up to 16 refinements of
//! 64 partial steps. It is design-time code; the monitor's per-edge paths never run it.

use super::load::Harmonic;
use super::motor::{Kloss, Parabola};
use super::varying::InertiaHarmonic;

/// Runge–Kutta steps per cycle of the fastest order.
pub(super) const STEPS_PER_CYCLE: u64 = 128;
/// Largest number of steps over one period.
pub const MAX_STEPS: u64 = 1 << 18;
/// Largest `h·λ` of a step (`λ` the rate of the linearised equation).
const MAX_STEP_RATE: f64 = 0.25;
/// Newton (or map) iterations at most.
const MAX_ITERATIONS: u32 = 60;
/// Steps of the descent from above at most (each one or two period maps).
const MAX_DESCENT: u32 = 400;
/// Halvings of a step whose trajectory stalls.
const MAX_HALVINGS: u32 = 60;
/// Extremum candidates refined per direction, at most.
const MAX_CANDIDATES: usize = 8;

/// Butcher's sixth-order method: nodes, stage coefficients (lower triangle) and weights (the
/// host's integration of a long load period steps with it too: [`rk6_step`], `RK6_C`).
pub const C: [f64; 7] = [0.0, 1.0 / 3.0, 2.0 / 3.0, 1.0 / 3.0, 0.5, 0.5, 1.0];
/// Stage coefficients of [`C`]'s method.
const A: [[f64; 6]; 7] = [
    [0.0; 6],
    [1.0 / 3.0, 0.0, 0.0, 0.0, 0.0, 0.0],
    [0.0, 2.0 / 3.0, 0.0, 0.0, 0.0, 0.0],
    [1.0 / 12.0, 1.0 / 3.0, -1.0 / 12.0, 0.0, 0.0, 0.0],
    [-1.0 / 16.0, 9.0 / 8.0, -3.0 / 16.0, -3.0 / 8.0, 0.0, 0.0],
    [0.0, 9.0 / 8.0, -3.0 / 8.0, -3.0 / 4.0, 0.5, 0.0],
    [
        9.0 / 44.0,
        -9.0 / 11.0,
        63.0 / 44.0,
        18.0 / 11.0,
        0.0,
        -16.0 / 11.0,
    ],
];
/// Weights of [`C`]'s method.
const B: [f64; 7] = [
    11.0 / 120.0,
    0.0,
    27.0 / 40.0,
    27.0 / 40.0,
    -4.0 / 15.0,
    -4.0 / 15.0,
    11.0 / 120.0,
];

/// One step of length `h` of Butcher's sixth-order method from `y`: `stage(i, y)` gives the
/// slope at stage `i` (at `C[i]` of the step, [`RK6_C`](crate::drive::RK6_C)) and state `y`,
/// with its derivative in `y`. Returns `y` after the step and the step's increment of
/// `∫∂F/∂y`; the first error `stage` gives ends the step.
pub fn rk6_step<E>(
    y: f64,
    h: f64,
    mut stage: impl FnMut(usize, f64) -> Result<(f64, f64), E>,
) -> Result<(f64, f64), E> {
    let mut k = [0.0f64; 7];
    let mut l = [0.0f64; 7];
    for i in 0..7 {
        let mut acc = 0.0;
        for j in 0..i {
            acc += A[i][j] * k[j];
        }
        let (f, df) = stage(i, y + h * acc)?;
        k[i] = f;
        l[i] = df;
    }
    let (mut dy, mut dl) = (0.0, 0.0);
    for i in 0..7 {
        dy += B[i] * k[i];
        dl += B[i] * l[i];
    }
    Ok((y + h * dy, h * dl))
}

/// `J(φ) = j0 + Σ a_k·cos(n_k·φ + ψ_k)` and its derivative `J'(φ)` at `phi`, as the
/// shooting's eq. 1 in `w = J·ω²` takes them (its term `−J'(φ)·ω̄²`); the host's integration
/// of a period too long for the shooting evaluates the same. Design-time code.
pub fn inertia_and_slope(j0: f64, harmonics: &[InertiaHarmonic], phi: f64) -> (f64, f64) {
    let (mut j, mut dj) = (j0, 0.0);
    for h in harmonics {
        let t = h.order() * phi + h.phase();
        j += h.amplitude() * libm::cos(t);
        dj -= h.amplitude() * h.order() * libm::sin(t);
    }
    (j, dj)
}

/// The motor characteristic the shooting integrates.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) enum Characteristic {
    /// The Kloss curve itself.
    Kloss(Kloss),
    /// A parabola (for the tests that check the shooting against the closed form).
    Parabola(Parabola),
}

impl Characteristic {
    /// `M_d(ω) − M_d(ω̄)` from `ω`, `ω̄` and `d = ω − ω̄`, and `dM_d/dω` at `ω`.
    fn change(&self, base: f64, omega: f64, d: f64) -> (f64, f64) {
        match self {
            Characteristic::Parabola(p) => {
                let a = -p.a();
                (-a * d * (omega + base), -2.0 * a * omega)
            }
            Characteristic::Kloss(k) => {
                let ws = k.synchronous_speed();
                let (sm, mm) = (k.breakdown_slip(), k.breakdown_torque());
                let s = (ws - omega) / ws;
                let sb = (ws - base) / ws;
                let ds = -d / ws;
                let q = s * s + sm * sm;
                let qb = sb * sb + sm * sm;
                let change = 2.0 * mm * sm * ds * ((sm * sm - s * sb) / q / qb);
                let slope = -2.0 * mm * sm * ((sm - s) * (sm + s) / q / q) / ws;
                (change, slope)
            }
        }
    }

    /// The working-branch speed at which the motor gives `m`, if any.
    fn speed_for(&self, m: f64) -> Option<f64> {
        match self {
            Characteristic::Parabola(p) => {
                let u = (p.b() - m) / -p.a();
                (u > 0.0 && u.is_finite()).then(|| libm::sqrt(u))
            }
            Characteristic::Kloss(k) => {
                let mm = k.breakdown_torque();
                // Also refuses a NaN `m`.
                if libm::fabs(m) >= mm || m.is_nan() {
                    return None;
                }
                // σ̄ = σm·(Mm − √(Mm² − M1²))/M1, as σm·M1/(Mm + √(…)): no cancellation.
                let root = libm::sqrt((mm - m) * (mm + m));
                let sb = k.breakdown_slip() * (m / (mm + root));
                let w = k.synchronous_speed() - k.synchronous_speed() * sb;
                (w > 0.0 && w.is_finite()).then_some(w)
            }
        }
    }

    fn torque(&self, omega: f64) -> f64 {
        match self {
            Characteristic::Parabola(p) => p.torque(omega),
            Characteristic::Kloss(k) => k.torque(omega),
        }
    }

    /// An upper bound of `|dM_d/dω|/ω` for `ω ≥ low`.
    fn rate_bound(&self, low: f64) -> f64 {
        match self {
            Characteristic::Parabola(p) => -2.0 * p.a(),
            // |dM/dσ| is largest at σ = 0: 2·M_m/σ_m.
            Characteristic::Kloss(k) => {
                2.0 * k.breakdown_torque() / k.breakdown_slip() / k.synchronous_speed() / low
            }
        }
    }

    /// A start above every periodic solution the drive could settle on from below: past the
    /// Kloss curve's generating breakdown point, twice the parabola's no-load speed.
    fn top_speed(&self) -> f64 {
        match self {
            Characteristic::Parabola(p) => 2.0 * p.no_load_speed(),
            Characteristic::Kloss(k) => k.synchronous_speed() * (1.0 + k.breakdown_slip()),
        }
    }
}

/// Why the shooting gave no steady state.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Failure {
    /// `|M1| ≥ M_m` (or the parabola's `B − M1 ≤ 0`): no speed carries the mean load.
    MeanLoad,
    /// The speed falls to zero within a period from every start tried: a stall.
    Stalls,
    /// The period needs more than [`MAX_STEPS`] steps (a drive too stiff for its inertia).
    Steps,
    /// No attracting periodic solution was found (no convergence, or a repelling one).
    NoAttractingState,
}

/// The trajectory reached `ω² ≤ 0` (or overflowed).
#[derive(Debug, Clone, Copy)]
struct Stalled;

/// The drive as the shooting sees it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Shooter<'a> {
    curve: Characteristic,
    j0: f64,
    inertia: &'a [InertiaHarmonic],
    load: &'a [Harmonic],
    /// `ω̄`, rad/s, and `ω̄²`.
    omega_ref: f64,
    u_ref: f64,
    /// `M_d(ω̄) − M1`, N·m (rounding only).
    c0: f64,
    period: f64,
    steps: u32,
}

/// The converged periodic solution.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub(super) struct Shot {
    /// `y(0)` of the periodic solution.
    pub y0: f64,
    /// `ω̄`, rad/s, and `M_d(ω̄) − M1`, N·m.
    pub omega_ref: f64,
    pub c0: f64,
    pub s_max: f64,
    pub s_min: f64,
    pub phi_max: f64,
    pub phi_min: f64,
    /// Mean of `s` over the period.
    pub s_mean: f64,
}

impl Shot {
    /// `ω̄²`, s⁻²: `ω² = centre + s`.
    pub(super) fn centre(&self) -> f64 {
        self.omega_ref * self.omega_ref
    }
}

/// Nodes whose neighbourhoods the golden section refines, with `y` at the node before.
#[derive(Debug, Clone, Copy, Default)]
struct Candidates {
    node: [u32; MAX_CANDIDATES],
    y_prev: [f64; MAX_CANDIDATES],
    y_here: [f64; MAX_CANDIDATES],
    key: [f64; MAX_CANDIDATES],
    len: usize,
}

impl Candidates {
    fn offer(&mut self, node: u32, y_prev: f64, y_here: f64, key: f64) {
        let slot = if self.len < MAX_CANDIDATES {
            self.len += 1;
            self.len - 1
        } else {
            let mut worst = 0;
            for k in 1..MAX_CANDIDATES {
                if self.key[k] < self.key[worst] {
                    worst = k;
                }
            }
            if key <= self.key[worst] {
                return;
            }
            worst
        };
        self.node[slot] = node;
        self.y_prev[slot] = y_prev;
        self.y_here[slot] = y_here;
        self.key[slot] = key;
    }
}

impl<'a> Shooter<'a> {
    /// The shooting setup over `period` (holding `cycles` cycles of the fastest order).
    pub(super) fn new(
        curve: Characteristic,
        j0: f64,
        inertia: &'a [InertiaHarmonic],
        load: &'a [Harmonic],
        mean_load: f64,
        period: f64,
        cycles: u64,
    ) -> Result<Self, Failure> {
        let omega_ref = curve.speed_for(mean_load).ok_or(Failure::MeanLoad)?;
        // The least J(φ): `j0 − Σ|amplitude|` bounds it from below where that is positive;
        // else (a crank-slider's series) it is searched over the period.
        let swing: f64 = inertia.iter().map(|h| libm::fabs(h.amplitude())).sum();
        let j_min = if swing < j0 {
            j0 - swing
        } else {
            super::model::least_inertia(j0, inertia).map_or(0.0, |(_, least)| least)
        };
        let rate = curve.rate_bound(0.5 * omega_ref) / j_min;
        let by_rate = libm::ceil(period * rate / MAX_STEP_RATE);
        let by_cycles = cycles.saturating_mul(STEPS_PER_CYCLE) as f64;
        let steps = by_rate.max(by_cycles).max(16.0);
        if !(j_min > 0.0 && steps.is_finite() && steps <= MAX_STEPS as f64) {
            return Err(Failure::Steps);
        }
        Ok(Self {
            curve,
            j0,
            inertia,
            load,
            omega_ref,
            u_ref: omega_ref * omega_ref,
            c0: curve.torque(omega_ref) - mean_load,
            period,
            steps: steps as u32,
        })
    }

    /// `ω̄`, rad/s.
    pub(super) fn omega_ref(&self) -> f64 {
        self.omega_ref
    }

    /// `J(φ)` and `J'(φ)`.
    fn inertia_at(&self, phi: f64) -> (f64, f64) {
        inertia_and_slope(self.j0, self.inertia, phi)
    }

    /// `s = ω² − ω̄²` from `y` at `phi`.
    fn swing(&self, phi: f64, y: f64) -> f64 {
        y / self.inertia_at(phi).0
    }

    /// `dy/dφ` and `∂(dy/dφ)/∂y`.
    fn rhs(&self, phi: f64, y: f64) -> Result<(f64, f64), Stalled> {
        let (j, dj) = self.inertia_at(phi);
        let s = y / j;
        let u = self.u_ref + s;
        if !(u > 0.0 && u.is_finite()) {
            return Err(Stalled);
        }
        let omega = libm::sqrt(u);
        let (dm, slope) = self
            .curve
            .change(self.omega_ref, omega, s / (omega + self.omega_ref));
        let mc: f64 = self
            .load
            .iter()
            .filter(|h| h.order() > 0.0)
            .map(|h| h.torque(phi))
            .sum();
        let f = 2.0 * ((dm + self.c0) - mc) - dj * self.u_ref;
        let df = slope / (j * omega);
        if f.is_finite() && df.is_finite() {
            Ok((f, df))
        } else {
            Err(Stalled)
        }
    }

    /// One Runge–Kutta step of length `h` from `(phi, y)`: `y` after it and the increment of
    /// `L = ∫∂F/∂y`.
    fn step(&self, phi: f64, y: f64, h: f64) -> Result<(f64, f64), Stalled> {
        rk6_step(y, h, |i, y| self.rhs(phi + C[i] * h, y))
    }

    fn node(&self, j: u32) -> f64 {
        self.period * (f64::from(j) / f64::from(self.steps))
    }

    /// The period map: `y(T)`, `L` over the period and the largest `|y|` on the nodes.
    fn map(&self, y0: f64) -> Result<(f64, f64, f64), Stalled> {
        let (mut y, mut l, mut big) = (y0, 0.0, libm::fabs(y0));
        for j in 0..self.steps {
            let phi = self.node(j);
            let (ny, dl) = self.step(phi, y, self.node(j + 1) - phi)?;
            y = ny;
            l += dl;
            big = big.max(libm::fabs(y));
        }
        if y.is_finite() && l.is_finite() {
            Ok((y, l, big))
        } else {
            Err(Stalled)
        }
    }

    /// `y(0)` of the attracting periodic solution, from `guess`, and `ln μ` there: Newton from
    /// `guess`; where that fails, the descent from above ([`Self::descend`]).
    fn fixed_point(&self, guess: f64) -> Result<(f64, f64), Failure> {
        match self.newton(guess) {
            Some(found) => Ok(found),
            None => self.descend(),
        }
    }

    /// The map's residual `|y(T) − y(0)|` at which a start counts as periodic: the rounding
    /// floor of a period's integration, relative to the largest `|y|` on it. The remaining
    /// error of `y(0)` moves the swing by about the residual (by `(1 − μ)·Δ`), even where a
    /// weak damping makes the Newton step `Δ` itself larger.
    fn tolerance(&self) -> f64 {
        (8.0 * f64::EPSILON * libm::sqrt(f64::from(self.steps))).max(1e-13)
    }

    /// Newton's method from `guess` (the map's own step where `μ ≥ 1`, a step halved while its
    /// trajectory stalls); `None` if it stalls at the start, does not converge, or converges
    /// to a repelling periodic solution.
    fn newton(&self, guess: f64) -> Option<(f64, f64)> {
        let mut y = guess;
        let (mut yt, mut l, mut big) = self.map(y).ok()?;
        let tol = self.tolerance();
        for _ in 0..MAX_ITERATIONS {
            let g = yt - y;
            let mut delta = if l < 0.0 { g / -libm::expm1(l) } else { g };
            if !delta.is_finite() {
                return None;
            }
            if libm::fabs(g) <= tol * big || delta == 0.0 {
                return (l < 0.0).then_some((y + delta, l));
            }
            let mut next = None;
            for _ in 0..MAX_HALVINGS {
                if let Ok(n) = self.map(y + delta) {
                    next = Some(n);
                    break;
                }
                delta *= 0.5;
            }
            y += delta;
            (yt, l, big) = next?;
        }
        None
    }

    /// The highest periodic solution, approached from above: from a start above synchronous
    /// speed (the Kloss curve's generating breakdown point), where the map's residual
    /// `g = y(T) − y(0)` is negative. The map is increasing (solutions of a scalar equation do
    /// not cross), so from any `y` above the highest fixed point `y*` the map's own step
    /// `P(y)` stays above it; a Newton step is taken where it is no lower than that, and once
    /// a trial start has `g > 0` (below `y*`) the two bracket `y*` and the steps stay inside
    /// the bracket (bisection where Newton leaves it). A trajectory that stalls from `P(y)`,
    /// which lies above every periodic solution, means there is none: a stall.
    fn descend(&self) -> Result<(f64, f64), Failure> {
        let (j_at_0, _) = self.inertia_at(0.0);
        let top = self.curve.top_speed();
        let mut hi = j_at_0 * ((top - self.omega_ref) * (top + self.omega_ref));
        let (mut pt, mut l, mut big) = self.map(hi).map_err(|_| Failure::Stalls)?;
        if pt >= hi {
            // A periodic solution at or above the top start: not a drive this model serves.
            return Err(Failure::NoAttractingState);
        }
        let tol = self.tolerance();
        let mut lo: Option<f64> = None;
        for _ in 0..MAX_DESCENT {
            let g = pt - hi;
            let newton = if l < 0.0 {
                hi + g / -libm::expm1(l)
            } else {
                pt
            };
            if libm::fabs(g) <= tol * big || lo.is_some_and(|lo| hi - lo <= tol * big) {
                let inside = lo.map_or(newton <= hi, |lo| (lo..=hi).contains(&newton));
                return if l < 0.0 && newton.is_finite() {
                    Ok((if inside { newton } else { hi }, l))
                } else {
                    Err(Failure::NoAttractingState)
                };
            }
            let trial = match lo {
                Some(lo) if !(newton > lo && newton < hi) => lo + (hi - lo) / 2.0,
                Some(_) => newton,
                None if newton >= pt && newton.is_finite() => newton,
                None => pt,
            };
            match self.map(trial) {
                Ok((t, _, _)) if t - trial > 0.0 => lo = Some(trial),
                Ok((t, lt, bt)) => {
                    (hi, pt, l, big) = (trial, t, lt, bt);
                    continue;
                }
                Err(Stalled) if trial != pt && lo.is_none() => {
                    // Newton overshot into the stall region: the map's own step instead.
                    let (t, lt, bt) = self.map(pt).map_err(|_| Failure::Stalls)?;
                    (hi, pt, l, big) = (pt, t, lt, bt);
                    continue;
                }
                Err(Stalled) if lo.is_none() => return Err(Failure::Stalls),
                Err(Stalled) => return Err(Failure::NoAttractingState),
            }
        }
        Err(Failure::NoAttractingState)
    }

    /// The periodic solution from `guess` (a `y(0)`), with its extrema.
    pub(super) fn solve(&self, guess: f64) -> Result<Shot, Failure> {
        let (y0, _) = self.fixed_point(guess)?;
        self.scan(y0).map_err(|_| Failure::NoAttractingState)
    }

    /// `s` at `phi` in `[node(j), node(j + 1)]` from `y` at node `j`.
    fn swing_within(&self, j: u32, y: f64, phi: f64) -> f64 {
        let p = self.node(j);
        match self.step(p, y, phi - p) {
            Ok((y, _)) => self.swing(phi, y),
            Err(Stalled) => f64::NAN,
        }
    }

    /// The converged period once more: node scan, golden-section refinement, mean of `s`.
    fn scan(&self, y0: f64) -> Result<Shot, Stalled> {
        let n = self.steps;
        // Nodes 0..=n+1 (node n is node 0 again): every node 1..=n has both neighbours.
        let (mut y_prev, mut y_cur) = (f64::NAN, y0);
        let (mut s_prev, mut s_cur) = (f64::NAN, self.swing(0.0, y0));
        let (mut best_max, mut best_min) = (f64::NEG_INFINITY, f64::INFINITY);
        let (mut j_max, mut j_min) = (0u32, 0u32);
        let (mut curvature, mut size, mut sum) = (0.0f64, 0.0f64, 0.0f64);
        let (mut maxima, mut minima) = (Candidates::default(), Candidates::default());
        for j in 0..=n {
            let phi = self.node(j);
            let (y_next, _) = self.step(phi, y_cur, self.node(j + 1) - phi)?;
            let s_next = self.swing(self.node(j + 1), y_next);
            if j >= 1 {
                if s_cur > best_max {
                    best_max = s_cur;
                    j_max = j;
                }
                if s_cur < best_min {
                    best_min = s_cur;
                    j_min = j;
                }
                sum += s_cur;
                curvature = curvature.max(libm::fabs(s_next - 2.0 * s_cur + s_prev));
                size = size.max(libm::fabs(s_cur));
                if s_cur >= s_prev && s_cur >= s_next {
                    maxima.offer(j, y_prev, y_cur, s_cur);
                }
                if s_cur <= s_prev && s_cur <= s_next {
                    minima.offer(j, y_prev, y_cur, -s_cur);
                }
            }
            (y_prev, y_cur) = (y_cur, y_next);
            (s_prev, s_cur) = (s_cur, s_next);
        }
        let margin = curvature + 8.0 * f64::EPSILON * size;
        let wrap = |phi: f64| {
            if phi >= self.period {
                phi - self.period
            } else {
                phi
            }
        };
        let mut out = Shot {
            y0,
            omega_ref: self.omega_ref,
            c0: self.c0,
            s_max: best_max,
            s_min: best_min,
            phi_max: wrap(self.node(j_max)),
            phi_min: wrap(self.node(j_min)),
            s_mean: sum / f64::from(n),
        };
        // s on [node(j − 1), node(j + 1)] from y at nodes j − 1 and j.
        let around = |c: &Candidates, k: usize, phi: f64| {
            let j = c.node[k];
            if phi <= self.node(j) {
                self.swing_within(j - 1, c.y_prev[k], phi)
            } else {
                self.swing_within(j, c.y_here[k], phi)
            }
        };
        for k in 0..maxima.len {
            if maxima.key[k] < best_max - margin {
                continue;
            }
            let j = maxima.node[k];
            let (lo, hi) = (self.node(j - 1), self.node(j + 1));
            let (phi, v) = super::model::golden(|p| around(&maxima, k, p), lo, hi, 1.0);
            if v > out.s_max {
                out.s_max = v;
                out.phi_max = wrap(phi);
            }
        }
        for k in 0..minima.len {
            if -minima.key[k] > best_min + margin {
                continue;
            }
            let j = minima.node[k];
            let (lo, hi) = (self.node(j - 1), self.node(j + 1));
            let (phi, v) = super::model::golden(|p| around(&minima, k, p), lo, hi, -1.0);
            if v < out.s_min {
                out.s_min = v;
                out.phi_min = wrap(phi);
            }
        }
        if [out.s_max, out.s_min, out.s_mean]
            .iter()
            .all(|x| x.is_finite())
        {
            Ok(out)
        } else {
            Err(Stalled)
        }
    }

    /// `s` at `phi ∈ [from.0, period]` by integrating from `from = (φ, y)` in steps of at most
    /// the solution's step; NaN if the trajectory stalls.
    pub(super) fn swing_from(&self, from: (f64, f64), phi: f64) -> (f64, f64) {
        let (mut p, mut y) = from;
        let h = self.period / f64::from(self.steps);
        let count = libm::ceil((phi - p) / h).max(0.0);
        if !(count.is_finite() && count <= f64::from(self.steps) + 1.0) {
            return (f64::NAN, f64::NAN);
        }
        let count = count as u32;
        let start = p;
        for i in 0..count {
            let q = start + (phi - start) * (f64::from(i + 1) / f64::from(count));
            match self.step(p, y, q - p) {
                Ok((ny, _)) => y = ny,
                Err(Stalled) => return (f64::NAN, f64::NAN),
            }
            p = q;
        }
        (self.swing(phi, y), y)
    }

    /// The setup of a converged solution again (the rest from the model and its horizon).
    pub(super) fn again(
        curve: Characteristic,
        shot: &Shot,
        j0: f64,
        inertia: &'a [InertiaHarmonic],
        load: &'a [Harmonic],
        period: f64,
        steps: u32,
    ) -> Self {
        Self {
            curve,
            j0,
            inertia,
            load,
            omega_ref: shot.omega_ref,
            u_ref: shot.centre(),
            c0: shot.c0,
            period,
            steps,
        }
    }

    /// Steps over the period.
    pub(super) fn steps(&self) -> u32 {
        self.steps
    }

    /// The period, rad.
    pub(super) fn period(&self) -> f64 {
        self.period
    }
}
