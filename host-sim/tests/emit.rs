//! `drive-sim predict SCENE --emit rust`: the table the firmware example includes is what the
//! command writes now (so it cannot go stale), and `--out` writes the same.

mod cli_common;

use cli_common::drive_sim;
use std::path::PathBuf;

/// The firmware example's checked-in table.
fn firmware_table() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../examples/qemu/src/three_mass_table.rs")
}

#[test]
fn the_firmware_table_is_what_predict_emits_now() {
    let (ok, out, err) = drive_sim(&["predict", "three-mass", "--emit", "rust"]);
    assert!(ok, "{err}");
    let file = std::fs::read_to_string(firmware_table()).expect("the firmware table exists");
    assert!(
        out == file,
        "examples/qemu/src/three_mass_table.rs is stale: regenerate it with \
         `cargo run --release -p host-sim -- predict three-mass --emit rust \
         --out examples/qemu/src/three_mass_table.rs`"
    );
    assert_eq!(
        host_sim::app::emit::emit_text("three-mass", host_sim::app::emit::Format::Rust).unwrap(),
        out
    );
}

#[test]
fn out_writes_the_same_and_errors_name_the_cause() {
    let scratch_dir = tempfile::Builder::new()
        .prefix("drive-sim-emit-")
        .tempdir()
        .unwrap();
    let dir = scratch_dir.path();
    let file = dir.join("table.rs");
    let path = file.to_str().unwrap();
    let (ok, out, err) = drive_sim(&["predict", "two-mass", "--emit", "rust", "--out", path]);
    assert!(ok && out.is_empty(), "{err}");
    let (ok, printed, err) = drive_sim(&["predict", "two-mass", "--emit", "rust"]);
    assert!(ok, "{err}");
    assert_eq!(std::fs::read_to_string(&file).unwrap(), printed);
    assert!(printed.contains("pub const MACHINE: MachineTable<'static>"));
    // No machine in the scene; an unwritable output; --out without --emit.
    let (ok, _, err) = drive_sim(&["predict", "kneader", "--emit", "rust"]);
    assert!(
        !ok && err.contains("kneader.toml") && err.contains("[autobalancer]"),
        "{err}"
    );
    let missing = dir.join("no/such/dir/table.rs");
    let (ok, _, err) = drive_sim(&[
        "predict",
        "three-mass",
        "--emit",
        "rust",
        "--out",
        missing.to_str().unwrap(),
    ]);
    assert!(
        !ok && err.contains("table.rs") && err.contains("cannot write"),
        "{err}"
    );
    let (ok, _, err) = drive_sim(&["predict", "three-mass", "--out", path]);
    assert!(!ok && err.contains("--emit"), "{err}");
}

/// The emitted table carries the margin `run` and `sweep` classify with: the scene's
/// `[monitor] regime_margin` (it said `TABLE_MARGIN`, 1 %, whatever the scene set, and a
/// firmware built as told committed at speeds the host calls near-characteristic).
#[test]
fn the_emitted_margin_is_the_scenes() {
    let scratch_dir = tempfile::Builder::new()
        .prefix("drive-sim-emit-")
        .tempdir()
        .unwrap();
    let scene = scratch_dir.path().join("wide.toml");
    let bundled = std::fs::read_to_string(
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("scenes/one-mass.toml"),
    )
    .unwrap();
    std::fs::write(
        &scene,
        format!("{bundled}\n[monitor]\nregime_margin = 0.05\n"),
    )
    .unwrap();
    let (ok, out, err) = drive_sim(&["predict", scene.to_str().unwrap(), "--emit", "rust"]);
    assert!(ok, "{err}");
    assert!(
        out.contains("pub const REGIME_MARGIN: f32 = 0.05;"),
        "{out}"
    );
    assert!(out.contains("Classifier::from_table(&REGIMES, REGIME_MARGIN, REGIME_MARGIN / 2.0)"));
    let (ok, out, err) = drive_sim(&["predict", "one-mass", "--emit", "rust"]);
    assert!(
        ok && out.contains("pub const REGIME_MARGIN: f32 = 0.01;"),
        "{err}"
    );
}
