//! Shared test harness of the `drive-sim` command-line tests: running the built binary.

use std::process::Command;

/// Runs `drive-sim` with `args`: whether it succeeded, its standard output and its standard
/// error.
pub fn drive_sim(args: &[&str]) -> (bool, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_drive-sim"))
        .args(args)
        .output()
        .expect("drive-sim runs");
    (
        out.status.success(),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}
