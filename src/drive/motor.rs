//! Motor characteristics `M_d(ω)`: the parabola of seed 000 (eq. 3–4) and the Kloss curve
//! (eq. 2) with a documented fit to a parabola.
//!
//! The closed-form steady state needs the parabola form `M_d = A·ω² + B` (it makes the equation
//! of motion linear in `u = ω²`). A real induction motor follows the Kloss curve; the simulator
//! integrates the curve itself ([`Motor::torque`]), and so does the prediction (by shooting
//! over one period, the `shooting` module), starting from the fitted parabola
//! ([`Motor::model`]); the parabola alone stands in only where the load's orders have no common
//! period the prediction samples ([`Horizon::Unbounded`](crate::drive::Horizon)), and there the
//! host builds the motor with the parabola at the operating point
//! ([`Kloss::operating_point_fit`], [`Motor::kloss_with`]).
//!
//! ## Which branch the parabola describes
//! With `A < 0` the parabola falls monotonically for every `ω > 0` (`dM_d/dω = 2Aω < 0`), so
//! any positive periodic solution of the parabola model is asymptotically stable: deviations of
//! `u` decay like `exp(−2·D1·φ)`, `D1 = −A/J`. A real induction motor is stable only on its
//! working branch `ω > ω_m` (slip below the breakdown slip); below `ω_m` its torque falls
//! while the parabola's keeps rising. The parabola's prediction is therefore trusted only while
//! the speed stays above [`Parabola::working_min_speed`]; the prediction reports this as
//! `within_working_branch`.

use crate::error::{non_negative, positive, ConfigError};

/// The parabolic characteristic `M_d(ω) = A·ω² + B`, `A < 0 < B` (seed 000, eq. 3–4).
///
/// Built from two points: no-load speed `ω0` (`M_d = 0`) and breakdown speed `ω_m`
/// (`M_d = M_m`): `A = −M_m/(ω0² − ω_m²)`, `B = +M_m·ω0²/(ω0² − ω_m²)`. The paper prints `B`
/// with a minus sign, with which the curve cannot pass through `(ω0, 0)`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Parabola {
    /// `−A`, N·m·s², strictly positive.
    neg_a: f64,
    /// `B`, N·m (stall torque of the parabola), strictly positive.
    b: f64,
    /// Lowest speed of the motor's working (stable) branch, rad/s.
    working_min_speed: f64,
    /// The motor's breakdown torque `M_m`, N·m (the characteristic scales with it).
    breakdown_torque: f64,
}

impl Parabola {
    /// The parabola through `(no_load_speed, 0)` and `(breakdown_speed, breakdown_torque)`.
    ///
    /// Requires `no_load_speed > 0`, `0 ≤ breakdown_speed < no_load_speed`,
    /// `breakdown_torque > 0`, all finite and not subnormal, and coefficients that fit in f64.
    pub fn new(
        no_load_speed: f64,
        breakdown_speed: f64,
        breakdown_torque: f64,
    ) -> Result<Self, ConfigError> {
        let w0 = positive("no_load_speed", no_load_speed)?;
        let wm = non_negative("breakdown_speed", breakdown_speed)?;
        let mm = positive("breakdown_torque", breakdown_torque)?;
        if wm >= w0 {
            return Err(ConfigError::Inconsistent("breakdown_speed"));
        }
        // ω0² − ω_m² as (ω0 − ω_m)(ω0 + ω_m): no cancellation when ω_m is close to ω0.
        let k = (w0 - wm) * (w0 + wm);
        if !(k.is_finite() && k >= f64::MIN_POSITIVE) {
            return Err(ConfigError::OutOfRange("no_load_speed"));
        }
        let neg_a = mm / k;
        let b = neg_a * w0 * w0;
        Self::checked(neg_a, b, wm, mm).ok_or(ConfigError::OutOfRange("breakdown_torque"))
    }

    /// A parabola from its coefficients; `None` unless `−A` and `B` are positive normal
    /// finite numbers.
    pub(crate) fn checked(
        neg_a: f64,
        b: f64,
        working_min_speed: f64,
        breakdown_torque: f64,
    ) -> Option<Self> {
        let ok = |x: f64| x.is_finite() && x >= f64::MIN_POSITIVE;
        if ok(neg_a) && ok(b) && ok(breakdown_torque) && working_min_speed.is_finite() {
            Some(Self {
                neg_a,
                b,
                working_min_speed,
                breakdown_torque,
            })
        } else {
            None
        }
    }

    /// The coefficient `A` (negative), N·m·s².
    pub fn a(&self) -> f64 {
        -self.neg_a
    }

    /// The coefficient `B` (positive): the parabola's torque at standstill, N·m.
    pub fn b(&self) -> f64 {
        self.b
    }

    /// The speed at which the parabola's torque is zero, `√(−B/A)`, rad/s.
    pub fn no_load_speed(&self) -> f64 {
        libm::sqrt(self.b / self.neg_a)
    }

    /// Lowest speed of the motor's stable working branch (the breakdown speed), rad/s.
    pub fn working_min_speed(&self) -> f64 {
        self.working_min_speed
    }

    /// The breakdown torque `M_m` the characteristic is proportional to, N·m.
    pub fn breakdown_torque(&self) -> f64 {
        self.breakdown_torque
    }

    /// Drive torque at speed `omega` (rad/s), N·m. Even in `omega`; NaN in, NaN out.
    pub fn torque(&self, omega: f64) -> f64 {
        self.b - self.neg_a * omega * omega
    }

    /// The same characteristic with every torque multiplied by `factor` (a stronger or weaker
    /// motor of the same speeds); `None` if the result leaves the valid range.
    pub fn scaled(&self, factor: f64) -> Option<Self> {
        Self::checked(
            self.neg_a * factor,
            self.b * factor,
            self.working_min_speed,
            self.breakdown_torque * factor,
        )
    }
}

/// The Kloss characteristic of an induction motor (seed 000, eq. 2):
/// `M_d = 2·M_m / (σ/σ_m + σ_m/σ)`, slip `σ = (ω_s − ω)/ω_s`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Kloss {
    synchronous_speed: f64,
    breakdown_slip: f64,
    breakdown_torque: f64,
}

/// How a Kloss curve is replaced by a parabola `A·ω² + B`: the start of the prediction's
/// shooting, and the prediction itself only for load orders with no common period
/// ([`Kloss::operating_point_fit`] fits it at a given mean load instead, for that case).
///
/// No parabola of this family follows the Kloss curve over its whole working branch: the
/// Kloss slope goes from `2·M_m/(σ_m·ω_s)` at synchronous speed to 0 at breakdown, while the
/// parabola's slope `2Aω` changes only by the factor `1 − σ_m` over the branch. What the
/// prediction needs is the torque and the slope near the operating point (the slope sets the
/// damping term `D1`). Measured worst `|parabola − Kloss|/M_m` (unit test
/// `kloss_fit_errors_on_working_branch`) on the whole working branch `σ ∈ [0, σ_m]` and on the
/// light-load part `σ ∈ [0, σ_m/3]` (loads up to about 0.6·M_m):
///
/// | σ_m | `Breakdown` `[0, σ_m]` | `[0, σ_m/3]` | `SynchronousTangent` `[0, σ_m]` | `[0, σ_m/3]` |
/// |-----|------|------|------|------|
/// | 0.1 | 0.287 | 0.255 | 0.900 | 0.056 |
/// | 0.2 | 0.273 | 0.242 | 0.800 | 0.044 |
/// | 0.3 | 0.256 | 0.227 | 0.700 | 0.033 |
///
/// The `Breakdown` parabola has `1/(2 − σ_m)` of the Kloss slope at synchronous speed, so a
/// drive at light load runs too slow and too soft in the prediction (δ too large);
/// `SynchronousTangent` is exact there and overestimates the torque towards breakdown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum KlossFit {
    /// The paper's fit: the parabola through the synchronous point `(ω_s, 0)` and the
    /// breakdown point `(ω_s·(1 − σ_m), M_m)`, i.e. `ω0 = ω_s`, `ω_m = ω_s·(1 − σ_m)`.
    Breakdown,
    /// The parabola through `(ω_s, 0)` with the Kloss slope there:
    /// `A = −M_m/(σ_m·ω_s²)`, `B = M_m/σ_m`.
    SynchronousTangent,
}

impl Kloss {
    /// A Kloss curve. Requires `synchronous_speed > 0`, `0 < breakdown_slip ≤ 1`,
    /// `breakdown_torque > 0`, all finite and not subnormal.
    pub fn new(
        synchronous_speed: f64,
        breakdown_slip: f64,
        breakdown_torque: f64,
    ) -> Result<Self, ConfigError> {
        let ws = positive("synchronous_speed", synchronous_speed)?;
        let sm = positive("breakdown_slip", breakdown_slip)?;
        let mm = positive("breakdown_torque", breakdown_torque)?;
        if sm > 1.0 {
            return Err(ConfigError::OutOfRange("breakdown_slip"));
        }
        Ok(Self {
            synchronous_speed: ws,
            breakdown_slip: sm,
            breakdown_torque: mm,
        })
    }

    /// Synchronous speed `ω_s`, rad/s.
    pub fn synchronous_speed(&self) -> f64 {
        self.synchronous_speed
    }

    /// Breakdown slip `σ_m`.
    pub fn breakdown_slip(&self) -> f64 {
        self.breakdown_slip
    }

    /// Breakdown (maximum) torque `M_m`, N·m.
    pub fn breakdown_torque(&self) -> f64 {
        self.breakdown_torque
    }

    /// Breakdown speed `ω_s·(1 − σ_m)`, rad/s: the lower end of the working branch.
    pub fn breakdown_speed(&self) -> f64 {
        self.synchronous_speed * (1.0 - self.breakdown_slip)
    }

    /// Drive torque at speed `omega` (rad/s), N·m: zero at synchronous speed, negative
    /// (generating) above it. NaN in, NaN out.
    pub fn torque(&self, omega: f64) -> f64 {
        // (ω_s − ω)/ω_s rather than 1 − ω/ω_s: the subtraction is exact near ω_s.
        let s = (self.synchronous_speed - omega) / self.synchronous_speed;
        if s == 0.0 {
            return 0.0;
        }
        let sm = self.breakdown_slip;
        2.0 * self.breakdown_torque / (s / sm + sm / s)
    }

    /// The parabola that replaces this curve in the prediction, by the given fit.
    pub fn fit(&self, fit: KlossFit) -> Result<Parabola, ConfigError> {
        match fit {
            KlossFit::Breakdown => Parabola::new(
                self.synchronous_speed,
                self.breakdown_speed(),
                self.breakdown_torque,
            ),
            KlossFit::SynchronousTangent => self.synchronous_tangent(),
        }
    }

    /// The parabola through the operating point: the working-branch speed `ω̄` at which the
    /// curve gives `mean_load` (`σ̄ = σ_m·M1/(M_m + √((M_m − M1)(M_m + M1)))`), with the curve's
    /// slope there, `2·A·ω̄ = dM_d/dω(ω̄) = −2·M_m·σ_m·(σ_m² − σ̄²)/((σ̄² + σ_m²)²·ω_s)`, and
    /// `B = M1 − A·ω̄²`. Its steady state has the curve's mean speed and damping to first order
    /// in the swing, where the tangent at synchronous speed puts a loaded drive too fast (at
    /// `M1 = 0.9·M_m`, `σ_m = 0.2`: 3.5 %). The host's prediction uses it where the load's
    /// orders have no common period the Kloss curve can be integrated over
    /// ([`Motor::kloss_with`]). `OutOfRange("load.mean")` when `|mean_load| ≥ M_m` (no speed
    /// carries it) or the parabola leaves f64's normal range (`B ≤ 0`: a generating mean load
    /// far beyond synchronous speed).
    pub fn operating_point_fit(&self, mean_load: f64) -> Result<Parabola, ConfigError> {
        let (ws, sm, mm) = (
            self.synchronous_speed,
            self.breakdown_slip,
            self.breakdown_torque,
        );
        if mean_load.is_nan() || libm::fabs(mean_load) >= mm {
            return Err(ConfigError::OutOfRange("load.mean"));
        }
        let root = libm::sqrt((mm - mean_load) * (mm + mean_load));
        let sb = sm * (mean_load / (mm + root));
        let wb = ws - ws * sb;
        let q = sb * sb + sm * sm;
        let neg_a = mm * sm * ((sm - sb) * (sm + sb) / q / q) / ws / wb;
        let b = mean_load + neg_a * wb * wb;
        Parabola::checked(neg_a, b, self.breakdown_speed(), mm)
            .filter(|_| wb > 0.0)
            .ok_or(ConfigError::OutOfRange("load.mean"))
    }

    /// Tangent parabola at synchronous speed: `M_d(ω_s) = 0` with the Kloss slope there,
    /// `dM/dω = −2·M_m/(σ_m·ω_s)`, so `A = −M_m/(σ_m·ω_s²)` and `B = M_m/σ_m`.
    fn synchronous_tangent(&self) -> Result<Parabola, ConfigError> {
        let ws = self.synchronous_speed;
        let mm = self.breakdown_torque;
        let neg_a = mm / (self.breakdown_slip * ws) / ws;
        Parabola::checked(neg_a, mm / self.breakdown_slip, self.breakdown_speed(), mm)
            .ok_or(ConfigError::OutOfRange("synchronous_speed"))
    }
}

/// A motor: the characteristic the machine really has (for simulation) and the parabola the
/// steady-state prediction uses.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Motor {
    kloss: Option<Kloss>,
    model: Parabola,
}

impl Motor {
    /// A motor whose characteristic is exactly the parabola.
    pub fn parabola(p: Parabola) -> Self {
        Self {
            kloss: None,
            model: p,
        }
    }

    /// A motor with a Kloss characteristic; the prediction integrates the curve itself, the
    /// parabola fit is its start (and the prediction where the load has no common period).
    pub fn kloss(k: Kloss, fit: KlossFit) -> Result<Self, ConfigError> {
        Ok(Self {
            kloss: Some(k),
            model: k.fit(fit)?,
        })
    }

    /// A motor with a Kloss characteristic and a parabola of the caller's (one from
    /// [`Kloss::operating_point_fit`]): what [`Motor::kloss`] builds, with `model` in place of
    /// the fit's parabola (the shooting's start, and the prediction where the load's orders
    /// have no common period).
    pub fn kloss_with(k: Kloss, model: Parabola) -> Self {
        Self {
            kloss: Some(k),
            model,
        }
    }

    /// Drive torque at speed `omega` (rad/s) of the real characteristic (Kloss if the motor
    /// was built from one), N·m. This is what a simulation integrates.
    pub fn torque(&self, omega: f64) -> f64 {
        match &self.kloss {
            Some(k) => k.torque(omega),
            None => self.model.torque(omega),
        }
    }

    /// The parabola used by the prediction.
    pub fn model(&self) -> &Parabola {
        &self.model
    }

    /// The Kloss curve, if the motor was built from one.
    pub fn kloss_curve(&self) -> Option<&Kloss> {
        self.kloss.as_ref()
    }

    /// The same motor with every torque multiplied by `factor`; `None` if out of range.
    pub fn scaled(&self, factor: f64) -> Option<Self> {
        let model = self.model.scaled(factor)?;
        let kloss = match self.kloss {
            Some(k) => Some(
                Kloss::new(
                    k.synchronous_speed,
                    k.breakdown_slip,
                    k.breakdown_torque * factor,
                )
                .ok()?,
            ),
            None => None,
        };
        Some(Self { kloss, model })
    }
}

impl From<Parabola> for Motor {
    fn from(p: Parabola) -> Self {
        Self::parabola(p)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::testutil::BAD;

    #[test]
    fn parabola_passes_through_its_two_points() {
        let p = Parabola::new(145.0, 36.0, 158.0).unwrap();
        assert!(p.torque(145.0).abs() < 1e-12);
        assert!((p.torque(36.0) - 158.0).abs() < 1e-12);
        // B has the corrected (positive) sign and the parabola falls with speed.
        assert!(p.b() > 0.0 && p.a() < 0.0);
        assert!(p.torque(100.0) > p.torque(120.0));
        assert!((p.no_load_speed() - 145.0).abs() < 1e-12);
        assert_eq!(p.working_min_speed(), 36.0);
        // Close points: ω0² − ω_m² computed without cancellation.
        let q = Parabola::new(1.0 + 1e-9, 1.0, 1.0).unwrap();
        assert!((q.torque(1.0) - 1.0).abs() < 1e-6);
    }

    #[test]
    fn parabola_rejects_bad_parameters() {
        for x in BAD {
            assert!(Parabola::new(x, 36.0, 158.0).is_err(), "{x}");
            assert!(Parabola::new(145.0, 36.0, x).is_err(), "{x}");
            if x != 0.0 {
                assert!(Parabola::new(145.0, x, 158.0).is_err(), "{x}");
            }
        }
        assert!(Parabola::new(145.0, 0.0, 158.0).is_ok());
        assert_eq!(
            Parabola::new(36.0, 145.0, 158.0),
            Err(ConfigError::Inconsistent("breakdown_speed"))
        );
        assert_eq!(
            Parabola::new(145.0, 145.0, 158.0),
            Err(ConfigError::Inconsistent("breakdown_speed"))
        );
        assert!(Parabola::new(1e200, 1e199, 1.0).is_err());
        assert!(Parabola::new(1.0, 0.5, 1.7e308).is_err());
    }

    #[test]
    fn kloss_shape() {
        let k = Kloss::new(157.08, 0.2, 100.0).unwrap();
        assert_eq!(k.torque(157.08), 0.0);
        assert!((k.torque(k.breakdown_speed()) - 100.0).abs() < 1e-9);
        // Maximum at the breakdown slip.
        for i in 0..100 {
            assert!(k.torque(i as f64 * 1.6) <= 100.0 + 1e-9);
        }
        assert!(k.torque(170.0) < 0.0);
        assert!(k.torque(f64::NAN).is_nan());
        assert_eq!(k.torque(157.08 * (1.0 + 1e-17)), 0.0);
        for x in BAD {
            assert!(Kloss::new(x, 0.2, 1.0).is_err());
            assert!(Kloss::new(1.0, x, 1.0).is_err());
            assert!(Kloss::new(1.0, 0.2, x).is_err());
        }
        assert_eq!(
            Kloss::new(1.0, 1.5, 1.0),
            Err(ConfigError::OutOfRange("breakdown_slip"))
        );
        assert!(Kloss::new(1.0, 1.0, 1.0).is_ok());
    }

    /// Worst |parabola − Kloss| / M_m for slips in [0, σ_hi], dense sampling.
    fn worst_error(k: &Kloss, p: &Parabola, slip_hi: f64) -> f64 {
        let ws = k.synchronous_speed();
        (0..=10_000)
            .map(|i| ws * (1.0 - slip_hi * i as f64 / 10_000.0))
            .map(|w| (p.torque(w) - k.torque(w)).abs() / k.breakdown_torque())
            .fold(0.0, f64::max)
    }

    #[test]
    fn kloss_fit_errors_on_working_branch() {
        // The table in the `KlossFit` docs, to 1e-3.
        let table = [
            (0.1, 0.287, 0.255, 0.900, 0.056),
            (0.2, 0.273, 0.242, 0.800, 0.044),
            (0.3, 0.256, 0.227, 0.700, 0.033),
        ];
        for (sm, b1, b3, t1, t3) in table {
            let k = Kloss::new(157.08, sm, 100.0).unwrap();
            let pb = k.fit(KlossFit::Breakdown).unwrap();
            let pt = k.fit(KlossFit::SynchronousTangent).unwrap();
            // The breakdown fit passes exactly through both points, the tangent through (ω_s, 0).
            assert!(pb.torque(157.08).abs() < 1e-9);
            assert!(pt.torque(157.08).abs() < 1e-9);
            assert!((pb.torque(k.breakdown_speed()) - 100.0).abs() < 1e-9);
            let got = [
                worst_error(&k, &pb, sm),
                worst_error(&k, &pb, sm / 3.0),
                worst_error(&k, &pt, sm),
                worst_error(&k, &pt, sm / 3.0),
            ];
            for (g, e) in got.iter().zip([b1, b3, t1, t3]) {
                assert!((g - e).abs() < 1e-3, "σm {sm}: {got:?}");
            }
            // Slopes at synchronous speed: breakdown fit 1/(2 − σm) of Kloss, tangent exact.
            let d = 1e-4;
            let slope = |f: &dyn Fn(f64) -> f64| (f(157.08 - d) - f(157.08 + d)) / (2.0 * d);
            let ks = slope(&|w| k.torque(w));
            let rb = slope(&|w| pb.torque(w)) / ks;
            let rt = slope(&|w| pt.torque(w)) / ks;
            assert!((rb - 1.0 / (2.0 - sm)).abs() < 1e-4, "{rb}");
            assert!((rt - 1.0).abs() < 1e-4, "{rt}");
        }
    }

    #[test]
    fn operating_point_fit_matches_the_curve_there() {
        let k = Kloss::new(157.08, 0.2, 100.0).unwrap();
        for m1 in [-60.0, 0.0, 30.0, 90.0, 99.0] {
            let p = k.operating_point_fit(m1).unwrap();
            // The parabola's speed for M1 is where the curve gives M1, with the curve's slope.
            let w = libm::sqrt((p.b() - m1) / -p.a());
            assert!(
                (k.torque(w) - m1).abs() < 1e-9 * 100.0,
                "{m1}: {}",
                k.torque(w)
            );
            let d = 1e-4;
            let slope = |f: &dyn Fn(f64) -> f64| (f(w + d) - f(w - d)) / (2.0 * d);
            let (sk, sp) = (slope(&|x| k.torque(x)), slope(&|x| p.torque(x)));
            assert!((sp / sk - 1.0).abs() < 1e-6, "{m1}: {sp} against {sk}");
            assert_eq!(p.breakdown_torque(), 100.0);
            assert_eq!(p.working_min_speed(), k.breakdown_speed());
        }
        // At M1 = 0 it is the tangent at synchronous speed.
        let t = k.fit(KlossFit::SynchronousTangent).unwrap();
        let z = k.operating_point_fit(0.0).unwrap();
        assert!((z.a() / t.a() - 1.0).abs() < 1e-12 && (z.b() / t.b() - 1.0).abs() < 1e-12);
        for m1 in [100.0, -100.0, 150.0, f64::NAN] {
            assert_eq!(
                k.operating_point_fit(m1),
                Err(ConfigError::OutOfRange("load.mean"))
            );
        }
        let m = Motor::kloss_with(k, z);
        assert_eq!(m.torque(140.0), k.torque(140.0));
        assert_eq!(*m.model(), z);
    }

    #[test]
    fn motor_torque_uses_the_real_curve() {
        let k = Kloss::new(157.08, 0.2, 100.0).unwrap();
        let m = Motor::kloss(k, KlossFit::SynchronousTangent).unwrap();
        assert_eq!(m.torque(140.0), k.torque(140.0));
        assert_ne!(m.torque(140.0), m.model().torque(140.0));
        let p = Parabola::new(145.0, 36.0, 158.0).unwrap();
        let m: Motor = p.into();
        assert_eq!(m.torque(140.0), p.torque(140.0));
        assert!(m.kloss_curve().is_none());
        let s = m.scaled(2.0).unwrap();
        assert!((s.torque(140.0) - 2.0 * p.torque(140.0)).abs() < 1e-12);
        assert!(m.scaled(f64::NAN).is_none());
        assert!(m.scaled(-1.0).is_none());
    }
}
