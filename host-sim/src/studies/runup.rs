//! The run-up capture page: a run-up scene whose loads start together, repeated at slower and
//! faster run-ups, so the page shows the release speed converging on the core's quasi-static
//! [`CaptureWindow::until`] as the run-up slows. The rotor is either prescribed (a ramp,
//! repeated at other ramp rates) or driven by the scene's motor (a Kloss or parabola
//! characteristic against the load and the machine's own reaction torque, seed 000; repeated
//! with the shaft's inertia scaled, which scales the run-up rate inversely).
//!
//! A finite-rate ramp releases late: the captured state disappears at the fold of the averaged
//! balance (at `until`, or just past it when the fold lies beyond the gathering zone, see
//! [`fold`]), but the loads need time to fall off it. [`ramp_rates`] repeats the scene at other
//! rates, [`release_fit`] fits the release speed against the rate, and [`markdown`] writes the
//! page. The analysis of each run is [`crate::app::capture`].
//!
//! [`CaptureWindow::until`]: drive_monitor::balancer::CaptureWindow::until

use crate::app::capture::{summary, write_capture_svg, write_time_svg, CaptureReport};
use crate::app::run::{run, Overrides, RunReport};
use crate::app::scene::{MotorSpec, Scene, SceneError};
use drive_monitor::balancer::Machine;
use serde::Serialize;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// A run of a ramp scene at another ramp rate.
#[derive(Debug, Clone, Serialize)]
pub struct RampRun {
    /// Ramp rate of the scene's motor, rad/s².
    pub rate: f64,
    /// The run's capture analysis.
    pub capture: Option<CaptureReport>,
}

/// Errors (naming `key`, the value scaled) unless the `what` factor is positive and finite.
fn slowdown_factor(file: &Path, key: &str, what: &str, factor: f64) -> Result<(), SceneError> {
    if factor.is_finite() && factor > 0.0 {
        Ok(())
    } else {
        Err(SceneError::value(
            file,
            key,
            format!("{what} factor must be positive and finite, got {factor}"),
        ))
    }
}

/// `scene` with its prescribed ramp `factor` times as long (the hold after the ramp kept).
/// Errors unless the scene's motor is a ramp and `factor` is positive and finite.
pub fn with_ramp_stretched(scene: &Scene, file: &Path, factor: f64) -> Result<Scene, SceneError> {
    slowdown_factor(file, "motor.duration", "ramp time", factor)?;
    let mut s = scene.clone();
    let Some(MotorSpec::Ramp { duration, .. }) = &mut s.motor else {
        return Err(SceneError::value(
            file,
            "motor",
            "the capture study needs a prescribed ramp (`model = \"ramp\"`)",
        ));
    };
    let hold = (s.simulation.duration - *duration).max(0.0);
    *duration *= factor;
    s.simulation.duration = *duration + hold;
    Ok(s)
}

/// `scene` with a motor-driven run-up `factor` times slower: the shaft's inertia and
/// flywheel, and the simulated time, scaled by `factor` (the acceleration under a given torque
/// falls as the inertia rises). Errors unless the scene's shaft is motor-driven (`[shaft]`
/// and a Kloss or parabola `[motor]`) and `factor` is positive and finite.
pub fn with_inertia_scaled(scene: &Scene, file: &Path, factor: f64) -> Result<Scene, SceneError> {
    slowdown_factor(file, "shaft.inertia", "inertia", factor)?;
    let mut s = scene.clone();
    if !matches!(
        s.motor,
        Some(MotorSpec::Kloss { .. } | MotorSpec::Parabola { .. })
    ) {
        return Err(SceneError::value(
            file,
            "motor",
            "a motor-driven run-up needs a Kloss or parabola motor",
        ));
    }
    let Some(shaft) = &mut s.shaft else {
        return Err(SceneError::value(
            file,
            "shaft",
            "missing: a motor-driven run-up needs [shaft]",
        ));
    };
    shaft.inertia *= factor;
    shaft.flywheel *= factor;
    s.simulation.duration *= factor;
    Ok(s)
}

/// The run-up scene repeated `factor` times slower for each of `factors` (a prescribed ramp
/// stretched, [`with_ramp_stretched`], or a motor-driven shaft's inertia scaled,
/// [`with_inertia_scaled`]), in parallel and without the encoder (only the loads are judged).
/// The rate of a ramp is its own; of a motor-driven run-up, the rotor's mean acceleration
/// while the loads were captured (NaN if they were not). In the order of `factors`.
pub fn ramp_rates(scene: &Scene, file: &Path, factors: &[f64]) -> Result<Vec<RampRun>, SceneError> {
    use rayon::prelude::*;
    let motor_driven = !matches!(scene.motor, Some(MotorSpec::Ramp { .. }));
    factors
        .par_iter()
        .map(|&f| {
            let mut s = if motor_driven {
                with_inertia_scaled(scene, file, f)?
            } else {
                with_ramp_stretched(scene, file, f)?
            };
            s.encoder = None;
            let r = run(&s, file, Overrides::default())?;
            let rate = match &s.motor {
                Some(MotorSpec::Ramp { from, to, duration }) => (to - from) / duration,
                _ => r
                    .capture
                    .as_ref()
                    .and_then(|c| c.ramp_rate)
                    .unwrap_or(f64::NAN),
            };
            Ok(RampRun {
                rate,
                capture: r.capture,
            })
        })
        .collect::<Result<_, SceneError>>()
}

/// The speed a run-up ends at: a ramp's final speed, or the steady mean speed the drive model
/// predicts for a motor-driven shaft (`None` otherwise).
pub fn final_speed(scene: &Scene, file: &Path) -> Result<Option<f64>, SceneError> {
    if let Some(MotorSpec::Ramp { to, .. }) = &scene.motor {
        return Ok(Some(*to));
    }
    Ok(crate::app::predict::drive_model(scene, file)?.map(|m| m.u_mean().max(0.0).sqrt()))
}

/// The run-up scene run at its final speed ([`final_speed`]) from the start, prescribed, loads
/// together at rest, without the encoder: the contrast to the run-up's end state.
pub fn held_run(scene: &Scene, file: &Path) -> Result<Option<RunReport>, SceneError> {
    let Some(to) = final_speed(scene, file)? else {
        return Ok(None);
    };
    let to = &to;
    let mut s = scene.clone();
    s.encoder = None;
    run(
        &s,
        file,
        Overrides {
            speed: Some(*to),
            loads_together: true,
        },
    )
    .map(Some)
}

/// The fold of the averaged balance: the largest `Ω + D(Ω)` (`D` = [`Machine::capture_lag`])
/// for `Ω` within 10 % of the first capture window's lower edge, as `(ω, Ω)`. The core's
/// `until` takes the maximum inside the gathering zone only; the fold may lie just past it.
pub fn fold(machine: &Machine) -> Option<(f64, f64)> {
    let from = machine.capture_windows().first()?.from;
    let n = 20_000;
    (0..=n)
        .map(|i| {
            let x = from * (0.9 + 0.2 * i as f64 / n as f64);
            (x + machine.capture_lag(x), x)
        })
        .max_by(|a, b| a.0.total_cmp(&b.0))
}

/// Least-squares fit `release = a + b·rate^(2/3)` over the released runs: `(a, b)`. The
/// exponent is that of a slow passage through a fold (saddle-node): the delay of the jump
/// grows as the two-thirds power of the sweep rate.
pub fn release_fit(runs: &[RampRun]) -> Option<(f64, f64)> {
    let pts: Vec<(f64, f64)> = runs
        .iter()
        .filter_map(|r| {
            let v = r.capture.as_ref()?.release_speed?;
            Some((r.rate.powf(2.0 / 3.0), v))
        })
        .collect();
    line_fit(&pts)
}

/// Least-squares line `y = a + b·x` through `pts`: `(a, b)`; `None` with fewer than two
/// points or no spread in `x`.
fn line_fit(pts: &[(f64, f64)]) -> Option<(f64, f64)> {
    if pts.len() < 2 {
        return None;
    }
    let n = pts.len() as f64;
    let mx = pts.iter().map(|p| p.0).sum::<f64>() / n;
    let my = pts.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = pts.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = pts.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| {
        let b = sxy / sxx;
        (my - b * mx, b)
    })
}

/// Slope of `log(release − ω_fold)` against `log(rate)` over the runs released above the
/// fold (2/3 for a slow passage through it).
pub fn release_slope(runs: &[RampRun], fold_speed: f64) -> Option<f64> {
    let pts: Vec<(f64, f64)> = runs
        .iter()
        .filter_map(|r| {
            let v = r.capture.as_ref()?.release_speed?;
            (v > fold_speed && r.rate > 0.0).then(|| (r.rate.ln(), (v - fold_speed).ln()))
        })
        .collect();
    line_fit(&pts).map(|(_, slope)| slope)
}

/// A ramp rate (rad/s²) as text: up to five decimals, trailing zeros dropped.
pub fn rate_text(r: f64) -> String {
    let t = format!("{r:.5}");
    t.trim_end_matches('0').trim_end_matches('.').to_string()
}

fn cell(v: Option<f64>, digits: usize) -> String {
    v.map_or("—".to_string(), |x| format!("{x:.digits$}"))
}

fn percent(v: Option<f64>) -> String {
    v.map_or("—".to_string(), |e| format!("{:+.2} %", 100.0 * e))
}

/// The capture page: the scene's run, the release speed per ramp rate with its quasi-static
/// limit, and the captured load speed against the core. `command` regenerates it; `plots`
/// are the file names of the Ω-against-ω and the time plots next to the page; `held` is the
/// scene run at its final speed from the start, loads together at rest ([`held_run`]).
pub fn markdown(
    title: &str,
    command: &str,
    plots: [&str; 2],
    main: &RunReport,
    runs: &[RampRun],
    machine: &Machine,
    held: Option<&RunReport>,
) -> String {
    let mut s = format!("# {title}\n\nRegenerated by `{command}`.\n\n");
    let Some(c) = &main.capture else {
        s.push_str("The run has no capture analysis (the loads did not start together).\n");
        return s;
    };
    let drive = if c.ramp_rate.is_some() && main.effects.contains(&"motor") {
        "the rotor is driven from rest by the scene's motor (its torque characteristic against \
         the load and the machine's own reaction torque, seed 000), through the first \
         resonance to its steady speed"
    } else {
        "the rotor's speed is prescribed, ramped through the first resonance and then held"
    };
    let predicted = crate::app::report::fmt_speeds_from(&[c.predicted_from, c.predicted_until], 2);
    let _ = writeln!(
        s,
        "The loads start together at rest; {drive}. The core predicts that gathered loads can \
         stay captured \
         near the resonance (turning at Ω < ω) for rotor speeds from {} up to {} rad/s \
         (`Machine::capture_windows`), turning at `Machine::capture_speed(ω)`. The simulation \
         counts the loads captured while the rotor is above {} rad/s and the loads lag it by \
         more than {:.0} % (speeds from the unwrapped angles over {:.2} s windows); the release \
         is where the lag falls back through {:.0} % for good.\n",
        predicted[0],
        predicted[1],
        predicted[0],
        100.0 * c.lag_fraction,
        c.window,
        100.0 * c.lag_fraction
    );
    let _ = writeln!(
        s,
        "![loads' speed against the rotor's]({})\n\n![speeds against time]({})\n",
        plots[0], plots[1]
    );
    let _ = writeln!(s, "## The scene's run\n\n```text\n{}```\n", summary(c));
    s.push_str(
        "The captured load speed is averaged over two turns of the slip `φ − θ` (rotor angle \
         minus the loads' mean angle): the rotor's own unbalance turns at ω, the loads at Ω, so \
         the platform's forcing beats at the slip frequency ω − Ω and the loads' speed \
         oscillates with it by a few rad/s (visible in the time plot); the core's averaged \
         balance describes the mean.\n\n",
    );
    s.push_str(
        "## Release speed against the run-up rate\n\n\
         A finite-rate run-up releases late: the captured state ceases to exist at the fold of \
         the averaged balance, but the loads need time to fall off it. The release speed \
         approaches the quasi-static value as the run-up slows (a ramp's rate is its own; a \
         motor-driven run-up, repeated with the shaft's inertia scaled, is given the rotor's \
         mean acceleration while the loads were captured).\n\n\
         | run-up, rad/s² | captured from, rad/s | released at, rad/s | core `until`, rad/s | difference | captured Ω (median), rad/s | largest Ω difference from `capture_speed` |\n\
         |---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in runs {
        let Some(c) = &r.capture else { continue };
        let worst = c
            .checks
            .iter()
            .filter_map(|k| k.relative_error)
            .max_by(|a, b| a.abs().total_cmp(&b.abs()));
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2} | {} | {} | {} |",
            rate_text(r.rate),
            cell(c.captured_from.map(|a| a[1]), 2),
            c.release_speed
                .map_or("not released".to_string(), |x| format!("{x:.2}")),
            c.predicted_until,
            percent(c.release_relative_error),
            cell(c.captured_load_speed_median, 2),
            percent(worst)
        );
    }
    let folded = fold(machine);
    if let Some((a, b)) = release_fit(runs) {
        let _ = write!(
            s,
            "\nFitting `release = a + b·rate^(2/3)` (the delay of a slow passage through a fold) \
             to these runs gives the quasi-static release a = {a:.2} rad/s (b = {b:.2}), \
             {:+.2} % from the core's `until` = {:.2} rad/s.",
            100.0 * (a / c.predicted_until - 1.0),
            c.predicted_until
        );
    }
    if let Some((w, x)) = folded {
        let _ = write!(
            s,
            " The averaged balance Ω + D(Ω) = ω itself folds at ω = {w:.2} rad/s (Ω = {x:.2} \
             rad/s), {:+.2} % above `until`: the core takes the maximum inside the gathering \
             zone, which ends at {:.2} rad/s.",
            100.0 * (w / c.predicted_until - 1.0),
            c.predicted_from
        );
        if let Some(k) = release_slope(runs, w) {
            let _ = write!(
                s,
                " The release's excess over the fold falls as rate^{k:.2} (log–log slope over \
                 the runs)."
            );
        }
    }
    s.push_str("\n\n## Captured load speed against `capture_speed(ω)` (the scene's run)\n\n");
    s.push_str(
        "| rotor ω, rad/s | simulated Ω, rad/s | core Ω, rad/s | difference |\n|---:|---:|---:|---:|\n",
    );
    for k in &c.checks {
        let _ = writeln!(
            s,
            "| {:.2} | {:.3} | {} | {} |",
            k.rotor_speed,
            k.load_speed,
            cell(k.predicted, 3),
            percent(k.relative_error)
        );
    }
    if let (Some(sim), Some(pred)) = (main.regime_simulated, main.regime_predicted) {
        let _ = write!(
            s,
            "\n## After the release\n\n\
             At the end of the run (rotor at {:.2} rad/s) the core classes the speed {}{} \
             (the criterion: {pred}); the simulation ends {sim}, residual unbalance {:.2} of the \
             rotor's.",
            main.speed_measured.unwrap_or(f64::NAN),
            main.regime_class.unwrap_or("?"),
            main.regime_reason
                .map_or(String::new(), |r| format!(" ({r})")),
            main.residual_relative.unwrap_or(f64::NAN)
        );
        if sim != pred && 1.0 - c.coherence_end < 1e-12 {
            s.push_str(
                " The loads end together (coherence 1 to double precision).\n\n\
                 This is a limit of the point-load model rather than of the criterion: gathered \
                 below the resonance and while captured, the loads converge on each other until \
                 their angles agree to rounding, and identical loads obey identical equations, so \
                 they never part again. They stay together, turning with the rotor, instead of \
                 parting to the balancing position. Real balls touch and cannot coincide.",
            );
            if let Some(h) = held {
                let _ = write!(
                    s,
                    " Started together at rest (0.01 rad apart, not coincident) with the rotor \
                     at the final speed from the outset, the same machine ends {}, residual \
                     unbalance {:.1e} of the rotor's.",
                    h.regime_simulated.unwrap_or("?"),
                    h.residual_relative.unwrap_or(f64::NAN)
                );
            }
            s.push('\n');
        } else {
            s.push('\n');
        }
    }
    s
}

/// Run-up slowdowns of the capture page, relative to the scene's (ramp time or shaft inertia;
/// slower run-ups for the convergence of the release speed, two faster ones for contrast),
/// ascending: the runs come out fastest first.
const RAMP_FACTORS: [f64; 8] = [0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0];

/// Writes the capture page of a run-up (`run SCENE --out DIR`): the Markdown page, the
/// Ω-against-ω plot over several ramp rates and the scene's speeds against time.
pub fn publish(
    name: &str,
    scene: &Scene,
    path: &Path,
    report: &RunReport,
    dir: &Path,
) -> Result<Vec<PathBuf>, String> {
    if report.capture.is_none() {
        return Err(format!(
            "{}: --out writes the capture page of a run-up: the loads must start together \
             (`[autobalancer] start = \"together\"`)",
            path.display()
        ));
    }
    let machine = crate::app::predict::machine(scene, path)
        .map_err(|e| e.to_string())?
        .ok_or_else(|| format!("{}: no auto-balancer", path.display()))?;
    let runs = ramp_rates(scene, path, &RAMP_FACTORS).map_err(|e| e.to_string())?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let stem = crate::app::run::scene_stem(path);
    let title =
        format!("{stem}: Sommerfeld capture in a run-up, against the core's capture window");
    let speeds = format!("capture-{stem}.svg");
    let time = format!("capture-{stem}-time.svg");
    // Three ramps on the Ω-against-ω plot: the fastest, the scene's and the slowest.
    let shown: Vec<(String, &CaptureReport)> = [runs.first(), runs.get(2), runs.last()]
        .into_iter()
        .flatten()
        .filter_map(|r| {
            r.capture
                .as_ref()
                .map(|c| (format!("simulated, run-up {} rad/s²", rate_text(r.rate)), c))
        })
        .collect();
    write_capture_svg(&dir.join(&speeds), &title, &shown, &machine)?;
    if let Some(c) = &report.capture {
        write_time_svg(
            &dir.join(&time),
            &format!("{stem}: speeds in the run-up"),
            c,
        )?;
    }
    let md = dir.join(format!("capture-{stem}.md"));
    let command = format!(
        "cargo run --release -p host-sim -- run {name} --out {}",
        dir.display()
    );
    let held = held_run(scene, path).map_err(|e| e.to_string())?;
    let text = markdown(
        &title,
        &command,
        [&speeds, &time],
        report,
        &runs,
        &machine,
        held.as_ref(),
    );
    std::fs::write(&md, text).map_err(|e| format!("{}: {e}", md.display()))?;
    Ok(vec![md, dir.join(speeds), dir.join(time)])
}
