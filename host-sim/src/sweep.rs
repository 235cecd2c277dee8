//! `drive-sim sweep`: a vibration-machine scene at a series of prescribed rotor speeds, in
//! parallel, comparing the criterion's zone with what the loads did in the simulation.

use crate::predict;
use crate::run::{run, Overrides};
use crate::scene::{Scene, SceneError};
use drive_monitor::balancer::{Classifier, Regime, DEFAULT_MARGIN};
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;
use serde::Serialize;
use std::path::Path;

/// One speed of a sweep.
#[derive(Debug, Clone, Serialize)]
pub struct SweepPoint {
    /// Prescribed rotor speed, rad/s.
    pub speed: f64,
    /// The criterion's zone at this speed (the core's zones, damping included):
    /// "balancing" | "gathering".
    pub regime_predicted: &'static str,
    /// The core's classification with its margin band and capture check:
    /// "balancing" | "gathering" | "bistable" | "near-characteristic".
    pub regime_class: &'static str,
    /// What the loads did, started near the balancing position with a small perturbation
    /// (or together at rest with `--together`): "balancing" | "gathering".
    pub regime_simulated: &'static str,
    /// Final residual unbalance relative to the rotor's.
    pub residual_relative: f64,
}

/// A whole sweep.
#[derive(Debug, Clone, Serialize)]
pub struct Sweep {
    /// The points, by ascending speed.
    pub points: Vec<SweepPoint>,
    /// Points outside the margin band around every damped characteristic speed.
    pub away_from_characteristic: usize,
    /// Of those, the points where the criterion and the simulation agree.
    pub agreeing: usize,
    /// The damped characteristic speeds (zone boundaries), rad/s.
    #[serde(skip)]
    pub boundaries: Vec<f64>,
    /// The zones (from, to, regime) for plotting.
    #[serde(skip)]
    pub zones: Vec<(f64, Option<f64>, &'static str)>,
}

impl Sweep {
    /// The regime map as a Markdown table, with the agreement line.
    pub fn markdown(&self) -> String {
        use std::fmt::Write;
        let mut s = String::from(
            "| speed, rad/s | criterion | core class | simulated | residual / rotor unbalance |\n\
             |---:|---|---|---|---:|\n",
        );
        for p in &self.points {
            let _ = writeln!(
                s,
                "| {:.2} | {} | {} | {}{} | {:.2e} |",
                p.speed,
                p.regime_predicted,
                p.regime_class,
                p.regime_simulated,
                if p.regime_predicted == p.regime_simulated {
                    ""
                } else {
                    " ≠"
                },
                p.residual_relative
            );
        }
        let _ = writeln!(
            s,
            "\nAway from the characteristic speeds (outside the margin band): {} of {} speeds agree.",
            self.agreeing, self.away_from_characteristic
        );
        s
    }

    /// The regime map as an SVG: zones along the speed axis, simulated outcomes as points
    /// (1 = balancing, 0 = gathering) with the final residual unbalance.
    pub fn write_svg(&self, path: &Path, title: &str) -> Result<(), String> {
        use crate::plot::{write_svg, Chart, Mark, Series};
        let top = self.points.last().map_or(1.0, |p| p.speed);
        let mut marks: Vec<Mark> = self
            .zones
            .iter()
            .map(|&(from, to, regime)| {
                Mark::Band(
                    format!("criterion: {regime}"),
                    from,
                    to.unwrap_or(top * 2.0),
                    regime == "gathering",
                )
            })
            .collect();
        marks.push(Mark::HLine("simulated balancing".into(), 1.0));
        let outcome = |p: &SweepPoint| {
            if p.regime_simulated == "balancing" {
                1.0
            } else {
                0.0
            }
        };
        write_svg(
            path,
            &Chart {
                title,
                x_label: "rotor speed, rad/s",
                y_label: "simulated: 1 balancing, 0 gathering",
                series: vec![Series {
                    label: "simulated outcome".into(),
                    points: self.points.iter().map(|p| (p.speed, outcome(p))).collect(),
                    markers: true,
                }],
                marks,
            },
        )
    }
}

/// Runs `scene` at `steps` speeds from `from` to `to` (inclusive), in parallel.
pub fn sweep(
    scene: &Scene,
    file: &Path,
    from: f64,
    to: f64,
    steps: usize,
    together: bool,
    progress: bool,
) -> Result<Sweep, SceneError> {
    let bad = |key: &str, message: String| SceneError::Value {
        file: file.to_path_buf(),
        key: key.into(),
        message,
    };
    let Some(machine) = predict::machine(scene, file)? else {
        return Err(bad(
            "platform",
            "missing: a sweep needs a vibration machine ([[platform]] and [autobalancer])".into(),
        ));
    };
    if !(from.is_finite() && to.is_finite() && from > 0.0 && to > from) {
        return Err(bad(
            "--from/--to",
            format!("need 0 < from < to, got {from} and {to}"),
        ));
    }
    if steps < 2 {
        return Err(bad(
            "--steps",
            format!("need at least 2 steps, got {steps}"),
        ));
    }
    let margin = scene
        .monitor
        .as_ref()
        .and_then(|m| m.regime_margin)
        .map_or(DEFAULT_MARGIN, |m| m as f32);
    let classifier = Classifier::new(&machine, margin, 0.5 * margin)
        .map_err(|e| predict::value_error(file, "monitor", e))?;
    // The sweep judges the loads, not δ: no encoder, so no edges to generate.
    let mut quiet = scene.clone();
    quiet.encoder = None;
    let bar = if progress {
        ProgressBar::new(steps as u64)
    } else {
        ProgressBar::hidden()
    };
    bar.set_style(
        ProgressStyle::with_template("{bar:40} {pos}/{len} speeds, {elapsed} elapsed, ETA {eta}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let points: Result<Vec<SweepPoint>, SceneError> = (0..steps)
        .into_par_iter()
        .map(|i| {
            let speed = from + (to - from) * i as f64 / (steps - 1) as f64;
            let r = run(
                &quiet,
                file,
                Overrides {
                    speed: Some(speed),
                    loads_together: together,
                },
            )?;
            bar.inc(1);
            Ok(SweepPoint {
                speed,
                regime_predicted: machine.zone_kind_at(speed).name(),
                regime_class: match classifier.classify(speed as f32) {
                    Regime::Balancing => "balancing",
                    Regime::Gathering => "gathering",
                    Regime::Bistable => "bistable",
                    Regime::NearCharacteristic => "near-characteristic",
                    Regime::Unknown => "unknown",
                },
                regime_simulated: r.regime_simulated.unwrap_or("unknown"),
                residual_relative: r.residual_relative.unwrap_or(f64::NAN),
            })
        })
        .collect();
    bar.finish_and_clear();
    let points = points?;
    let boundaries: Vec<f64> = classifier
        .characteristic_speeds()
        .iter()
        .map(|&b| f64::from(b))
        .collect();
    let margin = f64::from(margin);
    let away: Vec<&SweepPoint> = points
        .iter()
        .filter(|p| boundaries.iter().all(|&b| (p.speed - b).abs() > margin * b))
        .collect();
    Ok(Sweep {
        away_from_characteristic: away.len(),
        agreeing: away
            .iter()
            .filter(|p| p.regime_predicted == p.regime_simulated)
            .count(),
        boundaries,
        zones: machine
            .zones()
            .iter()
            .map(|z| (z.from, z.to, z.kind.name()))
            .collect(),
        points,
    })
}
