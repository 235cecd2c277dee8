//! Every numeric key of every bundled scene, mutated one at a time (NaN, ±inf, 0, the negative,
//! 1e308, 1e-308, a string, the key deleted): no panic, no hang, no NaN or inf in the printed
//! results, and every rejection names the key that was changed.
//!
//! Bounded work, so that the whole matrix takes seconds in the debug profile `cargo test
//! --workspace` uses: a mutated scene is validated, predicted, and run with its simulated time
//! clamped to [`RUN_SECONDS`] (the scene's own fields are public; no test-only switch in the
//! code). Validation and prediction see the mutated duration as written, so a mutated
//! `simulation.duration` is still checked against the limits. Each case runs on its own
//! thread, and a case that has not ended after [`HANG`] fails the test as a hang: a watchdog,
//! not a speed target (a case takes milliseconds).
#![allow(clippy::unwrap_used, clippy::expect_used)]

use host_sim::app::check::Written;
use host_sim::app::predict::predict;
use host_sim::app::report::{prediction_text, run_text};
use host_sim::app::run::{run_with, Overrides, RunOptions};
use host_sim::app::scene::{Scene, BUNDLED};
use rayon::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Simulated time of each run, s.
const RUN_SECONDS: f64 = 1.0;
/// A case still running after this is a hang.
const HANG: Duration = Duration::from_secs(120);

/// What replaces a value; `None` deletes the key's line.
const MUTATIONS: [Option<&str>; 9] = [
    Some("nan"),
    Some("inf"),
    Some("-inf"),
    Some("0"),
    Some("NEGATIVE"),
    Some("1e308"),
    Some("1e-308"),
    Some("\"x\""),
    None,
];

struct Case {
    scene: &'static str,
    key: String,
    mutation: String,
    text: String,
}

/// The mutated texts of one scene file.
fn cases(file: &'static str, text: &'static str) -> Vec<Case> {
    let written = Written::parse(text);
    let mut out = Vec::new();
    for (key, value, span) in written.entries() {
        let Some(span) = span else { continue };
        if value.parse::<f64>().is_err() {
            continue; // strings (model, kind, framing, description) are not numbers
        }
        for m in MUTATIONS {
            let (mutation, mutated) = match m {
                Some("NEGATIVE") => {
                    let neg = match value.strip_prefix('-') {
                        Some(v) => v.to_string(),
                        None => format!("-{value}"),
                    };
                    (neg.clone(), splice(text, &span, &neg))
                }
                Some(v) => (v.to_string(), splice(text, &span, v)),
                None => match delete_line(text, key, &span) {
                    Some(t) => ("(deleted)".to_string(), t),
                    None => continue, // inside an inline table or array: no line of its own
                },
            };
            out.push(Case {
                scene: file,
                key: key.to_string(),
                mutation,
                text: mutated,
            });
        }
    }
    out
}

fn splice(text: &str, span: &std::ops::Range<usize>, with: &str) -> String {
    format!("{}{with}{}", &text[..span.start], &text[span.end..])
}

/// `text` without the line `key = value` holding `span`, if the key has a line of its own.
fn delete_line(text: &str, key: &str, span: &std::ops::Range<usize>) -> Option<String> {
    let start = text[..span.start].rfind('\n').map_or(0, |i| i + 1);
    let end = text[span.end..]
        .find('\n')
        .map_or(text.len(), |i| span.end + i + 1);
    let last = key.rsplit('.').next()?;
    let line = text[start..end].trim_start();
    line.starts_with(&format!("{last} "))
        .then(|| format!("{}{}", &text[..start], &text[end..]))
        .or_else(|| {
            line.starts_with(&format!("{last}="))
                .then(|| format!("{}{}", &text[..start], &text[end..]))
        })
}

/// Whether the error `e` names `key`: scene errors quote the whole key path; the TOML parser's
/// errors (wrong type, missing key) show the key's line or name its last part.
fn names_key(e: &str, key: &str) -> bool {
    let last = key.rsplit('.').next().unwrap_or(key);
    let last = last.split('[').next().unwrap_or(last);
    if e.contains("TOML parse error") {
        e.contains(last)
    } else {
        e.contains(&format!("`{key}")) || e.contains(&format!("{key} ="))
    }
}

/// A number printed as NaN or infinity.
fn non_finite(text: &str) -> Option<&str> {
    text.split(|c: char| !(c.is_alphanumeric() || c == '-'))
        .find(|w| {
            matches!(
                w.to_ascii_lowercase().trim_start_matches('-'),
                "nan" | "inf" | "infinity"
            )
        })
}

/// One case: `Err` says what went wrong.
fn one(case: &Case) -> Result<(), String> {
    let path = PathBuf::from(format!("mutated/{}", case.scene));
    let scene = match Scene::parse(&case.text, &path) {
        Ok(s) => s,
        Err(e) => {
            let e = e.to_string();
            return check_error(&e, case);
        }
    };
    let p = match predict(&scene, &path) {
        Ok(p) => p,
        Err(e) => return check_error(&e.to_string(), case),
    };
    let predicted = prediction_text(&p);
    if let Some(w) = non_finite(&predicted) {
        return Err(format!("prediction prints {w}:\n{predicted}"));
    }
    let mut short = scene.clone();
    short.simulation.duration = short.simulation.duration.min(RUN_SECONDS);
    short.simulation.settle = None;
    if let Some(m) = &mut short.monitor {
        // A window of many revolutions would not complete in the short run; the mutation of
        // window_revolutions itself was checked by the validation above.
        m.window_revolutions = m.window_revolutions.map(|n| n.min(2));
    }
    let options = RunOptions {
        progress: false,
        keep_windows: false,
        ..RunOptions::default()
    };
    match run_with(&short, Path::new(&path), Overrides::default(), options) {
        Ok(r) => {
            let text = run_text(&short, &r);
            match non_finite(&text) {
                Some(w) => Err(format!("run prints {w}:\n{text}")),
                None => Ok(()),
            }
        }
        Err(e) => check_error(&e.to_string(), case),
    }
}

fn check_error(e: &str, case: &Case) -> Result<(), String> {
    if names_key(e, &case.key) {
        Ok(())
    } else {
        Err(format!("error does not name the key: {e}"))
    }
}

#[test]
fn every_numeric_key_of_every_bundled_scene_mutated() {
    let all: Vec<Case> = BUNDLED
        .iter()
        .flat_map(|(file, text)| cases(file, text))
        .collect();
    // Nine scenes of 8 to 40 numeric keys each, nine mutations per key.
    assert!(all.len() > 700, "{} cases", all.len());
    println!("{} mutated scenes", all.len());
    // The cases wait on their threads from a pool of their own: blocked in the global pool's
    // workers, they would leave none to the stability scan's own parallel work (a deadlock).
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(std::thread::available_parallelism().map_or(2, |n| n.get()))
        .build()
        .unwrap();
    let failures: Vec<String> = pool.install(|| {
        all.into_par_iter()
            .filter_map(|case| {
                let label = format!("{} `{}` = {}", case.scene, case.key, case.mutation);
                let (tx, rx) = std::sync::mpsc::channel();
                std::thread::spawn(move || {
                    let r = one(&case);
                    let _ = tx.send(r);
                });
                match rx.recv_timeout(HANG) {
                    Ok(Ok(())) => None,
                    Ok(Err(why)) => Some(format!("{label}: {why}")),
                    Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {
                        Some(format!("{label}: still running after {HANG:?}"))
                    }
                    Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                        Some(format!("{label}: panicked"))
                    }
                }
            })
            .collect()
    });
    assert!(
        failures.is_empty(),
        "{} failures:\n{}",
        failures.len(),
        failures.join("\n")
    );
}
