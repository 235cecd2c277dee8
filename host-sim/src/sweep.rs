//! `drive-sim sweep`: a vibration-machine scene at a series of prescribed rotor speeds, in
//! parallel, comparing the criterion's zone with what the loads did in the simulation.

use crate::predict;
use crate::run::{run, Overrides};
use crate::scene::{Scene, SceneError};
use drive_monitor::balancer::{Classifier, Regime};
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
        .unwrap_or(0.02) as f32;
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
    Ok(Sweep { points: points? })
}
