//! `drive-sim`: run, predict and sweep scenes.

use clap::{Parser, Subcommand};
use host_sim::app::predict::predict;
use host_sim::app::scene::{resolve, BUNDLED, DEFAULT_SCENE};
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
enum Command {
    /// Simulate a scene, feed its encoder edges to the core, report.
    Run {
        /// Scene file, or the name of a bundled scene.
        scene: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write SVG plots into this directory.
        #[arg(long)]
        plot: Option<std::path::PathBuf>,
        /// Write the capture page of a run-up (loads together, prescribed ramp) into this
        /// directory: Markdown and SVGs, the scene repeated at slower and faster ramps.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
    },
    /// Design-time results only (no simulation): predicted δ, support limits, regime zones.
    Predict {
        /// Scene file, or the name of a bundled scene.
        scene: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// Run a vibration-machine scene at prescribed rotor speeds from A to B rad/s, in
    /// parallel: the criterion's regime against what the loads did.
    Sweep {
        /// Scene file, or the name of a bundled scene.
        scene: String,
        /// Lowest speed, rad/s.
        #[arg(long)]
        from: f64,
        /// Highest speed, rad/s.
        #[arg(long)]
        to: f64,
        /// Number of speeds.
        #[arg(long, default_value_t = 20)]
        steps: usize,
        /// Start the loads together at rest instead of near the balancing position.
        #[arg(long)]
        together: bool,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write the regime map (Markdown table and SVG) into this directory.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
    },
    /// Check the auto-balancing criterion against simulation on randomised machines (seed 001):
    /// agreement, simulated boundary shifts and the margin band they need.
    Criterion {
        /// Number of machines (platforms cycle 1, 2, 3).
        #[arg(long, default_value_t = 30)]
        machines: usize,
        /// Seed of the draws.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Print JSON.
        #[arg(long)]
        json: bool,
        /// Write the report (Markdown and SVG) into this directory.
        #[arg(long)]
        out: Option<std::path::PathBuf>,
    },
    /// Measure what accuracy costs and write Markdown tables and SVG plots into a directory.
    Accuracy {
        /// Output directory (e.g. docs/).
        #[arg(long, default_value = "docs")]
        out: std::path::PathBuf,
        /// Also build and run the firmware under QEMU (needs the thumbv7em target and
        /// qemu-system-arm) and include its instruction counts.
        #[arg(long)]
        target: bool,
    },
    /// List the bundled scenes.
    Scenes,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => run_cmd(DEFAULT_SCENE, false, None, None),
        Some(Command::Run {
            scene,
            json,
            plot,
            out,
        }) => run_cmd(&scene, json, plot.as_deref(), out.as_deref()),
        Some(Command::Predict { scene, json }) => predict_cmd(&scene, json),
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
        Some(Command::Accuracy { out, target }) => {
            host_sim::studies::publish::accuracy(&out, target).map(|files| list(&files, "wrote"))
        }
        Some(Command::Scenes) => {
            for (name, text) in BUNDLED {
                let desc = text
                    .lines()
                    .find_map(|l| l.strip_prefix("description = "))
                    .unwrap_or("")
                    .trim_matches('"');
                println!("{name:<22} {desc}");
            }
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("drive-sim: {e}");
            ExitCode::FAILURE
        }
    }
}

fn run_cmd(
    name: &str,
    json: bool,
    plot: Option<&std::path::Path>,
    out: Option<&std::path::Path>,
) -> Result<(), String> {
    let (scene, path) = resolve(name).map_err(|e| e.to_string())?;
    let report =
        host_sim::app::run::run(&scene, &path, Default::default()).map_err(|e| e.to_string())?;
    if let Some(dir) = out {
        let files = host_sim::studies::runup::publish(name, &scene, &path, &report, dir)?;
        if !json {
            list(&files, "wrote");
        }
    }
    if let Some(dir) = plot {
        let files = host_sim::app::report::run_plots(&scene, &path, &report, dir)?;
        if !json {
            list(&files, "plot:");
        }
    }
    if json {
        print_json(&report)?;
    } else {
        let p = predict(&scene, &path).map_err(|e| e.to_string())?;
        print!("{}", host_sim::app::report::run_text(&scene, &report));
        print!("{}", host_sim::app::report::prediction_text(&p));
    }
    Ok(())
}

fn sweep_cmd(
    name: &str,
    from: f64,
    to: f64,
    steps: usize,
    together: bool,
    json: bool,
    out: Option<&std::path::Path>,
) -> Result<(), String> {
    let (scene, path) = resolve(name).map_err(|e| e.to_string())?;
    let request = host_sim::studies::sweep::SweepRequest {
        from,
        to,
        steps,
        together,
    };
    let s = host_sim::studies::sweep::sweep(&scene, &path, &request, true)
        .map_err(|e| e.to_string())?;
    if let Some(dir) = out {
        let files = s.publish(name, &path, dir)?;
        if !json {
            list(&files, "wrote");
        }
    }
    if json {
        print_json(&s)?;
    } else {
        println!(
            "{:>10}  {:<10} {:<32} {:<10} {:>10}",
            "speed", "criterion", "core class", "simulated", "residual"
        );
        for p in &s.points {
            let committed = p.regime_class == "balancing" || p.regime_class == "gathering";
            let mark = if committed
                && !host_sim::studies::sweep::agrees(p.regime_class, p.regime_simulated)
            {
                "  ≠"
            } else {
                ""
            };
            let class = match p.regime_reason {
                Some(r) => format!("{} ({r})", p.regime_class),
                None => p.regime_class.to_string(),
            };
            println!(
                "{:>10.3}  {:<10} {:<32} {:<10} {:>10.2e}{mark}",
                p.speed, p.regime_predicted, class, p.regime_simulated, p.residual_relative
            );
        }
        println!(
            "core ({} table) commits at {} of {} speeds, the simulation agrees at {}; the criterion alone agrees at {} of {} speeds away from its characteristic speeds",
            if s.exact { "exact" } else { "criterion" },
            s.committed,
            s.points.len(),
            s.committed_agreeing,
            s.agreeing,
            s.away_from_characteristic
        );
    }
    Ok(())
}

fn criterion_cmd(
    machines: usize,
    seed: u64,
    json: bool,
    out: Option<&std::path::Path>,
) -> Result<(), String> {
    let s = host_sim::studies::criterion::study(seed, machines, true).map_err(|e| e.to_string())?;
    if let Some(dir) = out {
        let files = host_sim::studies::criterion::publish(&s, dir)?;
        if !json {
            list(&files, "wrote");
        }
    }
    if json {
        print_json(&s)?;
    } else {
        print!("{}", host_sim::studies::criterion::summary_text(&s));
    }
    Ok(())
}

fn predict_cmd(name: &str, json: bool) -> Result<(), String> {
    let (scene, path) = resolve(name).map_err(|e| e.to_string())?;
    let p = predict(&scene, &path).map_err(|e| e.to_string())?;
    if json {
        print_json(&p)?;
    } else {
        println!("{}", host_sim::app::report::prediction_text(&p));
    }
    Ok(())
}

/// Prints `value` as pretty JSON on stdout.
fn print_json<T: serde::Serialize>(value: &T) -> Result<(), String> {
    let text = serde_json::to_string_pretty(value).map_err(|e| e.to_string())?;
    println!("{text}");
    Ok(())
}

/// Prints one line per file written: `what path`.
fn list(files: &[std::path::PathBuf], what: &str) {
    for f in files {
        println!("{what} {}", f.display());
    }
}
