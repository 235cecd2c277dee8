//! Readable text reports.

use crate::predict::Prediction;
use std::fmt::Write;

/// The design-time results as text.
pub fn prediction_text(p: &Prediction) -> String {
    let mut s = String::new();
    if let Some(i) = &p.irregularity {
        let _ = writeln!(
            s,
            "Predicted running irregularity (steady state, seed 000 eq. 11–13)"
        );
        if i.steady_state {
            let _ = writeln!(
                s,
                "  ω max {:.3} rad/s, ω min {:.3} rad/s, δ = {:.6}",
                i.omega_max, i.omega_min, i.delta
            );
        } else {
            let _ = writeln!(s, "  no steady state: the motor stalls under the peak load");
        }
        match i.flywheel_for_limit {
            Some(Some(j)) if j > 0.0 => {
                let _ = writeln!(s, "  flywheel for the δ limit: add {j:.4} kg·m²");
            }
            Some(Some(_)) => {
                let _ = writeln!(s, "  within the δ limit without a flywheel");
            }
            Some(None) => {
                let _ = writeln!(s, "  no flywheel reaches the δ limit");
            }
            None => {}
        }
        if let (Some(dj), Some(dm)) = (i.d_delta_d_inertia, i.d_delta_d_breakdown_torque) {
            let _ = writeln!(
                s,
                "  ∂δ/∂J = {dj:.4e} per kg·m², ∂δ/∂M_m = {dm:.4e} per N·m"
            );
        }
    }
    if let Some(u) = &p.supports {
        let _ = writeln!(s, "Support unbalance (seed 002) and limits (ISO 21940-11)");
        let _ = writeln!(
            s,
            "  equivalent unbalance: A {:.4e} kg·m (permissible {:.4e}), B {:.4e} kg·m (permissible {:.4e})",
            u.unbalance_a, u.permissible_a, u.unbalance_b, u.permissible_b
        );
        let _ = writeln!(
            s,
            "  static loads A {:.1} N, B {:.1} N; peak at service speed A {:.1} N, B {:.1} N",
            u.static_load[0],
            u.static_load[1],
            u.peak_load_at_service_speed[0],
            u.peak_load_at_service_speed[1]
        );
        match u.max_speed {
            Some(w) => {
                let _ = writeln!(s, "  maximum safe speed {w:.1} rad/s");
            }
            None => {
                let _ = writeln!(s, "  maximum safe speed: not limited by the support loads");
            }
        }
    }
    if let Some(a) = &p.autobalancer {
        let _ = writeln!(s, "Auto-balancer regimes (seed 001)");
        let list = |v: &[f64]| {
            v.iter()
                .map(|x| format!("{x:.3}"))
                .collect::<Vec<_>>()
                .join(", ")
        };
        let _ = writeln!(
            s,
            "  resonant speeds (undamped): {} rad/s",
            list(&a.resonant_speeds)
        );
        if !a.additional_speeds.is_empty() {
            let _ = writeln!(
                s,
                "  additional speeds (undamped): {} rad/s",
                list(&a.additional_speeds)
            );
        }
        for z in &a.zones {
            match z.to {
                Some(to) => {
                    let _ = writeln!(s, "  {:>9.3} – {:<9.3} rad/s  {}", z.from, to, z.regime);
                }
                None => {
                    let _ = writeln!(s, "  {:>9.3} – ∞         rad/s  {}", z.from, z.regime);
                }
            }
        }
        for c in &a.capture {
            let _ = writeln!(
                s,
                "  capture possible from {:.3} up to {:.3} rad/s (loads held near {:.3} rad/s)",
                c.from, c.until, c.at
            );
        }
    }
    s
}
