//! Load torque reduced to the drive shaft: `M_c(φ) = M1 + Σ_k M2k·sin(n_k·φ + ψ_k)`.

use crate::error::{finite, non_negative, ConfigError};

/// Fixed capacity of load harmonics.
pub const MAX_HARMONICS: usize = 8;

/// Largest accepted harmonic order (cycles per shaft revolution).
pub const MAX_ORDER: f64 = 1e6;

/// The checks every harmonic term shares (load torque or inertia), its sign already checked:
/// an order at most [`MAX_ORDER`], a finite amplitude, a finite phase within ±1e9 rad; errors
/// name `keys` (order, amplitude, phase).
pub(super) fn checked_term(
    keys: [&'static str; 3],
    order: f64,
    amplitude: f64,
    phase: f64,
) -> Result<[f64; 3], ConfigError> {
    if order > MAX_ORDER {
        return Err(ConfigError::OutOfRange(keys[0]));
    }
    let amplitude = finite(keys[1], amplitude)?;
    let phase = finite(keys[2], phase)?;
    if libm::fabs(phase) > 1e9 {
        return Err(ConfigError::OutOfRange(keys[2]));
    }
    Ok([order, amplitude, phase])
}

/// One harmonic `amplitude·sin(order·φ + phase)` of the load torque.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Harmonic {
    order: f64,
    amplitude: f64,
    phase: f64,
}

impl Harmonic {
    /// A harmonic of `order` cycles per shaft revolution (`0 ≤ order ≤ MAX_ORDER`; order 0 is
    /// a constant `amplitude·sin(phase)`), `amplitude` in N·m (any sign) and `phase` in rad.
    pub fn new(order: f64, amplitude: f64, phase: f64) -> Result<Self, ConfigError> {
        let order = non_negative("harmonic.order", order)?;
        let [order, amplitude, phase] = checked_term(
            ["harmonic.order", "harmonic.amplitude", "harmonic.phase"],
            order,
            amplitude,
            phase,
        )?;
        Ok(Self {
            order,
            amplitude,
            phase,
        })
    }

    /// Order `n` (cycles per shaft revolution).
    pub fn order(&self) -> f64 {
        self.order
    }

    /// Amplitude `M2`, N·m.
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// Phase `ψ`, rad.
    pub fn phase(&self) -> f64 {
        self.phase
    }

    /// Value at shaft angle `phi`, N·m.
    pub fn torque(&self, phi: f64) -> f64 {
        self.amplitude * libm::sin(self.order * phi + self.phase)
    }
}

/// The load torque `M_c(φ)`: a mean plus up to [`MAX_HARMONICS`] harmonics.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Load {
    mean: f64,
    harmonics: heapless::Vec<Harmonic, MAX_HARMONICS>,
}

impl Load {
    /// A load with mean `mean` (N·m, finite, any sign) and the given harmonics.
    pub fn new(mean: f64, harmonics: &[Harmonic]) -> Result<Self, ConfigError> {
        let mean = finite("load.mean", mean)?;
        let harmonics =
            heapless::Vec::from_slice(harmonics).map_err(|_| ConfigError::Capacity("harmonics"))?;
        Ok(Self { mean, harmonics })
    }

    /// The mean `M1`, N·m.
    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// The harmonics.
    pub fn harmonics(&self) -> &[Harmonic] {
        &self.harmonics
    }

    /// Load torque at shaft angle `phi` (rad), N·m. NaN in, NaN out.
    pub fn torque(&self, phi: f64) -> f64 {
        self.mean + self.harmonics.iter().map(|h| h.torque(phi)).sum::<f64>()
    }

    /// An upper bound of the load torque over all angles, `M1 + Σ|M2k|`, N·m.
    pub fn peak_bound(&self) -> f64 {
        self.mean
            + self
                .harmonics
                .iter()
                .map(|h| libm::fabs(h.amplitude))
                .sum::<f64>()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn load_evaluates_the_series() {
        let h = [
            Harmonic::new(0.125, 12.0, 0.0).unwrap(),
            Harmonic::new(2.0, -3.0, 0.5).unwrap(),
        ];
        let l = Load::new(24.0, &h).unwrap();
        let phi: f64 = 1.7;
        let expect = 24.0 + 12.0 * (0.125 * phi).sin() - 3.0 * (2.0 * phi + 0.5).sin();
        assert!((l.torque(phi) - expect).abs() < 1e-12);
        assert_eq!(l.peak_bound(), 39.0);
        assert_eq!(l.harmonics().len(), 2);
        let h0 = Harmonic::new(0.0, 2.0, 0.3).unwrap();
        assert!((h0.torque(123.0) - 2.0 * 0.3f64.sin()).abs() < 1e-15);
    }

    #[test]
    fn load_rejects_bad_parameters() {
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            assert_eq!(Load::new(x, &[]), Err(ConfigError::NonFinite("load.mean")));
            assert!(Harmonic::new(x, 1.0, 0.0).is_err());
            assert!(Harmonic::new(1.0, x, 0.0).is_err());
            assert!(Harmonic::new(1.0, 1.0, x).is_err());
        }
        assert_eq!(
            Harmonic::new(-1.0, 1.0, 0.0),
            Err(ConfigError::Negative("harmonic.order"))
        );
        assert_eq!(
            Harmonic::new(1e-310, 1.0, 0.0),
            Err(ConfigError::OutOfRange("harmonic.order"))
        );
        assert_eq!(
            Harmonic::new(2e6, 1.0, 0.0),
            Err(ConfigError::OutOfRange("harmonic.order"))
        );
        let h = Harmonic::new(1.0, 1.0, 0.0).unwrap();
        assert_eq!(
            Load::new(0.0, &[h; MAX_HARMONICS + 1]),
            Err(ConfigError::Capacity("harmonics"))
        );
        assert!(Load::new(0.0, &[h; MAX_HARMONICS]).is_ok());
    }
}
