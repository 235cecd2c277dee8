//! `drive-sim`: run, predict and sweep scenes.

use clap::{Parser, Subcommand};
use host_sim::predict::predict;
use host_sim::scene::{resolve, BUNDLED, DEFAULT_SCENE};
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
    /// Design-time results only (no simulation): predicted δ, support limits, regime zones.
    Predict {
        /// Scene file, or the name of a bundled scene.
        scene: String,
        /// Print JSON.
        #[arg(long)]
        json: bool,
    },
    /// List the bundled scenes.
    Scenes,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => predict_cmd(DEFAULT_SCENE, false),
        Some(Command::Predict { scene, json }) => predict_cmd(&scene, json),
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

fn predict_cmd(name: &str, json: bool) -> Result<(), String> {
    let (scene, path) = resolve(name).map_err(|e| e.to_string())?;
    let p = predict(&scene, &path).map_err(|e| e.to_string())?;
    if json {
        println!(
            "{}",
            serde_json::to_string_pretty(&p).map_err(|e| e.to_string())?
        );
    } else {
        println!("{}", host_sim::report::prediction_text(&p));
    }
    Ok(())
}
