//! The `drive-sim` command line: bundled scenes, JSON contracts, errors and exit codes.

mod cli_common;

use cli_common::drive_sim;
use std::process::Command;

fn json(args: &[&str]) -> serde_json::Value {
    let (ok, out, err) = drive_sim(args);
    assert!(ok, "{args:?}: {err}");
    serde_json::from_str(&out).expect("valid JSON")
}

#[test]
fn no_arguments_runs_the_kneader_and_reports() {
    let (ok, out, err) = drive_sim(&[]);
    assert!(ok, "{err}");
    assert!(
        out.contains("kneader.toml") && out.contains("δ measured"),
        "{out}"
    );
    assert!(out.contains("0.030656"), "{out}");
}

#[test]
fn scenes_lists_every_bundled_scene() {
    let (ok, out, _) = drive_sim(&["scenes"]);
    assert!(ok);
    for s in [
        "kneader",
        "auger",
        "auger-overhung",
        "one-mass",
        "one-mass-runup",
        "one-mass-motor-runup",
        "one-mass-undersized",
        "two-mass",
        "three-mass",
    ] {
        assert!(
            out.lines().any(|l| l.split_whitespace().next() == Some(s)),
            "{s}: {out}"
        );
    }
}

#[test]
fn predict_json_has_the_contracted_members() {
    let v = json(&["predict", "kneader", "--json"]);
    let i = &v["irregularity"];
    assert!((i["delta"].as_f64().unwrap() - 0.030656).abs() < 1e-6);
    assert!((i["omega_max"].as_f64().unwrap() - 136.311).abs() < 1e-3);
    assert!((i["omega_min"].as_f64().unwrap() - 132.196).abs() < 1e-3);
    assert_eq!(i["steady_state"], true);
    assert_eq!(i["flywheel_for_limit"].as_f64(), Some(0.0));

    let s = &json(&["predict", "auger", "--json"])["supports"];
    for k in [
        "unbalance_a",
        "unbalance_b",
        "permissible_a",
        "permissible_b",
        "max_speed",
    ] {
        assert!(s[k].as_f64().is_some(), "{k}: {s}");
    }

    let a = &json(&["predict", "two-mass", "--json"])["autobalancer"];
    assert_eq!(a["resonant_speeds"].as_array().unwrap().len(), 2);
    assert_eq!(a["additional_speeds"].as_array().unwrap().len(), 1);
    let zones = a["zones"].as_array().unwrap();
    assert_eq!(zones.first().unwrap()["regime"], "gathering");
    assert!(zones.last().unwrap()["to"].is_null());
}

#[test]
fn run_json_reports_measurement_prediction_and_cost() {
    let v = json(&["run", "kneader", "--json"]);
    // The integrator as kneader.toml names it (`integrator = "dp5"`).
    assert_eq!(v["integrator"], "dp5");
    let m = v["delta_measured"].as_f64().unwrap();
    let p = v["delta_predicted"].as_f64().unwrap();
    assert!((m / p - 1.0).abs() < 0.01);
    for k in [
        "windows",
        "invalid_windows",
        "noise_floor",
        "alarms",
        "wall_seconds",
        "rhs_evaluations",
        "edges",
    ] {
        assert!(!v[k].is_null(), "{k}");
    }
    let v = json(&["run", "one-mass", "--json"]);
    assert_eq!(v["regime_predicted"], "balancing");
    assert_eq!(v["regime_simulated"], "balancing");
}

#[test]
fn sweep_json_keeps_its_contract() {
    let v = json(&[
        "sweep", "one-mass", "--from", "40", "--to", "110", "--steps", "3", "--json",
    ]);
    let points = v["points"].as_array().unwrap();
    assert_eq!(points.len(), 3);
    for p in points {
        assert!(p["speed"].as_f64().is_some());
        for k in ["regime_predicted", "regime_simulated"] {
            let r = p[k].as_str().unwrap();
            assert!(r == "balancing" || r == "gathering", "{k}: {r}");
        }
    }
    assert_eq!(points[0]["regime_predicted"], "gathering");
    assert_eq!(points[2]["regime_simulated"], "balancing");
    // 40 and 110 rad/s are far from the resonance at 61.4 rad/s and agree; 75 rad/s is
    // outside the band too.
    assert_eq!(v["away_from_characteristic"], 3);
    assert_eq!(v["agreeing"], 3);
}

/// A bundled scene with some text replaced, written to a file of its own.
fn variant(
    dir: &std::path::Path,
    scene: &str,
    name: &str,
    edits: &[(&str, &str)],
) -> std::path::PathBuf {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/").to_string() + scene + ".toml";
    let mut text = std::fs::read_to_string(path).unwrap();
    for (from, to) in edits {
        assert!(text.contains(from), "{scene}: {from}");
        text = text.replace(from, to);
    }
    let file = dir.join(name);
    std::fs::write(&file, text).unwrap();
    file
}

/// `predict` never gives numbers that look like a result where there is none: a stalled
/// drive's δ, speeds are null (they were δ 2 and ω max 18.7) with the reason; a flywheel beyond
/// any scene's range is "none within range" with the figure (1.06e10 kg·m² was printed as the
/// design); a speed below the breakdown speed is warned of; an unbalance over its permissible
/// is flagged (only `run` did), and the allocation rule is named.
#[test]
fn predict_says_what_its_numbers_are() {
    let scratch_dir = scratch("variant");
    let dir = scratch_dir.path();
    let stall = variant(
        dir,
        "kneader",
        "stall.toml",
        &[("mean = 24.0", "mean = 170.0")],
    );
    let v = json(&["predict", stall.to_str().unwrap(), "--json"]);
    let i = &v["irregularity"];
    assert_eq!(i["steady_state"], false);
    for k in ["delta", "omega_max", "omega_min"] {
        assert!(i[k].is_null(), "{k}: {i}");
    }
    assert!(i["stall"].as_str().unwrap().contains("mean load"), "{i}");

    let tiny = variant(
        dir,
        "kneader",
        "tiny.toml",
        &[("delta_limit = 0.06", "delta_limit = 1e-12")],
    );
    let v = json(&["predict", tiny.to_str().unwrap(), "--json"]);
    let i = &v["irregularity"];
    assert!(i["flywheel_for_limit"].is_null(), "{i}");
    assert!(i["flywheel_beyond_range"].as_f64().unwrap() > 1e9, "{i}");
    let (_, out, _) = drive_sim(&["predict", tiny.to_str().unwrap()]);
    assert!(
        out.contains("no flywheel within `shaft.flywheel`'s range"),
        "{out}"
    );

    let low = variant(
        dir,
        "kneader",
        "low.toml",
        &[
            ("mean = 24.0", "mean = 150.0"),
            ("amplitude = 12.0", "amplitude = 40.0"),
        ],
    );
    let v = json(&["predict", low.to_str().unwrap(), "--json"]);
    let w = v["irregularity"]["working_branch_warning"]
        .as_str()
        .unwrap();
    assert!(w.contains("below the motor's breakdown speed"), "{w}");

    let heavy = variant(
        dir,
        "auger",
        "heavy.toml",
        &[("amount = 2.0e-3", "amount = 0.2")],
    );
    let v = json(&["predict", heavy.to_str().unwrap(), "--json"]);
    let s = &v["supports"];
    assert_eq!(s["unbalance_level"][0], "over", "{s}");
    assert_eq!(s["allocation"], "inboard");
    let v = json(&["predict", "auger", "--json"]);
    assert_eq!(v["supports"]["unbalance_level"][0], "normal");
    let v = json(&["predict", "auger-overhung", "--json"]);
    assert_eq!(v["supports"]["allocation"], "overhung");
}

/// A sweep above the speed range every scene speed has is refused at once, naming `--to`
/// (it ran for minutes, then blamed `simulation.duration` for too many integrator steps).
#[test]
fn a_sweep_beyond_the_speed_range_names_to() {
    let (ok, _, err) = drive_sim(&["sweep", "two-mass", "--from", "1e6", "--to", "2e6"]);
    assert!(!ok);
    assert!(
        err.contains("`--to`") && err.contains("allowed up to 1e5 rad/s"),
        "{err}"
    );
}

#[test]
fn plots_are_written() {
    let scratch_dir = scratch("plots");
    let dir = scratch_dir.path();
    let (ok, _, err) = drive_sim(&["run", "kneader", "--plot", dir.to_str().unwrap()]);
    assert!(ok, "{err}");
    for f in ["kneader-speed.svg", "kneader-delta.svg"] {
        let svg = std::fs::read_to_string(dir.join(f)).unwrap();
        assert!(svg.starts_with("<svg") && svg.len() > 2000, "{f}");
    }
    let (ok, _, err) = drive_sim(&["run", "auger", "--plot", dir.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(dir.join("auger-supports.svg").exists());
}

#[test]
fn predict_rejects_a_delta_limit_below_f64_resolution() {
    // The kneader with a δ limit far below what f64 resolves (2.2e-16): an error naming the
    // file and the key, not a flywheel of 1e19 kg·m².
    let scratch_dir = scratch("limit");
    let dir = scratch_dir.path();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/kneader.toml");
    let text = std::fs::read_to_string(scene).unwrap();
    assert!(text.contains("delta_limit = 0.06"));
    let path = dir.join("tiny-limit.toml");
    std::fs::write(
        &path,
        text.replace("delta_limit = 0.06", "delta_limit = 1e-20"),
    )
    .unwrap();
    for cmd in ["predict", "run"] {
        let (ok, _, err) = drive_sim(&[cmd, path.to_str().unwrap()]);
        assert!(!ok, "{cmd} should fail");
        assert!(
            err.contains("tiny-limit.toml") && err.contains("delta_limit"),
            "{cmd}: {err}"
        );
    }
}

/// An alarm that cannot judge a window for its noise floor says so: the kneader (δ 0.033)
/// with a 4 MHz timer and one-edge samples has a floor of 0.011, above 0.2 of a 0.03 limit, and
/// δ lies within that floor of the limit, so the core's alarm counts no window; "no alarm"
/// alone would read as a drive within it. Against a limit of 0.015 the same windows are over it
/// by more than their floor, and the alarm judges them and raises (it had judged none, and the
/// pin said no alarm for a drive twice its limit).
#[test]
fn an_alarm_that_judged_no_window_says_why() {
    let scratch_dir = scratch("blind");
    let dir = scratch_dir.path();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/kneader.toml");
    let text = std::fs::read_to_string(scene).unwrap();
    let text = text
        .replace("duration = 30.0", "duration = 15.0")
        .replace("settle = 10.0", "settle = 5.0")
        .replace("timer_hz = 84e6", "timer_hz = 4e6\nestimator_edges = 1");
    assert!(text.contains("timer_hz = 4e6") && text.contains("delta_limit = 0.06"));
    let path = dir.join("blind-alarm.toml");
    let far = dir.join("far-over.toml");
    std::fs::write(
        &path,
        text.replace("delta_limit = 0.06", "delta_limit = 0.03"),
    )
    .unwrap();
    std::fs::write(
        &far,
        text.replace("delta_limit = 0.06", "delta_limit = 0.015"),
    )
    .unwrap();
    // predict foresees it from the predicted speed: 2·ω̄/(K·timer_hz·pitch) = 1.09e-2.
    let v = json(&["predict", path.to_str().unwrap(), "--json"]);
    let w = v["irregularity"]["alarm_floor_warning"].as_str().unwrap();
    assert!(
        w.contains("1.09e-2")
            && w.contains("above 0.2 of the δ limit 0.03")
            && w.contains("would judge few windows or none"),
        "{w}"
    );
    let v = json(&["predict", far.to_str().unwrap(), "--json"]);
    let w = v["irregularity"]["alarm_floor_warning"].as_str().unwrap();
    assert!(w.contains("judged over"), "{w}");
    let v = json(&["predict", "kneader", "--json"]);
    assert!(v["irregularity"]["alarm_floor_warning"].is_null());
    let v = json(&["run", path.to_str().unwrap(), "--json"]);
    assert!(v["delta_measured"].as_f64().unwrap() > 0.03);
    assert_eq!(v["alarms"].as_array().unwrap().len(), 0);
    let j = &v["alarm_judged"];
    assert_eq!(j["counted"], 0);
    assert!(j["floor_near_limit"].as_u64().unwrap() > 10, "{j}");
    let (ok, out, err) = drive_sim(&["run", path.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        out.contains("no alarm — the alarm judged none of the") && out.contains("timer_hz"),
        "{out}"
    );
    let v = json(&["run", far.to_str().unwrap(), "--json"]);
    assert_eq!(v["alarms"].as_array().unwrap().len(), 1, "{}", v["alarms"]);
    assert!(v["alarm_judged"]["counted"].as_u64().unwrap() > 10);
}

#[test]
fn runup_reports_the_capture_and_out_needs_loads_together() {
    let scratch_dir = scratch("capture");
    let dir = scratch_dir.path();
    let (ok, out, err) = drive_sim(&["run", "one-mass-runup", "--plot", dir.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(
        out.contains("loads captured near") && out.contains("core predicts until 90.41"),
        "{out}"
    );
    for f in [
        "one-mass-runup-capture.svg",
        "one-mass-runup-capture-time.svg",
    ] {
        let svg = std::fs::read_to_string(dir.join(f)).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("capture"), "{f}");
    }
    let (ok, _, err) = drive_sim(&["run", "one-mass", "--out", dir.to_str().unwrap()]);
    assert!(!ok && err.contains("start = \"together\""), "{err}");
}

#[test]
fn bad_scenes_name_the_file_and_key_and_fail() {
    let scratch_dir = scratch("bad");
    let dir = scratch_dir.path();
    let cases = [
        ("unknown.toml", "[shaft]\ninertia = 0.3\nflywhel = 1.0\n", "flywhel"),
        ("missing.toml", "[motor]\nmodel = \"parabola\"\nno_load_speed = 145.0\nbreakdown_torque = 158.0\n", "breakdown_speed"),
        ("units.toml", "[encoder]\nlines = 1024\ntimer_hz = \"84 MHz\"\n", "timer_hz"),
        (
            "impossible.toml",
            "[shaft]\ninertia = -0.3\n[motor]\nmodel = \"parabola\"\nno_load_speed = 145.0\nbreakdown_speed = 36.0\nbreakdown_torque = 158.0\n[load]\nmean = 24.0\n",
            "shaft.inertia",
        ),
        (
            "stall.toml",
            "[shaft]\ninertia = 0.3\n[motor]\nmodel = \"parabola\"\nno_load_speed = 145.0\nbreakdown_speed = 150.0\nbreakdown_torque = 158.0\n[load]\nmean = 24.0\n",
            "motor.",
        ),
        // Arrays longer than their key takes: refused as shorter ones are (the extra values
        // were dropped unsaid: three `[t, ω, x]` points ran as `[t, ω]`).
        (
            "triples.toml",
            "[motor]\nmodel = \"profile\"\npoints = [[0.0, 0.0, 9.0], [1.0, 100.0, 9.0]]\n",
            "points = [[0.0, 0.0, 9.0]",
        ),
        (
            "window.toml",
            "[motor]\nmodel = \"speed\"\nspeed = 50.0\n[encoder]\nlines = 60\ntimer_hz = 1e6\nglitch_window = [0.3, 0.7, 0.9]\n",
            "glitch_window = [0.3, 0.7, 0.9]",
        ),
        // A nested array quoted as written (it was called "`encoder.gaps = [...]` (the
        // default)").
        (
            "gaps.toml",
            "[motor]\nmodel = \"speed\"\nspeed = 50.0\n[encoder]\nlines = 36\ntimer_hz = 1e6\nframing = \"none\"\ngaps = [[0, 2]]\n",
            "`encoder.gaps = [[0, 2]]`: only for a pattern wheel",
        ),
    ];
    for (file, text, key) in cases {
        let path = dir.join(file);
        std::fs::write(&path, text).unwrap();
        for cmd in ["run", "predict"] {
            let (ok, _, err) = drive_sim(&[cmd, path.to_str().unwrap()]);
            assert!(!ok, "{file} {cmd} should fail");
            assert!(
                err.contains(file) && err.contains(key),
                "{file} {cmd}: {err}"
            );
        }
    }
    let (ok, _, err) = drive_sim(&["run", "no-such-scene.toml"]);
    assert!(!ok && err.contains("no-such-scene.toml"), "{err}");
}

#[test]
fn criterion_writes_its_page_and_json() {
    // One machine (a single platform, so one criterion boundary): the page names the command
    // that regenerates it, and the JSON carries the machine, its grid, its exact boundaries
    // with their checks and the criterion's boundary beside them.
    let scratch_dir = scratch("criterion");
    let dir = scratch_dir.path();
    let (ok, out, err) = drive_sim(&[
        "criterion",
        "--machines",
        "1",
        "--seed",
        "3",
        "--json",
        "--out",
        dir.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let m = &v["machines"][0];
    assert_eq!(m["sample"]["platforms"], 1);
    assert_eq!(m["points"].as_array().unwrap().len(), 40);
    assert_eq!(m["shifts"][0]["kind"], "resonance");
    let checks = m["checks"].as_array().unwrap();
    assert!(!checks.is_empty());
    assert_eq!(checks[0]["stable_above"], true);
    assert!(
        m["design"]["exact"]["map"]["boundaries"]
            .as_array()
            .unwrap()
            .len()
            == checks.len()
    );
    let mut arrived = 0;
    for p in m["points"].as_array().unwrap() {
        assert!(["balancing", "gathering", "bistable"].contains(&p["class"].as_str().unwrap()));
        // Only bistable speeds are reached with the loads balanced; there the tracker says
        // balancing from history.
        if let Some(a) = p["arrived"].as_object() {
            assert_eq!(p["class"], "bistable");
            assert_eq!(a["class"], "balancing");
            assert_eq!(a["by_history"], true);
            assert!(a["from"].as_f64().unwrap() > 0.0);
            arrived += 1;
        }
    }
    let md = std::fs::read_to_string(dir.join("criterion.md")).unwrap();
    assert!(md.contains("criterion --machines 1 --seed 3 --out"), "{md}");
    assert!(
        md.contains(&format!("At {arrived} of the ")),
        "{arrived} speeds reached balanced: {md}"
    );
    for f in ["criterion-resonance.svg", "criterion-additional.svg"] {
        assert!(std::fs::read_to_string(dir.join(f))
            .unwrap()
            .starts_with("<svg"));
    }
}

/// A scratch directory for one test, removed when it is dropped (a failing test's too).
fn scratch(tag: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("drive-sim-{tag}-"))
        .tempdir()
        .unwrap()
}

#[test]
fn bundled_scenes_only_by_name_and_a_missing_path_is_an_error() {
    // Issue 16, finding 1: a mistyped path used to run the bundled scene of that file name.
    let (ok, out, err) = drive_sim(&["run", "/no/such/dir/kneader.toml", "--json"]);
    assert!(!ok && out.is_empty(), "{out}");
    assert!(
        err.contains("/no/such/dir/kneader.toml") && err.contains("no such file"),
        "{err}"
    );
    assert!(err.contains("drive-sim run kneader"), "{err}");
    let (ok, _, err) = drive_sim(&["predict", "kneader.toml"]);
    assert!(!ok && err.contains("kneader.toml: cannot read"), "{err}");
    // A scene file at a path runs from that path.
    let scratch_dir = scratch("by-path");
    let dir = scratch_dir.path();
    let path = dir.join("kneader.toml");
    std::fs::write(
        &path,
        include_str!("../scenes/kneader.toml")
            .replace("duration = 30.0", "duration = 3.0")
            .replace("settle = 10.0", "settle = 1.0"),
    )
    .unwrap();
    let v = json(&["run", path.to_str().unwrap(), "--json"]);
    assert_eq!(v["simulated_seconds"], 3.0);
    assert_eq!(v["scene"], path.to_str().unwrap());
}

#[test]
fn scene_files_are_bounded_and_an_empty_scene_is_an_error() {
    // Finding 2 (/dev/zero read without end) and finding 7 (`predict /dev/null --json` → `{}`).
    if std::path::Path::new("/dev/zero").exists() {
        let (ok, _, err) = drive_sim(&["run", "/dev/zero"]);
        assert!(
            !ok && err.contains("/dev/zero") && err.contains("limit"),
            "{err}"
        );
    }
    let scratch_dir = scratch("empty");
    let dir = scratch_dir.path();
    let empty = dir.join("empty.toml");
    std::fs::write(&empty, "# nothing here\n\n").unwrap();
    let only = dir.join("only-description.toml");
    std::fs::write(&only, "description = \"a scene without tables\"\n").unwrap();
    for (file, what) in [(&empty, "empty"), (&only, "nothing to predict")] {
        let (ok, out, err) = drive_sim(&["predict", file.to_str().unwrap(), "--json"]);
        assert!(!ok && out.is_empty(), "{out}");
        assert!(
            err.contains(file.to_str().unwrap()) && err.contains(what),
            "{err}"
        );
    }
}

#[test]
fn a_closed_pipe_or_a_full_disk_ends_quietly_with_a_failure() {
    // Finding 4: these panicked ("failed printing to stdout", exit 101).
    // A socket whose other end is closed before the command starts: every write to it fails
    // with a broken pipe, without depending on timing.
    #[cfg(unix)]
    {
        use std::os::fd::OwnedFd;
        use std::os::unix::net::UnixStream;
        use std::process::Stdio;
        let (ours, theirs) = UnixStream::pair().unwrap();
        drop(theirs);
        let out = Command::new(env!("CARGO_BIN_EXE_drive-sim"))
            .args(["predict", "kneader", "--json"])
            .stdout(Stdio::from(OwnedFd::from(ours)))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(err.is_empty(), "{err}");
    }
    if let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") {
        let out = Command::new(env!("CARGO_BIN_EXE_drive-sim"))
            .args(["predict", "kneader"])
            .stdout(full)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(1), "{err}");
        assert!(
            err.contains("cannot write the output") && !err.contains("panicked"),
            "{err}"
        );
    }
}

#[test]
fn output_directories_are_checked_before_simulating() {
    // Finding 9: a bad --plot/--out failed after the whole run, without the path.
    let scratch_dir = scratch("outdirs");
    let dir = scratch_dir.path();
    let file = dir.join("a-file");
    std::fs::write(&file, "").unwrap();
    let below = file.join("plots");
    // A scene that fails only when simulated: the directory error must come first.
    let scene = dir.join("no-motor.toml");
    std::fs::write(&scene, "[encoder]\nlines = 64\ntimer_hz = 1e6\n").unwrap();
    for option in ["--plot", "--out"] {
        for target in [&file, &below] {
            let (ok, _, err) = drive_sim(&[
                "run",
                scene.to_str().unwrap(),
                option,
                target.to_str().unwrap(),
            ]);
            assert!(!ok, "{option} {}", target.display());
            assert!(
                err.contains(option) && err.contains(target.to_str().unwrap()),
                "{err}"
            );
            assert!(!err.contains("motor"), "{err}");
        }
    }
}

#[test]
fn sweep_steps_and_criterion_machines_are_bounded() {
    // Finding 2: `--steps 18446744073709551615` and `--machines` as large never ended.
    let cases: [&[&str]; 4] = [
        &[
            "sweep",
            "one-mass",
            "--from",
            "40",
            "--to",
            "110",
            "--steps",
            "18446744073709551615",
        ],
        &[
            "sweep", "one-mass", "--from", "40", "--to", "110", "--steps", "1001",
        ],
        &["criterion", "--machines", "18446744073709551615"],
        &["criterion", "--machines", "0"],
    ];
    for args in cases {
        let (ok, _, err) = drive_sim(args);
        assert!(!ok, "{args:?}");
        assert!(err.contains("allowed"), "{args:?}: {err}");
    }
}
/// A number out of an option's range is refused with the project's message naming the value
/// and the range, also when it is beyond the type the option is held in (clap said
/// "70000 is not in 0..=65535") or negative (clap took `-1` for an unknown argument).
#[test]
fn numbers_out_of_range_name_the_value_and_the_range() {
    let dir = scratch("range");
    let file = dir.path().join("c.csv");
    std::fs::write(&file, "Time [s],Channel 0\n0.0,0\n0.001,1\n").unwrap();
    let f = file.to_str().unwrap();
    let cases: [(&[&str], &str); 12] = [
        (
            &["--lines", "500", "--window-revolutions", "70000"],
            "--window-revolutions 70000 is out of range: a window is 1 to 1024 revolutions",
        ),
        (
            &["--lines", "500", "--window-revolutions", "-1"],
            "--window-revolutions -1 is out of range: a window is 1 to 1024 revolutions",
        ),
        (
            &["--lines", "500", "--window-revolutions", "2000"],
            "--window-revolutions 2000 is out of range: a window is 1 to 1024 revolutions",
        ),
        (
            &["--lines", "500", "--min-speed", "-1"],
            "--min-speed -1 is out of range: the slowest speed still running is 1e-6 to 1e5 \
             rad/s",
        ),
        (
            &["--lines", "70000"],
            "--lines 70000 is out of range: a disc has 2 to 8192 lines",
        ),
        (
            &["--lines", "-5"],
            "--lines -5 is out of range: a disc has 2 to 8192 lines",
        ),
        (
            &["--lines", "500", "--counter-bits", "300"],
            "--counter-bits 300 is out of range: the counter is 16 to 32 bits wide",
        ),
        (
            &["--lines", "500", "--prescaler", "-4"],
            "--prescaler -4 is out of range: the input prescaler is 1, 2, 4 or 8",
        ),
        (
            &["--lines", "500", "--estimator-edges", "70000"],
            "--estimator-edges 70000 is out of range: a speed sample spans 1 to",
        ),
        (
            &["--lines", "500", "--timer-hz", "-1e6"],
            "--timer-hz -1000000 is out of range: the timer clock is 1 Hz to 10 GHz",
        ),
        (
            &["--lines", "500", "--sample-rate", "-1"],
            "--sample-rate -1: allowed 1 to 1e12 Hz",
        ),
        (
            &["--lines", "500", "--timer-hz", "1e11"],
            "--timer-hz 100000000000 is out of range: the timer clock is 1 Hz to 10 GHz",
        ),
    ];
    let refused = |args: &[&str], said: &str| {
        let (ok, _, err) = drive_sim(args);
        assert!(!ok, "{args:?}");
        assert!(err.contains(said), "{args:?}: {err}");
    };
    for (options, said) in cases {
        refused(&[&["analyze", f], options].concat(), said);
    }
    // sweep and criterion: a negative count or seed is a value out of range, not an argument.
    let cases: [(&[&str], &str); 3] = [
        (
            &[
                "sweep", "one-mass", "--from", "40", "--to", "110", "--steps", "-1",
            ],
            "allowed 2 to 1000",
        ),
        (&["criterion", "--machines", "-3"], "allowed 1 to 1000"),
        (
            &["criterion", "--seed", "-1"],
            "allowed 0 to 18446744073709551615",
        ),
    ];
    for (args, said) in cases {
        refused(args, said);
    }
}

#[test]
fn undersized_balancer_is_a_design_result() {
    // Two loads of 0.5 kg on 0.1 m (N·m·R = 0.1 kg·m) against a rotor unbalance of 0.12 kg·m:
    // no balancing position. predict reports the capacity and the residual with the loads at
    // their limit; run simulates it (at 100 rad/s the loads settle opposite the unbalance,
    // leaving that residual); sweep runs instead of stopping on a contradiction.
    let p = &json(&["predict", "one-mass-undersized", "--json"])["autobalancer"];
    assert!((p["capacity"].as_f64().unwrap() - 0.1).abs() < 1e-12, "{p}");
    assert!(
        (p["residual_floor"].as_f64().unwrap() - 0.02).abs() < 1e-12,
        "{p}"
    );
    assert!(p["stability"].is_null());
    assert_eq!(p["regime_table_source"], "criterion");
    let (_, text, _) = drive_sim(&["predict", "one-mass-undersized"]);
    assert!(text.contains("too small for its rotor"), "{text}");
    let v = json(&["run", "one-mass-undersized", "--json"]);
    assert_eq!(v["regime_simulated"], "saturated", "{v}");
    let floor = v["residual_floor"].as_f64().unwrap();
    let rel = v["residual_relative"].as_f64().unwrap();
    // Within 1 % of D of the floor (0.02/0.12 = 0.1667 of D).
    assert!((rel - floor / 0.12).abs() <= 0.01, "{rel} {floor}");
    let s = json(&[
        "sweep",
        "one-mass-undersized",
        "--from",
        "40",
        "--to",
        "110",
        "--steps",
        "2",
        "--json",
    ]);
    let points = s["points"].as_array().unwrap();
    assert_eq!(points[0]["regime_simulated"], "gathering");
    assert_eq!(points[1]["regime_simulated"], "saturated");
    assert_eq!(s["exact"], false);
}

#[test]
fn run_writes_a_capture_that_analyze_reads() {
    let scratch_dir = scratch("capture-readback");
    let dir = scratch_dir.path();
    let scene = dir.join("crank.toml");
    std::fs::write(
        &scene,
        "[simulation]\nduration = 2.0\n[motor]\nmodel = \"profile\"\n\
         points = [[0.0, 0.0], [0.5, 25.0]]\n[cranking]\nripple = 0.4\nstrokes = 2.0\n\
         [encoder]\nwheel = \"8-1\"\ntimer_hz = 1e6\nestimator_edges = 1\n\
         [capture]\nsample_rate = 2e5\n",
    )
    .unwrap();
    let capture = dir.join("crank.csv");
    let (ok, out, err) = drive_sim(&[
        "run",
        scene.to_str().unwrap(),
        "--capture",
        capture.to_str().unwrap(),
        "--capture-format",
        "sigrok",
    ]);
    assert!(ok, "{err}");
    assert!(out.contains("capture: wrote"), "{out}");
    let text = std::fs::read_to_string(&capture).unwrap();
    assert!(
        text.starts_with("; CSV generated by drive-sim"),
        "{text:.200}"
    );
    assert!(
        text.contains("; Samplerate: 200 kHz\nmicroseconds,logic\n"),
        "{text:.300}"
    );
    let v = json(&[
        "analyze",
        capture.to_str().unwrap(),
        "--wheel",
        "8-1",
        "--json",
    ]);
    assert_eq!(v["format"], "sigrok");
    assert_eq!(v["missing"], 0);
    assert_eq!(v["glitches"], 0);
    assert!(v["revolutions"].as_u64().unwrap() >= 3, "{v}");
    assert!(v["windows"]
        .as_array()
        .unwrap()
        .iter()
        .all(|w| w["valid"] == true));
    assert!(v["sync_acquired"].as_f64().is_some());
    // The text report and the plots.
    let plots = dir.join("plots");
    let (ok, out, err) = drive_sim(&[
        "analyze",
        capture.to_str().unwrap(),
        "--wheel",
        "8-1",
        "--plot",
        plots.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        out.contains("revolutions counted in sync") && out.contains("sync: acquired"),
        "{out}"
    );
    assert!(plots.join("crank-speed.svg").exists());
    // Errors name the option, the file and the line.
    let (ok, _, err) = drive_sim(&["analyze", capture.to_str().unwrap()]);
    assert!(!ok && err.contains("--wheel"), "{err}");
    let bad = dir.join("bad.csv");
    std::fs::write(&bad, "time_s,level\n0,0\n0.1,7\n").unwrap();
    let (ok, _, err) = drive_sim(&["analyze", bad.to_str().unwrap(), "--wheel", "36-2"]);
    assert!(
        !ok && err.contains("bad.csv:3:") && err.contains("not a logic level"),
        "{err}"
    );
}

/// The kneader's drive for `duration` s on a 1024-line index disc, captured at `rate`.
fn kneader_captured(duration: f64, rate: &str) -> String {
    format!(
        "[simulation]\nduration = {duration}\nsettle = 0.5\n\
         [shaft]\ninertia = 0.323\n\
         [motor]\nmodel = \"parabola\"\nno_load_speed = 145.0\nbreakdown_speed = 36.0\n\
         breakdown_torque = 158.0\n\
         [load]\nmean = 24.0\nharmonics = [{{ order = 0.125, amplitude = 12.0, phase = 0.0 }}]\n\
         [encoder]\nlines = 1024\ntimer_hz = 84e6\n\
         [capture]\nsample_rate = {rate}\n"
    )
}

/// A capture sampled too slowly for the pulses at the speed the run starts at is refused
/// before anything is simulated, naming the key, its value and the rate needed (it wrote a
/// file with 56 k of 656 k pulses at 10 kS/s, without a word); one that becomes too slow only
/// as the shaft runs up is written with a WARNING counting the level changes it lacks.
#[test]
fn a_capture_too_slow_for_the_pulses_is_refused_or_its_losses_counted() {
    let scratch_dir = scratch("capture-rate");
    let dir = scratch_dir.path();
    let scene = dir.join("slow.toml");
    std::fs::write(&scene, kneader_captured(1.0, "10000")).unwrap();
    let capture = dir.join("slow.csv");
    let (ok, out, err) = drive_sim(&[
        "run",
        scene.to_str().unwrap(),
        "--capture",
        capture.to_str().unwrap(),
    ]);
    assert!(!ok && out.is_empty(), "{out}");
    assert!(err.contains("`capture.sample_rate = 10000`"), "{err}");
    assert!(!capture.exists(), "{err}");
    // Two samples of half a pitch of 1024 lines at the predicted speeds: 2·1024·ω/π.
    let needed: f64 = err
        .split("needs at least ")
        .nth(1)
        .and_then(|r| r.split(' ').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{err}"));
    let at = |w: f64| 2.0 * 1024.0 * w / std::f64::consts::PI;
    assert!(
        needed > at(132.196) && needed < at(136.311),
        "{needed}: {err}"
    );
    // At the rate named, the file is written and nothing is lost.
    std::fs::write(&scene, kneader_captured(1.0, &format!("{}", needed.ceil()))).unwrap();
    let (ok, out, err) = drive_sim(&[
        "run",
        scene.to_str().unwrap(),
        "--capture",
        capture.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    assert!(
        out.starts_with("capture: wrote") && !out.contains("WARNING capture"),
        "{out}"
    );
    // Started at 20 rad/s, where 2 kS/s is plenty, the shaft runs up to 134 rad/s, where a
    // pulse of a 64-line disc lasts 0.37 ms: merged away, and counted.
    let text = kneader_captured(3.0, "2000")
        .replace(
            "inertia = 0.323\n",
            "inertia = 0.323\ninitial_speed = 20.0\n",
        )
        .replace("lines = 1024", "lines = 64");
    std::fs::write(&scene, text).unwrap();
    let (ok, out, err) = drive_sim(&[
        "run",
        scene.to_str().unwrap(),
        "--capture",
        capture.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let warning = out
        .lines()
        .find(|l| l.starts_with("WARNING capture:"))
        .unwrap_or_else(|| panic!("{out}"));
    assert!(
        warning.contains("level changes of channel `Channel 0`")
            && warning.contains("`capture.sample_rate = 2000`"),
        "{warning}"
    );
    let lost: u64 = warning
        .trim_start_matches("WARNING capture: ")
        .split(' ')
        .next()
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{warning}"));
    assert!(lost > 1000, "{warning}");
    // Without an [encoder] there is no signal to record (it wrote one edge of the run's
    // internal encoder).
    let text = kneader_captured(1.0, "1e6");
    let text = &text[..text.find("[encoder]").unwrap()];
    std::fs::write(&scene, text).unwrap();
    let capture = dir.join("none.csv");
    let (ok, _, err) = drive_sim(&[
        "run",
        scene.to_str().unwrap(),
        "--capture",
        capture.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("`encoder`") && err.contains("--capture"),
        "{err}"
    );
    assert!(!capture.exists());
}

/// Without --capture-format the capture's format follows the file's extension (`x.vcd` was
/// written as Saleae CSV); a format the extension contradicts is refused before simulating.
#[test]
fn the_capture_format_follows_the_files_extension() {
    let scratch_dir = scratch("capture-format");
    let dir = scratch_dir.path();
    let scene = dir.join("disc.toml");
    std::fs::write(
        &scene,
        "[simulation]\nduration = 0.5\n[motor]\nmodel = \"speed\"\nspeed = 40.0\n\
         [encoder]\nlines = 24\ntimer_hz = 1e6\nestimator_edges = 1\n",
    )
    .unwrap();
    let run = |file: &str, format: Option<&str>| {
        let path = dir.join(file);
        let mut args = vec![
            "run".to_string(),
            scene.to_str().unwrap().to_string(),
            "--capture".to_string(),
            path.to_str().unwrap().to_string(),
        ];
        if let Some(f) = format {
            args.extend(["--capture-format".to_string(), f.to_string()]);
        }
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let (ok, _, err) = drive_sim(&args);
        (ok, err, std::fs::read_to_string(&path).ok())
    };
    let (ok, err, text) = run("x.vcd", None);
    assert!(ok, "{err}");
    let text = text.unwrap();
    assert!(
        text.starts_with("$version drive-sim") && text.contains("$timescale"),
        "{text:.200}"
    );
    let (ok, err, text) = run("X.VCD", Some("vcd"));
    assert!(ok && text.unwrap().starts_with("$version"), "{err}");
    let (ok, err, text) = run("x.csv", None);
    assert!(ok, "{err}");
    assert!(
        text.unwrap().starts_with("Time [s],Channel 0,Channel 1\n"),
        "{err}"
    );
    let (ok, err, text) = run("y.csv", Some("plain"));
    assert!(
        ok && text.unwrap().starts_with("time_s,level,index\n"),
        "{err}"
    );
    for (file, format, says) in [
        ("z.vcd", "saleae", "ends in .vcd"),
        ("z.vcd", "plain", "ends in .vcd"),
        ("z.csv", "vcd", "ends in .csv"),
    ] {
        let (ok, err, text) = run(file, Some(format));
        assert!(!ok && text.is_none(), "{file} {format}: {err}");
        assert!(
            err.contains(&format!("--capture-format {format}")) && err.contains(says),
            "{err}"
        );
    }
}

/// `run` counts the line edges and the index pulses apart, as `analyze` of its capture counts
/// them (it said 656 961 edges for the kneader, its 656 321 line edges and 640 index pulses
/// together), noise pulses among the line edges.
#[test]
fn run_counts_line_edges_and_index_pulses_as_analyze_does() {
    let scratch_dir = scratch("run-edges");
    let dir = scratch_dir.path();
    let scene = dir.join("disc.toml");
    std::fs::write(
        &scene,
        "[simulation]\nduration = 2.0\nseed = 5\n[motor]\nmodel = \"speed\"\nspeed = 40.0\n\
         [encoder]\nlines = 24\ntimer_hz = 1e6\nestimator_edges = 1\n\
         glitch_probability = 0.02\nglitch_window = [0.3, 0.7]\n",
    )
    .unwrap();
    let capture = dir.join("disc.csv");
    let (ok, out, err) = drive_sim(&[
        "run",
        scene.to_str().unwrap(),
        "--capture",
        capture.to_str().unwrap(),
    ]);
    assert!(ok, "{err}");
    let run = json(&["run", scene.to_str().unwrap(), "--json"]);
    let a = json(&[
        "analyze",
        capture.to_str().unwrap(),
        "--lines",
        "24",
        "--framing",
        "index",
        "--json",
    ]);
    let (line, noise, index) = (
        run["line_edges"].as_u64().unwrap(),
        run["noise_pulses"].as_u64().unwrap(),
        run["index_pulses"].as_u64().unwrap(),
    );
    assert!(noise > 0 && index > 0, "{run}");
    assert_eq!(line, a["edges"].as_u64().unwrap(), "{a}");
    assert_eq!(index, a["index_pulses"].as_u64().unwrap(), "{a}");
    assert_eq!(run["edges"].as_u64().unwrap(), line + index);
    assert!(
        out.contains(&format!(
            "{line} line edges ({noise} of them noise pulses) and {index} index pulses"
        )),
        "{out}"
    );
}

#[test]
fn predict_says_a_prescribed_speed_gives_no_delta() {
    // A prescribed speed with [load] and [shaft]: the message said the scene had no [motor]
    // with [load] and [shaft], which it has.
    let scratch_dir = scratch("prescribed");
    let dir = scratch_dir.path();
    let path = dir.join("prescribed.toml");
    std::fs::write(
        &path,
        "[shaft]\ninertia = 0.3\n[motor]\nmodel = \"speed\"\nspeed = 100.0\n\
         [load]\nmean = 3.0\nharmonics = [{ order = 1.0, amplitude = 2.0 }]\n",
    )
    .unwrap();
    let (ok, out, err) = drive_sim(&["predict", path.to_str().unwrap()]);
    assert!(!ok && out.is_empty(), "{out}");
    assert!(
        err.contains("nothing to predict")
            && err.contains("model = \"speed\" prescribes the speed"),
        "{err}"
    );
}

#[test]
fn run_says_which_tables_a_prescribed_speed_leaves_out() {
    // A prescribed speed with [load] and [shaft]: neither moves the shaft, and the run said
    // nothing of them (the load's ripple simply did not show).
    let scratch_dir = scratch("prescribed-run");
    let dir = scratch_dir.path();
    let path = dir.join("prescribed.toml");
    std::fs::write(
        &path,
        "[shaft]\ninertia = 0.3\n[motor]\nmodel = \"speed\"\nspeed = 100.0\n\
         [load]\nmean = 3.0\nharmonics = [{ order = 1.0, amplitude = 2.0 }]\n\
         [encoder]\nlines = 360\ntimer_hz = 1e6\n[simulation]\nduration = 0.5\n",
    )
    .unwrap();
    let file = path.to_str().unwrap();
    let (ok, out, err) = drive_sim(&["run", file]);
    assert!(ok, "{err}");
    assert!(
        out.contains("NOT SIMULATED [load]: the speed is prescribed ([motor] model = \"speed\")")
            && out.contains("NOT SIMULATED [shaft]"),
        "{out}"
    );
    let v = json(&["run", file, "--json"]);
    let notes = v["not_simulated"].as_array().expect("not_simulated");
    assert_eq!(notes.len(), 2, "{v}");
    assert!(notes[0].as_str().unwrap().starts_with("[load]"), "{v}");
    assert!(notes[1].as_str().unwrap().starts_with("[shaft]"), "{v}");
    // A motor-driven scene leaves nothing out, and its δ limit is in the JSON as in the text.
    let v = json(&["run", "kneader", "--json"]);
    assert!(v.get("not_simulated").is_none(), "{v}");
    assert_eq!(v["delta_limit"].as_f64(), Some(0.06));
}

/// A 50 g rotor (supports 30 mm apart, centre of mass 20 mm from A, 1e-7 kg·m at 10 mm, 1000
/// rad/s): the statics give static loads 0.05·9.80665·(1/3, 2/3) = 0.16344, 0.32689 N and
/// peaks 0.16344 + 6.6667e-8·1e6 = 0.23011 N, 0.32689 + 3.3333e-8·1e6 = 0.36022 N. Printed to
/// 0.1 N they read "static loads A 0.2 N, B 0.3 N; peak at service speed A 0.2 N, B 0.4 N":
/// 22 % off, and A's rotating part (0.067 N) vanished. Small loads keep four digits now.
#[test]
fn a_small_rotors_support_loads_keep_their_digits() {
    let scratch_dir = scratch("small-rotor");
    let dir = scratch_dir.path();
    let scene = dir.join("small.toml");
    std::fs::write(
        &scene,
        "[rotor]\nmass = 0.05\ncentre_of_mass = 0.02\nsupport_a = 0.0\nsupport_b = 0.03\n\
         grade = 2.5\nservice_speed = 1000.0\nsupport_load_limit = [0.6, 0.6]\n\
         [[unbalance]]\nz = 0.01\namount = 1e-7\nangle = 45.0\n\
         [motor]\nmodel = \"speed\"\nspeed = 1000.0\n[simulation]\nduration = 0.5\n",
    )
    .unwrap();
    let path = scene.to_str().unwrap();
    let (ok, out, err) = drive_sim(&["predict", path]);
    assert!(ok, "{err}");
    assert!(
        out.contains(
            "static loads A 0.1634 N, B 0.3269 N; peak at service speed A 0.2301 N, B 0.3602 N"
        ),
        "{out}"
    );
    let (ok, out, err) = drive_sim(&["run", path]);
    assert!(ok, "{err}");
    assert!(
        out.contains("simulated peak reactions over the run A 0.2301 N at ")
            && out.contains(" s (normal against the load limit), B 0.3602 N at "),
        "{out}"
    );
    // Large loads print as before.
    let (ok, out, _) = drive_sim(&["predict", "auger"]);
    assert!(
        ok && out.contains("static loads A 2402.0 N, B 2230.4 N"),
        "{out}"
    );
}

/// `run` classifies with the core's regime tracker fed every window's speed: ramped down into
/// the one-mass machine's capture band (bistable on [72.3, 90.4) rad/s) from 120 rad/s with
/// the loads near the balancing position, it says balancing from history (and the loads did
/// balance); run up into it with the loads together at rest, the band stays bistable.
#[test]
fn run_reads_the_regime_from_the_speed_history() {
    let scratch_dir = scratch("history");
    let dir = scratch_dir.path();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/one-mass-runup.toml");
    let text = std::fs::read_to_string(scene).unwrap();
    let ramp = |from: &str, start: &str| {
        text.replace("from = 0.0 ", &format!("from = {from} "))
            .replace("to = 130.0 ", "to = 80.0 ")
            .replace("duration = 130.0 ", "duration = 20.0 ")
            .replace("duration = 160.0 ", "duration = 40.0 ")
            .replace("start = \"together\"", start)
    };
    let down = ramp("120.0", "");
    assert!(down.contains("from = 120.0 ") && down.contains("duration = 40.0 "));
    let path = dir.join("rundown.toml");
    std::fs::write(&path, down).unwrap();
    let v = json(&["run", path.to_str().unwrap(), "--json"]);
    assert_eq!(v["regime_class"], "balancing", "{v}");
    assert_eq!(v["regime_by_history"], true);
    assert_eq!(v["regime_simulated"], "balancing");
    let (ok, out, err) = drive_sim(&["run", path.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(out.contains("from the speed's history"), "{out}");
    let path = dir.join("runup.toml");
    std::fs::write(&path, ramp("40.0", "start = \"together\"")).unwrap();
    let v = json(&["run", path.to_str().unwrap(), "--json"]);
    assert_eq!(v["regime_class"], "bistable", "{v}");
    assert!(v.get("regime_by_history").is_none());
}

/// A lightly damped two-mass machine whose balancing position is unstable at 120 rad/s, so
/// slowly (growth rate 0.078/s) that a 10 s run still ends with the residual under 1 %:
/// `run` says the verdict is unsettled and why, where it said "balancing"; `sweep` runs that
/// speed ten e-foldings long and sees the loads gather, as the table says. A heavily damped
/// pendulum balancer still settling at 80 rad/s after 10 s (residual 2 %) was "gathering"; the
/// sweep now runs it until it balances.
#[test]
fn a_run_too_short_for_its_regime_says_unsettled() {
    let scratch_dir = scratch("unsettled");
    let dir = scratch_dir.path();
    // A sweep of two speeds, as JSON.
    let sweep2 = |path: &std::path::Path, from: &str, to: &str| {
        let p = path.to_str().unwrap();
        json(&[
            "sweep", p, "--from", from, "--to", to, "--steps", "2", "--json",
        ])
    };
    let light = "[[platform]]\nmass = 20.0\nstiffness = 1.0e5\ndamping = 2.0\n\n\
        [[platform]]\nmass = 300.0\nstiffness = 2.0e6\ndamping = 10.0\n\n\
        [[coupling]]\nbetween = [2, 1]\nstiffness = 5.0e4\ndamping = 1.0\n\n\
        [autobalancer]\nkind = \"roller\"\nplatform = 1\nloads = 2\nload_mass = 0.2\n\
        radius = 0.05\nhousing_mass = 1.0\nviscosity = 2.0\nrotor_unbalance = 0.01\n\n\
        [motor]\nmodel = \"speed\"\nspeed = 120.0\n\n[simulation]\nduration = 10.0\n";
    let path = dir.join("light.toml");
    std::fs::write(&path, light).unwrap();
    let v = json(&["run", path.to_str().unwrap(), "--json"]);
    assert_eq!(v["regime_simulated"], "unsettled", "{v}");
    let why = v["regime_unsettled"].as_str().unwrap();
    assert!(why.contains("unstable at 120.00 rad/s"), "{why}");
    assert!(v["residual_relative"].as_f64().unwrap() < 0.01);
    let (ok, out, err) = drive_sim(&["run", path.to_str().unwrap()]);
    assert!(ok, "{err}");
    assert!(out.contains("The simulated regime is unsettled"), "{out}");
    let v = sweep2(&path, "120", "125");
    for p in v["points"].as_array().unwrap() {
        assert_eq!(p["regime_class"], "gathering", "{p}");
        assert_eq!(p["regime_simulated"], "gathering", "{p}");
        // Ten e-foldings (129 s) capped at ten times the scene's 10 s.
        assert!(p["duration"].as_f64().unwrap() >= 100.0, "{p}");
    }
    let pendulum = "[[platform]]\nmass = 40.0\nstiffness = 2.0e5\ndamping = 4000.0\n\n\
        [autobalancer]\nkind = \"pendulum\"\npendulum_inertia = 0.002\nplatform = 1\nloads = 3\n\
        load_mass = 0.3\nradius = 0.08\nhousing_mass = 3.0\nviscosity = 5.0\n\
        rotor_unbalance = 0.03\n\n[motor]\nmodel = \"speed\"\nspeed = 80.0\n\n\
        [simulation]\nduration = 10.0\n";
    let path = dir.join("pendulum.toml");
    std::fs::write(&path, pendulum).unwrap();
    let v = sweep2(&path, "79", "80");
    for p in v["points"].as_array().unwrap() {
        assert_eq!(p["regime_class"], "balancing", "{p}");
        assert_eq!(p["regime_simulated"], "balancing", "{p}");
    }
}
