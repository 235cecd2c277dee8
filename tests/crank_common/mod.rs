//! What the fault-injection sweeps on missing-tooth wheels share (`crank_sweep.rs`,
//! `start_flare.rs`): the capture timer's clock, the 16-point Gauss-Legendre rule their
//! generators integrate 1/ω with, and the monitor run edge by edge with every tooth and fault
//! recorded. Nothing here comes from the crate's `testutil` or from host-sim: the core is used
//! only through its public API.

use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator, Pattern};
use drive_monitor::irregularity::{WindowConfig, WindowLength};
use drive_monitor::monitor::{DeltaMonitor, WindowOutcome};
use drive_monitor::speed::{Direction, EdgeSink, Fault, Tooth};

/// The capture timer's clock, Hz (ticks of 1 µs).
pub const HZ: f64 = 1e6;

// The 16-point Gauss-Legendre nodes and weights (the positive half), to double precision.
const GL_X: [f64; 8] = [
    0.0950125098376374,
    0.2816035507792589,
    0.4580167776572274,
    0.6178762444026438,
    0.755404408355003,
    0.8656312023878318,
    0.9445750230732326,
    0.9894009349916499,
];
const GL_W: [f64; 8] = [
    0.1894506104550685,
    0.1826034150449236,
    0.1691565193950025,
    0.1495959888165768,
    0.1246289712555339,
    0.0951585116824928,
    0.0622535239386479,
    0.0271524594117541,
];

/// ∫ f over [a, b], 16-point Gauss-Legendre.
pub fn integrate(f: &dyn Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (c, h) = ((a + b) / 2.0, (b - a) / 2.0);
    let mut s = 0.0;
    for (x, w) in GL_X.iter().zip(GL_W) {
        s += w * (f(c + h * x) + f(c - h * x));
    }
    s * h
}

/// The teeth the core accepted (time, number, synced, frame) and the faults it counted, with
/// their times.
#[derive(Default)]
pub struct Rec {
    pub teeth: Vec<(u32, u16, bool, bool)>,
    pub faults: Vec<(Fault, u32)>,
}

impl EdgeSink for Rec {
    fn tooth(&mut self, t: &Tooth) {
        self.teeth.push((t.time, t.tooth, t.synced, t.frame));
    }
    fn fault(&mut self, f: Fault, time: u32) {
        self.faults.push((f, time));
    }
}

/// A `DeltaMonitor<1024>` on an `n`-`m` wheel (K-edge samples, windows of `w` revolutions,
/// min speed 5 rad/s, steady tolerance 2 %) fed `ticks` forward edge by edge: its windows and
/// what it decided.
pub fn run_wheel(n: u32, m: u32, k: u16, w: u16, ticks: &[u32]) -> (Vec<WindowOutcome>, Rec) {
    let mut c = EncoderConfig::pattern(Pattern::missing_teeth(n as u8, m as u8), HZ);
    c.estimator = Estimator::Edges(k);
    c.min_speed = 5.0;
    let mut mon: DeltaMonitor<1024> = DeltaMonitor::new(
        Encoder::new(c).unwrap(),
        WindowConfig {
            length: WindowLength::Revolutions(w),
            steady_tolerance: 0.02,
        },
        None,
    )
    .unwrap();
    let mut rec = Rec::default();
    let mut out = Vec::new();
    for &t in ticks {
        if let Some(o) = mon.on_edge_observed(t, Some(Direction::Forward), &mut rec) {
            out.push(o);
        }
    }
    (out, rec)
}
