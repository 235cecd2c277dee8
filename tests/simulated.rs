//! The core driven by the simulator: encoder edges of simulated machines through the same
//! monitor that runs on the target, compared with the design-time prediction.

use host_sim::app::run::{run, Overrides};
use host_sim::app::scene::{resolve, Scene};
use std::path::Path;

fn scene(text: &str) -> Scene {
    Scene::parse(text, Path::new("test.toml")).expect("scene parses")
}

const KNEADER: &str = include_str!("../host-sim/scenes/kneader.toml");

#[test]
fn kneader_measured_delta_is_within_one_percent_of_the_prediction() {
    let (s, path) = resolve("kneader").unwrap();
    let r = run(&s, &path, Overrides::default()).unwrap();
    let measured = r.delta_measured.expect("steady windows");
    let predicted = r.delta_predicted.expect("steady state");
    assert!((predicted - 0.030656).abs() < 1e-6, "{predicted}");
    assert!(
        (measured / predicted - 1.0).abs() < 0.01,
        "{measured} vs {predicted}"
    );
    // The window is the load cycle: 8 revolutions, so about 134/(16π) windows per second.
    assert!(r.windows > 70, "{}", r.windows);
    assert_eq!(r.invalid_windows, 0);
    assert!(r.noise_floor.unwrap() < 1e-4);
    assert!(r.alarms.is_empty(), "δ 0.031 is within the limit 0.06");
    // Only the effects the scene calls for were evaluated.
    assert_eq!(r.effects, vec!["motor", "load"]);
    assert!(!r.component_evaluations.contains_key("vibration"));
}

#[test]
fn a_lower_limit_raises_the_alarm_once_steady() {
    let text = KNEADER.replace("delta_limit = 0.06", "delta_limit = 0.02");
    let r = run(&scene(&text), Path::new("test.toml"), Overrides::default()).unwrap();
    assert_eq!(r.alarms.len(), 1, "{:?}", r.alarms);
    assert_eq!(r.alarms[0].event, "raised");
}

#[test]
fn a_flywheel_brings_measured_and_predicted_delta_down_together() {
    let text = KNEADER.replace("flywheel = 0.0", "flywheel = 0.734");
    let r = run(&scene(&text), Path::new("test.toml"), Overrides::default()).unwrap();
    let (m, p) = (r.delta_measured.unwrap(), r.delta_predicted.unwrap());
    assert!((p - 0.01).abs() < 2e-4, "{p}");
    assert!((m / p - 1.0).abs() < 0.02, "{m} vs {p}");
}

#[test]
fn a_16_bit_timer_measures_the_same_delta() {
    // A 16-bit counter at 84 MHz wraps every 780 µs: the slowest speed it can time on 1024
    // lines is 7.9 rad/s, so the default minimum speed of 1 rad/s is rejected.
    let text = KNEADER.replace("timer_hz = 84e6", "timer_hz = 84e6\ncounter_bits = 16");
    let err = run(&scene(&text), Path::new("test.toml"), Overrides::default()).unwrap_err();
    assert!(
        err.to_string()
            .contains("monitor.min_speed = 1` (the default)"),
        "{err}"
    );
    let text = text.replace("delta_limit = 0.06", "delta_limit = 0.06\nmin_speed = 20.0");
    let r = run(&scene(&text), Path::new("test.toml"), Overrides::default()).unwrap();
    let (m, p) = (r.delta_measured.unwrap(), r.delta_predicted.unwrap());
    assert!((m / p - 1.0).abs() < 0.01, "{m} vs {p}");
    assert_eq!(r.invalid_windows, 0);
}

#[test]
fn faulty_encoders_give_invalid_windows_with_their_reasons() {
    let text = KNEADER.replace(
        "timer_hz = 84e6",
        "timer_hz = 84e6\ndrop_probability = 2e-5\nglitch_probability = 2e-5",
    );
    let r = run(&scene(&text), Path::new("test.toml"), Overrides::default()).unwrap();
    assert!(r.invalid_windows > 0);
    let reasons: u32 = r.invalid_reasons.values().sum();
    assert_eq!(reasons, r.invalid_windows);
    assert!(
        r.invalid_reasons.contains_key("glitch") && r.invalid_reasons.contains_key("missing-edge"),
        "{:?}",
        r.invalid_reasons
    );
    // The valid windows still measure the drive.
    let (m, p) = (r.delta_measured.unwrap(), r.delta_predicted.unwrap());
    assert!((m / p - 1.0).abs() < 0.01, "{m} vs {p}");
}

#[test]
fn an_unlearned_disc_error_shows_in_delta() {
    // Run-out of e/r = 2e-3 adds a false once-per-turn ripple that δ cannot tell from the
    // shaft's: without a learned correction δ measures the disc too.
    let text = KNEADER.replace("timer_hz = 84e6", "timer_hz = 84e6\nrunout = 2e-3");
    let r = run(&scene(&text), Path::new("test.toml"), Overrides::default()).unwrap();
    let (m, p) = (r.delta_measured.unwrap(), r.delta_predicted.unwrap());
    assert!(m > p * 1.05, "{m} vs {p}");
}

#[test]
fn vibration_scenes_agree_with_the_criterion_at_their_speed() {
    for name in ["one-mass", "two-mass", "three-mass"] {
        let (s, path) = resolve(name).unwrap();
        let r = run(&s, &path, Overrides::default()).unwrap();
        assert_eq!(r.regime_predicted, Some("balancing"), "{name}");
        assert_eq!(r.regime_simulated, Some("balancing"), "{name}");
        assert!(
            r.residual_relative.unwrap() < 1e-6,
            "{name}: {:?}",
            r.residual_relative
        );
        assert_eq!(r.effects, vec!["vibration"], "{name}");
        // Prescribed speed: the core measures exactly it.
        let w = r.speed_measured.unwrap();
        let set = match &s.motor {
            Some(host_sim::app::scene::MotorSpec::Speed { speed }) => *speed,
            _ => unreachable!(),
        };
        assert!((w / set - 1.0).abs() < 1e-5, "{name}: {w} vs {set}");
    }
}

#[test]
fn below_resonance_the_loads_gather_as_predicted() {
    let (s, path) = resolve("one-mass").unwrap();
    let r = run(
        &s,
        &path,
        Overrides {
            speed: Some(40.0),
            loads_together: false,
        },
    )
    .unwrap();
    assert_eq!(r.regime_predicted, Some("gathering"));
    assert_eq!(r.regime_simulated, Some("gathering"));
}

#[test]
fn support_loads_from_the_core_match_the_simulated_reactions() {
    for name in ["auger", "auger-overhung"] {
        let (s, path) = resolve(name).unwrap();
        let r = run(&s, &path, Overrides::default()).unwrap();
        let sup = r.supports.unwrap();
        for k in 0..2 {
            let (core, sim) = (
                sup.peak_load[k].expect("a measured speed"),
                sup.simulated_peak_reaction[k],
            );
            // f32 runtime against the f64 simulation sampled at step ends: 1e-4 relative.
            assert!(
                (core / sim - 1.0).abs() < 1e-4,
                "{name} support {k}: {core} vs {sim}"
            );
        }
        assert_eq!(sup.load_level, ["normal", "normal"], "{name}");
        assert_eq!(r.effects, vec!["rotor-loads"]);
    }
}
