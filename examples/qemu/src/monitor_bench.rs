//! The irregularity monitor on the target: a pulse sequence of known δ through the public API,
//! what the core reports, checks on it, and what it costs per edge, in RAM and in stack.
//!
//! The sequence is the capture timestamps of a 1024-line disc (index framing, 84 MHz 32-bit
//! timer) on a shaft running ω(φ) = ω̄·(1 + ε·sin(φ/8)) with ω̄ = 134 rad/s: a load cycle of
//! 8 revolutions like the seed's kneader, and δ = 2ε exactly. Timestamps are generated in f64
//! (midpoint rule per pitch, error far below one tick) before anything is measured. The index
//! pulse of each revolution is reported (with its timestamp, one tick before the revolution's
//! first edge) before that revolution's edges, as an index capture interrupt would.
//!
//! Lines printed (the names are a contract, `docs/accuracy.md` quotes them):
//! `bench monitor::on_edge`, `bench monitor::on_edge+learner`, `bench monitor::on_captures/64`
//! (instructions per edge, with two decimals), `bench monitor::window_finish` (per window),
//! `memory: DeltaMonitor<1024>`, `memory: DeltaMonitor<1024>+learner` (bytes),
//! `stack: construct` (bytes).

use core::hint::black_box;

use cortex_m_semihosting::hprintln;
use drive_monitor::alarm::AlarmConfig;
use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator};
use drive_monitor::irregularity::{WindowConfig, WindowLength, MAX_WINDOW_REVS};
use drive_monitor::learn::ToothLearner;
use drive_monitor::monitor::{DeltaMonitor, MonitorConfig};
use drive_monitor::pitch::Corrected;
use drive_monitor::speed::Direction;
use drive_monitor::ConfigError;

use crate::bench::ensure;
use crate::entry_points;
use crate::icount;

const LINES: u16 = 1024;
const PER_REV: usize = LINES as usize;
const TIMER_HZ: f64 = 84e6;
const REVS: usize = 8 * 5 + 2;
const EDGES: usize = PER_REV * REVS;
const EPS: f64 = 0.015;
const OMEGA: f64 = 134.0;
/// Captures per batch, as half of a 128-entry DMA ring delivers them (the contract line; a
/// batch of a whole revolution is measured beside it).
const BATCH: usize = 64;

type Ticks = [u32; EDGES];

fn generate(ticks: &mut Ticks) {
    let pitch = core::f64::consts::TAU / f64::from(LINES);
    let mut t = 0.0f64;
    for (i, slot) in ticks.iter_mut().enumerate() {
        let mid = (i as f64 + 0.5) * pitch;
        t += pitch / (OMEGA * (1.0 + EPS * libm::sin(mid / 8.0)));
        *slot = (t * TIMER_HZ) as u64 as u32;
    }
}

const fn encoder_config(k: u16) -> EncoderConfig {
    let mut c = EncoderConfig::indexed(LINES, TIMER_HZ);
    c.estimator = Estimator::Edges(k);
    c.min_speed = 10.0;
    c
}

const fn window(revs: u16) -> WindowConfig {
    WindowConfig {
        length: WindowLength::Revolutions(revs),
        steady_tolerance: 0.02,
    }
}

/// The configuration of the entry-point check (16-edge samples, 8-revolution windows, δ
/// limit 0.06), validated by the compiler: no checking code for it is in the image.
const CONFIG: MonitorConfig =
    match MonitorConfig::new(encoder_config(16), window(8), Some(AlarmConfig::new(0.06))) {
        Ok(c) => c,
        Err(e) => panic!("{}", e.parameter()),
    };

fn encoder(k: u16) -> Encoder {
    match Encoder::new(encoder_config(k)) {
        Ok(e) => e,
        Err(e) => crate::bench::fail(format_args!("encoder config rejected: {}", e)),
    }
}

fn monitor(k: u16, revs: u16) -> DeltaMonitor<1024> {
    match DeltaMonitor::new(encoder(k), window(revs), Some(AlarmConfig::new(0.06))) {
        Ok(m) => m,
        Err(e) => crate::bench::fail(format_args!("monitor config rejected: {}", e)),
    }
}

/// The index capture of revolution `rev`: one tick before its first edge.
fn index_of(ticks: &Ticks, rev: usize) -> u32 {
    ticks
        .get(rev * PER_REV)
        .copied()
        .unwrap_or(0)
        .wrapping_sub(1)
}

/// Feeds the stream edge by edge; returns (instructions, windows).
#[inline(never)]
fn feed(m: &mut DeltaMonitor<1024>, ticks: &Ticks, print: bool) -> (u64, u32) {
    let mut windows = 0;
    let start = icount::instructions();
    for (rev, edges) in ticks.chunks_exact(PER_REV).enumerate() {
        m.on_index(index_of(ticks, rev));
        for &t in edges {
            // Only the outcome's presence is looked at in the timed passes, as a caller that
            // acts on windows would (the report itself is read when one is there).
            if let Some(o) = m.on_edge(black_box(t), Some(Direction::Forward)) {
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
    }
    (icount::instructions() - start, windows)
}

/// [`feed`] with a learner watching every tooth.
#[inline(never)]
fn feed_learning(
    m: &mut DeltaMonitor<1024>,
    learner: &mut ToothLearner<1024>,
    ticks: &Ticks,
) -> (u64, u32) {
    let mut windows = 0;
    let start = icount::instructions();
    for (rev, edges) in ticks.chunks_exact(PER_REV).enumerate() {
        m.on_index(index_of(ticks, rev));
        for &t in edges {
            if m.on_edge_observed(black_box(t), Some(Direction::Forward), learner)
                .is_some()
            {
                windows += 1;
            }
        }
    }
    (icount::instructions() - start, windows)
}

/// The same loops without the monitor: what they cost themselves.
#[inline(never)]
fn feed_empty(ticks: &Ticks) -> u64 {
    let start = icount::instructions();
    for (rev, edges) in ticks.chunks_exact(PER_REV).enumerate() {
        black_box(index_of(ticks, rev));
        for &t in edges {
            black_box(t);
        }
    }
    icount::instructions() - start
}

/// Feeds the stream in batches of `batch` captures, the index pulse reported before the batch
/// holding its edge; returns (instructions, windows).
#[inline(never)]
fn feed_batches(m: &mut DeltaMonitor<1024>, ticks: &Ticks, batch: usize) -> (u64, u32) {
    let mut windows = 0;
    let start = icount::instructions();
    for (b, batch_captures) in ticks.chunks_exact(batch).enumerate() {
        let batch_start = b * batch;
        if batch_start % PER_REV == 0 {
            m.on_index(index_of(ticks, batch_start / PER_REV));
        }
        let batch = batch_captures;
        m.on_captures(black_box(batch), |_| windows += 1);
    }
    (icount::instructions() - start, windows)
}

/// The batch loop without the monitor.
#[inline(never)]
fn feed_batches_empty(ticks: &Ticks, batch: usize) -> u64 {
    let start = icount::instructions();
    for (b, batch_captures) in ticks.chunks_exact(batch).enumerate() {
        if (b * batch) % PER_REV == 0 {
            black_box(index_of(ticks, b * batch / PER_REV));
        }
        black_box(batch_captures);
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

/// Instructions that finishing a window adds to the edges that end and return it (the frame
/// edge, and the edge after it, which returns the window held for it), and the number of
/// windows measured. The stream goes through two monitors that differ only in window length:
/// one revolution (every frame edge once the first window has started ends one) and
/// [`MAX_WINDOW_REVS`] (no frame edge of the stream ends one). Each frame edge and the edge
/// after it are timed in both; the cost is the mean difference over the windows returned.
#[inline(never)]
fn window_finish(ticks: &Ticks) -> (u64, u32) {
    let (mut with, mut without, mut n) = (0u64, 0u64, 0u32);
    for _ in 0..FINISH_PASSES {
        let mut short = monitor(16, 1);
        let mut long = monitor(16, MAX_WINDOW_REVS);
        for (rev, edges) in ticks.chunks_exact(PER_REV).enumerate() {
            short.on_index(index_of(ticks, rev));
            long.on_index(index_of(ticks, rev));
            // The frame edge ends the window; the edge after it returns it (a window is held
            // until the edge after its frame is judged): both are timed.
            let (mut at_short, mut at_long) = (0u64, 0u64);
            for (i, &t) in edges.iter().enumerate() {
                if i < 2 {
                    let (a, ended) = timed_edge(&mut short, t);
                    let (b, ended_long) = timed_edge(&mut long, t);
                    at_short += a;
                    at_long += b;
                    if i == 1 && ended && !ended_long {
                        with += at_short;
                        without += at_long;
                        n += 1;
                    }
                } else {
                    black_box(short.on_edge(black_box(t), Some(Direction::Forward)));
                    black_box(long.on_edge(black_box(t), Some(Direction::Forward)));
                }
            }
        }
    }
    let d = with.saturating_sub(without);
    ((d + u64::from(n) / 2) / u64::from(n.max(1)), n)
}

/// Stack used to configure a monitor held in a `static`, in place.
fn construct_stack() -> usize {
    let Some(m) = cortex_m::singleton!(: DeltaMonitor<1024> = DeltaMonitor::unconfigured()) else {
        crate::bench::fail(format_args!("monitor static taken twice"));
    };
    let used = crate::stack::used_by(|| {
        let r = m.configure_from(
            black_box(encoder_config(16)),
            black_box(window(8)),
            black_box(Some(AlarmConfig::new(0.06))),
        );
        ensure!(r.is_ok(), "configuring in place failed: {:?}", r);
    });
    ensure!(
        m.encoder().edges() == LINES,
        "configured monitor has the wrong disc"
    );
    used
}

pub fn run() {
    let Some(ticks) = cortex_m::singleton!(: Ticks = [0; EDGES]) else {
        crate::bench::fail(format_args!("edge buffer taken twice"));
    };
    generate(ticks);
    hprintln!(
        "pulses: {} lines, {} revolutions, 84 MHz timer, expected delta {:.6}",
        LINES,
        REVS,
        2.0 * EPS
    );
    hprintln!(
        "memory: DeltaMonitor<1024> {} bytes",
        core::mem::size_of::<DeltaMonitor<1024>>()
    );
    hprintln!(
        "memory: DeltaMonitor<1024,Corrected<1024>> {} bytes",
        core::mem::size_of::<DeltaMonitor<1024, Corrected<1024>>>()
    );
    // Learning a correction to apply it: the corrected monitor and the learner.
    hprintln!(
        "memory: DeltaMonitor<1024>+learner {} bytes",
        core::mem::size_of::<DeltaMonitor<1024, Corrected<1024>>>()
            + core::mem::size_of::<ToothLearner<1024>>()
    );
    hprintln!("stack: construct {} bytes", construct_stack());

    // The report, with 16-edge speed samples and 8-revolution windows (printed in a pass of
    // its own, so formatting stays out of the measured passes).
    feed(&mut monitor(16, 8), ticks, true);
    let empty = feed_empty(ticks);
    // In hundredths of an instruction, rounded, printed with two decimals (`20.49`): a goal
    // such as "at most 20" shows in the line itself.
    let per_edge = |total: u64, empty: u64| {
        PerEdge((100 * total.saturating_sub(empty) + EDGES as u64 / 2) / EDGES as u64)
    };
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
        d.edges.glitches == 0 && d.edges.missing == 0 && d.edges.missing_frames == 0,
        "unexpected faults {:?}",
        d
    );
    // Instructions per edge, amortised over the stream (windows included).
    hprintln!(
        "bench {:<28} {:>7}",
        "monitor::on_edge",
        per_edge(total16, empty)
    );
    let (total1, _) = feed(&mut monitor(1, 8), ticks, false);
    hprintln!(
        "bench {:<28} {:>7}",
        "monitor::on_edge k=1",
        per_edge(total1, empty)
    );

    // With the learner watching (a per-tooth correction being learned).
    let mut learning = monitor(16, 8);
    let Some(learner) = cortex_m::singleton!(: Option<ToothLearner<1024>> = None) else {
        crate::bench::fail(format_args!("learner taken twice"));
    };
    let Ok(l) = ToothLearner::new(learning.encoder(), 0.01) else {
        crate::bench::fail(format_args!("learner rejected"));
    };
    let learner = learner.insert(l);
    let (total_learning, learned_windows) = feed_learning(&mut learning, learner, ticks);
    ensure!(
        learned_windows == 5,
        "learning changed the windows: {}",
        learned_windows
    );
    ensure!(
        learner.revolutions() >= 25,
        "the learner folded only {} revolutions",
        learner.revolutions()
    );
    hprintln!(
        "bench {:<28} {:>7}",
        "monitor::on_edge+learner",
        per_edge(total_learning, empty)
    );

    // In batches, as a DMA half-buffer delivers them: the same windows, edge for edge.
    for (label, batch) in [
        ("monitor::on_captures/64", BATCH),
        ("monitor::on_captures/1024", PER_REV),
    ] {
        let mut batched = monitor(16, 8);
        let (total_batches, batch_windows) = feed_batches(&mut batched, ticks, batch);
        let empty_batches = feed_batches_empty(ticks, batch);
        ensure!(
            batch_windows == 5 && batched.diagnostics() == m.diagnostics(),
            "batches of {} differ from edge by edge: {:?} vs {:?}",
            batch,
            batched.diagnostics(),
            m.diagnostics()
        );
        hprintln!(
            "bench {:<28} {:>7}",
            label,
            per_edge(total_batches, empty_batches)
        );
    }

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
    for (rev, edges) in ticks.chunks_exact(PER_REV).enumerate() {
        check.on_index(index_of(ticks, rev));
        for &t in edges {
            if let Some(o) = check.on_edge(t, Some(Direction::Forward)) {
                last = o.report.measurement().copied();
            }
        }
    }
    let Some(r) = last else {
        crate::bench::fail(format_args!("no valid window reported"));
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
    entry_points_agree(ticks, r.delta);
}

/// The out-of-line entry points (which `panic-free.sh` checks) report the windows the inlined
/// calls do: the last δ of each way of feeding the stream is `delta`, bit for bit.
fn entry_points_agree(ticks: &Ticks, delta: f32) {
    let mut each = DeltaMonitor::unconfigured();
    let configured = entry_points::configure_monitor(
        &mut each,
        encoder_config(16),
        window(8),
        Some(AlarmConfig::new(0.06)),
    );
    ensure!(
        configured.is_ok(),
        "configuration rejected: {:?}",
        configured
    );
    // The same configuration validated at run time and by the compiler is the same value.
    let checked_now = MonitorConfig::new(
        black_box(encoder_config(16)),
        black_box(window(8)),
        black_box(Some(AlarmConfig::new(0.06))),
    );
    ensure!(
        checked_now.as_ref() == Ok(&CONFIG),
        "the compile-time configuration differs from the run-time one: {:?}",
        checked_now
    );
    // This image is built without pattern wheels: one is refused, naming the wheel.
    let crank = MonitorConfig::new(
        black_box(EncoderConfig::missing_teeth(36, 2, TIMER_HZ)),
        window(8),
        None,
    );
    ensure!(
        crank == Err(ConfigError::Unsupported("wheel")),
        "a pattern wheel in a build without them: {:?}",
        crank
    );
    let mut batched = DeltaMonitor::unconfigured();
    let applied = entry_points::apply_config(&mut batched, &CONFIG);
    ensure!(applied.is_ok(), "configuration not applied: {:?}", applied);
    let mut learning = monitor(16, 8);
    let Ok(mut learner) = ToothLearner::new(learning.encoder(), 0.01) else {
        crate::bench::fail(format_args!("learner rejected"));
    };
    let Ok(mut corrected) = DeltaMonitor::<1024, Corrected<1024>>::new(
        encoder(16),
        window(8),
        Some(AlarmConfig::new(0.06)),
    ) else {
        crate::bench::fail(format_args!("corrected monitor rejected"));
    };
    let mut last = [None::<f32>; 4];
    let mut keep = |slot: usize, o: Option<drive_monitor::monitor::WindowOutcome>| {
        if let Some(m) = o.and_then(|o| o.report.measurement().copied()) {
            if let Some(l) = last.get_mut(slot) {
                *l = Some(m.delta);
            }
        }
    };
    for (rev, edges) in ticks.chunks_exact(PER_REV).enumerate() {
        let index = index_of(ticks, rev);
        entry_points::on_index(&mut each, index);
        entry_points::on_index(&mut batched, index);
        entry_points::on_index(&mut learning, index);
        corrected.on_index(index);
        for &t in edges {
            let d = Some(Direction::Forward);
            keep(0, entry_points::on_edge(&mut each, t, d));
            keep(
                2,
                entry_points::on_edge_learning(&mut learning, &mut learner, t, d),
            );
            keep(3, entry_points::on_edge_corrected(&mut corrected, t, d));
        }
        for batch in edges.chunks(BATCH) {
            keep(1, entry_points::on_captures(&mut batched, batch).0);
        }
    }
    let end = ticks.last().copied().unwrap_or(0);
    ensure!(
        entry_points::poll(&mut each, end.wrapping_add(1)).is_none(),
        "poll right after the last edge ended a window"
    );
    ensure!(
        last.iter().all(|d| *d == Some(delta)),
        "entry points report {:?}, the inlined calls {}",
        last,
        delta
    );
}

/// Instructions per edge in hundredths, shown with two decimals in the bench lines' column
/// (`   20.49`).
#[derive(Clone, Copy)]
struct PerEdge(u64);

impl core::fmt::Display for PerEdge {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "{:>4}.{:02}", self.0 / 100, self.0 % 100)
    }
}
