//! The `three-mass` scene's auto-balancer machine, analysed on the host for firmware:
//! written by `drive-sim predict three-mass --emit rust`; regenerate rather than edit.
//!
//! Three-mass vibration machine, roller auto-balancer on the middle platform (seed 001).
//!
//! Speeds in rad/s. Each f64 is Rust's shortest round-trip form of the value
//! `Machine::new` computed (default `SearchOptions`): it reads back as the same bits.

use drive_monitor::balancer::{
    BistableReason, CaptureWindow, MachineTable, Regime, RegimeSegment, RegimeTable, Zone, ZoneKind,
};

/// Characteristic speeds, zones and capture windows of the `three-mass` scene's machine
/// ([`MachineTable`]).
#[rustfmt::skip]
pub const MACHINE: MachineTable<'static> = MachineTable {
    resonant: &[49.45334900613397, 66.43112527392405, 80.42584094726612],
    additional: &[51.63977794943223, 70.71067811865476],
    zones: &[
        Zone { from: 0.0, to: Some(49.74062014725808), kind: ZoneKind::Gathering },
        Zone { from: 49.74062014725808, to: Some(51.3491542743101), kind: ZoneKind::Balancing },
        Zone { from: 51.3491542743101, to: Some(66.6231498246738), kind: ZoneKind::Gathering },
        Zone { from: 66.6231498246738, to: Some(70.57425411122668), kind: ZoneKind::Balancing },
        Zone { from: 70.57425411122668, to: Some(80.33713623877476), kind: ZoneKind::Gathering },
        Zone { from: 80.33713623877476, to: None, kind: ZoneKind::Balancing },
    ],
    captures: &[
        CaptureWindow { from: 49.74062014725808, until: 50.95455277616617, at: 49.74062014725808 },
        CaptureWindow { from: 66.6231498246738, until: 74.55178532208701, at: 66.53934341660285 },
        CaptureWindow { from: 80.33713623877476, until: 105.82215063858969, at: 80.33713623877476 },
    ],
};

/// The exact regime table of the `three-mass` scene's machine (the balancing position's
/// stability from the Floquet multipliers of the model, the capture windows, the
/// criterion), speeds in the core's f32: build the classifier with
/// `Classifier::from_table(&REGIMES, REGIME_MARGIN, REGIME_MARGIN / 2.0)`.
#[rustfmt::skip]
pub const REGIMES: RegimeTable<'static> = RegimeTable {
    segments: &[
        RegimeSegment { from: 0.0, regime: Regime::Gathering },
        RegimeSegment { from: 50.324696, regime: Regime::Bistable(BistableReason::Capture) },
        RegimeSegment { from: 50.956127, regime: Regime::Balancing },
        RegimeSegment { from: 51.349155, regime: Regime::Bistable(BistableReason::Coexisting) },
        RegimeSegment { from: 51.435593, regime: Regime::Gathering },
        RegimeSegment { from: 70.13968, regime: Regime::Bistable(BistableReason::Capture) },
        RegimeSegment { from: 70.93867, regime: Regime::Gathering },
        RegimeSegment { from: 91.15673, regime: Regime::Bistable(BistableReason::Capture) },
        RegimeSegment { from: 106.167465, regime: Regime::Balancing },
    ],
};

/// The margin about each boundary of `REGIMES` within which the classifier says
/// near-characteristic (the scene's `[monitor] regime_margin`, or the core's
/// `TABLE_MARGIN`), as `drive-sim run` and `sweep` classify.
pub const REGIME_MARGIN: f32 = 0.01;
