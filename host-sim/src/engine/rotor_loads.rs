//! Support loads of a rigid rotor with unbalances on two supports (seed 002), as output channels.
//!
//! # Model
//!
//! The rotor axis is `z`; supports A and B sit at `z_A` and `z_B` (either order, as in the core's
//! `drive_monitor::supports::Rotor`), signed span `L = z_B − z_A`.
//! Unbalance `i` (amount `D_i` = mass·eccentricity, kg·m) sits at axial position `z_i` and at
//! angle `α_i` on the rotor, so in the fixed frame its vector is
//! `D_i·e^{i(φ+α_i)}` (x, y components, the plane normal to the axis). Turning at speed `ω`
//! (and angular acceleration `ω̇`) it loads the rotor with the inertial force
//! `D_i·(ω²·e_r − ω̇·e_t)`, `e_r = e^{i(φ+α_i)}`, `e_t = i·e_r`.
//!
//! Force and moment balance of the rigid rotor split every transverse force `F` applied at `z`
//! onto the supports (what each support receives from the rotor, the bearing load):
//!
//! ```text
//! F_A = F·(z_B − z)/L,   F_B = F·(z − z_A)/L      (so F_A + F_B = F, z_A·F_A + z_B·F_B = z·F)
//! ```
//!
//! which holds for `z` outside the span too (overhung unbalance). Applied to the unbalances it
//! gives the support-plane unbalances of seed 002, eq. 5–7, `D_A = Σ D_i·(z_B − z_i)/L`,
//! `D_B = Σ D_i·(z_i − z_A)/L` (kg·m vectors in the rotor frame); the seed's split into static
//! `D_st·L_B/L`, `D_st·L_A/L` and moment parts `∓M_D/L` about any reference point is the same
//! sum regrouped (checked in the tests). Static loads (the rotor's weight at its centre of
//! mass, a distributed process load `q` in N/m over `[z_0, z_1]`, replaced by its resultant
//! `q·(z_1 − z_0)` at the middle) are split the same way once, at configuration. The support
//! loads at shaft angle `φ`:
//!
//! ```text
//! F_A(φ) = S_A + ω²·D_A·e^{iφ} − ω̇·i·D_A·e^{iφ}     (complex form, D_A in the rotor frame)
//! ```
//!
//! and likewise for B. At constant speed the largest load per turn is `|S_A| + ω²·|D_A|`.
//! [`RotorLoads`] is an [`Effect`] with no state and no torque (rigid supports, gravity torque
//! of the unbalance neglected); the simulator's output stage calls [`RotorLoads::reactions`] at
//! sampled times.

use crate::engine::model::{Effect, Shaft};
use drive_monitor::error::{finite, non_negative, ConfigError};
use serde::Deserialize;

/// One unbalance on the rotor.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct UnbalanceParams {
    /// Amount, kg·m (mass times eccentricity).
    pub amount: f64,
    /// Angle on the rotor, rad (measured from the rotor's reference mark).
    #[serde(default)]
    pub angle: f64,
    /// Axial position, m (same origin as the supports).
    pub z: f64,
}

/// A static (non-rotating) transverse load on the rotor.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum StaticLoadParams {
    /// A point force (e.g. the rotor's weight at its centre of mass).
    Point {
        /// Force (x, y), N.
        force: [f64; 2],
        /// Axial position, m.
        z: f64,
    },
    /// A uniform distributed load (e.g. the process load over the immersed length).
    Distributed {
        /// Intensity (x, y), N/m.
        intensity: [f64; 2],
        /// Start of the loaded length, m.
        from: f64,
        /// End of the loaded length, m.
        to: f64,
    },
}

/// The rotor, its supports and loads, as read from a scene file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RotorLoadsParams {
    /// Axial position of support A, m.
    pub support_a: f64,
    /// Axial position of support B, m (not `support_a`; either side of it).
    pub support_b: f64,
    /// The unbalances.
    #[serde(default)]
    pub unbalances: Vec<UnbalanceParams>,
    /// The static loads.
    #[serde(default)]
    pub static_loads: Vec<StaticLoadParams>,
}

/// Validated rotor-on-two-supports model; an [`Effect`] of dimension 0.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RotorLoads {
    /// Support-plane unbalances in the rotor frame, kg·m: `[D_A, D_B]`, each (x, y).
    support_unbalance: [[f64; 2]; 2],
    /// Static support loads, N: `[S_A, S_B]`.
    static_loads: [[f64; 2]; 2],
}

fn split(za: f64, zb: f64, f: [f64; 2], z: f64) -> [[f64; 2]; 2] {
    let l = zb - za;
    let (wa, wb) = ((zb - z) / l, (z - za) / l);
    [[f[0] * wa, f[1] * wa], [f[0] * wb, f[1] * wb]]
}

fn add(acc: &mut [[f64; 2]; 2], s: [[f64; 2]; 2]) {
    for (a, b) in acc.iter_mut().zip(s) {
        a[0] += b[0];
        a[1] += b[1];
    }
}

impl RotorLoads {
    /// Validates `p`: finite values, `support_b ≠ support_a` (either order: the split below uses
    /// the signed span, as the core's `Rotor` does), non-negative amounts, `to ≥ from`.
    pub fn new(p: &RotorLoadsParams) -> Result<Self, ConfigError> {
        let za = finite("support_a", p.support_a)?;
        let zb = finite("support_b", p.support_b)?;
        if zb == za {
            return Err(ConfigError::Inconsistent("support_b"));
        }
        let mut support_unbalance = [[0.0; 2]; 2];
        for u in &p.unbalances {
            let d = non_negative("unbalances.amount", u.amount)?;
            let a = finite("unbalances.angle", u.angle)?;
            let z = finite("unbalances.z", u.z)?;
            add(
                &mut support_unbalance,
                split(za, zb, [d * a.cos(), d * a.sin()], z),
            );
        }
        let mut static_loads = [[0.0; 2]; 2];
        for s in &p.static_loads {
            let (f, z) = match *s {
                StaticLoadParams::Point { force, z } => (
                    [
                        finite("static_loads.force", force[0])?,
                        finite("static_loads.force", force[1])?,
                    ],
                    finite("static_loads.z", z)?,
                ),
                StaticLoadParams::Distributed {
                    intensity,
                    from,
                    to,
                } => {
                    let (z0, z1) = (
                        finite("static_loads.from", from)?,
                        finite("static_loads.to", to)?,
                    );
                    if z1 < z0 {
                        return Err(ConfigError::Inconsistent("static_loads.to"));
                    }
                    let len = z1 - z0;
                    (
                        [
                            finite("static_loads.intensity", intensity[0])? * len,
                            finite("static_loads.intensity", intensity[1])? * len,
                        ],
                        0.5 * (z0 + z1),
                    )
                }
            };
            add(&mut static_loads, split(za, zb, f, z));
        }
        Ok(RotorLoads {
            support_unbalance,
            static_loads,
        })
    }

    /// Support-plane unbalances `[D_A, D_B]` in the rotor frame, kg·m (seed 002, eq. 7).
    pub fn support_unbalances(&self) -> [[f64; 2]; 2] {
        self.support_unbalance
    }

    /// Static support loads `[S_A, S_B]`, N.
    pub fn static_reactions(&self) -> [[f64; 2]; 2] {
        self.static_loads
    }

    /// Loads each support receives from the rotor, `[[F_Ax, F_Ay], [F_Bx, F_By]]` in N, at
    /// shaft state `shaft` and constant speed.
    pub fn reactions(&self, shaft: Shaft) -> [[f64; 2]; 2] {
        self.reactions_accelerating(shaft, 0.0)
    }

    /// As [`RotorLoads::reactions`] with the shaft's angular acceleration `omega_dot` (rad/s²),
    /// which adds the tangential inertial force `−ω̇·i·D·e^{iφ}`.
    pub fn reactions_accelerating(&self, shaft: Shaft, omega_dot: f64) -> [[f64; 2]; 2] {
        let (s, c) = shaft.phi.sin_cos();
        let w2 = shaft.omega * shaft.omega;
        let mut out = self.static_loads;
        for (o, d) in out.iter_mut().zip(&self.support_unbalance) {
            // Rotor-frame vector turned to the fixed frame.
            let (x, y) = (d[0] * c - d[1] * s, d[0] * s + d[1] * c);
            o[0] += w2 * x + omega_dot * y;
            o[1] += w2 * y - omega_dot * x;
        }
        out
    }

    /// Largest load per turn on each support at constant speed `omega`, N:
    /// `|S| + ω²·|D|` (the rotating part lines up with the static part once a turn).
    pub fn peak_loads(&self, omega: f64) -> [f64; 2] {
        let w2 = omega * omega;
        let mut out = [0.0; 2];
        for ((o, s), d) in out
            .iter_mut()
            .zip(&self.static_loads)
            .zip(&self.support_unbalance)
        {
            *o = s[0].hypot(s[1]) + w2 * d[0].hypot(d[1]);
        }
        out
    }
}

impl Effect for RotorLoads {
    fn name(&self) -> &'static str {
        "rotor_loads"
    }
    fn eval(&self, _t: f64, _shaft: Shaft, _y: &[f64], _dy: &mut [f64]) -> f64 {
        0.0
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn params() -> RotorLoadsParams {
        RotorLoadsParams {
            support_a: 0.0,
            support_b: 2.0,
            unbalances: vec![
                UnbalanceParams {
                    amount: 0.01,
                    angle: 0.0,
                    z: 0.5,
                },
                UnbalanceParams {
                    amount: 0.02,
                    angle: core::f64::consts::FRAC_PI_2,
                    z: 3.0, // overhung, beyond B
                },
            ],
            static_loads: vec![
                StaticLoadParams::Point {
                    force: [0.0, -981.0],
                    z: 1.0,
                },
                StaticLoadParams::Distributed {
                    intensity: [0.0, -300.0],
                    from: 0.0,
                    to: 1.0,
                },
            ],
        }
    }

    #[test]
    fn hand_computed_case() {
        let r = RotorLoads::new(&params()).unwrap();
        // D_A = 0.01·(1.5/2)·(1,0) + 0.02·(−1/2)·(0,1) = (0.0075, −0.01)
        // D_B = 0.01·(0.5/2)·(1,0) + 0.02·(3/2)·(0,1)  = (0.0025, 0.03)
        let d = r.support_unbalances();
        let want = [[0.0075, -0.01], [0.0025, 0.03]];
        for i in 0..2 {
            for k in 0..2 {
                assert!((d[i][k] - want[i][k]).abs() < 1e-15, "{d:?}");
            }
        }
        // Static: weight 981 N at mid-span splits evenly; process load 300 N at z = 0.5 splits
        // 225 / 75.
        let s = r.static_reactions();
        assert!((s[0][1] + 490.5 + 225.0).abs() < 1e-12 && (s[1][1] + 490.5 + 75.0).abs() < 1e-12);
        // At φ = π/2, ω = 100: D_A turns to (0.01, 0.0075), times ω² = 1e4.
        let f = r.reactions(Shaft {
            phi: core::f64::consts::FRAC_PI_2,
            omega: 100.0,
        });
        assert!((f[0][0] - 100.0).abs() < 1e-9 && (f[0][1] - (75.0 - 715.5)).abs() < 1e-9);
        assert!((f[1][0] + 300.0).abs() < 1e-9 && (f[1][1] - (25.0 - 565.5)).abs() < 1e-9);
        let pk = r.peak_loads(100.0);
        assert!((pk[0] - (715.5 + 125.0)).abs() < 1e-9);
    }

    #[test]
    fn force_and_moment_balance() {
        let p = params();
        let r = RotorLoads::new(&p).unwrap();
        for &(phi, omega, wdot) in &[(0.3, 50.0, 0.0), (2.0, 120.0, 40.0), (-1.0, 7.0, -300.0)] {
            let f = r.reactions_accelerating(Shaft { phi, omega }, wdot);
            // Applied forces: unbalances D(ω²e_r − ω̇e_t) plus static resultants.
            let (mut fx, mut fy, mut mx, mut my) = (0.0, 0.0, 0.0, 0.0);
            for u in &p.unbalances {
                let a = phi + u.angle;
                let gx = u.amount * (omega * omega * a.cos() + wdot * a.sin());
                let gy = u.amount * (omega * omega * a.sin() - wdot * a.cos());
                fx += gx;
                fy += gy;
                mx += gx * u.z;
                my += gy * u.z;
            }
            fy += -981.0 - 300.0;
            my += -981.0 * 1.0 - 300.0 * 0.5;
            let sum = [f[0][0] + f[1][0], f[0][1] + f[1][1]];
            let mom = [2.0 * f[1][0], 2.0 * f[1][1]]; // about A (z_A = 0)
            let scale = 1.0 + fx.abs() + fy.abs();
            assert!((sum[0] - fx).abs() < 1e-12 * scale && (sum[1] - fy).abs() < 1e-12 * scale);
            assert!((mom[0] - mx).abs() < 1e-12 * scale && (mom[1] - my).abs() < 1e-12 * scale);
        }
    }

    #[test]
    fn static_plus_moment_split_of_seed_002() {
        // Seed 002, eq. 5–7: D_A = D_st·L_B/L − M_D/L, D_B = D_st·L_A/L + M_D/L about any
        // reference point z_c (the seed uses the centre of mass).
        let p = params();
        let r = RotorLoads::new(&p).unwrap();
        for &zc in &[0.8, 1.3, -0.4] {
            let (la, lb, l) = (
                zc - p.support_a,
                p.support_b - zc,
                p.support_b - p.support_a,
            );
            let mut dst = [0.0; 2];
            let mut md = [0.0; 2];
            for u in &p.unbalances {
                let v = [u.amount * u.angle.cos(), u.amount * u.angle.sin()];
                for k in 0..2 {
                    dst[k] += v[k];
                    md[k] += (u.z - zc) * v[k];
                }
            }
            let d = r.support_unbalances();
            for k in 0..2 {
                assert!((d[0][k] - (dst[k] * lb / l - md[k] / l)).abs() < 1e-15);
                assert!((d[1][k] - (dst[k] * la / l + md[k] / l)).abs() < 1e-15);
            }
        }
    }

    #[test]
    fn supports_in_either_order() {
        // The core's Rotor (and so `predict`) takes the supports in either order; so does the
        // simulation: swapping the positions swaps the supports' loads.
        let p = params();
        let mut q = params();
        (q.support_a, q.support_b) = (p.support_b, p.support_a);
        let (r, s) = (RotorLoads::new(&p).unwrap(), RotorLoads::new(&q).unwrap());
        let shaft = Shaft {
            phi: 0.7,
            omega: 80.0,
        };
        let (f, g) = (r.reactions(shaft), s.reactions(shaft));
        for k in 0..2 {
            assert!((f[0][k] - g[1][k]).abs() < 1e-9 && (f[1][k] - g[0][k]).abs() < 1e-9);
        }
    }

    #[test]
    fn rejects_bad_scenes() {
        let mut p = params();
        p.support_b = 0.0;
        assert_eq!(
            RotorLoads::new(&p),
            Err(ConfigError::Inconsistent("support_b"))
        );
        let mut p = params();
        p.unbalances[0].amount = -1.0;
        assert_eq!(
            RotorLoads::new(&p),
            Err(ConfigError::Negative("unbalances.amount"))
        );
        let bad: Result<RotorLoadsParams, _> =
            toml::from_str("support_a = 0.0\nsupport_b = 1.0\nspeed = 3.0\n");
        assert!(bad.unwrap_err().to_string().contains("speed"));
        let ok: RotorLoadsParams = toml::from_str(
            "support_a = 0.0\nsupport_b = 1.0\n[[unbalances]]\namount = 0.01\nz = 0.5\n\
             [[static_loads]]\ntype = \"distributed\"\nintensity = [0.0, -10.0]\nfrom = 0.0\nto = 1.0\n",
        )
        .unwrap();
        assert_eq!(ok.unbalances.len(), 1);
        assert_eq!(ok.static_loads.len(), 1);
    }
}
