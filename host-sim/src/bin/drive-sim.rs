//! `drive-sim`: run, predict and sweep scenes.

use clap::{Parser, Subcommand};
use host_sim::app::analyze::{Channel, FramingArg, Lead, Polarity};
use host_sim::app::logic::CaptureFormat;
use host_sim::app::predict::predict;
use host_sim::app::scene::{resolve, BUNDLED, DEFAULT_SCENE};
use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "drive-sim",
    version,
    about = "Simulate machines from scene files and run the drive-monitor core on their encoder edges"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
// (Parsed once: analyze's whole numbers are held wide so that their range can be said.)
#[allow(clippy::large_enum_variant)]
enum Command {
    /// Simulate a scene, feed its encoder edges to the core, report.
    Run {
        /// The name of a bundled scene (`drive-sim scenes`), or a scene file's path.
        scene: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write SVG plots into this directory.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Write the capture page of a run-up (loads together, a prescribed ramp or a motor)
        /// into this directory: Markdown and SVGs, the scene repeated at slower and faster
        /// ramps.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Write the encoder signal (and the index channel, if any) as a logic analyzer
        /// records it: levels over time (the scene's [capture] settings). A sample_rate that
        /// takes fewer than 2 samples of the shortest pulse at the speed the scene prescribes
        /// or starts at is refused; level changes lost to the sampling later in the run are
        /// counted in a WARNING.
        #[arg(long)]
        capture: Option<PathBuf>,
        /// Format of the capture file (default: the file's extension: .vcd a value change
        /// dump, .csv or any other Saleae's CSV). A format the extension contradicts (saleae,
        /// sigrok or plain to a .vcd file, vcd to a .csv file) is refused, and so are sr and
        /// a .sr file (a sigrok session file, which analyze reads).
        #[arg(long, value_enum, requires = "capture")]
        capture_format: Option<CaptureFormat>,
        /// The largest capture file to write, bytes (default 1e9): a sigrok file of every
        /// sample (no [capture] dedup) estimated larger is refused before the run, with the
        /// estimate and what makes it smaller.
        #[arg(long, requires = "capture")]
        capture_max_bytes: Option<f64>,
    },
    /// Run the core on a recorded capture (Saleae Logic 2 or 1.x, sigrok/PulseView or plain CSV, a
    /// sigrok session file (.sr), Saleae Logic 2's binary export (its folder, or one channel's
    /// file), a value change dump, or a file of edge times):
    /// windows, faults, sync, edges and revolutions counted.
    Analyze {
        /// The capture file (or the folder of Saleae Logic 2's binary export).
        capture: PathBuf,
        /// Its format (default: told from its first lines; a zip archive is a sigrok session
        /// file, sr; a folder, or a file starting <SALEAE>, Saleae's binary export).
        #[arg(long, value_enum)]
        format: Option<CaptureFormat>,
        #[command(flatten)]
        options: AnalyzeArgs,
        /// The logic analyzer's samples per second, Hz. A sigrok file (CSV or .sr) states it, and so does a
        /// value change dump from sigrok (needed for a sigrok CSV that does not: its time
        /// column alone is not exact; it must agree with the file when it states one); a
        /// Saleae Logic 1.x export with sample numbers for times needs it (sample n is at
        /// n / rate s); for any format it widens the windows' noise floor by the sampling's
        /// resolution (a time is known to one sample period besides the timer's tick).
        #[arg(long, allow_negative_numbers = true)]
        sample_rate: Option<f64>,
        /// The unit of the times of a file of edge times or a plain CSV (default seconds, or
        /// the unit its header names: `time_ms`, `time_us`; a header naming another unit than
        /// the option is refused). Other formats state their unit, and it is refused for them.
        #[arg(long, value_enum)]
        time_unit: Option<host_sim::app::logic::TimeUnit>,
        /// Read the channels' columns as values (an oscilloscope's or an analog channel's CSV
        /// export, e.g. a variable-reluctance crank sensor's voltage), levels through a Schmitt
        /// trigger at this value: high above it plus half the hysteresis, low below it less
        /// half, between them as before. CSV formats only.
        #[arg(long, allow_negative_numbers = true)]
        threshold: Option<f64>,
        /// The band around --threshold (same unit, default 0): wider than the signal's noise,
        /// or each noisy crossing is a glitch.
        #[arg(long, requires = "threshold", allow_negative_numbers = true)]
        hysteresis: Option<f64>,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write SVG plots (speed, δ per window) into this directory.
        #[arg(long)]
        plot: Option<PathBuf>,
    },
    /// Design-time results only (no simulation): predicted δ, support limits, regime zones.
    Predict {
        /// The name of a bundled scene (`drive-sim scenes`), or a scene file's path.
        scene: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write the auto-balancer machine's speeds, zones and capture windows as source for
        /// firmware instead (rust: a `const` MachineTable).
        #[arg(long, value_enum, conflicts_with = "json")]
        emit: Option<host_sim::app::emit::Format>,
        /// With --emit: write to this file instead of standard output.
        #[arg(long, requires = "emit")]
        out: Option<std::path::PathBuf>,
    },
    /// Run a vibration-machine scene at prescribed rotor speeds from A to B rad/s, in
    /// parallel: the criterion's regime against what the loads did.
    ///
    /// Each speed runs at least the scene's duration and 10/|σ| (σ the balancing position's
    /// Floquet growth rate; at most ten times the duration), doubled up to three times while
    /// the residual unbalance is between 1 % (balancing) and 10 % (gathering) of the
    /// rotor's. A speed still between them is "unsettled": counted neither agreeing nor
    /// disagreeing, its reason in the JSON's `regime_unsettled`.
    Sweep {
        /// The name of a bundled scene (`drive-sim scenes`), or a scene file's path.
        scene: String,
        /// Lowest speed, rad/s.
        #[arg(long, allow_negative_numbers = true)]
        from: f64,
        /// Highest speed, rad/s.
        #[arg(long, allow_negative_numbers = true)]
        to: f64,
        /// Number of speeds (2 to 1000).
        #[arg(long, default_value_t = 20, value_parser = sweep_steps, allow_negative_numbers = true)]
        steps: usize,
        /// Start the loads together at rest instead of near the balancing position.
        #[arg(long)]
        together: bool,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write the regime map (Markdown table and SVG) into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Check the auto-balancing criterion of seed paper 001 against simulation on randomised
    /// machines (drawn by --seed): agreement, simulated boundary shifts and the margin band
    /// they need.
    Criterion {
        /// Number of machines (platforms cycle 1, 2, 3; 1 to 1000).
        #[arg(
            long,
            default_value_t = 30,
            value_parser = criterion_machines,
            allow_negative_numbers = true
        )]
        machines: usize,
        /// Seed of the draws.
        #[arg(long, default_value_t = 1, value_parser = seed, allow_negative_numbers = true)]
        seed: u64,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write the report (Markdown and SVG) into this directory.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Measure what accuracy costs and write Markdown tables and SVG plots into a directory.
    Accuracy {
        /// Output directory (e.g. docs/).
        #[arg(long, default_value = "docs")]
        out: PathBuf,
        /// Also build and run the firmware under QEMU (needs the thumbv7em target and
        /// qemu-system-arm) and include its instruction counts.
        #[arg(long)]
        target: bool,
    },
    /// List the bundled scenes.
    Scenes,
}

/// The options of `analyze` that describe the encoder, the core's settings and the channels
/// (`AnalyzeOptions` once `--scene` is read).
#[derive(clap::Args)]
struct AnalyzeArgs {
    /// The encoder channel: its name in the header, or its number among the channels
    /// (from 0; refused when another channel's name carries that number, e.g. `3` on an
    /// export of `Channel 1` to `Channel 4`: give the name then).
    #[arg(long, default_value = "0")]
    channel: Channel,
    /// The index channel of an index disc (default: channel 1).
    #[arg(long)]
    index_channel: Option<Channel>,
    /// The quadrature B channel: its level at each edge of --channel gives the edge's
    /// direction, so a reversal is seen (without it every edge counts as forward).
    #[arg(long)]
    direction_channel: Option<Channel>,
    /// Which channel leads when the shaft runs forward (with --direction-channel; default A
    /// leads). A capture that runs backward a pitch at a time for most of its edges is said
    /// to, with the --forward that reads it as forward.
    #[arg(long, value_enum)]
    forward: Option<Lead>,
    /// The edges the capture unit takes (default rising; not with a file of edge times, whose
    /// rows are the edges taken).
    #[arg(long, value_enum)]
    edge: Option<Polarity>,
    /// A missing-tooth wheel, "N-M" (e.g. 36-2, 60-2, 8-1).
    #[arg(long)]
    wheel: Option<String>,
    /// A uniform disc of N lines (framed as --framing says).
    #[arg(long, allow_negative_numbers = true)]
    lines: Option<i128>,
    /// How the uniform disc of --lines is framed (default none: no index channel is read, as
    /// a capture need not have one, and the report says so; a scene's [encoder] lines = N is
    /// framed by its index).
    #[arg(long, value_enum)]
    framing: Option<FramingArg>,
    /// Take the wheel, the timer, the tolerances and the window from a scene's [encoder]
    /// and [monitor] (a bundled scene's name or a file).
    #[arg(long)]
    scene: Option<String>,
    /// The emulated capture timer clock, Hz (default 1e6, or the scene's).
    #[arg(long, allow_negative_numbers = true)]
    timer_hz: Option<f64>,
    /// The emulated counter width, bits (16 to 32; default 32, or the scene's).
    #[arg(long, allow_negative_numbers = true)]
    counter_bits: Option<i128>,
    /// The emulated capture's input prescaler: one capture every 1, 2, 4 or 8 edges of the
    /// channel, as a timer's input prescaler takes them (default 1, or the scene's; a uniform
    /// disc only, whose lines it divides).
    #[arg(long, allow_negative_numbers = true)]
    prescaler: Option<i128>,
    /// Slowest speed still running, rad/s (default 1, or the scene's).
    #[arg(long, allow_negative_numbers = true)]
    min_speed: Option<f64>,
    /// Captured edges per speed sample (with --prescaler P each capture spans P lines;
    /// default 1, or the scene's).
    #[arg(long, allow_negative_numbers = true)]
    estimator_edges: Option<i128>,
    /// Revolutions per δ window (default 1, or the scene's).
    #[arg(long, allow_negative_numbers = true)]
    window_revolutions: Option<i128>,
}

impl AnalyzeArgs {
    /// The options, with `--scene` resolved and read.
    fn resolve(self) -> Result<host_sim::app::analyze::AnalyzeOptions, Failure> {
        let scene = match self.scene {
            Some(name) => Some(resolve(&name)?),
            None => None,
        };
        Ok(host_sim::app::analyze::AnalyzeOptions {
            wheel: self.wheel,
            lines: narrow("--lines", self.lines)?,
            framing: self.framing,
            scene,
            timer_hz: self.timer_hz,
            counter_bits: narrow("--counter-bits", self.counter_bits)?,
            prescaler: narrow("--prescaler", self.prescaler)?,
            min_speed: self.min_speed,
            estimator_edges: narrow("--estimator-edges", self.estimator_edges)?,
            window_revolutions: narrow("--window-revolutions", self.window_revolutions)?,
            channel: Some(self.channel),
            index_channel: self.index_channel,
            direction_channel: self.direction_channel,
            forward: self.forward,
            edge: self.edge,
        })
    }
}

/// A whole number given to `option`, in the type the analysis holds it in. The command line
/// reads it wider, so that one beyond that type (`--window-revolutions 70000`) or negative is
/// refused with the option's range as `analyze` words it, not the type's (0 to 65535).
fn narrow<T: TryFrom<i128>>(option: &str, n: Option<i128>) -> Result<Option<T>, Failure> {
    n.map(|n| {
        T::try_from(n).map_err(|_| {
            Failure::Message(
                host_sim::app::analyze::out_of_range(option, &n.to_string())
                    .unwrap_or_else(|| format!("{option} {n} is out of range")),
            )
        })
    })
    .transpose()
}

/// Most speeds `sweep --steps` accepts (each is a whole simulation of the scene).
const MAX_SWEEP_STEPS: usize = 1000;
/// Most machines `criterion --machines` accepts (each is a grid of simulations).
const MAX_CRITERION_MACHINES: usize = 1000;

/// `--steps`: 2 to [`MAX_SWEEP_STEPS`].
fn sweep_steps(text: &str) -> Result<usize, String> {
    bounded(text, 2, MAX_SWEEP_STEPS)
}

/// `--machines`: 1 to [`MAX_CRITERION_MACHINES`].
fn criterion_machines(text: &str) -> Result<usize, String> {
    bounded(text, 1, MAX_CRITERION_MACHINES)
}

/// `--seed`: 0 to 2^64 − 1.
fn seed(text: &str) -> Result<u64, String> {
    bounded(text, 0, u64::MAX)
}

/// A whole number from `min` to `max`.
fn bounded<T>(text: &str, min: T, max: T) -> Result<T, String>
where
    T: TryFrom<i128> + PartialOrd + std::fmt::Display,
{
    // (Signed: a negative count is out of the range, not "an invalid digit".)
    let n: i128 = text
        .trim()
        .parse()
        .map_err(|e| format!("not a whole number ({e}); allowed {min} to {max}"))?;
    match T::try_from(n) {
        Ok(n) if min <= n && n <= max => Ok(n),
        _ => Err(format!("allowed {min} to {max}")),
    }
}

/// Why a command failed.
enum Failure {
    /// A message for stderr.
    Message(String),
    /// Whoever read stdout has gone (`| head`): end quietly.
    BrokenPipe,
}

impl From<String> for Failure {
    fn from(m: String) -> Self {
        Failure::Message(m)
    }
}

impl From<host_sim::app::scene::SceneError> for Failure {
    fn from(e: host_sim::app::scene::SceneError) -> Self {
        Failure::Message(e.to_string())
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => run_cmd(DEFAULT_SCENE, false, None, None, None, None),
        Some(Command::Run {
            scene,
            json,
            plot,
            out,
            capture,
            capture_format,
            capture_max_bytes,
        }) => (|| {
            let capture = match capture {
                Some(path) => Some(host_sim::app::run::CaptureTarget {
                    format: CaptureFormat::for_file(&path, capture_format)?,
                    path,
                }),
                None => None,
            };
            run_cmd(
                &scene,
                json,
                plot.as_deref(),
                out.as_deref(),
                capture,
                capture_max_bytes,
            )
        })(),
        Some(Command::Analyze {
            capture,
            format,
            options,
            sample_rate,
            time_unit,
            threshold,
            hysteresis,
            json,
            plot,
        }) => (|| {
            let options = options.resolve()?;
            let threshold = threshold
                .map(|v| host_sim::app::logic::Threshold::new(v, hysteresis.unwrap_or(0.0)))
                .transpose()?;
            analyze_cmd(
                &capture,
                (format, time_unit),
                sample_rate,
                threshold,
                &options,
                json,
                plot.as_deref(),
            )
        })(),
        Some(Command::Predict {
            scene,
            emit: Some(format),
            out,
            ..
        }) => emit_cmd(&scene, format, out.as_deref()),
        Some(Command::Predict { scene, json, .. }) => predict_cmd(&scene, json),
        Some(Command::Sweep {
            scene,
            from,
            to,
            steps,
            together,
            json,
            out,
        }) => sweep_cmd(&scene, from, to, steps, together, json, out.as_deref()),
        Some(Command::Criterion {
            machines,
            seed,
            json,
            out,
        }) => criterion_cmd(machines, seed, json, out.as_deref()),
        Some(Command::Accuracy { out, target }) => accuracy_cmd(&out, target),
        Some(Command::Scenes) => {
            let mut text = String::new();
            for (file, body) in BUNDLED {
                let name = file.strip_suffix(".toml").unwrap_or(file);
                let desc = body
                    .lines()
                    .find_map(|l| l.strip_prefix("description = "))
                    .unwrap_or("")
                    .trim_matches('"');
                text.push_str(&format!("{name:<22} {desc}\n"));
            }
            write_out(&text)
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(Failure::BrokenPipe) => ExitCode::FAILURE,
        Err(Failure::Message(e)) => {
            // stderr may be gone too: nothing more to do then.
            let _ = writeln!(std::io::stderr(), "drive-sim: {e}");
            ExitCode::FAILURE
        }
    }
}

/// Writes `text` to stdout and flushes: a reader that has gone is [`Failure::BrokenPipe`], any
/// other error (a full disk) a message naming it.
fn write_out(text: &str) -> Result<(), Failure> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::BrokenPipe => Failure::BrokenPipe,
            _ => Failure::Message(format!("cannot write the output: {e}")),
        })
}

/// Checks before any work that `dir` (for `option`) is, or can be made, a writable directory.
fn writable_dir(option: &str, dir: &Path) -> Result<(), Failure> {
    let fail = |why: String| Failure::Message(format!("{option} {}: {why}", dir.display()));
    if dir.exists() && !dir.is_dir() {
        return Err(fail("exists and is not a directory".into()));
    }
    std::fs::create_dir_all(dir).map_err(|e| fail(format!("cannot create the directory: {e}")))?;
    let probe = dir.join(format!(".drive-sim-probe-{}", std::process::id()));
    std::fs::write(&probe, b"").map_err(|e| fail(format!("cannot write into it: {e}")))?;
    // The probe is ours; failing to remove it is not worth failing the command.
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

fn analyze_cmd(
    capture: &Path,
    (format, time_unit): (
        Option<CaptureFormat>,
        Option<host_sim::app::logic::TimeUnit>,
    ),
    sample_rate: Option<f64>,
    threshold: Option<host_sim::app::logic::Threshold>,
    options: &host_sim::app::analyze::AnalyzeOptions,
    json: bool,
    plot: Option<&Path>,
) -> Result<(), Failure> {
    use host_sim::app::analyze;
    if let Some(r) = sample_rate {
        if !(r.is_finite() && (1.0..=1e12).contains(&r)) {
            return Err(Failure::Message(format!(
                "--sample-rate {}: allowed 1 to 1e12 Hz",
                analyze::fmt_number(r)
            )));
        }
    }
    let cfg = analyze::configure(options)?;
    if let Some(dir) = plot {
        writable_dir("--plot", dir)?;
    }
    let mut reader =
        host_sim::app::logic::CaptureReader::open_with(capture, format, sample_rate, time_unit)
            .map_err(|e| e.to_string())?;
    if let Some(t) = threshold {
        reader.set_threshold(t).map_err(|e| e.to_string())?;
    }
    let mut report = analyze::analyze(&mut reader, &cfg, &mut |_| {}).map_err(|e| e.to_string())?;
    report.file = capture.display().to_string();
    let mut text = String::new();
    if let Some(dir) = plot {
        let stem = capture
            .file_stem()
            .and_then(|s| s.to_str())
            .unwrap_or("capture");
        let files = analyze::plots(&report, stem, dir)?;
        if !json {
            text.push_str(&list(&files, "plot:"));
        }
    }
    if json {
        text.push_str(&to_json(&report)?);
    } else {
        text.push_str(&analyze::text(&report));
    }
    write_out(&text)
}

fn run_cmd(
    name: &str,
    json: bool,
    plot: Option<&Path>,
    out: Option<&Path>,
    capture: Option<host_sim::app::run::CaptureTarget>,
    capture_max_bytes: Option<f64>,
) -> Result<(), Failure> {
    let (scene, path) = resolve(name)?;
    if let Some(dir) = plot {
        writable_dir("--plot", dir)?;
    }
    if let Some(dir) = out {
        writable_dir("--out", dir)?;
    }
    let options = host_sim::app::run::RunOptions {
        progress: !json,
        keep_windows: plot.is_some(),
        capture,
        keep_edges: false,
        capture_max_bytes: capture_max_bytes.unwrap_or(host_sim::app::run::CAPTURE_MAX_BYTES),
    };
    let report = host_sim::app::run::run_with(&scene, &path, Default::default(), options)?;
    let mut text = String::new();
    if let (Some(f), Some(rows), false) = (&report.capture_file, report.capture_rows, json) {
        text.push_str(&format!("capture: wrote {f} ({rows} rows)\n"));
        if let Some(w) = &report.capture_warning {
            text.push_str(&format!("{w}\n"));
        }
    }
    if let Some(dir) = out {
        let files = host_sim::studies::runup::publish(name, &scene, &path, &report, dir)?;
        if !json {
            text.push_str(&list(&files, "wrote"));
        }
    }
    if let Some(dir) = plot {
        let files = host_sim::app::report::run_plots(&scene, &path, &report, dir)?;
        if !json {
            text.push_str(&list(&files, "plot:"));
        }
    }
    if json {
        text.push_str(&to_json(&report)?);
    } else {
        let p = predict(&scene, &path)?;
        text.push_str(&host_sim::app::report::run_text(&scene, &report));
        text.push_str(&host_sim::app::report::prediction_text(&p));
    }
    write_out(&text)
}

fn sweep_cmd(
    name: &str,
    from: f64,
    to: f64,
    steps: usize,
    together: bool,
    json: bool,
    out: Option<&Path>,
) -> Result<(), Failure> {
    let (scene, path) = resolve(name)?;
    if let Some(dir) = out {
        writable_dir("--out", dir)?;
    }
    let request = host_sim::studies::sweep::SweepRequest {
        from,
        to,
        steps,
        together,
    };
    let s = host_sim::studies::sweep::sweep(&scene, &path, &request, !json)?;
    let mut text = String::new();
    if let Some(dir) = out {
        let files = s.publish(name, &path, dir)?;
        if !json {
            text.push_str(&list(&files, "wrote"));
        }
    }
    if json {
        text.push_str(&to_json(&s)?);
    } else {
        for why in &s.not_simulated {
            text.push_str(&format!("NOT SIMULATED {why}\n"));
        }
        for w in &s.warnings {
            text.push_str(&format!("{w}\n"));
        }
        text.push_str(&format!(
            "{:>10}  {:<10} {:<32} {:<10} {:>10}\n",
            "speed", "criterion", "core class", "simulated", "residual"
        ));
        let speeds = host_sim::app::report::fmt_speeds(
            &s.points.iter().map(|p| p.speed).collect::<Vec<_>>(),
        );
        for (p, speed) in s.points.iter().zip(&speeds) {
            let mark = if p.contradicts() { "  ≠" } else { "" };
            let class = match p.regime_reason {
                Some(r) => format!("{} ({r})", p.regime_class),
                None => p.regime_class.to_string(),
            };
            // No settled regime in the simulation: no residual to show.
            let residual = if p.residual_relative.is_finite() {
                format!("{:.2e}", p.residual_relative)
            } else {
                "–".to_string()
            };
            text.push_str(&format!(
                "{speed:>10}  {:<10} {:<32} {:<10} {:>10}{mark}\n",
                p.regime_predicted, class, p.regime_simulated, residual
            ));
        }
        text.push_str(&format!(
            "core ({} table) commits at {} of {} speeds, the simulation agrees at {}; the criterion alone agrees at {} of {} speeds away from its characteristic speeds\n",
            if s.exact { "exact" } else { "criterion" },
            s.committed,
            s.points.len(),
            s.committed_agreeing,
            s.agreeing,
            s.away_from_characteristic
        ));
        // Runs without a verdict are left out of both counts, and said so.
        if s.unsettled + s.coincident > 0 {
            text.push_str(&format!(
                "not judged, in neither count: {} unsettled (the longest run showed no regime; why in --json's regime_unsettled), {} coincident\n",
                s.unsettled, s.coincident
            ));
        }
    }
    write_out(&text)
}

fn criterion_cmd(
    machines: usize,
    seed: u64,
    json: bool,
    out: Option<&Path>,
) -> Result<(), Failure> {
    if let Some(dir) = out {
        writable_dir("--out", dir)?;
    }
    let s = host_sim::studies::criterion::study(seed, machines, !json)?;
    let mut text = String::new();
    if let Some(dir) = out {
        let files = host_sim::studies::criterion::publish(&s, dir)?;
        if !json {
            text.push_str(&list(&files, "wrote"));
        }
    }
    if json {
        text.push_str(&to_json(&s)?);
    } else {
        text.push_str(&host_sim::studies::criterion::summary_text(&s));
    }
    write_out(&text)
}

fn accuracy_cmd(out: &Path, target: bool) -> Result<(), Failure> {
    writable_dir("--out", out)?;
    let files = host_sim::studies::publish::accuracy(out, target)?;
    write_out(&list(&files, "wrote"))
}

/// The machine's table as Rust source, to `out` or stdout.
fn emit_cmd(
    name: &str,
    format: host_sim::app::emit::Format,
    out: Option<&Path>,
) -> Result<(), Failure> {
    let text = host_sim::app::emit::emit_text(name, format).map_err(|e| e.to_string())?;
    match out {
        Some(file) => std::fs::write(file, text)
            .map_err(|e| Failure::Message(format!("--out {}: cannot write: {e}", file.display()))),
        None => write_out(&text),
    }
}

fn predict_cmd(name: &str, json: bool) -> Result<(), Failure> {
    let (scene, path) = resolve(name)?;
    let p = predict(&scene, &path)?;
    if p.is_empty() {
        use host_sim::app::scene::MotorSpec;
        // A prescribed speed has no torque balance: its [load] and [shaft] give no δ.
        let prescribed = match &scene.motor {
            Some(MotorSpec::Speed { .. }) => Some("speed"),
            Some(MotorSpec::Ramp { .. }) => Some("ramp"),
            Some(MotorSpec::Profile { .. }) => Some("profile"),
            _ => None,
        };
        let why = match prescribed {
            Some(model) => format!(
                " ([motor] model = \"{model}\" prescribes the speed, so no δ follows from a \
                 load; a torque model, \"parabola\" or \"kloss\", does)"
            ),
            None => String::new(),
        };
        return Err(Failure::Message(format!(
            "{}: nothing to predict: the scene has no torque motor ([motor] model = \"parabola\" \
             or \"kloss\") with [load] and [shaft], no [rotor] and no [[platform]] with \
             [autobalancer]{why}",
            path.display()
        )));
    }
    if json {
        write_out(&to_json(&p)?)
    } else {
        write_out(&format!("{}\n", host_sim::app::report::prediction_text(&p)))
    }
}

/// `value` as pretty JSON with a final newline.
fn to_json<T: serde::Serialize>(value: &T) -> Result<String, Failure> {
    let text = serde_json::to_string_pretty(value).map_err(|e| e.to_string())?;
    Ok(text + "\n")
}

/// One line per file written: `what path`.
fn list(files: &[PathBuf], what: &str) -> String {
    files
        .iter()
        .map(|f| format!("{what} {}\n", f.display()))
        .collect()
}
