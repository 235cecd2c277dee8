//! Engine-like cranking: a prescribed mean speed with a compression ripple per stroke.
//!
//! A cranking engine's speed swings with every compression stroke: the starter slows down
//! while a cylinder compresses and speeds up as it expands. The simulator prescribes it as a
//! speed law in angle and time,
//!
//! ω(φ, t) = ω̄(t) · (1 + a · sin(s·φ + ψ)),
//!
//! with ω̄(t) piecewise linear through given points (held after the last one): a start from
//! rest is a first point at 0 rad/s, a stall a last point at 0 rad/s. `s` is the number of
//! compression strokes per revolution (2 for a four-cylinder four-stroke engine on its crank),
//! `a` the relative ripple (0.4: ±40 % per stroke). The angle follows from dφ/dt = ω(φ, t),
//! integrated with the run's integrator and its dense output, so the encoder's edges are
//! located on the same law the truth is computed from. A speed law rather than torques: the
//! ripple is exactly what the scene asks for at every mean speed, and a stall is where the
//! scene puts it.
//!
//! Without a ripple (`a = 0`) the same law is a piecewise-linear prescribed speed.

use drive_monitor::error::{finite, non_negative, ConfigError};

/// The compression ripple: a · sin(strokes·φ + phase), relative to the mean speed.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ripple {
    /// Relative amplitude a, 0 ≤ a < 1.
    pub amplitude: f64,
    /// Compression strokes per revolution (cycles of the ripple per turn), > 0.
    pub strokes: f64,
    /// Phase ψ, rad.
    pub phase: f64,
}

/// A prescribed speed ω(φ, t) = ω̄(t)·(1 + ripple(φ)) (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct SpeedProfile {
    /// (t, ω̄) points, s and rad/s, in increasing time; ω̄ is linear between them, equal to
    /// the first point's before it and to the last point's after it.
    pub mean: Vec<(f64, f64)>,
    /// The compression ripple (none: ω = ω̄).
    pub ripple: Option<Ripple>,
}

/// Most points of a mean-speed profile.
pub const MAX_PROFILE_POINTS: usize = 10_000;

impl SpeedProfile {
    /// A constant-speed profile.
    pub fn constant(omega: f64) -> Self {
        SpeedProfile {
            mean: vec![(0.0, omega)],
            ripple: None,
        }
    }

    /// Checks the parameters: at least one point, times finite and strictly increasing, speeds
    /// finite and not negative (a cranking shaft does not turn backwards), `0 ≤ a < 1`,
    /// strokes positive.
    pub fn validate(&self) -> Result<(), ConfigError> {
        if self.mean.is_empty() || self.mean.len() > MAX_PROFILE_POINTS {
            return Err(ConfigError::OutOfRange("profile.points"));
        }
        for (i, &(t, w)) in self.mean.iter().enumerate() {
            finite("profile.time", t)?;
            non_negative("profile.speed", w)?;
            if i > 0 && t <= self.mean[i - 1].0 {
                return Err(ConfigError::Inconsistent("profile.time"));
            }
        }
        if let Some(r) = self.ripple {
            non_negative("ripple.amplitude", r.amplitude)?;
            if r.amplitude >= 1.0 {
                return Err(ConfigError::OutOfRange("ripple.amplitude"));
            }
            if !(r.strokes.is_finite() && r.strokes > 0.0) {
                return Err(ConfigError::NotPositive("ripple.strokes"));
            }
            finite("ripple.phase", r.phase)?;
        }
        Ok(())
    }

    /// The mean speed ω̄ at time `t`, rad/s.
    pub fn mean_at(&self, t: f64) -> f64 {
        let m = &self.mean;
        let Some(&(t0, w0)) = m.first() else {
            return 0.0;
        };
        if t <= t0 {
            return w0;
        }
        // The first point after t (binary search: profiles may be long).
        let k = m.partition_point(|&(tk, _)| tk <= t);
        match (m.get(k.wrapping_sub(1)), m.get(k)) {
            (Some(&(ta, wa)), Some(&(tb, wb))) => wa + (wb - wa) * (t - ta) / (tb - ta),
            (Some(&(_, wa)), None) => wa,
            _ => w0,
        }
    }

    /// The speed ω(φ, t), rad/s.
    pub fn omega(&self, phi: f64, t: f64) -> f64 {
        let mean = self.mean_at(t);
        match self.ripple {
            Some(r) => mean * (1.0 + r.amplitude * (r.strokes * phi + r.phase).sin()),
            None => mean,
        }
    }

    /// Times where ω̄ changes slope (the integrator steps onto them, so no step straddles a
    /// corner of the profile).
    pub fn breakpoints(&self) -> impl Iterator<Item = f64> + '_ {
        self.mean.iter().map(|&(t, _)| t)
    }

    /// The largest speed the profile reaches, rad/s.
    pub fn max_speed(&self) -> f64 {
        let peak = self.mean.iter().map(|&(_, w)| w).fold(0.0, f64::max);
        peak * (1.0 + self.ripple.map_or(0.0, |r| r.amplitude))
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn the_mean_is_piecewise_linear_and_held() {
        let p = SpeedProfile {
            mean: vec![(0.0, 0.0), (1.0, 20.0), (3.0, 20.0), (4.0, 0.0)],
            ripple: Some(Ripple {
                amplitude: 0.4,
                strokes: 2.0,
                phase: 0.0,
            }),
        };
        p.validate().unwrap();
        assert_eq!(p.mean_at(-1.0), 0.0);
        assert_eq!(p.mean_at(0.5), 10.0);
        assert_eq!(p.mean_at(2.0), 20.0);
        assert_eq!(p.mean_at(3.75), 5.0);
        assert_eq!(p.mean_at(9.0), 0.0);
        let phi = std::f64::consts::FRAC_PI_4; // sin(2φ) = 1
        assert!((p.omega(phi, 2.0) - 28.0).abs() < 1e-12);
        assert!((p.max_speed() - 28.0).abs() < 1e-12);
        let mut bad = p.clone();
        bad.mean.push((4.0, 1.0));
        assert_eq!(
            bad.validate(),
            Err(ConfigError::Inconsistent("profile.time"))
        );
        let mut bad = p;
        bad.ripple = Some(Ripple {
            amplitude: 1.0,
            strokes: 2.0,
            phase: 0.0,
        });
        assert_eq!(
            bad.validate(),
            Err(ConfigError::OutOfRange("ripple.amplitude"))
        );
    }
}
