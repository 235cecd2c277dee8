//! `drive-sim criterion`: the auto-balancing criterion (seed 001) against direct simulation on
//! randomised machines.
//!
//! Seed 001's criterion (`Re H(ω) < 0`: balancing, the core's
//! [`Machine::zones`](drive_monitor::balancer::Machine::zones)) is
//! approximate; its authors ask for the limits to be checked by computational experiment. This
//! module draws machines at random in a documented range of the seed's dimensionless groups
//! ([`RANGE`]), simulates each at a grid of prescribed rotor speeds, and reports
//!
//! - the agreement between the criterion's zone and the simulated outcome away from the
//!   characteristic speeds, and how many of the disagreements the core's capture check
//!   already reports as [`Regime::Bistable`](drive_monitor::balancer::Regime);
//! - for every zone boundary `b` (a damped characteristic speed) the simulated boundary: the
//!   speed `s_low` up to which the lower zone's regime holds and the speed `s_high` from which
//!   the upper zone's regime holds, each found by bisection between grid speeds, and their
//!   shifts `s/b − 1`;
//! - the margin each boundary needs: the relative half-width of the band about `b` outside
//!   which the core's class (with its capture check) matches the simulation.
//!
//! # Outcome at one speed
//!
//! The loads start at the balancing position, turning with the rotor, one of them displaced
//! by 0.05 rad ([`crate::app::run::vibration_params`]). The run lasts `T = clamp(30/r, 1000, 10000)`
//! in the seed's time `τ = ω̃·t`, where `r = min(ε·β, 1/β)` is the slower of the loads' own
//! relaxation rate (`ε·β`, seed eq. 4) and the overdamped drift of the balancing position
//! (`1/β`). The outcome is *balancing* when the residual unbalance over the last quarter stays
//! below 1 % of the rotor's, *gathering* when it has grown to three times its initial value;
//! otherwise the run is repeated twice as long, up to four times `T`, and a run still
//! unsettled then is judged by its trend (final residual below the initial one: balancing)
//! and counted as *unsettled*.

use crate::app::predict;
use crate::app::run::{run, Overrides};
use crate::app::scene::{Scene, SceneError};
use crate::engine::vibration::Regime as Simulated;
use drive_monitor::balancer::{Classifier, Regime, ZoneKind, DEFAULT_MARGIN};
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

/// The documented range: `ε` from small to moderate, light to moderate damping, viscous
/// loads from weakly to strongly damped.
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
/// Bisection steps per simulated boundary.
const BISECTIONS: usize = 7;
/// The margin band the agreement is counted outside of (the classifier's default).
const BAND: f64 = DEFAULT_MARGIN as f64;

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
    /// The residual unbalance decayed (or, unsettled, ended below its initial value).
    pub balancing: bool,
    /// The run settled within four times the base duration.
    pub settled: bool,
    /// Final residual over the rotor unbalance.
    pub residual_relative: f64,
}

/// Simulates `scene` at `speed`, doubling the duration until the residual has settled.
pub fn outcome(scene: &Scene, file: &Path, speed: f64) -> Result<Outcome, SceneError> {
    let mut s = scene.clone();
    s.encoder = None;
    let base = s.simulation.duration;
    let mut k = 0;
    loop {
        s.simulation.duration = base * f64::from(1u32 << k);
        let r = run(
            &s,
            file,
            Overrides {
                speed: Some(speed),
                loads_together: false,
            },
        )?;
        let Some(d) = r.regime_detail else {
            return Err(SceneError::value(
                file,
                "autobalancer",
                "the run produced no regime samples",
            ));
        };
        // Balancing: the run's own classification (residual below 1 % of the reference).
        let balanced = d.regime == Simulated::Balancing;
        let grown = d.residual_relative >= 3.0 * d.residual_initial_relative;
        k += 1;
        if balanced || grown || k == 3 {
            return Ok(Outcome {
                speed,
                balancing: balanced
                    || (!grown && d.residual_relative < d.residual_initial_relative),
                settled: balanced || grown,
                residual_relative: d.residual_relative,
            });
        }
    }
}

/// A zone boundary and where the simulation puts it.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Boundary {
    /// Damped characteristic speed `b` (the criterion's boundary), rad/s.
    pub predicted: f64,
    /// `b/ω̃`.
    pub q: f64,
    /// "resonance" (gathering below, balancing above) or "additional" (balancing below,
    /// gathering above).
    pub kind: &'static str,
    /// Highest speed up to which the lower zone's regime holds (from the previous boundary's
    /// midpoint), rad/s.
    pub simulated_low: f64,
    /// Lowest speed from which the upper zone's regime holds (to the next boundary's
    /// midpoint), rad/s.
    pub simulated_high: f64,
    /// `simulated_low/b − 1`.
    pub shift_low: f64,
    /// `simulated_high/b − 1`.
    pub shift_high: f64,
    /// The upper zone's regime was not found holding up to the end of the boundary's range
    /// (the geometric midpoint to the next boundary, or the grid's top); `simulated_high` is
    /// that end, so the shift is at least `shift_high`.
    pub beyond_grid: bool,
    /// Upper end of the capture window above `b` (core), rad/s, if any.
    pub capture_until: Option<f64>,
    /// Relative half-width of the band about `b` the core's class needs to match the
    /// simulation on both sides (capture window counted as covering the upper side).
    pub margin_needed: f64,
}

/// One machine's results.
#[derive(Debug, Clone, Serialize)]
pub struct MachineResult {
    /// The machine.
    pub sample: Sample,
    /// Grid outcomes, ascending speed.
    pub points: Vec<Outcome>,
    /// Boundaries, ascending.
    pub boundaries: Vec<Boundary>,
    /// Grid speeds outside the margin band ([`DEFAULT_MARGIN`]) about every boundary.
    pub away: usize,
    /// Of those, speeds where the criterion's zone matches the simulation.
    pub agreeing: usize,
    /// Of the disagreeing ones, speeds the core classifies as bistable (capture possible).
    pub disagreeing_bistable: usize,
    /// Runs judged by their trend (unsettled after four times the base duration).
    pub unsettled: usize,
}

fn grid(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|i| lo * (hi / lo).powf(i as f64 / (n - 1) as f64))
        .collect()
}

/// Bisects between `a` (regime `!want`) and `b` (regime `want`) for the switch, `BISECTIONS`
/// times.
fn refine(
    scene: &Scene,
    file: &Path,
    mut a: f64,
    mut b: f64,
    want: bool,
) -> Result<f64, SceneError> {
    for _ in 0..BISECTIONS {
        let mid = (a * b).sqrt();
        if outcome(scene, file, mid)?.balancing == want {
            b = mid;
        } else {
            a = mid;
        }
    }
    Ok((a * b).sqrt())
}

/// Studies one machine.
pub fn study_machine(sample: Sample) -> Result<MachineResult, SceneError> {
    let file = PathBuf::from(format!("random-machine-{}.toml", sample.id));
    let scene = Scene::parse(&sample.scene, &file)?;
    let Some(machine) = predict::machine(&scene, &file)? else {
        return Err(SceneError::value(&file, "autobalancer", "missing"));
    };
    let classifier = Classifier::new(&machine, BAND as f32, 0.5 * BAND as f32)
        .map_err(|e| predict::value_error(&file, "monitor", e))?;
    // Without a margin band: the classes the core gives on either side of each boundary.
    let segments = Classifier::new(&machine, 0.0, 0.0)
        .map_err(|e| predict::value_error(&file, "monitor", e))?;
    let zones = machine.zones();
    let bounds: Vec<f64> = zones.iter().skip(1).map(|z| z.from).collect();
    // The grid reaches past every capture window: where capture ends is part of the check.
    let until = machine
        .capture_windows()
        .iter()
        .fold(0.0f64, |u, c| u.max(c.until));
    let (lo, hi) = match (bounds.first(), bounds.last()) {
        (Some(&a), Some(&b)) => (0.5 * a, (2.0 * b).max(1.25 * until).min(8.0 * b)),
        _ => (0.5 * OMEGA_REF, 2.0 * OMEGA_REF),
    };
    let speeds = grid(lo, hi, GRID);
    let points = speeds
        .iter()
        .map(|&w| outcome(&scene, &file, w))
        .collect::<Result<Vec<_>, _>>()?;
    let predicted_balancing = |w: f64| machine.zone_kind_at(w) == ZoneKind::Balancing;
    let mut away = 0;
    let mut agreeing = 0;
    let mut bistable = 0;
    for p in &points {
        if bounds.iter().all(|&b| (p.speed - b).abs() > BAND * b) {
            away += 1;
            if predicted_balancing(p.speed) == p.balancing {
                agreeing += 1;
            } else if classifier.classify(p.speed as f32) == Regime::Bistable {
                bistable += 1;
            }
        }
    }
    let mut boundaries = Vec::new();
    for (k, &b) in bounds.iter().enumerate() {
        let upper_balancing = predicted_balancing(b * (1.0 + 1e-9));
        let from = if k == 0 {
            0.0
        } else {
            (bounds[k - 1] * b).sqrt()
        };
        let to = bounds.get(k + 1).map_or(f64::INFINITY, |&n| (n * b).sqrt());
        let idx: Vec<usize> = (0..points.len())
            .filter(|&i| points[i].speed > from && points[i].speed < to)
            .collect();
        // Highest grid point not in the upper regime, and lowest not in the lower one.
        let last_not_upper = idx
            .iter()
            .rev()
            .find(|&&i| points[i].balancing != upper_balancing)
            .copied();
        let first_not_lower = idx
            .iter()
            .find(|&&i| points[i].balancing == upper_balancing)
            .copied();
        let high = match last_not_upper {
            Some(i) if i + 1 < points.len() && idx.contains(&(i + 1)) => refine(
                &scene,
                &file,
                points[i].speed,
                points[i + 1].speed,
                upper_balancing,
            )?,
            Some(_) => to.min(hi),
            None => from.max(lo),
        };
        let beyond_grid =
            matches!(last_not_upper, Some(i) if i + 1 >= points.len() || !idx.contains(&(i + 1)));
        let low = match first_not_lower {
            Some(i) if i > 0 && idx.contains(&(i - 1)) => refine(
                &scene,
                &file,
                points[i - 1].speed,
                points[i].speed,
                upper_balancing,
            )?,
            Some(_) => from.max(lo),
            None => to.min(hi),
        };
        let capture_until = if upper_balancing {
            machine
                .capture_windows()
                .iter()
                .find(|c| (c.from - b).abs() <= 1e-9 * b)
                .map(|c| c.until)
        } else {
            None
        };
        // A disagreement on [x0, x1) is covered where the core says bistable all along it.
        let covered = |x0: f64, x1: f64| {
            [x0 * (1.0 + 1e-6), x1 * (1.0 - 1e-6)]
                .iter()
                .all(|&x| segments.classify(x as f32) == Regime::Bistable)
        };
        let need_low = if low < b && !covered(low, b) {
            1.0 - low / b
        } else {
            0.0
        };
        let need_high = if high > b && !covered(b, high) {
            high / b - 1.0
        } else {
            0.0
        };
        let margin_needed = need_low.max(need_high);
        boundaries.push(Boundary {
            predicted: b,
            q: b / OMEGA_REF,
            kind: if upper_balancing {
                "resonance"
            } else {
                "additional"
            },
            simulated_low: low,
            simulated_high: high,
            shift_low: low / b - 1.0,
            shift_high: high / b - 1.0,
            beyond_grid,
            capture_until,
            margin_needed,
        });
    }
    let unsettled = points.iter().filter(|p| !p.settled).count();
    Ok(MachineResult {
        sample,
        points,
        boundaries,
        away,
        agreeing,
        disagreeing_bistable: bistable,
        unsettled,
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

/// Per-boundary table (Markdown), one row per boundary of every machine.
pub fn boundary_table(s: &Study) -> String {
    let mut t = String::from(
        "| machine | P | ε | h | β | kind | b, rad/s | q = b/ω̃ | low shift | high shift | capture until / b | margin needed |\n\
         |---:|---:|---:|---:|---:|---|---:|---:|---:|---:|---:|---:|\n",
    );
    for m in &s.machines {
        let p = &m.sample;
        for b in &m.boundaries {
            let _ = writeln!(
                t,
                "| {} | {} | {:.4} | {:.3} | {:.2} | {} | {:.2} | {:.3} | {:+.2} % | {}{:+.2} % | {} | {:.2} % |",
                p.id,
                p.platforms,
                p.epsilon,
                p.h,
                p.beta,
                b.kind,
                b.predicted,
                b.q,
                100.0 * b.shift_low,
                if b.beyond_grid { "> " } else { "" },
                100.0 * b.shift_high,
                b.capture_until
                    .map_or("–".to_string(), |u| format!("{:.3}", u / b.predicted)),
                100.0 * b.margin_needed
            );
        }
    }
    t
}

/// Agreement totals: (away, agreeing, disagreeing but bistable, unsettled, points).
pub fn totals(s: &Study) -> (usize, usize, usize, usize, usize) {
    s.machines.iter().fold((0, 0, 0, 0, 0), |a, m| {
        (
            a.0 + m.away,
            a.1 + m.agreeing,
            a.2 + m.disagreeing_bistable,
            a.3 + m.unsettled,
            a.4 + m.points.len(),
        )
    })
}

/// A plain-text summary.
pub fn summary_text(s: &Study) -> String {
    let (away, agree, bistable, unsettled, points) = totals(s);
    let mut t = boundary_table(s);
    let _ = writeln!(
        t,
        "\n{} machines, {points} speeds ({unsettled} judged by trend): away from the characteristic speeds {agree} of {away} agree; {bistable} of the {} disagreements are classified bistable by the core",
        s.machines.len(),
        away - agree
    );
    t
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

fn quantile(v: &mut [f64], q: f64) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    v[((v.len() - 1) as f64 * q).round() as usize]
}

/// The boundaries of every machine with their machine's groups.
fn all_boundaries(s: &Study) -> Vec<(&Sample, usize, &Boundary)> {
    s.machines
        .iter()
        .flat_map(|m| {
            m.boundaries
                .iter()
                .enumerate()
                .map(move |(k, b)| (&m.sample, k, b))
        })
        .collect()
}

/// Writes `criterion.md`, `criterion-resonance.svg` and `criterion-additional.svg` into `dir`.
pub fn publish(s: &Study, dir: &Path) -> Result<Vec<PathBuf>, String> {
    use crate::app::plot::{write_svg, Chart, Mark, Series};
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let bs = all_boundaries(s);
    let first: Vec<_> = bs
        .iter()
        .filter(|(_, k, b)| *k == 0 && b.kind == "resonance")
        .collect();
    let resonances: Vec<_> = bs
        .iter()
        .filter(|(_, _, b)| b.kind == "resonance")
        .collect();
    let additional: Vec<_> = bs
        .iter()
        .filter(|(_, _, b)| b.kind == "additional")
        .collect();
    let (away, agree, bistable, unsettled, points) = totals(s);
    let mut t = String::new();
    let _ = writeln!(
        t,
        "# The auto-balancing criterion against simulation on random machines\n\n\
         Regenerated by `cargo run --release -p host-sim -- criterion --machines {} --seed {} --out {}`.\n\n\
         Method: `host-sim/src/studies/criterion.rs` (module docs). Each machine is drawn in the range below, \
         simulated at {GRID} prescribed rotor speeds from half its first damped characteristic \
         speed to twice its last (and past its capture windows), starting the loads at the \
         balancing position turning with the rotor, one load displaced by 0.05 rad. Each \
         boundary's simulated position is then bisected ({BISECTIONS} steps) between grid speeds. \
         The study's bisection agrees with a Floquet analysis of seed eq. 4 to 0.05 % of speed \
         (`host-sim/tests/vibration.rs`, `criterion_study_boundaries_match_floquet`).\n",
        s.machines.len(),
        s.seed,
        dir.display()
    );
    let r = &s.range;
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
    let _ = writeln!(
        t,
        "## Agreement\n\n{} machines, {points} speeds ({unsettled} still unsettled after four times \
         the base run and judged by their trend). Away from the characteristic speeds (outside \
         ±{:.0} % of each): the criterion's zone and the simulation agree at **{agree} of {away}** \
         speeds ({:.1} %). Of the {} disagreements, {bistable} lie where the core's classifier \
         already says `Bistable` (inside a capture window above a resonance).\n",
        s.machines.len(),
        100.0 * BAND,
        100.0 * agree as f64 / away.max(1) as f64,
        away - agree
    );
    let uncovered: Vec<_> = resonances
        .iter()
        .filter(|(_, _, b)| b.margin_needed > BAND)
        .collect();
    let mut high: Vec<f64> = first.iter().map(|(_, _, b)| b.shift_high).collect();
    let _ = writeln!(
        t,
        "## Boundaries at the resonances (gathering below, balancing above)\n\n\
         On the first resonance of the {} machines, the speed from which balancing holds in \
         simulation lies {:+.1} % (median) from the criterion's boundary, from {:+.1} % to \
         {:+.1} %. (A positive shift means the balancing position is unstable just above the \
         resonance, as a Floquet analysis shows for the seed's h = 0.1, ε = 0.05, β = 2 \
         machine: unstable on 1.087 < q < 1.425.) The core's classifier says `Bistable` \
         (balancing not assured) on `[b, until)`, up to where capture ends: of {} resonance \
         boundaries, {} have every disagreement inside that band or within the ±{:.0} % margin. \
         The {} others:\n",
        first.len(),
        100.0 * quantile(&mut high, 0.5),
        100.0 * high.first().copied().unwrap_or(f64::NAN),
        100.0 * high.last().copied().unwrap_or(f64::NAN),
        resonances.len(),
        resonances.len() - uncovered.len(),
        100.0 * BAND,
        uncovered.len()
    );
    for (p, k, b) in &uncovered {
        let _ = writeln!(
            t,
            "- machine {} ({} platforms, ε = {:.4}, h = {:.3}, β = {:.2}), boundary {} at {:.2} rad/s: \
             balancing {} {:+.1} %, capture window to {}",
            p.id,
            p.platforms,
            p.epsilon,
            p.h,
            p.beta,
            k + 1,
            b.predicted,
            if b.beyond_grid { "not reached up to" } else { "from" },
            100.0 * b.shift_high,
            b.capture_until
                .map_or("none".into(), |u| format!("{:+.1} %", 100.0 * (u / b.predicted - 1.0)))
        );
    }
    let fit_line = |t: &mut String, what: &str, pts: &[(f64, f64, f64, f64)]| {
        if let Some((c, rms)) = power_fit(pts) {
            let _ = writeln!(
                t,
                "\n{what}: least squares on logs gives {:.3}·ε^{:.2}·h^{:.2}·β^{:.2} (RMS scatter \
                 ×{:.2}, {} points).",
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
        .map(|(p, _, b)| (p.epsilon, p.h, p.beta, b.shift_high))
        .collect();
    fit_line(&mut t, "Shift of the first resonance boundary", &pts);
    let mut need: Vec<f64> = additional.iter().map(|(_, _, b)| b.margin_needed).collect();
    let within = need.iter().filter(|&&x| x <= BAND).count();
    let default = f64::from(DEFAULT_MARGIN);
    let suggested = additional
        .iter()
        .filter(|(_, _, b)| b.margin_needed <= default)
        .count();
    let _ = writeln!(
        t,
        "\n## Boundaries at the additional speeds (balancing below, gathering above)\n\n\
         These move little: of {} such boundaries {} need no more than the classifier's ±{:.0} % \
         band to be right on both sides; the band they need is {:.2} % at the median, {:.2} % at \
         the 90th percentile and {:.2} % at most; the core's `DEFAULT_MARGIN` \
         ({:.0} %, the default of `drive-sim run` and `sweep`) covers {} of {}.",
        additional.len(),
        within,
        100.0 * BAND,
        100.0 * quantile(&mut need, 0.5),
        100.0 * quantile(&mut need, 0.9),
        100.0 * need.last().copied().unwrap_or(f64::NAN),
        100.0 * default,
        suggested,
        additional.len()
    );
    let pts: Vec<_> = additional
        .iter()
        .map(|(p, _, b)| (p.epsilon, p.h, p.beta, b.margin_needed))
        .collect();
    fit_line(
        &mut t,
        "Margin needed at the additional speeds (non-zero ones)",
        &pts,
    );
    // Terciles of each group.
    let _ = writeln!(
        t,
        "\n## Dependence on ε and damping\n\nMedian shift of the first resonance boundary, and \
         largest margin needed at an additional speed, by third of each group's range:\n\n\
         | group | third | range | first resonance: median shift | additional: largest need |\n\
         |---|---|---|---:|---:|"
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
            let inside = |p: &Sample| get(p) >= a && get(p) < b;
            let mut sh: Vec<f64> = first
                .iter()
                .filter(|(p, _, _)| inside(p))
                .map(|(_, _, b)| b.shift_high)
                .collect();
            let mx = additional
                .iter()
                .filter(|(p, _, _)| inside(p))
                .map(|(_, _, b)| b.margin_needed)
                .fold(0.0f64, f64::max);
            let _ = writeln!(
                t,
                "| {name} | {} | [{a:.3}, {b:.3}) | {:+.1} % ({}) | {:.2} % |",
                third + 1,
                100.0 * quantile(&mut sh, 0.5),
                sh.len(),
                100.0 * mx
            );
        }
    }
    let _ = writeln!(
        t,
        "\n![first resonance](criterion-resonance.svg)\n\n![additional speeds](criterion-additional.svg)\n\n\
         ## Every boundary\n\n`low shift`: the lower zone's regime holds up to b·(1 + low shift); \
         `high shift`: the upper zone's regime holds from b·(1 + high shift); `margin needed`: \
         the half-width of the band about b outside which the core's class (its `Bistable` \
         capture band counted) matches the simulation.\n\n{}",
        boundary_table(s)
    );
    let md = dir.join("criterion.md");
    std::fs::write(&md, t).map_err(|e| format!("{}: {e}", md.display()))?;
    // Plots: shift against β (first resonance, by third of h) and need against ε.
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
                    .map(|(p, _, b)| (p.beta.log10(), 100.0 * b.shift_high))
                    .collect(),
                markers: true,
            }
        })
        .collect();
    write_svg(
        &svg1,
        &Chart {
            title: "First resonance: where balancing sets in, above the criterion's boundary",
            x_label: "log10 β",
            y_label: "simulated boundary shift, %",
            series,
            marks: vec![Mark::HLine("criterion".into(), 0.0)],
        },
    )?;
    let svg2 = dir.join("criterion-additional.svg");
    write_svg(
        &svg2,
        &Chart {
            title: "Additional speeds: band needed about the criterion's boundary",
            x_label: "ε",
            y_label: "margin needed, %",
            series: vec![Series {
                label: "additional-speed boundaries".into(),
                points: additional
                    .iter()
                    .map(|(p, _, b)| (p.epsilon, 100.0 * b.margin_needed))
                    .collect(),
                markers: true,
            }],
            marks: vec![Mark::HLine(
                format!("classifier band ±{:.0} %", 100.0 * BAND),
                100.0 * BAND,
            )],
        },
    )?;
    Ok(vec![md, svg1, svg2])
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
