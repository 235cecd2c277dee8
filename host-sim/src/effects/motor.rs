//! Motor torque characteristics M_d(ω) of an asynchronous motor (seed 000, eq. 2–3).
//!
//! A motor held at a prescribed speed is not an effect: that is a prescribed shaft law
//! (`system::SpeedLaw`).

use serde::Deserialize;

use drive_monitor::error::{positive, ConfigError};

use crate::model::{Effect, Shaft};

/// The working branch of the motor characteristic approximated by the parabola
/// M_d = A·ω² + B through (ω0, 0) and (ω_m, M_m):
/// A = −M_m/(ω0² − ω_m²), B = +M_m·ω0²/(ω0² − ω_m²)
/// (seed 000 prints B with a minus sign; with it the parabola misses (ω0, 0)).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ParabolaMotor {
    /// No-load (synchronous) speed ω0, rad/s.
    pub omega0: f64,
    /// Speed at the maximum (breakdown) torque ω_m, rad/s (0 < ω_m < ω0).
    pub omega_m: f64,
    /// Maximum torque M_m, N·m.
    pub m_max: f64,
}

impl ParabolaMotor {
    /// Checks the parameters (ω0 > ω_m > 0, M_m > 0).
    pub fn validate(&self) -> Result<(), ConfigError> {
        let w0 = positive("omega0", self.omega0)?;
        let wm = positive("omega_m", self.omega_m)?;
        positive("m_max", self.m_max)?;
        if wm >= w0 {
            return Err(ConfigError::Inconsistent("omega_m"));
        }
        Ok(())
    }

    /// K = ω0² − ω_m², rad²/s².
    pub fn k(&self) -> f64 {
        // (ω0 − ω_m)(ω0 + ω_m): no cancellation when ω_m is close to ω0.
        (self.omega0 - self.omega_m) * (self.omega0 + self.omega_m)
    }

    /// Coefficient A, N·m·s².
    pub fn a(&self) -> f64 {
        -self.m_max / self.k()
    }

    /// Coefficient B, N·m.
    pub fn b(&self) -> f64 {
        self.m_max * self.omega0 * self.omega0 / self.k()
    }

    /// Torque at speed ω, N·m.
    pub fn torque(&self, omega: f64) -> f64 {
        self.m_max * (self.omega0 - omega) * (self.omega0 + omega) / self.k()
    }
}

impl Effect for ParabolaMotor {
    fn name(&self) -> &'static str {
        "motor"
    }
    fn dim(&self) -> usize {
        0
    }
    fn init(&self, _y: &mut [f64]) {}
    fn eval(&self, _t: f64, shaft: Shaft, _y: &[f64], _dy: &mut [f64]) -> f64 {
        self.torque(shaft.omega)
    }
}

/// Kloss formula M_d = 2·M_m/(σ/σ_m + σ_m/σ), slip σ = (ω0 − ω)/ω0 (seed 000, eq. 2).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct KlossMotor {
    /// Synchronous speed ω0, rad/s.
    pub omega0: f64,
    /// Breakdown torque M_m, N·m.
    pub m_max: f64,
    /// Critical slip σ_m (slip at the breakdown torque), 0 < σ_m < 1.
    pub slip_critical: f64,
}

impl KlossMotor {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), ConfigError> {
        positive("omega0", self.omega0)?;
        positive("m_max", self.m_max)?;
        let s = positive("slip_critical", self.slip_critical)?;
        if s >= 1.0 {
            return Err(ConfigError::OutOfRange("slip_critical"));
        }
        Ok(())
    }

    /// Torque at speed ω, N·m.
    pub fn torque(&self, omega: f64) -> f64 {
        let s = (self.omega0 - omega) / self.omega0;
        let sm = self.slip_critical;
        // 2·M_m·σ·σ_m/(σ² + σ_m²): the printed form divides by σ, which is 0 at ω0.
        2.0 * self.m_max * s * sm / (s * s + sm * sm)
    }
}

impl Effect for KlossMotor {
    fn name(&self) -> &'static str {
        "motor"
    }
    fn dim(&self) -> usize {
        0
    }
    fn init(&self, _y: &mut [f64]) {}
    fn eval(&self, _t: f64, shaft: Shaft, _y: &[f64], _dy: &mut [f64]) -> f64 {
        self.torque(shaft.omega)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parabola_passes_through_its_two_points() {
        let m = ParabolaMotor {
            omega0: 145.0,
            omega_m: 36.0,
            m_max: 158.0,
        };
        assert!(m.validate().is_ok());
        assert!(m.torque(145.0).abs() < 1e-12);
        assert!((m.torque(36.0) - 158.0).abs() < 1e-12);
        // Same curve as A ω² + B with B's corrected sign.
        let w = 120.0;
        assert!((m.a() * w * w + m.b() - m.torque(w)).abs() < 1e-10);
        assert!(m.b() > 0.0);
    }

    #[test]
    fn kloss_peaks_at_the_critical_slip() {
        let m = KlossMotor {
            omega0: 157.08,
            m_max: 200.0,
            slip_critical: 0.2,
        };
        assert!(m.validate().is_ok());
        assert_eq!(m.torque(157.08), 0.0);
        let w_crit = 157.08 * (1.0 - 0.2);
        assert!((m.torque(w_crit) - 200.0).abs() < 1e-10);
        for dw in [-1.0, 1.0] {
            assert!(m.torque(w_crit + dw) < 200.0);
        }
        // Above synchronous speed the machine brakes (generator).
        assert!(m.torque(160.0) < 0.0);
        let bad = KlossMotor {
            slip_critical: 1.5,
            ..m
        };
        assert_eq!(
            bad.validate(),
            Err(ConfigError::OutOfRange("slip_critical"))
        );
    }
}
