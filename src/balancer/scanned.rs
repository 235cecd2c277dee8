//! The reference zone and capture search by scanning ([`Machine::new_scanned`]): the
//! algorithm `Machine::new` used before the zones were built from polynomial roots, kept
//! unchanged so the faster search can be compared against it. It evaluates the pivoted
//! solve at every scan node: thousands of solves and `pow` calls for three platforms, tens of
//! millions of instructions on a Cortex-M4F in soft-float f64.
//!
//! # Zone search
//!
//! The sign of `g(ω) = Re H_ee(ω)` ([`System::criterion`]: a pivoted solve of `Z·y = e_e`, not
//! the determinant form, whose roots degrade at double poles) is evaluated on the system
//! scaled to unit largest mass and stiffness (no overflow for any units). `g(0) > 0`
//! (static compliance); undamped, `g` also changes sign at its poles. The scan nodes are `0`,
//! then, in each interval between consecutive undamped characteristic speeds (from `10⁻³·` the
//! lowest to `max_factor·` the highest), `nodes_per_interval` log-spaced nodes, so every
//! undamped zone is sampled inside however narrow it is. Each sign change is bisected to a relative bracket width `rel_tol`. Above the
//! scan `g < 0` is required (at high speed `H_ee → −1/(M_eΣ·ω²)`); if not, the scan is
//! extended by doubling. Pairs of boundaries closer than `1e3·rel_tol` (relative) are
//! dropped: such a zone is below the resolution of the search (a pole and a zero that
//! nearly cancel).

use super::damped::{capture_lag, characteristic, scaled, Boundaries, Scaled};
use super::modal::System;
use super::{CaptureWindow, ConfigError, Machine, MachineConfig, SearchOptions, ZoneKind};

fn gathering(sys: &System, w: f64) -> bool {
    sys.criterion(w) > 0.0
}

/// Bisection of a sign change of `pred` on `[lo, hi]` to relative width `tol`.
pub(crate) fn bisect(mut lo: f64, mut hi: f64, tol: f64, pred: impl Fn(f64) -> bool) -> f64 {
    let at_lo = pred(lo);
    for _ in 0..400 {
        if hi - lo <= tol * hi {
            break;
        }
        let mid = lo + 0.5 * (hi - lo);
        if mid <= lo || mid >= hi {
            break;
        }
        if pred(mid) == at_lo {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    lo + 0.5 * (hi - lo)
}

/// Scans `[a, b]` with `nodes` log-spaced steps, continuing from the state `(w, sign)` of
/// the previous node; records bisected sign changes.
fn scan(
    sys: &System,
    prev: &mut (f64, bool),
    a: f64,
    b: f64,
    nodes: u16,
    tol: f64,
    out: &mut Boundaries,
) -> Result<(), ConfigError> {
    let ratio = b / a;
    for i in 0..=nodes {
        let w = if i == nodes {
            b
        } else {
            a * libm::pow(ratio, f64::from(i) / f64::from(nodes))
        };
        if w <= prev.0 {
            continue;
        }
        let s = gathering(sys, w);
        if s != prev.1 {
            let root = bisect(prev.0, w, tol, |x| gathering(sys, x));
            out.push(root)?;
        }
        *prev = (w, s);
    }
    Ok(())
}

pub(crate) fn find_zones(
    sys_si: &System,
    m: &mut Machine,
    opt: &SearchOptions,
) -> Result<(), ConfigError> {
    let Scaled { sys, w_s, .. } = scaled(sys_si);
    let (chars, n_chars) = characteristic(m, w_s);
    let nodes = opt.nodes_per_interval;
    let tol = opt.rel_tol;
    let mut out = Boundaries::EMPTY;
    let first = chars.first().copied().unwrap_or(1.0);
    let mut prev = (0.0, gathering(&sys, 0.0));
    let mut a = first * 1e-3;
    for &c in chars.iter().take(n_chars) {
        if c > a {
            scan(&sys, &mut prev, a, c, nodes, tol, &mut out)?;
            a = c;
        }
    }
    let mut top = a * opt.max_factor;
    scan(&sys, &mut prev, a, top, nodes, tol, &mut out)?;
    let mut doublings = 0;
    while prev.1 && doublings < 60 {
        scan(&sys, &mut prev, top, 2.0 * top, nodes, tol, &mut out)?;
        top *= 2.0;
        doublings += 1;
    }
    if prev.1 {
        return Err(ConfigError::Inconsistent("zone search"));
    }
    out.into_zones(m, tol, sys.n, w_s)
}

/// `Ω + D(Ω)`: the rotor speed that holds gathered loads at `Ω`.
fn rotor_speed_for(sys: &System, cfg: &MachineConfig, load_speed: f64) -> f64 {
    load_speed + capture_lag(sys, cfg, load_speed)
}

pub(crate) fn find_captures(sys: &System, m: &mut Machine, opt: &SearchOptions) {
    let cfg = m.config;
    let nodes = u32::from(opt.nodes_per_interval);
    let mut n = 0;
    let zones = m.zones;
    for z in zones.iter().take(usize::from(m.n_zones)).copied() {
        let (ZoneKind::Gathering, Some(b)) = (z.kind, z.to) else {
            continue;
        };
        let a = z.from.max(b * 1e-3);
        let node = |i: u32| a * libm::pow(b / a, f64::from(i) / f64::from(nodes));
        let mut best = (b, rotor_speed_for(sys, &cfg, b));
        let mut best_i = nodes;
        for i in 0..nodes {
            let x = node(i);
            let v = rotor_speed_for(sys, &cfg, x);
            if v > best.1 {
                best = (x, v);
                best_i = i;
            }
        }
        if best_i < nodes {
            // Golden-section refinement between the neighbouring nodes.
            let mut lo = node(best_i.saturating_sub(1));
            let mut hi = node(best_i + 1);
            let g = 0.5 * (libm::sqrt(5.0) - 1.0);
            for _ in 0..200 {
                if hi - lo <= 1e-12 * hi {
                    break;
                }
                let x1 = hi - g * (hi - lo);
                let x2 = lo + g * (hi - lo);
                if rotor_speed_for(sys, &cfg, x1) >= rotor_speed_for(sys, &cfg, x2) {
                    hi = x2;
                } else {
                    lo = x1;
                }
            }
            let x = 0.5 * (lo + hi);
            let v = rotor_speed_for(sys, &cfg, x);
            if v > best.1 {
                best = (x, v);
            }
        }
        if best.1 <= b * (1.0 + super::MIN_CAPTURE_WIDTH) {
            continue;
        }
        if let Some(slot) = m.captures.get_mut(n) {
            *slot = CaptureWindow {
                from: b,
                until: best.1,
                at: best.0,
            };
            n += 1;
        }
    }
    m.n_captures = n as u8;
}
