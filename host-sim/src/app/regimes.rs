//! The exact regime table of a scene's vibration machine, computed at design time on the host
//! and shipped to the target as data ([`drive_monitor::balancer::RegimeTable`]).
//!
//! Three things decide the regime at a rotor speed `ω`:
//!
//! 1. **Is the balancing position stable?** From the Floquet multipliers of the model
//!    linearised about the balanced motion ([`crate::engine::vibration::floquet`]), scanned and
//!    bisected to 1e-7 relative by [`stability_map`]. Exact for the model; it depends on the
//!    rotor unbalance `D`, which fixes the loads' balancing angles.
//! 2. **Can gathered loads stay captured below the rotor?** The core's capture windows
//!    ([`Machine::capture_windows`]): `ω` in `[from, until)` of a window below.
//! 3. **Does the criterion say gathered loads hold together?** The seed's criterion
//!    ([`Machine::zones`]): `Re H(ω) > 0`.
//!
//! The table ([`table`]) commits to `Gathering` where the balancing position is unstable (the
//! loads cannot balance, whatever their history: for two loads the balancing position is
//! unique; for more, see below), to `Balancing` where it is stable and neither (2)
//! nor (3) holds, and says `Bistable(Capture)` where it is stable and (2) holds,
//! `Bistable(Coexisting)` where it is stable and only (3) holds. Below the scanned range the
//! class at its lowest speed is kept, above it the class at its highest (the scan reaches
//! past every characteristic speed and capture window up to the fastest speed a scene turns,
//! [`crate::app::check::MAX_SPEED`], and is extended until the balancing position is stable at
//! its top or it reaches that speed).
//!
//! The scan starts at a quarter of the lowest resonance, or higher where a revolution there
//! would last more than [`crate::engine::vibration::floquet::REVOLUTION_RATIO`] periods of the machine's fastest motion
//! ([`crate::engine::vibration::floquet::lowest_speed`]: a machine hung only on its couplings, its rigid-body resonance
//! near 1e-4 rad/s and its couplings' at 45 rad/s, took over a million integration steps for
//! one revolution there), and higher still where the scan from there would take more than half
//! its step budget ([`stability_map`]: a lightly damped fast motion takes some 17 steps a
//! period). Below that speed the table follows the criterion's zones
//! ([`Exact::criterion_below`], said by `predict`), as the criterion's own table does.
//!
//! Where the multiplier of the loads' slow drift along what is a family of balancing
//! positions at `D = 0` cannot be told from 1 (a tiny `D`: it is `1 − O(D²)`), it is treated as
//! neutral, as at `D = 0`, and the map says where ([`StabilityMap::unresolved`], shown by
//! `predict`; see [`crate::engine::vibration::floquet`]).
//!
//! For `N ≥ 3` loads the balancing positions form a family. Stability is decided for the
//! equally spaced fan (the simulator's start) and for [`FAMILY_MEMBERS`] other members
//! ([`family_members`]); where the fan is unstable but a member is stable the loads can balance
//! there or gather, and the table says `Bistable(Family)`, committing to `Gathering` only where
//! every member analysed is unstable. Limits: members between those sampled are not analysed;
//! a balancer too small for its rotor (`D > N·m·R`) has no balancing
//! position, so it has no exact table ([`Design::exact`] is `None`) and the criterion's table
//! is used, its `Balancing` meaning the loads sit at their limit opposite the unbalance
//! ([`Design::residual_floor`]).

use crate::app::predict::value_error;
use crate::app::run::vibration_params;
use crate::app::scene::{Scene, SceneError};
use crate::engine::vibration::floquet::{golden, Floquet, ScanOptions, StabilityMap, SCAN_STEPS};
use crate::engine::vibration::VibrationMachine;
use drive_monitor::balancer::{
    BistableReason, CaptureWindow, Classifier, Machine, Regime, RegimeSegment, RegimeStatus,
    RegimeTable, RegimeTracker, ZoneKind, DEFAULT_MARGIN, TABLE_MARGIN,
};
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// What the design-time analysis of a scene's auto-balancer found.
#[derive(Debug, Clone, Serialize)]
pub struct Design {
    /// `N·m·R`: the largest unbalance the loads can balance, kg·m.
    pub capacity: f64,
    /// The rotor's unbalance `D` the loads are to balance, kg·m.
    pub rotor_unbalance: f64,
    /// The least residual unbalance the loads can leave, `max(0, D − N·m·R)`, kg·m: 0 when
    /// they can balance the rotor; else with every load at its limit opposite the unbalance.
    pub residual_floor: f64,
    /// The exact stability and regime table (`None` without a balancing position: fewer than
    /// two loads, or `D > N·m·R`).
    pub exact: Option<Exact>,
}

/// The exact stability of the balancing position and the regime table built on it.
#[derive(Debug, Clone, Serialize)]
pub struct Exact {
    /// Where the balancing position is stable (Floquet).
    pub map: StabilityMap,
    /// The regime table, segments `(from rad/s, regime)` ascending from 0.
    #[serde(skip)]
    pub segments: Vec<(f64, Regime)>,
    /// The criterion's boundaries beside the exact ones.
    pub comparison: Vec<Comparison>,
    /// Three or more loads: the members of their family of balancing positions analysed
    /// beside the equally spaced fan ([`family_members`]); 0 for two loads.
    pub family_members: usize,
    /// Where each of those members is stable (Floquet, the fan's scan settings), scanned over
    /// the fan's unstable intervals only (elsewhere the table does not ask); empty where the
    /// fan is stable throughout.
    #[serde(skip)]
    pub family: Vec<StabilityMap>,
    /// Where the scan starts above a quarter of the lowest resonance because a revolution
    /// below would take too many integration steps; the table follows the criterion below.
    pub criterion_below: Option<CriterionBelow>,
}

/// The speed below which the exact analysis cannot integrate a revolution, and why.
#[derive(Debug, Clone, Serialize)]
pub struct CriterionBelow {
    /// The lowest speed analysed exactly, rad/s ([`crate::engine::vibration::floquet::lowest_speed`]).
    pub speed: f64,
    /// The bound on the machine's fastest motion it comes from, rad/s.
    pub fastest_rate: f64,
    /// What sets that motion (scene keys).
    pub set_by: String,
}

/// A boundary of the seed criterion's zones and the exact boundary of the same kind nearest
/// to it.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Comparison {
    /// The criterion's boundary (a damped characteristic speed), rad/s.
    pub criterion: f64,
    /// "resonance" (gathering below, balancing above) or "additional" (the reverse).
    pub kind: &'static str,
    /// The nearest exact boundary where the balancing position becomes stable (resonance) or
    /// unstable (additional), rad/s; `None` if there is none.
    pub exact: Option<f64>,
    /// `exact/criterion − 1`.
    pub difference: Option<f64>,
}

/// The scene's vibration machine as the simulator builds it (the loads at the balancing
/// position; `None` without an auto-balancer).
pub fn vibration_machine(
    scene: &Scene,
    file: &Path,
) -> Result<Option<VibrationMachine>, SceneError> {
    let Some(p) = vibration_params(scene, false, 0.0) else {
        return Ok(None);
    };
    VibrationMachine::new(&p)
        .map(Some)
        .map_err(|e| value_error(file, "autobalancer", e))
}

/// The growth rate σ (1/s) of the least stable perturbation of the balancing position at
/// `speed` rad/s (Floquet, at the tolerance of `exact`'s map): positive where it is unstable.
/// A run shows its regime only after several `1/|σ|` (see [`settle_time`]).
pub fn growth_rate(
    scene: &Scene,
    file: &Path,
    exact: &Exact,
    speed: f64,
) -> Result<Option<f64>, SceneError> {
    let Some(vm) = vibration_machine(scene, file)? else {
        return Ok(None);
    };
    let Ok(f) = Floquet::new(&vm) else {
        return Ok(None);
    };
    f.multipliers(speed, exact.map.options.rtol)
        .map(|m| Some(m.growth_rate()))
        .map_err(|e| SceneError::value(file, "autobalancer", e.to_string()))
}

/// How long a run at a speed with growth rate `sigma` (1/s) takes to show its regime:
/// `10/|σ|`, ten e-foldings of the least stable perturbation (as the criterion study runs),
/// seconds; infinite at `σ = 0`.
pub fn settle_time(sigma: f64) -> f64 {
    10.0 / sigma.abs()
}

/// Relative distance within which a resonant and an additional speed are one speed
/// ([`excited_speeds`]). The core finds a double root to 1e-14 (a symmetric chain's
/// antisymmetric mode); nearly equal partial frequencies (1e-6 apart) leave a narrow but real
/// resonance, kept.
const CANCEL_RTOL: f64 = 1e-9;

/// The undamped characteristic speeds the rotor excites: the machine's resonant and additional
/// speeds with every pair of equal ones cancelled. A mode with a node at the balancer's
/// platform (platforms 1 and 3 of a symmetric chain swinging against each other, platform 2 at
/// rest) is an eigenfrequency of the machine and of the machine with that platform held: a
/// pole and a zero of the platform's receptance at once, which cancel. The rotor does not
/// excite that mode, and `Re H` changes sign there only as often as the zeros outnumber the
/// poles (the symmetric chain: once, where the seed's lists hold the speed three times).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ExcitedSpeeds {
    /// Resonant speeds the rotor excites, ascending, rad/s.
    pub resonant: Vec<f64>,
    /// Additional speeds (zeros of the receptance) left after cancelling, ascending, rad/s.
    pub additional: Vec<f64>,
    /// The speeds of the cancelled pairs (a resonance and an additional speed each),
    /// ascending, rad/s.
    pub cancelled: Vec<f64>,
}

/// [`ExcitedSpeeds`] of `machine`: each resonant speed paired with an unpaired additional
/// speed within [`CANCEL_RTOL`] of it, both dropped.
pub fn excited_speeds(machine: &Machine) -> ExcitedSpeeds {
    let mut additional: Vec<f64> = machine.additional_speeds().to_vec();
    let mut out = ExcitedSpeeds::default();
    for &r in machine.resonant_speeds() {
        let pair = additional
            .iter()
            .position(|&a| (a - r).abs() <= CANCEL_RTOL * r.abs().max(a.abs()));
        match pair {
            Some(k) => {
                additional.remove(k);
                out.cancelled.push(r);
            }
            None => out.resonant.push(r),
        }
    }
    out.additional = additional;
    out
}

/// Log-spaced nodes per capture band search ([`resonance_captures`]).
const CAPTURE_NODES: usize = 2000;

/// Sommerfeld capture at every resonance, whether or not the criterion has a gathering zone
/// ending there: for each undamped resonant speed `r`, the highest interior local maximum of
/// `Ω + D(Ω)` ([`Machine::capture_lag`], every load gathered) over `Ω` between the additional
/// speeds either side of `r` (from `10⁻³·r` below the first, to `16·r` above the last), as a
/// window from `min(r, Ω*)` to that maximum. The core's windows ([`Machine::capture_windows`])
/// take the maximum only inside a gathering zone; where damping removes the sign change of
/// `Re H` at a higher resonance there is no zone, but loads a run-up brings there are still
/// captured (a two-platform machine with resonances at 49.6 and 124.2 rad/s kept them turning
/// near 115–122 rad/s with the rotor at 165 for 335 s, where the balancing position is stable).
/// No window where `Ω + D(Ω)` has no interior maximum (it only rises: a slip in proportion
/// to the speed, no capture).
pub fn resonance_captures(machine: &Machine) -> Vec<CaptureWindow> {
    // Only the resonances the rotor excites, bracketed by the zeros left ([`excited_speeds`]):
    // a cancelled one, bracketed by nothing, copied the first resonance's window.
    let ExcitedSpeeds {
        resonant,
        additional: extra,
        ..
    } = excited_speeds(machine);
    let f = |w: f64| w + machine.capture_lag(w);
    let mut out = Vec::new();
    for &r in &resonant {
        if !(r.is_finite() && r > 0.0) {
            continue;
        }
        let lo = extra
            .iter()
            .copied()
            .filter(|&a| a < r)
            .fold(1e-3 * r, f64::max);
        let hi = extra
            .iter()
            .copied()
            .filter(|&a| a > r)
            .fold(16.0 * r, f64::min);
        let node = |i: usize| lo * (hi / lo).powf(i as f64 / CAPTURE_NODES as f64);
        let values: Vec<f64> = (0..=CAPTURE_NODES).map(|i| f(node(i))).collect();
        // The highest interior local maximum of the scan (NaN, on a resonance, is none).
        let best = (1..CAPTURE_NODES)
            .filter(|&i| values[i] >= values[i - 1] && values[i] >= values[i + 1])
            .filter(|&i| values[i].is_finite())
            .max_by(|&a, &b| values[a].total_cmp(&values[b]));
        let Some(i) = best else {
            continue;
        };
        // Golden-section search between the neighbouring nodes (a unimodal bracket; its log
        // width, under 0.01, falls below 1e-12 in 48 steps).
        let (at, top) = golden(node(i - 1), node(i + 1), 48, |w| {
            Ok::<_, core::convert::Infallible>(f(w))
        })
        .unwrap_or_else(|e| match e {});
        let until = top.max(values[i]);
        if until.is_finite() && until > r * (1.0 + drive_monitor::balancer::MIN_CAPTURE_WIDTH) {
            out.push(CaptureWindow {
                from: r.min(at),
                until,
                at,
            });
        }
    }
    out
}

/// Every capture window the exact table heeds: the core's ([`Machine::capture_windows`]) and
/// those at every resonance ([`resonance_captures`]).
pub fn capture_bands(machine: &Machine) -> Vec<CaptureWindow> {
    let mut all = machine.capture_windows().to_vec();
    all.extend(resonance_captures(machine));
    all
}

/// The speeds scanned for `machine`: from a quarter of its lowest resonance to four times its
/// highest characteristic speed, and at least 1.5 times past every capture window.
pub fn scan_options(machine: &Machine) -> ScanOptions {
    let first = machine
        .resonant_speeds()
        .first()
        .copied()
        .unwrap_or(machine.config().dimensionless().omega_ref);
    let last = machine.zones().last().map_or(first, |z| z.from).max(first);
    let until = capture_bands(machine)
        .iter()
        .fold(0.0f64, |u, w| u.max(w.until));
    ScanOptions::new(0.25 * first, (4.0 * last).max(1.5 * until))
}

/// The stability map of `floquet` over [`scan_options`], its top extended (doubled, up to
/// four times) while the balancing position is still unstable there, and its bottom raised to
/// [`crate::engine::vibration::floquet::lowest_speed`] where that is higher (returned: the
/// table follows the criterion below it), its top then at least four times that. The top is
/// never above [`crate::app::check::MAX_SPEED`], the fastest a scene turns, unless the bottom
/// is within two octaves of it (then four times the bottom).
pub fn stability_map(
    floquet: &Floquet,
    machine: &Machine,
    file: &Path,
) -> Result<(StabilityMap, Option<CriterionBelow>), SceneError> {
    let err = |e: crate::engine::vibration::floquet::StabilityError| {
        SceneError::value(file, "autobalancer", e.to_string())
    };
    let mut opts = scan_options(machine);
    let mut start = opts.from.max(floquet.lowest_speed());
    // A scan's steps are spent in its lowest octaves, where a revolution spans the most
    // periods of the fastest motion and a monodromy's steps fall as 1/ω: the grid's sum is
    // the first one's times Σ 2^(−k/n) = 1/(1 − 2^(−1/n)) for n speeds an octave (about 70 at
    // 48), half as much again for the boundaries. A start whose scan would take more than half
    // the budget is raised until it would not (a lightly damped 620 rad/s coupling took
    // 16 666 steps a revolution at 0.62 rad/s, and its scan from 0.88 rad/s 946 000, next to
    // the budget).
    let first = floquet.revolution_steps(start, opts.rtol).map_err(err)?;
    let grid_sum = 1.0 / (1.0 - 0.5f64.powf(1.0 / opts.per_octave.max(1) as f64));
    let estimate = 1.5 * grid_sum * first as f64;
    let afford = 0.5 * SCAN_STEPS as f64;
    if estimate > afford {
        start *= estimate / afford;
    }
    let mut below = None;
    if opts.from < start {
        let fast = floquet.fastest_motion();
        let set_by = fast.source.to_string();
        // Nothing of the criterion's range can be integrated (a single platform hung on
        // nothing, loads relaxing a million times faster than the rotor turns): two octaves
        // above the lowest speed are, and their class holds beyond.
        if start >= opts.to {
            opts.to = 4.0 * start;
        }
        opts.from = start;
        below = Some(CriterionBelow {
            speed: start,
            fastest_rate: fast.rate,
            set_by,
        });
    }
    // No scene turns faster than MAX_SPEED: the scan stops there (random machines whose
    // capture windows reach far above it were scanned to 8.5e8 rad/s), keeping two octaves
    // above its start.
    let top = crate::app::check::MAX_SPEED.max(4.0 * opts.from);
    opts.to = opts.to.min(top);
    let mut map = floquet.map(&opts).map_err(err)?;
    for _ in 0..4 {
        if map.stable_at(opts.to) || opts.to >= top {
            break;
        }
        // Only the new octave is scanned; the map below is kept.
        let upper = ScanOptions {
            from: opts.to,
            to: (2.0 * opts.to).min(top),
            ..opts
        };
        map = map.joined(floquet.map(&upper).map_err(err)?);
        opts.to = upper.to;
    }
    Ok((map, below))
}

/// The regime table from the exact stability map and the machine's criterion and capture
/// windows (module docs), as `(from rad/s, regime)` ascending from 0, neighbours different.
/// Below `criterion_below` rad/s (where the scan could not reach) the criterion's zone decides
/// in place of the map: `Gathering` in its gathering zones, else as a stable balancing position.
pub fn table(
    map: &StabilityMap,
    family: &[StabilityMap],
    machine: &Machine,
    criterion_below: Option<f64>,
) -> Vec<(f64, Regime)> {
    let bands = capture_bands(machine);
    let captured = |w: f64| bands.iter().any(|c| c.from <= w && w < c.until);
    let regime = |w: f64| {
        let below = criterion_below.is_some_and(|c| w < c);
        let stable = if below {
            machine.zone_kind_at(w) == ZoneKind::Balancing
        } else {
            map.stable_at(w)
        };
        if !stable && below {
            Regime::Gathering
        } else if !stable {
            // Three or more loads can balance at another member of their family.
            if family.iter().any(|f| f.stable_at(w)) {
                Regime::Bistable(BistableReason::Family)
            } else {
                Regime::Gathering
            }
        } else if captured(w) {
            Regime::Bistable(BistableReason::Capture)
        } else if machine.zone_kind_at(w) == ZoneKind::Gathering {
            Regime::Bistable(BistableReason::Coexisting)
        } else {
            Regime::Balancing
        }
    };
    let mut cuts: Vec<f64> = map
        .boundaries
        .iter()
        .chain(family.iter().flat_map(|f| &f.boundaries))
        .map(|b| b.speed)
        .collect();
    cuts.extend(machine.zones().iter().skip(1).map(|z| z.from));
    for c in &bands {
        cuts.push(c.from);
        cuts.push(c.until);
    }
    cuts.extend(criterion_below);
    cuts.retain(|c| c.is_finite() && *c > 0.0);
    cuts.sort_by(f64::total_cmp);
    cuts.dedup();
    let mut out: Vec<(f64, Regime)> = Vec::new();
    let mut lo = 0.0;
    for (k, &c) in cuts.iter().enumerate() {
        // The regime on [lo, c): evaluated inside, at the geometric midpoint (half of c for
        // the first interval).
        let probe = if k == 0 { 0.5 * c } else { (lo * c).sqrt() };
        push(&mut out, lo, regime(probe));
        lo = c;
    }
    push(&mut out, lo, regime(2.0 * lo.max(1e-300)));
    out
}

fn push(out: &mut Vec<(f64, Regime)>, from: f64, r: Regime) {
    if out.last().map(|l| l.1) != Some(r) {
        out.push((from, r));
    }
}

/// The table in the core's f32 form, neighbours that become equal in f32 merged. A speed f32
/// cannot hold is an error naming `file`'s auto-balancer.
pub fn core_segments(
    segments: &[(f64, Regime)],
    file: &Path,
) -> Result<Vec<RegimeSegment>, SceneError> {
    let mut out: Vec<RegimeSegment> = Vec::new();
    for &(from, regime) in segments {
        let s = RegimeSegment::new("regime table speed", from, regime).map_err(|e| {
            SceneError::value(
                file,
                "autobalancer",
                format!("{e}: {from:e} rad/s in the regime table"),
            )
        })?;
        if out.last().is_some_and(|l| l.from >= s.from) {
            out.pop();
        }
        if out.last().map(|l| l.regime) != Some(s.regime) {
            out.push(s);
        }
    }
    Ok(out)
}

/// How many members of the family of balancing positions of three or more loads are analysed
/// beside the equally spaced fan.
pub const FAMILY_MEMBERS: usize = 8;

/// Members of the family of balancing positions of `fan.len() ≥ 3` loads (angles relative to
/// the shaft) other than the equally spaced fan `fan`: the first load turned by `k·2π/9`
/// (`k` = 1 to [`FAMILY_MEMBERS`]), the loads after it up to the last two kept, the last two
/// placed to close the balance again (two unit vectors summing to what is left: their mean
/// direction ± `acos(|v|/2)`), where they can. None for two loads (their balancing position
/// is unique up to the pair's exchange).
///
/// For three or more loads the balancing positions form a family, and the fan's stability
/// does not decide the regime: where the fan is unstable another member may be stable and
/// the loads balance there (a three-ball machine whose fan is unstable at 70 rad/s balances
/// in simulation; `host-sim/tests/vibration.rs`).
pub fn family_members(fan: &[f64]) -> Vec<Vec<f64>> {
    let n = fan.len();
    if n < 3 {
        return Vec::new();
    }
    let sum = |a: &[f64]| {
        a.iter()
            .fold((0.0, 0.0), |(x, y), t| (x + t.cos(), y + t.sin()))
    };
    let (cx, cy) = sum(fan);
    (1..=FAMILY_MEMBERS)
        .filter_map(|k| {
            let mut a = fan.to_vec();
            a[0] += k as f64 * std::f64::consts::TAU / (FAMILY_MEMBERS + 1) as f64;
            let (kx, ky) = sum(&a[..n - 2]);
            let (vx, vy) = (cx - kx, cy - ky);
            let len = vx.hypot(vy);
            (len <= 2.0 && len > 0.0).then(|| {
                let mid = vy.atan2(vx);
                let half = (0.5 * len).acos();
                a[n - 2] = mid + half;
                a[n - 1] = mid - half;
                a
            })
        })
        .collect()
}

/// Each criterion boundary with the nearest exact boundary of its kind (none below
/// `criterion_below`, where the scan does not reach).
pub fn compare(
    map: &StabilityMap,
    machine: &Machine,
    criterion_below: Option<f64>,
) -> Vec<Comparison> {
    machine
        .zones()
        .iter()
        .skip(1)
        .map(|z| {
            let resonance = z.kind == ZoneKind::Balancing;
            let reached = criterion_below.is_none_or(|c| z.from >= c);
            let exact = map
                .boundaries
                .iter()
                .filter(|_| reached)
                .filter(|b| b.stable_above == resonance)
                .map(|b| b.speed)
                .min_by(|a, b| (a / z.from).ln().abs().total_cmp(&(b / z.from).ln().abs()));
            Comparison {
                criterion: z.from,
                kind: if resonance { "resonance" } else { "additional" },
                exact,
                difference: exact.map(|e| e / z.from - 1.0),
            }
        })
        .collect()
}

/// The design-time analysis of the scene's auto-balancer (`None` without one).
pub fn design(scene: &Scene, file: &Path, machine: &Machine) -> Result<Option<Design>, SceneError> {
    let Some(vm) = vibration_machine(scene, file)? else {
        return Ok(None);
    };
    let exact = match Floquet::new(&vm) {
        Ok(f) => {
            let (map, criterion_below) = stability_map(&f, machine, file)?;
            let err = |e: crate::engine::vibration::floquet::StabilityError| {
                SceneError::value(file, "autobalancer", e.to_string())
            };
            // A member matters only where the fan is unstable (the table asks whether some
            // member balances there): each is scanned over the fan's unstable intervals alone,
            // the members side by side.
            let unstable = map.unstable_within();
            let members = family_members(f.angles());
            let family = members
                .par_iter()
                .map(|a| {
                    let member = Floquet::with_angles(&vm, a)?;
                    let mut joined: Option<StabilityMap> = None;
                    for &(from, to) in &unstable {
                        let part = member.map(&ScanOptions {
                            from,
                            to,
                            ..map.options
                        })?;
                        joined = Some(match joined {
                            Some(j) => j.joined(part),
                            None => part,
                        });
                    }
                    Ok(joined)
                })
                .collect::<Result<Vec<_>, _>>()
                .map_err(err)?
                .into_iter()
                .flatten()
                .collect::<Vec<_>>();
            let below = criterion_below.as_ref().map(|c| c.speed);
            let segments = table(&map, &family, machine, below);
            let comparison = compare(&map, machine, below);
            Some(Exact {
                map,
                segments,
                comparison,
                family_members: members.len(),
                family,
                criterion_below,
            })
        }
        Err(_) => None,
    };
    Ok(Some(Design {
        capacity: vm.capacity(),
        rotor_unbalance: vm.rotor_unbalance(),
        residual_floor: vm.residual_floor(),
        exact,
    }))
}

/// The scene's `[monitor] regime_margin`, as the core's f32.
pub fn given_margin(scene: &Scene) -> Option<f32> {
    scene
        .monitor
        .as_ref()
        .and_then(|m| m.regime_margin)
        .map(|m| m as f32)
}

/// The run-time classifier of a scene's machine: from the exact table when there is one
/// (margin: the scene's `[monitor] regime_margin`, default [`TABLE_MARGIN`]), else from the
/// criterion (default margin [`DEFAULT_MARGIN`]); half the margin as hysteresis. Returns the
/// classifier, its margin and whether it is the exact one.
pub fn classifier(
    scene: &Scene,
    file: &Path,
    machine: &Machine,
    design: Option<&Design>,
) -> Result<(Classifier, f32, bool), SceneError> {
    let given = given_margin(scene);
    if let Some(exact) = design.and_then(|d| d.exact.as_ref()) {
        let margin = given.unwrap_or(TABLE_MARGIN);
        let segments = core_segments(&exact.segments, file)?;
        let c = Classifier::from_table(
            &RegimeTable {
                segments: &segments,
            },
            margin,
            0.5 * margin,
        )
        .map_err(|e| value_error(file, "monitor", e))?;
        return Ok((c, margin, true));
    }
    let margin = given.unwrap_or(DEFAULT_MARGIN);
    let c = Classifier::new(machine, margin, 0.5 * margin)
        .map_err(|e| value_error(file, "monitor", e))?;
    Ok((c, margin, false))
}

/// A speed inside the `Balancing` segment of `segs` nearest to `w` (in ratio) that is
/// reachable from `w`'s segment through segments where the balancing position is stable:
/// the geometric middle of a bounded segment, 1.1 times the start of the last (half the end
/// of a first one). `None` when a `Gathering` segment lies between `w` and every one.
pub fn balanced_start(segs: &[RegimeSegment], w: f64) -> Option<f64> {
    let i = segs
        .partition_point(|s| f64::from(s.from) <= w)
        .checked_sub(1)?;
    let inside = |k: usize| {
        let from = f64::from(segs.get(k)?.from);
        let to = segs.get(k + 1).map_or(f64::INFINITY, |s| f64::from(s.from));
        Some(if !to.is_finite() {
            1.1 * from
        } else if from > 0.0 {
            (from * to).sqrt()
        } else {
            0.5 * to
        })
    };
    let balancing = |k: &usize| segs.get(*k).is_some_and(|s| s.regime == Regime::Balancing);
    let stable = |k: &usize| segs.get(*k).is_some_and(|s| s.regime != Regime::Gathering);
    let up = (i..segs.len())
        .take_while(stable)
        .find(balancing)
        .and_then(inside);
    let down = (0..=i)
        .rev()
        .take_while(stable)
        .find(balancing)
        .and_then(inside);
    match (up, down) {
        (Some(a), Some(b)) => Some(if (a / w).ln().abs() <= (w / b).ln().abs() {
            a
        } else {
            b
        }),
        (a, b) => a.or(b),
    }
}

/// The tracker's status after a linear ramp of the speed from `from` to `to` (400 steps).
pub fn tracked(c: &Classifier, from: f64, to: f64) -> RegimeStatus {
    let mut t = RegimeTracker::new();
    let mut st = t.update(c, from as f32);
    for k in 1..=400 {
        st = t.update(c, (from + (to - from) * f64::from(k) / 400.0) as f32);
    }
    st
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::app::predict;
    use crate::app::scene::resolve;
    use crate::engine::vibration::floquet::Boundary;

    fn one_mass() -> (Scene, std::path::PathBuf, Machine) {
        let (scene, path) = resolve("one-mass").unwrap();
        let m = predict::machine(&scene, &path).unwrap().unwrap();
        (scene, path, m)
    }

    fn map_with(stable_at_from: bool, speeds: &[f64]) -> StabilityMap {
        let mut stable = stable_at_from;
        StabilityMap {
            options: ScanOptions::new(10.0, 400.0),
            stable_at_from,
            boundaries: speeds
                .iter()
                .map(|&w| {
                    stable = !stable;
                    Boundary {
                        speed: w,
                        bracket: [w, w],
                        stable_above: stable,
                        radius: [1.0, 1.0],
                    }
                })
                .collect(),
            evaluations: 0,
            steps: 0,
            neutral_drift: 0.0,
            unresolved: None,
            marginal: None,
        }
    }

    #[test]
    fn table_combines_stability_capture_and_criterion() {
        let (_, _, m) = one_mass();
        let b = m.zones()[1].from; // 61.43: the criterion's resonance
                                   // The capture bands end together: the core's window (90.41) or the resonance's band.
        let until = capture_bands(&m).iter().fold(0.0f64, |u, c| u.max(c.until));
        let capture = Regime::Bistable(BistableReason::Capture);
        // Stable from 72, as the Floquet analysis finds for this machine.
        let t = table(&map_with(false, &[72.0]), &[], &m, None);
        assert_eq!(
            t,
            vec![
                (0.0, Regime::Gathering),
                (72.0, capture),
                (until, Regime::Balancing)
            ]
        );
        // Stable already below the criterion's boundary: coexisting with gathered loads there.
        let t = table(&map_with(false, &[55.0]), &[], &m, None);
        assert_eq!(
            t,
            vec![
                (0.0, Regime::Gathering),
                (55.0, Regime::Bistable(BistableReason::Coexisting)),
                (b, capture),
                (until, Regime::Balancing)
            ]
        );
        // An unstable band inside the capture window and another above it.
        let t = table(
            &map_with(false, &[65.0, 70.0, 80.0, 120.0, 130.0]),
            &[],
            &m,
            None,
        );
        assert_eq!(
            t,
            vec![
                (0.0, Regime::Gathering),
                (65.0, capture),
                (70.0, Regime::Gathering),
                (80.0, capture),
                (until, Regime::Balancing),
                (120.0, Regime::Gathering),
                (130.0, Regime::Balancing)
            ]
        );
        // Never stable: gathering everywhere.
        assert_eq!(
            table(&map_with(false, &[]), &[], &m, None),
            vec![(0.0, Regime::Gathering)]
        );
    }

    /// A two-platform machine (resonances 49.6 and 124.2 rad/s) whose damping hides the second
    /// resonance from the criterion: its only gathering zone ends at 49.6, so the core's only
    /// capture window is there. Run up to 165 rad/s with the loads together and held for
    /// 335 s, the loads stayed captured near 115–122 rad/s (two simulations), where the
    /// balancing position is stable: the table committed to balancing from 154.9 rad/s up.
    /// Now the capture at the second resonance makes it bistable there.
    #[test]
    fn a_resonance_without_a_criterion_zone_still_captures() {
        let text = "[[platform]]\nmass = 54.450883282155964\nstiffness = 129756.66936812556\n\
            damping = 381.1643992325081\n\n[[platform]]\nmass = 92.09423774712249\n\
            stiffness = 250000.0\ndamping = 700.0150893005239\n\n[[coupling]]\n\
            between = [1, 2]\nstiffness = 458518.6708010421\ndamping = 700.0150893005239\n\n\
            [autobalancer]\nkind = \"ball\"\nplatform = 2\nloads = 2\n\
            load_mass = 1.4528811264387569\nradius = 0.1\nhousing_mass = 5.0\n\
            viscosity = 5.909176653434912\nrotor_unbalance = 0.09870443055938408\n\n\
            [motor]\nmodel = \"speed\"\nspeed = 50.0\n";
        let path = std::path::PathBuf::from("hidden-resonance.toml");
        let scene = Scene::parse(text, &path).unwrap();
        let m = predict::machine(&scene, &path).unwrap().unwrap();
        assert_eq!(m.capture_windows().len(), 1);
        let bands = resonance_captures(&m);
        assert_eq!(bands.len(), 2, "{bands:?}");
        let second = bands[1];
        assert!((second.from - 124.0).abs() < 1.0, "{second:?}");
        assert!(second.until > 165.0, "{second:?}");
        let d = design(&scene, &path, &m).unwrap().unwrap();
        let exact = d.exact.as_ref().unwrap();
        assert!(exact.map.stable_at(165.0));
        let at = |w: f64| exact.segments.iter().rev().find(|s| s.0 <= w).map(|s| s.1);
        assert_eq!(
            at(165.0),
            Some(Regime::Bistable(BistableReason::Capture)),
            "{:?}",
            exact.segments
        );
        // Far above every band: balancing.
        assert_eq!(at(2.0 * second.until), Some(Regime::Balancing));
    }

    /// Each band's `until` is the maximum of `Ω + D(Ω)` near its resonance: against a scan of
    /// 200 000 nodes over the same range (within 1e-9 relative), and no lower than the core's
    /// window at that resonance (which maximises over the gathering zone only).
    #[test]
    fn resonance_bands_hold_the_local_maximum_of_the_capture_balance() {
        for name in ["one-mass", "two-mass", "three-mass"] {
            let (scene, path) = resolve(name).unwrap();
            let m = predict::machine(&scene, &path).unwrap().unwrap();
            let bands = resonance_captures(&m);
            assert!(!bands.is_empty(), "{name}");
            let f = |w: f64| w + m.capture_lag(w);
            for b in &bands {
                // The scan between the band's neighbouring additional speeds.
                let r = m
                    .resonant_speeds()
                    .iter()
                    .copied()
                    .min_by(|x, y| (x - b.from).abs().total_cmp(&(y - b.from).abs()))
                    .unwrap();
                let lo = m
                    .additional_speeds()
                    .iter()
                    .copied()
                    .filter(|&a| a < r)
                    .fold(1e-3 * r, f64::max);
                let hi = m
                    .additional_speeds()
                    .iter()
                    .copied()
                    .filter(|&a| a > r)
                    .fold(16.0 * r, f64::min);
                // A scan of 200 000 nodes for the highest interior local maximum, then one of
                // 200 000 across the two nodes either side of it (spacing 1e-9 relative).
                let scan = |lo: f64, hi: f64, n: u32| -> Vec<(f64, f64)> {
                    (0..=n)
                        .map(|i| {
                            let x = lo * (hi / lo).powf(f64::from(i) / f64::from(n));
                            (x, f(x))
                        })
                        .collect()
                };
                let coarse = scan(lo, hi, 200_000);
                let top = (1..coarse.len() - 1)
                    .filter(|&i| coarse[i].1 >= coarse[i - 1].1 && coarse[i].1 >= coarse[i + 1].1)
                    .filter(|&i| coarse[i].1.is_finite())
                    .max_by(|&x, &y| coarse[x].1.total_cmp(&coarse[y].1))
                    .unwrap();
                let fine = scan(coarse[top - 1].0, coarse[top + 1].0, 200_000);
                let peak = fine.iter().map(|p| p.1).fold(f64::NEG_INFINITY, f64::max);
                assert!((b.until / peak - 1.0).abs() < 1e-9, "{name}: {b:?} {peak}");
                let slope = |x: f64| (f(x * (1.0 + 1e-6)) - f(x * (1.0 - 1e-6))) / (2e-6 * x);
                assert!(
                    f(b.at * (1.0 + 1e-4)) <= b.until && f(b.at * (1.0 - 1e-4)) <= b.until,
                    "{name}: {b:?}"
                );
                assert!(
                    slope(b.at).abs() < 1e-3 * b.until / b.at,
                    "{name}: {b:?} slope {}",
                    slope(b.at)
                );
            }
            for w in m.capture_windows() {
                assert!(
                    bands.iter().any(|b| b.until >= w.until * (1.0 - 1e-9)),
                    "{name}: {w:?} {bands:?}"
                );
            }
        }
    }

    #[test]
    fn core_segments_merge_what_f32_cannot_separate() {
        let t = [
            (0.0, Regime::Gathering),
            (61.43, Regime::Balancing),
            (61.430_000_001, Regime::Gathering),
            (70.0, Regime::Balancing),
        ];
        let s = core_segments(&t, Path::new("t.toml")).unwrap();
        // 61.43 and 61.430000001 are one f32: the later segment replaces the earlier, and
        // then joins the gathering one before it.
        assert_eq!(
            s,
            vec![
                RegimeSegment {
                    from: 0.0,
                    regime: Regime::Gathering
                },
                RegimeSegment {
                    from: 70.0,
                    regime: Regime::Balancing
                }
            ]
        );
        let e = core_segments(
            &[(0.0, Regime::Gathering), (1e300, Regime::Balancing)],
            Path::new("t.toml"),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("t.toml") && e.contains("1e300"), "{e}");
    }

    #[test]
    fn scenes_get_the_exact_classifier_and_its_margin() {
        let (scene, path, m) = one_mass();
        let d = design(&scene, &path, &m).unwrap().unwrap();
        let e = d.exact.as_ref().unwrap();
        assert_eq!(e.map.boundaries.len(), 1);
        let w = e.map.boundaries[0].speed;
        // The criterion says balancing above 61.43; the balancing position is unstable to 72.3.
        assert!((72.2..72.5).contains(&w), "{w}");
        assert_eq!(e.comparison[0].kind, "resonance");
        assert!((e.comparison[0].difference.unwrap() - (w / 61.43 - 1.0)).abs() < 1e-3);
        let (c, margin, exact) = classifier(&scene, &path, &m, Some(&d)).unwrap();
        assert!(exact && margin == TABLE_MARGIN);
        assert_eq!(c.classify(66.0), Regime::Gathering);
        assert_eq!(c.classify(80.0), Regime::Bistable(BistableReason::Capture));
        assert_eq!(c.classify(110.0), Regime::Balancing);
        // The scene's margin overrides the default.
        let mut s2 = scene.clone();
        s2.monitor
            .get_or_insert_with(Default::default)
            .regime_margin = Some(0.03);
        let (_, margin, _) = classifier(&s2, &path, &m, Some(&d)).unwrap();
        assert_eq!(margin, 0.03);
        // A balancer too small for its rotor has no exact table: the criterion's, with its
        // own default margin.
        let mut small = scene.clone();
        small.autobalancer.as_mut().unwrap().rotor_unbalance = Some(0.12);
        let d = design(&small, &path, &m).unwrap().unwrap();
        assert!(d.exact.is_none());
        assert!((d.residual_floor - 0.02).abs() < 1e-12 && (d.capacity - 0.1).abs() < 1e-12);
        let (c, margin, exact) = classifier(&small, &path, &m, Some(&d)).unwrap();
        assert!(!exact && margin == DEFAULT_MARGIN);
        assert_eq!(c.classify(110.0), Regime::Balancing);
    }

    #[test]
    fn the_scan_stops_at_the_fastest_speed_a_scene_turns() {
        // The one-mass scene on 0.01 N·s/m has a capture window up to 5.8e5 rad/s: the scan
        // was to run to 1.5 times that, 8.7e5, beyond the 1e5 rad/s any scene can turn (random
        // machines were scanned to 8.5e8). It ends at MAX_SPEED; the table still
        // holds the window, and the class at the top holds above.
        let (mut scene, path) = resolve("one-mass").unwrap();
        scene.platform[0].damping = 0.01;
        let m = predict::machine(&scene, &path).unwrap().unwrap();
        assert!(scan_options(&m).to > 1.5 * crate::app::check::MAX_SPEED);
        let d = design(&scene, &path, &m).unwrap().unwrap();
        let e = d.exact.as_ref().unwrap();
        assert_eq!(e.map.options.to, crate::app::check::MAX_SPEED);
        assert!(e.map.stable_at(crate::app::check::MAX_SPEED));
        assert!(
            e.segments
                .iter()
                .any(|s| s.1 == Regime::Bistable(BistableReason::Capture)),
            "{:?}",
            e.segments
        );
    }

    #[test]
    fn a_scan_that_would_overrun_its_step_budget_starts_higher() {
        // A random two-platform machine with a lightly damped 620 rad/s coupling (1e-6 N/m to
        // the ground, 0.016 N·s/m between): at its lowest integrable speed, 0.62 rad/s, one
        // revolution takes 16 666 steps (17 a period of the coupling's motion), and its scan
        // from a quarter of the first resonance took 946 000 of the 1 000 000 allowed (with
        // four loads, then each of eight family members as much). The start is raised until
        // the scan is planned within half the budget; the resonance's boundary above it is
        // still found, and the table follows the criterion below it.
        let text = "[[platform]]\nmass = 468.5079505439287\nstiffness = 1e-06\n\
            damping = 0.01699962796691155\n[[platform]]\nmass = 651.9092089485077\n\
            stiffness = 13840.677296011232\ndamping = 3.4624985415690723\n[[coupling]]\n\
            between = [1, 2]\nstiffness = 90647809.1705915\ndamping = 0.016411080511131614\n\
            [autobalancer]\nkind = \"roller\"\nplatform = 1\nloads = 2\n\
            load_mass = 0.1706145806544954\nradius = 0.11322604842487596\n\
            housing_mass = 1.7508408049444173\nviscosity = 7.698974235709857\n\
            rotor_unbalance = 0.00803150789304654\n";
        let path = std::path::PathBuf::from("fast-coupling.toml");
        let scene = Scene::parse(text, &path).unwrap();
        let m = predict::machine(&scene, &path).unwrap().unwrap();
        let d = design(&scene, &path, &m).unwrap().unwrap();
        let e = d.exact.as_ref().unwrap();
        let below = e.criterion_below.as_ref().unwrap();
        let lowest = below.fastest_rate / crate::engine::vibration::floquet::REVOLUTION_RATIO;
        assert!(
            below.speed > 2.0 * lowest.max(scan_options(&m).from),
            "{below:?}"
        );
        assert!(e.map.steps < SCAN_STEPS / 2, "{}", e.map.steps);
        let first = m.resonant_speeds()[0];
        assert!(below.speed < first, "{below:?} {first}");
        let b = e.map.boundaries[0];
        assert!(
            b.stable_above && (b.speed / first - 1.0).abs() < 0.05,
            "{b:?} {first}"
        );
    }

    #[test]
    fn a_capture_window_of_rounding_width_is_none() {
        // A random machine (a stiff 1e-6 kg platform coupled at 1e15 N/m, five loads) had a
        // capture window of 1.8e-13 of its 2.2e6 rad/s zone end, printed by `predict` and
        // tabled as a bistable band: the maximum of Ω + D(Ω) at the zone's end with next to
        // no lag. Every window kept is at least MIN_CAPTURE_WIDTH wide.
        let text = "[[platform]]\nmass = 1e-06\nstiffness = 457064073.37010396\ndamping = 0.0\n\
            [[platform]]\nmass = 1253.0104322346122\nstiffness = 0.17676739985650625\n\
            damping = 291789825.95562595\n[[coupling]]\nbetween = [1, 2]\n\
            stiffness = 1000000000000000.0\ndamping = 1.2508481097276043e-08\n\
            [autobalancer]\nkind = \"ball\"\nplatform = 1\nloads = 5\n\
            load_mass = 0.00041403031666508675\nradius = 1.4794367632932022e-06\n\
            housing_mass = 243.00665177988233\nviscosity = 1000000000000.0\n";
        let path = std::path::PathBuf::from("wide.toml");
        let scene = Scene::parse(text, &path).unwrap();
        let m = predict::machine(&scene, &path).unwrap().unwrap();
        let zone_ends: Vec<f64> = m.zones().iter().skip(1).map(|z| z.from).collect();
        assert!(
            zone_ends.iter().any(|&z| (z / 2.2142e6 - 1.0).abs() < 1e-4),
            "{zone_ends:?}"
        );
        for w in capture_bands(&m) {
            assert!(
                w.until > w.from * (1.0 + drive_monitor::balancer::MIN_CAPTURE_WIDTH),
                "{w:?}"
            );
        }
    }

    #[test]
    fn platforms_hung_only_on_their_coupling_are_scanned_from_the_lowest_integrable_speed() {
        // The two-mass scene with both platforms at 1e-6 N/m to the ground: a rigid-body
        // resonance near 1e-4 rad/s, where one revolution took over a million integration
        // steps, and the coupling's near 44 rad/s. The scan starts at the coupling's motion
        // over 1000 (its Gershgorin bound √(2·1e5/100) = 44.72 rad/s), the table follows the
        // criterion below it, and the exact boundaries above it are found.
        let (mut scene, path) = resolve("two-mass").unwrap();
        for p in &mut scene.platform {
            p.stiffness = 1e-6;
        }
        let m = predict::machine(&scene, &path).unwrap().unwrap();
        let d = design(&scene, &path, &m).unwrap().unwrap();
        let e = d.exact.as_ref().unwrap();
        let below = e.criterion_below.as_ref().unwrap();
        let bound = (2.0e5f64 / 100.0).sqrt();
        assert!(
            (below.speed / (bound / 1000.0) - 1.0).abs() < 1e-9,
            "{below:?}"
        );
        assert!(below.set_by.contains("platform[1].stiffness"), "{below:?}");
        assert_eq!(e.map.options.from, below.speed);
        // The criterion's rigid-body resonance lies below the scan: its zones decide there,
        // and its comparison has no exact boundary.
        let rigid = m.zones()[1].from;
        assert!(
            rigid < 1e-3 && m.zones()[1].kind == ZoneKind::Balancing,
            "{rigid}"
        );
        assert_eq!(e.segments[0], (0.0, Regime::Gathering));
        assert!(e.segments.iter().any(|s| s.0 == rigid), "{:?}", e.segments);
        assert!(e.comparison[0].exact.is_none());
        let at = |w: f64| {
            e.segments
                .iter()
                .rev()
                .find(|s| s.0 <= w)
                .map(|s| s.1)
                .unwrap()
        };
        assert_eq!(at(0.5 * rigid), Regime::Gathering);
        assert_eq!(at(0.01), Regime::Balancing);
        assert_eq!(at(0.5 * below.speed + 0.5 * 31.0), Regime::Balancing);
        // Above it the exact boundaries of the coupling's resonance, within the scan's budget.
        let speeds: Vec<f64> = e.map.boundaries.iter().map(|b| b.speed).collect();
        assert!(
            speeds.len() == 2
                && (31.6..31.8).contains(&speeds[0])
                && (45.4..45.6).contains(&speeds[1]),
            "{speeds:?}"
        );
        assert!(e.map.steps < 1_000_000, "{}", e.map.steps);
        // One platform hung on nothing: the criterion's whole range (its resonance near 1e-4
        // rad/s) lies below the lowest speed (the loads' relaxation 10/(1.4·0.5) = 14.3 1/s
        // over 1000). Two octaves above it are scanned; the criterion decides below.
        let (mut scene, path) = resolve("one-mass").unwrap();
        scene.platform[0].stiffness = 1e-6;
        let m = predict::machine(&scene, &path).unwrap().unwrap();
        let d = design(&scene, &path, &m).unwrap().unwrap();
        let e = d.exact.as_ref().unwrap();
        let below = e.criterion_below.as_ref().unwrap();
        assert!(
            (below.speed / (10.0 / 1.4 / 0.5 / 1000.0) - 1.0).abs() < 1e-9,
            "{below:?}"
        );
        assert!(below.set_by.contains("autobalancer.load_mass"), "{below:?}");
        assert!(e.map.options.to >= 4.0 * below.speed && e.map.boundaries.is_empty());
        assert_eq!(e.segments[0], (0.0, Regime::Gathering));
        assert_eq!(e.segments.last().unwrap().1, Regime::Balancing);
        assert!(e.segments[1].0 < 1e-3, "{:?}", e.segments);
        // The bundled scenes' scans start where they always did.
        for name in ["one-mass", "two-mass", "three-mass", "one-mass-runup"] {
            let (scene, path) = resolve(name).unwrap();
            let m = predict::machine(&scene, &path).unwrap().unwrap();
            let d = design(&scene, &path, &m).unwrap().unwrap();
            let e = d.exact.unwrap();
            assert!(e.criterion_below.is_none(), "{name}");
            let first = m.resonant_speeds()[0];
            assert_eq!(e.map.options.from, 0.25 * first, "{name}");
        }
    }

    #[test]
    fn an_unbalance_too_small_to_resolve_gives_the_table_of_d_0() {
        // The one-mass machine with D = 1e-9 kg·m (1e-8 of its capacity): the loads' drift
        // along what is a family of balancing positions at D = 0 has the multiplier
        // 1 − 3e-17, and its sign against 1 was noise (109 boundaries from 61 to 491 rad/s).
        // D = 1e-9, 1e-8 and 1e-7 must give the table of D = 0 (3 boundaries: 61.4423, 61.6829,
        // 72.9103 rad/s; balancing from 90.406), and say that the drift was set aside.
        let (scene, path, m) = one_mass();
        let at = |d: f64| {
            let mut s = scene.clone();
            s.autobalancer.as_mut().unwrap().rotor_unbalance = Some(d);
            design(&s, &path, &m).unwrap().unwrap().exact.unwrap()
        };
        let zero = at(0.0);
        assert!(zero.map.unresolved.is_none());
        let speeds: Vec<f64> = zero.map.boundaries.iter().map(|b| b.speed).collect();
        assert_eq!(speeds.len(), 3, "{speeds:?}");
        for (w, want) in speeds.iter().zip([61.4423, 61.6829, 72.9103]) {
            assert!((w - want).abs() < 1e-4, "{speeds:?}");
        }
        let until = capture_bands(&m).iter().fold(0.0f64, |u, c| u.max(c.until));
        assert_eq!(zero.segments.last(), Some(&(until, Regime::Balancing)));
        for d in [1e-9, 1e-8, 1e-7] {
            let e = at(d);
            let got: Vec<f64> = e.map.boundaries.iter().map(|b| b.speed).collect();
            assert_eq!(got.len(), 3, "D = {d}: {got:?}");
            for (a, b) in got.iter().zip(&speeds) {
                assert!(
                    (a / b - 1.0).abs() < 1e-6,
                    "D = {d}: {got:?} against {speeds:?}"
                );
            }
            assert_eq!(e.map.stable_at_from, zero.map.stable_at_from);
            let regimes = |x: &Exact| x.segments.iter().map(|s| s.1).collect::<Vec<_>>();
            assert_eq!(regimes(&e), regimes(&zero), "D = {d}");
            assert_eq!(e.segments.last(), Some(&(until, Regime::Balancing)));
            // Said, not silent: where the drift was set aside and to what resolution.
            let u = e.map.unresolved.unwrap();
            assert!(u.evaluations > e.map.evaluations / 2, "D = {d}: {u:?}");
            assert!(u.resolution == 1e-10 && u.largest <= u.resolution, "{u:?}");
        }
        // The bundled scene's ordinary unbalance: nothing set aside.
        let d = design(&scene, &path, &m).unwrap().unwrap();
        assert!(d.exact.unwrap().map.unresolved.is_none());
    }

    fn seg(from: f32, regime: Regime) -> RegimeSegment {
        RegimeSegment { from, regime }
    }

    #[test]
    fn a_balanced_start_is_found_only_through_stable_segments() {
        let cap = Regime::Bistable(BistableReason::Capture);
        let segs = [
            seg(0.0, Regime::Gathering),
            seg(10.0, cap),
            seg(20.0, Regime::Balancing),
            seg(30.0, Regime::Gathering),
            seg(40.0, cap),
        ];
        // Up into [20, 30): its geometric middle.
        assert_eq!(balanced_start(&segs, 15.0), Some(600f64.sqrt()));
        // Above the unstable band there is no balancing segment to come from.
        assert_eq!(balanced_start(&segs, 45.0), None);
        // From inside an unstable segment nothing is reachable.
        assert_eq!(balanced_start(&segs, 5.0), None);
        // Balancing on both sides: the nearer in ratio (11/6 against 6/2.5); a last segment
        // is entered at 1.1 times its start, a first one at half its end (11/5.1 against
        // 5.1/2.5).
        let both = [
            seg(0.0, Regime::Balancing),
            seg(5.0, cap),
            seg(10.0, Regime::Balancing),
        ];
        assert_eq!(balanced_start(&both, 6.0), Some(11.0));
        assert_eq!(balanced_start(&both, 5.1), Some(2.5));
    }

    /// Every family member balances the rotor exactly as the fan does, and differs from it.
    #[test]
    fn family_members_balance_the_rotor() {
        for (n, d) in [(3usize, 0.3), (3, 1.2), (4, 0.5), (5, 2.0)] {
            let fan = crate::engine::vibration::balancing_fan(n, 1.0, d, 0.4).unwrap();
            let fan = &fan[..n];
            let members = family_members(fan);
            assert!(
                members.len() >= FAMILY_MEMBERS / 2,
                "{n} {d}: {}",
                members.len()
            );
            let closure = |a: &[f64]| {
                let (x, y) = a
                    .iter()
                    .fold((0.0, 0.0), |(x, y), t| (x + t.cos(), y + t.sin()));
                (x + d * 0.4f64.cos(), y + d * 0.4f64.sin())
            };
            for m in &members {
                let (x, y) = closure(m);
                assert!(x.hypot(y) < 1e-12, "{n} {d}: {m:?} leaves ({x}, {y})");
                assert!(m.iter().zip(fan).any(|(a, b)| (a - b).abs() > 1e-3));
            }
        }
        assert!(family_members(&[0.0, 2.0]).is_empty());
    }

    /// Three balls whose equally spaced fan is unstable just below where it becomes stable
    /// (69.0 to 73.1 rad/s) balance there in simulation at another member of their family:
    /// the table says bistable (family), not gathering. Two balls on the same machine have no
    /// family.
    #[test]
    fn three_loads_balance_where_their_fan_is_unstable() {
        let text = "[[platform]]\nmass = 40.0\nstiffness = 2.0e5\ndamping = 4000.0\n\n\
            [autobalancer]\nkind = \"ball\"\nplatform = 1\nloads = 3\nload_mass = 0.3\n\
            radius = 0.08\nhousing_mass = 3.0\nviscosity = 5.0\nrotor_unbalance = 0.03\n\n\
            [motor]\nmodel = \"speed\"\nspeed = 70.0\n\n[simulation]\nduration = 10.0\n";
        let path = std::path::PathBuf::from("three-balls.toml");
        let scene = Scene::parse(text, &path).unwrap();
        let m = predict::machine(&scene, &path).unwrap().unwrap();
        let d = design(&scene, &path, &m).unwrap().unwrap();
        let exact = d.exact.as_ref().unwrap();
        // Six of the eight turns of the first ball leave a balance the last two can close.
        assert_eq!(exact.family_members, 6);
        assert!(!exact.map.stable_at(70.0));
        let family = Regime::Bistable(BistableReason::Family);
        let at = |w: f64| {
            exact
                .segments
                .iter()
                .rev()
                .find(|(from, _)| *from <= w)
                .map(|s| s.1)
        };
        assert_eq!(at(70.0), Some(family), "{:?}", exact.segments);
        // The band README quotes: from 69.0 to 73.1 rad/s.
        let from = exact.segments.iter().find(|s| s.1 == family).unwrap().0;
        assert!((from - 69.0).abs() < 0.05, "{from}");
        assert_eq!(exact.map.boundaries.len(), 1);
        assert!((exact.map.boundaries[0].speed - 73.1).abs() < 0.05);
        assert_eq!(at(60.0), Some(Regime::Gathering));
        // The members are scanned only where the fan is unstable: scanned over the fan's whole
        // range instead (another grid), they give the same table, each cut within the
        // bisection's 1e-7 bracket (1e-6 allowed).
        let vm = vibration_machine(&scene, &path).unwrap().unwrap();
        let fan = Floquet::new(&vm).unwrap();
        let whole: Vec<StabilityMap> = family_members(fan.angles())
            .iter()
            .map(|a| {
                Floquet::with_angles(&vm, a)
                    .unwrap()
                    .map(&exact.map.options)
                    .unwrap()
            })
            .collect();
        let below = exact.criterion_below.as_ref().map(|c| c.speed);
        let t = table(&exact.map, &whole, &m, below);
        assert_eq!(t.len(), exact.segments.len(), "{t:?}");
        for (a, b) in t.iter().zip(&exact.segments) {
            assert_eq!(a.1, b.1);
            assert!(
                (a.0 - b.0).abs() <= 1e-6 * b.0,
                "{t:?} {:?}",
                exact.segments
            );
        }
        // The fan is unstable at both speeds; from near it the loads find a stable member at
        // 70 rad/s and gather at 72.
        for (w, want) in [(70.0, "balancing"), (72.0, "gathering")] {
            let sigma = growth_rate(&scene, &path, exact, w).unwrap().unwrap();
            assert!(sigma > 0.0, "{w}");
            let (r, _, settled) =
                crate::studies::sweep::settled_run(&scene, &path, w, false, Some(sigma)).unwrap();
            assert!(settled, "{w}");
            assert_eq!(r.regime_simulated, Some(want), "{w}: {:?}", r.regime_detail);
        }
        // Two balls: no family, so the fan's instability is gathering.
        let two = Scene::parse(&text.replace("loads = 3", "loads = 2"), &path).unwrap();
        let m2 = predict::machine(&two, &path).unwrap().unwrap();
        let d2 = design(&two, &path, &m2).unwrap().unwrap();
        let e2 = d2.exact.as_ref().unwrap();
        assert_eq!(e2.family_members, 0);
        assert!(e2.segments.iter().all(|s| s.1 != family));
    }
}
