//! The auto-balancer on the target: the three-mass machine's characteristic speeds computed at
//! configuration time (f64, software-emulated on the M4), the same analysis taken instead from
//! the table `drive-sim predict three-mass --emit rust` wrote (`three_mass_table.rs`, a classifier
//! built at compile time), and the per-speed-update classification (f32, binary search over the
//! segments) from the criterion's zones and from the exact regime table the host computes.

use core::hint::black_box;

use crate::three_mass_table::REGIME_MARGIN;
use cortex_m_semihosting::hprintln;
use drive_monitor::balancer::{
    AutoBalancer, BalancerKind, BistableReason, Classifier, Coupling, Machine, MachineConfig,
    Platform, Regime, RegimeTracker, SearchOptions,
};

use crate::bench::{ensure, measure, measure_each};
use crate::icount;
use crate::three_mass_table;

/// Margin and hysteresis of the classifier.
const MARGIN: f32 = 0.02;
const HYSTERESIS: f32 = 0.01;

/// The classifier of the emitted table, built by the compiler: no analysis on the target.
const FROM_TABLE: Classifier =
    match Classifier::from_machine_table(&three_mass_table::MACHINE, MARGIN, HYSTERESIS) {
        Ok(c) => c,
        Err(_) => panic!("three_mass_table.rs: not a valid machine table"),
    };

/// The classifier of the emitted exact regime table (`REGIMES`: Floquet stability of the
/// balancing position, the capture windows, the criterion), built by the compiler.
const EXACT: Classifier = match Classifier::from_table(
    &three_mass_table::REGIMES,
    REGIME_MARGIN,
    0.5 * REGIME_MARGIN,
) {
    Ok(c) => c,
    Err(_) => panic!("three_mass_table.rs: not a valid regime table"),
};

/// The bundled `three-mass.toml` machine.
fn config() -> MachineConfig {
    let p = |mass, stiffness| Platform {
        mass,
        stiffness,
        damping: 200.0,
    };
    let c = |a, b| Coupling {
        between: [a, b],
        stiffness: 1.0e5,
        damping: 50.0,
    };
    let balancer = AutoBalancer {
        kind: BalancerKind::Roller,
        platform: 2,
        loads: 2,
        load_mass: 0.5,
        radius: 0.1,
        housing_mass: 5.0,
        viscosity: 10.0,
    };
    match MachineConfig::new(
        &[p(100.0, 4.0e5), p(100.0, 4.0e5), p(150.0, 3.0e5)],
        &[c(1, 2), c(2, 3)],
        balancer,
    ) {
        Ok(c) => c,
        Err(e) => crate::bench::fail(format_args!("machine rejected: {}", e)),
    }
}

pub fn run() {
    hprintln!("-- auto-balancer: three-mass machine");
    let start = icount::instructions();
    let machine = match Machine::new(config(), SearchOptions::default()) {
        Ok(m) => m,
        Err(e) => crate::bench::fail(format_args!("machine rejected: {}", e)),
    };
    let config_cost = icount::instructions() - start;
    hprintln!("bench {:<28} {:>7}", "balancer::Machine::new", config_cost);
    let r = machine.resonant_speeds();
    hprintln!(
        "resonant speeds {:.3} {:.3} {:.3} rad/s, zones {}",
        r.first().copied().unwrap_or(0.0),
        r.get(1).copied().unwrap_or(0.0),
        r.get(2).copied().unwrap_or(0.0),
        machine.zones().len()
    );
    // The host computes 49.453, 66.431, 80.426 rad/s and 6 zones for this machine.
    ensure!(
        r.len() == 3 && libm::fabs(r[0] - 49.453) < 1e-3 && libm::fabs(r[2] - 80.426) < 1e-3,
        "resonant speeds {:?}",
        r
    );
    ensure!(
        machine.zones().len() == 6,
        "zones {}",
        machine.zones().len()
    );

    let classifier = match Classifier::new(&machine, MARGIN, HYSTERESIS) {
        Ok(c) => c,
        Err(e) => crate::bench::fail(format_args!("classifier rejected: {}", e)),
    };
    check_table(&machine, &classifier);
    let mut speeds = [0f32; 64];
    for (i, s) in speeds.iter_mut().enumerate() {
        *s = 20.0 + 2.0 * i as f32;
    }
    measure_each("balancer::classify", &speeds, 100, |w| {
        classifier.classify(w)
    });
    ensure!(
        classifier.classify(30.0) == Regime::Gathering
            && classifier.classify(120.0) == Regime::Balancing,
        "classification"
    );
    let start = icount::instructions();
    let exact = match Classifier::from_table(
        black_box(&three_mass_table::REGIMES),
        REGIME_MARGIN,
        0.5 * REGIME_MARGIN,
    ) {
        Ok(c) => c,
        Err(e) => crate::bench::fail(format_args!("table rejected: {}", e)),
    };
    let table_cost = icount::instructions() - start;
    ensure!(
        exact == EXACT,
        "the exact table's classifier differs built at run time and by the compiler"
    );
    hprintln!(
        "bench {:<28} {:>7}",
        "balancer::Classifier::from_table",
        table_cost
    );
    measure_each("balancer::classify (exact table)", &speeds, 100, |w| {
        exact.classify(w)
    });
    ensure!(
        exact.classify(30.0) == Regime::Gathering
            && exact.classify(60.0) == Regime::Gathering
            && exact.classify(100.0) == Regime::Bistable(BistableReason::Capture)
            && exact.classify(120.0) == Regime::Balancing,
        "exact classification"
    );
    let mut tracker = RegimeTracker::new();
    let mut i = 0usize;
    measure("balancer::RegimeTracker::update", 6400, || {
        i = (i + 1) % speeds.len();
        black_box(tracker.update(&classifier, speeds[i]));
    });
}

/// The table the host wrote against the analysis done here: the same values bit for bit
/// (host f64 and the M4's soft-float f64 both round correctly, and the literals read back
/// exactly), and the classifier built from it at compile time classifying a sweep of speeds —
/// 0 to 200 rad/s in steps of 0.01, and each segment edge and characteristic speed one f32
/// step either side — and a tracker's run up and down that sweep, exactly like the one built
/// from `Machine::new`.
fn check_table(machine: &Machine, classifier: &Classifier) {
    let table = three_mass_table::MACHINE;
    ensure!(
        machine.table() == table,
        "three_mass_table.rs differs from Machine::new on the target: regenerate it with \
         `drive-sim predict three-mass --emit rust`"
    );
    ensure!(
        FROM_TABLE == *classifier,
        "classifier from the table differs"
    );
    let mut speeds = 0u32;
    let mut same = |w: f32| {
        speeds += 1;
        FROM_TABLE.classify(w) == classifier.classify(w)
            && FROM_TABLE.advice(w) == classifier.advice(w)
    };
    let mut all = true;
    for i in 0..=20_000u32 {
        all &= same(i as f32 * 0.01);
    }
    let edges = table
        .zones
        .iter()
        .map(|z| z.from)
        .chain(table.captures.iter().map(|w| w.until))
        .chain(table.resonant.iter().copied())
        .chain(table.additional.iter().copied());
    for e in edges {
        for f in [1.0 - MARGIN, 1.0, 1.0 + MARGIN] {
            let w = (e * f64::from(f)) as f32;
            all &= same(w) && same(next_down(w)) && same(next_up(w));
        }
    }
    let (mut a, mut b) = (RegimeTracker::new(), RegimeTracker::new());
    for i in (0..=4_000u32).chain((0..=4_000u32).rev()) {
        let w = i as f32 * 0.05;
        all &= a.update(&FROM_TABLE, w) == b.update(classifier, w);
    }
    ensure!(all, "the table's classifier disagrees with Machine::new's");
    hprintln!(
        "balancer: emitted table equals Machine::new bit for bit; its compile-time classifier agrees at {} speeds and over a tracked sweep",
        speeds
    );
}

fn next_up(x: f32) -> f32 {
    f32::from_bits(x.to_bits() + 1)
}

fn next_down(x: f32) -> f32 {
    if x > 0.0 {
        f32::from_bits(x.to_bits() - 1)
    } else {
        x
    }
}
