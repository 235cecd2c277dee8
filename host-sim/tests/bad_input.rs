//! Issue 16's findings on bad input, one test each: errors name the key as written and are
//! raised before any simulation; no NaN or inf is printed; a run that measures nothing says
//! so; work is bounded up front.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use host_sim::app::predict::predict;
use host_sim::app::report::{prediction_text, run_text};
use host_sim::app::run::{run, run_with, Overrides, RunOptions};
use host_sim::app::scene::{Scene, BUNDLED};
use std::path::Path;

fn bundled(name: &str) -> &'static str {
    BUNDLED
        .iter()
        .find(|(n, _)| n.strip_suffix(".toml") == Some(name))
        .map(|(_, t)| *t)
        .unwrap()
}

/// The error of `scene` with `from` replaced by `to` (parse, predict or run).
fn error(scene: &str, from: &str, to: &str) -> String {
    let text = bundled(scene);
    assert!(text.contains(from), "{scene} has no `{from}`");
    let text = text.replacen(from, to, 1);
    let path = Path::new("bad.toml");
    let s = match Scene::parse(&text, path) {
        Ok(s) => s,
        Err(e) => return e.to_string(),
    };
    if let Err(e) = predict(&s, path) {
        return e.to_string();
    }
    match run(&s, path, Overrides::default()) {
        Ok(_) => panic!("{scene} with `{to}` was accepted"),
        Err(e) => e.to_string(),
    }
}

fn assert_names(e: &str, want: &[&str]) {
    for w in want {
        assert!(e.contains(w), "`{w}` not in: {e}");
    }
    assert!(e.starts_with("bad.toml: "), "{e}");
}

#[test]
fn errors_name_the_key_and_the_value_as_written() {
    // Finding 3: these named another key, or only the table.
    let e = error("one-mass", "housing_mass = 5.0", "housing_mass = 1e308");
    assert_names(
        &e,
        &["`autobalancer.housing_mass = 1e308`", "allowed [0, 1e9] kg"],
    );
    let e = error(
        "kneader",
        "delta_limit = 0.06",
        "delta_limit = 0.06\nmin_speed = 1e308",
    );
    assert_names(&e, &["`monitor.min_speed = 1e308`", "allowed"]);
    let e = error(
        "auger",
        "speed = 60.0              # rad/s, prescribed",
        "speed = nan",
    );
    assert_names(&e, &["`motor.speed = nan`", "allowed [-1e5, 1e5] rad/s"]);
    let e = error("kneader", "lines = 1024", "lines = 1");
    assert_names(&e, &["`encoder.lines = 1`", "allowed 2 to 8192"]);
    // A value the ranges allow but the core's encoder refuses together with others: every key
    // involved is quoted, the one changed among them.
    let e = error(
        "kneader",
        "timer_hz = 84e6\n\n[monitor]\ndelta_limit = 0.06",
        "timer_hz = 1e6\n\n[monitor]\ndelta_limit = 0.06\nmin_speed = 5e4",
    );
    assert_names(
        &e,
        &[
            "`monitor.min_speed = 5e4`",
            "`encoder.timer_hz = 1e6`",
            "contradict",
        ],
    );
    // Wrong types inside [motor] name the key, not only the table.
    for (from, to, key) in [
        (
            "no_load_speed = 145.0",
            "no_load_speed = \"fast\"",
            "no_load_speed",
        ),
        (
            "breakdown_torque = 158.0",
            "breakdown_torque = [158.0]",
            "breakdown_torque",
        ),
    ] {
        let e = error("kneader", from, to);
        assert!(e.contains("TOML parse error") && e.contains(key), "{e}");
    }
    let e = error(
        "kneader",
        "breakdown_speed = 36.0",
        "breakdwon_speed = 36.0",
    );
    assert!(e.contains("breakdwon_speed"), "{e}");
    let e = error(
        "auger",
        "speed = 60.0              # rad/s, prescribed",
        "speed = 60.0\nbreakdown_torque = 1.0",
    );
    assert!(
        e.contains("`motor.breakdown_torque` does not belong to model = \"speed\""),
        "{e}"
    );
    // What used to end as "integration failed: step size underflow at t = 0" is refused up
    // front, naming the key.
    let e = error("one-mass", "atol = 1e-10", "atol = 1e-308");
    assert_names(&e, &["`simulation.atol = 1e-308`", "not subnormal"]);
    let e = error("one-mass", "rtol = 1e-8", "rtol = 1e-300");
    assert_names(&e, &["`simulation.rtol = 1e-300`"]);
}

#[test]
fn values_that_gave_nan_or_inf_results_are_refused_by_key() {
    // Finding 5: platform mass ≥ 1e155 gave a NaN resonant speed, service_speed = 1e308 an
    // infinite peak load.
    let e = error("one-mass", "mass = 100.0 ", "mass = 1e155 ");
    assert_names(&e, &["`platform[1].mass = 1e155`"]);
    let e = error("three-mass", "mass = 150.0 ", "mass = 2e200 ");
    assert_names(&e, &["`platform[3].mass = 2e200`"]);
    let e = error("auger", "service_speed = 60.0", "service_speed = 1e308");
    assert_names(&e, &["`rotor.service_speed = 1e308`"]);
    let e = error("auger", "per_length = 400.0", "per_length = 2e48");
    assert_names(&e, &["`process_load.per_length = 2e48`"]);
    let e = error("auger", "grade = 6.3", "grade = 1.7e308");
    assert_names(&e, &["`rotor.grade = 1.7e308`"]);
    // At the ends of every range the results print as numbers.
    for (scene, from, to) in [
        ("one-mass", "mass = 100.0 ", "mass = 1e9 "),
        ("one-mass", "stiffness = 4.0e5", "stiffness = 1e15"),
        ("auger", "service_speed = 60.0", "service_speed = 1e5"),
        ("auger", "per_length = 400.0", "per_length = 1e12"),
        ("auger", "grade = 6.3", "grade = 1e4"),
        ("auger", "amount = 2.0e-3", "amount = 1e6"),
        (
            "kneader",
            "breakdown_torque = 158.0",
            "breakdown_torque = 1e9",
        ),
    ] {
        let text = bundled(scene).replacen(from, to, 1);
        let s = Scene::parse(&text, Path::new("edge.toml")).unwrap();
        match predict(&s, Path::new("edge.toml")) {
            Ok(p) => {
                let t = prediction_text(&p);
                assert!(!t.contains("NaN") && !t.contains("inf"), "{to}: {t}");
            }
            Err(e) => assert!(e.to_string().contains(to.split(' ').next().unwrap()), "{e}"),
        }
    }
}

/// A δ limit is allowed in [f64's epsilon, 2), and the error says that range whatever the
/// bad value (2 was refused as "out of range" with no range, from deep in the design).
#[test]
fn a_delta_limit_of_two_or_below_epsilon_names_the_range() {
    for (bad, why) in [
        ("2", "reaches 2 only when the shaft stops"),
        ("3", "reaches 2 only when the shaft stops"),
        ("2.2e-16", "finer than f64 resolves the speed"),
        ("-1", "allowed"),
    ] {
        let e = error(
            "kneader",
            "delta_limit = 0.06",
            &format!("delta_limit = {bad}"),
        );
        assert_names(
            &e,
            &[
                &format!("`monitor.delta_limit = {bad}`"),
                "allowed [2.220446049250313e-16, 2)",
                why,
            ],
        );
    }
}

#[test]
fn keys_a_scene_does_not_use_are_still_checked() {
    // Finding 6: accepted because nothing read them.
    let e = error(
        "one-mass",
        "kind = \"ball\"",
        "kind = \"ball\"\npendulum_inertia = nan",
    );
    assert_names(&e, &["`autobalancer.pendulum_inertia = nan`"]);
    let e = error(
        "auger",
        "timer_hz = 10e6",
        "timer_hz = 10e6\nrunout_phase = inf",
    );
    assert_names(&e, &["`encoder.runout_phase = inf`"]);
    let e = error(
        "kneader",
        "delta_limit = 0.06",
        "delta_limit = 0.06\nregime_margin = nan",
    );
    assert_names(&e, &["`monitor.regime_margin = nan`"]);
    let e = error(
        "kneader",
        "delta_limit = 0.06",
        "delta_limit = 0.06\nwarning_fraction = -1",
    );
    assert_names(&e, &["`monitor.warning_fraction = -1`"]);
    let e = error(
        "kneader",
        "timer_hz = 84e6",
        "timer_hz = 84e6\nframing = \"index\"\nmissing = 255",
    );
    assert_names(
        &e,
        &[
            "`encoder.missing = 255`",
            "only with framing = \"missing-tooth\"",
        ],
    );
    let e = error(
        "kneader",
        "timer_hz = 84e6",
        "timer_hz = 84e6\njitter = 1e308",
    );
    assert_names(&e, &["`encoder.jitter = 1e308`", "allowed [0, 0.001] s"]);
}

#[test]
fn a_run_that_measures_nothing_says_why_and_does_not_judge_the_supports_normal() {
    // Finding 8: the measurement section was dropped silently and the supports were judged
    // "normal" at the service speed whatever the simulation did.
    let text = bundled("auger").replacen(
        "speed = 60.0              # rad/s, prescribed",
        "speed = -60.0",
        1,
    );
    let s = Scene::parse(&text, Path::new("reverse.toml")).unwrap();
    let r = run(&s, Path::new("reverse.toml"), Overrides::default()).unwrap();
    let why = r.no_measurement.as_deref().unwrap();
    assert!(why.contains("reverse"), "{why}");
    let sup = r.supports.as_ref().unwrap();
    assert_eq!(sup.speed, None);
    assert_eq!(sup.load_level, ["unknown"; 2]);
    assert_eq!(sup.simulated_reaction_level, Some(["normal"; 2]));
    let text = run_text(&s, &r);
    assert!(
        text.contains("NOTHING MEASURED") && text.contains("NOT JUDGED"),
        "{text}"
    );
    // Edges too jittery for the core: most rejected, no window; reactions over the limit are
    // reported as over, not as normal.
    let text = bundled("auger")
        .replacen("timer_hz = 10e6", "timer_hz = 10e6\njitter = 1e-3", 1)
        .replacen(
            "support_load_limit = [8000.0, 8000.0]",
            "support_load_limit = [2000.0, 8000.0]",
            1,
        );
    let s = Scene::parse(&text, Path::new("jitter.toml")).unwrap();
    let r = run(&s, Path::new("jitter.toml"), Overrides::default()).unwrap();
    let why = r.no_measurement.as_deref().unwrap();
    assert!(why.contains("rejected"), "{why}");
    let sup = r.supports.as_ref().unwrap();
    assert_eq!(sup.simulated_reaction_level, Some(["over", "normal"]));
    // A bundled scene measures: no such note.
    let s = Scene::parse(bundled("auger"), Path::new("auger.toml")).unwrap();
    let r = run(&s, Path::new("auger.toml"), Overrides::default()).unwrap();
    assert!(r.no_measurement.is_none());
    assert!(r.supports.unwrap().speed.is_some());
}

#[test]
fn a_run_without_an_encoder_says_the_core_measured_nothing() {
    // The kneader without [encoder]: the report listed 427 edges (the simulation's internal
    // coarse encoder) and said nothing about the measurement at all.
    let text = bundled("kneader").replacen("[encoder]\nlines = 1024\ntimer_hz = 84e6\n", "", 1);
    assert!(!text.contains("[encoder]"));
    let text = text
        .replacen("duration = 30.0", "duration = 3.0", 1)
        .replacen("settle = 10.0", "settle = 1.0", 1);
    let s = Scene::parse(&text, Path::new("no-encoder.toml")).unwrap();
    let r = run(&s, Path::new("no-encoder.toml"), Overrides::default()).unwrap();
    assert_eq!(r.edges, 0);
    let why = r.no_measurement.as_deref().unwrap();
    assert!(why.contains("[encoder]"), "{why}");
    let text = run_text(&s, &r);
    assert!(text.contains("NOTHING MEASURED"), "{text}");
}

#[test]
fn work_is_bounded_before_simulating() {
    // Finding 2: `duration = 1e308` was accepted and ran without end; `motor.speed = 1e308`
    // looped forever; memory grew with the duration.
    let e = error("kneader", "duration = 30.0", "duration = 1e308");
    assert_names(&e, &["`simulation.duration = 1e308`", "allowed (0, 1e6] s"]);
    let e = error(
        "auger",
        "speed = 60.0              # rad/s, prescribed",
        "speed = 1e308",
    );
    assert_names(&e, &["`motor.speed = 1e308`"]);
    // Within every range, the edges it would produce are over the limit: refused up front.
    let e = error("auger", "duration = 5.0", "duration = 1e6");
    assert_names(&e, &["`simulation.duration = 1e6`", "edges", "motor.speed"]);
    // A long run without an encoder keeps no per-step trace: the regime is judged from
    // reductions, not from 100 samples per simulated second.
    let text = bundled("one-mass").replacen("duration = 40.0", "duration = 400.0", 1);
    let s = Scene::parse(&text, Path::new("long.toml")).unwrap();
    let options = RunOptions {
        progress: false,
        keep_windows: false,
        ..RunOptions::default()
    };
    let r = run_with(&s, Path::new("long.toml"), Overrides::default(), options).unwrap();
    assert!(r.window_list.is_empty());
    assert_eq!(r.regime_simulated, Some("balancing"));
}

/// The number after `prefix` in `e`.
fn number_after(e: &str, prefix: &str) -> f64 {
    let at = e
        .find(prefix)
        .unwrap_or_else(|| panic!("`{prefix}` not in: {e}"))
        + prefix.len();
    let s: String = e[at..]
        .chars()
        .take_while(|c| c.is_ascii_digit() || matches!(c, '.' | 'e' | '-' | '+'))
        .collect();
    s.parse()
        .unwrap_or_else(|_| panic!("no number after `{prefix}` in: {e}"))
}

/// A speed range the timer cannot hold says which values would fit, each the core's own bound
/// (the longest pitch at the minimum speed fits the counter and lasts at least 2 ticks), to
/// three digits on the side that fits; and a scene with the suggested value is accepted.
#[test]
fn a_speed_range_the_timer_cannot_hold_says_what_would_fit() {
    let pitch = std::f64::consts::TAU / 1024.0;
    // A 16-bit counter at 84 MHz: the slowest pitch must be under 65 535 ticks.
    let e = error(
        "kneader",
        "timer_hz = 84e6\n\n[monitor]\ndelta_limit = 0.06",
        "timer_hz = 84e6\ncounter_bits = 16\n\n[monitor]\ndelta_limit = 0.06\nmin_speed = 0.1",
    );
    assert_names(
        &e,
        &[
            "`monitor.min_speed = 0.1`",
            "more ticks than the counter holds",
        ],
    );
    let speed = number_after(&e, "`monitor.min_speed` at least ");
    let exact = pitch * 84e6 / 65_535.0;
    assert!(
        speed >= exact && speed <= exact * 1.01,
        "{speed} against {exact}: {e}"
    );
    let timer = number_after(&e, "`encoder.timer_hz` at most ");
    let exact = 65_535.0 * 0.1 / pitch;
    assert!(
        timer <= exact && timer >= exact * 0.99,
        "{timer} against {exact}: {e}"
    );
    // 84e6 / 0.1 · pitch = 5.15e6 ticks: 23 bits.
    assert!(e.contains("`encoder.counter_bits` = 23"), "{e}");
    // The suggestion is taken.
    let text = bundled("kneader").replacen(
        "timer_hz = 84e6\n\n[monitor]\ndelta_limit = 0.06",
        &format!("timer_hz = 84e6\ncounter_bits = 16\n\n[monitor]\ndelta_limit = 0.06\nmin_speed = {speed}"),
        1,
    );
    let s = Scene::parse(&text, Path::new("fixed.toml")).unwrap();
    predict(&s, Path::new("fixed.toml")).unwrap();
    // The other side: at 1 MHz a pitch at 5e4 rad/s lasts 0.12 ticks.
    let e = error(
        "kneader",
        "timer_hz = 84e6\n\n[monitor]\ndelta_limit = 0.06",
        "timer_hz = 1e6\n\n[monitor]\ndelta_limit = 0.06\nmin_speed = 5e4",
    );
    assert_names(&e, &["fewer than 2 ticks"]);
    let timer = number_after(&e, "`encoder.timer_hz` at least ");
    let exact = 2.0 * 5e4 / pitch;
    assert!(
        timer >= exact && timer <= exact * 1.01,
        "{timer} against {exact}: {e}"
    );
    let speed = number_after(&e, "`monitor.min_speed` at most ");
    let exact = 1e6 * pitch / 2.0;
    assert!(
        speed <= exact && speed >= exact * 0.99,
        "{speed} against {exact}: {e}"
    );
}

#[test]
fn a_pendulum_inertia_on_balls_or_rollers_is_refused_not_ignored() {
    // `pendulum_inertia = 0.01` beside `kind = "ball"` was checked for its range, then ignored:
    // `predict` gave the same 61.430 rad/s resonance and zones as without it.
    for kind in ["ball", "roller"] {
        let e = error(
            "one-mass",
            "kind = \"ball\"",
            &format!("kind = \"{kind}\"\npendulum_inertia = 0.01"),
        );
        assert_names(
            &e,
            &[
                "`autobalancer.pendulum_inertia = 0.01`",
                "kind = \"pendulum\" only",
                kind,
            ],
        );
    }
    // With a pendulum it is read (and required).
    let text = bundled("one-mass").replacen(
        "kind = \"ball\"",
        "kind = \"pendulum\"\npendulum_inertia = 0.01",
        1,
    );
    assert!(Scene::parse(&text, Path::new("ok.toml")).is_ok());
}

#[test]
fn refusals_quote_arrays_as_written_and_say_what_would_be_valid() {
    // `between = [1, 1]` was quoted as "`coupling[1].between = [1, 1] (the default)`":
    // written arrays are kept element by element, and the whole array was not found.
    let e = error("two-mass", "between = [1, 2]", "between = [1, 1]");
    assert_names(
        &e,
        &["`coupling[1].between = [1, 1]`", "two different platforms"],
    );
    assert!(!e.contains("the default"), "{e}");
    // Two tables coupling the same pair: "`coupling`: contradict each other", no hint.
    let e = error(
        "two-mass",
        "[autobalancer]",
        "[[coupling]]\nbetween = [2, 1]\nstiffness = 1.0e5\ndamping = 0.0\n\n[autobalancer]",
    );
    assert_names(
        &e,
        &["coupling", "same two platforms", "one table per pair"],
    );
    // Supports in one plane: "`rotor.support_b = 0.0`, `rotor.support_a = 0.0`: contradict
    // each other", without saying what separation is needed.
    let e = error("auger", "support_b = 4.0", "support_b = 0.0");
    assert_names(
        &e,
        &[
            "`rotor.support_b = 0.0`",
            "`rotor.support_a = 0.0`",
            "two distinct planes",
            "1e-6",
        ],
    );
}

/// A platform's or coupling's damping or the balancer's housing mass left out was taken as 0
/// without a word (the two-mass machine undamped: its table "gathering" up to 2317 rad/s,
/// where with its damping the balancing position is stable from 84 rad/s): they are required,
/// 0 written where meant.
#[test]
fn damping_and_housing_mass_are_written_not_assumed() {
    for (scene, line, key) in [
        ("two-mass", "damping = 200.0", "damping"),
        ("three-mass", "damping = 50.0", "damping"),
        ("one-mass", "housing_mass = 5.0", "housing_mass"),
    ] {
        let e = error(scene, line, "");
        assert!(
            e.contains(&format!("missing field `{key}`")),
            "{scene}: {e}"
        );
    }
}

/// A rotor unbalance the scene leaves out is half the capacity, and the report says it was
/// assumed (it printed D like a value of the scene's).
#[test]
fn an_assumed_rotor_unbalance_is_said_to_be_assumed() {
    let line = "rotor_unbalance = 0.05  # kg·m, the unbalance the loads balance\n";
    let with = bundled("one-mass");
    assert!(with.contains(line));
    let without = with.replacen(line, "", 1);
    let path = Path::new("one-mass.toml");
    let said = |text: &str| {
        let p = predict(&Scene::parse(text, path).unwrap(), path).unwrap();
        let a = p.autobalancer.as_ref().unwrap();
        (a.capacity, a.rotor_unbalance, prediction_text(&p))
    };
    let (cap, d, text) = said(&without);
    assert_eq!(d, 0.5 * cap);
    assert!(text.contains("half the capacity assumed"), "{text}");
    let (_, d, text) = said(with);
    assert_eq!(d, 0.05);
    assert!(!text.contains("assumed"), "{text}");
}

/// A shaft measured above the rotor's service speed: the permissible unbalance was allotted for
/// the service speed (U_per ∝ 1/ω), so the run says the levels are judged too leniently, with
/// the share the grade allows there (60/80 = 75 %); at the service speed it says nothing.
#[test]
fn a_run_above_the_service_speed_says_the_unbalance_limit_was_allotted_lower() {
    let path = Path::new("auger.toml");
    let prescribed = "speed = 60.0              # rad/s, prescribed";
    let report = |text: &str| {
        let s = Scene::parse(text, path).unwrap();
        let r = run(&s, path, Overrides::default()).unwrap();
        let text = run_text(&s, &r);
        (r.supports.unwrap().above_service_speed, text)
    };
    let (w, text) = report(&bundled("auger").replacen(prescribed, "speed = 80.0", 1));
    let w = w.unwrap();
    assert!(
        w.contains("service speed 60") && w.contains("75.0 %"),
        "{w}"
    );
    assert!(text.contains(&w), "{text}");
    assert_eq!(report(bundled("auger")).0, None);
}

/// A balancer whose loads move far faster than the rotor turns (0.1 mg loads at 10 N·s/m on
/// a 1 mg platform): the stability scan ran for minutes with nothing printed, then stopped at
/// its step budget. Its scan now starts where a revolution lasts 1000 periods of the loads'
/// relaxation (7.14e4 rad/s), below which the table follows the criterion, naming the keys
/// that set it, and ends within a few hundred monodromy matrices.
#[test]
fn a_stability_scan_of_loads_far_faster_than_the_rotor_starts_where_it_can() {
    let text = "[[platform]]\nmass = 1e-6\nstiffness = 4e5\ndamping = 0.0\n[autobalancer]\nkind = \"ball\"\n\
                platform = 1\nloads = 2\nload_mass = 1e-7\nradius = 0.1\nhousing_mass = 5.0\n\
                viscosity = 10.0\nrotor_unbalance = 1e-9\n";
    let path = Path::new("fast-loads.toml");
    let p = predict(&Scene::parse(text, path).unwrap(), path).unwrap();
    let st = p.autobalancer.unwrap().stability.unwrap();
    let below = st.criterion_below.unwrap();
    assert!(
        below.set_by.contains("autobalancer.load_mass")
            && (below.speed / (10.0 / (1.4 * 1e-7) / 1000.0) - 1.0).abs() < 1e-9,
        "{below:?}"
    );
    assert!(st.evaluations < 500, "{}", st.evaluations);
}

#[test]
fn a_sweep_below_the_lowest_integrable_speed_is_refused_naming_from() {
    // The two-mass machine hung only on its coupling (platforms at 1e-6 N/m): a revolution
    // below 0.0447 rad/s lasts over 1000 periods of the coupling's motion. `--from 1e-6`
    // ran the stability analysis into a million steps and blamed `autobalancer`, `--from
    // 1e-300` ended in "step size underflow"; both are refused naming `--from` and the speed.
    use host_sim::studies::sweep::{sweep, SweepRequest};
    let text =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/two-mass.toml"))
            .unwrap()
            .replace("stiffness = 4.0e5", "stiffness = 1e-6");
    let path = Path::new("hung.toml");
    let scene = Scene::parse(&text, path).unwrap();
    for from in [1e-6, 1e-300] {
        let request = SweepRequest {
            from,
            to: 100.0,
            steps: 3,
            together: false,
        };
        let e = sweep(&scene, path, &request, false)
            .err()
            .unwrap()
            .to_string();
        assert!(
            e.contains("`--from`")
                && e.contains("below 4.4721e-2 rad/s")
                && e.contains("platform[1].stiffness"),
            "{e}"
        );
    }
    // predict says where its scan starts and why.
    let text = prediction_text(&predict(&scene, path).unwrap());
    assert!(
        text.contains("the scan starts at 4.4721e-2 rad/s")
            && text.contains("the regime table follows the criterion below it"),
        "{text}"
    );
}

/// Platforms the balancer's platform reaches through no coupling are no part of the machine:
/// three equal platforms and no `[[coupling]]` had two modes the rotor cannot excite listed as
/// resonances and additional speeds, with capture lines copied from the first. Refused,
/// naming them; once coupled, the same platforms are a machine.
#[test]
fn platforms_joined_to_nothing_are_named() {
    let platforms = "[[platform]]\nmass = 100.0\nstiffness = 4e5\ndamping = 200.0\n".repeat(3);
    let balancer = "[autobalancer]\nkind = \"ball\"\nplatform = 2\nloads = 2\nload_mass = 0.5\n\
                    radius = 0.1\nhousing_mass = 5.0\nviscosity = 10.0\n";
    let path = Path::new("bad.toml");
    let refusal = |text: &str| match Scene::parse(text, path) {
        Err(e) => Some(e.to_string()),
        Ok(s) => predict(&s, path).err().map(|e| e.to_string()),
    };
    let alone = format!("{platforms}{balancer}");
    let e = refusal(&alone).unwrap();
    assert_names(
        &e,
        &[
            "`autobalancer.platform = 2`",
            "platform[1], platform[3]",
            "no [[coupling]]",
        ],
    );
    let one = format!(
        "{platforms}[[coupling]]\nbetween = [1, 2]\nstiffness = 1e5\ndamping = 50.0\n{balancer}"
    );
    let e = refusal(&one).unwrap();
    assert_names(&e, &["platform[3] is joined"]);
    let chained = format!(
        "{platforms}[[coupling]]\nbetween = [1, 2]\nstiffness = 1e5\ndamping = 50.0\n\
         [[coupling]]\nbetween = [3, 2]\nstiffness = 1e5\ndamping = 50.0\n{balancer}"
    );
    assert_eq!(refusal(&chained), None);
}

/// J(φ) was checked by the sufficient condition Σ|amplitude| < inertia + flywheel, and refused
/// with a bare "`shaft.inertia_harmonics`, `shaft.inertia = 0.323`, `shaft.flywheel = 0.0`:
/// contradict each other": a crank-slider's series (J ≥ 0.1 everywhere, Σ|a| above its mean)
/// or 0.323 + 0.2·(cos φ + cos 2φ) (least 0.098) could not be run. Now J(φ)'s least value
/// decides, and the refusal of one that reaches 0 says where and quotes the amplitudes.
#[test]
fn a_reduced_inertia_is_refused_only_where_it_reaches_zero() {
    let with = |harmonics: &str| {
        bundled("kneader").replacen(
            "flywheel = 0.0",
            &format!("flywheel = 0.0\ninertia_harmonics = {harmonics}"),
            1,
        )
    };
    let e = Scene::parse(
        &with("[{ order = 1.0, amplitude = 0.323, phase = 0.0 }]"),
        Path::new("bad.toml"),
    )
    .err()
    .unwrap()
    .to_string();
    assert_names(
        &e,
        &[
            "`shaft.inertia_harmonics` (amplitudes 0.323)",
            "`shaft.inertia = 0.323`",
            "`shaft.flywheel = 0.0`",
            "falls to 0 kg·m² at φ = 3.1416 rad",
            "the reduced inertia must stay positive",
        ],
    );
    // 0.323 + 0.2·cos φ − 0.3·cos 2φ: least −0.177 at φ = π.
    let e = Scene::parse(
        &with("[{ order = 1.0, amplitude = 0.2 }, { order = 2.0, amplitude = -0.3 }]"),
        Path::new("bad.toml"),
    )
    .err()
    .unwrap()
    .to_string();
    assert_names(
        &e,
        &[
            "(amplitudes 0.2, -0.3)",
            "falls to -0.1770 kg·m² at φ = 3.1416 rad",
        ],
    );
    // Positive everywhere although Σ|amplitude| = 0.4 > 0.323: predicted and run.
    let positive = with("[{ order = 1.0, amplitude = 0.2 }, { order = 2.0, amplitude = 0.2 }]");
    let s = Scene::parse(&positive, Path::new("ok.toml")).unwrap();
    let p = predict(&s, Path::new("ok.toml")).unwrap();
    assert!(p.irregularity.unwrap().delta.unwrap() > 0.9);
    let short = positive
        .replacen("duration = 30.0", "duration = 1.0", 1)
        .replacen("settle = 10.0", "settle = 0.5", 1);
    let s = Scene::parse(&short, Path::new("ok.toml")).unwrap();
    run(&s, Path::new("ok.toml"), Overrides::default()).unwrap();
}

/// A negative prescribed speed with `[cranking]` was refused as "`motor.points`: must not be
/// negative", a key of `model = "profile"` the scene did not have, without the value or a
/// reason. The key as written, its value and why are said now; without `[cranking]` the
/// same speeds still run the shaft backwards.
#[test]
fn a_negative_speed_under_a_cranking_ripple_names_its_own_key() {
    let base = "[shaft]\ninertia = 1.0\n[motor]\nMOTOR\n[encoder]\nlines = 256\ntimer_hz = 10e6\n\
                [simulation]\nduration = 0.2\n";
    let cranking = "[cranking]\nripple = 0.1\nstrokes = 2\n";
    for (motor, named) in [
        ("model = \"speed\"\nspeed = -50.0", "`motor.speed = -50.0`"),
        (
            "model = \"ramp\"\nfrom = -1.0\nto = 100.0\nduration = 0.1",
            "`motor.from = -1.0`",
        ),
        (
            "model = \"ramp\"\nfrom = 10.0\nto = -1e2\nduration = 0.1",
            "`motor.to = -1e2`",
        ),
    ] {
        let text = format!("{}{cranking}", base.replace("MOTOR", motor));
        let e = Scene::parse(&text, Path::new("bad.toml"))
            .err()
            .unwrap()
            .to_string();
        assert_names(
            &e,
            &[
                named,
                "a cranking ripple needs a forward speed",
                "allowed [0, 1e5] rad/s",
            ],
        );
        assert!(!e.contains("motor.points"), "{e}");
        // Without the ripple: accepted.
        let plain = base.replace("MOTOR", motor);
        let s = Scene::parse(&plain, Path::new("ok.toml")).unwrap();
        run(&s, Path::new("ok.toml"), Overrides::default()).unwrap();
    }
}

/// `missing = 2` without `framing` was refused as "only with framing = \"missing-tooth\" (this
/// encoder has no gap)", although the key docs say `missing` implies the framing as `wheel`,
/// `gaps` and `teeth` do: it implies it now. A prescaler on a wheel was refused with a bare
/// "`encoder.prescaler = 2`, `encoder.framing = \"missing-tooth\"` (the default): contradict
/// each other": the framing is the wheel's, not a default, and the reason is said.
#[test]
fn missing_teeth_imply_their_framing_and_a_prescaler_on_a_wheel_says_why() {
    let e = error(
        "kneader",
        "lines = 1024",
        "lines = 36\nmissing = 2\nprescaler = 2",
    );
    assert_names(
        &e,
        &[
            "`encoder.prescaler = 2`",
            "framing = \"missing-tooth\", implied by `encoder.missing = 2`",
            "the prescaler is for uniform discs only",
        ],
    );
    assert!(!e.contains("the default"), "{e}");
    let e = error("kneader", "lines = 1024", "wheel = \"36-2\"\nprescaler = 2");
    assert_names(
        &e,
        &[
            "`encoder.prescaler = 2`",
            "implied by `encoder.wheel = \"36-2\"`",
            "the prescaler is for uniform discs only",
        ],
    );
    // A uniform disc whose lines the prescaler does not divide: said.
    let e = error("kneader", "lines = 1024", "lines = 30\nprescaler = 4");
    assert_names(
        &e,
        &["`encoder.prescaler = 4`", "divide the disc's 30 lines"],
    );
    // Missing teeth alone: a 36-2 wheel, framed by its gap, that runs.
    let text = bundled("kneader")
        .replacen("lines = 1024", "lines = 36\nmissing = 2", 1)
        .replacen("duration = 30.0", "duration = 3.0", 1)
        .replacen("settle = 10.0", "settle = 1.0", 1);
    let s = Scene::parse(&text, Path::new("ok.toml")).unwrap();
    assert_eq!(
        s.encoder.as_ref().unwrap().framing(),
        host_sim::app::scene::FramingSpec::MissingTooth
    );
    let r = run(&s, Path::new("ok.toml"), Overrides::default()).unwrap();
    assert!(r.delta_measured.is_some());
}

/// A count the file gives was quoted as a default: "`unbalance = 100 tables (the default)`:
/// at most 32 unbalances", "`motor.points = 0 points (the default)`"; a load of 9 harmonics got
/// a bare "more than the fixed capacity holds". Counts are quoted as the file's, with the
/// limit (README's limits table lists them).
#[test]
fn counts_written_in_the_file_are_not_called_defaults() {
    let unbalance = "[[unbalance]]\nz = 1.0\namount = 1e-3\nangle = 0.0\n";
    let mut text = bundled("auger").to_string();
    for _ in 0..40 {
        text.push_str(unbalance);
    }
    let e = Scene::parse(&text, Path::new("bad.toml"))
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("`unbalance = ") && e.contains(" tables`: at most 32 unbalances"),
        "{e}"
    );
    assert!(!e.contains("the default"), "{e}");
    let e = error(
        "auger",
        "model = \"speed\"\nspeed = 60.0              # rad/s, prescribed",
        "model = \"profile\"\npoints = []",
    );
    assert_names(&e, &["`motor.points = 0 points`: 1 to 10000 points"]);
    assert!(!e.contains("the default"), "{e}");
    let nine = (1..=9)
        .map(|i| format!("{{ order = {i}.0, amplitude = 1.0 }}"))
        .collect::<Vec<_>>()
        .join(", ");
    let e = error(
        "kneader",
        "harmonics = [{ order = 0.125, amplitude = 12.0, phase = 0.0 }]",
        &format!("harmonics = [{nine}]"),
    );
    assert_names(
        &e,
        &["`load.harmonics = 9 harmonics`", "at most 8 harmonics"],
    );
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../README.md"))
            .unwrap();
    assert!(readme.contains("`[[unbalance]]` at most 32"));
}

/// An integer key beyond its storage type (negative, or above 255 or 65535) is refused like
/// any other value outside its range, naming the key, the value as written and the range:
/// serde alone had said "invalid value: integer `70000`, expected u16".
#[test]
fn scene_integers_beyond_their_type_are_refused_with_their_range() {
    let cases: &[(&str, &str, &str, &[&str])] = &[
        (
            "kneader",
            "lines = 1024",
            "lines = 70000",
            &["`encoder.lines = 70000`", "allowed 2 to 8192"],
        ),
        (
            "kneader",
            "lines = 1024",
            "lines = -1",
            &["`encoder.lines = -1`", "allowed 2 to 8192"],
        ),
        (
            "kneader",
            "[monitor]",
            "[monitor]\nwindow_revolutions = 70000",
            &["`monitor.window_revolutions = 70000`", "allowed 1 to 1024"],
        ),
        (
            "kneader",
            "lines = 1024",
            "lines = 1024\ncounter_bits = 300",
            &["`encoder.counter_bits = 300`", "allowed 16 to 32"],
        ),
        (
            "kneader",
            "lines = 1024",
            "lines = 1024\nprescaler = 256",
            &["`encoder.prescaler = 256`", "allowed 1, 2, 4 or 8"],
        ),
        (
            "kneader",
            "lines = 1024",
            "lines = 1024\nestimator_edges = -3",
            &["`encoder.estimator_edges = -3`", "allowed 1 to 32"],
        ),
        (
            "kneader",
            "lines = 1024",
            "lines = 36\nmissing = 300",
            &["`encoder.missing = 300`", "1 to 33 on 36 positions"],
        ),
        (
            "kneader",
            "lines = 1024",
            "lines = 36\nteeth = [0, 1, 70000]",
            &["`encoder.teeth[3] = 70000`", "0 to 35"],
        ),
        (
            "kneader",
            "lines = 1024",
            "lines = 36\ngaps = [[70000, 2]]",
            &["`encoder.gaps[1][1] = 70000`", "0 to 35"],
        ),
        (
            "kneader",
            "lines = 1024",
            "wheel = \"36-300\"",
            &["`encoder.wheel = \"36-300\"`", "1 to 33 on 36 positions"],
        ),
        (
            "kneader",
            "seed = 1",
            "seed = -1",
            &["`simulation.seed = -1`", "allowed 0 to"],
        ),
        (
            "one-mass",
            "platform = 1",
            "platform = 300",
            &["`autobalancer.platform = 300`", "allowed 1 to 1"],
        ),
        (
            "one-mass",
            "loads = 2",
            "loads = -2",
            &["`autobalancer.loads = -2`", "allowed 2 to"],
        ),
        (
            "two-mass",
            "between = [1, 2]",
            "between = [1, 300]",
            &["`coupling[1].between[2] = 300`", "allowed 1 to 2"],
        ),
    ];
    for (scene, from, to, want) in cases {
        let e = error(scene, from, to);
        assert!(!e.contains("expected u"), "{to}: {e}");
        for w in *want {
            assert!(e.contains(w), "{to}: `{w}` not in: {e}");
        }
    }
    // A value that is no integer at all still says what is wanted, not a storage type.
    let e = error("kneader", "lines = 1024", "lines = 2.5");
    assert!(e.contains("expected a whole number"), "{e}");
}

/// `run kneader --capture … --capture-format sigrok` wrote 23.4 GB (a row for every sample of
/// 30 s at 50 MHz) without a word. A sigrok file of every sample is now estimated before the
/// run and refused above the bound (1e9 bytes unless raised), with the estimate and what makes
/// it smaller; nothing is written then. Under the bound the file is written, and the estimate
/// holds it; `dedup` writes only the changes and is never refused for its size.
#[test]
fn a_capture_of_every_sample_too_large_is_refused_with_its_size() {
    use host_sim::app::run::CaptureTarget;
    let text = "[motor]\nmodel = \"speed\"\nspeed = 100.0\n[encoder]\nlines = 64\n\
                timer_hz = 1e6\n[simulation]\nduration = 0.2\n[capture]\nsample_rate = 1e6\nDEDUP\n";
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("cap.csv");
    let capture = |text: &str, max: f64| {
        let scene = Scene::parse(text, Path::new("bad.toml")).unwrap();
        let options = RunOptions {
            capture: Some(CaptureTarget {
                path: file.clone(),
                format: host_sim::app::logic::CaptureFormat::Sigrok,
            }),
            capture_max_bytes: max,
            ..RunOptions::default()
        };
        run_with(&scene, Path::new("bad.toml"), Overrides::default(), options)
    };
    let every = text.replace("DEDUP", "");
    let e = capture(&every, 1e5).unwrap_err().to_string();
    assert_names(
        &e,
        &[
            "would be about",
            "2.000e5 rows",
            "more than the 1e5 bytes",
            "`[capture] dedup = true`",
            "--capture-max-bytes",
        ],
    );
    assert!(!file.exists(), "nothing is written when refused");
    // The estimate, from the message, against the file written under a raised bound.
    let estimate: f64 = e
        .split("would be about ")
        .nth(1)
        .and_then(|x| x.split(' ').next())
        .unwrap()
        .parse()
        .unwrap();
    capture(&every, 1e9).unwrap();
    let written = std::fs::metadata(&file).unwrap().len() as f64;
    assert!(
        written <= estimate * 1.001 && written > 0.8 * estimate,
        "{written} {estimate}"
    );
    // Only the changes: written under the same small bound.
    let r = capture(&text.replace("DEDUP", "dedup = true"), 1e5).unwrap();
    assert!(r.capture_rows.unwrap() < 1000, "{:?}", r.capture_rows);
}
