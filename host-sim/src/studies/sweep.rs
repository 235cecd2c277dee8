//! `drive-sim sweep`: a vibration-machine scene at a series of prescribed rotor speeds, in
//! parallel, comparing the core's classification (from the machine's exact regime table,
//! [`crate::app::regimes`]) and the seed criterion's zone with what the loads did in the
//! simulation.

use crate::app::predict;
use crate::app::progress::progress_bar;
use crate::app::regimes::{balanced_start, growth_rate, settle_time, tracked};
use crate::app::run::{run, Overrides};
use crate::app::scene::{Scene, SceneError};
use crate::engine::vibration::floquet;
use crate::studies::criterion::ramp_outcome;
use drive_monitor::balancer::{Regime, RegimeSegment, DEFAULT_MARGIN};
use rayon::prelude::*;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// One speed of a sweep.
#[derive(Debug, Clone, Serialize)]
pub struct SweepPoint {
    /// Prescribed rotor speed, rad/s.
    pub speed: f64,
    /// The seed criterion's zone at this speed (the core's zones, damping included):
    /// "balancing" | "gathering".
    pub regime_predicted: &'static str,
    /// The core's classification with its margin band, from the exact regime table (or the
    /// criterion's, for a balancer too small for its rotor): "balancing" | "gathering" |
    /// "bistable" | "near-characteristic".
    pub regime_class: &'static str,
    /// Why bistable: "capture" | "coexisting".
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_reason: Option<&'static str>,
    /// What the loads did, started near the balancing position with a small perturbation
    /// (or together at rest with `--together`): "balancing" | "saturated" | "gathering", or
    /// "unsettled" when no run up to [`settled_run`]'s longest decided it.
    pub regime_simulated: &'static str,
    /// Why the last run is "unsettled" (`run`'s `regime_unsettled`): e.g. its residual stayed
    /// between 1 % and 10 % of the rotor's, near where it started, the run a fraction of an
    /// e-folding of the growth rate.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub regime_unsettled: Option<String>,
    /// Final residual unbalance relative to the rotor's.
    pub residual_relative: f64,
    /// Length of the (last) run, s: see [`settled_run`].
    pub duration: f64,
    /// Floquet growth rate of the balancing position's least stable perturbation here, 1/s
    /// (with an exact table).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub growth_rate: Option<f64>,
    /// Where the class is bistable and the tracker commits from the loads' history once the
    /// speed comes from a `Balancing` segment of the table through stable ones: that start
    /// and what the loads did ([`Arrived`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub arrived: Option<Arrived>,
}

/// A bistable speed reached with the loads balanced: the rotor ramped from `from` (inside the
/// nearest `Balancing` segment reachable through stable ones,
/// [`crate::app::regimes::balanced_start`]) over the scene's duration and held, the loads
/// started near the balancing position ([`crate::studies::criterion::ramp_outcome`]), where
/// the core's `RegimeTracker`, fed the same ramp, says "balancing" from history.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Arrived {
    /// Where the ramp started, rad/s.
    pub from: f64,
    /// What the loads did: "balancing", "gathering", "unsettled" or "coincident".
    pub simulated: &'static str,
    /// Final residual unbalance relative to the rotor's.
    pub residual_relative: f64,
}

impl SweepPoint {
    /// The core's class committed (balancing or gathering) and a judged simulation says
    /// otherwise (the ≠ of the tables): an unsettled or coincident run contradicts nothing.
    pub fn contradicts(&self) -> bool {
        matches!(self.regime_class, "balancing" | "gathering")
            && !matches!(self.regime_simulated, "unsettled" | "coincident")
            && !agrees(self.regime_class, self.regime_simulated)
    }
}

/// Whether a simulated outcome is the predicted regime: "balancing" is met by "balancing",
/// and, for a balancer too small for its rotor, by "saturated" (as balanced as it can be).
pub fn agrees(predicted: &str, simulated: &str) -> bool {
    predicted == simulated || (predicted == "balancing" && simulated == "saturated")
}

/// What to sweep: `steps` speeds from `from` to `to` rad/s (inclusive), the loads started
/// near the balancing position or, with `together`, together at rest.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepRequest {
    /// Lowest speed, rad/s.
    pub from: f64,
    /// Highest speed, rad/s.
    pub to: f64,
    /// Number of speeds.
    pub steps: usize,
    /// Start the loads together at rest.
    pub together: bool,
}

/// A whole sweep.
#[derive(Debug, Clone, Serialize)]
pub struct Sweep {
    /// The points, by ascending speed.
    pub points: Vec<SweepPoint>,
    /// Points outside the margin band around every damped characteristic speed (the
    /// criterion's boundaries).
    pub away_from_characteristic: usize,
    /// Of those, the points where the criterion and the simulation agree.
    pub agreeing: usize,
    /// Points where the core's classifier commits ("balancing" or "gathering").
    pub committed: usize,
    /// Of those, the points where the simulation agrees.
    pub committed_agreeing: usize,
    /// Points where no run settled ([`settled_run`]): neither agreeing nor disagreeing.
    pub unsettled: usize,
    /// Points where the loads met and moved as one where the balancing position is stable
    /// (`run`'s "coincident"): neither agreeing nor disagreeing.
    pub coincident: usize,
    /// Bistable points where the tracker commits from history ([`SweepPoint::arrived`]).
    pub history_committed: usize,
    /// Of those, where the loads brought there balanced stayed balanced.
    pub history_agreeing: usize,
    /// The classifier is built from the exact table (else from the criterion's).
    pub exact: bool,
    /// Tables of the scene the sweep does not use, each with why ([`not_used`]): it
    /// prescribes the rotor speed, so a torque motor, `[load]` and `[shaft]` move nothing.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_simulated: Vec<String>,
    /// What the sweep's models leave out of what the scene asks for, each a NOTE or WARNING
    /// (a cranking ripple: applied, and its ω̇ terms omitted,
    /// [`crate::app::run::cranking_warning`]).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// The damped characteristic speeds (the criterion's zone boundaries), rad/s.
    #[serde(skip)]
    pub boundaries: Vec<f64>,
    /// The classifier's table (from, to, regime name) for plotting.
    #[serde(skip)]
    pub zones: Vec<(f64, Option<f64>, &'static str)>,
    /// What was swept.
    #[serde(skip)]
    pub request: SweepRequest,
}

impl Sweep {
    /// Writes the regime map of the scene `name` (file `path`) into `dir` as
    /// `regimes-STEM.md` and `regimes-STEM.svg`, the page naming the command that regenerates
    /// it.
    pub fn publish(&self, name: &str, path: &Path, dir: &Path) -> Result<Vec<PathBuf>, String> {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let stem = crate::app::run::scene_stem(path);
        let SweepRequest {
            from,
            to,
            steps,
            together,
        } = self.request;
        let start = if together {
            "loads together at rest"
        } else {
            "near the balancing position"
        };
        let title = format!("{stem}: regimes and simulated outcome (start {start})");
        let svg = dir.join(format!("regimes-{stem}.svg"));
        self.write_svg(&svg, &title)?;
        let md = dir.join(format!("regimes-{stem}.md"));
        let text = format!(
            "# {title}\n\nRegenerated by `cargo run --release -p host-sim -- sweep {name} --from {from} --to {to} --steps {steps}{} --out {}`.\n\n![regime map](regimes-{stem}.svg)\n\n{}",
            if together { " --together" } else { "" },
            dir.display(),
            self.markdown()
        );
        std::fs::write(&md, text).map_err(|e| format!("{}: {e}", md.display()))?;
        Ok(vec![md, svg])
    }

    /// The regime map as a Markdown table, with the agreement lines.
    pub fn markdown(&self) -> String {
        use std::fmt::Write;
        let mut s = String::new();
        for why in &self.not_simulated {
            let _ = writeln!(s, "NOT SIMULATED {why}\n");
        }
        for w in &self.warnings {
            let _ = writeln!(s, "{w}\n");
        }
        s.push_str(
            "| speed, rad/s | criterion | core class | simulated | residual / rotor unbalance | reached balanced: from, rad/s → simulated |\n\
             |---:|---|---|---|---:|---|\n",
        );
        let speeds = crate::app::report::fmt_speeds_from(
            &self.points.iter().map(|p| p.speed).collect::<Vec<_>>(),
            2,
        );
        for (p, speed) in self.points.iter().zip(&speeds) {
            let _ = writeln!(
                s,
                "| {speed} | {} | {}{} | {}{} | {:.2e} | {} |",
                p.regime_predicted,
                p.regime_class,
                p.regime_reason.map_or(String::new(), |r| format!(" ({r})")),
                p.regime_simulated,
                if p.contradicts() { " ≠" } else { "" },
                p.residual_relative,
                p.arrived.map_or("—".to_string(), |a| format!(
                    "{:.1} → {}{}",
                    a.from,
                    a.simulated,
                    if a.simulated == "balancing" {
                        ""
                    } else {
                        " ≠"
                    }
                ))
            );
        }
        let _ = writeln!(
            s,
            "\nEach speed runs until its regime shows: at least ten e-foldings of the balancing \
             position's least stable perturbation (`10/|σ|` from the exact analysis, up to ten \
             times the scene's duration), doubled up to three times while the residual is \
             between 1 % and 10 % of the rotor's; {} speeds did not settle (\"unsettled\": \
             neither agreeing nor disagreeing, why in the JSON's `regime_unsettled`); at {} \
             the loads met and moved as one where the balancing position is stable \
             (\"coincident\": not judged, the model has no contact between loads; see `run`).\n\n\
             The core's classifier ({} table) commits at {} of {} speeds; the simulation \
             agrees at {} of them (≠ marks the others). The seed's criterion alone, away from \
             its characteristic speeds (outside the margin band): {} of {} speeds agree.\n\n\
             Reached with the loads balanced (the last column: the rotor ramped from inside a \
             `Balancing` segment of the table through segments where the balancing position \
             stays stable, over the scene's duration, then held), the core's `RegimeTracker` \
             also commits at {} bistable speeds, balancing from the loads' history, and the \
             loads stayed balanced at {} of them: {} of {} speeds committed with that history.",
            self.unsettled,
            self.coincident,
            if self.exact { "exact" } else { "criterion" },
            self.committed,
            self.points.len(),
            self.committed_agreeing,
            self.agreeing,
            self.away_from_characteristic,
            self.history_committed,
            self.history_agreeing,
            self.committed + self.history_committed,
            self.points.len()
        );
        s
    }

    /// The regime map as an SVG: zones along the speed axis, simulated outcomes as points
    /// (1 = balancing, 0 = gathering) with the final residual unbalance.
    pub fn write_svg(&self, path: &Path, title: &str) -> Result<(), String> {
        use crate::app::plot::{write_svg, Chart, Mark, Series};
        let top = self.points.last().map_or(1.0, |p| p.speed);
        let mut marks: Vec<Mark> = self
            .zones
            .iter()
            .filter(|(_, _, regime)| *regime != "bistable")
            .map(|&(from, to, regime)| {
                Mark::Band(
                    format!("core: {regime}"),
                    from,
                    to.unwrap_or(top * 2.0),
                    regime == "gathering",
                )
            })
            .collect();
        marks.extend(
            self.boundaries
                .iter()
                .map(|&b| Mark::VLine("criterion boundary".into(), b)),
        );
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

/// Longest run relative to the scene's duration that a slow growth or decay (`10/|σ|`) may
/// ask for before doubling.
const SETTLE_CAP: f64 = 10.0;
/// Times a run still between the thresholds is doubled.
const DOUBLINGS: u32 = 3;
/// Runs `scene` at `speed` until its regime shows: for at least the scene's duration and
/// `10/|σ|` (ten e-foldings of the least stable perturbation, `sigma` from the exact
/// analysis; at most [`SETTLE_CAP`] times the scene's duration), doubled up to
/// [`DOUBLINGS`] times while `run` says the loads have not settled (the residual between 1 %
/// and 10 % of the rotor's over the final quarter, unless it reached 10 % and swings there
/// steadily, or a balancing verdict from a run shorter than `10/σ` where the balancing
/// position is unstable). Returns the last run, its duration and whether it settled. A
/// fixed-length run judged a slowly growing residual still under 1 % as balancing, and a
/// slowly decaying one as gathering; a residual still at its starting offset, between the
/// two, stays unsettled however steady it is (an e-folding of 4700 s against 1600 s).
pub fn settled_run(
    scene: &Scene,
    file: &Path,
    speed: f64,
    together: bool,
    sigma: Option<f64>,
) -> Result<(crate::app::run::RunReport, f64, bool), SceneError> {
    let base = scene.simulation.duration;
    let mut s = scene.clone();
    s.simulation.duration = sigma.map_or(base, |g| settle_time(g).min(SETTLE_CAP * base).max(base));
    let mut k = 0;
    loop {
        let r = run(
            &s,
            file,
            Overrides {
                speed: Some(speed),
                loads_together: together,
            },
        )?;
        // `run` says "unsettled" when the residual lies between the thresholds, or when a
        // balancing verdict comes from a run shorter than `10/σ` where the balancing position
        // is unstable.
        let decided = r.regime_simulated != Some("unsettled");
        if decided || k == DOUBLINGS {
            return Ok((r, s.simulation.duration, decided));
        }
        s.simulation.duration *= 2.0;
        k += 1;
    }
}

/// Runs `scene` at the speeds of `request`, in parallel.
pub fn sweep(
    scene: &Scene,
    file: &Path,
    request: &SweepRequest,
    progress: bool,
) -> Result<Sweep, SceneError> {
    let SweepRequest {
        from,
        to,
        steps,
        together,
    } = *request;
    let bad = |key: &str, message: String| SceneError::value(file, key, message);
    let Some(machine) = predict::machine(scene, file)? else {
        return Err(bad(
            "platform",
            "missing: a sweep needs a vibration machine ([[platform]] and [autobalancer])".into(),
        ));
    };
    if !(from.is_finite() && to.is_finite() && from > 0.0 && to > from) {
        return Err(bad(
            "--from/--to",
            format!("need finite speeds 0 < from < to, got {from} and {to}"),
        ));
    }
    let max = crate::app::check::MAX_SPEED;
    if to > max {
        return Err(bad(
            "--to",
            format!("{to} rad/s: allowed up to {max:e} rad/s, as every speed of a scene is"),
        ));
    }
    if steps < 2 {
        return Err(bad(
            "--steps",
            format!("need at least 2 steps, got {steps}"),
        ));
    }
    // Each speed's settling time comes from a monodromy over its revolution (where the loads
    // can balance the rotor: an exact table): refused before the design's scan where that
    // cannot be integrated.
    if let Some(vm) = crate::app::regimes::vibration_machine(scene, file)? {
        if floquet::Floquet::new(&vm).is_ok() {
            let lowest = floquet::lowest_speed(&vm);
            if from < lowest {
                let fast = floquet::fastest_motion(&vm);
                return Err(bad(
                    "--from",
                    format!(
                        "{from:e} rad/s is below {lowest:.4e} rad/s, the lowest speed at which \
                         the stability analysis integrates a revolution of this machine: a \
                         revolution there lasts more than {} periods of {fast}; sweep from \
                         {lowest:.4e} rad/s or above",
                        floquet::REVOLUTION_RATIO
                    ),
                ));
            }
        }
    }
    let design = crate::app::regimes::design(scene, file, &machine)?;
    let (classifier, _, exact) =
        crate::app::regimes::classifier(scene, file, &machine, design.as_ref())?;
    // The sweep judges the loads, not δ: no encoder, so no edges to generate.
    let mut quiet = scene.clone();
    quiet.encoder = None;
    let exact_design = design.as_ref().and_then(|d| d.exact.as_ref());
    let segments: Vec<RegimeSegment> = classifier.segments().collect();
    let bar = progress_bar(steps, "speeds", progress);
    let points: Result<Vec<SweepPoint>, SceneError> = (0..steps)
        .into_par_iter()
        .map(|i| {
            let speed = from + (to - from) * i as f64 / (steps - 1) as f64;
            let sigma = match exact_design {
                Some(e) => growth_rate(&quiet, file, e, speed)?,
                None => None,
            };
            let (r, duration, settled) = settled_run(&quiet, file, speed, together, sigma)?;
            let class = classifier.classify(speed as f32);
            let arrived = match balanced_start(&segments, speed) {
                Some(start) if matches!(class, Regime::Bistable(_)) => {
                    let st = tracked(&classifier, start, speed);
                    if st.by_history {
                        let o = ramp_outcome(
                            &quiet,
                            file,
                            start,
                            speed,
                            quiet.simulation.duration,
                            false,
                        )?;
                        Some(Arrived {
                            from: start,
                            simulated: match (o.settled, o.balancing) {
                                (false, _) => "unsettled",
                                (true, true) => "balancing",
                                (true, false) => "gathering",
                            },
                            residual_relative: o.residual_relative,
                        })
                    } else {
                        None
                    }
                }
                _ => None,
            };
            bar.inc(1);
            Ok(SweepPoint {
                speed,
                regime_predicted: machine.zone_kind_at(speed).name(),
                regime_class: class.name(),
                regime_reason: class.reason().map(|r| r.name()),
                regime_simulated: if settled {
                    r.regime_simulated.unwrap_or("unknown")
                } else {
                    "unsettled"
                },
                regime_unsettled: r.regime_unsettled.clone(),
                residual_relative: r.residual_relative.unwrap_or(f64::NAN),
                duration,
                growth_rate: sigma,
                arrived,
            })
        })
        .collect();
    bar.finish_and_clear();
    let points = points?;
    let boundaries: Vec<f64> = machine.zones().iter().skip(1).map(|z| z.from).collect();
    let band = f64::from(DEFAULT_MARGIN);
    let away: Vec<&SweepPoint> = points
        .iter()
        .filter(|p| boundaries.iter().all(|&b| (p.speed - b).abs() > band * b))
        .collect();
    let committed: Vec<&SweepPoint> = points
        .iter()
        .filter(|p| p.regime_class == "balancing" || p.regime_class == "gathering")
        .collect();
    let zones = segments
        .iter()
        .enumerate()
        .map(|(k, seg)| {
            (
                f64::from(seg.from),
                segments.get(k + 1).map(|n| f64::from(n.from)),
                seg.regime.name(),
            )
        })
        .collect();
    Ok(Sweep {
        away_from_characteristic: away.len(),
        agreeing: away
            .iter()
            .filter(|p| agrees(p.regime_predicted, p.regime_simulated))
            .count(),
        committed: committed.len(),
        committed_agreeing: committed
            .iter()
            .filter(|p| agrees(p.regime_class, p.regime_simulated))
            .count(),
        unsettled: points
            .iter()
            .filter(|p| p.regime_simulated == "unsettled")
            .count(),
        coincident: points
            .iter()
            .filter(|p| p.regime_simulated == "coincident")
            .count(),
        history_committed: points.iter().filter(|p| p.arrived.is_some()).count(),
        history_agreeing: points
            .iter()
            .filter(|p| p.arrived.is_some_and(|a| a.simulated == "balancing"))
            .count(),
        exact,
        not_simulated: not_used(scene),
        warnings: sweep_warnings(scene),
        boundaries,
        zones,
        points,
        request: *request,
    })
}

/// The tables of `scene` a sweep leaves out, each with why: every speed of a sweep is
/// prescribed, so a motor's own speed law or torque curve, the load torque and the shaft's
/// inertia (and the vibration machine's reaction torque on it) move nothing. A `speed` motor's
/// speed is what the sweep replaces by design: not listed.
pub fn not_used(scene: &Scene) -> Vec<String> {
    use crate::app::scene::MotorSpec;
    let by = "the sweep prescribes the rotor speed at each of its speeds";
    let drive = "`drive-sim run` simulates the drive";
    let mut out = Vec::new();
    let motor = match &scene.motor {
        Some(MotorSpec::Parabola { .. }) => Some((
            "parabola",
            "its torque curve moves nothing (no slip under the load or the machine's reaction torque)",
        )),
        Some(MotorSpec::Kloss { .. }) => Some((
            "kloss",
            "its torque curve moves nothing (no slip under the load or the machine's reaction torque)",
        )),
        Some(MotorSpec::Ramp { .. }) => Some(("ramp", "its ramp is not followed")),
        Some(MotorSpec::Profile { .. }) => Some(("profile", "its speed profile is not followed")),
        Some(MotorSpec::Speed { .. }) | None => None,
    };
    if let Some((model, what)) = motor {
        out.push(format!(
            "[motor] model = \"{model}\": {by}, so {what}; {drive}"
        ));
    }
    if scene.load.is_some() {
        out.push(format!(
            "[load]: {by}, so its torque and ripple move nothing; {drive}"
        ));
    }
    if scene.shaft.is_some() {
        out.push(format!(
            "[shaft]: {by}, so its inertia moves nothing; {drive}"
        ));
    }
    if scene.rotor.is_some() {
        out.push(
            "[rotor] (its [[unbalance]] and [process_load]): the sweep judges the balancer's \
             regime only, not the rotor's supports; `drive-sim predict` and `drive-sim run` \
             report them"
                .to_string(),
        );
    }
    out
}

/// The NOTE and WARNING lines of a sweep: a `[cranking]` ripple is applied at every speed
/// (the mean speed the sweep's), and its ω̇ terms are left out of the vibration machine's
/// model ([`crate::app::run::cranking_warning`]).
pub fn sweep_warnings(scene: &Scene) -> Vec<String> {
    let mut out = Vec::new();
    if let Some(c) = scene.cranking.filter(|c| c.ripple > 0.0) {
        out.push(format!(
            "NOTE: [cranking] is applied: each speed of the sweep is the ω̄ of a prescribed \
             speed ω̄·(1 + {}·sin({}·φ + {})), as in `drive-sim run`",
            c.ripple, c.strokes, c.phase
        ));
    }
    out.extend(crate::app::run::cranking_warning(scene));
    out
}
