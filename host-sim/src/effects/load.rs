//! Load torques on the shaft: the working machine's resistance M_c(φ) (seed 000) and
//! viscous friction.

use serde::Deserialize;

use drive_monitor::error::{finite, non_negative, positive, ConfigError};

use crate::model::{Effect, Shaft};

/// One harmonic of the load, M2·sin(n·φ + ψ).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadHarmonic {
    /// Amplitude M2, N·m.
    pub amplitude: f64,
    /// Order n (cycles per shaft revolution; may be fractional, e.g. 1/8 for a load that
    /// repeats every 8 turns).
    pub order: f64,
    /// Phase ψ, rad.
    #[serde(default)]
    pub phase: f64,
}

/// Load torque M_c(φ) = M1 + Σ M2k·sin(n_k·φ + ψ_k), opposing the drive
/// (the effect returns −M_c).
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadTorque {
    /// Mean load M1, N·m.
    pub mean: f64,
    /// Harmonics (none: a constant load).
    #[serde(default)]
    pub harmonics: Vec<LoadHarmonic>,
}

impl LoadTorque {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), ConfigError> {
        finite("load.mean", self.mean)?;
        for h in &self.harmonics {
            finite("load.harmonics.amplitude", h.amplitude)?;
            positive("load.harmonics.order", h.order)?;
            finite("load.harmonics.phase", h.phase)?;
        }
        Ok(())
    }

    /// M_c(φ), N·m (positive resists forward motion).
    pub fn resisting(&self, phi: f64) -> f64 {
        self.mean
            + self
                .harmonics
                .iter()
                .map(|h| h.amplitude * (h.order * phi + h.phase).sin())
                .sum::<f64>()
    }
}

impl Effect for LoadTorque {
    fn name(&self) -> &'static str {
        "load"
    }
    fn dim(&self) -> usize {
        0
    }
    fn init(&self, _y: &mut [f64]) {}
    fn eval(&self, _t: f64, shaft: Shaft, _y: &[f64], _dy: &mut [f64]) -> f64 {
        -self.resisting(shaft.phi)
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
    fn dim(&self) -> usize {
        0
    }
    fn init(&self, _y: &mut [f64]) {}
    fn eval(&self, _t: f64, shaft: Shaft, _y: &[f64], _dy: &mut [f64]) -> f64 {
        -self.coefficient * shaft.omega
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn load_opposes_the_drive_with_its_harmonic() {
        let l = LoadTorque {
            mean: 24.0,
            harmonics: vec![LoadHarmonic {
                amplitude: 12.0,
                order: 0.125,
                phase: 0.0,
            }],
        };
        assert!(l.validate().is_ok());
        let s = |phi| Shaft { phi, omega: 100.0 };
        assert_eq!(l.eval(0.0, s(0.0), &[], &mut []), -24.0);
        // sin(φ/8) = 1 at φ = 4π.
        assert!((l.eval(0.0, s(4.0 * core::f64::consts::PI), &[], &mut []) + 36.0).abs() < 1e-12);
        let parsed: LoadTorque =
            toml::from_str("mean = 24.0\nharmonics = [{ amplitude = 12.0, order = 0.125 }]")
                .unwrap();
        assert_eq!(parsed, l);
        assert!(toml::from_str::<LoadTorque>("mean = 1.0\nmen = 2.0").is_err());
    }
}
