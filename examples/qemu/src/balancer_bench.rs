//! The auto-balancer on the target: the three-mass machine's characteristic speeds computed at
//! configuration time (f64, software-emulated on the M4), and the per-speed-update
//! classification (f32, binary search over the segments) from the criterion's zones and from
//! the exact regime table the host computes and ships as a `const`.

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use drive_monitor::balancer::{
    AutoBalancer, BalancerKind, BistableReason, Classifier, Coupling, Machine, MachineConfig,
    Platform, Regime, RegimeSegment, RegimeTable, RegimeTracker, SearchOptions, TABLE_MARGIN,
};

use crate::bench::{ensure, measure, measure_each};
use crate::icount;

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

const fn seg(from: f32, regime: Regime) -> RegimeSegment {
    RegimeSegment { from, regime }
}

/// The bundled `three-mass.toml` machine's exact regime table: `regime_table` of
/// `drive-sim predict three-mass --json` (Floquet stability of the balancing position, the
/// core's capture windows, the criterion), speeds rounded to f32.
const EXACT: RegimeTable<'static> = RegimeTable {
    segments: &[
        seg(0.0, Regime::Gathering),
        seg(50.324_696, Regime::Bistable(BistableReason::Capture)),
        seg(50.954_55, Regime::Balancing),
        seg(51.349_155, Regime::Bistable(BistableReason::Coexisting)),
        seg(51.435_593, Regime::Gathering),
        seg(70.139_68, Regime::Bistable(BistableReason::Capture)),
        seg(70.938_67, Regime::Gathering),
        seg(91.156_73, Regime::Bistable(BistableReason::Capture)),
        seg(105.822_15, Regime::Balancing),
    ],
};

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

    let classifier = match Classifier::new(&machine, 0.02, 0.01) {
        Ok(c) => c,
        Err(e) => crate::bench::fail(format_args!("classifier rejected: {}", e)),
    };
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
    let exact = match Classifier::from_table(&EXACT, TABLE_MARGIN, 0.5 * TABLE_MARGIN) {
        Ok(c) => c,
        Err(e) => crate::bench::fail(format_args!("table rejected: {}", e)),
    };
    let table_cost = icount::instructions() - start;
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
