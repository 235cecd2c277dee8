//! `drive-sim predict SCENE --emit rust [--out FILE]`: the scene's auto-balancer machine
//! analysed on the host ([`Machine::new`]) and written as Rust source: one `const`
//! [`MachineTable`](drive_monitor::balancer::MachineTable) holding its characteristic speeds,
//! zones and capture windows. Firmware includes the file as a module and builds its
//! classifier at compile time with the `const fn`
//! [`Classifier::from_table`](drive_monitor::balancer::Classifier::from_table), so the target
//! never analyses the machine (nor links the analysis).
//!
//! Every f64 is written in Rust's shortest round-trip form (`{:?}`: the fewest digits that
//! read back as the same bits; `str::parse` and rustc's float literals both round correctly),
//! so the constant holds exactly the values computed here. The firmware example
//! (`examples/qemu`) compares its checked-in table with `Machine::new` run on the target, and
//! a host test compares that file with what this writes now.

use crate::app::predict::machine;
use crate::app::scene::{resolve, SceneError};
use drive_monitor::balancer::{Machine, ZoneKind};
use std::fmt::Write as _;
use std::path::PathBuf;

/// What `--emit` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Rust source: a `const MACHINE: MachineTable` for firmware.
    Rust,
}

/// Why nothing could be emitted.
#[derive(Debug, thiserror::Error)]
pub enum EmitError {
    /// The scene could not be read or is invalid.
    #[error(transparent)]
    Scene(#[from] SceneError),
    /// The scene has no auto-balancer machine to analyse.
    #[error("{file}: has no [autobalancer]: --emit rust writes an auto-balancer machine's table")]
    NoMachine {
        /// The scene file.
        file: PathBuf,
    },
}

/// `x` as a Rust f64 literal that reads back as the same bits (the shortest round-trip
/// decimal, e.g. `49.7406201472722`, `0.0`, `1e-7`).
pub fn literal(x: f64) -> String {
    format!("{x:?}")
}

/// The Rust source for the machine of the scene named `scene` (as given on the command line),
/// with its one-line `description`.
pub fn rust_table(scene: &str, description: Option<&str>, m: &Machine) -> String {
    let list = |v: &[f64]| v.iter().map(|&x| literal(x)).collect::<Vec<_>>().join(", ");
    let mut s = String::new();
    let _ = writeln!(
        s,
        "//! The `{scene}` scene's auto-balancer machine, analysed on the host for firmware:\n\
         //! written by `drive-sim predict {scene} --emit rust`; regenerate rather than edit.\n//!"
    );
    if let Some(d) = description {
        let _ = writeln!(s, "//! {d}.\n//!");
    }
    let _ = writeln!(
        s,
        "//! Speeds in rad/s. Each f64 is Rust's shortest round-trip form of the value\n\
         //! `Machine::new` computed (default `SearchOptions`): it reads back as the same bits.\n"
    );
    let mut types = vec!["MachineTable", "Zone", "ZoneKind"];
    if !m.capture_windows().is_empty() {
        types.insert(0, "CaptureWindow");
    }
    let _ = writeln!(
        s,
        "use drive_monitor::balancer::{{{}}};\n",
        types.join(", ")
    );
    let _ = writeln!(
        s,
        "/// Characteristic speeds, zones and capture windows of the `{scene}` scene's machine\n\
         /// ([`MachineTable`]).\n\
         #[rustfmt::skip]\n\
         pub const MACHINE: MachineTable<'static> = MachineTable {{"
    );
    let _ = writeln!(s, "    resonant: &[{}],", list(m.resonant_speeds()));
    let _ = writeln!(s, "    additional: &[{}],", list(m.additional_speeds()));
    let _ = writeln!(s, "    zones: &[");
    for z in m.zones() {
        let to =
            z.to.map_or_else(|| "None".to_string(), |t| format!("Some({})", literal(t)));
        let kind = match z.kind {
            ZoneKind::Gathering => "Gathering",
            ZoneKind::Balancing => "Balancing",
        };
        let _ = writeln!(
            s,
            "        Zone {{ from: {}, to: {to}, kind: ZoneKind::{kind} }},",
            literal(z.from)
        );
    }
    let _ = writeln!(s, "    ],");
    if m.capture_windows().is_empty() {
        let _ = writeln!(s, "    captures: &[],");
    } else {
        let _ = writeln!(s, "    captures: &[");
        for w in m.capture_windows() {
            let _ = writeln!(
                s,
                "        CaptureWindow {{ from: {}, until: {}, at: {} }},",
                literal(w.from),
                literal(w.until),
                literal(w.at)
            );
        }
        let _ = writeln!(s, "    ],");
    }
    let _ = writeln!(s, "}};");
    s
}

/// The source `drive-sim predict SCENE --emit FORMAT` writes for the scene `name` (a file or
/// the name of a bundled scene).
pub fn emit_text(name: &str, format: Format) -> Result<String, EmitError> {
    let (scene, path) = resolve(name)?;
    let Some(m) = machine(&scene, &path)? else {
        return Err(EmitError::NoMachine { file: path });
    };
    Ok(match format {
        Format::Rust => rust_table(name, scene.description.as_deref(), &m),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every value of every bundled machine reads back from its literal as the same bits, and
    /// appears in the emitted source.
    #[test]
    fn literals_round_trip_exactly() {
        for (file, _) in crate::app::scene::BUNDLED {
            let file = file.strip_suffix(".toml").unwrap_or(file);
            let (scene, path) = resolve(file).unwrap();
            let Some(m) = machine(&scene, &path).unwrap() else {
                continue;
            };
            let text = rust_table(file, scene.description.as_deref(), &m);
            let mut values: Vec<f64> = m
                .resonant_speeds()
                .iter()
                .chain(m.additional_speeds())
                .copied()
                .collect();
            for z in m.zones() {
                values.push(z.from);
                values.extend(z.to);
            }
            for w in m.capture_windows() {
                values.extend([w.from, w.until, w.at]);
            }
            for v in values {
                let l = literal(v);
                assert_eq!(l.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{l}");
                assert!(text.contains(&l), "{file}: {l} missing");
            }
        }
        // Values whose shortest form has an exponent, or none.
        for v in [
            0.0,
            1e-7,
            1.5e300,
            123456789.0,
            0.1 + 0.2,
            f64::MIN_POSITIVE,
        ] {
            assert_eq!(literal(v).parse::<f64>().unwrap().to_bits(), v.to_bits());
        }
    }

    #[test]
    fn a_scene_without_a_machine_is_an_error_naming_it() {
        let e = emit_text("kneader", Format::Rust).unwrap_err().to_string();
        assert!(
            e.contains("kneader.toml") && e.contains("[autobalancer]"),
            "{e}"
        );
        let e = emit_text("no-such-scene", Format::Rust)
            .unwrap_err()
            .to_string();
        assert!(e.contains("no-such-scene"), "{e}");
    }
}
