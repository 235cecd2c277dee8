//! Load torques on the shaft: the working machine's resistance M_c(φ) (seed 000), as the
//! core's [`Load`], and viscous friction.
//!
//! M_c(φ) is defined once, in `drive_monitor::drive`; the simulator integrates exactly the
//! [`Load::torque`] the prediction is built from.

use serde::Deserialize;

use drive_monitor::drive::Load;
use drive_monitor::error::{non_negative, ConfigError};

use crate::engine::model::{Effect, Shaft};

/// The load opposes the drive: the effect's torque is −M_c(φ).
impl Effect for Load {
    fn name(&self) -> &'static str {
        "load"
    }
    fn eval(&self, _t: f64, shaft: Shaft, _y: &[f64], _dy: &mut [f64]) -> f64 {
        -self.torque(shaft.phi)
    }
}

/// Viscous friction −c·ω.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViscousFriction {
    /// Coefficient c, N·m·s/rad.
    pub coefficient: f64,
}

impl ViscousFriction {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), ConfigError> {
        non_negative("friction.coefficient", self.coefficient).map(|_| ())
    }
}

impl Effect for ViscousFriction {
    fn name(&self) -> &'static str {
        "friction"
    }
    fn eval(&self, _t: f64, shaft: Shaft, _y: &[f64], _dy: &mut [f64]) -> f64 {
        -self.coefficient * shaft.omega
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use drive_monitor::drive::Harmonic;

    use super::*;

    #[test]
    fn load_opposes_the_drive_with_its_harmonic() {
        let l = Load::new(24.0, &[Harmonic::new(0.125, 12.0, 0.0).unwrap()]).unwrap();
        assert_eq!((l.name(), l.dim()), ("load", 0));
        let s = |phi| Shaft { phi, omega: 100.0 };
        assert_eq!(l.eval(0.0, s(0.0), &[], &mut []), -24.0);
        // sin(φ/8) = 1 at φ = 4π.
        assert!((l.eval(0.0, s(4.0 * core::f64::consts::PI), &[], &mut []) + 36.0).abs() < 1e-12);
        // Exactly the core's M_c(φ), negated, and the series written out.
        for phi in [-3.0, 0.7, 10.0, 123.4] {
            assert_eq!(l.eval(0.0, s(phi), &[], &mut []), -l.torque(phi));
            let exact = 24.0 + 12.0 * (0.125 * phi).sin();
            assert!((l.eval(0.0, s(phi), &[], &mut []) + exact).abs() < 1e-12);
        }
        // A constant load (no harmonics) does not depend on the angle.
        let c = Load::new(10.0, &[]).unwrap();
        assert_eq!(c.eval(0.0, s(5.0), &[], &mut []), -10.0);
    }

    #[test]
    fn friction_opposes_the_speed() {
        let f = ViscousFriction { coefficient: 0.5 };
        assert!(f.validate().is_ok());
        let s = Shaft {
            phi: 0.0,
            omega: -4.0,
        };
        assert_eq!(f.eval(0.0, s, &[], &mut []), 2.0);
        assert!(ViscousFriction { coefficient: -1.0 }.validate().is_err());
    }
}
