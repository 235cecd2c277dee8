//! Support loads on the target: the f32 speed update, the maximum safe speed recomputed through
//! each math backend, the same load arithmetic in (software) f64, and the f64 configuration.
//!
//! The rotor is auger-like: 350 kg, centre of mass at 1.9 m, supports at 0 and 4 m, balance
//! grade G 6.3 at a service speed of 60 rad/s, 8000 N allowed on each support, an unbalance of
//! 2e-3 kg·m at z = 1.2 m and 30°, and a process load of 400 N/m over 0.5..3.5 m at 270°.

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use drive_monitor::math::{Libm, Micromath};
use drive_monitor::supports::{
    Level, Limits, LoadRange, ProcessLoad, Rotor, SupportAnalysis, SupportMonitor, Unbalance,
    DEFAULT_WARNING_FRACTION,
};

use crate::bench::{ensure, fail, measure, measure_each};

/// Speeds per table.
const N: usize = 64;
/// Passes over each table.
const REPS: u32 = 50;

fn rotor() -> Rotor<4> {
    let unbalance = [Unbalance::new(1.2, 2e-3, 30f64.to_radians())];
    let process = ProcessLoad {
        per_length: 400.0,
        from: 0.5,
        to: 3.5,
        angle: 270f64.to_radians(),
    };
    match Rotor::new(350.0, 1.9, 0.0, 4.0, &unbalance, Some(process)) {
        Ok(r) => r,
        Err(e) => fail(format_args!("rotor rejected: {}", e)),
    }
}

fn limits() -> Limits {
    match Limits::new(6.3, 60.0, Some([8000.0, 8000.0]), DEFAULT_WARNING_FRACTION) {
        Ok(l) => l,
        Err(e) => fail(format_args!("limits rejected: {}", e)),
    }
}

pub fn run() {
    hprintln!("-- supports: auger-like rotor, 350 kg on supports 0 and 4 m");

    // Configuration time: validation, plane split, static loads, ISO allocation, limits.
    measure("supports::configure f64", 20, || {
        let a = SupportAnalysis::new(&black_box(rotor()), &black_box(limits()));
        let _ = black_box(a);
    });
    let rotor = rotor();
    let analysis = match SupportAnalysis::new(&rotor, &limits()) {
        Ok(a) => a,
        Err(e) => fail(format_args!("analysis rejected: {}", e)),
    };
    let monitor = match analysis.monitor() {
        Ok(m) => m,
        Err(e) => fail(format_args!("monitor rejected: {}", e)),
    };
    let Some(max_speed) = analysis.max_safe_speed() else {
        fail(format_args!("no maximum safe speed with load limits set"));
    };

    // Speeds from standstill to twice the maximum safe speed: every level is visited.
    let mut speeds = [0f32; N];
    for (i, w) in speeds.iter_mut().enumerate() {
        *w = (2.0 * max_speed * i as f64 / (N - 1) as f64) as f32;
    }
    let update = measure_each("supports::update f32", &speeds, REPS, |w| monitor.update(w));

    // The same per-support arithmetic (peak and minimum load from |S|, |D| and ω²) in f64,
    // software-emulated on the M4: what f32 saves on the runtime path.
    let s = rotor.static_load().map(|v| v.norm());
    let d = rotor.support_unbalance().map(|v| v.norm());
    let mut speeds64 = [0f64; N];
    for (w64, &w) in speeds64.iter_mut().zip(speeds.iter()) {
        *w64 = f64::from(w);
    }
    let loads64 = measure_each("supports::loads f64", &speeds64, REPS, |w| {
        let w2 = w * w;
        [LoadRange::at(s[0], d[0], w2), LoadRange::at(s[1], d[1], w2)]
    });
    ensure!(
        update > 0 && loads64 > update,
        "f64 load arithmetic ({}) not dearer than the f32 update ({})",
        loads64,
        update
    );

    // The f32 update against the f64 analysis on the same speeds.
    let mut worst = 0f64;
    let mut levels = [false; 3];
    for &w in speeds.iter() {
        let st = monitor.update(w);
        let reference = rotor.loads(f64::from(w));
        for (i, r) in reference.iter().enumerate() {
            let peak = f64::from(st.peak_load[i]);
            worst = worst.max(libm::fabs(peak / r.peak - 1.0));
            let min = f64::from(st.min_load[i]);
            worst = worst.max(libm::fabs(min - r.min) / r.peak);
            match st.load[i] {
                Level::Normal => levels[0] = true,
                Level::Warning => levels[1] = true,
                Level::Over => levels[2] = true,
                Level::Unknown => fail(format_args!("level unknown at {} rad/s", w)),
            }
        }
        let over = f64::from(w) > max_speed * 1.000_001;
        let under = f64::from(w) < max_speed * 0.999_999;
        let any_over = st.load.contains(&Level::Over);
        ensure!(
            (!over || any_over) && (!under || !any_over),
            "load level at {} rad/s disagrees with the maximum safe speed {}",
            w,
            max_speed
        );
    }
    hprintln!(
        "accuracy supports::update f32     {:.2e} (of the peak load, against f64)",
        worst
    );
    ensure!(
        worst < 1e-6,
        "f32 support loads off the f64 analysis by {:e}",
        worst
    );
    ensure!(
        levels == [true, true, true],
        "not every level visited: {:?}",
        levels
    );

    // Maximum safe speed recomputed from new unbalance magnitudes, per math backend.
    let base = monitor.unbalance();
    let mut scales = [(0f32, 0f32); N];
    for (i, p) in scales.iter_mut().enumerate() {
        let k = 0.5 + 1.5 * i as f32 / (N - 1) as f32;
        *p = (base[0] * k, base[1] * k);
    }
    let mut m_libm = monitor;
    let mut m_micro = monitor;
    measure_each("supports::set_unbalance libm", &scales, REPS, |(a, b)| {
        m_libm.set_unbalance::<Libm>(a, b)
    });
    measure_each(
        "supports::set_unbalance micromath",
        &scales,
        REPS,
        |(a, b)| m_micro.set_unbalance::<Micromath>(a, b),
    );

    // Against the f64 formula √((F − |S|)/|D|) on each scaled unbalance.
    let (mut e_libm, mut e_micro) = (0f64, 0f64);
    for &(a, b) in scales.iter() {
        ensure!(
            m_libm.set_unbalance::<Libm>(a, b) && m_micro.set_unbalance::<Micromath>(a, b),
            "unbalance ({}, {}) refused",
            a,
            b
        );
        let exact = [(s[0], a), (s[1], b)]
            .map(|(s, d)| libm::sqrt((8000.0 - s) / f64::from(d)))
            .iter()
            .fold(f64::INFINITY, |m, &x| m.min(x));
        let rel = |m: &SupportMonitor| match m.max_safe_speed() {
            Some(w) => libm::fabs(f64::from(w) / exact - 1.0),
            None => f64::INFINITY,
        };
        e_libm = e_libm.max(rel(&m_libm));
        e_micro = e_micro.max(rel(&m_micro));
    }
    hprintln!(
        "accuracy supports::max_safe_speed libm {:.2e}, micromath {:.2e} (relative, against f64)",
        e_libm,
        e_micro
    );
    // f32 rounding of the inputs and one sqrt; micromath's sqrt is good to 6.2 %.
    ensure!(e_libm < 1e-6, "libm max safe speed off by {:e}", e_libm);
    ensure!(
        e_micro < 0.062,
        "micromath max safe speed off by {:e}",
        e_micro
    );
}
