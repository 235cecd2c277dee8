//! `drive-sim predict SCENE --emit rust [--out FILE]`: the scene's auto-balancer machine
//! analysed on the host and written as Rust source: a `const`
//! [`MachineTable`](drive_monitor::balancer::MachineTable) holding its characteristic speeds,
//! zones and capture windows ([`Machine::new`]), and, when the machine has a balancing
//! position, a `const` [`RegimeTable`](drive_monitor::balancer::RegimeTable): the exact regime
//! table ([`crate::app::regimes`]: the balancing position's stability from the Floquet
//! multipliers, the capture windows, the criterion). Firmware includes the file as a module
//! and builds its classifier at compile time with the `const fn`s
//! [`Classifier::from_table`](drive_monitor::balancer::Classifier::from_table) (the exact
//! table) or [`Classifier::from_machine_table`](drive_monitor::balancer::Classifier::from_machine_table)
//! (the criterion's), so the target never analyses the machine (nor links the analysis).
//!
//! Every f64 is written in Rust's shortest round-trip form (`{:?}`: the fewest digits that
//! read back as the same bits; `str::parse` and rustc's float literals both round correctly),
//! so the constant holds exactly the values computed here; the regime table's speeds are the
//! core's f32 (each f64 boundary rounded to nearest), written the same way. The firmware example
//! (`examples/qemu`) compares its checked-in table with `Machine::new` run on the target, and
//! a host test compares that file with what this writes now.

use crate::app::predict::machine;
use crate::app::regimes::{core_segments, design, given_margin};
use crate::app::scene::{resolve, SceneError};
use drive_monitor::balancer::{BistableReason, Machine, Regime, RegimeSegment, ZoneKind};
use std::fmt::Write as _;
use std::path::PathBuf;

/// What `--emit` writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    /// Rust source: `const MACHINE: MachineTable` and `const REGIMES: RegimeTable` for
    /// firmware.
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
/// with its one-line `description` and its exact regime table, if it has one, with the margin
/// its classifier takes (`margin`: the scene's `[monitor] regime_margin`, or the core's
/// `TABLE_MARGIN`).
pub fn rust_table(
    scene: &str,
    description: Option<&str>,
    m: &Machine,
    regimes: Option<&[RegimeSegment]>,
    margin: f32,
) -> String {
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
    if let Some(r) = regimes {
        types.extend(["Regime", "RegimeSegment", "RegimeTable"]);
        if r.iter().any(|g| matches!(g.regime, Regime::Bistable(_))) {
            types.insert(0, "BistableReason");
        }
        types.sort_unstable();
    }
    // As rustfmt lays it out (the checked-in file must pass `cargo fmt --check`): one line
    // when it fits in 100 columns, else the names filling indented lines.
    let one = format!("use drive_monitor::balancer::{{{}}};", types.join(", "));
    if one.len() <= 100 {
        let _ = writeln!(s, "{one}\n");
    } else {
        let _ = writeln!(s, "use drive_monitor::balancer::{{");
        let mut line = String::from("   ");
        for t in &types {
            if line.len() + t.len() + 2 > 100 {
                let _ = writeln!(s, "{line}");
                line = String::from("   ");
            }
            line.push(' ');
            line.push_str(t);
            line.push(',');
        }
        let _ = writeln!(s, "{line}\n}};\n");
    }
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
    match regimes {
        Some(r) => {
            let _ = writeln!(
                s,
                "\n/// The exact regime table of the `{scene}` scene's machine (the balancing position's\n\
                 /// stability from the Floquet multipliers of the model, the capture windows, the\n\
                 /// criterion), speeds in the core's f32: build the classifier with\n\
                 /// `Classifier::from_table(&REGIMES, REGIME_MARGIN, REGIME_MARGIN / 2.0)`.\n\
                 #[rustfmt::skip]\n\
                 pub const REGIMES: RegimeTable<'static> = RegimeTable {{\n    segments: &["
            );
            for g in r {
                let regime = match g.regime {
                    Regime::Balancing => "Regime::Balancing",
                    Regime::Gathering => "Regime::Gathering",
                    Regime::Bistable(BistableReason::Capture) => {
                        "Regime::Bistable(BistableReason::Capture)"
                    }
                    Regime::Bistable(BistableReason::Coexisting) => {
                        "Regime::Bistable(BistableReason::Coexisting)"
                    }
                    Regime::Bistable(BistableReason::Family) => {
                        "Regime::Bistable(BistableReason::Family)"
                    }
                    // A validated table has neither.
                    Regime::NearCharacteristic | Regime::Unknown => "Regime::Unknown",
                };
                let _ = writeln!(
                    s,
                    "        RegimeSegment {{ from: {:?}, regime: {regime} }},",
                    g.from
                );
            }
            let _ = writeln!(s, "    ],\n}};");
            let _ = writeln!(
                s,
                "\n/// The margin about each boundary of `REGIMES` within which the classifier says\n\
                 /// near-characteristic (the scene's `[monitor] regime_margin`, or the core's\n\
                 /// `TABLE_MARGIN`), as `drive-sim run` and `sweep` classify.\n\
                 pub const REGIME_MARGIN: f32 = {margin:?};"
            );
        }
        None => {
            let _ = writeln!(
                s,
                "\n// No exact regime table: the machine has no balancing position (fewer than two\n\
                 // loads, or a rotor unbalance larger than they can balance)."
            );
        }
    }
    s
}

/// The source `drive-sim predict SCENE --emit FORMAT` writes for the scene `name` (a file or
/// the name of a bundled scene).
pub fn emit_text(name: &str, format: Format) -> Result<String, EmitError> {
    let (scene, path) = resolve(name)?;
    let Some(m) = machine(&scene, &path)? else {
        return Err(EmitError::NoMachine { file: path });
    };
    let regimes = match design(&scene, &path, &m)?.and_then(|d| d.exact) {
        Some(exact) => Some(core_segments(&exact.segments, &path)?),
        None => None,
    };
    // The margin `run` and `sweep` classify with (a table that ignored it had the firmware
    // commit where they say near-characteristic).
    let margin = given_margin(&scene).unwrap_or(drive_monitor::balancer::TABLE_MARGIN);
    Ok(match format {
        Format::Rust => rust_table(
            name,
            scene.description.as_deref(),
            &m,
            regimes.as_deref(),
            margin,
        ),
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
            let text = rust_table(file, scene.description.as_deref(), &m, None, 0.01);
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

    /// The exact regime table is written when the machine has one, each f32 speed in a form
    /// that reads back as the same bits; a machine without a balancing position says so.
    #[test]
    fn the_exact_regime_table_is_emitted_when_there_is_one() {
        let (scene, path) = resolve("three-mass").unwrap();
        let m = machine(&scene, &path).unwrap().unwrap();
        let exact = design(&scene, &path, &m).unwrap().unwrap().exact.unwrap();
        let segments = core_segments(&exact.segments, &path).unwrap();
        let text = emit_text("three-mass", Format::Rust).unwrap();
        assert!(
            text.contains("pub const REGIMES: RegimeTable<'static>"),
            "{text}"
        );
        for g in &segments {
            let l = format!("{:?}", g.from);
            assert_eq!(l.parse::<f32>().unwrap().to_bits(), g.from.to_bits(), "{l}");
            assert!(text.contains(&format!("from: {l}, ")), "{l} missing");
        }
        assert_eq!(text.matches("RegimeSegment {").count(), segments.len());
        let text = emit_text("one-mass-undersized", Format::Rust).unwrap();
        assert!(
            !text.contains("REGIMES") && text.contains("No exact regime table"),
            "{text}"
        );
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
