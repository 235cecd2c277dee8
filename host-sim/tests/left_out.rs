//! What a scene composes and a model leaves out is said beside the number it affects: the
//! drive prediction beside a vibration machine, a cranking ripple on a vibration machine, the
//! support analysis beside an auto-balancer, the encoder's errors in a measured δ, the tables a
//! sweep does not use, and the estimator's range in README's limits.

mod cli_common;

use cli_common::drive_sim;
use std::path::{Path, PathBuf};

fn json(args: &[&str]) -> serde_json::Value {
    let (ok, out, err) = drive_sim(args);
    assert!(ok, "{args:?}: {err}");
    serde_json::from_str(&out).expect("valid JSON")
}

fn text(args: &[&str]) -> String {
    let (ok, out, err) = drive_sim(args);
    assert!(ok, "{args:?}: {err}");
    out
}

/// Writes `body` as `name` into `dir`.
/// Asserts that the line after the first line of `out` that `anchor` accepts starts with
/// `prefix`.
fn assert_next_line(out: &str, anchor: impl Fn(&str) -> bool, prefix: &str) {
    let line = out.lines().position(anchor).expect("anchor line");
    assert!(
        out.lines().nth(line + 1).unwrap_or("").starts_with(prefix),
        "{out}"
    );
}

fn scene(dir: &Path, name: &str, body: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, body).unwrap();
    path
}

fn scratch(tag: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("drive-sim-{tag}-"))
        .tempdir()
        .unwrap()
}

/// The two-mass machine with its ball balancer on platform 2.
const TWO_MASS: &str = "[[platform]]\nmass = 100.0\nstiffness = 4.0e5\ndamping = 200.0\n\
    [[platform]]\nmass = 100.0\nstiffness = 4.0e5\ndamping = 200.0\n\
    [[coupling]]\nbetween = [1, 2]\nstiffness = 1.0e5\ndamping = 50.0\n\
    [autobalancer]\nkind = \"ball\"\nplatform = 2\nloads = 2\nload_mass = 0.5\nradius = 0.1\n\
    housing_mass = 5.0\nviscosity = 10.0\nrotor_unbalance = 0.05\n";

/// A Kloss motor (ω_s = 80 rad/s) against a constant 8 N·m: its steady speed, 78.384 rad/s,
/// lies in the two-mass machine's exact gathering segment 71.238 – 84.043 rad/s.
const KLOSS_DRIVE: &str = "[motor]\nmodel = \"kloss\"\nsynchronous_speed = 80.0\n\
    breakdown_slip = 0.2\nbreakdown_torque = 40.0\n[load]\nmean = 8.0\n[shaft]\ninertia = 0.5\n\
    [encoder]\nlines = 256\ntimer_hz = 10e6\n[monitor]\ndelta_limit = 3.0e-4\n\
    [simulation]\nduration = 4.0\nrtol = 1e-9\natol = 1e-10\nsettle = 1.0\n";

/// The one-mass machine (ball balancer) at a prescribed 100 rad/s.
const ONE_MASS_AT_100: &str = "[[platform]]\nmass = 100.0\nstiffness = 4.0e5\ndamping = 200.0\n\
    [autobalancer]\nkind = \"ball\"\nplatform = 1\nloads = 2\nload_mass = 0.5\nradius = 0.1\n\
    housing_mass = 5.0\nviscosity = 10.0\nrotor_unbalance = 0.05\n\
    [motor]\nmodel = \"speed\"\nspeed = 100.0\n[encoder]\nlines = 256\ntimer_hz = 10e6\n\
    [simulation]\nduration = 2.0\nrtol = 1e-8\natol = 1e-10\n";

/// `predict` gave δ = 0, "within the δ limit without a flywheel", for a Kloss drive of the
/// two-mass machine whose loads gather at its speed, and `run` measured twice the limit: the
/// prediction leaves out the machine's torque on the shaft, which `run` integrates. Both say
/// so now; a drive without a machine says nothing of it.
#[test]
fn the_drive_prediction_says_it_leaves_out_the_machines_torque() {
    let dir = scratch("machine-torque");
    let coupled = scene(
        dir.path(),
        "coupled.toml",
        &format!("{TWO_MASS}{KLOSS_DRIVE}"),
    );
    let alone = scene(dir.path(), "alone.toml", KLOSS_DRIVE);
    let coupled = coupled.to_str().unwrap();
    let alone = alone.to_str().unwrap();

    let out = text(&["predict", coupled]);
    assert!(
        out.contains("δ = 0.000000\n  WARNING: this δ is the drive's alone"),
        "{out}"
    );
    assert!(
        out.contains(
            "the predicted speed 78.384 rad/s lies where the regime table says gathering \
             (71.238 – 84.043 rad/s): there the loads need not balance"
        ),
        "{out}"
    );
    let v = json(&["predict", coupled, "--json"]);
    let w = v["irregularity"]["machine_torque_warning"]
        .as_str()
        .unwrap();
    assert!(
        w.contains("[[platform]], [autobalancer]") && w.contains("drive-sim run"),
        "{w}"
    );
    let v = json(&["predict", alone, "--json"]);
    assert!(
        v["irregularity"].get("machine_torque_warning").is_none(),
        "{v}"
    );

    // `run` integrates the machine's torque with the drive: its δ line says the prediction
    // does not.
    let v = json(&["run", coupled, "--json"]);
    assert_eq!(
        v["effects"],
        serde_json::json!(["motor", "load", "vibration"])
    );
    assert!(v["delta_predicted"].as_f64().is_some(), "{v}");
    let notes = v["delta_notes"].as_array().expect("delta_notes");
    assert_eq!(notes.len(), 1, "{v}");
    assert!(
        notes[0]
            .as_str()
            .unwrap()
            .starts_with("WARNING: the predicted δ is the drive's alone"),
        "{v}"
    );
    let out = text(&["run", coupled]);
    assert_next_line(
        &out,
        |l| l.contains("δ measured"),
        "  WARNING: the predicted δ is the drive's alone",
    );
    let v = json(&["run", alone, "--json"]);
    assert!(v.get("delta_notes").is_none(), "{v}");
}

/// A 30 % two-stroke cranking ripple on the one-mass machine: the machine's model leaves out
/// the ω̇ terms, whose tangential unbalance force reaches a·s/√(1 − a²) = 0.6/√0.91 = 0.629 of
/// the centrifugal one. `run` and `sweep` say so; without the ripple nothing is said.
#[test]
fn cranking_a_vibration_machine_says_the_angular_acceleration_is_left_out() {
    let dir = scratch("cranking-machine");
    let cranked = scene(
        dir.path(),
        "cranked.toml",
        &format!("{ONE_MASS_AT_100}[cranking]\nripple = 0.3\nstrokes = 2.0\n"),
    );
    let steady = scene(dir.path(), "steady.toml", ONE_MASS_AT_100);
    let cranked = cranked.to_str().unwrap();
    let steady = steady.to_str().unwrap();
    let ratio = 0.6 / 0.91f64.sqrt();
    let figure = format!("= {ratio:.3} of ω²");
    assert_eq!(figure, "= 0.629 of ω²");

    let v = json(&["run", cranked, "--json"]);
    let w = v["model_warnings"].as_array().expect("model_warnings");
    // The WARNING, and the NOTE on the ripple's mean speed.
    assert_eq!(w.len(), 2, "{v}");
    assert!(w[1]
        .as_str()
        .unwrap()
        .starts_with("NOTE: with [cranking] ripple = 0.3"));
    let w = w[0].as_str().unwrap();
    assert!(
        w.starts_with("WARNING: [cranking] (ripple = 0.3, strokes = 2)")
            && w.contains(&figure)
            && w.contains("D·ω̇·cos(φ + θ)")
            && w.contains("computed at a constant speed"),
        "{w}"
    );
    let out = text(&["run", cranked]);
    assert!(out.contains("\nWARNING: [cranking] (ripple = 0.3"), "{out}");
    let v = json(&["run", steady, "--json"]);
    assert!(v.get("model_warnings").is_none(), "{v}");

    let args = ["--from", "90", "--to", "100", "--steps", "2"];
    let out = text(&[&["sweep", cranked][..], &args].concat());
    assert!(
        out.starts_with("NOTE: [cranking] is applied")
            && out.contains("\nWARNING: [cranking] (ripple = 0.3, strokes = 2)")
            && out.contains(&figure),
        "{out}"
    );
    let v = json(&[&["sweep", cranked, "--json"][..], &args].concat());
    assert_eq!(v["warnings"].as_array().map(Vec::len), Some(2), "{v}");
    let v = json(&[&["sweep", steady, "--json"][..], &args].concat());
    assert!(
        v.get("warnings").is_none() && v.get("not_simulated").is_none(),
        "{v}"
    );
}

/// The one-mass machine's rotor also on two supports with its own unbalance: the support
/// loads (274.5 N: the rigid-support formula for the unbalanced rotor) beside "balancing,
/// residual 5e-9" said nothing of the two being independent models. They say so now, in
/// `predict` and in `run`; a rotor without a balancer says nothing.
#[test]
fn the_support_analysis_says_it_leaves_out_the_auto_balancer() {
    let dir = scratch("supports-balancer");
    let rotor = "[rotor]\nmass = 5.0\ncentre_of_mass = 0.1\nsupport_a = 0.0\nsupport_b = 0.2\n\
        grade = 16.0\nservice_speed = 100.0\nsupport_load_limit = [2000.0, 2000.0]\n\
        [[unbalance]]\nz = 0.1\namount = 0.05\nangle = 0.0\n";
    let both = scene(
        dir.path(),
        "both.toml",
        &format!("{ONE_MASS_AT_100}{rotor}").replace("duration = 2.0", "duration = 1.0"),
    );
    let both = both.to_str().unwrap();
    let out = text(&["predict", both]);
    assert!(
        out.contains(
            "\n  WARNING: the support analysis ([rotor], [[unbalance]]) leaves out the \
             auto-balancer ([autobalancer], [[platform]])"
        ) && out.contains("(up to N·m·R = 1.0000e-1 kg·m)"),
        "{out}"
    );
    let v = json(&["predict", both, "--json"]);
    assert!(v["supports"]["balancer_warning"].as_str().is_some(), "{v}");
    let v = json(&["run", both, "--json"]);
    assert!(v["supports"]["balancer_warning"].as_str().is_some(), "{v}");
    let out = text(&["run", both]);
    assert_next_line(
        &out,
        |l| l.starts_with("Supports at"),
        "  WARNING: the support analysis",
    );
    let v = json(&["predict", "auger", "--json"]);
    assert!(v["supports"].get("balancer_warning").is_none(), "{v}");
}

/// The kneader with encoder errors: the measured δ includes them and the noise floor it quotes
/// is the quantization's alone; a NOTE under the δ line names the keys set. Without them, no
/// note.
#[test]
fn a_measured_delta_names_the_encoder_errors_it_includes() {
    let dir = scratch("encoder-errors");
    let kneader = include_str!("../scenes/kneader.toml")
        .replace("duration = 30.0", "duration = 4.0")
        .replace("settle = 10.0", "settle = 1.0");
    let clean = scene(dir.path(), "clean.toml", &kneader);
    let errors = scene(
        dir.path(),
        "errors.toml",
        &kneader.replace(
            "timer_hz = 84e6",
            "timer_hz = 84e6\nrunout = 0.002\npitch_error = 2e-4\njitter = 1e-6",
        ),
    );
    let v = json(&["run", errors.to_str().unwrap(), "--json"]);
    assert!(v["delta_measured"].as_f64().is_some(), "{v}");
    let notes = v["delta_notes"].as_array().expect("delta_notes");
    assert_eq!(notes.len(), 1, "{v}");
    let n = notes[0].as_str().unwrap();
    assert!(
        n.starts_with(
            "NOTE: the scene's encoder errors (encoder.runout = 2e-3, encoder.pitch_error = \
             2e-4 rad, encoder.jitter = 1e-6 s)"
        ) && n.contains("quantization alone"),
        "{n}"
    );
    let out = text(&["run", errors.to_str().unwrap()]);
    assert_next_line(
        &out,
        |l| l.contains("δ measured"),
        "  NOTE: the scene's encoder errors",
    );
    let v = json(&["run", clean.to_str().unwrap(), "--json"]);
    assert!(v.get("delta_notes").is_none(), "{v}");
}

/// `sweep` on a motor-driven machine ran at prescribed speeds and said nothing of the Kloss
/// motor, `[load]` and `[shaft]` it did not use. It names them now, like `run`'s NOT
/// SIMULATED.
#[test]
fn a_sweep_names_the_tables_it_does_not_use() {
    let dir = scratch("sweep-unused");
    let driven = scene(
        dir.path(),
        "driven.toml",
        &format!("{TWO_MASS}{KLOSS_DRIVE}"),
    );
    let driven = driven.to_str().unwrap();
    let args = ["--from", "100", "--to", "110", "--steps", "2"];
    let out = text(&[&["sweep", driven][..], &args].concat());
    let head: Vec<&str> = out.lines().take(3).collect();
    assert!(
        head[0].starts_with(
            "NOT SIMULATED [motor] model = \"kloss\": the sweep prescribes the rotor speed"
        ) && head[1].starts_with("NOT SIMULATED [load]: the sweep prescribes the rotor speed")
            && head[2].starts_with("NOT SIMULATED [shaft]: the sweep prescribes the rotor speed"),
        "{out}"
    );
    let v = json(&[&["sweep", driven, "--json"][..], &args].concat());
    let notes = v["not_simulated"].as_array().expect("not_simulated");
    assert_eq!(notes.len(), 3, "{v}");
    // A prescribed speed is what a sweep replaces by design: nothing to say.
    let prescribed = scene(
        dir.path(),
        "prescribed.toml",
        &format!(
            "{TWO_MASS}[motor]\nmodel = \"speed\"\nspeed = 100.0\n[simulation]\nduration = 2.0\n"
        ),
    );
    let v = json(
        &[
            &["sweep", prescribed.to_str().unwrap(), "--json"][..],
            &args,
        ]
        .concat(),
    );
    assert!(v.get("not_simulated").is_none(), "{v}");
}

/// README's limits list `encoder.estimator_edges` with the range the scene check refuses
/// outside of: 1 to 32, and at most the edges captured per revolution.
#[test]
fn readme_limits_give_the_estimator_edges_range() {
    let readme = include_str!("../../README.md");
    let row = readme
        .lines()
        .find(|l| l.starts_with("| `encoder.estimator_edges` |"))
        .expect("a Limits row for encoder.estimator_edges");
    assert!(
        row.contains("1 to 32") && row.contains("16 by default") && row.contains("prescaler"),
        "{row}"
    );
    let dir = scratch("estimator-edges");
    let kneader = include_str!("../scenes/kneader.toml");
    let many = scene(
        dir.path(),
        "many.toml",
        &kneader.replace("lines = 1024", "lines = 1024\nestimator_edges = 33"),
    );
    let (ok, _, err) = drive_sim(&["predict", many.to_str().unwrap()]);
    assert!(
        !ok && err.contains("`encoder.estimator_edges = 33`: allowed 1 to 32"),
        "{err}"
    );
    let few = scene(
        dir.path(),
        "few.toml",
        &kneader.replace("lines = 1024", "lines = 64\nprescaler = 8"),
    );
    let (ok, _, err) = drive_sim(&["predict", few.to_str().unwrap()]);
    assert!(
        !ok && err.contains("`encoder.estimator_edges = 16 (the default)`: allowed 1 to 8"),
        "{err}"
    );
}
