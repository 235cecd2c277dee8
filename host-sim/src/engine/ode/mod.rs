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

mod dormand_prince;

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

/// The fastest rate of the system linearised at (t, y), 1/s: the spectral radius of its
/// Jacobian ∂f/∂y, by central differences (2·dim evaluations of f) and Gelfand's formula
/// ‖A^(2^k)‖^(2^−k) over eight squarings (the norm's dependence on the variables' units is
/// taken to the power 1/256). A fixed RK4 step h is stable on that linearisation only where
/// h times it stays under about 2.8. `None` where f is not finite there.
pub fn fastest_rate<S: OdeSystem + ?Sized>(sys: &mut S, t: f64, y: &[f64]) -> Option<f64> {
    let n = sys.dim();
    if n == 0 {
        return Some(0.0);
    }
    let mut a = vec![0.0; n * n];
    let mut yp = y.to_vec();
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    for j in 0..n {
        let d = 1e-6 * y[j].abs().max(1.0);
        yp[j] = y[j] + d;
        sys.rhs(t, &yp, &mut fp);
        yp[j] = y[j] - d;
        sys.rhs(t, &yp, &mut fm);
        yp[j] = y[j];
        for i in 0..n {
            a[i * n + j] = (fp[i] - fm[i]) / (2.0 * d);
        }
    }
    if a.iter().any(|v| !v.is_finite()) {
        return None;
    }
    let norm = |m: &[f64]| {
        (0..n)
            .map(|i| m[i * n..(i + 1) * n].iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0f64, f64::max)
    };
    // A^(2^k) = e^log_scale · a.
    let mut log_scale = 0.0;
    let mut sq = vec![0.0; n * n];
    const SQUARINGS: i32 = 8;
    for _ in 0..SQUARINGS {
        let s = norm(&a);
        if s == 0.0 {
            return Some(0.0);
        }
        a.iter_mut().for_each(|v| *v /= s);
        log_scale = 2.0 * (log_scale + s.ln());
        for i in 0..n {
            for j in 0..n {
                sq[i * n + j] = (0..n).map(|k| a[i * n + k] * a[k * n + j]).sum();
            }
        }
        std::mem::swap(&mut a, &mut sq);
    }
    let s = norm(&a);
    if s == 0.0 {
        return Some(0.0);
    }
    Some(((log_scale + s.ln()) / f64::from(1 << SQUARINGS)).exp())
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

    /// Short name of the method, as scenes write it (`[simulation] integrator`: "rk4", "dp5",
    /// "dop853").
    pub fn name(&self) -> &'static str {
        match self {
            Integrator::Rk4 { .. } => "rk4",
            Integrator::Dopri5 { .. } => "dp5",
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
    /// Whether each accepted step forms its dense output ([`Solver::without_dense_output`]).
    dense_wanted: bool,
    stats: SolverStats,
    /// RK4: the largest local error estimated so far, over its scale, and the step's start
    /// time ([`Solver::fixed_step_error`]).
    worst_rk4: (f64, f64),
    /// RK4: the last step's estimated local error over its scale ([`Solver::last_step_error`]).
    last_rk4: f64,
}

const SAFETY: f64 = 0.9;

/// The scale of RK4's local error estimate ([`Solver::fixed_step_error`]): relative to each
/// component, with a floor for components near zero. Above it a step is not resolved: on the
/// kneader (12 s, settle 4 s) steps of 0.01 s stay within it and read δ 0.03 % off, 0.1 s
/// estimate 5.4 of it and read δ 0.46 % off, 0.5 s estimate 2.7e4 of it and read δ 655 % off.
pub const RK4_RTOL: f64 = 1e-4;
/// See [`RK4_RTOL`].
pub const RK4_ATOL: f64 = 1e-7;

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
            dense_wanted: true,
            stats: SolverStats::default(),
            worst_rk4: (0.0, 0.0),
            last_rk4: 0.0,
        }
    }

    /// The same solver forming no dense output: for a caller that needs only the state at the
    /// end of its steps (a monodromy matrix), DOP853's three extra stages a step and the
    /// polynomial's coefficients are saved; the steps and states are the same bit for bit.
    /// [`Solver::dense`] then stays as it was built.
    pub fn without_dense_output(mut self) -> Self {
        self.dense_wanted = false;
        self
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

    /// For the fixed-step RK4: the largest local error of a step estimated so far, over
    /// `RK4_ATOL + RK4_RTOL·|y|` component by component, and the time that step started
    /// (`None` for the adaptive methods, which hold their own tolerance). The estimate is free:
    /// the third-order solution through the same stages and f(t + h, y₁), weights (1/6, 1/3,
    /// 1/3, 0, 1/6), differs from RK4's by h/6·(k₃ − f(t + h, y₁)).
    pub fn fixed_step_error(&self) -> Option<(f64, f64)> {
        matches!(self.method, Method::Rk4 { .. }).then_some(self.worst_rk4)
    }

    /// For the fixed-step RK4: the last step's estimated local error over its scale, as in
    /// [`Solver::fixed_step_error`] (`None` for the adaptive methods).
    pub fn last_step_error(&self) -> Option<f64> {
        matches!(self.method, Method::Rk4 { .. }).then_some(self.last_rk4)
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
        let mut worst = 0.0f64;
        for i in 0..n {
            let e = (h / 6.0 * (self.k[3 * n + i] - self.fnew[i])).abs();
            let scale = RK4_ATOL + RK4_RTOL * self.y[i].abs().max(self.ynew[i].abs());
            worst = worst.max(e / scale);
        }
        self.last_rk4 = worst;
        if worst > self.worst_rk4.0 {
            self.worst_rk4 = (worst, t);
        }
        if self.dense_wanted {
            self.hermite_blocks(h);
            self.set_dense(t, h, 3);
        }
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
        let ctrl = Controller::of(tab);
        if self.h <= 0.0 {
            self.h = self.initial_step(sys, tol, ctrl.order, t_end - self.t);
        }
        loop {
            let t = self.t;
            let proposed = self.h.min(tol.max_step);
            let h = last_step(t, proposed, t_end);
            let clipped = h < proposed;
            if h <= 16.0 * f64::EPSILON * t.abs().max(1e-300) {
                return Err(OdeError::StepSizeUnderflow { t });
            }
            let err = self.attempt(sys, h, tol, tab);
            if err.is_finite() && err <= 1.0 {
                self.accept_adaptive(sys, tab, &ctrl, h, err, clipped);
                return Ok(());
            }
            self.stats.rejected_steps += 1;
            self.last_rejected = true;
            self.h = ctrl.retry(h, err);
        }
    }

    /// Takes the attempted step `h` of error `err` (≤ 1): its dense output, the next step's
    /// proposal (kept from before when `clipped`: a step shortened to land on `t_end` says
    /// little about the next one), and the new time and state.
    fn accept_adaptive<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &mut S,
        tab: Tableau,
        ctrl: &Controller,
        h: f64,
        err: f64,
        clipped: bool,
    ) {
        let t = self.t;
        let mut hnew = ctrl.next(h, err, self.facold);
        self.facold = err.max(1e-4);
        if self.last_rejected {
            hnew = hnew.min(h);
        }
        self.last_rejected = false;
        // FSAL: fnew = f(t + h, ynew) was computed by the attempt.
        match tab {
            _ if !self.dense_wanted => {}
            Tableau::Dp5 => self.dense_dp5(t, h),
            Tableau::Dp853 => self.dense_dp853(sys, t, h),
        }
        if !clipped {
            self.h = hnew;
        }
        self.accept(t + h);
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

/// Hairer's step-size controller of a tableau: its order, the β stabilisation and the bounds
/// on how fast the step may shrink or grow.
#[derive(Debug, Clone, Copy)]
struct Controller {
    order: i32,
    beta: f64,
    expo: f64,
    fac_shrink: f64,
    fac_grow: f64,
}

impl Controller {
    fn of(tab: Tableau) -> Self {
        // Hairer's parameters: order, β, weight of β in the exponent, shrink and growth limits.
        let (order, beta, beta_weight, fac_shrink, fac_grow) = match tab {
            Tableau::Dp5 => (5, 0.04, 0.75, 0.2, 10.0),
            Tableau::Dp853 => (8, 0.04, 0.2, 0.333, 6.0),
        };
        Controller {
            order,
            beta,
            expo: 1.0 / f64::from(order) - beta_weight * beta,
            fac_shrink,
            fac_grow,
        }
    }

    /// The step proposed after accepting `h` with error `err`, the previous accepted error
    /// being `facold`.
    fn next(&self, h: f64, err: f64, facold: f64) -> f64 {
        let fac11 = err.powf(self.expo);
        let fac = (fac11 / facold.powf(self.beta) / SAFETY)
            .clamp(1.0 / self.fac_grow, 1.0 / self.fac_shrink);
        h / fac
    }

    /// The step to retry with after rejecting `h` with error `err` (maybe not finite).
    fn retry(&self, h: f64, err: f64) -> f64 {
        let shrink = if err.is_finite() {
            (1.0 / self.fac_shrink).min(err.powf(self.expo) / SAFETY)
        } else {
            1.0 / self.fac_shrink
        };
        h / shrink
    }
}

#[derive(Debug, Clone, Copy)]
struct Tol {
    rtol: f64,
    atol: f64,
    max_step: f64,
}

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

    /// y'' = −c·y' − k·y, written in units that make its Jacobian far from normal.
    struct Damped {
        c: f64,
        k: f64,
        unit: f64,
    }

    impl OdeSystem for Damped {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&mut self, _t: f64, y: &[f64], dy: &mut [f64]) {
            dy[0] = y[1] / self.unit;
            dy[1] = (-self.c * y[1] / self.unit - self.k * y[0]) * self.unit;
        }
    }

    #[test]
    fn the_fastest_rate_is_the_jacobians_spectral_radius() {
        // The oscillator: eigenvalues ±i.
        let r = fastest_rate(&mut Osc { evals: 0 }, 0.0, &[1.0, 0.0]).unwrap();
        assert!((r - 1.0).abs() < 1e-3, "{r}");
        // Real eigenvalues −1 and −100 (c = 101, k = 100), the velocity in units of 1e-4:
        // the matrix norm is 1e4 times off, the radius is not.
        for unit in [1.0, 1e-4] {
            let mut d = Damped {
                c: 101.0,
                k: 100.0,
                unit,
            };
            let r = fastest_rate(&mut d, 0.0, &[0.3, 2.0 * unit]).unwrap();
            assert!((r / 100.0 - 1.0).abs() < 0.05, "{unit}: {r}");
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
        assert_eq!(i.name(), "dp5");
        let bad: Result<Integrator, _> = toml::from_str("method = \"rk4\"\nstep = 1e-3\nrtol = 1");
        assert!(bad.is_err());
        let i: Integrator = toml::from_str("method = \"rk4\"\nstep = -1.0").unwrap();
        assert_eq!(
            i.validate(),
            Err(ConfigError::NotPositive("integrator.step"))
        );
    }
}
