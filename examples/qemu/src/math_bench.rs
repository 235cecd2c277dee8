//! The math backends on the target: instructions per call and worst error against an f64
//! reference, for [`Libm`] and [`Micromath`] over the same table of inputs.

use core::f32::consts::PI;

use cortex_m_semihosting::hprintln;
use drive_monitor::math::{Libm, Math, Micromath};

use crate::bench::{ensure, measure_each};

/// Inputs per table.
const N: usize = 64;
/// Passes over each table per measurement.
const REPS: u32 = 100;

/// Worst-error bounds: `[sqrt relative, sin, cos, atan2 absolute]` on (0, 10] (the bounds the
/// core's `math` module states and tests on the host).
const LIBM_BOUND: [f64; 4] = [1.2e-7, 1e-6, 1e-6, 1e-6];
const MICROMATH_BOUND: [f64; 4] = [0.062, 1.1e-3, 1.1e-3, 2.9e-3];

/// The input tables: `x` evenly inside (0, 10], and points `(y, x)` on a circle of radius 3
/// all the way round, for atan2.
struct Inputs {
    x: [f32; N],
    yx: [(f32, f32); N],
}

impl Inputs {
    fn new() -> Self {
        let mut x = [0f32; N];
        let mut yx = [(0f32, 0f32); N];
        for (i, (xi, p)) in x.iter_mut().zip(yx.iter_mut()).enumerate() {
            let u = (i as f32 + 0.5) / N as f32;
            *xi = 10.0 * u;
            let angle = 2.0 * PI * u - PI;
            *p = (3.0 * libm::sinf(angle), 3.0 * libm::cosf(angle));
        }
        Inputs { x, yx }
    }
}

/// Instructions per call of each function of backend `M`, labelled `<backend>::<function>`.
fn costs<M: Math>(inputs: &Inputs, labels: [&str; 4]) -> [u64; 4] {
    [
        measure_each(labels[0], &inputs.x, REPS, M::sqrt),
        measure_each(labels[1], &inputs.x, REPS, M::sin),
        measure_each(labels[2], &inputs.x, REPS, M::cos),
        measure_each(labels[3], &inputs.yx, REPS, |(y, x)| M::atan2(y, x)),
    ]
}

/// Worst errors of backend `M` against f64 `libm`: `[sqrt relative, sin, cos, atan2]`.
fn worst_errors<M: Math>(inputs: &Inputs) -> [f64; 4] {
    let mut e = [0f64; 4];
    for (&x, &(y, xx)) in inputs.x.iter().zip(inputs.yx.iter()) {
        let xd = f64::from(x);
        e[0] = e[0].max((f64::from(M::sqrt(x)) / libm::sqrt(xd) - 1.0).abs());
        e[1] = e[1].max((f64::from(M::sin(x)) - libm::sin(xd)).abs());
        e[2] = e[2].max((f64::from(M::cos(x)) - libm::cos(xd)).abs());
        let reference = libm::atan2(f64::from(y), f64::from(xx));
        e[3] = e[3].max((f64::from(M::atan2(y, xx)) - reference).abs());
    }
    e
}

/// Prints and checks the worst errors of backend `M` against its stated bounds.
fn check<M: Math>(backend: &str, inputs: &Inputs, bound: [f64; 4]) {
    let e = worst_errors::<M>(inputs);
    let names = ["sqrt (relative)", "sin", "cos", "atan2"];
    for ((name, err), limit) in names.iter().zip(e).zip(bound) {
        hprintln!(
            "accuracy {:>9}::{:<16} {:.2e} (bound {:.1e})",
            backend,
            name,
            err,
            limit
        );
        ensure!(
            err < limit,
            "{}::{} error {:e} exceeds its bound {:e}",
            backend,
            name,
            err,
            limit
        );
    }
}

/// Benchmarks both backends, then checks both against the f64 reference.
pub fn run() {
    hprintln!(
        "-- math backends: instructions per call, {} inputs x {} passes",
        N,
        REPS
    );
    let inputs = Inputs::new();
    let libm = costs::<Libm>(
        &inputs,
        ["libm::sqrt", "libm::sin", "libm::cos", "libm::atan2"],
    );
    let micro = costs::<Micromath>(
        &inputs,
        [
            "micromath::sqrt",
            "micromath::sin",
            "micromath::cos",
            "micromath::atan2",
        ],
    );
    for (name, (l, m)) in ["sqrt", "sin", "cos", "atan2"]
        .iter()
        .zip(libm.iter().zip(micro))
    {
        ensure!(
            *l > 0 && m > 0,
            "{} measured as free: libm {}, micromath {}",
            name,
            l,
            m
        );
    }
    hprintln!("-- math backends: worst error against f64 libm on the same inputs");
    check::<Libm>("libm", &inputs, LIBM_BOUND);
    check::<Micromath>("micromath", &inputs, MICROMATH_BOUND);
}
