//! The motor as an effect: the core's [`Motor`] characteristic M_d(ω) (seed 000, eq. 2–4)
//! applied to the shaft.
//!
//! The characteristic is defined once, in `drive_monitor::drive`; the simulator integrates
//! exactly the [`Motor::torque`] the prediction is built from (the Kloss curve itself when
//! the motor was built from one, the parabola otherwise).
//!
//! A motor held at a prescribed speed is not an effect: that is a prescribed shaft law
//! (`system::SpeedLaw`).

use drive_monitor::drive::Motor;

use crate::engine::model::{Effect, Shaft};

impl Effect for Motor {
    fn name(&self) -> &'static str {
        "motor"
    }
    fn eval(&self, _t: f64, shaft: Shaft, _y: &[f64], _dy: &mut [f64]) -> f64 {
        self.torque(shaft.omega)
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use drive_monitor::drive::{Kloss, KlossFit, Parabola};
    use drive_monitor::error::ConfigError;

    use super::*;

    fn torque(m: &Motor, omega: f64) -> f64 {
        m.eval(0.0, Shaft { phi: 1.0, omega }, &[], &mut [])
    }

    #[test]
    fn parabola_passes_through_its_two_points() {
        let p = Parabola::new(145.0, 36.0, 158.0).unwrap();
        let m = Motor::parabola(p);
        assert_eq!((m.name(), m.dim()), ("motor", 0));
        assert!(torque(&m, 145.0).abs() < 1e-12);
        assert!((torque(&m, 36.0) - 158.0).abs() < 1e-12);
        // Same curve as A ω² + B with B's corrected sign, and the same numbers as the core.
        let w = 120.0;
        assert!((p.a() * w * w + p.b() - torque(&m, w)).abs() < 1e-10);
        assert!(p.b() > 0.0);
        // Independent form M_m·(ω0² − ω²)/(ω0² − ω_m²).
        let exact = 158.0 * (145.0 * 145.0 - w * w) / (145.0 * 145.0 - 36.0 * 36.0);
        assert!((torque(&m, w) - exact).abs() < 1e-10);
        for w in [0.0, 50.0, 140.0, 150.0] {
            assert_eq!(torque(&m, w), m.torque(w));
        }
    }

    #[test]
    fn kloss_peaks_at_the_critical_slip() {
        // Slip convention σ = (ω0 − ω)/ω0, as in seed 000 eq. 2.
        let k = Kloss::new(157.08, 0.2, 200.0).unwrap();
        // The effect integrates the Kloss curve, not the fitted parabola.
        let m = Motor::kloss(k, KlossFit::Breakdown).unwrap();
        assert_eq!(torque(&m, 157.08), 0.0);
        let w_crit = 157.08 * (1.0 - 0.2);
        assert!((torque(&m, w_crit) - 200.0).abs() < 1e-10);
        for dw in [-1.0, 1.0] {
            assert!(torque(&m, w_crit + dw) < 200.0);
        }
        // Independent form 2·M_m·σ·σ_m/(σ² + σ_m²) at a working-branch speed, where the
        // fitted parabola differs from it.
        let w = 150.0;
        let s = (157.08 - w) / 157.08;
        let exact = 2.0 * 200.0 * s * 0.2 / (s * s + 0.04);
        assert!((torque(&m, w) - exact).abs() < 1e-10);
        assert!((m.model().torque(w) - exact).abs() > 1.0);
        // Above synchronous speed the machine brakes (generator).
        assert!(torque(&m, 160.0) < 0.0);
        assert_eq!(
            Kloss::new(157.08, 1.5, 200.0),
            Err(ConfigError::OutOfRange("breakdown_slip"))
        );
    }
}
