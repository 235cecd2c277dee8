//! The predicted δ on the target: configuration-time f64 (software-emulated on the M4).
//!
//! The seed's drive: a motor parabola through ω0 = 145 rad/s and (ω_m = 36 rad/s,
//! M_m = 158 N·m), reduced inertia J = 0.323 kg·m², load M_c = 24 + 12·sin(φ/8) N·m; and the
//! same with a second harmonic 6·sin(φ/2 + 1), whose extrema come from a search over the
//! common period.

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use drive_monitor::drive::{DriveModel, Harmonic, Horizon, Load, Motor, Parabola, SteadyState};

use crate::bench::{ensure, fail, measure};

const J: f64 = 0.323;
/// The seed's δ (paper and host tests).
const SEED_DELTA: f64 = 0.030656;
/// Flywheel sizing target.
const TARGET: f64 = 0.01;

fn harmonic(order: f64, amplitude: f64, phase: f64) -> Harmonic {
    match Harmonic::new(order, amplitude, phase) {
        Ok(h) => h,
        Err(e) => fail(format_args!("harmonic rejected: {}", e)),
    }
}

fn model(harmonics: &[Harmonic], flywheel: f64) -> DriveModel {
    let motor: Motor = match Parabola::new(145.0, 36.0, 158.0) {
        Ok(p) => p.into(),
        Err(e) => fail(format_args!("motor rejected: {}", e)),
    };
    let load = match Load::new(24.0, harmonics) {
        Ok(l) => l,
        Err(e) => fail(format_args!("load rejected: {}", e)),
    };
    match DriveModel::new(motor, load, J, flywheel) {
        Ok(m) => m,
        Err(e) => fail(format_args!("drive rejected: {}", e)),
    }
}

fn steady(m: &DriveModel) -> SteadyState {
    match m.predict().steady() {
        Some(s) => *s,
        None => fail(format_args!("no steady state")),
    }
}

/// Largest and smallest steady speed on an even grid of `n` angles over `period`: an
/// independent check of the extrema the model finds (never outside them).
fn grid_extrema(m: &DriveModel, period: f64, n: u32) -> (f64, f64) {
    let (mut hi, mut lo) = (0f64, f64::INFINITY);
    for i in 0..n {
        let phi = period * f64::from(i) / f64::from(n);
        if let Some(w) = m.steady_omega(phi) {
            hi = hi.max(w);
            lo = lo.min(w);
        }
    }
    (hi, lo)
}

pub fn run() {
    hprintln!("-- predicted delta: configuration time, f64");
    let one = [harmonic(0.125, 12.0, 0.0)];
    let two = [harmonic(0.125, 12.0, 0.0), harmonic(0.5, 6.0, 1.0)];

    measure("drive::new+predict 1 harmonic", 20, || {
        black_box(model(black_box(&one), 0.0).predict());
    });
    measure("drive::new+predict 2 harmonics", 3, || {
        black_box(model(black_box(&two), 0.0).predict());
    });
    let seed = model(&one, 0.0);
    measure("drive::flywheel_for 1 harmonic", 20, || {
        black_box(black_box(&seed).flywheel_for(TARGET)).ok();
    });

    // The seed case.
    let s1 = steady(&seed);
    hprintln!(
        "drive: seed delta {:.6} (omega max {:.3}, min {:.3})",
        s1.delta,
        s1.omega_max,
        s1.omega_min
    );
    ensure!(
        libm::fabs(s1.delta - SEED_DELTA) < 5e-7 && s1.horizon == Horizon::ClosedForm,
        "seed delta {} (expected {}), horizon {:?}",
        s1.delta,
        SEED_DELTA,
        s1.horizon
    );

    // Two harmonics: the searched extrema bound a grid over the common period from outside,
    // and by no more than the grid's own spacing error.
    let m2 = model(&two, 0.0);
    let s2 = steady(&m2);
    let Horizon::Period { radians, .. } = s2.horizon else {
        fail(format_args!("two harmonics: horizon {:?}", s2.horizon));
    };
    let (hi, lo) = grid_extrema(&m2, radians, 2000);
    let (e_hi, e_lo) = (s2.omega_max / hi - 1.0, 1.0 - s2.omega_min / lo);
    hprintln!(
        "drive: two harmonics delta {:.6}; extrema beyond a 2000-point grid by {:.1e}, {:.1e}",
        s2.delta,
        e_hi,
        e_lo
    );
    ensure!(
        (-1e-12..1e-5).contains(&e_hi) && (-1e-12..1e-5).contains(&e_lo),
        "two-harmonic extrema {} {} against grid {} {}",
        s2.omega_max,
        s2.omega_min,
        hi,
        lo
    );

    // The flywheel meets the target.
    let extra = match seed.flywheel_for(TARGET) {
        Ok(f) => f,
        Err(e) => fail(format_args!("flywheel_for: {:?}", e)),
    };
    let sized = match seed.with_flywheel(extra) {
        Ok(m) => steady(&m),
        Err(e) => fail(format_args!("with_flywheel: {}", e)),
    };
    hprintln!(
        "drive: flywheel {:.4} kg m^2 gives delta {:.6}",
        extra,
        sized.delta
    );
    ensure!(
        extra > 0.0 && libm::fabs(sized.delta / TARGET - 1.0) < 1e-9,
        "flywheel {} gives delta {}",
        extra,
        sized.delta
    );
}
