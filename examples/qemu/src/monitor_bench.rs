//! The irregularity monitor on the target: a pulse sequence of known δ through the public API,
//! what the core reports, checks on it, and instructions per encoder edge.
//!
//! The sequence is the capture timestamps of a 1024-line disc (index framing, 84 MHz 32-bit
//! timer) on a shaft running ω(φ) = ω̄·(1 + ε·sin(φ/8)) with ω̄ = 134 rad/s: a load cycle of
//! 8 revolutions like the seed's kneader, and δ = 2ε exactly. Timestamps are generated in f64
//! (midpoint rule per pitch, error far below one tick) before anything is measured.

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use drive_monitor::alarm::AlarmConfig;
use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator};
use drive_monitor::irregularity::{WindowConfig, WindowLength, MAX_WINDOW_REVS};
use drive_monitor::monitor::DeltaMonitor;
use drive_monitor::speed::Direction;

use crate::bench::ensure;
use crate::icount;

const LINES: u16 = 1024;
const TIMER_HZ: f64 = 84e6;
const REVS: usize = 8 * 5 + 2;
const EDGES: usize = LINES as usize * REVS;
const EPS: f64 = 0.015;
const OMEGA: f64 = 134.0;

fn generate(ticks: &mut [u32; EDGES]) {
    let pitch = core::f64::consts::TAU / f64::from(LINES);
    let mut t = 0.0f64;
    for (i, slot) in ticks.iter_mut().enumerate() {
        let mid = (i as f64 + 0.5) * pitch;
        t += pitch / (OMEGA * (1.0 + EPS * libm::sin(mid / 8.0)));
        *slot = (t * TIMER_HZ) as u64 as u32;
    }
}

fn monitor(k: u16, revs: u16) -> DeltaMonitor<1024> {
    let mut c = EncoderConfig::indexed(LINES, TIMER_HZ);
    c.estimator = Estimator::Edges(k);
    c.min_speed = 10.0;
    let Ok(enc) = Encoder::new(c) else {
        crate::bench::fail(format_args!("encoder config rejected"));
    };
    let w = WindowConfig {
        length: WindowLength::Revolutions(revs),
        steady_tolerance: 0.02,
    };
    match DeltaMonitor::new(enc, w, Some(AlarmConfig::new(0.06))) {
        Ok(m) => m,
        Err(e) => crate::bench::fail(format_args!("monitor config rejected: {}", e)),
    }
}

/// Feeds the stream (index pulse before every tooth 0); returns (instructions, windows).
#[inline(never)]
fn feed(m: &mut DeltaMonitor<1024>, ticks: &[u32; EDGES], print: bool) -> (u64, u32) {
    let mut windows = 0;
    let start = icount::instructions();
    for (i, &t) in ticks.iter().enumerate() {
        if i % LINES as usize == 0 {
            m.on_index(t.wrapping_sub(1));
        }
        if let Some(o) = black_box(m.on_edge(black_box(t), Some(Direction::Forward))) {
            windows += 1;
            if print {
                match o.report.measurement() {
                    Some(r) => hprintln!(
                        "window: delta {:.6} omega max {:.3} min {:.3} mean {:.3} floor {:.1e} steady {}",
                        r.delta, r.omega_max, r.omega_min, r.omega_mean, r.noise_floor, r.steady
                    ),
                    None => hprintln!("window: invalid {:?}", o.report.fault()),
                }
            }
        }
    }
    (icount::instructions() - start, windows)
}

/// The same loop without the monitor: what the loop itself costs.
#[inline(never)]
fn feed_empty(ticks: &[u32; EDGES]) -> u64 {
    let start = icount::instructions();
    for (i, &t) in ticks.iter().enumerate() {
        if i % LINES as usize == 0 {
            black_box(());
        }
        black_box(black_box(t));
    }
    icount::instructions() - start
}

/// Passes over the stream in [`window_finish`]: each timed call is read to the counter's
/// 40-instruction resolution, and the 160 windows of four passes average that out (when this
/// was chosen, 1, 2, 4 and 8 passes agreed within 3 instructions).
const FINISH_PASSES: u32 = 4;

/// One edge, timed: (instructions, whether it ended a window). Both monitors of
/// [`window_finish`] go through this same code, so its overhead cancels in their difference.
#[inline(never)]
fn timed_edge(m: &mut DeltaMonitor<1024>, t: u32) -> (u64, bool) {
    let start = icount::instructions();
    let ended = black_box(m.on_edge(black_box(t), Some(Direction::Forward))).is_some();
    (icount::instructions() - start, ended)
}

/// Instructions that finishing a window adds to the edge that ends it, and the number of
/// windows measured. The stream goes through two monitors that differ only in window length:
/// one revolution (every frame edge once the first window has started ends one) and
/// [`MAX_WINDOW_REVS`] (no frame edge of the stream ends one). Each frame edge is timed in
/// both; the cost is the mean difference over the edges that ended a window.
///
/// Differencing whole streams with short and long windows instead would also count per-sample
/// work that the window length changes: the running extremes move far more often in short
/// windows (on this stream ~250 more extremum updates per one-revolution window than in
/// eight-revolution windows), each a few instructions on the per-edge path.
#[inline(never)]
fn window_finish(ticks: &[u32; EDGES]) -> (u64, u32) {
    let (mut with, mut without, mut n) = (0u64, 0u64, 0u32);
    for _ in 0..FINISH_PASSES {
        let mut short = monitor(16, 1);
        let mut long = monitor(16, MAX_WINDOW_REVS);
        for (i, &t) in ticks.iter().enumerate() {
            if i % LINES as usize == 0 {
                short.on_index(t.wrapping_sub(1));
                long.on_index(t.wrapping_sub(1));
                let (a, ended) = timed_edge(&mut short, t);
                let (b, ended_long) = timed_edge(&mut long, t);
                if ended && !ended_long {
                    with += a;
                    without += b;
                    n += 1;
                }
            } else {
                black_box(short.on_edge(black_box(t), Some(Direction::Forward)));
                black_box(long.on_edge(black_box(t), Some(Direction::Forward)));
            }
        }
    }
    let d = with.saturating_sub(without);
    ((d + u64::from(n) / 2) / u64::from(n.max(1)), n)
}

pub fn run() {
    let Some(ticks) = cortex_m::singleton!(: [u32; EDGES] = [0; EDGES]) else {
        crate::bench::fail(format_args!("edge buffer taken twice"));
    };
    generate(ticks);
    hprintln!(
        "pulses: {} lines, {} revolutions, 84 MHz timer, expected delta {:.6}",
        LINES,
        REVS,
        2.0 * EPS
    );
    let empty = feed_empty(ticks);
    hprintln!(
        "memory: DeltaMonitor<1024> {} bytes",
        core::mem::size_of::<DeltaMonitor<1024>>()
    );

    // The report, with 16-edge speed samples and 8-revolution windows (printed in a pass of
    // its own, so formatting stays out of the measured passes).
    feed(&mut monitor(16, 8), ticks, true);
    let mut m = monitor(16, 8);
    let (total16, windows) = feed(&mut m, ticks, false);
    let d = m.diagnostics();
    hprintln!(
        "diagnostics: accepted {} glitches {} missing {} revolutions {} valid windows {} invalid {}",
        d.edges.accepted, d.edges.glitches, d.edges.missing, d.edges.revolutions,
        d.valid_windows, d.invalid_windows
    );
    ensure!(
        windows == 5 && d.valid_windows == 5,
        "expected 5 valid windows, got {:?}",
        d
    );
    ensure!(
        d.edges.glitches == 0 && d.edges.missing == 0,
        "unexpected faults {:?}",
        d
    );

    // Instructions per edge, amortised over the stream (windows included).
    let per_edge = |total: u64| (total.saturating_sub(empty) + EDGES as u64 / 2) / EDGES as u64;
    hprintln!(
        "bench {:<28} {:>7}",
        "monitor::on_edge k=16",
        per_edge(total16)
    );
    let mut m1 = monitor(1, 8);
    let (total1, _) = feed(&mut m1, ticks, false);
    hprintln!(
        "bench {:<28} {:>7}",
        "monitor::on_edge k=1",
        per_edge(total1)
    );

    // Window finishing (δ report, alarm, restart), per window.
    let (finish, finished) = window_finish(ticks);
    ensure!(
        finished == FINISH_PASSES * (REVS as u32 - 2),
        "expected {} finished windows, got {}",
        FINISH_PASSES * (REVS as u32 - 2),
        finished
    );
    hprintln!("bench {:<28} {:>7}", "monitor::window_finish", finish);

    // Check the δ the target computed against the known ripple (quantization floor ≈ 3e-5).
    let mut check = monitor(16, 8);
    let mut last = None;
    for (i, &t) in ticks.iter().enumerate() {
        if i % LINES as usize == 0 {
            check.on_index(t.wrapping_sub(1));
        }
        if let Some(o) = check.on_edge(t, Some(Direction::Forward)) {
            last = o.report.measurement().copied();
        }
    }
    let Some(r) = last else {
        crate::bench::fail(format_args!("no window reported"));
    };
    let err = libm::fabs(f64::from(r.delta) / (2.0 * EPS) - 1.0);
    hprintln!(
        "delta: measured {:.6}, exact {:.6}, relative error {:.1e}",
        r.delta,
        2.0 * EPS,
        err
    );
    ensure!(
        err < 3e-3,
        "delta {} off the exact {} by {}",
        r.delta,
        2.0 * EPS,
        err
    );
    ensure!(
        r.steady && !check.alarm_active(),
        "window not steady or alarm raised: {:?}",
        r
    );
}
