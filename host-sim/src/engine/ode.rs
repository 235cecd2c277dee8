//! Explicit Runge–Kutta integrators with dense output, stepped one accepted step at a time.
//!
//! Three methods:
//! - [`Integrator::Rk4`]: classical fixed-step RK4 (4 right-hand-side evaluations per step),
//!   dense output by the cubic Hermite interpolant on (y, f) at both ends of the step
//!   (the end derivative is the next step's first stage, so it costs nothing extra).
//!   Use it for comparisons and for scenes whose step is dictated by something else.
//! - [`Integrator::Dopri5`]: adaptive Dormand–Prince 5(4), FSAL, 6 evaluations per accepted
//!   step, with Shampine's 4th-order continuous extension (no extra evaluations). The default
//!   for non-stiff scenes at moderate tolerances (rtol 1e-6 … 1e-10).
//! - [`Integrator::Dop853`]: adaptive Dormand–Prince 8(5,3), 12 evaluations per accepted step
//!   plus 3 for its 7th-order dense output. It pays at tight tolerances (rtol ≤ 1e-10) and on
//!   long smooth runs, where its steps are several times longer than DOPRI5's.
//!
//! None of them is for stiff systems (stiff supports with small masses): their step would be
//! limited by stability, not accuracy; the solver reports the number of steps, which makes that
//! visible.
//!
//! Step-size control follows Hairer, Nørsett & Wanner (*Solving ODE I*, II.4 and the codes
//! DOPRI5/DOP853): the RMS norm of the error scaled by `atol + rtol·max(|y₀|, |y₁|)`, safety 0.9,
//! a bounded growth/shrink factor and the β = 0.04 step-size stabilisation; the first step
//! comes from the usual two-evaluation estimate. A component may declare a fixed magnitude for
//! its relative tolerance ([`OdeSystem::error_reference`]): the shaft angle φ grows without
//! bound, so its error is measured against one revolution, not against the angle accumulated
//! so far, and edge-time accuracy does not degrade over a long run.
//!
//! Why not a crate: the edge locator needs, after every accepted step, the dense polynomial of
//! one component (φ) in a form it can evaluate with its derivative in a few flops, hundreds of
//! times per step, without allocation; the state dimension is known only when a scene is
//! assembled; and the right-hand side counts its evaluations per component. The steppers here
//! expose exactly that ([`DenseOutput::component`], a power-basis polynomial per component).
//! The benchmark suite compares them with a published crate on the same scene at the same
//! accuracy.

use serde::Deserialize;

use drive_monitor::error::{positive, ConfigError};

/// A system of first-order ODEs y' = f(t, y) of fixed dimension.
pub trait OdeSystem {
    /// Number of state variables.
    fn dim(&self) -> usize;
    /// Writes f(t, y) into `dy` (`y.len() == dy.len() == self.dim()`).
    fn rhs(&mut self, t: f64, y: &[f64], dy: &mut [f64]);
    /// A fixed magnitude against which the relative tolerance of component `i` is measured,
    /// instead of the component's current value (`None`: use `max(|y₀|, |y₁|)`).
    fn error_reference(&self, _i: usize) -> Option<f64> {
        None
    }
}

/// Which integrator to use, with its parameters. Deserializable from TOML, but scene files choose
/// it with `[simulation] integrator`, `rtol`, `atol` and `step` ([`crate::app::scene::SimulationSpec`]),
/// which `drive-sim run` maps onto this.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case", deny_unknown_fields)]
pub enum Integrator {
    /// Classical RK4 with a fixed step.
    Rk4 {
        /// Step, s.
        step: f64,
    },
    /// Adaptive Dormand–Prince 5(4).
    Dopri5 {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance (in the units of each state variable).
        atol: f64,
        /// Largest step, s (none: unlimited).
        #[serde(default)]
        max_step: Option<f64>,
    },
    /// Adaptive Dormand–Prince 8(5,3).
    Dop853 {
        /// Relative tolerance.
        rtol: f64,
        /// Absolute tolerance.
        atol: f64,
        /// Largest step, s (none: unlimited).
        #[serde(default)]
        max_step: Option<f64>,
    },
}

impl Integrator {
    /// Checks every parameter once.
    pub fn validate(&self) -> Result<(), ConfigError> {
        match *self {
            Integrator::Rk4 { step } => positive("integrator.step", step).map(|_| ()),
            Integrator::Dopri5 {
                rtol,
                atol,
                max_step,
            }
            | Integrator::Dop853 {
                rtol,
                atol,
                max_step,
            } => {
                let rtol = positive("integrator.rtol", rtol)?;
                positive("integrator.atol", atol)?;
                if rtol < 1e-14 {
                    // Below this the error estimate is rounding noise and the step collapses.
                    return Err(ConfigError::OutOfRange("integrator.rtol"));
                }
                if let Some(h) = max_step {
                    positive("integrator.max_step", h)?;
                }
                Ok(())
            }
        }
    }

    /// Short name of the method ("rk4", "dopri5", "dop853").
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Rk4 { .. } => "rk4",
            Integrator::Dopri5 { .. } => "dopri5",
            Integrator::Dop853 { .. } => "dop853",
        }
    }
}

/// Why integration stopped.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum OdeError {
    /// The step size fell below the resolution of t (the problem is stiff or singular there).
    #[error("step size underflow at t = {t} s")]
    StepSizeUnderflow {
        /// Time at which it happened, s.
        t: f64,
    },
    /// The right-hand side returned NaN or infinity on a fixed-step method.
    #[error("non-finite state at t = {t} s")]
    NonFinite {
        /// Time at which it happened, s.
        t: f64,
    },
}

/// Work counters of a solver, cumulative since it was created.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct SolverStats {
    /// Right-hand-side evaluations.
    pub rhs_evals: u64,
    /// Accepted steps.
    pub accepted_steps: u64,
    /// Rejected steps (error estimate above tolerance, or non-finite).
    pub rejected_steps: u64,
}

/// Largest polynomial degree of any dense output (DOP853's).
pub const MAX_DENSE_DEGREE: usize = 7;

/// The dense output of the last accepted step, in power form: for θ = (t − t₀)/h ∈ [0, 1],
/// yᵢ(t) = y₀ᵢ + Σₖ aₖᵢ θᵏ (k = 1 … degree).
#[derive(Debug, Clone)]
pub struct DenseOutput {
    t0: f64,
    h: f64,
    n: usize,
    degree: usize,
    y0: Vec<f64>,
    /// Coefficient of θᵏ for component i at `(k − 1)·n + i`.
    a: Vec<f64>,
}

/// The dense polynomial of one component on one step: y(t) = base + Σₖ coeffs[k−1]·θᵏ with
/// θ = (t − t0)/h. Used by the edge locator for the shaft angle.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ComponentPoly {
    /// Start of the step, s.
    pub t0: f64,
    /// Step length, s.
    pub h: f64,
    /// Value at t0.
    pub base: f64,
    /// Polynomial degree (≤ [`MAX_DENSE_DEGREE`]).
    pub degree: usize,
    /// Coefficients of θ¹ … θ^degree (unused entries are zero).
    pub coeffs: [f64; MAX_DENSE_DEGREE],
}

impl ComponentPoly {
    /// y(θ) − base and dy/dθ at θ.
    #[inline]
    pub fn eval_rel(&self, theta: f64) -> (f64, f64) {
        let mut p = 0.0;
        let mut dp = 0.0;
        let mut k = self.degree;
        while k > 0 {
            let c = self.coeffs[k - 1];
            dp = dp * theta + p;
            p = p * theta + c;
            k -= 1;
        }
        // p now holds Σ c_k θ^(k−1); multiply by θ (and fix the derivative accordingly).
        (p * theta, dp * theta + p)
    }

    /// End of the step, s.
    pub fn t1(&self) -> f64 {
        self.t0 + self.h
    }
}

impl DenseOutput {
    fn new(n: usize) -> Self {
        DenseOutput {
            t0: 0.0,
            h: 0.0,
            n,
            degree: 0,
            y0: vec![0.0; n],
            a: vec![0.0; MAX_DENSE_DEGREE * n],
        }
    }

    /// Start of the step, s.
    pub fn t0(&self) -> f64 {
        self.t0
    }

    /// End of the step, s.
    pub fn t1(&self) -> f64 {
        self.t0 + self.h
    }

    /// Step length, s.
    pub fn h(&self) -> f64 {
        self.h
    }

    /// Polynomial degree of the interpolant (3 RK4, 4 DOPRI5, 7 DOP853).
    pub fn degree(&self) -> usize {
        self.degree
    }

    /// Component `i` as a polynomial in θ.
    pub fn component(&self, i: usize) -> ComponentPoly {
        let mut coeffs = [0.0; MAX_DENSE_DEGREE];
        for (k, c) in coeffs.iter_mut().enumerate().take(self.degree) {
            *c = self.a[k * self.n + i];
        }
        ComponentPoly {
            t0: self.t0,
            h: self.h,
            base: self.y0[i],
            degree: self.degree,
            coeffs,
        }
    }

    /// Value of component `i` at time `t` (extrapolates outside the step).
    pub fn eval(&self, i: usize, t: f64) -> f64 {
        let theta = if self.h > 0.0 {
            (t - self.t0) / self.h
        } else {
            0.0
        };
        let mut p = 0.0;
        for k in (0..self.degree).rev() {
            p = (p + self.a[k * self.n + i]) * theta;
        }
        self.y0[i] + p
    }

    /// All components at time `t` into `out` (`out.len() == dim`).
    pub fn eval_into(&self, t: f64, out: &mut [f64]) {
        for (i, o) in out.iter_mut().enumerate().take(self.n) {
            *o = self.eval(i, t);
        }
    }

    /// Fills the power-form coefficients from the nested form used by the DOPRI codes:
    /// y = y₀ + θ(F₀ + (1−θ)(F₁ + θ(F₂ + (1−θ)(F₃ + …)))), the `m` blocks Fⱼ (length n each)
    /// stored one after the other in `f` (Fⱼ at `j·n`).
    fn set_from_nested(&mut self, t0: f64, h: f64, y0: &[f64], f: &[f64], m: usize) {
        self.t0 = t0;
        self.h = h;
        self.degree = m;
        self.y0.copy_from_slice(y0);
        let n = self.n;
        for i in 0..n {
            // q holds polynomial coefficients q[0..=m] in θ.
            let mut q = [0.0f64; MAX_DENSE_DEGREE + 1];
            q[0] = f[(m - 1) * n + i];
            for j in (0..m - 1).rev() {
                // Degree of q before this multiplication.
                let deg = m - 2 - j;
                // Multiply by g_{j+1}: θ if j+1 is even, (1 − θ) if odd.
                if (j + 1) % 2 == 0 {
                    q.copy_within(0..=deg, 1);
                    q[0] = 0.0;
                } else {
                    q[deg + 1] = 0.0;
                    for k in (1..=deg + 1).rev() {
                        q[k] -= q[k - 1];
                    }
                }
                q[0] += f[j * n + i];
            }
            // Final factor θ: coefficient of θ^(k+1) is q[k].
            for (k, &qk) in q.iter().enumerate().take(m) {
                self.a[k * n + i] = qk;
            }
        }
    }
}

#[derive(Debug, Clone, Copy)]
enum Method {
    Rk4 { step: f64 },
    Adaptive { tol: Tol, tableau: Tableau },
}

/// A one-step-at-a-time integrator holding its state, work buffers and the dense output of the
/// last accepted step. All buffers are allocated once in [`Solver::new`].
#[derive(Debug, Clone)]
pub struct Solver {
    method: Method,
    n: usize,
    t: f64,
    y: Vec<f64>,
    /// f(t, y), valid when `have_f`.
    f: Vec<f64>,
    have_f: bool,
    /// Proposed next step (adaptive methods); 0 before the first step.
    h: f64,
    facold: f64,
    last_rejected: bool,
    /// Stage derivatives, 16 blocks of n.
    k: Vec<f64>,
    ytmp: Vec<f64>,
    ynew: Vec<f64>,
    fnew: Vec<f64>,
    /// Nested dense-output blocks, up to 7 of n.
    nested: Vec<f64>,
    dense: DenseOutput,
    stats: SolverStats,
}

const SAFETY: f64 = 0.9;

impl Solver {
    /// A solver for an `n`-dimensional system. `integrator` must have been validated.
    pub fn new(integrator: &Integrator, n: usize) -> Self {
        let adaptive = |rtol, atol, max_step: Option<f64>, tableau| Method::Adaptive {
            tol: Tol {
                rtol,
                atol,
                max_step: max_step.unwrap_or(f64::INFINITY),
            },
            tableau,
        };
        let method = match *integrator {
            Integrator::Rk4 { step } => Method::Rk4 { step },
            Integrator::Dopri5 {
                rtol,
                atol,
                max_step,
            } => adaptive(rtol, atol, max_step, Tableau::Dp5),
            Integrator::Dop853 {
                rtol,
                atol,
                max_step,
            } => adaptive(rtol, atol, max_step, Tableau::Dp853),
        };
        Solver {
            method,
            n,
            t: 0.0,
            y: vec![0.0; n],
            f: vec![0.0; n],
            have_f: false,
            h: 0.0,
            facold: 1e-4,
            last_rejected: false,
            k: vec![0.0; 16 * n],
            ytmp: vec![0.0; n],
            ynew: vec![0.0; n],
            fnew: vec![0.0; n],
            nested: vec![0.0; MAX_DENSE_DEGREE * n],
            dense: DenseOutput::new(n),
            stats: SolverStats::default(),
        }
    }

    /// Sets the initial condition (keeps the counters). `y0.len()` must equal the dimension.
    pub fn reset(&mut self, t0: f64, y0: &[f64]) {
        self.t = t0;
        self.y.copy_from_slice(y0);
        self.have_f = false;
        self.h = 0.0;
        self.facold = 1e-4;
        self.last_rejected = false;
    }

    /// Current time, s.
    pub fn t(&self) -> f64 {
        self.t
    }

    /// Current state.
    pub fn y(&self) -> &[f64] {
        &self.y
    }

    /// Dense output of the last accepted step.
    pub fn dense(&self) -> &DenseOutput {
        &self.dense
    }

    /// Work counters.
    pub fn stats(&self) -> SolverStats {
        self.stats
    }

    fn eval<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, t: f64, which: Buf, stage: usize) {
        self.stats.rhs_evals += 1;
        let n = self.n;
        match which {
            Buf::F => sys.rhs(t, &self.y, &mut self.f),
            Buf::Stage => sys.rhs(t, &self.ytmp, &mut self.k[stage * n..(stage + 1) * n]),
            Buf::FNew => sys.rhs(t, &self.ynew, &mut self.fnew),
        }
    }

    /// Takes one accepted step, never beyond `t_end` (the last step is shortened to land on
    /// it). On return [`Solver::dense`] describes the step just taken and [`Solver::t`],
    /// [`Solver::y`] its end. Does nothing if `t >= t_end`.
    pub fn step<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, t_end: f64) -> Result<(), OdeError> {
        if self.t >= t_end {
            return Ok(());
        }
        if !self.have_f {
            let t = self.t;
            self.eval(sys, t, Buf::F, 0);
            self.have_f = true;
        }
        match self.method {
            Method::Rk4 { step } => self.step_rk4(sys, t_end, step),
            Method::Adaptive { tol, tableau } => self.step_adaptive(sys, t_end, tol, tableau),
        }
    }

    fn step_rk4<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t_end: f64,
        step: f64,
    ) -> Result<(), OdeError> {
        let n = self.n;
        let t = self.t;
        let h = last_step(t, step, t_end);
        // k0 = f (already), k1..k3 in stage blocks 1..3.
        for i in 0..n {
            self.ytmp[i] = self.y[i] + 0.5 * h * self.f[i];
        }
        self.eval(sys, t + 0.5 * h, Buf::Stage, 1);
        for i in 0..n {
            self.ytmp[i] = self.y[i] + 0.5 * h * self.k[n + i];
        }
        self.eval(sys, t + 0.5 * h, Buf::Stage, 2);
        for i in 0..n {
            self.ytmp[i] = self.y[i] + h * self.k[2 * n + i];
        }
        self.eval(sys, t + h, Buf::Stage, 3);
        for i in 0..n {
            self.ynew[i] = self.y[i]
                + h / 6.0
                    * (self.f[i] + 2.0 * (self.k[n + i] + self.k[2 * n + i]) + self.k[3 * n + i]);
        }
        if self.ynew.iter().any(|v| !v.is_finite()) {
            return Err(OdeError::NonFinite { t });
        }
        self.eval(sys, t + h, Buf::FNew, 0);
        self.hermite_blocks(h);
        self.set_dense(t, h, 3);
        self.accept(t + h);
        Ok(())
    }

    /// Nested blocks 0–2: the cubic Hermite interpolant on (y, f) at both ends of the step,
    /// y₀ + θ(Δ + (1−θ)(h f₀ − Δ + θ(2Δ − h(f₀ + f₁)))) — RK4's whole dense output and the
    /// start of DOP853's.
    fn hermite_blocks(&mut self, h: f64) {
        let n = self.n;
        for i in 0..n {
            let d = self.ynew[i] - self.y[i];
            self.nested[i] = d;
            self.nested[n + i] = h * self.f[i] - d;
            self.nested[2 * n + i] = 2.0 * d - h * (self.f[i] + self.fnew[i]);
        }
    }

    /// The dense output of the step [t, t + h] from the first `blocks` nested blocks.
    fn set_dense(&mut self, t: f64, h: f64, blocks: usize) {
        self.dense
            .set_from_nested(t, h, &self.y, &self.nested[..blocks * self.n], blocks);
    }

    fn accept(&mut self, t_new: f64) {
        self.t = t_new;
        std::mem::swap(&mut self.y, &mut self.ynew);
        std::mem::swap(&mut self.f, &mut self.fnew);
        self.stats.accepted_steps += 1;
    }

    /// Error scale of component i: atol + rtol·magnitude.
    fn scale(&self, reference: Option<f64>, i: usize, tol: Tol) -> f64 {
        let mag = match reference {
            Some(r) => r,
            None => self.y[i].abs().max(self.ynew[i].abs()),
        };
        tol.atol + tol.rtol * mag
    }

    /// Hairer's starting-step estimate (one extra evaluation).
    fn initial_step<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        tol: Tol,
        order: i32,
        span: f64,
    ) -> f64 {
        let n = self.n;
        if n == 0 {
            return span.min(tol.max_step);
        }
        let mut d0 = 0.0;
        let mut d1 = 0.0;
        for i in 0..n {
            let mag = sys.error_reference(i).unwrap_or(self.y[i].abs());
            let sk = tol.atol + tol.rtol * mag;
            d0 += (self.y[i] / sk).powi(2);
            d1 += (self.f[i] / sk).powi(2);
        }
        let (d0, d1) = ((d0 / n as f64).sqrt(), (d1 / n as f64).sqrt());
        let mut h0 = if d0 < 1e-10 || d1 < 1e-10 {
            1e-6
        } else {
            0.01 * d0 / d1
        };
        h0 = h0.min(tol.max_step).min(span);
        for i in 0..n {
            self.ytmp[i] = self.y[i] + h0 * self.f[i];
        }
        let t = self.t;
        self.eval(sys, t + h0, Buf::Stage, 1);
        let mut d2 = 0.0;
        for i in 0..n {
            let mag = sys.error_reference(i).unwrap_or(self.y[i].abs());
            let sk = tol.atol + tol.rtol * mag;
            d2 += ((self.k[n + i] - self.f[i]) / sk).powi(2);
        }
        let d2 = (d2 / n as f64).sqrt() / h0;
        let der12 = d2.max(d1);
        let h1 = if der12 <= 1e-15 {
            (h0 * 1e-3).max(1e-6)
        } else {
            (0.01 / der12).powf(1.0 / f64::from(order))
        };
        (100.0 * h0).min(h1).min(tol.max_step).min(span)
    }

    fn step_adaptive<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        t_end: f64,
        tol: Tol,
        tab: Tableau,
    ) -> Result<(), OdeError> {
        // Hairer's parameters: order, β, weight of β in the exponent, shrink and growth limits.
        let (order, beta, beta_weight, fac_shrink, fac_grow) = match tab {
            Tableau::Dp5 => (5, 0.04, 0.75, 0.2, 10.0),
            Tableau::Dp853 => (8, 0.04, 0.2, 0.333, 6.0),
        };
        let expo = 1.0 / f64::from(order) - beta_weight * beta;
        if self.h <= 0.0 {
            self.h = self.initial_step(sys, tol, order, t_end - self.t);
        }
        loop {
            let t = self.t;
            let proposed = self.h.min(tol.max_step);
            let h = last_step(t, proposed, t_end);
            let clipped = h < proposed;
            if h <= 16.0 * f64::EPSILON * t.abs().max(1e-300) {
                return Err(OdeError::StepSizeUnderflow { t });
            }
            let err = match tab {
                Tableau::Dp5 => self.attempt_dp5(sys, h, tol),
                Tableau::Dp853 => self.attempt_dp853(sys, h, tol),
            };
            if err.is_finite() && err <= 1.0 {
                let fac11 = err.powf(expo);
                let fac = (fac11 / self.facold.powf(beta) / SAFETY)
                    .clamp(1.0 / fac_grow, 1.0 / fac_shrink);
                let mut hnew = h / fac;
                self.facold = err.max(1e-4);
                if self.last_rejected {
                    hnew = hnew.min(h);
                }
                self.last_rejected = false;
                // FSAL: fnew = f(t + h, ynew) was computed by the attempt.
                match tab {
                    Tableau::Dp5 => self.dense_dp5(t, h),
                    Tableau::Dp853 => self.dense_dp853(sys, t, h),
                }
                // A step shortened to land on t_end says little about the next one: keep
                // the previous proposal then.
                if !clipped {
                    self.h = hnew;
                }
                self.accept(t + h);
                return Ok(());
            }
            self.stats.rejected_steps += 1;
            self.last_rejected = true;
            let shrink = if err.is_finite() {
                (1.0 / fac_shrink).min(err.powf(expo) / SAFETY)
            } else {
                1.0 / fac_shrink
            };
            self.h = h / shrink;
        }
    }

    /// `ytmp = y + h·Σ_j a_j·k_j` over the stages `j < a.len()` (zero coefficients skipped).
    fn stage_input(&mut self, a: &[f64], h: f64) {
        let n = self.n;
        for i in 0..n {
            let mut acc = 0.0;
            for (j, aj) in a.iter().enumerate() {
                if *aj != 0.0 {
                    acc += aj * self.k[j * n + i];
                }
            }
            self.ytmp[i] = self.y[i] + h * acc;
        }
    }

    fn attempt_dp5<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, h: f64, tol: Tol) -> f64 {
        let n = self.n;
        let t = self.t;
        // Stage s (1-based 2..6) in block s-1; block 0 mirrors f.
        self.k[..n].copy_from_slice(&self.f);
        for s in 1..6 {
            self.stage_input(&DP5_A[s][..s], h);
            self.eval(sys, t + DP5_C[s] * h, Buf::Stage, s);
        }
        for i in 0..n {
            let mut acc = 0.0;
            for (j, b) in DP5_B.iter().enumerate() {
                acc += b * self.k[j * n + i];
            }
            self.ynew[i] = self.y[i] + h * acc;
        }
        self.eval(sys, t + h, Buf::FNew, 0);
        if self.ynew.iter().any(|v| !v.is_finite()) {
            return f64::NAN;
        }
        if n == 0 {
            return 0.0;
        }
        let mut sum = 0.0;
        for i in 0..n {
            let mut acc = DP5_E[6] * self.fnew[i];
            for (j, e) in DP5_E.iter().enumerate().take(6) {
                acc += e * self.k[j * n + i];
            }
            let sk = self.scale(sys.error_reference(i), i, tol);
            sum += (h * acc / sk).powi(2);
        }
        (sum / n as f64).sqrt()
    }

    /// Shampine's continuous extension in Hairer's DOPRI5 form (its block 2 is the Hermite
    /// term written as Δ − h f₁ − (h f₀ − Δ), rounded as there).
    fn dense_dp5(&mut self, t: f64, h: f64) {
        let n = self.n;
        for i in 0..n {
            let d = self.ynew[i] - self.y[i];
            let bspl = h * self.f[i] - d;
            self.nested[i] = d;
            self.nested[n + i] = bspl;
            self.nested[2 * n + i] = d - h * self.fnew[i] - bspl;
            let mut acc = DP5_D[6] * self.fnew[i];
            for (j, dj) in DP5_D.iter().enumerate().take(6) {
                acc += dj * self.k[j * n + i];
            }
            self.nested[3 * n + i] = h * acc;
        }
        self.set_dense(t, h, 4);
    }

    fn attempt_dp853<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, h: f64, tol: Tol) -> f64 {
        let n = self.n;
        let t = self.t;
        self.k[..n].copy_from_slice(&self.f);
        for s in 1..12 {
            self.stage_input(&DP8_A[s][..s], h);
            self.eval(sys, t + DP8_C[s] * h, Buf::Stage, s);
        }
        for i in 0..n {
            let mut acc = 0.0;
            for (j, b) in DP8_A[12].iter().enumerate().take(12) {
                if *b != 0.0 {
                    acc += b * self.k[j * n + i];
                }
            }
            self.ynew[i] = self.y[i] + h * acc;
        }
        // Combined 5th/3rd-order error estimate (Hairer's DOP853).
        let mut err5 = 0.0;
        let mut err3 = 0.0;
        for i in 0..n {
            let mut e5 = 0.0;
            let mut e3 = 0.0;
            for j in 0..12 {
                let kj = self.k[j * n + i];
                e5 += DP8_E5[j] * kj;
                e3 += (DP8_A[12][j] - DP8_BHH[j]) * kj;
            }
            let sk = self.scale(sys.error_reference(i), i, tol);
            err5 += (e5 / sk).powi(2);
            err3 += (e3 / sk).powi(2);
        }
        let ok = self.ynew.iter().all(|v| v.is_finite());
        self.eval(sys, t + h, Buf::FNew, 0);
        if !ok {
            return f64::NAN;
        }
        if n == 0 {
            return 0.0;
        }
        let mut deno = err5 + 0.01 * err3;
        if deno <= 0.0 {
            deno = 1.0;
        }
        h.abs() * err5 / (deno * n as f64).sqrt()
    }

    fn dense_dp853<S: OdeSystem + ?Sized>(&mut self, sys: &mut S, t: f64, h: f64) {
        let n = self.n;
        // Block 12 holds f(t + h, ynew); blocks 13..15 the three extra stages.
        self.k[12 * n..13 * n].copy_from_slice(&self.fnew);
        for s in 13..16 {
            self.stage_input(&DP8_A[s][..s], h);
            self.eval(sys, t + DP8_C[s] * h, Buf::Stage, s);
        }
        self.hermite_blocks(h);
        for i in 0..n {
            for (r, drow) in DP8_D.iter().enumerate() {
                let mut acc = 0.0;
                for (j, dj) in drow.iter().enumerate() {
                    if *dj != 0.0 {
                        acc += dj * self.k[j * n + i];
                    }
                }
                self.nested[(3 + r) * n + i] = h * acc;
            }
        }
        self.set_dense(t, h, 7);
    }
}

/// The step to take from `t` towards `t_end` when `h` is proposed: `h`, or exactly what is left
/// when that is at most 1 % more than `h` (no sliver of a last step).
fn last_step(t: f64, h: f64, t_end: f64) -> f64 {
    if t + 1.01 * h >= t_end {
        t_end - t
    } else {
        h
    }
}

#[derive(Debug, Clone, Copy)]
enum Buf {
    F,
    Stage,
    FNew,
}

#[derive(Debug, Clone, Copy)]
enum Tableau {
    Dp5,
    Dp853,
}

#[derive(Debug, Clone, Copy)]
struct Tol {
    rtol: f64,
    atol: f64,
    max_step: f64,
}

// Dormand–Prince 5(4) tableau (Hairer's DOPRI5).
const DP5_C: [f64; 7] = [0.0, 0.2, 0.3, 0.8, 8.0 / 9.0, 1.0, 1.0];
const DP5_A: [[f64; 6]; 6] = [
    [0.0; 6],
    [0.2, 0.0, 0.0, 0.0, 0.0, 0.0],
    [3.0 / 40.0, 9.0 / 40.0, 0.0, 0.0, 0.0, 0.0],
    [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0, 0.0, 0.0, 0.0],
    [
        19372.0 / 6561.0,
        -25360.0 / 2187.0,
        64448.0 / 6561.0,
        -212.0 / 729.0,
        0.0,
        0.0,
    ],
    [
        9017.0 / 3168.0,
        -355.0 / 33.0,
        46732.0 / 5247.0,
        49.0 / 176.0,
        -5103.0 / 18656.0,
        0.0,
    ],
];
const DP5_B: [f64; 6] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
];
const DP5_E: [f64; 7] = [
    71.0 / 57600.0,
    0.0,
    -71.0 / 16695.0,
    71.0 / 1920.0,
    -17253.0 / 339200.0,
    22.0 / 525.0,
    -1.0 / 40.0,
];
const DP5_D: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

// Dormand–Prince 8(5,3) (Hairer's DOP853): nodes, stages 1–12, row 12 = weights b,
// rows 13–15 the extra stages of the dense output.
#[allow(clippy::excessive_precision)]
const DP8_C: [f64; 16] = [
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0,
    1.0,
    0.1,
    0.2,
    0.777777777777777777777777777778,
];

#[allow(clippy::excessive_precision)]
const DP8_A: [[f64; 16]; 16] = {
    let mut a = [[0.0f64; 16]; 16];
    a[1][0] = 5.26001519587677318785587544488e-2;
    a[2][0] = 1.97250569845378994544595329183e-2;
    a[2][1] = 5.91751709536136983633785987549e-2;
    a[3][0] = 2.95875854768068491816892993775e-2;
    a[3][2] = 8.87627564304205475450678981324e-2;
    a[4][0] = 2.41365134159266685502369798665e-1;
    a[4][2] = -8.84549479328286085344864962717e-1;
    a[4][3] = 9.24834003261792003115737966543e-1;
    a[5][0] = 3.7037037037037037037037037037e-2;
    a[5][3] = 1.70828608729473871279604482173e-1;
    a[5][4] = 1.25467687566822425016691814123e-1;
    a[6][0] = 3.7109375e-2;
    a[6][3] = 1.70252211019544039314978060272e-1;
    a[6][4] = 6.02165389804559606850219397283e-2;
    a[6][5] = -1.7578125e-2;
    a[7][0] = 3.70920001185047927108779319836e-2;
    a[7][3] = 1.70383925712239993810214054705e-1;
    a[7][4] = 1.07262030446373284651809199168e-1;
    a[7][5] = -1.53194377486244017527936158236e-2;
    a[7][6] = 8.27378916381402288758473766002e-3;
    a[8][0] = 6.24110958716075717114429577812e-1;
    a[8][3] = -3.36089262944694129406857109825;
    a[8][4] = -8.68219346841726006818189891453e-1;
    a[8][5] = 2.75920996994467083049415600797e1;
    a[8][6] = 2.01540675504778934086186788979e1;
    a[8][7] = -4.34898841810699588477366255144e1;
    a[9][0] = 4.77662536438264365890433908527e-1;
    a[9][3] = -2.48811461997166764192642586468;
    a[9][4] = -5.90290826836842996371446475743e-1;
    a[9][5] = 2.12300514481811942347288949897e1;
    a[9][6] = 1.52792336328824235832596922938e1;
    a[9][7] = -3.32882109689848629194453265587e1;
    a[9][8] = -2.03312017085086261358222928593e-2;
    a[10][0] = -9.3714243008598732571704021658e-1;
    a[10][3] = 5.18637242884406370830023853209;
    a[10][4] = 1.09143734899672957818500254654;
    a[10][5] = -8.14978701074692612513997267357;
    a[10][6] = -1.85200656599969598641566180701e1;
    a[10][7] = 2.27394870993505042818970056734e1;
    a[10][8] = 2.49360555267965238987089396762;
    a[10][9] = -3.0467644718982195003823669022;
    a[11][0] = 2.27331014751653820792359768449;
    a[11][3] = -1.05344954667372501984066689879e1;
    a[11][4] = -2.00087205822486249909675718444;
    a[11][5] = -1.79589318631187989172765950534e1;
    a[11][6] = 2.79488845294199600508499808837e1;
    a[11][7] = -2.85899827713502369474065508674;
    a[11][8] = -8.87285693353062954433549289258;
    a[11][9] = 1.23605671757943030647266201528e1;
    a[11][10] = 6.43392746015763530355970484046e-1;
    a[12][0] = 5.42937341165687622380535766363e-2;
    a[12][5] = 4.45031289275240888144113950566;
    a[12][6] = 1.89151789931450038304281599044;
    a[12][7] = -5.8012039600105847814672114227;
    a[12][8] = 3.1116436695781989440891606237e-1;
    a[12][9] = -1.52160949662516078556178806805e-1;
    a[12][10] = 2.01365400804030348374776537501e-1;
    a[12][11] = 4.47106157277725905176885569043e-2;
    a[13][0] = 5.61675022830479523392909219681e-2;
    a[13][6] = 2.53500210216624811088794765333e-1;
    a[13][7] = -2.46239037470802489917441475441e-1;
    a[13][8] = -1.24191423263816360469010140626e-1;
    a[13][9] = 1.5329179827876569731206322685e-1;
    a[13][10] = 8.20105229563468988491666602057e-3;
    a[13][11] = 7.56789766054569976138603589584e-3;
    a[13][12] = -8.298e-3;
    a[14][0] = 3.18346481635021405060768473261e-2;
    a[14][5] = 2.83009096723667755288322961402e-2;
    a[14][6] = 5.35419883074385676223797384372e-2;
    a[14][7] = -5.49237485713909884646569340306e-2;
    a[14][10] = -1.08347328697249322858509316994e-4;
    a[14][11] = 3.82571090835658412954920192323e-4;
    a[14][12] = -3.40465008687404560802977114492e-4;
    a[14][13] = 1.41312443674632500278074618366e-1;
    a[15][0] = -4.28896301583791923408573538692e-1;
    a[15][5] = -4.69762141536116384314449447206;
    a[15][6] = 7.68342119606259904184240953878;
    a[15][7] = 4.06898981839711007970213554331;
    a[15][8] = 3.56727187455281109270669543021e-1;
    a[15][12] = -1.39902416515901462129418009734e-3;
    a[15][13] = 2.9475147891527723389556272149;
    a[15][14] = -9.15095847217987001081870187138;
    a
};

/// Weights of the embedded 3rd-order solution (b − ê₃ gives the 3rd-order error estimate).
#[allow(clippy::excessive_precision)]
const DP8_BHH: [f64; 12] = {
    let mut b = [0.0f64; 12];
    b[0] = 0.244094488188976377952755905512;
    b[8] = 0.733846688281611857341361741547;
    b[11] = 0.220588235294117647058823529412e-1;
    b
};

#[allow(clippy::excessive_precision)]
const DP8_E5: [f64; 12] = [
    0.1312004499419488073250102996e-1,
    0.0,
    0.0,
    0.0,
    0.0,
    -0.1225156446376204440720569753e1,
    -0.4957589496572501915214079952,
    0.1664377182454986536961530415e1,
    -0.3503288487499736816886487290,
    0.3341791187130174790297318841,
    0.8192320648511571246570742613e-1,
    -0.2235530786388629525884427845e-1,
];

/// Coefficients of the 4th–7th nested blocks of DOP853's dense output, over the 16 stages.
#[allow(clippy::excessive_precision)]
const DP8_D: [[f64; 16]; 4] = {
    let mut d = [[0.0f64; 16]; 4];
    d[0][0] = -0.84289382761090128651353491142e1;
    d[0][5] = 0.56671495351937776962531783590;
    d[0][6] = -0.30689499459498916912797304727e1;
    d[0][7] = 0.23846676565120698287728149680e1;
    d[0][8] = 0.21170345824450282767155149946e1;
    d[0][9] = -0.87139158377797299206789907490;
    d[0][10] = 0.22404374302607882758541771650e1;
    d[0][11] = 0.63157877876946881815570249290;
    d[0][12] = -0.88990336451333310820698117400e-1;
    d[0][13] = 0.18148505520854727256656404962e2;
    d[0][14] = -0.91946323924783554000451984436e1;
    d[0][15] = -0.44360363875948939664310572000e1;
    d[1][0] = 0.10427508642579134603413151009e2;
    d[1][5] = 0.24228349177525818288430175319e3;
    d[1][6] = 0.16520045171727028198505394887e3;
    d[1][7] = -0.37454675472269020279518312152e3;
    d[1][8] = -0.22113666853125306036270938578e2;
    d[1][9] = 0.77334326684722638389603898808e1;
    d[1][10] = -0.30674084731089398182061213626e2;
    d[1][11] = -0.93321305264302278729567221706e1;
    d[1][12] = 0.15697238121770843886131091075e2;
    d[1][13] = -0.31139403219565177677282850411e2;
    d[1][14] = -0.93529243588444783865713862664e1;
    d[1][15] = 0.35816841486394083752465898540e2;
    d[2][0] = 0.19985053242002433820987653617e2;
    d[2][5] = -0.38703730874935176555105901742e3;
    d[2][6] = -0.18917813819516756882830838328e3;
    d[2][7] = 0.52780815920542364900561016686e3;
    d[2][8] = -0.11573902539959630126141871134e2;
    d[2][9] = 0.68812326946963000169666922661e1;
    d[2][10] = -0.10006050966910838403183860980e1;
    d[2][11] = 0.77771377980534432092869265740;
    d[2][12] = -0.27782057523535084065932004339e1;
    d[2][13] = -0.60196695231264120758267380846e2;
    d[2][14] = 0.84320405506677161018159903784e2;
    d[2][15] = 0.11992291136182789328035130030e2;
    d[3][0] = -0.25693933462703749003312586129e2;
    d[3][5] = -0.15418974869023643374053993627e3;
    d[3][6] = -0.23152937917604549567536039109e3;
    d[3][7] = 0.35763911791061412378285349910e3;
    d[3][8] = 0.93405324183624310003907691704e2;
    d[3][9] = -0.37458323136451633156875139351e2;
    d[3][10] = 0.10409964950896230045147246184e3;
    d[3][11] = 0.29840293426660503123344363579e2;
    d[3][12] = -0.43533456590011143754432175058e2;
    d[3][13] = 0.96324553959188282948394950600e2;
    d[3][14] = -0.39177261675615439165231486172e2;
    d[3][15] = -0.14972683625798562581422125276e3;
    d
};

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    /// Harmonic oscillator y'' = −y: y = (cos t, −sin t).
    struct Osc {
        evals: u64,
    }

    impl OdeSystem for Osc {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
            self.evals += 1;
            dy[0] = y[1];
            dy[1] = -y[0];
        }
    }

    fn run(integrator: Integrator, t_end: f64) -> (Solver, f64, f64) {
        let mut sys = Osc { evals: 0 };
        let mut s = Solver::new(&integrator, 2);
        s.reset(0.0, &[1.0, 0.0]);
        let mut max_dense_err: f64 = 0.0;
        while s.t() < t_end {
            s.step(&mut sys, t_end).unwrap();
            let d = s.dense();
            for j in 1..8 {
                let t = d.t0() + d.h() * f64::from(j) / 8.0;
                max_dense_err = max_dense_err.max((d.eval(0, t) - t.cos()).abs());
                let (p, dp) = d.component(0).eval_rel(f64::from(j) / 8.0);
                assert!((d.component(0).base + p - d.eval(0, t)).abs() < 1e-14);
                // dy/dt of the interpolant ≈ y[1] = −sin t.
                assert!((dp / d.h() + t.sin()).abs() < 1e-3);
            }
        }
        assert_eq!(sys.evals, s.stats().rhs_evals);
        let err = (s.y()[0] - t_end.cos())
            .abs()
            .max((s.y()[1] + t_end.sin()).abs());
        (s, err, max_dense_err)
    }

    fn dopri5(rtol: f64) -> Integrator {
        Integrator::Dopri5 {
            rtol,
            atol: rtol,
            max_step: None,
        }
    }

    fn dop853(rtol: f64) -> Integrator {
        Integrator::Dop853 {
            rtol,
            atol: rtol,
            max_step: None,
        }
    }

    #[test]
    fn rk4_is_fourth_order() {
        let (_, e1, d1) = run(Integrator::Rk4 { step: 0.02 }, 10.0);
        let (s2, e2, d2) = run(Integrator::Rk4 { step: 0.01 }, 10.0);
        let ratio = e1 / e2;
        assert!((12.0..20.0).contains(&ratio), "ratio {ratio}");
        // Cubic Hermite: local error O(h⁴), same order as the method's global error.
        assert!(d2 < 1e-8 && d1 / d2 > 8.0, "dense {d1} {d2}");
        assert_eq!(s2.stats().accepted_steps, 1000);
        assert_eq!(s2.stats().rhs_evals, 1 + 4 * 1000);
    }

    #[test]
    fn dopri5_meets_tolerance_with_dense_output() {
        for rtol in [1e-6, 1e-9, 1e-11] {
            let (s, e, d) = run(dopri5(rtol), 10.0);
            assert!(e < 50.0 * rtol, "rtol {rtol}: end error {e}");
            assert!(d < 50.0 * rtol, "rtol {rtol}: dense error {d}");
            let st = s.stats();
            // FSAL: 6 evaluations per attempted step, plus 2 to start.
            assert_eq!(
                st.rhs_evals,
                2 + 6 * (st.accepted_steps + st.rejected_steps)
            );
        }
    }

    #[test]
    fn dop853_meets_tolerance_with_fewer_steps() {
        for rtol in [1e-8, 1e-11, 1e-13] {
            let (s8, e, d) = run(dop853(rtol), 10.0);
            assert!(e < 50.0 * rtol, "rtol {rtol}: end error {e}");
            assert!(d < 50.0 * rtol, "rtol {rtol}: dense error {d}");
            let (s5, _, _) = run(dopri5(rtol), 10.0);
            assert!(s8.stats().accepted_steps * 2 < s5.stats().accepted_steps);
        }
    }

    #[test]
    fn lands_exactly_on_t_end_and_respects_max_step() {
        let mut sys = Osc { evals: 0 };
        let mut s = Solver::new(
            &Integrator::Dopri5 {
                rtol: 1e-8,
                atol: 1e-8,
                max_step: Some(0.05),
            },
            2,
        );
        s.reset(0.0, &[1.0, 0.0]);
        while s.t() < 1.2345 {
            s.step(&mut sys, 1.2345).unwrap();
            assert!(s.dense().h() <= 0.05 * 1.0101);
        }
        assert_eq!(s.t(), 1.2345);
    }

    #[test]
    fn scene_tables_deserialize_and_validate() {
        let i: Integrator =
            toml::from_str("method = \"dopri5\"\nrtol = 1e-9\natol = 1e-9").unwrap();
        assert!(i.validate().is_ok());
        assert_eq!(i.name(), "dopri5");
        let bad: Result<Integrator, _> = toml::from_str("method = \"rk4\"\nstep = 1e-3\nrtol = 1");
        assert!(bad.is_err());
        let i: Integrator = toml::from_str("method = \"rk4\"\nstep = -1.0").unwrap();
        assert_eq!(
            i.validate(),
            Err(ConfigError::NotPositive("integrator.step"))
        );
    }
}
