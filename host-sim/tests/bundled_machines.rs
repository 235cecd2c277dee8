//! The bundled scenes' auto-balancer machines: `Machine::new` (zones from polynomial roots,
//! captures from an f32 scan refined in f64) against the scan it replaced,
//! `Machine::new_scanned`, with the tolerances `compare_with_scan` states.

#[allow(clippy::unwrap_used, clippy::expect_used)]
#[path = "../../src/testutil.rs"]
mod testutil;

use drive_monitor::balancer::{Machine, SearchOptions};
use host_sim::app::predict::machine;
use host_sim::app::scene::{resolve, BUNDLED};

#[test]
fn every_bundled_machine_matches_the_scan() {
    let mut compared = Vec::new();
    for (file, _) in BUNDLED {
        let file = file.strip_suffix(".toml").unwrap_or(file);
        let (scene, path) = resolve(file).unwrap();
        let Some(fast) = machine(&scene, &path).unwrap() else {
            continue;
        };
        let scan = Machine::new_scanned(*fast.config(), SearchOptions::default()).unwrap();
        let a = testutil::compare_with_scan(&fast, &scan, file);
        // On these machines the scan found every maximum: nothing to excuse.
        assert_eq!(a.scan_missed, 0, "{file}: {a:?}");
        println!("{file}: {a:?}");
        compared.push(file);
    }
    assert_eq!(
        compared,
        [
            "one-mass",
            "one-mass-runup",
            "one-mass-undersized",
            "one-mass-motor-runup",
            "two-mass",
            "three-mass"
        ]
    );
}
