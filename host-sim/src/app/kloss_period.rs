//! The periodic steady state of a Kloss drive whose load orders have a common period too long
//! for the core's prediction (more than [`drive_monitor::drive::MAX_SAMPLES`] samples, 32 a
//! cycle of the fastest order: orders 0.333 and 12 repeat every 1000/3 revolutions, 4000 cycles
//! of order 12), integrated here on the host over that whole period.
//!
//! The equation and its form are the core's `Horizon::Shooting` (`src/drive/shooting.rs`):
//! eq. 1 in `w = J·ω²` is `dw/dφ = 2·(M_d(ω) − M_c(φ))` for a constant inertia, integrated in
//! the deviation `y = J·(ω² − ω̄²)` from the speed `ω̄` at which the Kloss curve carries the
//! mean load, the curve's change `M_d(ω) − M_d(ω̄)` formed without cancellation, so the swing
//! keeps its relative precision. `run` integrates the same curve in time.
//!
//! With an inertia that depends on the angle, `J(φ) = J0 + Σ a_k·cos(n_k·φ + ψ_k)` (the
//! period then common to the load and inertia orders), it is the core's shooting equation for
//! J(φ): `w = J(φ)·ω²`, `y = w − J(φ)·ω̄²`, `dy/dφ = 2·(M_d(ω) − M_d(ω̄)) + 2·(M_d(ω̄) − M1) −
//! 2·M̃_c(φ) − J'(φ)·ω̄²` and `s = y/J(φ)`, `J` and `J'` from the core's
//! [`inertia_and_slope`]; the steps are sized on the least J(φ) (as the core sizes them), the
//! settling on the damping at the largest bound `J0 + Σ|a_k|`.
//!
//! ## Method
//! Butcher's sixth-order, seven-stage Runge–Kutta method (the core's) on `N` equal steps a
//! period, [`STEPS_PER_CYCLE`] = 32 a cycle of the fastest order (the core takes 128 on its
//! shorter periods; at 32 the sixth-order error is at most about `4⁶` times its 1e-13 of the
//! swing; measured 4e-12 of δ on the 0.333/12 scene and at most 6e-11 on six random drives
//! against a DOP853 integration, `host-sim/tests/kloss_steady.rs`), raised so that `h·λ ≤ 1/4` for the largest
//! rate `λ = |dM_d/dω|/(J·ω)` down to half of `ω̄`, at most [`MAX_STEPS`]. The periodic start
//! is found as the map over a period contracts it: the drive is first settled from `ω̄` over
//! [`SETTLE_FOLDS`] e-foldings of its damping at `ω̄` ending at φ = 0 of the period (the
//! forcing is periodic; not where that would take a period or more), then the period is
//! integrated with `L = ∫∂F/∂y dφ`
//! (the map's derivative `μ = e^L`), and Newton's step `(y(T) − y(0))/(1 − μ)` repeats the
//! period until `|y(T) − y(0)|` is within the rounding floor of the largest `|y|` (the core's
//! tolerance); on a loaded drive the settling alone leaves the start within rounding and one
//! period suffices. The last period's nodes are scanned for the extrema of `s = ω² − ω̄²`,
//! and every node extremum within the scan's resolution of the best is refined by golden
//! section on partial Runge–Kutta steps from its neighbouring node, as the core does.
//!
//! ## Cost
//! About `7·(N + settling steps)` evaluations of the curve and the load per solution (one
//! period when the settling converged it), plus the refinements. Measured (release build, CPU
//! time of `drive-sim predict`): the 0.333/12 scene (`N` = 128 000, 84 292 settling steps)
//! 0.22 s with the sensitivities (five solutions), 0.53 s with the flywheel for δ ≤ 0.004; at
//! the bound (orders 1/1024 and 32: 32 768 cycles, δ 0.10) 1.3 s with the sensitivities and
//! 14 s with the flywheel for δ ≤ 0.004 (270 kg·m², where the drive is so weakly damped that
//! it does not settle within a period and Newton's method takes three periods a solution).
//! With J(φ) each stage also evaluates J and J' (one `sin` and `cos` a harmonic): the 0.333/12
//! scene with `J = 0.5 + 0.01·cos(3φ + 0.3)` 0.40 s with the sensitivities, 1.61 s with the
//! δ through 8-edge speed samples of a 60-line disc as well (the time table's ω at 2 M angles
//! through [`Cursor`] and the scans of the teeth's phase), 2.55 s with the flywheel for
//! δ ≤ 0.004 too.

use drive_monitor::drive::{
    inertia_and_slope, least_inertia, period_revolutions, Harmonic, InertiaHarmonic, Kloss, Load,
};
use std::f64::consts::TAU;

/// Runge–Kutta steps per cycle of the fastest order.
pub const STEPS_PER_CYCLE: u64 = 32;
/// The most steps over one period the host integrates: 2²⁰ (32 768 cycles of the fastest
/// order at 32 steps a cycle, 16 times the core's 2048; about 0.25 s a solution there); a
/// longer period is predicted through the parabola at the operating point instead
/// ([`crate::app::predict`]).
pub const MAX_STEPS: u64 = 1 << 20;
/// Largest `h·λ` of a step (`λ` the rate of the linearised equation).
const MAX_STEP_RATE: f64 = 0.25;
/// E-foldings of the damping at the operating point the drive settles over before the
/// period whose start is tested (e⁻⁴⁰ ≈ 4e-18).
pub const SETTLE_FOLDS: f64 = 40.0;
/// Periods integrated at most while Newton's method converges.
const MAX_MAPS: u32 = 12;
/// Halvings of a Newton step whose trajectory stalls.
const MAX_HALVINGS: u32 = 40;
/// Golden-section iterations per refined extremum (bracket 0.618⁶⁴ ≈ 4e-14 of two steps).
const GOLDEN_ITERATIONS: u32 = 64;

// Butcher's sixth-order method, as the core's shooting integrates with it.
use drive_monitor::drive::{rk6_step, RK6_C as C};

/// The common period of a load's oscillating orders.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Period {
    /// The period in revolutions, `Q/G` (orders `m_k/Q`, `G = gcd(m_k)`; 1000/3 for 0.333
    /// and 12).
    pub revolutions: f64,
    /// The smallest whole number of revolutions holding it, `Q` (the δ window a monitor
    /// needs: [`period_revolutions`]).
    pub whole_revolutions: u64,
    /// The period, rad.
    pub radians: f64,
    /// Cycles of the fastest order in it.
    pub cycles: u64,
}

/// The common period of `orders` (cycles per revolution; zeros ignored) as the core
/// recognises them (rationals with denominator ≤ [`drive_monitor::drive::MAX_DENOMINATOR`]),
/// however long; `None` without one or without an oscillating order.
pub fn common_period(orders: &[f64]) -> Option<Period> {
    let orders: Vec<f64> = orders
        .iter()
        .map(|o| o.abs())
        .filter(|o| *o > 0.0)
        .collect();
    if orders.is_empty() {
        return None;
    }
    let q = period_revolutions(&orders)?;
    let (mut g, mut m_max) = (0u64, 0u64);
    for o in &orders {
        let m = (o * q as f64).round();
        if !(1.0..9.0e15).contains(&m) {
            return None;
        }
        let m = m as u64;
        g = gcd(g, m);
        m_max = m_max.max(m);
    }
    (g != 0).then(|| Period {
        revolutions: q as f64 / g as f64,
        whole_revolutions: q,
        radians: TAU * (q as f64 / g as f64),
        cycles: m_max / g,
    })
}

fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// Why no steady state was found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Failure {
    /// `|M1| ≥ M_m`: no speed carries the mean load.
    MeanLoad,
    /// The period needs more than [`MAX_STEPS`] steps.
    Steps,
    /// The speed falls to zero from above every periodic solution: none exists, the drive
    /// stalls under the peak load (or a Newton step's trajectory kept falling to zero).
    Stalls,
    /// Newton's method did not converge within 12 periods, or to a repelling
    /// solution.
    NoConvergence,
}

/// The converged periodic steady state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Steady {
    /// ω max, rad/s.
    pub omega_max: f64,
    /// ω min, rad/s.
    pub omega_min: f64,
    /// δ = 2(ωmax − ωmin)/(ωmax + ωmin), from the difference of squares.
    pub delta: f64,
    /// √ of the mean of ω² over the period, rad/s.
    pub omega_rms: f64,
    /// Shaft angle of ω max within the period, rad.
    pub phi_max: f64,
    /// Shaft angle of ω min within the period, rad.
    pub phi_min: f64,
    /// Runge–Kutta steps a period.
    pub steps: u64,
    /// Steps of the settling before the first period.
    pub settle_steps: u64,
    /// Periods integrated (Newton's iterations), the scanned one included.
    pub periods: u32,
    /// `|y(T) − y(0)|/max|y|` of the scanned period.
    pub residual: f64,
    /// `y(0) = J(0)·(ω(0)² − ω̄²)` of the scanned period, kg·m²·s⁻² (where [`Drive::cursor`]
    /// starts).
    pub y0: f64,
}

/// A Kloss drive with a constant inertia, or with `J(φ) = J0 + Σ a_k·cos(n_k·φ + ψ_k)`.
#[derive(Debug, Clone)]
pub struct Drive {
    kloss: Kloss,
    /// The constant inertia `J0`, kg·m².
    inertia: f64,
    mean: f64,
    /// The oscillating harmonics (order > 0, amplitude ≠ 0).
    load: Vec<Harmonic>,
    /// The inertia's harmonics (amplitude ≠ 0; none: a constant inertia).
    inertia_harmonics: Vec<InertiaHarmonic>,
}

impl Drive {
    /// The drive: the Kloss curve, the total inertia (kg·m²) and the load (its order-0
    /// harmonics join the mean, as in the core).
    pub fn new(kloss: Kloss, inertia: f64, load: &Load) -> Self {
        let mut mean = load.mean();
        for h in load.harmonics().iter().filter(|h| h.order() == 0.0) {
            mean += h.amplitude() * h.phase().sin();
        }
        Self {
            kloss,
            inertia,
            mean,
            load: load
                .harmonics()
                .iter()
                .filter(|h| h.order() > 0.0 && h.amplitude() != 0.0)
                .copied()
                .collect(),
            inertia_harmonics: Vec::new(),
        }
    }

    /// The same drive with the inertia `J(φ) = J0 + Σ harmonics` (`J0` this drive's inertia;
    /// harmonics of amplitude 0 are dropped), replacing any given before. The caller checks
    /// that `J(φ) > 0` (the core's [`least_inertia`]); the steps are sized on its least value.
    pub fn with_inertia_harmonics(&self, harmonics: &[InertiaHarmonic]) -> Self {
        Self {
            inertia_harmonics: harmonics
                .iter()
                .filter(|h| h.amplitude() != 0.0)
                .copied()
                .collect(),
            ..self.clone()
        }
    }

    /// The inertia's harmonics (empty for a constant inertia).
    pub fn inertia_harmonics(&self) -> &[InertiaHarmonic] {
        &self.inertia_harmonics
    }

    /// Whether `period` is within the steps the host integrates ([`MAX_STEPS`]; `true` also
    /// where no speed carries the mean load, which [`Self::solve`] reports as such).
    pub fn fits(&self, period: &Period) -> bool {
        !matches!(Setup::new(self, period), Err(Failure::Steps))
    }

    /// A cursor over the periodic steady state `steady` (from [`Self::solve`] over `period`),
    /// for ω at ascending angles.
    pub fn cursor(&self, period: &Period, steady: &Steady) -> Result<Cursor<'_>, Failure> {
        Ok(Cursor {
            setup: Setup::new(self, period)?,
            node: 0,
            y: steady.y0,
        })
    }

    /// The same drive with another total inertia.
    pub fn with_inertia(&self, inertia: f64) -> Self {
        Self {
            inertia,
            ..self.clone()
        }
    }

    /// The same drive with every torque of the curve multiplied by `factor` (`None` if the
    /// curve leaves its range).
    pub fn scaled(&self, factor: f64) -> Option<Self> {
        let k = &self.kloss;
        let kloss = Kloss::new(
            k.synchronous_speed(),
            k.breakdown_slip(),
            k.breakdown_torque() * factor,
        )
        .ok()?;
        Some(Self {
            kloss,
            ..self.clone()
        })
    }

    /// The total inertia, kg·m² (with J(φ), its constant part `J0`).
    pub fn inertia(&self) -> f64 {
        self.inertia
    }

    /// The mean load, order-0 harmonics included, N·m.
    pub fn mean_load(&self) -> f64 {
        self.mean
    }

    /// The periodic steady state over `period`; `start`, an estimate of ω² at φ = 0 (s⁻²),
    /// is where Newton's method starts on a drive too weakly damped to settle within a period
    /// (without it, or for a settled drive: from `ω̄`).
    pub fn solve(&self, period: &Period, start: Option<f64>) -> Result<Steady, Failure> {
        Setup::new(self, period)?.solve(start)
    }
}

/// The trajectory reached `ω² ≤ 0` (or overflowed).
struct Stalled;

/// A node extremum to refine: node, `y` at the node before and at the node, `s` there.
#[derive(Debug, Clone, Copy)]
struct Candidate {
    node: u64,
    y_prev: f64,
    y_here: f64,
    s: f64,
}

/// What a scanned period saw.
#[derive(Debug, Default)]
struct Scan {
    maxima: Vec<Candidate>,
    minima: Vec<Candidate>,
    curvature: f64,
    size: f64,
    sum: f64,
}

/// The Kloss curve's constants about the operating point.
#[derive(Debug, Clone, Copy, Default)]
struct Curve {
    ws: f64,
    inv_ws: f64,
    sm: f64,
    sm2: f64,
    /// `σ̄`.
    sb: f64,
    /// `2·M_m·σ_m/(σ̄² + σ_m²)`.
    factor: f64,
    /// `−2·M_m·σ_m/ω_s`.
    slope: f64,
}

struct Setup<'a> {
    drive: &'a Drive,
    omega_ref: f64,
    u_ref: f64,
    /// `M_d(ω̄) − M1`, N·m (rounding only).
    c0: f64,
    /// The curve's constants about `ω̄`.
    curve: Curve,
    /// `1/J` (with J(φ), `1/J0`).
    inv_j: f64,
    /// The inertia depends on φ.
    varying: bool,
    /// `|dM_d/dω|/(J·ω̄)` at `ω̄`, per rad (with J(φ), at its largest bound `J0 + Σ|a_k|`).
    damping: f64,
    period: f64,
    steps: u64,
    /// The step, `period/steps`, rad.
    h: f64,
    /// `sin_cos(order·C[i]·h)` for each oscillating harmonic and stage.
    stage_turns: Vec<[(f64, f64); 7]>,
}

impl<'a> Setup<'a> {
    fn new(drive: &'a Drive, period: &Period) -> Result<Self, Failure> {
        let k = &drive.kloss;
        let (ws, sm, mm) = (
            k.synchronous_speed(),
            k.breakdown_slip(),
            k.breakdown_torque(),
        );
        let m1 = drive.mean;
        if m1.is_nan() || m1.abs() >= mm {
            return Err(Failure::MeanLoad);
        }
        let root = ((mm - m1) * (mm + m1)).sqrt();
        let omega_ref = ws - ws * (sm * (m1 / (mm + root)));
        if !(omega_ref > 0.0 && omega_ref.is_finite()) {
            return Err(Failure::MeanLoad);
        }
        let j = drive.inertia;
        // J(φ)'s bounds: its least value sizes the steps (as the core's shooting takes it), its
        // largest bound the damping the settling counts on.
        let swing: f64 = drive
            .inertia_harmonics
            .iter()
            .map(|h| h.amplitude().abs())
            .sum();
        let j_min = if swing < j {
            j - swing
        } else {
            least_inertia(j, &drive.inertia_harmonics).map_or(0.0, |(_, least)| least)
        };
        let j_max = j + swing;
        // The largest rate down to half of ω̄: |dM/dσ| is largest at σ = 0, 2·M_m/σ_m.
        let rate = 2.0 * mm / sm / ws / (0.5 * omega_ref) / j_min;
        let by_rate = (period.radians * rate / MAX_STEP_RATE).ceil();
        let by_cycles = period.cycles.saturating_mul(STEPS_PER_CYCLE) as f64;
        let steps = by_rate.max(by_cycles).max(16.0);
        if !(j > 0.0 && j_min > 0.0 && steps.is_finite() && steps <= MAX_STEPS as f64) {
            return Err(Failure::Steps);
        }
        let sb = (ws - omega_ref) / ws;
        let curve = Curve {
            ws,
            inv_ws: 1.0 / ws,
            sm,
            sm2: sm * sm,
            sb,
            factor: 2.0 * mm * sm / (sb * sb + sm * sm),
            slope: -2.0 * mm * sm / ws,
        };
        let mut s = Self {
            curve,
            inv_j: 1.0 / j,
            varying: !drive.inertia_harmonics.is_empty(),
            drive,
            omega_ref,
            u_ref: omega_ref * omega_ref,
            c0: k.torque(omega_ref) - m1,
            damping: 0.0,
            period: period.radians,
            steps: steps as u64,
            h: period.radians / steps,
            stage_turns: Vec::new(),
        };
        s.stage_turns = drive
            .load
            .iter()
            .map(|harmonic| C.map(|c| (harmonic.order() * (c * s.h)).sin_cos()))
            .collect();
        let (_, slope) = s.change(omega_ref, 0.0);
        s.damping = slope.abs() / (j_max * omega_ref);
        Ok(s)
    }

    /// `M_d(ω) − M_d(ω̄)` from `ω` and `d = ω − ω̄`, and `dM_d/dω` at `ω` (the core's form,
    /// `2·M_m·σ_m·(σ − σ̄)·(σ_m² − σ·σ̄)/((σ² + σ_m²)(σ̄² + σ_m²))`, with the constants of `ω̄`
    /// taken once).
    fn change(&self, omega: f64, d: f64) -> (f64, f64) {
        let c = &self.curve;
        let s = (c.ws - omega) * c.inv_ws;
        let ds = -d * c.inv_ws;
        let inv_q = 1.0 / (s * s + c.sm2);
        let change = c.factor * ds * ((c.sm2 - s * c.sb) * inv_q);
        let slope = c.slope * ((c.sm - s) * (c.sm + s) * inv_q * inv_q);
        (change, slope)
    }

    /// `J(φ)` and `J'(φ)` (the core's [`inertia_and_slope`]; `(J, 0)` for a constant inertia).
    fn inertia_at(&self, phi: f64) -> (f64, f64) {
        if self.varying {
            inertia_and_slope(self.drive.inertia, &self.drive.inertia_harmonics, phi)
        } else {
            (self.drive.inertia, 0.0)
        }
    }

    /// `dy/dφ` and `∂(dy/dφ)/∂y` with the load's oscillating torque `mc` and `(J, J')` at that
    /// angle: the core's shooting equation, `2·((M_d(ω) − M_d(ω̄)) + (M_d(ω̄) − M1) − M̃_c) −
    /// J'·ω̄²` in `y = w − J(φ)·ω̄²` (its last term only with J(φ)).
    fn rhs(&self, mc: f64, (j, dj): (f64, f64), y: f64) -> Result<(f64, f64), Stalled> {
        let s = if self.varying { y / j } else { y * self.inv_j };
        let u = self.u_ref + s;
        if !(u > 0.0 && u.is_finite()) {
            return Err(Stalled);
        }
        let omega = u.sqrt();
        let (dm, slope) = self.change(omega, s / (omega + self.omega_ref));
        let mut f = 2.0 * ((dm + self.c0) - mc);
        if self.varying {
            f -= dj * self.u_ref;
        }
        let df = slope / (j * omega);
        if f.is_finite() && df.is_finite() {
            Ok((f, df))
        } else {
            Err(Stalled)
        }
    }

    /// The load's oscillating torque at the seven stages of a step of length `h` from `phi`:
    /// one `sin_cos` a harmonic at `phi`, the stages by the angle-addition formulas with the
    /// sines and cosines of `order·C[i]·h` (from the table for the period's own step, which the
    /// node differences match to their rounding).
    fn load_at_stages(&self, phi: f64, h: f64) -> [f64; 7] {
        let mut mc = [0.0f64; 7];
        let tabled = (h - self.h).abs() <= 1e-9 * self.h;
        for (k, harmonic) in self.drive.load.iter().enumerate() {
            let (s0, c0) = (harmonic.order() * phi + harmonic.phase()).sin_cos();
            let a = harmonic.amplitude();
            for (i, m) in mc.iter_mut().enumerate() {
                let (si, ci) = if tabled {
                    self.stage_turns[k][i]
                } else {
                    (harmonic.order() * (C[i] * h)).sin_cos()
                };
                *m += a * (s0 * ci + c0 * si);
            }
        }
        mc
    }

    /// One step of length `h` from `(phi, y)`: `y` after it and the increment of `L`.
    fn step(&self, phi: f64, y: f64, h: f64) -> Result<(f64, f64), Stalled> {
        let mc = self.load_at_stages(phi, h);
        if self.varying {
            rk6_step(y, h, |i, y| {
                self.rhs(mc[i], self.inertia_at(phi + C[i] * h), y)
            })
        } else {
            let j = (self.drive.inertia, 0.0);
            rk6_step(y, h, |i, y| self.rhs(mc[i], j, y))
        }
    }

    /// Node `j` (`j` may exceed the step count: the next period).
    fn node(&self, j: u64) -> f64 {
        self.period * (j as f64 / self.steps as f64)
    }

    /// `s = ω² − ω̄²` from `y` at `phi`.
    fn swing(&self, phi: f64, y: f64) -> f64 {
        y / self.inertia_at(phi).0
    }

    /// `y` at φ = 0 after settling from `y = from` over the last stretch of a period, and the
    /// steps taken; none (`from` itself) where the settling would take a whole period or more
    /// (a weakly damped drive, whose period map is nearly affine: Newton's method converges in
    /// a few periods).
    fn settle(&self, from: f64) -> Result<(f64, u64), Stalled> {
        let want = (SETTLE_FOLDS / self.damping / self.h).ceil();
        if !(want.is_finite() && want < self.steps as f64) {
            return Ok((from, 0));
        }
        let count = want as u64;
        let mut y = from;
        for j in self.steps - count..self.steps {
            let phi = self.node(j);
            (y, _) = self.step(phi, y, self.node(j + 1) - phi)?;
        }
        Ok((y, count))
    }

    /// The period map from `y0`: `y(T)`, `L` and the largest `|y|` on the nodes; with `scan`,
    /// the node extrema of `s` over nodes 1..=N (node N is node 0 of the next period).
    fn map(&self, y0: f64, mut scan: Option<&mut Scan>) -> Result<(f64, f64, f64), Stalled> {
        let n = self.steps;
        let (mut y, mut l, mut big) = (y0, 0.0, y0.abs());
        let (mut y_prev, mut s_prev) = (f64::NAN, f64::NAN);
        let mut s_cur = self.swing(0.0, y0);
        let mut y_end = f64::NAN;
        // Steps 0..N make the map; step N (to node N + 1) completes the scan of node N.
        let last = if scan.is_some() { n + 1 } else { n };
        for j in 0..last {
            let phi = self.node(j);
            let (ny, dl) = self.step(phi, y, self.node(j + 1) - phi)?;
            if j < n {
                l += dl;
                big = big.max(ny.abs());
            }
            if j + 1 == n {
                y_end = ny;
            }
            if let Some(sc) = scan.as_deref_mut() {
                let s_next = self.swing(self.node(j + 1), ny);
                if j >= 1 {
                    sc.sum += s_cur;
                    sc.curvature = sc.curvature.max((s_next - 2.0 * s_cur + s_prev).abs());
                    sc.size = sc.size.max(s_cur.abs());
                    let c = Candidate {
                        node: j,
                        y_prev,
                        y_here: y,
                        s: s_cur,
                    };
                    if s_cur >= s_prev && s_cur >= s_next {
                        sc.maxima.push(c);
                    }
                    if s_cur <= s_prev && s_cur <= s_next {
                        sc.minima.push(c);
                    }
                }
                (y_prev, s_prev, s_cur) = (y, s_cur, s_next);
            }
            y = ny;
        }
        if y_end.is_finite() && l.is_finite() {
            Ok((y_end, l, big))
        } else {
            Err(Stalled)
        }
    }

    /// The map's residual at which a start counts as periodic (the core's).
    fn tolerance(&self) -> f64 {
        (8.0 * f64::EPSILON * (self.steps as f64).sqrt()).max(1e-13)
    }

    /// The periodic solution: settled from `ω̄` (from `start` on a drive too weakly damped to
    /// settle within a period), then Newton's method over whole periods. Where the drive falls
    /// to standstill from there, it starts again from above every periodic solution, past the
    /// curve's generating breakdown point (`ω_s·(1 + σ_m)`, the core's start from above):
    /// solutions of a scalar equation do not cross, so a fall from there means no periodic
    /// solution exists, a stall ([`Failure::Stalls`]).
    fn solve(&self, start: Option<f64>) -> Result<Steady, Failure> {
        let top = self.curve.ws * (1.0 + self.curve.sm);
        let y_top = self.inertia_at(0.0).0 * ((top - self.omega_ref) * (top + self.omega_ref));
        let (mut y0, settle_steps, mut from_top) = match self.settle(0.0) {
            Ok((y, n)) => (y, n, false),
            Err(Stalled) => {
                let (y, n) = self.settle(y_top).map_err(|_| Failure::Stalls)?;
                (y, n, true)
            }
        };
        if settle_steps == 0 {
            if let Some(u) = start.filter(|u| *u > 0.0 && u.is_finite()) {
                y0 = self.inertia_at(0.0).0 * (u - self.u_ref);
            }
        }
        let tol = self.tolerance();
        for periods in 1..=MAX_MAPS {
            let mut scan = Scan::default();
            let (yt, l, big) = match self.map(y0, Some(&mut scan)) {
                Ok(m) => m,
                Err(Stalled) if !from_top => {
                    (y0, from_top) = (y_top, true);
                    continue;
                }
                Err(Stalled) => return Err(Failure::Stalls),
            };
            let g = yt - y0;
            if g.abs() <= tol * big.max(f64::MIN_POSITIVE) {
                if l >= 0.0 {
                    return Err(Failure::NoConvergence);
                }
                return self
                    .extrema(
                        &scan,
                        y0,
                        settle_steps,
                        periods,
                        g.abs() / big.max(f64::MIN_POSITIVE),
                    )
                    .ok_or(Failure::Stalls);
            }
            let mut delta = if l < 0.0 { g / -l.exp_m1() } else { g };
            let mut moved = false;
            for _ in 0..MAX_HALVINGS {
                if self.map(y0 + delta, None).is_ok() {
                    moved = true;
                    break;
                }
                delta *= 0.5;
            }
            if !(moved && delta.is_finite()) {
                return Err(Failure::Stalls);
            }
            y0 += delta;
        }
        Err(Failure::NoConvergence)
    }

    /// `s` at `phi` in `[node(j), node(j + 1)]` from `y` at node `j`.
    fn swing_within(&self, j: u64, y: f64, phi: f64) -> f64 {
        let p = self.node(j);
        match self.step(p, y, phi - p) {
            Ok((y, _)) => self.swing(phi, y),
            Err(Stalled) => f64::NAN,
        }
    }

    /// The refined extrema of a converged period's scan.
    fn extrema(
        &self,
        scan: &Scan,
        y0: f64,
        settle_steps: u64,
        periods: u32,
        residual: f64,
    ) -> Option<Steady> {
        let margin = scan.curvature + 8.0 * f64::EPSILON * scan.size;
        let refine = |cands: &[Candidate], sign: f64| -> Option<(f64, f64)> {
            let best = cands
                .iter()
                .map(|c| sign * c.s)
                .fold(f64::NEG_INFINITY, f64::max);
            let mut out: Option<(f64, f64)> = None;
            for c in cands.iter().filter(|c| sign * c.s >= best - margin) {
                let (lo, mid, hi) = (
                    self.node(c.node - 1),
                    self.node(c.node),
                    self.node(c.node + 1),
                );
                let f = |p: f64| {
                    sign * if p <= mid {
                        self.swing_within(c.node - 1, c.y_prev, p)
                    } else {
                        self.swing_within(c.node, c.y_here, p)
                    }
                };
                let (phi, v) = golden(f, lo, hi);
                let (phi, v) = if sign * c.s > v {
                    (mid, sign * c.s)
                } else {
                    (phi, v)
                };
                if out.is_none_or(|(_, w)| v > w) {
                    out = Some((phi, v));
                }
            }
            out.map(|(p, v)| (p, sign * v))
        };
        let (phi_max, s_max) = refine(&scan.maxima, 1.0)?;
        let (phi_min, s_min) = refine(&scan.minima, -1.0)?;
        let (u_max, u_min) = (self.u_ref + s_max, self.u_ref + s_min);
        if !(u_min > 0.0 && u_max.is_finite()) {
            return None;
        }
        let (w_max, w_min) = (u_max.sqrt(), u_min.sqrt());
        let w = w_max + w_min;
        let wrap = |p: f64| if p >= self.period { p - self.period } else { p };
        Some(Steady {
            omega_max: w_max,
            omega_min: w_min,
            delta: 2.0 * ((s_max - s_min) / w) / w,
            omega_rms: (self.u_ref + scan.sum / self.steps as f64).sqrt(),
            phi_max: wrap(phi_max),
            phi_min: wrap(phi_min),
            steps: self.steps,
            settle_steps,
            periods,
            residual,
            y0,
        })
    }
}

/// ω of a periodic steady state at ascending angles ([`Drive::cursor`]): the period's nodes
/// integrated once from `y(0)` as the solution's last period was, each angle reached by a
/// partial Runge–Kutta step from the node before it (so it carries the integration's own
/// accuracy, as the refined extrema do). Angles past the period continue into the next one
/// (the solution repeats within its residual).
pub struct Cursor<'a> {
    setup: Setup<'a>,
    node: u64,
    y: f64,
}

impl Cursor<'_> {
    /// ω at `phi`, rad/s (`phi` at least the last one asked, from 0); `None` where the
    /// trajectory stalls.
    pub fn omega(&mut self, phi: f64) -> Option<f64> {
        let s = &self.setup;
        while s.node(self.node + 1) <= phi {
            let p = s.node(self.node);
            self.y = s.step(p, self.y, s.node(self.node + 1) - p).ok()?.0;
            self.node += 1;
        }
        let p = s.node(self.node);
        let y = if phi > p {
            s.step(p, self.y, phi - p).ok()?.0
        } else {
            self.y
        };
        let u = s.u_ref + s.swing(phi, y);
        (u > 0.0 && u.is_finite()).then(|| u.sqrt())
    }
}

/// The maximum of `f` on `[lo, hi]` by golden section: `(x, f(x))`.
fn golden(f: impl Fn(f64) -> f64, mut lo: f64, mut hi: f64) -> (f64, f64) {
    let r = (5f64.sqrt() - 1.0) / 2.0;
    let mut x1 = hi - r * (hi - lo);
    let mut x2 = lo + r * (hi - lo);
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..GOLDEN_ITERATIONS {
        if f1 >= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - r * (hi - lo);
            f1 = f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + r * (hi - lo);
            f2 = f(x2);
        }
    }
    if f1 >= f2 {
        (x1, f1)
    } else {
        (x2, f2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn common_period_of_a_third_and_twelve() {
        let p = common_period(&[0.333, 12.0]).unwrap();
        assert_eq!(p.whole_revolutions, 1000);
        assert_eq!(p.cycles, 4000);
        assert!((p.revolutions - 1000.0 / 3.0).abs() < 1e-12);
        assert!(common_period(&[1.0, 1.5000001]).is_none());
        let p = common_period(&[0.5, 0.0, 1.5]).unwrap();
        assert_eq!((p.whole_revolutions, p.cycles), (2, 3));
        assert!((p.radians - 2.0 * TAU).abs() < 1e-12);
    }
}
