//! Readable text reports.

use crate::app::plot::{write_svg, Chart, Mark, Series};
use crate::app::predict::{self, fmt_delta, Prediction};
use crate::app::run::RunReport;
use crate::app::scene::Scene;
use std::fmt::Write;
use std::path::{Path, PathBuf};

/// A noise floor as text (`–` when no window was counted).
fn floor(x: Option<f64>) -> String {
    x.map_or("–".to_string(), |x| format!("{x:.1e}"))
}

/// After "no alarm": how many windows the alarm could judge, when it could not judge them
/// all for their noise floor (a silent "no alarm" from an alarm that judged nothing would read
/// as a drive within its limit).
fn alarm_judged(r: &RunReport) -> String {
    let Some(j) = r.alarm_judged.filter(|j| j.floor_near_limit > 0) else {
        return String::new();
    };
    let why = format!(
        "{} had a noise floor above {} of the limit, which δ cannot be told from",
        j.floor_near_limit, j.floor_fraction
    );
    if j.counted == 0 {
        format!(
            " — the alarm judged none of the {} windows: {why}; a faster capture timer \
             (`encoder.timer_hz`) or more estimator edges (`encoder.estimator_edges`) lower the \
             floor",
            r.windows
        )
    } else {
        format!(
            " (judged {} of the {} windows; {why})",
            j.counted, r.windows
        )
    }
}

/// The edges a run produced: the line edges (as `analyze` of its capture counts the channel's
/// edges), with the noise pulses among them, and the index pulses on their own channel.
fn edges_text(r: &RunReport) -> String {
    let mut s = format!("{} line edges", r.line_edges);
    if r.noise_pulses > 0 {
        let _ = write!(s, " ({} of them noise pulses)", r.noise_pulses);
    }
    if r.index_pulses > 0 {
        let _ = write!(s, " and {} index pulses", r.index_pulses);
    }
    s
}

/// What a run simulated: a prescribed shaft's law (with its cranking ripple), then the
/// effects, counted in the singular for one ("1 effect: rotor-loads"; a prescribed speed
/// without any had printed "0 effects: ").
fn effects_text(r: &RunReport) -> String {
    let effects = match r.effects.len() {
        0 => "no effects".to_string(),
        1 => format!("1 effect: {}", r.effects[0]),
        n => format!("{n} effects: {}", r.effects.join(", ")),
    };
    match r.shaft {
        "motor-driven" | "" => effects,
        law => format!("shaft {law}; {effects}"),
    }
}

/// A run as text.
pub fn run_text(scene: &Scene, r: &RunReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "Scene {}", r.scene);
    if let Some(d) = &scene.description {
        let _ = writeln!(s, "  {d}");
    }
    let _ = writeln!(
        s,
        "Simulated {:.1} s with {} ({}) in {:.3} s wall: {} RHS evaluations, {} steps ({} rejected), {}",
        r.simulated_seconds,
        r.integrator,
        effects_text(r),
        r.wall_seconds,
        r.rhs_evaluations,
        r.steps[0],
        r.steps[1],
        edges_text(r)
    );
    for why in &r.not_simulated {
        let _ = writeln!(s, "NOT SIMULATED {why}");
    }
    for w in &r.model_warnings {
        let _ = writeln!(s, "{w}");
    }
    if let Some(why) = &r.no_measurement {
        let _ = writeln!(s, "NOTHING MEASURED by the core: {why}");
    }
    if r.windows > 0 {
        let _ = writeln!(s, "Measured by the core from the encoder edges");
        let _ = writeln!(
            s,
            "  windows {} ({} invalid{}), edges rejected: {} glitches, {} missing, {} extra",
            r.windows,
            r.invalid_windows,
            if r.invalid_reasons.is_empty() {
                String::new()
            } else {
                format!(
                    ": {}",
                    r.invalid_reasons
                        .iter()
                        .map(|(k, v)| format!("{v} {k}"))
                        .collect::<Vec<_>>()
                        .join(", ")
                )
            },
            r.rejected_edges[0],
            r.rejected_edges[1],
            r.rejected_edges[2]
        );
        if r.timeouts > 0 {
            let _ = writeln!(
                s,
                "  standstill: the core found the shaft stopped {} time(s) (its timeout)",
                r.timeouts
            );
        }
        if let Some(w) = r.speed_measured {
            let _ = writeln!(s, "  mean speed {w:.3} rad/s");
        }
        if let Some(w) = &r.window_warning {
            let _ = writeln!(s, "  {w}");
        }
        match (r.delta_measured, r.delta_predicted) {
            (Some(m), Some(p)) => {
                // The speed samples can read more than 1 % less than the predicted δ: say what
                // they show with this scene's teeth, which the measurement is compared with,
                // and over the load's phase against the teeth (the prediction's WARNING says
                // why).
                let through = match (
                    r.delta_predicted_through_samples,
                    r.delta_predicted_through_samples_least,
                    r.delta_predicted_through_samples_most,
                ) {
                    (Some(d), Some(lo), Some(hi)) if lo < 0.99 * p => Some((d, lo, hi)),
                    _ => None,
                };
                let shown = |d: f64| predict::fmt_sampled(d, p);
                let sampled = match through {
                    Some((d, lo, hi)) if predict::sampled_spread(p, lo, hi) => {
                        format!(
                            " ({} through the core's speed samples with the teeth where this \
                             scene has them, {} to {} over the load's phase against the teeth)",
                            shown(d),
                            shown(lo),
                            shown(hi)
                        )
                    }
                    Some((d, ..)) => format!(" ({} through the core's speed samples)", shown(d)),
                    None => String::new(),
                };
                // Against what the samples show, where that is above the noise floor.
                let against = match (through, r.noise_floor) {
                    (Some((d, ..)), f) if d > f.unwrap_or(0.0) && d > 0.0 => {
                        format!(" ({:+.2} % against the samples)", 100.0 * (m / d - 1.0))
                    }
                    _ => String::new(),
                };
                let _ = writeln!(
                    s,
                    "  δ measured {} (median of steady windows after {:.1} s), predicted {}{sampled}{}, noise floor {}",
                    fmt_delta(m),
                    r.settle,
                    fmt_delta(p),
                    // A drive without load ripple is predicted δ = 0: no relative difference.
                    // Neither above the noise floor: the difference is the quantization's. At
                    // the floor counts as within it, as `analyze` judges a window (a steady
                    // quantised speed reads δ equal to its floor).
                    match r.noise_floor {
                        Some(f) if m <= f && p <= f => {
                            ": neither above the noise floor, not resolved".to_string()
                        }
                        _ if p > 0.0 => format!(": {:+.2} %{against}", 100.0 * (m / p - 1.0)),
                        _ => String::new(),
                    },
                    floor(r.noise_floor)
                );
            }
            (Some(m), None) => {
                // Within the noise floor (at it counts as within, as `analyze` judges a
                // window): not resolved, as the line with a prediction says.
                let _ = writeln!(
                    s,
                    "  δ measured {}, noise floor {}{}",
                    fmt_delta(m),
                    floor(r.noise_floor),
                    match r.noise_floor {
                        Some(f) if m <= f => ": within the noise floor, not resolved",
                        _ => "",
                    }
                );
            }
            _ => {}
        }
        for n in &r.delta_notes {
            let _ = writeln!(s, "  {n}");
        }
        if let Some(l) = r.delta_limit {
            if r.alarms.is_empty() {
                let _ = writeln!(s, "  δ limit {l}: no alarm{}", alarm_judged(r));
            }
            for a in &r.alarms {
                let _ = writeln!(s, "  δ limit {l}: alarm {} at {:.2} s", a.event, a.time);
            }
        }
    }
    if let (Some(cap), Some(d), Some(floor)) = (r.capacity, r.rotor_unbalance, r.residual_floor) {
        if floor > 0.0 {
            let _ = writeln!(
                s,
                "Auto-balancer too small for its rotor: capacity N·m·R = {cap:.4e} kg·m < rotor \
                 unbalance D = {d:.4e} kg·m; with every load at its limit the residual unbalance \
                 is {floor:.4e} kg·m ({:.1} % of D); simulated: {}, residual {:.2e} of D",
                100.0 * floor / d,
                r.regime_simulated.unwrap_or("?"),
                r.residual_relative.unwrap_or(f64::NAN)
            );
        }
    }
    if let (Some(p), Some(sim)) = (r.regime_predicted, r.regime_simulated) {
        let _ = writeln!(
            s,
            "Regime at the measured speed: core class {}{}{}, criterion {p}, simulation {sim} (residual unbalance {} of the rotor's)",
            r.regime_class.unwrap_or("?"),
            r.regime_reason.map_or(String::new(), |x| format!(" ({x})")),
            if r.regime_by_history {
                " (from the speed's history: the table says bistable here, and the loads came balanced from a balancing speed)"
            } else {
                ""
            },
            r.residual_relative
                .map_or("–".to_string(), |x| format!("{x:.2e}"))
        );
    } else if let Some(sim) = r.regime_simulated {
        // No measured speed (no [encoder]): what the loads did, without the core's class.
        let _ = writeln!(
            s,
            "Regime simulated: {sim} (residual unbalance {} of the rotor's; no [encoder], so no \
             measured speed for the core to classify)",
            r.residual_relative
                .map_or("–".to_string(), |x| format!("{x:.2e}"))
        );
    }
    if let Some(why) = &r.regime_unsettled {
        let _ = writeln!(s, "The simulated regime is unsettled: {why}");
    }
    if let Some(why) = &r.regime_mismatch {
        let _ = writeln!(s, "  ≠ the core's class and the simulation disagree: {why}");
    }
    if let Some(why) = &r.regime_coincident {
        let _ = writeln!(s, "The simulated regime is not judged: {why}");
    }
    if let Some(swing) = &r.regime_swing {
        let _ = writeln!(s, "The simulated regime is gathering: {swing}");
    }
    if let Some(c) = &r.capture {
        s.push_str(&crate::app::capture::summary(c));
    }
    if let Some(u) = &r.supports {
        s.push_str(&supports_text(u));
    }
    s
}

/// Speeds in rad/s, each with at least three decimals and three significant digits, and with
/// as many more as it takes to differ from its neighbours in `v` where the values differ: a
/// segment whose ends differ never prints as `0.254 – 0.254`. A boundary gets the same digits
/// wherever it appears (its decimals are the most either neighbour needs); `∞` for infinity.
pub fn fmt_speeds(v: &[f64]) -> Vec<String> {
    fmt_speeds_from(v, 3)
}

/// [`fmt_speeds`] with at least `min` decimals.
pub fn fmt_speeds_from(v: &[f64], min: usize) -> Vec<String> {
    // Beyond 40 decimals a difference is no speed anyone sets.
    const MAX: usize = 40;
    let min = min.min(MAX);
    let significant = |x: f64| {
        if x == 0.0 || !x.is_finite() {
            min
        } else {
            (2 - x.abs().log10().floor() as i64).clamp(min as i64, MAX as i64) as usize
        }
    };
    let apart = |a: f64, b: f64| {
        (min..=MAX)
            .find(|&d| a == b || format!("{a:.d$}") != format!("{b:.d$}"))
            .unwrap_or(MAX)
    };
    (0..v.len())
        .map(|k| {
            let x = v[k];
            if x.is_infinite() {
                return "∞".to_string();
            }
            let mut d = significant(x);
            if k > 0 && v[k - 1].is_finite() {
                d = d.max(apart(v[k - 1], x));
            }
            if let Some(&n) = v.get(k + 1).filter(|n| n.is_finite()) {
                d = d.max(apart(x, n));
            }
            format!("{x:.d$}")
        })
        .collect()
}

/// Two speeds, `from` and `to`, as [`fmt_speeds`] prints them.
pub fn fmt_speed_pair(from: f64, to: f64) -> (String, String) {
    let mut v = fmt_speeds(&[from, to]).into_iter();
    let a = v.next().unwrap_or_default();
    (a, v.next().unwrap_or_default())
}

/// A safe speed, rad/s: one decimal from 100 rad/s (188.2), 4 significant digits below (0.09410,
/// 5.432), scientific from 1e6 (1.0690e152), where a fixed-point figure would run to many
/// digits; 0 as "0.0".
fn fmt_safe_speed(w: f64) -> String {
    let a = w.abs();
    if a >= 1e6 && a.is_finite() {
        format!("{w:.4e}")
    } else {
        fmt_force(w)
    }
}

/// A support load in N: one decimal from 100 N up (`2407.0`), four significant digits below
/// (`0.1634`, `52.18`), so that a small rotor's loads keep their digits (a 50 g rotor's
/// 0.163 N was printed `0.2`), and `1.234e-5` under a millinewton.
pub fn fmt_force(f: f64) -> String {
    let a = f.abs();
    if a == 0.0 || a >= 100.0 || !a.is_finite() {
        format!("{f:.1}")
    } else if a < 1e-3 {
        format!("{f:.3e}")
    } else {
        // 1e-3 ≤ |f| < 100: 4 significant digits.
        let decimals = (3 - a.log10().floor() as i32).max(1) as usize;
        format!("{f:.decimals$}")
    }
}

/// The supports line of a run: the core's judgement at the measured speed, or, without one,
/// the simulated reactions against the load limits.
fn supports_text(u: &crate::app::run::SupportsRunOut) -> String {
    let load = |v: Option<f64>| v.map_or("–".to_string(), fmt_force);
    // The simulated reactions, each with its level against the load limit when there is one.
    let reactions = |k: usize| match u.simulated_reaction_level {
        Some(levels) => format!(
            "{} N at {:.3} s ({} against the load limit)",
            fmt_force(u.simulated_peak_reaction[k]),
            u.simulated_peak_at[k],
            levels[k]
        ),
        None => format!(
            "{} N at {:.3} s",
            fmt_force(u.simulated_peak_reaction[k]),
            u.simulated_peak_at[k]
        ),
    };
    let mut text = match u.speed {
        Some(speed) => format!(
            "Supports at {speed:.2} rad/s (the fastest speed a valid window measured{}{}): peak loads A {} N ({}), B {} N ({}); simulated peak reactions over the run A {}, B {}; unbalance A {}, B {}\n",
            u.speed_at
                .map_or(String::new(), |t| format!(", in the window ending at {t:.3} s")),
            u.speed_mean
                .map_or(String::new(), |m| format!(", mean {m:.2}")),
            load(u.peak_load[0]),
            u.load_level[0],
            load(u.peak_load[1]),
            u.load_level[1],
            reactions(0),
            reactions(1),
            u.unbalance_level[0],
            u.unbalance_level[1]
        ),
        None => format!(
            "Supports NOT JUDGED by the core (it measured no speed): simulated peak reactions over the run A {}, B {}; unbalance A {}, B {}\n",
            reactions(0),
            reactions(1),
            u.unbalance_level[0],
            u.unbalance_level[1]
        ),
    };
    for w in [
        &u.above_service_speed,
        &u.balancer_warning,
        &u.unbalance_warning,
        &u.reactions_note,
    ]
    .into_iter()
    .flatten()
    {
        text.push_str("  ");
        text.push_str(w);
        text.push('\n');
    }
    text
}

/// Writes the plots a run calls for into `dir`; returns the files written.
pub fn run_plots(
    scene: &Scene,
    file: &Path,
    r: &RunReport,
    dir: &Path,
) -> Result<Vec<PathBuf>, String> {
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let mut out = Vec::new();
    let stem = file
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("scene")
        .to_string();
    if !r.speed_trace.is_empty() {
        out.push(speed_plot(r, &dir.join(format!("{stem}-speed.svg")))?);
    }
    if !r.window_list.is_empty() {
        out.push(delta_plot(r, &dir.join(format!("{stem}-delta.svg")))?);
    }
    let machine = predict::machine(scene, file).map_err(|e| e.to_string())?;
    if let (Some(c), Some(machine)) = (&r.capture, &machine) {
        let path = dir.join(format!("{stem}-capture.svg"));
        crate::app::capture::write_capture_svg(
            &path,
            "Loads' speed against the rotor's (Sommerfeld capture)",
            &[("simulated".into(), c)],
            machine,
        )?;
        out.push(path);
        let path = dir.join(format!("{stem}-capture-time.svg"));
        crate::app::capture::write_time_svg(&path, "Rotor and loads' speeds", c)?;
        out.push(path);
    }
    if let Some(machine) = &machine {
        let path = dir.join(format!("{stem}-regimes.svg"));
        out.push(regimes_plot(r, machine, &path)?);
    }
    if let Some((rotor, limits)) = predict::rotor(scene, file).map_err(|e| e.to_string())? {
        let path = dir.join(format!("{stem}-supports.svg"));
        out.push(supports_plot(scene, file, r, &rotor, &limits, &path)?);
    }
    Ok(out)
}

/// The speed the core measured against time, with the first invalid windows and the
/// settling time marked.
fn speed_plot(r: &RunReport, path: &Path) -> Result<PathBuf, String> {
    let mut marks: Vec<Mark> = r
        .window_list
        .iter()
        .filter(|w| !w.valid)
        .map(|w| {
            Mark::VLine(
                format!("invalid window ({})", w.fault.unwrap_or("?")),
                w.time,
            )
        })
        .take(5)
        .collect();
    marks.push(Mark::Band("settling".into(), 0.0, r.settle, true));
    write_svg(
        path,
        &Chart {
            title: "Shaft speed measured by the core (per speed sample)",
            x_label: "time, s",
            y_label: "ω, rad/s",
            series: vec![Series {
                label: "ω".into(),
                points: r.speed_trace.clone(),
                markers: false,
            }],
            marks,
        },
    )?;
    Ok(path.to_path_buf())
}

/// δ of every valid window against time, with the limit and the prediction.
fn delta_plot(r: &RunReport, path: &Path) -> Result<PathBuf, String> {
    let mut marks = Vec::new();
    if let Some(l) = r.delta_limit {
        marks.push(Mark::HLine(format!("limit {l}"), l));
    }
    if let Some(p) = r.delta_predicted {
        marks.push(Mark::HLine(format!("predicted {p:.5}"), p));
    }
    let valid: Vec<(f64, f64)> = r
        .window_list
        .iter()
        .filter(|w| w.valid)
        .map(|w| (w.time, w.delta))
        .collect();
    write_svg(
        path,
        &Chart {
            title: "δ per window (one load cycle each)",
            x_label: "time, s",
            y_label: "δ",
            series: vec![Series {
                label: "δ measured".into(),
                points: valid,
                markers: true,
            }],
            marks,
        },
    )?;
    Ok(path.to_path_buf())
}

/// The auto-balancer's zones along the speed axis over Re H of the exciter platform, with
/// the measured speed.
fn regimes_plot(
    r: &RunReport,
    machine: &drive_monitor::balancer::Machine,
    path: &Path,
) -> Result<PathBuf, String> {
    let top = machine
        .resonant_speeds()
        .iter()
        .copied()
        .fold(0.0, f64::max)
        * 1.6;
    let mut marks: Vec<Mark> = machine
        .zones()
        .iter()
        .map(|z| {
            Mark::Band(
                z.kind.name().into(),
                z.from,
                z.to.unwrap_or(top),
                z.kind.name() == "gathering",
            )
        })
        .collect();
    if let Some(w) = r.speed_measured {
        marks.push(Mark::VLine(format!("measured speed {w:.2} rad/s"), w));
    }
    let n = 400;
    let re: Vec<(f64, f64)> = (1..=n)
        .map(|i| {
            let w = top * i as f64 / n as f64;
            let (re, _) = machine.receptance(w);
            (w, re)
        })
        .collect();
    let scale = re.iter().map(|p| p.1.abs()).fold(0.0, f64::max).max(1e-300);
    write_svg(
        path,
        &Chart {
            title: "Auto-balancer zones (criterion: balancing where Re H < 0)",
            x_label: "rotor speed, rad/s",
            y_label: "Re H / max |Re H|",
            series: vec![Series {
                label: "Re H of the exciter platform".into(),
                points: re.into_iter().map(|(w, v)| (w, v / scale)).collect(),
                markers: false,
            }],
            marks,
        },
    )?;
    Ok(path.to_path_buf())
}

/// The peak support loads per turn against speed, with the load limits, the service speed
/// and the measured speed.
fn supports_plot(
    scene: &Scene,
    file: &Path,
    r: &RunReport,
    rotor: &drive_monitor::supports::Rotor<{ predict::MAX_UNBALANCES }>,
    limits: &drive_monitor::supports::Limits,
    path: &Path,
) -> Result<PathBuf, String> {
    let analysis = predict::analysis(scene, rotor, limits, file).map_err(|e| e.to_string())?;
    let top = analysis
        .max_safe_speed()
        .filter(|w| w.is_finite())
        .unwrap_or(3.0 * limits.service_speed())
        * 1.2;
    let n = 300;
    let curve = |k: usize| -> Vec<(f64, f64)> {
        (0..=n)
            .map(|i| {
                let w = top * i as f64 / n as f64;
                (w, rotor.loads(w)[k].peak)
            })
            .collect()
    };
    let mut marks = Vec::new();
    if let Some(l) = scene.rotor.as_ref().and_then(|r| r.support_load_limit) {
        marks.push(Mark::HLine(format!("limit A {} N", l[0]), l[0]));
        if l[1] != l[0] {
            marks.push(Mark::HLine(format!("limit B {} N", l[1]), l[1]));
        }
    }
    marks.push(Mark::VLine(
        format!("service speed {} rad/s", limits.service_speed()),
        limits.service_speed(),
    ));
    if let Some(w) = r.speed_measured {
        marks.push(Mark::VLine(format!("measured {w:.1} rad/s"), w));
    }
    write_svg(
        path,
        &Chart {
            title: "Peak support load per turn against speed",
            x_label: "speed, rad/s",
            y_label: "load, N",
            series: vec![
                Series {
                    label: "support A".into(),
                    points: curve(0),
                    markers: false,
                },
                Series {
                    label: "support B".into(),
                    points: curve(1),
                    markers: false,
                },
            ],
            marks,
        },
    )?;
    Ok(path.to_path_buf())
}

/// The design-time results as text.
pub fn prediction_text(p: &Prediction) -> String {
    let mut s = String::new();
    if let Some(i) = &p.irregularity {
        let _ = writeln!(
            s,
            "Predicted running irregularity (steady state, {})",
            if i.approximate {
                "APPROXIMATE: seed 000 eq. 11–13 with the Kloss curve's parabola at the \
                 operating point, see the motor line"
            } else if i.kloss_curve && i.inertia_note.is_some() {
                "seed 000 eq. 1 with the Kloss curve and J(φ)"
            } else if i.kloss_curve {
                "seed 000 eq. 1 with the Kloss curve"
            } else if i.inertia_note.is_some() {
                "seed 000 eq. 1 with J(φ)"
            } else {
                "seed 000 eq. 11–13"
            }
        );
        if let (Some(max), Some(min), Some(d)) = (i.omega_max, i.omega_min, i.delta) {
            let _ = writeln!(
                s,
                "  ω max {max:.3} rad/s, ω min {min:.3} rad/s, δ = {}",
                fmt_delta(d)
            );
            for w in [
                &i.working_branch_warning,
                &i.generator_note,
                &i.alarm_floor_warning,
                &i.min_speed_warning,
                &i.phase_warning,
                &i.machine_torque_warning,
            ]
            .into_iter()
            .flatten()
            {
                let _ = writeln!(s, "  {w}");
            }
        } else {
            let _ = writeln!(
                s,
                "  no steady state: {}",
                i.stall.unwrap_or("the motor stalls under the peak load")
            );
        }
        match i.flywheel_for_limit {
            Some(Some(j)) if j > 0.0 => {
                let _ = writeln!(s, "  flywheel for the δ limit: add {j:.4} kg·m²");
            }
            Some(Some(_)) => {
                let _ = writeln!(s, "  within the δ limit without a flywheel");
            }
            Some(None) => match i.flywheel_beyond_range {
                Some(j) => {
                    let _ = writeln!(
                        s,
                        "  no flywheel within `shaft.flywheel`'s range (at most {:e} kg·m²) \
                         reaches the δ limit: it would take {j:.4e} kg·m²",
                        crate::app::check::MAX_INERTIA
                    );
                }
                None => {
                    let _ = writeln!(s, "  no flywheel reaches the δ limit");
                }
            },
            None => {}
        }
        if let (Some(dj), Some(dm)) = (i.d_delta_d_inertia, i.d_delta_d_breakdown_torque) {
            let _ = writeln!(
                s,
                "  ∂δ/∂J = {dj:.4e} per kg·m², ∂δ/∂M_m = {dm:.4e} per N·m"
            );
        }
        if let Some(w) = &i.sampling_warning {
            let _ = writeln!(s, "  {w}");
        }
        if let Some(n) = &i.sampling_note {
            let _ = writeln!(s, "  {n}");
        }
        if let Some(n) = &i.motor_note {
            let _ = writeln!(s, "  {n}");
        }
        if let Some(n) = &i.inertia_note {
            let _ = writeln!(s, "  {n}");
        }
    }
    if let Some(why) = &p.irregularity_not_predicted {
        let _ = writeln!(s, "Running irregularity NOT PREDICTED: {why}");
    }
    if let Some(w) = &p.window_warning {
        let _ = writeln!(s, "  {w}");
    }
    if let Some(u) = &p.supports {
        let _ = writeln!(s, "Support unbalance (seed 002) and limits (ISO 21940-11)");
        let _ = writeln!(
            s,
            "  equivalent unbalance: A {:.4e} kg·m (permissible {:.4e}: {}), B {:.4e} kg·m (permissible {:.4e}: {})",
            u.unbalance_a,
            u.permissible_a,
            u.unbalance_level[0],
            u.unbalance_b,
            u.permissible_b,
            u.unbalance_level[1]
        );
        let _ = writeln!(
            s,
            "  permissible allotted {}",
            if u.allocation == "inboard" {
                "by the lever, each plane within 30–70 % of U_per (ISO 21940-11, inboard rotor)"
            } else {
                "by the lever of U_per at the centre of mass, the far plane at least 30 % of \
                 U_per (overhung rotor: this product's rule)"
            }
        );
        let _ = writeln!(
            s,
            "  static loads A {} N, B {} N; peak at service speed A {} N, B {} N{}",
            fmt_force(u.static_load[0]),
            fmt_force(u.static_load[1]),
            fmt_force(u.peak_load_at_service_speed[0]),
            fmt_force(u.peak_load_at_service_speed[1]),
            u.load_level
                .map_or(String::new(), |l| format!(" ({}, {})", l[0], l[1]))
        );
        match (u.max_speed, u.max_speed_status) {
            (Some(w), _) => {
                let why = u
                    .no_safe_speed
                    .as_ref()
                    .map_or(String::new(), |why| format!(": {why}"));
                let above = if w > crate::app::check::MAX_SPEED {
                    format!(
                        ", above the {:e} rad/s any scene can turn: not limited within the \
                         speeds a scene runs",
                        crate::app::check::MAX_SPEED
                    )
                } else {
                    String::new()
                };
                let _ = writeln!(
                    s,
                    "  maximum safe speed {} rad/s{above}{why}",
                    fmt_safe_speed(w)
                );
            }
            (None, "no_load_limit") => {
                let _ = writeln!(
                    s,
                    "  maximum safe speed: not computed (no `rotor.support_load_limit` given)"
                );
            }
            (None, _) => {
                let _ = writeln!(
                    s,
                    "  maximum safe speed: not limited by the support loads (no unbalance \
                     loads them with the speed)"
                );
            }
        }
        if let (Some(w), Some(peak)) = (u.predicted_speed, u.peak_load_at_predicted_speed) {
            let _ = writeln!(
                s,
                "  at the {} {w:.2} rad/s: peak A {} N, B {} N{}",
                if u.speed_prescribed {
                    "prescribed top speed"
                } else {
                    "predicted ω max"
                },
                fmt_force(peak[0]),
                fmt_force(peak[1]),
                u.load_level_at_predicted_speed
                    .map_or(String::new(), |l| format!(" ({}, {})", l[0], l[1]))
            );
        }
        if let Some(w) = &u.above_service_speed {
            let _ = writeln!(s, "  {w}");
        }
        if let Some(w) = &u.balancer_warning {
            let _ = writeln!(s, "  {w}");
        }
        if let Some(w) = &u.unbalance_warning {
            let _ = writeln!(s, "  {w}");
        }
    }
    if let Some(a) = &p.autobalancer {
        let _ = writeln!(s, "Auto-balancer regimes (seed 001)");
        // Three decimals, more where a speed needs them to show at all (a platform hung only
        // on its couplings resonates near 1e-4 rad/s).
        let list = |v: &[f64]| fmt_speeds(v).join(", ");
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
        if !a.unexcited_speeds.is_empty() {
            let _ = writeln!(
                s,
                "  not excited by the rotor: {} rad/s (a mode with a node at the balancer's \
                 platform: a resonance and an additional speed of the seed's lists, whose pole \
                 and zero cancel)",
                list(&a.unexcited_speeds)
            );
        }
        // The zones are contiguous: each boundary printed once with the digits both its
        // zones need.
        let ends = fmt_speeds(
            &a.zones
                .iter()
                .map(|z| z.from)
                .chain([a.zones.last().and_then(|z| z.to).unwrap_or(f64::INFINITY)])
                .collect::<Vec<_>>(),
        );
        for (k, z) in a.zones.iter().enumerate() {
            let to = match (z.to, a.zones.get(k + 1)) {
                (Some(to), Some(n)) if to != n.from => fmt_speed_pair(z.from, to).1,
                _ => ends[k + 1].clone(),
            };
            let _ = writeln!(s, "  {:>9} – {to:<9} rad/s  {}", ends[k], z.regime);
        }
        for c in &a.capture {
            let v = fmt_speeds(&[c.from, c.until]);
            let _ = writeln!(
                s,
                "  capture possible from {} up to {} rad/s (loads held near {} rad/s)",
                v[0],
                v[1],
                fmt_speeds(&[c.at])[0]
            );
        }
        for c in &a.resonance_capture {
            let v = fmt_speeds(&[c.from, c.until]);
            let _ = writeln!(
                s,
                "  at the resonance near {} rad/s, gathered loads can be held up to {} \
                 rad/s (near {} rad/s; the exact table's capture, whether or not a zone of \
                 the criterion ends there)",
                v[0],
                v[1],
                fmt_speeds(&[c.at])[0]
            );
        }
        let _ = writeln!(
            s,
            "  capacity N·m·R = {:.4e} kg·m, rotor unbalance D = {:.4e} kg·m{}",
            a.capacity,
            a.rotor_unbalance,
            if a.rotor_unbalance_assumed {
                " (no `autobalancer.rotor_unbalance` in the scene: half the capacity assumed)"
            } else {
                ""
            }
        );
        if a.residual_floor > 0.0 {
            let _ = writeln!(
                s,
                "  the balancer is too small for its rotor: no balancing position; with every \
                 load at its limit, opposite the unbalance, the residual unbalance is {:.4e} \
                 kg·m ({:.1} % of D)",
                a.residual_floor,
                100.0 * a.residual_floor / a.rotor_unbalance
            );
            let _ = writeln!(
                s,
                "  (the table below is the criterion's: its `balancing` means the loads at their \
                 limit, the machine saturated)"
            );
        }
        if let Some(st) = &a.stability {
            let scanned = fmt_speeds_from(&st.scanned, 2);
            let _ =
                writeln!(
                s,
                "  exact stability of the balancing position (Floquet, {} monodromy matrices over \
                 {}–{} rad/s): {} at the lowest speed",
                st.evaluations,
                scanned[0],
                scanned[1],
                if st.stable_at_start { "stable" } else { "unstable" }
            );
            if let Some(c) = &st.criterion_below {
                let _ = writeln!(
                    s,
                    "  the scan starts at {:.4e} rad/s, not a quarter of the lowest resonance: \
                     below it a revolution lasts more than {:.0} periods of the machine's fastest \
                     motion ({:.4e} rad/s, set by {}) and the scan would take too many \
                     integration steps; the regime table follows the criterion below it",
                    c.speed,
                    c.fastest_rate / c.speed,
                    c.fastest_rate,
                    c.set_by
                );
            }
            if let Some(u) = &st.drift_treated_as_neutral {
                let speeds = fmt_speeds_from(&u.speeds, 2);
                let _ = writeln!(
                    s,
                    "  the loads' slow drift along the balancing positions (neutral at D = 0) has a \
                     multiplier within {:.0e} of 1, the integration's resolution, at {} of those \
                     speeds ({}–{} rad/s; |ρ − 1| at most {:.1e}): treated there as \
                     neutral, as at D = 0",
                    u.resolution,
                    u.evaluations,
                    speeds[0],
                    speeds[1],
                    u.largest
                );
            }
            if let Some(u) = &st.neutral_within_resolution {
                let speeds = fmt_speeds_from(&u.speeds, 2);
                let _ = writeln!(
                    s,
                    "  the spectral radius lies within {:.0e} of 1, the integration's resolution, \
                     at {} of those speeds ({}–{} rad/s; |ρ − 1| at most {:.1e}): the motion \
                     there grows or decays by less than that a revolution (an undamped one, such \
                     as a platform's on `damping = 0`, at every speed; a boundary where ρ crosses \
                     1 slowly, over a band) and is taken as stable, a boundary in the band placed \
                     at its unstable edge",
                    u.resolution, u.evaluations, speeds[0], speeds[1], u.largest
                );
            }
            let speeds = fmt_speeds_from(
                &st.boundaries.iter().map(|b| b.speed).collect::<Vec<_>>(),
                4,
            );
            for (b, speed) in st.boundaries.iter().zip(&speeds) {
                let _ = writeln!(
                    s,
                    "    {speed:>10} rad/s  becomes {}",
                    if b.stable_above { "stable" } else { "unstable" }
                );
            }
            for c in &st.criterion {
                let below = st
                    .criterion_below
                    .as_ref()
                    .filter(|b| c.criterion < b.speed);
                let _ = writeln!(
                    s,
                    "  criterion boundary {} rad/s ({}): nearest exact boundary where the \
                     balancing position becomes {} {}",
                    fmt_speeds(&[c.criterion])[0],
                    c.kind,
                    // A resonance is where the criterion's balancing begins, an additional
                    // speed where it ends: each is set beside the exact boundary of its kind.
                    if c.kind == "resonance" {
                        "stable"
                    } else {
                        "unstable"
                    },
                    match (c.exact, c.difference, below) {
                        (_, _, Some(b)) => format!(
                            "none: below the exact scan's {} rad/s",
                            fmt_speeds(&[b.speed])[0]
                        ),
                        (Some(e), Some(d), None) => {
                            format!("{} rad/s ({:+.2} %)", fmt_speeds(&[e])[0], 100.0 * d)
                        }
                        _ => "none".to_string(),
                    }
                );
            }
        }
        let _ = writeln!(s, "  regime table ({}):", a.regime_table_source);
        let ends = fmt_speeds(
            &a.regime_table
                .iter()
                .map(|g| g.from)
                .chain([f64::INFINITY])
                .collect::<Vec<_>>(),
        );
        for (k, seg) in a.regime_table.iter().enumerate() {
            let _ = writeln!(
                s,
                "    {:>9} – {:<9} rad/s  {}{}",
                ends[k],
                ends[k + 1],
                seg.regime,
                seg.reason.map_or(String::new(), |r| format!(" ({r})"))
            );
        }
        if a.regime_table_source == "exact"
            && a.regime_table.iter().any(|g| g.regime == "balancing")
        {
            let _ = writeln!(
                s,
                "  (balancing: loads near the balancing position stay there; started together at \
                 rest, on a few machines they instead keep slipping up to about 4 % slower than \
                 the rotor there: docs/criterion.md)"
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The regime table of a two-platform machine (`predict` printed `21.905 – 21.905 rad/s
    /// bistable (coexisting)`): every segment's ends now differ in print, a boundary prints
    /// alike in both its segments, and each figure is the speed rounded to its digits.
    #[test]
    fn segment_ends_that_differ_print_differently() {
        let ends = [
            0.0,
            19.03310146892505,
            19.033845894172092,
            21.905342837271974,
            21.905368333620213,
            37.363870225711594,
            37.40573958339075,
            f64::INFINITY,
        ];
        let text = fmt_speeds(&ends);
        assert_eq!(
            text,
            ["0.000", "19.033", "19.034", "21.9053", "21.9054", "37.364", "37.406", "∞"]
        );
        for (x, t) in ends.iter().zip(&text).filter(|(x, _)| x.is_finite()) {
            let decimals = t.split('.').nth(1).map_or(0, str::len) as i32;
            let printed: f64 = t.parse().unwrap();
            assert!(
                (printed - x).abs() <= 0.5 * 10f64.powi(-decimals),
                "{x} {t}"
            );
        }
        // A capture window 2.6e-7 rad/s wide at 0.254 rad/s, and a speed far below a
        // thousandth keeps three significant digits rather than printing as 0.000.
        let (a, b) = fmt_speed_pair(0.25400012, 0.25400038);
        assert!(
            a != b && a.starts_with("0.254") && b.starts_with("0.254"),
            "{a} {b}"
        );
        assert_eq!(fmt_speeds(&[2.53e-5])[0], "0.0000253");
        // Equal ends keep the usual digits; a single speed too.
        assert_eq!(
            fmt_speed_pair(0.802, 0.802),
            ("0.802".into(), "0.802".into())
        );
        assert_eq!(fmt_speeds_from(&[61.4312, 90.4149], 2), ["61.43", "90.41"]);
    }
}
