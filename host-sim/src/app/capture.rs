//! Sommerfeld capture in a run-up: the loads of an auto-balancer started together at rest,
//! the rotor ramped through the first resonance.
//!
//! Below the first damped characteristic speed the gathered loads turn as one unbalance a
//! little behind the rotor. Past it they can stay *captured*: held near the resonance by the
//! power the platform dissipates, turning at `Ω < ω` while the rotor runs faster, until the
//! rotor speed reaches the core's [`CaptureWindow::until`]; above it no captured state exists
//! and the loads jump to the rotor's speed.
//!
//! [`analyse`] reads this from a run's regime samples. The rotor's and the loads' mean speeds
//! are central differences of the unwrapped angles over a short window (two turns at the zone
//! boundary, at least two sample intervals: the release is a jump). A point is *captured* when
//! the rotor is above the first zone boundary ([`CaptureWindow::from`]) and the loads lag it by
//! more than the lag fraction (2 %, [`crate::engine::vibration::RegimeCriteria::lag_fraction`]). The
//! capture interval starts at the first captured point and ends at the first free point after
//! which the loads stay free for a second (the rotor's own unbalance turns at `ω`, the loads at
//! `Ω`, so the platform's forcing beats at the slip frequency `ω − Ω` and the loads' speed
//! wobbles with it); the release is where the lag falls through the fraction there
//! (interpolated between points). While captured, the loads' speed averaged over two whole slip
//! turns is compared with the core's quasi-static [`Machine::capture_speed`] at four rotor
//! speeds.
//!
//! A finite-rate ramp releases late: the captured state disappears at the fold of the averaged
//! balance, but the loads need time to fall off it; the run-up study
//! ([`crate::studies::runup`]) repeats a ramp scene at other rates to show the release speed
//! converging as the ramp slows.
//!
//! [`CaptureWindow::until`]: drive_monitor::balancer::CaptureWindow::until
//! [`CaptureWindow::from`]: drive_monitor::balancer::CaptureWindow::from

use crate::app::plot::{write_svg_with_legend, Chart, Mark, Series};
use crate::engine::vibration::{RegimeCriteria, RegimeSample};
use drive_monitor::balancer::Machine;
use plotters::prelude::SeriesLabelPosition;
use serde::Serialize;
use std::fmt::Write;
use std::path::Path;

/// Turns at the zone boundary the speed window spans (short: the release is a jump).
const WINDOW_TURNS: f64 = 2.0;
/// The loads count as released once they stay free this long, s (the slip beat may dip the
/// lag below the fraction for a moment while they are still captured).
const FREE_FOR: f64 = 1.0;
/// Slip periods the captured load speed is averaged over for the comparison with the core.
const SLIP_PERIODS: f64 = 2.0;
/// Fractions of the captured rotor-speed range where the load speed is compared with the core.
const CHECK_AT: [f64; 4] = [0.2, 0.4, 0.6, 0.8];

/// Rotor and load speeds at one instant (central differences of the unwrapped angles).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpeedPoint {
    /// Time, s.
    pub t: f64,
    /// Rotor speed ω, rad/s.
    pub rotor: f64,
    /// Loads' mean speed Ω, rad/s.
    pub load: f64,
}

/// The captured loads' speed at one rotor speed against the core's prediction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct CaptureCheck {
    /// Rotor speed ω, rad/s.
    pub rotor_speed: f64,
    /// Loads' simulated speed Ω, rad/s.
    pub load_speed: f64,
    /// [`Machine::capture_speed`] at ω, rad/s (`None`: the core predicts no capture there).
    pub predicted: Option<f64>,
    /// `load_speed / predicted − 1`.
    pub relative_error: Option<f64>,
}

/// What the loads did in a run-up, against the core's capture window.
#[derive(Debug, Clone, PartialEq, Serialize, Default)]
pub struct CaptureReport {
    /// The core's first capture window: its lower edge (the first gathering zone's upper
    /// edge), rad/s.
    pub predicted_from: f64,
    /// Rotor speed above which the core finds capture impossible, rad/s.
    pub predicted_until: f64,
    /// The exact table's capture bands at every resonance, `[from, until]` rad/s
    /// ([`crate::app::regimes::resonance_captures`]): loads can also be held at a resonance
    /// the core's windows leave out.
    pub resonance_bands: Vec<[f64; 2]>,
    /// Lag fraction used: captured when `Ω < (1 − lag_fraction)·ω`.
    pub lag_fraction: f64,
    /// Window of the speed differences, s.
    pub window: f64,
    /// The loads were captured at some point.
    pub captured: bool,
    /// Time and rotor speed where the capture interval starts, s and rad/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub captured_from: Option<[f64; 2]>,
    /// The loads were released before the run ended.
    pub released: bool,
    /// Time of the release, s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub release_time: Option<f64>,
    /// Rotor speed at the release, rad/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub release_speed: Option<f64>,
    /// `release_speed / predicted_until − 1`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub release_relative_error: Option<f64>,
    /// Median load speed while captured, rad/s.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub captured_load_speed_median: Option<f64>,
    /// Mean rotor acceleration over the capture interval, the time the rotor's speed held
    /// (a hold after the ramp) left out, rad/s².
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ramp_rate: Option<f64>,
    /// Captured load speed against [`Machine::capture_speed`] at a few rotor speeds.
    pub checks: Vec<CaptureCheck>,
    /// The loads' coherence `|Σ e^{iφ_j}|/N` at the end of the run (1: together).
    pub coherence_end: f64,
    /// Rotor and load speeds over the run (for plots).
    #[serde(skip)]
    pub trace: Vec<SpeedPoint>,
}

/// Rotor and load speeds from regime samples (uniformly spaced in time), central differences
/// over `k` samples either side.
fn speeds(samples: &[RegimeSample], k: usize) -> Vec<SpeedPoint> {
    samples
        .windows(2 * k + 1)
        .filter_map(|w| {
            let (a, b) = (w.first()?, w.last()?);
            let dt = b.t - a.t;
            (dt > 0.0).then(|| SpeedPoint {
                t: 0.5 * (a.t + b.t),
                rotor: (b.rotor_angle - a.rotor_angle) / dt,
                load: (b.mean_load_angle - a.mean_load_angle) / dt,
            })
        })
        .collect()
}

fn lerp(x0: f64, x1: f64, s: f64) -> f64 {
    x0 + (x1 - x0) * s
}

/// Mean rotor and load speeds over whole slip periods about sample `c`: the window widens
/// symmetrically until the slip `φ − θ` (rotor angle minus mean load angle) has advanced by
/// [`SLIP_PERIODS`] turns or the window reaches `lo` or `hi` (sample indices).
fn slip_averaged(samples: &[RegimeSample], lo: usize, hi: usize, c: usize) -> Option<(f64, f64)> {
    let slip = |s: &RegimeSample| s.rotor_angle - s.mean_load_angle;
    let mut h = 1;
    loop {
        let (a, b) = (samples.get(c.checked_sub(h)?)?, samples.get(c + h)?);
        if slip(b) - slip(a) >= SLIP_PERIODS * std::f64::consts::TAU || c - h <= lo || c + h >= hi {
            let dt = b.t - a.t;
            return (dt > 0.0).then(|| {
                (
                    (b.rotor_angle - a.rotor_angle) / dt,
                    (b.mean_load_angle - a.mean_load_angle) / dt,
                )
            });
        }
        h += 1;
    }
}

/// Analyses the samples (uniformly spaced in time) of a run whose loads started together.
/// `None` when the machine has no capture window (no gathering zone ends at a finite speed)
/// or there are too few samples.
pub fn analyse(samples: &[RegimeSample], machine: &Machine) -> Option<CaptureReport> {
    let window_of = machine.capture_windows().first()?;
    let lag_fraction = RegimeCriteria::new(1.0).lag_fraction;
    let dt = match samples {
        [a, b, ..] => b.t - a.t,
        _ => return None,
    };
    if dt <= 0.0 {
        return None;
    }
    let turn = std::f64::consts::TAU / window_of.from;
    let k = ((0.5 * WINDOW_TURNS * turn / dt).round() as usize).max(1);
    let trace = speeds(samples, k);
    let mut r = CaptureReport {
        coherence_end: samples.last().map_or(f64::NAN, |s| s.coherence),
        predicted_from: window_of.from,
        predicted_until: window_of.until,
        resonance_bands: crate::app::regimes::resonance_captures(machine)
            .iter()
            .map(|w| [w.from, w.until])
            .collect(),
        lag_fraction,
        window: 2.0 * k as f64 * dt,
        ..Default::default()
    };
    let lag = |p: &SpeedPoint| 1.0 - p.load / p.rotor;
    let captured = |p: &SpeedPoint| p.rotor > window_of.from && lag(p) > lag_fraction;
    let Some(start) = trace.iter().position(captured) else {
        r.trace = trace;
        return Some(r);
    };
    // The end: the first free point after which the loads stay free for FREE_FOR.
    let free_run = ((FREE_FOR / dt).ceil() as usize).max(1);
    let end = (start..trace.len()).find(|&i| {
        trace
            .get(i..(i + free_run).min(trace.len()))
            .is_some_and(|w| !w.iter().any(captured))
    });
    let span = trace.get(start..end.unwrap_or(trace.len()))?;
    let first = span.first()?;
    let last = span.last()?;
    r.captured = true;
    r.captured_from = Some([first.t, first.rotor]);
    let mut loads: Vec<f64> = span.iter().map(|p| p.load).collect();
    loads.sort_by(f64::total_cmp);
    r.captured_load_speed_median = loads.get(loads.len() / 2).copied();
    if let Some(after) = end.and_then(|e| trace.get(e)) {
        // Where the lag falls through the fraction, between the last captured point and the
        // first free one (if the rotor dropped below the boundary instead, its speed there).
        let (l0, l1) = (lag(last), lag(after));
        let s = if l0 > l1 {
            ((l0 - lag_fraction) / (l0 - l1)).clamp(0.0, 1.0)
        } else {
            1.0
        };
        let speed = lerp(last.rotor, after.rotor, s);
        r.released = true;
        r.release_time = Some(lerp(last.t, after.t, s));
        r.release_speed = Some(speed);
        r.release_relative_error = Some(speed / window_of.until - 1.0);
    }
    // The ramp's own rate: the speed gained over the time the rotor was gaining it (steps
    // whose acceleration is under 1e-3 of the mean left out), so that a hold after the ramp (a
    // run up to a speed inside the band, held there) does not dilute it (a 2.5 rad/s² ramp
    // held for 10 s read 1.35); a ramp still going at the release is unchanged.
    if last.t > first.t {
        let mean = (last.rotor - first.rotor) / (last.t - first.t);
        let ramping: f64 = span
            .windows(2)
            .map(|w| (w[1].t - w[0].t, w[1].rotor - w[0].rotor))
            .filter(|&(dt, dw)| dw.abs() > 1e-3 * mean.abs() * dt)
            .map(|(dt, _)| dt)
            .sum();
        r.ramp_rate = Some(if ramping > 0.0 {
            (last.rotor - first.rotor) / ramping
        } else {
            mean
        });
    }
    // Trace point i is centred on sample i + k.
    let (lo, hi) = (start + k, start + k + span.len() - 1);
    let top = last.rotor.min(window_of.until);
    for f in CHECK_AT {
        let target = lerp(first.rotor, top, f);
        let Some(i) = span.iter().position(|p| p.rotor >= target) else {
            continue;
        };
        let Some((rotor, load)) = slip_averaged(samples, lo, hi, lo + i) else {
            continue;
        };
        let predicted = machine.capture_speed(rotor);
        r.checks.push(CaptureCheck {
            rotor_speed: rotor,
            load_speed: load,
            predicted,
            relative_error: predicted.map(|w| load / w - 1.0),
        });
    }
    r.trace = trace;
    Some(r)
}

/// A capture report as text (two or three lines).
pub fn summary(c: &CaptureReport) -> String {
    let mut s = String::new();
    let bands = c
        .resonance_bands
        .iter()
        .map(|b| crate::app::report::fmt_speeds_from(b, 2).join("–"))
        .collect::<Vec<_>>()
        .join(", ");
    let predicted = crate::app::report::fmt_speeds_from(&[c.predicted_from, c.predicted_until], 2);
    let _ = write!(
        s,
        "Sommerfeld capture (loads started together; core: capture possible from {} up to {} rad/s{})\n  ",
        predicted[0],
        predicted[1],
        if bands.is_empty() {
            String::new()
        } else {
            format!("; at every resonance, the exact table's bands {bands} rad/s")
        }
    );
    match (c.captured_from, c.captured_load_speed_median) {
        (Some([_, a]), Some(x)) => {
            let _ = write!(
                s,
                "loads captured near {x:.2} rad/s (median) from rotor speed {a:.2} rad/s"
            );
            match (c.release_speed, c.release_relative_error) {
                (Some(b), Some(e)) => {
                    let _ = write!(
                        s,
                        " to {b:.2} rad/s; released at {b:.2} rad/s, core predicts until {:.2} ({:+.2} %)",
                        c.predicted_until,
                        100.0 * e
                    );
                }
                _ => s.push_str("; not released by the end of the run"),
            }
            if let Some(a) = c.ramp_rate {
                let _ = write!(s, "; ramp {a:.3} rad/s² while captured");
            }
            s.push('\n');
            if !c.checks.is_empty() {
                s.push_str("  captured load speed against the core's capture_speed(ω):");
                for k in &c.checks {
                    match (k.predicted, k.relative_error) {
                        (Some(p), Some(e)) => {
                            let _ = write!(
                                s,
                                " ω {:.1}: {:.2} vs {p:.2} ({:+.2} %);",
                                k.rotor_speed,
                                k.load_speed,
                                100.0 * e
                            );
                        }
                        _ => {
                            let _ =
                                write!(s, " ω {:.1}: {:.2} vs none;", k.rotor_speed, k.load_speed);
                        }
                    }
                }
                s.pop();
                s.push('\n');
            }
        }
        _ => s.push_str("the loads were not captured\n"),
    }
    s
}

/// At most this many points of a trace go into a plot.
const PLOT_POINTS: usize = 3000;

fn decimated(trace: &[SpeedPoint]) -> impl Iterator<Item = &SpeedPoint> {
    trace
        .iter()
        .step_by(trace.len().div_ceil(PLOT_POINTS).max(1))
}

/// The loads' speed against the rotor's, one curve per run, with the core's capture branch
/// `capture_speed(ω)`, the line `Ω = ω` and the predicted capture window shaded.
pub fn write_capture_svg(
    path: &Path,
    title: &str,
    runs: &[(String, &CaptureReport)],
    machine: &Machine,
) -> Result<(), String> {
    let top = runs
        .iter()
        .flat_map(|(_, c)| c.trace.iter().map(|p| p.rotor))
        .fold(0.0, f64::max)
        .max(1.2 * machine.capture_windows().first().map_or(1.0, |w| w.until));
    let mut series: Vec<Series> = runs
        .iter()
        .map(|(label, c)| Series {
            label: label.clone(),
            points: decimated(&c.trace).map(|p| (p.rotor, p.load)).collect(),
            markers: false,
        })
        .collect();
    // Points, not a line: they stay visible over the simulated loads' slip beat.
    let n = 80;
    series.push(Series {
        label: "core: captured loads' speed capture_speed(ω)".into(),
        points: (1..=n)
            .filter_map(|i| {
                let w = top * i as f64 / n as f64;
                machine.capture_speed(w).map(|c| (w, c))
            })
            .collect(),
        markers: true,
    });
    series.push(Series {
        label: "Ω = ω (loads turn with the rotor)".into(),
        points: vec![(0.0, 0.0), (top, top)],
        markers: false,
    });
    let marks = machine
        .capture_windows()
        .first()
        .map(|w| {
            Mark::Band(
                format!(
                    "core: capture window {} rad/s",
                    crate::app::report::fmt_speeds_from(&[w.from, w.until], 2).join("–")
                ),
                w.from,
                w.until,
                true,
            )
        })
        .into_iter()
        .collect();
    write_svg_with_legend(
        path,
        &Chart {
            title,
            x_label: "rotor speed ω, rad/s",
            y_label: "loads' mean speed Ω, rad/s",
            series,
            marks,
        },
        Some(SeriesLabelPosition::UpperLeft),
    )
}

/// The rotor's and the loads' speed against time, with the capture window's edges.
pub fn write_time_svg(path: &Path, title: &str, c: &CaptureReport) -> Result<(), String> {
    let mut marks = vec![
        Mark::HLine(
            format!(
                "core: capture possible up to {:.2} rad/s",
                c.predicted_until
            ),
            c.predicted_until,
        ),
        Mark::HLine(
            format!("first zone boundary {:.2} rad/s", c.predicted_from),
            c.predicted_from,
        ),
    ];
    if let Some(t) = c.release_time {
        marks.push(Mark::VLine(
            format!(
                "release at ω = {:.2} rad/s",
                c.release_speed.unwrap_or(f64::NAN)
            ),
            t,
        ));
    }
    write_svg_with_legend(
        path,
        &Chart {
            title,
            x_label: "time, s",
            y_label: "speed, rad/s",
            series: vec![
                Series {
                    label: "rotor ω".into(),
                    points: decimated(&c.trace).map(|p| (p.t, p.rotor)).collect(),
                    markers: false,
                },
                Series {
                    label: "loads' mean speed Ω".into(),
                    points: decimated(&c.trace).map(|p| (p.t, p.load)).collect(),
                    markers: false,
                },
            ],
            marks,
        },
        Some(SeriesLabelPosition::UpperLeft),
    )
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    #[test]
    fn central_differences_recover_linear_speeds() {
        // ω = 2 + 0.5 t (angle 2t + t²/4), Ω = 1.5: exact for a central difference.
        let s: Vec<RegimeSample> = (0..50)
            .map(|i| {
                let t = 0.1 * i as f64;
                RegimeSample {
                    t,
                    residual: 0.0,
                    coherence: 1.0,
                    mean_load_angle: 1.5 * t,
                    rotor_angle: 2.0 * t + 0.25 * t * t,
                }
            })
            .collect();
        let v = speeds(&s, 3);
        assert_eq!(v.len(), 50 - 6);
        for p in &v {
            assert!((p.rotor - (2.0 + 0.5 * p.t)).abs() < 1e-12, "{p:?}");
            assert!((p.load - 1.5).abs() < 1e-12);
        }
    }

    /// The bundled one-mass machine.
    fn one_mass() -> Machine {
        let (scene, path) = crate::app::scene::resolve("one-mass").unwrap();
        crate::app::predict::machine(&scene, &path)
            .unwrap()
            .unwrap()
    }

    /// Samples of a made-up run-up at 1 rad/s² (ω = t): the loads turn with the rotor up to
    /// 60 rad/s, stay at 60 rad/s until the rotor reaches 91 rad/s, except for 0.3 s at
    /// ω = 75 where they speed up to within 1 % of the rotor, then turn with it again.
    fn made_up_runup() -> Vec<RegimeSample> {
        let load_speed = |t: f64| {
            if !(60.0..91.0).contains(&t) {
                t
            } else if (75.0..75.3).contains(&t) {
                0.99 * t
            } else {
                60.0
            }
        };
        let dt = 0.01;
        let mut theta = 0.0;
        (0..12_000)
            .map(|i| {
                let t = i as f64 * dt;
                if i > 0 {
                    // Midpoint rule: the angle of a piecewise-smooth speed.
                    theta += dt * load_speed(t - 0.5 * dt);
                }
                RegimeSample {
                    t,
                    residual: 0.0,
                    coherence: 1.0,
                    mean_load_angle: theta,
                    rotor_angle: 0.5 * t * t,
                }
            })
            .collect()
    }

    #[test]
    fn finds_the_capture_and_its_release() {
        let machine = one_mass();
        let w = machine.capture_windows()[0];
        let c = analyse(&made_up_runup(), &machine).unwrap();
        assert!(c.captured && c.released);
        // Captured from the zone boundary (the loads lag by 2.3 % there), to within a sample.
        let from = c.captured_from.unwrap()[1];
        assert!((from - w.from).abs() < 0.02, "{from}");
        // The brief speed-up at 75 rad/s does not end the capture; the release is the jump at
        // 91 rad/s, found within the half window (0.1 s, 0.1 rad/s at 1 rad/s²) after it.
        let b = c.release_speed.unwrap();
        assert!((91.0..91.1).contains(&b), "{b}");
        assert!((c.release_relative_error.unwrap() - (b / w.until - 1.0)).abs() < 1e-15);
        assert!((c.ramp_rate.unwrap() - 1.0).abs() < 1e-3);
        assert!((c.captured_load_speed_median.unwrap() - 60.0).abs() < 1e-9);
        // The checks see the loads' 60 rad/s (whole slip turns, away from the speed-up).
        assert_eq!(c.checks.len(), CHECK_AT.len());
        for k in &c.checks {
            if (k.rotor_speed - 75.15).abs() > 2.0 {
                assert!((k.load_speed - 60.0).abs() < 1e-6, "{k:?}");
            }
            assert_eq!(k.predicted, machine.capture_speed(k.rotor_speed));
        }
        // Loads that never lag are never captured.
        let free: Vec<RegimeSample> = made_up_runup()
            .into_iter()
            .map(|s| RegimeSample {
                mean_load_angle: s.rotor_angle,
                ..s
            })
            .collect();
        let c = analyse(&free, &machine).unwrap();
        assert!(!c.captured && !c.released && c.release_speed.is_none());
    }

    /// A run-up at 1 rad/s² to 80 rad/s, inside the capture band, held there for 40 s with the
    /// loads captured at 60 rad/s: the ramp's rate is its own (over the whole captured span,
    /// the hold included, it read 0.35 rad/s²).
    #[test]
    fn a_hold_after_the_ramp_does_not_dilute_its_rate() {
        let machine = one_mass();
        let rotor_angle = |t: f64| {
            if t < 80.0 {
                0.5 * t * t
            } else {
                3200.0 + 80.0 * (t - 80.0)
            }
        };
        let samples: Vec<RegimeSample> = (0..12_000)
            .map(|i| {
                let t = i as f64 * 0.01;
                let load = if t < 60.0 {
                    rotor_angle(t)
                } else {
                    1800.0 + 60.0 * (t - 60.0)
                };
                RegimeSample {
                    t,
                    residual: 0.0,
                    coherence: 1.0,
                    mean_load_angle: load,
                    rotor_angle: rotor_angle(t),
                }
            })
            .collect();
        let c = analyse(&samples, &machine).unwrap();
        assert!(c.captured && !c.released);
        // Within 1 %: the trace's speeds are differences over a window, which smear the
        // ramp's corner over it (0.995 here).
        let rate = c.ramp_rate.unwrap();
        assert!((rate - 1.0).abs() < 1e-2, "{rate}");
    }
}
