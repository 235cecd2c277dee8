//! `drive-sim criterion`: the exact regime classifier against direct simulation on randomised
//! machines, and the seed's criterion beside the exact boundaries.
//!
//! The seed's criterion (`Re H(ω) < 0`: balancing, the core's
//! [`Machine::zones`](drive_monitor::balancer::Machine::zones)) is approximate; the model is
//! not. This module draws machines at random in a documented range of the seed's dimensionless
//! groups ([`RANGE`]) and, for each,
//!
//! 1. computes where the balancing position is stable from the Floquet multipliers of the
//!    model ([`crate::engine::vibration::floquet`]; boundaries bisected to 1e-7 relative) and
//!    builds the exact regime table ([`crate::app::regimes`]);
//! 2. simulates the machine at a grid of prescribed rotor speeds and compares the exact
//!    classifier's committed answers (`Balancing`, `Gathering`) with what the loads did;
//! 3. checks every exact boundary by simulation just either side of it, and by integrating the
//!    monodromy 10⁴ times more tightly at the ends of its final bracket;
//! 4. puts the criterion's boundaries beside the exact ones.
//!
//! # Outcome at one speed
//!
//! The loads start at the balancing position turning with the rotor, one of them displaced by
//! 0.05 rad ([`crate::app::run::vibration_params`]); where the exact classifier commits to
//! `Balancing` the machine is also started with the loads together at rest (0.01 rad apart),
//! the other attractor a run-up can leave them in. Where it says `Bistable` (outside the
//! margin band) the loads are started together at rest too: loads that stay gathered there
//! show the second attractor exists, so the speed is bistable indeed; loads that balance show
//! only that it is not reached from that start. Where it says bistable for capture, the loads
//! are also run up ([`runup_outcome`]): together at rest with the rotor at the lowest grid
//! speed, the rotor ramped to the speed over `T` (below) and held there for `T` (the hold
//! doubled up to three times until the residual settles); loads still gathered at the end were
//! captured by the run-up and stay so at that speed. Where it says `Bistable` and a `Balancing`
//! segment of the table is reachable through segments where the balancing position stays
//! stable, the loads are brought there balanced ([`Point::arrived`]): started near the
//! balancing position inside that segment, the rotor ramped to the speed the same way, and the
//! core's [`RegimeTracker`] fed the same ramp. A run lasts at least the scene's
//! `T = clamp(30/r, 1000, 10000)` in the seed's time `τ = ω̃·t` (`r = min(ε·β, 1/β)`, the slower
//! of the loads' own relaxation and the overdamped drift of the balancing position), and at
//! least `10/|σ|` with `σ` the Floquet growth rate of the least stable perturbation at that
//! speed (capped at 20 000 in `τ`), so that a slow decay or growth near a boundary has time to
//! show. Judgement, on the residual unbalance `|U|` over the final quarter of the run relative
//! to the rotor's `D`:
//!
//! - **balancing** when it stays at most 1 % throughout (the simulator's own definition);
//! - **gathering** when it reaches 10 % in the final quarter: the loads are away from the
//!   balancing position there (gathered, captured, or wandering past it). A run started near
//!   the balancing position begins below 10 % (its perturbation leaves 2–8 %), and a decaying
//!   one never climbs back above its start, so reaching 10 % this late means it has left;
//!   Loads started together begin far above 10 %; for them gathering needs the residual to
//!   stay at least 10 % throughout the final quarter (still decaying towards balance is not
//!   gathering);
//! - otherwise the run is repeated twice as long, up to eight times; a run still undecided
//!   then is judged balancing when its largest residual is below 3.16 % (the geometric middle
//!   of the two thresholds) and counted as **unsettled**.
//!
//! The run's own tolerances (`rtol` 1e-8, `atol` 1e-10, DOPRI5) are those of the scene.

use crate::app::predict;
use crate::app::regimes::{self, balanced_start, tracked, Design};
use crate::app::run::{run, Overrides};
use crate::app::scene::{MotorSpec, Scene, SceneError};
use crate::engine::vibration::floquet::{Floquet, ScanOptions};
// Balancing: the residual at most `BALANCED` of `D` over the final quarter; gathering: it
// reaches `AWAY` there (the thresholds `run` and `sweep` judge by too).
use crate::engine::vibration::regime::{RegimeReport, AWAY, BALANCED};
use drive_monitor::balancer::{
    BistableReason, Classifier, Machine, Regime, RegimeTable, ZoneKind, DEFAULT_MARGIN,
    TABLE_MARGIN,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::Serialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The range the random machines are drawn from (the seed's dimensionless groups; see
/// [`drive_monitor::balancer::Dimensionless`]).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Range {
    /// `ε = N·m/(κ·M_eΣ)`, drawn log-uniform.
    pub epsilon: [f64; 2],
    /// Damping ratio `h` of every support and coupling (`h_i`, `h_il`), drawn log-uniform.
    pub h: [f64; 2],
    /// `β = b_w·M_eΣ/(N·m²·ω̃)`, drawn log-uniform.
    pub beta: [f64; 2],
    /// Rotor unbalance over what the loads can balance, `D/(N·m·R)`, uniform.
    pub unbalance: [f64; 2],
    /// `n_i²` of the other platforms and `n_il²` of the couplings, uniform.
    pub n_sq: [f64; 2],
    /// `ρ_i = M_eΣ/M_i` of the other platforms, uniform.
    pub rho: [f64; 2],
}

/// The documented range: `ε` from small to moderate, light to heavy damping (`h` up to 0.2),
/// viscous loads from weakly to strongly damped (`β` 1 to 50).
pub const RANGE: Range = Range {
    epsilon: [0.005, 0.1],
    h: [0.01, 0.2],
    beta: [1.0, 50.0],
    unbalance: [0.3, 0.7],
    n_sq: [0.4, 2.0],
    rho: [0.5, 2.0],
};
/// Fixed physical scale of the random machines: `ω̃`, rad/s.
const OMEGA_REF: f64 = 50.0;
/// `M_eΣ`, kg.
const EXCITER_MASS: f64 = 100.0;
/// Auto-balancer housing, kg.
const HOUSING: f64 = 5.0;
/// Radius of the loads' track, m.
const RADIUS: f64 = 0.1;
/// Two balls (`κ = 7/5`).
const LOADS: f64 = 2.0;
const KAPPA: f64 = 1.4;
/// Speed grid per machine.
const GRID: usize = 40;
/// The exact classifier's margin band (the core's default for exact tables).
const BAND: f64 = TABLE_MARGIN as f64;
/// The criterion classifier's margin band (the core's default for the criterion).
const CRITERION_BAND: f64 = DEFAULT_MARGIN as f64;
/// Margins the exact classifier's agreement and commitment are also reported at.
pub const MARGINS: [f64; 5] = [0.0, 0.005, 0.01, 0.02, 0.05];
/// Relative distance either side of an exact boundary at which it is checked by simulation.
pub const CHECK_OFFSET: f64 = 0.01;
/// Floor of the run length from the Floquet rate: `10/|σ|`, capped at this many `τ`.
const RATE_RUN_CAP: f64 = 20_000.0;
/// Doublings of a run that has not settled.
const DOUBLINGS: u32 = 3;

/// One random machine: its groups and its scene.
#[derive(Debug, Clone, Serialize)]
pub struct Sample {
    /// Index in the study.
    pub id: usize,
    /// Platforms (1–3).
    pub platforms: usize,
    /// `ε`.
    pub epsilon: f64,
    /// `h`.
    pub h: f64,
    /// `β`.
    pub beta: f64,
    /// `D/(N·m·R)`.
    pub unbalance: f64,
    /// The machine as a scene file (run it with `drive-sim run`).
    #[serde(skip)]
    pub scene: String,
}

fn log_uniform(rng: &mut ChaCha8Rng, r: [f64; 2]) -> f64 {
    (r[0].ln() + rng.gen::<f64>() * (r[1].ln() - r[0].ln())).exp()
}

fn uniform(rng: &mut ChaCha8Rng, r: [f64; 2]) -> f64 {
    r[0] + rng.gen::<f64>() * (r[1] - r[0])
}

/// Draws machine `id` with `platforms` platforms from `range` (deterministic in `seed`).
pub fn draw(seed: u64, id: usize, platforms: usize, range: &Range) -> Sample {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ (id as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15));
    let epsilon = log_uniform(&mut rng, range.epsilon);
    let h = log_uniform(&mut rng, range.h);
    let beta = log_uniform(&mut rng, range.beta);
    let unbalance = uniform(&mut rng, range.unbalance);
    let others: Vec<(f64, f64)> = (1..platforms)
        .map(|_| (uniform(&mut rng, range.rho), uniform(&mut rng, range.n_sq)))
        .collect();
    let couplings: Vec<f64> = (1..platforms)
        .map(|_| uniform(&mut rng, range.n_sq))
        .collect();
    machine(id, epsilon, h, beta, unbalance, &others, &couplings)
}

/// The machine with the given groups as a scene: `1 + others.len()` platforms (the exciter is
/// platform 1 of one, platform 2 of two or three, as in the seed) with `ω̃` = 50 rad/s,
/// `M_eΣ` = 100 kg, two balls on a 0.1 m track; `others` holds `(ρ_i, n_i²)` of the other
/// platforms in order, `couplings` the `n_il²` of the chain 1–2, 2–3; every support and
/// coupling has damping ratio `h`; `unbalance` is `D/(N·m·R)`.
pub fn machine(
    id: usize,
    epsilon: f64,
    h: f64,
    beta: f64,
    unbalance: f64,
    others: &[(f64, f64)],
    couplings: &[f64],
) -> Sample {
    let platforms = 1 + others.len().min(2);
    let w = OMEGA_REF;
    let me = EXCITER_MASS;
    let m = epsilon * KAPPA * me / LOADS;
    let viscosity = beta * LOADS * m * m * w / me;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "description = \"Random {platforms}-platform machine {id}: eps = {epsilon:.4}, h = {h:.4}, beta = {beta:.3}, D/(N m R) = {unbalance:.3}\"\n"
    );
    let exciter = if platforms == 1 { 1 } else { 2 };
    let exciter_own = me - HOUSING - LOADS * m;
    // n_e² = 1 by the choice of ω̃ (stiffness over the moving mass M_eΣ).
    let exciter_stiffness = me * w * w;
    let mut other = others.iter();
    for i in 1..=platforms {
        if i == exciter {
            let _ = writeln!(
                s,
                "[[platform]]\nmass = {exciter_own:e}\nstiffness = {exciter_stiffness:e}\ndamping = {:e}\n",
                2.0 * h * me * w
            );
        } else if let Some(&(rho, n_sq)) = other.next() {
            let mass = me / rho;
            let _ = writeln!(
                s,
                "[[platform]]\nmass = {mass:e}\nstiffness = {:e}\ndamping = {:e}\n",
                n_sq * mass * w * w,
                2.0 * h * mass * w
            );
        }
    }
    for (pair, n_sq) in [[1, 2], [2, 3]].iter().zip(couplings).take(platforms - 1) {
        let _ = writeln!(
            s,
            "[[coupling]]\nbetween = [{}, {}]\nstiffness = {:e}\ndamping = {:e}\n",
            pair[0],
            pair[1],
            n_sq * me * w * w,
            2.0 * h * me * w
        );
    }
    let slow_rate = (epsilon * beta).min(1.0 / beta);
    let duration = (30.0 / slow_rate).clamp(1000.0, 10000.0) / w;
    let _ = writeln!(
        s,
        "[autobalancer]\nkind = \"ball\"\nplatform = {exciter}\nloads = {LOADS}\nload_mass = {m:e}\nradius = {RADIUS}\nhousing_mass = {HOUSING}\nviscosity = {viscosity:e}\nrotor_unbalance = {:e}\n\n[motor]\nmodel = \"speed\"\nspeed = {w}\n\n[simulation]\nduration = {duration:e}\nrtol = 1e-8\natol = 1e-10",
        unbalance * LOADS * m * RADIUS
    );
    Sample {
        id,
        platforms,
        epsilon,
        h,
        beta,
        unbalance,
        scene: s,
    }
}

/// What the loads did at one speed.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Outcome {
    /// Rotor speed, rad/s.
    pub speed: f64,
    /// The loads were started together at rest (else near the balancing position).
    pub together: bool,
    /// Judged balancing (see the module docs).
    pub balancing: bool,
    /// The run settled (balancing or gathering) within eight times its base length.
    pub settled: bool,
    /// Largest residual over the final quarter, relative to the rotor unbalance.
    pub residual_relative: f64,
    /// Smallest residual over the final quarter, relative to the rotor unbalance.
    pub residual_min_relative: f64,
    /// Length of the last run, in the seed's time `τ = ω̃·t`.
    pub duration_tau: f64,
    /// `1 − Ω/ω` over the final quarter: how much slower the loads turn than the rotor.
    pub slip: f64,
}

/// Simulates `scene` at `speed` for at least `min_duration` seconds (and the scene's own
/// duration), doubling the run until the residual has settled (module docs).
pub fn outcome(
    scene: &Scene,
    file: &Path,
    speed: f64,
    together: bool,
    min_duration: f64,
) -> Result<Outcome, SceneError> {
    let mut s = scene.clone();
    s.encoder = None;
    let base = s.simulation.duration.max(min_duration);
    let mut k = 0;
    loop {
        s.simulation.duration = base * f64::from(1u32 << k);
        let d = regime_of(&s, file, Some(speed), together)?;
        let balanced = d.residual_relative <= BALANCED;
        // Started near balance the residual begins below AWAY: reaching it means the loads
        // left. Started together it begins far above: only staying above it counts.
        let away = if together {
            d.residual_min_relative >= AWAY
        } else {
            d.residual_relative >= AWAY
        };
        if let Some(o) = judged_run(speed, together, &d, &s, (balanced, away), k == DOUBLINGS) {
            return Ok(o);
        }
        k += 1;
    }
}

/// The outcome of run `s` at `speed` from its regime samples `d`, judged `(balanced, away)`
/// (module docs), or `None` when neither holds and the run is to be doubled; after the
/// `last` doubling an undecided run is judged balancing below 3.16 % (the geometric middle
/// of the two thresholds) and counted as unsettled.
fn judged_run(
    speed: f64,
    together: bool,
    d: &RegimeReport,
    s: &Scene,
    (balanced, away): (bool, bool),
    last: bool,
) -> Option<Outcome> {
    (balanced || away || last).then(|| {
        let balancing = balanced || (!away && d.residual_relative < (BALANCED * AWAY).sqrt());
        Outcome::judged(speed, together, balancing, balanced || away, d, s)
    })
}

/// A run-up to `speed`: the loads started together at rest with the rotor at `from`, the
/// rotor ramped linearly to `speed` over `ramp` seconds and held there ([`ramp_outcome`]).
/// Gathered at the end (residual at least 10 % throughout the final quarter): the loads a
/// run-up captured stayed captured at `speed`; balanced: they were released on the way or
/// during the hold.
pub fn runup_outcome(
    scene: &Scene,
    file: &Path,
    from: f64,
    speed: f64,
    ramp: f64,
) -> Result<Outcome, SceneError> {
    ramp_outcome(scene, file, from, speed, ramp, true)
}

/// The rotor ramped linearly from `from` to `speed` over `ramp` seconds and held there as
/// long, the loads started together at rest (`together`) or near the balancing position;
/// judged on the final quarter of the run (inside the hold): balanced when the residual stays
/// at most 1 % there, gathered when it stays at least 10 % throughout. Otherwise the hold is
/// doubled, up to three times, as [`outcome`] doubles its runs, and a run still undecided is
/// judged as there (balancing below 3.16 %, unsettled).
pub fn ramp_outcome(
    scene: &Scene,
    file: &Path,
    from: f64,
    speed: f64,
    ramp: f64,
    together: bool,
) -> Result<Outcome, SceneError> {
    let mut s = scene.clone();
    s.encoder = None;
    s.motor = Some(MotorSpec::Ramp {
        from,
        to: speed,
        duration: ramp,
    });
    let mut k = 0;
    loop {
        s.simulation.duration = ramp * (1.0 + f64::from(1u32 << k));
        let d = regime_of(&s, file, None, together)?;
        let balanced = d.residual_relative <= BALANCED;
        let away = d.residual_min_relative >= AWAY;
        if let Some(o) = judged_run(speed, together, &d, &s, (balanced, away), k == DOUBLINGS) {
            return Ok(o);
        }
        k += 1;
    }
}

/// Runs `s` (at a prescribed `speed`, or with its own motor) and returns its regime samples.
fn regime_of(
    s: &Scene,
    file: &Path,
    speed: Option<f64>,
    loads_together: bool,
) -> Result<RegimeReport, SceneError> {
    let r = run(
        s,
        file,
        Overrides {
            speed,
            loads_together,
        },
    )?;
    r.regime_detail.ok_or_else(|| {
        SceneError::value(file, "autobalancer", "the run produced no regime samples")
    })
}

impl Outcome {
    /// The outcome of run `s` at `speed`, judged `balancing` (and `settled`) from `d`.
    fn judged(
        speed: f64,
        together: bool,
        balancing: bool,
        settled: bool,
        d: &RegimeReport,
        s: &Scene,
    ) -> Self {
        Outcome {
            speed,
            together,
            balancing,
            settled,
            residual_relative: d.residual_relative,
            residual_min_relative: d.residual_min_relative,
            duration_tau: s.simulation.duration * OMEGA_REF,
            slip: 1.0 - d.load_speed / d.rotor_speed,
        }
    }
}

/// One grid speed: the classes and what the simulation did.
#[derive(Debug, Clone, Serialize)]
pub struct Point {
    /// Rotor speed, rad/s.
    pub speed: f64,
    /// The exact table's class here, without a margin band (`"balancing"`, `"gathering"`,
    /// `"bistable"`); within a band of relative half-width `m` about a table boundary
    /// (`distance ≤ m`) the classifier says `"near-characteristic"` instead.
    pub class: &'static str,
    /// Why bistable (`"capture"`, `"coexisting"`), if so.
    pub reason: Option<&'static str>,
    /// The balancing position is stable here (Floquet).
    pub stable: bool,
    /// Floquet growth rate of the least stable perturbation, per unit of the seed's time `τ`.
    pub growth_rate: f64,
    /// Distance to the nearest boundary of the exact table, relative to it.
    pub distance: f64,
    /// The criterion's zone: `"balancing"` or `"gathering"`.
    pub criterion: &'static str,
    /// Distance to the nearest criterion boundary, relative to it.
    pub criterion_distance: f64,
    /// Started near the balancing position.
    pub simulated: Outcome,
    /// Started with the loads together at rest: only where the exact class is `Balancing` or
    /// `Bistable` and [`Point::distance`] exceeds the default margin band. Where the class is
    /// `Bistable` it shows whether the gathered attractor exists.
    pub together: Option<Outcome>,
    /// A slow run-up to this speed with the loads together at rest, then a hold
    /// ([`runup_outcome`]): only where the class is bistable for capture outside the default
    /// margin band. Whether loads a run-up captured stay captured here.
    pub runup: Option<Outcome>,
    /// Where the class is bistable (outside the default margin band) and a `Balancing`
    /// segment of the table is reachable through segments where the balancing position is
    /// stable: the loads balanced there and the speed brought here ([`Arrival`]).
    pub arrived: Option<Arrival>,
}

/// A bistable speed reached with the loads balanced: the rotor ramped from a speed inside the
/// nearest `Balancing` segment reachable through stable segments (the geometric middle of a
/// bounded one, 1.1 times the start of the last) to this speed over the machine's base run
/// time and held, the loads started near the balancing position ([`ramp_outcome`]); the
/// core's [`RegimeTracker`] fed the same ramp.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Arrival {
    /// Where the ramp started, rad/s.
    pub from: f64,
    /// The tracker's regime at the end of the ramp (`"balancing"` from the loads' history).
    pub class: &'static str,
    /// The tracker reported it from history ([`drive_monitor::balancer::RegimeStatus::by_history`]).
    pub by_history: bool,
    /// What the loads did.
    pub outcome: Outcome,
}

/// An exact boundary checked by simulation and by a tighter integration.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct BoundaryCheck {
    /// The boundary, rad/s.
    pub speed: f64,
    /// `speed/ω̃`.
    pub q: f64,
    /// Stable above it.
    pub stable_above: bool,
    /// Relative offset of the two simulations: [`CHECK_OFFSET`], or less when the next
    /// boundary is closer (0.4 of the relative gap to it).
    pub offset: f64,
    /// Simulated at `speed·(1 − offset)`.
    pub below: Outcome,
    /// Simulated at `speed·(1 + offset)`.
    pub above: Outcome,
    /// Both simulations as the boundary says.
    pub agrees: bool,
    /// Spectral radius at the ends of the final bracket with the monodromy integrated to
    /// rtol 1e-14 (the map's: 1e-10).
    pub tight_radius: [f64; 2],
    /// The tighter integration puts the boundary inside the same bracket.
    pub tight_agrees: bool,
}

/// A criterion boundary beside the exact ones.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Shift {
    /// The criterion's boundary `b`, rad/s.
    pub criterion: f64,
    /// `b/ω̃`.
    pub q: f64,
    /// "resonance" (gathering below, balancing above) or "additional" (the reverse).
    pub kind: &'static str,
    /// The nearest exact boundary of the same kind, rad/s.
    pub nearest: Option<f64>,
    /// Resonance: the speed from which the balancing position stays stable up to the
    /// criterion zone's end (the geometric midpoint to the next criterion boundary, or the
    /// scan's top for the last zone); `None` if it is not stable there. Additional: the speed
    /// up to which it is stable from the zone's start (the midpoint to the previous
    /// boundary); `None` if it is not.
    pub holds: Option<f64>,
    /// `holds/b − 1`.
    pub shift: Option<f64>,
}

/// One machine's results.
#[derive(Debug, Clone, Serialize)]
pub struct MachineResult {
    /// The machine.
    pub sample: Sample,
    /// The design-time analysis (exact boundaries, table, criterion comparison).
    pub design: Design,
    /// Wall time of the design-time analysis, s.
    pub design_seconds: f64,
    /// Grid outcomes, ascending speed.
    pub points: Vec<Point>,
    /// Every exact boundary, checked.
    pub checks: Vec<BoundaryCheck>,
    /// Every criterion boundary, beside the exact ones.
    pub shifts: Vec<Shift>,
}

fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect()
}

/// Relative distance from `w` to the nearest of `bounds` (∞ without any).
fn distance(w: f64, bounds: impl Iterator<Item = f64>) -> f64 {
    bounds
        .map(|b| (w / b - 1.0).abs())
        .fold(f64::INFINITY, f64::min)
}

/// The criterion boundaries beside the exact stability map.
fn shifts(machine: &Machine, design: &Design) -> Vec<Shift> {
    let Some(exact) = &design.exact else {
        return Vec::new();
    };
    let map = &exact.map;
    let bounds: Vec<f64> = machine.zones().iter().skip(1).map(|z| z.from).collect();
    bounds
        .iter()
        .enumerate()
        .map(|(k, &b)| {
            let resonance = machine.zone_kind_at(b * (1.0 + 1e-9)) == ZoneKind::Balancing;
            let nearest = exact
                .comparison
                .iter()
                .find(|c| c.criterion == b)
                .and_then(|c| c.exact);
            let holds = if resonance {
                let end = bounds
                    .get(k + 1)
                    .map_or(map.options.to, |&n| (n * b).sqrt());
                // The last change of stability below the zone's end; stable from there on.
                let last = map.boundaries.iter().rev().find(|x| x.speed < end);
                match last {
                    _ if !map.stable_at(end * (1.0 - 1e-9)) => None,
                    Some(x) => Some(x.speed),
                    None => Some(map.options.from),
                }
            } else {
                let start = k
                    .checked_sub(1)
                    .and_then(|j| bounds.get(j))
                    .map_or(map.options.from, |&p| (p * b).sqrt());
                let first = map.boundaries.iter().find(|x| x.speed > start);
                match first {
                    _ if !map.stable_at(start * (1.0 + 1e-9)) => None,
                    Some(x) => Some(x.speed),
                    None => Some(map.options.to),
                }
            };
            Shift {
                criterion: b,
                q: b / OMEGA_REF,
                kind: if resonance { "resonance" } else { "additional" },
                nearest,
                holds,
                shift: holds.map(|h| h / b - 1.0),
            }
        })
        .collect()
}

/// Studies one machine.
pub fn study_machine(sample: Sample) -> Result<MachineResult, SceneError> {
    let file = PathBuf::from(format!("random-machine-{}.toml", sample.id));
    let scene = Scene::parse(&sample.scene, &file)?;
    let Some(machine) = predict::machine(&scene, &file)? else {
        return Err(SceneError::value(&file, "autobalancer", "missing"));
    };
    let started = std::time::Instant::now();
    let Some(design) = regimes::design(&scene, &file, &machine)? else {
        return Err(SceneError::value(&file, "autobalancer", "missing"));
    };
    let design_seconds = started.elapsed().as_secs_f64();
    let Some(exact) = &design.exact else {
        return Err(SceneError::value(
            &file,
            "autobalancer",
            "no balancing position to analyse",
        ));
    };
    let segments = regimes::core_segments(&exact.segments, &file)?;
    let table = RegimeTable {
        segments: &segments,
    };
    let bad = |e| predict::value_error(&file, "monitor", e);
    let classifier = Classifier::from_table(&table, 0.0, 0.0).map_err(bad)?;
    // The run-time tracker as firmware would build it: the default band, no hysteresis (the
    // ramps it is fed are monotone).
    let tracker = Classifier::from_table(&table, TABLE_MARGIN, 0.0).map_err(bad)?;
    let Some(vm) = regimes::vibration_machine(&scene, &file)? else {
        return Err(SceneError::value(&file, "autobalancer", "missing"));
    };
    let floquet =
        Floquet::new(&vm).map_err(|e| SceneError::value(&file, "autobalancer", e.to_string()))?;
    let rtol = exact.map.options.rtol;
    let rate = |w: f64| -> Result<f64, SceneError> {
        floquet
            .multipliers(w, rtol)
            .map(|m| m.growth_rate())
            .map_err(|e| SceneError::value(&file, "autobalancer", e.to_string()))
    };
    // A run long enough for the Floquet rate to show: 10/|σ|, capped.
    let min_run = |sigma: f64| (10.0 / sigma.abs()).min(RATE_RUN_CAP / OMEGA_REF);
    let criterion_bounds: Vec<f64> = machine.zones().iter().skip(1).map(|z| z.from).collect();
    // The grid reaches past every capture window: where capture ends is part of the check.
    let until = machine
        .capture_windows()
        .iter()
        .fold(0.0f64, |u, c| u.max(c.until));
    let (lo, hi) = match (criterion_bounds.first(), criterion_bounds.last()) {
        (Some(&a), Some(&b)) => (0.5 * a, (2.0 * b).max(1.25 * until).min(8.0 * b)),
        _ => (0.5 * OMEGA_REF, 2.0 * OMEGA_REF),
    };
    let base = scene.simulation.duration;
    let mut points = Vec::with_capacity(GRID);
    for w in grid(lo, hi, GRID) {
        let sigma = rate(w)?;
        let class = classifier.classify(w as f32);
        let simulated = outcome(&scene, &file, w, false, min_run(sigma))?;
        let near = distance(w, classifier.boundaries().iter().map(|&b| f64::from(b)));
        // Balancing: does the gathered state also balance? Bistable: is it there at all?
        let both = matches!(class, Regime::Balancing | Regime::Bistable(_));
        let together = if both && near > BAND {
            Some(outcome(&scene, &file, w, true, min_run(sigma))?)
        } else {
            None
        };
        // Capture: from the grid's lowest speed (half the first characteristic speed), ramped
        // over the machine's base run time and held as long.
        let runup = if class.reason() == Some(BistableReason::Capture) && near > BAND {
            Some(runup_outcome(&scene, &file, lo, w, base)?)
        } else {
            None
        };
        // Bistable: reached with the loads balanced, as the core's tracker is told.
        let arrived = match balanced_start(&segments, w) {
            Some(from) if matches!(class, Regime::Bistable(_)) && near > BAND => {
                let st = tracked(&tracker, from, w);
                Some(Arrival {
                    from,
                    class: st.regime.name(),
                    by_history: st.by_history,
                    outcome: ramp_outcome(&scene, &file, from, w, base, false)?,
                })
            }
            _ => None,
        };
        points.push(Point {
            speed: w,
            class: class.name(),
            reason: class.reason().map(|r| r.name()),
            stable: exact.map.stable_at(w),
            growth_rate: sigma / OMEGA_REF,
            distance: near,
            criterion: machine.zone_kind_at(w).name(),
            criterion_distance: distance(w, criterion_bounds.iter().copied()),
            simulated,
            together,
            runup,
            arrived,
        });
    }
    let mut checks = Vec::new();
    let speeds: Vec<f64> = exact.map.boundaries.iter().map(|b| b.speed).collect();
    for b in &exact.map.boundaries {
        // Stay inside the neighbouring intervals: a narrow stable window is checked inside.
        let gap = speeds
            .iter()
            .filter(|&&x| x != b.speed)
            .map(|&x| (x / b.speed - 1.0).abs())
            .fold(f64::INFINITY, f64::min);
        let offset = CHECK_OFFSET.min(0.4 * gap);
        let (wl, wh) = (b.speed * (1.0 - offset), b.speed * (1.0 + offset));
        let below = outcome(&scene, &file, wl, false, min_run(rate(wl)?))?;
        let above = outcome(&scene, &file, wh, false, min_run(rate(wh)?))?;
        let tight = |w: f64| {
            floquet
                .multipliers(w, 1e-14)
                .map(|m| m.radius)
                .map_err(|e| SceneError::value(&file, "autobalancer", e.to_string()))
        };
        let tight_radius = [tight(b.bracket[0])?, tight(b.bracket[1])?];
        checks.push(BoundaryCheck {
            speed: b.speed,
            q: b.speed / OMEGA_REF,
            stable_above: b.stable_above,
            offset,
            below,
            above,
            agrees: below.balancing != b.stable_above && above.balancing == b.stable_above,
            tight_radius,
            tight_agrees: (tight_radius[0] < 1.0) != b.stable_above
                && (tight_radius[1] < 1.0) == b.stable_above,
        });
    }
    let shifts = shifts(&machine, &design);
    Ok(MachineResult {
        sample,
        design_seconds,
        points,
        checks,
        shifts,
        design,
    })
}

/// The whole study.
#[derive(Debug, Clone, Serialize)]
pub struct Study {
    /// Seed of the draws.
    pub seed: u64,
    /// The range.
    pub range: Range,
    /// Per machine.
    pub machines: Vec<MachineResult>,
}

/// Draws `count` machines (platforms cycling 1, 2, 3) and studies them in parallel.
pub fn study(seed: u64, count: usize, progress: bool) -> Result<Study, SceneError> {
    let bar = crate::app::progress::progress_bar(count, "machines", progress);
    let machines = (0..count)
        .into_par_iter()
        .map(|id| {
            let r = study_machine(draw(seed, id, 1 + id % 3, &RANGE));
            bar.inc(1);
            r
        })
        .collect::<Result<Vec<_>, _>>()?;
    bar.finish_and_clear();
    Ok(Study {
        seed,
        range: RANGE,
        machines,
    })
}

/// What loads started together at rest did at the speeds of one bistable reason.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Together {
    /// Speeds classed bistable for this reason (outside the margin band).
    pub speeds: usize,
    /// Of those, where the loads were also started together at rest (outside the default
    /// band only).
    pub started: usize,
    /// Of those, where they stayed gathered (settled: residual at least 10 % throughout the
    /// final quarter): the gathered attractor exists beside the balancing one.
    pub gathered: usize,
    /// Where they balanced (settled): the gathered state was not reached from that start.
    pub balanced: usize,
    /// Where the run had not settled after its doublings.
    pub unsettled: usize,
}

impl Together {
    fn count(&mut self, o: Option<Outcome>) {
        self.speeds += 1;
        let Some(o) = o else {
            return;
        };
        self.started += 1;
        match (o.settled, o.balancing) {
            (false, _) => self.unsettled += 1,
            (true, true) => self.balanced += 1,
            (true, false) => self.gathered += 1,
        }
    }
}

/// The exact classifier's record at one margin.
#[derive(Debug, Clone, Copy, Default, Serialize)]
pub struct Tally {
    /// The margin band, relative.
    pub margin: f64,
    /// Grid speeds.
    pub speeds: usize,
    /// Speeds where the classifier commits (`Balancing` or `Gathering`).
    pub committed: usize,
    /// Of those, where the simulation (started near the balancing position) agrees.
    pub agreeing: usize,
    /// Committed to `Balancing`.
    pub balancing: usize,
    /// Of those, where the loads were also started together at rest (outside the default
    /// band only).
    pub together: usize,
    /// Of those, where the loads started together at rest also balanced.
    pub together_balancing: usize,
    /// Speeds classed bistable for capture.
    pub capture: usize,
    /// Speeds classed bistable for coexisting gathered loads.
    pub coexisting: usize,
    /// Loads started together at rest at the speeds bistable for capture.
    pub capture_together: Together,
    /// The same speeds after a slow run-up with the loads together ([`Point::runup`]).
    pub capture_runup: Together,
    /// Loads started together at rest at the speeds bistable for coexisting gathered loads.
    pub coexisting_together: Together,
    /// Bistable speeds (either reason) the loads can reach balanced ([`Point::arrived`]).
    pub reachable: usize,
    /// Of those, where the core's tracker, fed the ramp, commits from the loads' history.
    pub history_committed: usize,
    /// Of those, where the loads brought there balanced stayed balanced (settled).
    pub history_agreeing: usize,
}

impl Tally {
    /// Committed fraction of the speeds.
    pub fn commit_rate(&self) -> f64 {
        self.committed as f64 / self.speeds.max(1) as f64
    }
    /// Agreeing fraction of the committed speeds.
    pub fn agreement(&self) -> f64 {
        self.agreeing as f64 / self.committed.max(1) as f64
    }
    /// Committed fraction of the speeds when the loads are known to have balanced: the
    /// table's committed speeds and the bistable ones where the tracker commits from
    /// history ([`Point::arrived`]).
    pub fn history_commit_rate(&self) -> f64 {
        (self.committed + self.history_committed) as f64 / self.speeds.max(1) as f64
    }
    /// Agreeing fraction of [`Tally::history_commit_rate`]'s committed speeds: the table's
    /// agreeing ones and the bistable ones where the loads brought there balanced stayed so.
    pub fn history_agreement(&self) -> f64 {
        (self.agreeing + self.history_agreeing) as f64
            / (self.committed + self.history_committed).max(1) as f64
    }
    /// What if: the committed fraction were every bistable speed where gathered loads were
    /// not seen to persist committed as balancing: for capture, where a run-up released them
    /// (settled, [`Point::runup`]); for coexisting loads, where loads started together at rest
    /// balanced (settled). Not the classifier's figure.
    pub fn what_if_commit_rate(&self) -> f64 {
        (self.committed + self.capture_runup.balanced + self.coexisting_together.balanced) as f64
            / self.speeds.max(1) as f64
    }
}

/// The exact classifier's record over the study with margin `margin`.
pub fn tally(s: &Study, margin: f64) -> Tally {
    tally_where(s, margin, |_, _| true)
}

/// [`tally`] over the points `keep` accepts.
pub fn tally_where(s: &Study, margin: f64, keep: impl Fn(&MachineResult, &Point) -> bool) -> Tally {
    tally_points(
        margin,
        s.machines
            .iter()
            .flat_map(|m| m.points.iter().map(move |p| (m, p)))
            .filter(|(m, p)| keep(m, p))
            .map(|(_, p)| p),
    )
}

/// The exact classifier's record over `points` with margin `margin`.
pub fn tally_points<'a>(margin: f64, points: impl Iterator<Item = &'a Point>) -> Tally {
    let mut t = Tally {
        margin,
        ..Tally::default()
    };
    for p in points {
        t.speeds += 1;
        if p.distance <= margin {
            continue;
        }
        match (p.class, p.reason) {
            ("balancing", _) => {
                t.committed += 1;
                t.balancing += 1;
                t.agreeing += usize::from(p.simulated.balancing);
                t.together += usize::from(p.together.is_some());
                t.together_balancing += usize::from(p.together.is_some_and(|o| o.balancing));
            }
            ("gathering", _) => {
                t.committed += 1;
                t.agreeing += usize::from(!p.simulated.balancing);
            }
            (_, Some("capture")) => {
                t.capture += 1;
                t.capture_together.count(p.together);
                t.capture_runup.count(p.runup);
            }
            _ => {
                t.coexisting += 1;
                t.coexisting_together.count(p.together);
            }
        }
        if let Some(a) = p.arrived {
            t.reachable += 1;
            // The tracker commits from history only to balancing.
            if a.by_history {
                t.history_committed += 1;
                t.history_agreeing += usize::from(a.outcome.settled && a.outcome.balancing);
            }
        }
    }
    t
}

/// The committed speeds where the simulation disagrees, with the default margin: (machine,
/// point).
pub fn disagreements(s: &Study) -> Vec<(&MachineResult, &Point)> {
    s.machines
        .iter()
        .flat_map(|m| m.points.iter().map(move |p| (m, p)))
        .filter(|(_, p)| {
            p.distance > BAND
                && match p.class {
                    "balancing" => {
                        !p.simulated.balancing || p.together.is_some_and(|o| !o.balancing)
                    }
                    "gathering" => p.simulated.balancing,
                    _ => false,
                }
        })
        .collect()
}

/// The criterion classifier's record (the seed's zones with the capture check, margin
/// [`DEFAULT_MARGIN`]): (speeds outside its band, of which its zone agrees with the
/// simulation, committed speeds, of which agreeing).
pub fn criterion_record(s: &Study) -> (usize, usize, usize, usize) {
    let mut r = (0, 0, 0, 0);
    for p in s.machines.iter().flat_map(|m| &m.points) {
        if p.criterion_distance <= CRITERION_BAND {
            continue;
        }
        r.0 += 1;
        let agree = (p.criterion == "balancing") == p.simulated.balancing;
        r.1 += usize::from(agree);
    }
    for m in &s.machines {
        let file = PathBuf::from("criterion");
        let Ok(Some(machine)) =
            Scene::parse(&m.sample.scene, &file).and_then(|sc| predict::machine(&sc, &file))
        else {
            continue;
        };
        let Ok(c) = Classifier::new(&machine, CRITERION_BAND as f32, 0.0) else {
            continue;
        };
        for p in &m.points {
            match c.classify(p.speed as f32) {
                Regime::Balancing => {
                    r.2 += 1;
                    r.3 += usize::from(p.simulated.balancing);
                }
                Regime::Gathering => {
                    r.2 += 1;
                    r.3 += usize::from(!p.simulated.balancing);
                }
                _ => {}
            }
        }
    }
    r
}

fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[((v.len() - 1) as f64 * q).round() as usize]
}

fn pct(x: f64) -> String {
    format!("{:.1} %", 100.0 * x)
}

fn signed(x: Option<f64>) -> String {
    x.map_or("—".to_string(), |v| format!("{:+.2} %", 100.0 * v))
}

/// All checks of exact boundaries: (machine, check).
fn all_checks(s: &Study) -> Vec<(&MachineResult, &BoundaryCheck)> {
    s.machines
        .iter()
        .flat_map(|m| m.checks.iter().map(move |c| (m, c)))
        .collect()
}

/// All criterion boundaries with their machine and index.
fn all_shifts(s: &Study) -> Vec<(&Sample, usize, &Shift)> {
    s.machines
        .iter()
        .flat_map(|m| {
            m.shifts
                .iter()
                .enumerate()
                .map(move |(k, b)| (&m.sample, k, b))
        })
        .collect()
}

/// The headline numbers as text (also the end of [`summary_text`]).
pub fn headline(s: &Study) -> String {
    let t = tally(s, BAND);
    let checks = all_checks(s);
    let sim_ok = checks.iter().filter(|(_, c)| c.agrees).count();
    let tight_ok = checks.iter().filter(|(_, c)| c.tight_agrees).count();
    let unsettled = s
        .machines
        .iter()
        .flat_map(|m| &m.points)
        .flat_map(|p| {
            // The together-start runs at bistable speeds are reported on their own.
            let together = p.together.as_ref().filter(|_| p.class == "balancing");
            std::iter::once(&p.simulated).chain(together)
        })
        .filter(|o| !o.settled)
        .count();
    format!(
        "{} machines, {} speeds: with the ±{:.0} % margin the exact classifier commits at {} \
         ({}) and the simulation agrees at {} of them ({}); loads started together at rest \
         balanced at {} of {} speeds committed to balancing; {} runs unsettled. With the \
         loads known to have balanced (the run-time tracker), it commits at {} ({}) and \
         agrees at {} ({}). Exact \
         boundaries: {} of {} confirmed by simulation at ±{:.0} %, {} of {} unchanged by a 10⁴× \
         tighter integration.",
        s.machines.len(),
        t.speeds,
        100.0 * BAND,
        t.committed,
        pct(t.commit_rate()),
        t.agreeing,
        pct(t.agreement()),
        t.together_balancing,
        t.together,
        unsettled,
        t.committed + t.history_committed,
        pct(t.history_commit_rate()),
        t.agreeing + t.history_agreeing,
        pct(t.history_agreement()),
        sim_ok,
        checks.len(),
        100.0 * CHECK_OFFSET,
        tight_ok,
        checks.len()
    )
}

/// Per-boundary table (Markdown): every criterion boundary beside the exact ones.
pub fn boundary_table(s: &Study) -> String {
    let mut t = String::from(
        "| machine | P | ε | h | β | D/(N·m·R) | kind | criterion b, rad/s | q = b/ω̃ | nearest exact | stable from / to | shift |\n\
         |---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|\n",
    );
    for m in &s.machines {
        let p = &m.sample;
        for b in &m.shifts {
            let _ = writeln!(
                t,
                "| {} | {} | {:.4} | {:.3} | {:.2} | {:.2} | {} | {:.2} | {:.3} | {} | {} | {} |",
                p.id,
                p.platforms,
                p.epsilon,
                p.h,
                p.beta,
                p.unbalance,
                b.kind,
                b.criterion,
                b.q,
                b.nearest.map_or("—".to_string(), |x| format!("{x:.2}")),
                b.holds.map_or("—".to_string(), |x| format!("{x:.2}")),
                signed(b.shift)
            );
        }
    }
    t
}

/// A plain-text summary.
pub fn summary_text(s: &Study) -> String {
    let mut t = boundary_table(s);
    let _ = writeln!(t, "\n{}", headline(s));
    t
}

/// Writes `criterion.md`, `criterion-resonance.svg` and `criterion-additional.svg` into `dir`.
pub fn publish(s: &Study, dir: &Path) -> Result<Vec<PathBuf>, String> {
    use crate::app::plot::{write_svg, Chart, Mark, Series};
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let r = &s.range;
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# Regimes of the auto-balancer: the exact classifier against simulation on random machines\n\n\
         Regenerated by `cargo run --release -p host-sim -- criterion --machines {} --seed {} --out {}`.\n",
        s.machines.len(),
        s.seed,
        dir.display()
    );
    let scan = ScanOptions::new(1.0, 2.0);
    let _ = writeln!(
        t,
        "Method: `host-sim/src/studies/criterion.rs` (module docs). For each machine, where the \
         balancing position is stable comes from the model itself: the equations of motion \
         linearised about the balanced motion (loads turning with the rotor at the balancing \
         angles, platforms at rest: an exact periodic solution at a prescribed rotor speed), \
         whose monodromy matrix over one revolution is integrated (DOP853, rtol {:e}) and whose \
         Floquet multipliers decide stability, the neutral directions (moves along the family \
         of balancing positions, multiplier exactly 1) removed exactly, and the multiplier of \
         the loads' slow drift along what is such a direction at D = 0 set aside as neutral \
         where it lies within the integration's resolution of 1 (a rotor unbalance tiny against \
         the capacity) \
         (`host-sim/src/engine/vibration/floquet.rs`). The speeds where stability changes are \
         found on a grid of {} speeds per octave, with every near-critical extremum of the \
         spectral radius searched, and bisected to {:e} relative. The exact regime table \
         (`host-sim/src/app/regimes.rs`) commits to *gathering* where the balancing position is \
         unstable, to *balancing* where it is stable and no other state is known to persist, \
         and says *bistable* (with its reason) where it is stable but gathered loads can stay \
         captured below the rotor (`capture`: inside a capture window of the core, or of the \
         capture balance's fold at any resonance, `regimes::resonance_captures`) or held \
         together by the criterion's `Re H > 0` (`coexisting`). Each machine is then simulated \
         at {GRID} prescribed rotor speeds from half its first damped characteristic speed to \
         twice its last (and past its capture windows), the loads started at the balancing \
         position with one displaced by 0.05 rad; where the classifier commits to balancing or \
         says bistable, also with the loads together at rest, and where it says bistable for \
         capture, also run up slowly to the speed with the loads together (below). Judgement \
         (module docs): balancing when the \
         residual unbalance stays at most 1 % of the rotor's over the final quarter of the run, \
         gathering when it reaches 10 % there (started together: stays above 10 % there); runs \
         last at least the machine's base time and \
         10/|σ| (σ the Floquet growth rate there, capped at 20 000 in the seed's time), and are \
         doubled up to three times until one of the two holds.\n",
        scan.rtol, scan.per_octave, scan.rel_tol
    );
    let _ = writeln!(
        t,
        "Range (seed 001's groups; log-uniform unless said): ε = N·m/(κ·M_eΣ) in [{}, {}], \
         damping ratio h of every support and coupling in [{}, {}], β = b_w·M_eΣ/(N·m²·ω̃) in \
         [{}, {}], D/(N·m·R) uniform in [{}, {}], two balls; one, two and three platforms in \
         turn, the others with ρ_i and n_i², n_il² uniform in [{}, {}] and [{}, {}].\n",
        r.epsilon[0],
        r.epsilon[1],
        r.h[0],
        r.h[1],
        r.beta[0],
        r.beta[1],
        r.unbalance[0],
        r.unbalance[1],
        r.rho[0],
        r.rho[1],
        r.n_sq[0],
        r.n_sq[1]
    );
    let main = tally(s, BAND);
    let _ = writeln!(
        t,
        "## The exact classifier against simulation\n\n{}\n\n\
         With the core's default margin for exact tables (`TABLE_MARGIN`, ±{:.0} % about each \
         boundary of the table), the classifier commits at **{} of {} speeds ({})** and the \
         simulation agrees with it at **{} of {} ({})**. It does not commit at {} speeds \
         bistable for capture, {} bistable for coexisting gathered loads and {} within the \
         margin band. Where it commits to balancing, loads started together at rest (not near \
         the balancing position) also balanced at {} of {} speeds.\n",
        headline(s),
        100.0 * BAND,
        main.committed,
        main.speeds,
        pct(main.commit_rate()),
        main.agreeing,
        main.committed,
        pct(main.agreement()),
        main.capture,
        main.coexisting,
        main.speeds - main.committed - main.capture - main.coexisting,
        main.together_balancing,
        main.together
    );
    let misses: Vec<(&MachineResult, &Point)> = s
        .machines
        .iter()
        .flat_map(|m| m.points.iter().map(move |p| (m, p)))
        .filter(|(_, p)| {
            p.class == "balancing" && p.distance > BAND && p.together.is_some_and(|o| !o.balancing)
        })
        .collect();
    if !misses.is_empty() {
        let near = misses.iter().filter(|(_, p)| p.distance <= 0.03).count();
        let far: Vec<&(&MachineResult, &Point)> =
            misses.iter().filter(|(_, p)| p.distance > 0.03).collect();
        let slips: Vec<f64> = far
            .iter()
            .filter_map(|(_, p)| p.together.map(|o| o.slip))
            .filter(|&x| x > 1e-3)
            .collect();
        let mut machines: Vec<(usize, f64)> = far
            .iter()
            .map(|(m, _)| (m.sample.id, m.sample.beta))
            .collect();
        machines.dedup_by_key(|x| x.0);
        let _ = writeln!(
            t,
            "Of the {} speeds where loads started at rest did not balance, {near} lie within \
             3 % of a boundary of the table, just past the end of a capture band, the capture \
             balance's fold, which loads that start at rest pass slowly (the delay of a slow \
             passage through a fold). The other {} are on {} machines (β = {}); at {} of them the loads \
             still turned slower than the rotor at the end of the run (by {} to {}), slipping \
             past each other and the balancing position: a motion the capture theory does not \
             describe, reached from rest; the rest were still on their way. There the table's \
             *balancing* is what loads near the balancing position do.\n",
            misses.len(),
            far.len(),
            machines.len(),
            machines
                .iter()
                .map(|(_, b)| format!("{b:.1}"))
                .collect::<Vec<_>>()
                .join(", "),
            slips.len(),
            pct(slips.iter().copied().fold(f64::INFINITY, f64::min)),
            pct(slips.iter().copied().fold(0.0, f64::max)),
        );
    }
    let within = |m: &MachineResult, p: &Point| {
        m.shifts
            .last()
            .is_some_and(|b| p.speed <= 2.0 * b.criterion)
    };
    let core = tally_where(s, BAND, within);
    let _ = writeln!(
        t,
        "Bistable speeds are where the loads' history decides: in a capture band a slow run-up \
         leaves them captured (`docs/capture-one-mass-runup.md`), a start near the balancing \
         position leaves them balanced. The bands are wide where the machine is lightly \
         damped and its loads weakly viscous (the averaged capture balance reaches about \
         1 + 1/(4·h·β) times a single-platform resonance), and the grid above reaches past \
         every capture window. Up to twice the last characteristic speed only (without that \
         extension) the classifier commits at {} of {} speeds ({}), agreeing at {}. By third \
         of β's range:\n\n| β | speeds | committed | commit rate | agreeing |\n|---|---:|---:|---:|---:|",
        core.committed,
        core.speeds,
        pct(core.commit_rate()),
        pct(core.agreement())
    );
    for third in 0..3 {
        let edge = |k: f64| (r.beta[0].ln() + k / 3.0 * (r.beta[1].ln() - r.beta[0].ln())).exp();
        let (a, b) = (edge(third as f64), edge(third as f64 + 1.0));
        let x = tally_where(s, BAND, |m, _| m.sample.beta >= a && m.sample.beta < b);
        let _ = writeln!(
            t,
            "| [{a:.2}, {b:.2}) | {} | {} | {} | {} |",
            x.speeds,
            x.committed,
            pct(x.commit_rate()),
            pct(x.agreement())
        );
    }
    t.push_str(
        "\nThe same speeds with other margins (the class outside the band is the table's, \
         whatever the margin):\n\n\
         | margin | committed | commit rate | agreeing | agreement |\n|---:|---:|---:|---:|---:|\n",
    );
    for m in MARGINS {
        let x = tally(s, m);
        let _ = writeln!(
            t,
            "| ±{:.1} % | {} of {} | {} | {} | {} |",
            100.0 * m,
            x.committed,
            x.speeds,
            pct(x.commit_rate()),
            x.agreeing,
            pct(x.agreement())
        );
    }
    let dis = disagreements(s);
    if dis.is_empty() {
        t.push_str("\nNo committed speed disagrees with the simulation.\n");
    } else {
        let near_balance = dis
            .iter()
            .filter(|(_, p)| (p.class == "balancing") != p.simulated.balancing)
            .count();
        let _ = writeln!(
            t,
            "\nThe committed speeds where a simulation disagrees ({near_balance} of them started \
             near the balancing position, {} started together at rest):\n\n\
             | machine | speed, rad/s | class | distance to boundary | near balance: simulated (residual max) | together at rest: simulated (residual max, min) | slip 1 − Ω/ω | settled |\n\
             |---:|---:|---|---:|---|---|---:|---|",
            dis.len() - near_balance
        );
        let name = |b: bool| if b { "balancing" } else { "gathering" };
        for (m, p) in &dis {
            let tog = p.together;
            let _ = writeln!(
                t,
                "| {} | {:.2} | {} | {:.2} % | {} ({:.1e}) | {} | {} | {} |",
                m.sample.id,
                p.speed,
                p.class,
                100.0 * p.distance,
                name(p.simulated.balancing),
                p.simulated.residual_relative,
                tog.map_or("—".to_string(), |o| format!(
                    "{} ({:.2}, {:.2})",
                    name(o.balancing),
                    o.residual_relative,
                    o.residual_min_relative
                )),
                tog.map_or("—".to_string(), |o| pct(o.slip)),
                if p.simulated.settled && tog.is_none_or(|o| o.settled) {
                    "yes"
                } else {
                    "no"
                }
            );
        }
    }
    let (away, agree, committed, committed_agree) = criterion_record(s);
    let _ = writeln!(
        t,
        "\nFor comparison, the seed's criterion on the same runs: its zone agrees with the \
         simulation at {agree} of {away} speeds outside ±{:.0} % of its boundaries ({}); the \
         core's criterion classifier (`Classifier::new`, capture band `Bistable`, margin ±{:.0} \
         %) commits at {committed} of {} speeds ({}) and agrees at {committed_agree} of them \
         ({}).\n",
        100.0 * CRITERION_BAND,
        pct(agree as f64 / away.max(1) as f64),
        100.0 * CRITERION_BAND,
        main.speeds,
        pct(committed as f64 / main.speeds.max(1) as f64),
        pct(committed_agree as f64 / committed.max(1) as f64)
    );
    history_section(&mut t, s);
    together_section(&mut t, s);
    // Exact boundaries checked.
    let checks = all_checks(s);
    let sim_ok = checks.iter().filter(|(_, c)| c.agrees).count();
    let tight_ok = checks.iter().filter(|(_, c)| c.tight_agrees).count();
    let drift = s
        .machines
        .iter()
        .filter_map(|m| m.design.exact.as_ref())
        .map(|e| e.map.neutral_drift)
        .fold(0.0f64, f64::max);
    let neutral = s
        .machines
        .iter()
        .filter(|m| m.design.rotor_unbalance == 0.0)
        .count();
    let narrow = checks
        .iter()
        .filter(|(_, c)| c.offset < CHECK_OFFSET)
        .count();
    let mut secs: Vec<f64> = s.machines.iter().map(|m| m.design_seconds).collect();
    let mut evals: Vec<f64> = s
        .machines
        .iter()
        .filter_map(|m| m.design.exact.as_ref())
        .map(|e| e.map.evaluations as f64)
        .collect();
    let most_steps = s
        .machines
        .iter()
        .filter_map(|m| m.design.exact.as_ref())
        .map(|e| e.map.steps)
        .max()
        .unwrap_or(0);
    let unresolved = s
        .machines
        .iter()
        .filter_map(|m| m.design.exact.as_ref())
        .filter(|e| e.map.unresolved.is_some())
        .count();
    let unresolved_text = if unresolved == 0 {
        " No machine's slow drift came within the integration's resolution of 1.".to_string()
    } else {
        format!(
            " At {unresolved} machines the slow drift's multiplier came within the integration's \
             resolution of 1 at some speeds and was set aside as neutral there."
        )
    };
    let neutral_text = if neutral == 0 {
        "Every machine has a rotor unbalance (D > 0), so none has a neutral direction to remove."
            .to_string()
    } else {
        format!(
            "The neutral directions of the {neutral} machines without rotor unbalance stay \
             neutral to {drift:.1e} over a revolution (the largest drift met)."
        )
    } + &unresolved_text;
    let _ = writeln!(
        t,
        "## The exact boundaries checked\n\n\
         {} boundaries over {} machines. Simulated at ±{:.0} % of each ({narrow} lie closer to \
         their neighbour than that and are simulated at 0.4 of the gap), both sides came out \
         as the Floquet analysis says at **{sim_ok} of {}**; integrated 10⁴ times more tightly \
         (rtol 1e-14), the spectral radius at the ends of each final bracket keeps its side of \
         1 at **{tight_ok} of {}** (the bracket is 1e-7 wide: the boundary is placed to better \
         than 1e-6). {neutral_text} The analysis integrated {:.0} monodromy matrices per \
         machine at the median ({:.0} at most; a scan took at most {most_steps} integration \
         steps, against the million `floquet::SCAN_STEPS` allows), in {:.2} s (median; {:.2} s \
         at most) of wall \
         time per machine, release build, the machines two at a time on this machine's two \
         cores. `host-sim/tests/vibration.rs` checks the analysis against a Floquet analysis of \
         seed eq. 4 written independently (boundaries to 1e-6) and against the growth rate of a \
         small perturbation in the nonlinear simulation.\n",
        checks.len(),
        s.machines.len(),
        100.0 * CHECK_OFFSET,
        checks.len(),
        checks.len(),
        quantile(&mut evals, 0.5),
        evals.last().copied().unwrap_or(f64::NAN),
        quantile(&mut secs, 0.5),
        secs.last().copied().unwrap_or(f64::NAN),
    );
    let failed: Vec<_> = checks
        .iter()
        .filter(|(_, c)| !c.agrees || !c.tight_agrees)
        .collect();
    if !failed.is_empty() {
        t.push_str(
            "| machine | boundary, rad/s | q | stable above | below: simulated (residual max, min) | above: simulated (residual max, min) | tighter integration agrees |\n\
             |---:|---:|---:|---|---|---|---|\n",
        );
        let o = |x: &Outcome| {
            format!(
                "{}{} ({:.1e}, {:.1e})",
                if x.balancing {
                    "balancing"
                } else {
                    "gathering"
                },
                if x.settled { "" } else { ", unsettled" },
                x.residual_relative,
                x.residual_min_relative
            )
        };
        for (m, c) in &failed {
            let _ = writeln!(
                t,
                "| {} | {:.3} | {:.4} | {} | {} | {} | {} |",
                m.sample.id,
                c.speed,
                c.q,
                c.stable_above,
                o(&c.below),
                o(&c.above),
                c.tight_agrees
            );
        }
        t.push('\n');
    }
    // The criterion beside the exact boundaries.
    let shifts = all_shifts(s);
    let first: Vec<_> = shifts
        .iter()
        .filter(|(_, k, b)| *k == 0 && b.kind == "resonance")
        .collect();
    let resonances: Vec<_> = shifts
        .iter()
        .filter(|(_, _, b)| b.kind == "resonance")
        .collect();
    let additional: Vec<_> = shifts
        .iter()
        .filter(|(_, _, b)| b.kind == "additional")
        .collect();
    let mut first_shift: Vec<f64> = first.iter().filter_map(|(_, _, b)| b.shift).collect();
    let never = resonances
        .iter()
        .filter(|(_, _, b)| b.holds.is_none())
        .count();
    let bands = s
        .machines
        .iter()
        .filter(|m| {
            m.design.exact.as_ref().is_some_and(|e| {
                let ups = e.map.boundaries.iter().filter(|b| b.stable_above).count();
                ups > m.shifts.iter().filter(|b| b.kind == "resonance").count()
            })
        })
        .count();
    let _ = writeln!(
        t,
        "## The seed's criterion beside the exact boundaries\n\n\
         The criterion puts a boundary at every damped characteristic speed b. At the first \
         resonance of the {} machines, the balancing position is stable for good (up to the \
         criterion zone's end) from b·(1 + shift), shift {} at the median, from {} to {}. At \
         {never} of the {} resonance boundaries it is not stable anywhere up to its zone's end \
         (the criterion says balancing where the loads cannot balance). {bands} machines have \
         more changes to stability than the criterion has resonances: a stable band just above \
         a resonance, then instability, then stability again (the seed's h = 0.1, ε = 0.05, \
         β = 2 machine: stable on 1.0016 < q < 1.0874, unstable to 1.4252).\n",
        first.len(),
        signed(Some(quantile(&mut first_shift, 0.5))),
        signed(first_shift.first().copied()),
        signed(first_shift.last().copied()),
        resonances.len()
    );
    let fit_line = |t: &mut String, what: &str, pts: &[(f64, f64, f64, f64)]| {
        if let Some((c, rms)) = power_fit(pts) {
            let _ = writeln!(
                t,
                "{what}: least squares on logs gives {:.3}·ε^{:.2}·h^{:.2}·β^{:.2} (RMS scatter \
                 ×{:.2}, {} points).\n",
                c[0],
                c[1],
                c[2],
                c[3],
                rms.exp(),
                pts.len()
            );
        }
    };
    let pts: Vec<_> = first
        .iter()
        .filter_map(|(p, _, b)| Some((p.epsilon, p.h, p.beta, b.shift?)))
        .collect();
    fit_line(&mut t, "Shift of the first resonance boundary", &pts);
    let mut add: Vec<f64> = additional.iter().filter_map(|(_, _, b)| b.shift).collect();
    let mut add_abs: Vec<f64> = add.iter().map(|x| x.abs()).collect();
    let _ = writeln!(
        t,
        "At the {} additional speeds (balancing below, gathering above) the balancing position \
         stays stable up to b·(1 + shift): shift {} at the median, from {} to {}; |shift| {} at \
         the 90th percentile.\n",
        additional.len(),
        signed(Some(quantile(&mut add, 0.5))),
        signed(add.first().copied()),
        signed(add.last().copied()),
        signed(Some(quantile(&mut add_abs, 0.9)))
    );
    let _ = writeln!(
        t,
        "Median shift of the first resonance boundary by third of each group's range:\n\n\
         | group | third | range | median shift (machines) |\n|---|---|---|---:|"
    );
    type Get = fn(&Sample) -> f64;
    let groups: [(&str, Get, [f64; 2]); 3] = [
        ("ε", |p| p.epsilon, r.epsilon),
        ("h", |p| p.h, r.h),
        ("β", |p| p.beta, r.beta),
    ];
    for (name, get, range) in groups {
        for third in 0..3 {
            let edge = |k: f64| (range[0].ln() + k / 3.0 * (range[1].ln() - range[0].ln())).exp();
            let (a, b) = (edge(third as f64), edge(third as f64 + 1.0));
            let mut sh: Vec<f64> = first
                .iter()
                .filter(|(p, _, _)| get(p) >= a && get(p) < b)
                .filter_map(|(_, _, x)| x.shift)
                .collect();
            let _ = writeln!(
                t,
                "| {name} | {} | [{a:.3}, {b:.3}) | {} ({}) |",
                third + 1,
                signed(Some(quantile(&mut sh, 0.5))),
                sh.len()
            );
        }
    }
    let _ = writeln!(
        t,
        "\n![first resonance](criterion-resonance.svg)\n\n![additional speeds](criterion-additional.svg)\n\n\
         ## Every criterion boundary\n\n`nearest exact`: the exact boundary of the same kind \
         nearest to b; `stable from / to`: for a resonance, the speed from which the balancing \
         position stays stable to the zone's end, for an additional speed the speed up to which \
         it is stable from the zone's start (— : not stable there); `shift`: that speed over b, \
         minus 1.\n\n{}",
        boundary_table(s)
    );
    let md = dir.join("criterion.md");
    std::fs::write(&md, t).map_err(|e| format!("{}: {e}", md.display()))?;
    let svg1 = dir.join("criterion-resonance.svg");
    let edges_h = |k: f64| (r.h[0].ln() + k / 3.0 * (r.h[1].ln() - r.h[0].ln())).exp();
    let series = (0..3)
        .map(|k| {
            let (a, b) = (edges_h(k as f64), edges_h(k as f64 + 1.0));
            Series {
                label: format!("h in [{a:.3}, {b:.3})"),
                points: first
                    .iter()
                    .filter(|(p, _, _)| p.h >= a && p.h < b)
                    .filter_map(|(p, _, x)| Some((p.beta.log10(), 100.0 * x.shift?)))
                    .collect(),
                markers: true,
            }
        })
        .collect();
    write_svg(
        &svg1,
        &Chart {
            title:
                "First resonance: where the balancing position becomes stable for good (Floquet)",
            x_label: "log10 β",
            y_label: "exact boundary over the criterion's, −1, %",
            series,
            marks: vec![Mark::HLine("criterion".into(), 0.0)],
        },
    )?;
    let svg2 = dir.join("criterion-additional.svg");
    write_svg(
        &svg2,
        &Chart {
            title: "Additional speeds: where the balancing position stops being stable (Floquet)",
            x_label: "ε",
            y_label: "exact boundary over the criterion's, −1, %",
            series: vec![Series {
                label: "additional-speed boundaries".into(),
                points: additional
                    .iter()
                    .filter_map(|(p, _, x)| Some((p.epsilon, 100.0 * x.shift?)))
                    .collect(),
                markers: true,
            }],
            marks: vec![Mark::HLine("criterion".into(), 0.0)],
        },
    )?;
    Ok(vec![md, svg1, svg2])
}

/// The grid points bistable for capture outside the default margin band.
fn capture_points(s: &Study) -> impl Iterator<Item = &Point> {
    s.machines
        .iter()
        .flat_map(|m| &m.points)
        .filter(|p| p.reason == Some("capture") && p.distance > BAND)
}

/// The loads started together at rest at the bistable speeds: is the gathered state there?
/// The bistable speeds reached with the loads balanced, and the run-time tracker there.
fn history_section(t: &mut String, s: &Study) {
    let main = tally(s, BAND);
    let arrived: Vec<&Arrival> = s
        .machines
        .iter()
        .flat_map(|m| &m.points)
        .filter(|p| p.distance > BAND)
        .filter_map(|p| p.arrived.as_ref())
        .collect();
    let committed = || arrived.iter().filter(|a| a.by_history);
    let gathered = committed()
        .filter(|a| a.outcome.settled && !a.outcome.balancing)
        .count();
    let unsettled = committed().filter(|a| !a.outcome.settled).count();
    let declined = arrived.iter().filter(|a| !a.by_history).count();
    let _ = write!(
        t,
        "\n### Bistable speeds reached with the loads balanced: the run-time tracker\n\n\
         The table leaves a bistable speed to the machine's history, and the core's \
         `RegimeTracker` knows one history that decides it: loads that balanced in a \
         `Balancing` segment stay at the balancing position while the speed moves through \
         segments where that position stays stable, so there it reports `Balancing` \
         (`RegimeStatus::by_history`). At {} of the {} bistable speeds (outside the band) a \
         `Balancing` segment is reachable that way; the rotor was ramped from inside it (the \
         nearest such segment, its geometric middle, or 1.1 times the start of the last) to the \
         speed over the machine's base run time and held as long (doubled until settled), the \
         loads started near the balancing position, and the tracker was fed the same ramp. It committed to balancing \
         at {}, and \
         the loads **stayed balanced at {} of {}** ({}); {} gathered, {} unsettled.\n\n\
         With that history the classifier commits at **{} of {} speeds ({})** and the \
         simulation agrees at **{} of {} ({})**. Reached from rest instead (a run-up through \
         the resonance) a capture band stays bistable: a run-up captures the loads at most of \
         its speeds but not at all (below), and on lightly damped machines with wide bands \
         captured and released speeds alternate along the band, so no rule of the speed \
         history alone would commit there.\n\n",
        arrived.len(),
        main.capture + main.coexisting,
        if declined == 0 {
            "every one of them".to_string()
        } else {
            format!("{} of them (not at {declined})", main.history_committed)
        },
        main.history_agreeing,
        main.history_committed,
        pct(main.history_agreeing as f64 / main.history_committed.max(1) as f64),
        gathered,
        unsettled,
        main.committed + main.history_committed,
        main.speeds,
        pct(main.history_commit_rate()),
        main.agreeing + main.history_agreeing,
        main.committed + main.history_committed,
        pct(main.history_agreement()),
    );
    let misses: Vec<(usize, f64, &Arrival)> = s
        .machines
        .iter()
        .flat_map(|m| m.points.iter().map(move |p| (m.sample.id, p)))
        .filter(|(_, p)| p.distance > BAND)
        .filter_map(|(id, p)| p.arrived.as_ref().map(|a| (id, p.speed, a)))
        .filter(|(_, _, a)| a.by_history && !(a.outcome.settled && a.outcome.balancing))
        .collect();
    if !misses.is_empty() {
        t.push_str(
            "Where the loads brought there balanced did not stay so:\n\n\
             | machine | speed, rad/s | ramped from, rad/s | residual max | slip 1 − Ω/ω | settled |\n\
             |---:|---:|---:|---:|---:|---|\n",
        );
        for (id, w, a) in misses {
            let _ = writeln!(
                t,
                "| {id} | {w:.2} | {:.2} | {:.3} | {:.1} % | {} |",
                a.from,
                a.outcome.residual_relative,
                100.0 * a.outcome.slip,
                if a.outcome.settled { "yes" } else { "no" }
            );
        }
        t.push('\n');
    }
}

fn together_section(t: &mut String, s: &Study) {
    let main = tally(s, BAND);
    let c = main.capture_together;
    let mut slips: Vec<f64> = capture_points(s)
        .filter_map(|p| p.together)
        .filter(|o| o.settled && !o.balancing)
        .map(|o| o.slip)
        .collect();
    let _ = write!(
        t,
        "### Loads started together at rest in the capture bands\n\n\
         At the {} speeds bistable for capture (outside the ±{:.0} % band) the loads were also \
         started together at rest (gathered, the state a run-up can leave them in), with the \
         same run lengths and judgement. They **stayed gathered at {} of {}** (residual at least 10 % of \
         the rotor's throughout the final quarter): there the captured state is seen beside the \
         balancing one the start near the balancing position reached, so both attractors exist \
         and the speed is bistable indeed; the gathered loads turned slower than the rotor at \
         the end of the run by {} to {} ({} at the median), captured below it. They **balanced at {}** ({}): from that start the \
         captured state was not reached, which does not prove it absent there. Unsettled: {}.",
        c.speeds,
        100.0 * BAND,
        c.gathered,
        c.started,
        pct(slips.iter().copied().fold(f64::INFINITY, f64::min)),
        pct(slips.iter().copied().fold(f64::NEG_INFINITY, f64::max)),
        pct(quantile(&mut slips, 0.5)),
        c.balanced,
        pct(c.balanced as f64 / c.started.max(1) as f64),
        c.unsettled
    );
    let u = main.capture_runup;
    let _ = write!(
        t,
        "\n\nRun up instead (the loads together at rest with the rotor at the machine's lowest grid \
         speed, ramped to the speed over the machine's base run time and held there as long, \
         the hold doubled up to three times until the residual settles, judged over the final \
         quarter): of the {} capture-bistable speeds the loads \
         **stayed captured at {}** (gathered at the end of the hold) and were **released at {}** \
         (balanced), {} unsettled.",
        u.started, u.gathered, u.balanced, u.unsettled
    );
    let released: Vec<f64> = capture_points(s)
        .filter(|p| p.runup.is_some_and(|o| o.settled && o.balancing))
        .map(|p| p.distance)
        .collect();
    // Both attractors seen: captured by the run-up, balanced from near the balancing position.
    let both = capture_points(s)
        .filter(|p| p.runup.is_some_and(|o| o.settled && !o.balancing))
        .filter(|p| p.simulated.settled && p.simulated.balancing)
        .count();
    if u.started > 0 {
        let near = released.iter().filter(|&&d| d <= 0.05).count();
        let _ = write!(
            t,
            " So a run-up kept gathered loads captured at {} of the {} speeds the table calls \
             bistable for capture; at {} of them loads started near the balancing position \
             balanced too (both attractors seen). Of the {} releases, {} lie within 5 % of a \
             boundary of the table (a band's end).",
            pct(u.gathered as f64 / u.started as f64),
            u.started,
            both,
            released.len(),
            near
        );
    }
    let [gathered, split, balanced, other] = capture_bands(s);
    let _ = write!(
        t,
        "\n\nThe capture-bistable speeds of a machine form {} bands (runs of neighbouring grid \
         speeds; unsettled runs left out): at {gathered} the loads started together stayed \
         gathered throughout, at {split} they stayed gathered at the lower speeds and balanced \
         at the upper ones, at {balanced} they balanced throughout, and at {other} the two \
         alternate.",
        gathered + split + balanced + other
    );
    if split > 4 * other {
        t.push_str(" Where captured loads are seen, they are seen in the lower part of a band.");
    }
    let _ = writeln!(
        t,
        "\n\nWhat if every capture-bistable speed where a run-up released the loads were \
         committed as balancing (not the classifier's figure: its table says bistable there): \
         it would commit at {} of {} speeds (**{}**, against its {}). Committing the capture \
         bands from the speed alone is what a higher commit rate without the loads' history \
         would take, and the run-ups show loads captured there.\n",
        main.committed + u.balanced + main.coexisting_together.balanced,
        main.speeds,
        pct(main.what_if_commit_rate()),
        pct(main.commit_rate())
    );
    let x = main.coexisting_together;
    if x.speeds > 0 {
        let _ = writeln!(
            t,
            "At the {} speeds bistable for coexisting gathered loads, loads started together at \
             rest stayed gathered at {} of {}, balanced at {}, {} unsettled.\n",
            x.speeds, x.gathered, x.started, x.balanced, x.unsettled
        );
    }
    t.push_str(
        "By third of β's range:\n\n\
         | β | capture-bistable speeds | stayed gathered | balanced | unsettled |\n\
         |---|---:|---:|---:|---:|\n",
    );
    let r = &s.range;
    for third in 0..3 {
        let edge = |k: f64| (r.beta[0].ln() + k / 3.0 * (r.beta[1].ln() - r.beta[0].ln())).exp();
        let (a, b) = (edge(third as f64), edge(third as f64 + 1.0));
        let x = tally_where(s, BAND, |m, _| m.sample.beta >= a && m.sample.beta < b);
        let y = x.capture_together;
        let _ = writeln!(
            t,
            "| [{a:.2}, {b:.2}) | {} | {} | {} | {} |",
            y.speeds, y.gathered, y.balanced, y.unsettled
        );
    }
    t.push('\n');
}

/// The bands of neighbouring grid speeds classed bistable for capture, by what loads started
/// together at rest did across each (settled runs outside the default margin band only):
/// `[stayed gathered throughout, gathered below and balanced above, balanced throughout,
/// alternating]`.
pub fn capture_bands(s: &Study) -> [usize; 4] {
    capture_bands_of(s.machines.iter().map(|m| m.points.as_slice()))
}

/// [`capture_bands`] over the grid points of each machine.
pub fn capture_bands_of<'a>(machines: impl Iterator<Item = &'a [Point]>) -> [usize; 4] {
    let mut n = [0; 4];
    let mut close = |band: &mut Vec<bool>| {
        let split = band.iter().position(|&b| b).unwrap_or(band.len());
        if !band.is_empty() {
            let rest = band[split..].iter().all(|&b| b);
            n[match (split, rest) {
                (_, false) => 3,
                (0, true) => 2,
                (k, true) if k == band.len() => 0,
                _ => 1,
            }] += 1;
        }
        band.clear();
    };
    for points in machines {
        // Balanced (true) or gathered (false), ascending speed.
        let mut band = Vec::new();
        for p in points {
            if p.reason != Some("capture") {
                close(&mut band);
                continue;
            }
            if let Some(o) = p.together.filter(|o| o.settled && p.distance > BAND) {
                band.push(o.balancing);
            }
        }
        close(&mut band);
    }
    n
}

/// `ln y = c0 + a·ln ε + b·ln h + c·ln β` by least squares: `[C, a, b, c]` with `C = e^c0`
/// and the RMS of the residuals in `ln y`; `None` with fewer than 5 points.
pub fn power_fit(points: &[(f64, f64, f64, f64)]) -> Option<([f64; 4], f64)> {
    let rows: Vec<[f64; 5]> = points
        .iter()
        .filter(|p| p.0 > 0.0 && p.1 > 0.0 && p.2 > 0.0 && p.3 > 0.0)
        .map(|p| [1.0, p.0.ln(), p.1.ln(), p.2.ln(), p.3.ln()])
        .collect();
    if rows.len() < 5 {
        return None;
    }
    // Normal equations (4×4, well conditioned for log-uniform draws), solved with partial
    // pivoting.
    let mut a = [[0.0f64; 5]; 4];
    for r in &rows {
        for i in 0..4 {
            for j in 0..5 {
                a[i][j] += r[i] * r[j];
            }
        }
    }
    for c in 0..4 {
        let p = (c..4).max_by(|&i, &j| a[i][c].abs().total_cmp(&a[j][c].abs()))?;
        a.swap(c, p);
        if a[c][c].abs() < 1e-300 {
            return None;
        }
        let pivot = a[c];
        for row in a.iter_mut().skip(c + 1) {
            let f = row[c] / pivot[c];
            for (x, p) in row.iter_mut().zip(pivot).skip(c) {
                *x -= f * p;
            }
        }
    }
    let mut x = [0.0f64; 4];
    for r in (0..4).rev() {
        let s: f64 = (r + 1..4).map(|k| a[r][k] * x[k]).sum();
        x[r] = (a[r][4] - s) / a[r][r];
    }
    let rms = (rows
        .iter()
        .map(|r| {
            let e = x[0] + x[1] * r[1] + x[2] * r[2] + x[3] * r[3] - r[4];
            e * e
        })
        .sum::<f64>()
        / rows.len() as f64)
        .sqrt();
    Some(([x[0].exp(), x[1], x[2], x[3]], rms))
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn drawn_machines_have_the_drawn_groups() {
        // The scene text must reproduce ε, h, β and D/(N·m·R) through the core's own
        // dimensionless groups (an independent path: the core parses the physical values).
        for id in 0..9 {
            let s = draw(7, id, 1 + id % 3, &RANGE);
            let file = PathBuf::from("t.toml");
            let scene = Scene::parse(&s.scene, &file).unwrap();
            let m = predict::machine(&scene, &file).unwrap().unwrap();
            let d = m.config().dimensionless();
            assert!((d.omega_ref / OMEGA_REF - 1.0).abs() < 1e-12, "{d:?}");
            assert!((d.epsilon / s.epsilon - 1.0).abs() < 1e-12, "{d:?} {s:?}");
            assert!((d.beta / s.beta - 1.0).abs() < 1e-12, "{d:?} {s:?}");
            let e = m.config().exciter_index();
            assert!((d.h[e] / s.h - 1.0).abs() < 1e-12, "{d:?} {s:?}");
            assert_eq!(m.config().platforms().len(), s.platforms);
            for x in [s.epsilon, s.h, s.beta] {
                assert!(x > 0.0);
            }
            assert!((RANGE.epsilon[0]..=RANGE.epsilon[1]).contains(&s.epsilon));
            assert!((RANGE.h[0]..=RANGE.h[1]).contains(&s.h));
            assert!((RANGE.beta[0]..=RANGE.beta[1]).contains(&s.beta));
            assert!((RANGE.unbalance[0]..=RANGE.unbalance[1]).contains(&s.unbalance));
        }
        // Deterministic in the seed.
        assert_eq!(draw(7, 3, 1, &RANGE).scene, draw(7, 3, 1, &RANGE).scene);
        assert_ne!(draw(7, 3, 1, &RANGE).scene, draw(8, 3, 1, &RANGE).scene);
    }

    fn point(class: &'static str, reason: Option<&'static str>, distance: f64) -> Point {
        let o = Outcome {
            speed: 60.0,
            together: false,
            balancing: class != "gathering",
            settled: true,
            residual_relative: 0.0,
            residual_min_relative: 0.0,
            duration_tau: 1000.0,
            slip: 0.0,
        };
        Point {
            speed: 60.0,
            class,
            reason,
            stable: class != "gathering",
            growth_rate: -1e-3,
            distance,
            criterion: "balancing",
            criterion_distance: 1.0,
            simulated: o,
            together: None,
            runup: None,
            arrived: None,
        }
    }

    /// A run of `p`'s with the loads together, judged as given.
    fn together_run(p: &Point, balancing: bool, settled: bool) -> Option<Outcome> {
        Some(Outcome {
            together: true,
            balancing,
            settled,
            ..p.simulated
        })
    }

    fn started(mut p: Point, balancing: bool, settled: bool) -> Point {
        p.together = together_run(&p, balancing, settled);
        p
    }

    fn run_up(mut p: Point, balancing: bool, settled: bool) -> Point {
        p.runup = together_run(&p, balancing, settled);
        p
    }

    #[test]
    fn speeds_reached_balanced_are_tallied_with_the_tracker() {
        let cap = Some("capture");
        let arrive = |mut p: Point, by_history: bool, balancing: bool, settled: bool| {
            p.arrived = Some(Arrival {
                from: 80.0,
                class: if by_history { "balancing" } else { "bistable" },
                by_history,
                outcome: Outcome {
                    balancing,
                    settled,
                    ..p.simulated
                },
            });
            p
        };
        let points = [
            point("balancing", None, 0.5),
            point("gathering", None, 0.5),
            // Committed from history: stayed balanced, gathered, unsettled.
            arrive(point("bistable", cap, 0.5), true, true, true),
            arrive(point("bistable", cap, 0.5), true, false, true),
            arrive(point("bistable", cap, 0.5), true, true, false),
            // Reached, but the tracker did not commit; not reachable.
            arrive(point("bistable", cap, 0.5), false, true, true),
            point("bistable", cap, 0.5),
        ];
        let t = tally_points(BAND, points.iter());
        assert_eq!((t.speeds, t.committed, t.agreeing), (7, 2, 2));
        assert_eq!(
            (t.reachable, t.history_committed, t.history_agreeing),
            (4, 3, 1)
        );
        assert!((t.history_commit_rate() - 5.0 / 7.0).abs() < 1e-15);
        assert!((t.history_agreement() - 3.0 / 5.0).abs() < 1e-15);
    }

    #[test]
    fn together_runs_at_bistable_speeds_are_tallied_apart() {
        let cap = Some("capture");
        let points = vec![
            // Committed balancing, together-start gathered: the existing counts.
            started(point("balancing", None, 0.5), false, true),
            started(point("balancing", None, 0.5), true, true),
            point("gathering", None, 0.5),
            // Capture: gathered, gathered, balanced, unsettled (judged either way); in the
            // band, not run.
            // Run up: captured, captured, released, unsettled; one not run.
            run_up(
                started(point("bistable", cap, 0.5), false, true),
                false,
                true,
            ),
            run_up(
                started(point("bistable", cap, 0.5), false, true),
                false,
                true,
            ),
            run_up(started(point("bistable", cap, 0.5), true, true), true, true),
            run_up(
                started(point("bistable", cap, 0.5), true, false),
                true,
                false,
            ),
            started(point("bistable", cap, 0.5), false, false),
            point("bistable", cap, 0.005),
            started(point("bistable", Some("coexisting"), 0.5), true, true),
            // Within the band: counted as a speed only.
            started(point("bistable", cap, 0.001), true, true),
        ];
        let t = tally_points(BAND, points.iter());
        assert_eq!(t.speeds, 11);
        assert_eq!((t.committed, t.balancing, t.agreeing), (3, 2, 3));
        // The balancing counts see only the committed-balancing speeds.
        assert_eq!((t.together, t.together_balancing), (2, 1));
        assert_eq!((t.capture, t.coexisting), (5, 1));
        let c = t.capture_together;
        assert_eq!(
            (c.speeds, c.started, c.gathered, c.balanced, c.unsettled),
            (5, 5, 2, 1, 2)
        );
        let u = t.capture_runup;
        assert_eq!(
            (u.speeds, u.started, u.gathered, u.balanced, u.unsettled),
            (5, 4, 2, 1, 1)
        );
        let x = t.coexisting_together;
        assert_eq!((x.speeds, x.started, x.balanced), (1, 1, 1));
        // What if the released capture speeds and the balanced coexisting one were committed:
        // 3 + 1 + 1 of 11.
        assert!((t.what_if_commit_rate() - 5.0 / 11.0).abs() < 1e-15);
        assert!((t.commit_rate() - 3.0 / 11.0).abs() < 1e-15);
        // Without a margin the speeds in the band count too, started or not.
        let all = tally_points(0.0, points.iter());
        let c = all.capture_together;
        assert_eq!((all.capture, c.speeds, c.started, c.balanced), (7, 7, 6, 2));
    }

    #[test]
    fn capture_bands_are_classed_by_what_the_together_start_did() {
        let cap = |balancing: bool, settled: bool| {
            started(point("bistable", Some("capture"), 0.5), balancing, settled)
        };
        let gap = || point("balancing", None, 0.5);
        let machine_a = vec![
            gap(),
            // Gathered below, balanced above; the unsettled run is left out.
            cap(false, true),
            cap(false, false),
            cap(true, true),
            cap(true, true),
            gap(),
            // Gathered throughout; a speed in the margin band does not end the band.
            cap(false, true),
            started(point("bistable", Some("capture"), 0.001), true, true),
            cap(false, true),
        ];
        let machine_b = vec![
            // Balanced throughout, then alternating, then only unsettled (no band).
            cap(true, true),
            gap(),
            cap(false, true),
            cap(true, true),
            cap(false, true),
            gap(),
            cap(true, false),
        ];
        let n = capture_bands_of([machine_a.as_slice(), machine_b.as_slice()].into_iter());
        assert_eq!(n, [1, 1, 1, 1]);
        // A band ends at the machine's last point, not across machines.
        let last = [cap(false, true)];
        let first = [cap(true, true)];
        assert_eq!(
            capture_bands_of([last.as_slice(), first.as_slice()].into_iter()),
            [1, 0, 1, 0]
        );
    }

    #[test]
    fn power_fit_recovers_an_exact_law() {
        // y = 0.3·ε^0.5·h^-1·β^0.25 on a spread of points: recovered to rounding.
        let mut pts = Vec::new();
        for i in 0..4 {
            for j in 0..3 {
                for k in 0..3 {
                    let (e, h, b) = (
                        0.005 * 2f64.powi(i),
                        0.01 * 3f64.powi(j),
                        1.0 + 7.0 * k as f64,
                    );
                    pts.push((e, h, b, 0.3 * e.sqrt() / h * b.powf(0.25)));
                }
            }
        }
        let (c, rms) = power_fit(&pts).unwrap();
        for (got, want) in c.iter().zip([0.3, 0.5, -1.0, 0.25]) {
            assert!((got - want).abs() < 1e-9, "{c:?}");
        }
        assert!(rms < 1e-9);
        // Too few points, or a degenerate spread: no fit.
        assert!(power_fit(&pts[..4]).is_none());
        assert!(power_fit(&[(0.01, 0.1, 2.0, 0.1); 8]).is_none());
    }
}
