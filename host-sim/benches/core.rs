//! Host benchmarks of the core's hot paths (criterion), the counterparts of the firmware's
//! instruction counts: the per-edge update over a 1024-line pulse stream, the window finish
//! amortised over it, a small crank wheel's edges while its frame is sought and once synced,
//! the support-load update, and the predicted δ.
//!
//! Kept quick (20 samples, short warm-up and measurement) so a full `cargo bench` stays within
//! CI budgets; `cargo bench --no-run` only compiles them.

use std::hint::black_box;
use std::time::Duration;

use criterion::{BatchSize, Criterion, Throughput};
use drive_monitor::alarm::AlarmConfig;
use drive_monitor::drive::{DriveModel, Harmonic, Load, Parabola};
use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator};
use drive_monitor::irregularity::{WindowConfig, WindowLength};
use drive_monitor::monitor::DeltaMonitor;
use drive_monitor::speed::{Direction, SyncState};
use drive_monitor::supports::{
    Limits, ProcessLoad, Rotor, SupportAnalysis, Unbalance, DEFAULT_WARNING_FRACTION,
};
use host_sim::studies::accuracy::pulse_train;

const LINES: u16 = 1024;
const TIMER_HZ: f64 = 84e6;
const REVS: u32 = 8 * 5 + 2;

/// Capture timestamps of the kneader-like ripple ω = 134·(1 + 0.015·sin(φ/8)) rad/s on a
/// 1024-line disc and an 84 MHz timer (as the firmware's monitor section).
fn stream() -> Vec<u32> {
    pulse_train(134.0, 0.015, LINES, TIMER_HZ, REVS)
}

fn monitor(k: u16, revs: u16) -> DeltaMonitor<1024> {
    let mut c = EncoderConfig::indexed(LINES, TIMER_HZ);
    c.estimator = Estimator::Edges(k);
    c.min_speed = 10.0;
    let enc = Encoder::new(c).expect("encoder");
    let w = WindowConfig {
        length: WindowLength::Revolutions(revs),
        steady_tolerance: 0.02,
    };
    DeltaMonitor::new(enc, w, Some(AlarmConfig::new(0.06))).expect("monitor")
}

/// Feeds the whole stream (index pulse before every tooth 0); returns the windows reported.
fn feed(m: &mut DeltaMonitor<1024>, ticks: &[u32]) -> u32 {
    let mut windows = 0;
    for (i, &t) in ticks.iter().enumerate() {
        if i % usize::from(LINES) == 0 {
            m.on_index(t.wrapping_sub(1));
        }
        if black_box(m.on_edge(black_box(t), Some(Direction::Forward))).is_some() {
            windows += 1;
        }
    }
    windows
}

/// Feeds the stream in batches of `batch` captures (a DMA ring's halves), the index pulse
/// reported before the batch holding its edge.
fn feed_batches(m: &mut DeltaMonitor<1024>, ticks: &[u32], batch: usize) -> u32 {
    let mut windows = 0;
    for (c, chunk) in ticks.chunks(batch).enumerate() {
        let first = c * batch;
        let index = first.div_ceil(usize::from(LINES)) * usize::from(LINES);
        if index < first + chunk.len() {
            m.on_index(ticks[index].wrapping_sub(1));
        }
        m.on_captures(black_box(chunk), |_| windows += 1);
    }
    windows
}

fn bench_monitor(c: &mut Criterion) {
    let ticks = stream();
    let mut g = c.benchmark_group("monitor");
    g.throughput(Throughput::Elements(ticks.len() as u64));
    // k = 1 and k = 16 with 8-revolution windows: the per-edge cost; 1-revolution windows on
    // the same edges finish 8× as many windows, so the difference is the window finish.
    for (name, k, revs) in [
        ("on_edge k=1", 1, 8),
        ("on_edge k=16", 16, 8),
        ("on_edge k=16 window=1", 16, 1),
    ] {
        let fresh = monitor(k, revs);
        g.bench_function(name, |b| {
            b.iter_batched_ref(|| fresh.clone(), |m| feed(m, &ticks), BatchSize::LargeInput)
        });
    }
    let fresh = monitor(16, 8);
    g.bench_function("on_captures/64 k=16", |b| {
        b.iter_batched_ref(
            || fresh.clone(),
            |m| feed_batches(m, &ticks, 64),
            BatchSize::LargeInput,
        )
    });
    g.finish();
}

/// Capture timestamps (1 MHz timer) of a `positions`-1 wheel cranking at ω = 25·(1 + 0.4·sin 2φ)
/// rad/s for `revs` revolutions, each tooth's time the integral of dφ/ω (Simpson's rule, 64
/// steps a grid position: a stream to be fed, not a reference).
fn crank_stream(positions: u8, revs: u32) -> Vec<u32> {
    let omega = |phi: f64| 25.0 * (1.0 + 0.4 * (2.0 * phi).sin());
    let step = std::f64::consts::TAU / f64::from(positions) / 64.0;
    let (mut t, mut phi, mut ticks) = (0.0f64, 0.0f64, Vec::new());
    for k in 0..revs * u32::from(positions) {
        for _ in 0..32 {
            let (a, m, b) = (phi, phi + step, phi + 2.0 * step);
            t += 2.0 * step / 6.0 * (1.0 / omega(a) + 4.0 / omega(m) + 1.0 / omega(b));
            phi = b;
        }
        // Teeth half a position after the grid mark; the last position is the gap.
        if k % u32::from(positions) != u32::from(positions) - 1 {
            ticks.push((t * 1e6) as u32);
        }
    }
    ticks
}

fn bench_crank(c: &mut Criterion) {
    // An 8-1 wheel: the smallest a whole revolution of intervals is fitted for, edge by edge
    // while the frame is sought (the first three revolutions, from a fresh monitor: it syncs
    // in the third) and once synced (every edge judged against the last revolution).
    let positions = 8u8;
    let ticks = crank_stream(positions, 12);
    let per_rev = usize::from(positions) - 1;
    let mut cfg = EncoderConfig::missing_teeth(positions, 1, 1e6);
    cfg.estimator = Estimator::Edges(1);
    cfg.min_speed = 5.0;
    let w = WindowConfig {
        length: WindowLength::Revolutions(1),
        steady_tolerance: 0.02,
    };
    let fresh =
        DeltaMonitor::<64>::new(Encoder::new(cfg).expect("encoder"), w, None).expect("monitor");
    let (seek, rest) = ticks.split_at(3 * per_rev);
    let mut synced = fresh.clone();
    for &t in seek {
        synced.on_edge(t, None);
    }
    assert_eq!(
        synced.sync_state(),
        SyncState::Synced,
        "the bench stream syncs"
    );
    let mut g = c.benchmark_group("crank 8-1");
    for (name, start, edges) in [
        ("on_edge seeking the frame", &fresh, seek),
        ("on_edge synced", &synced, rest),
    ] {
        g.throughput(Throughput::Elements(edges.len() as u64));
        g.bench_function(name, |b| {
            b.iter_batched_ref(
                || start.clone(),
                |m| {
                    for &t in edges {
                        black_box(m.on_edge(black_box(t), None));
                    }
                },
                BatchSize::SmallInput,
            )
        });
    }
    g.finish();
}

fn bench_supports(c: &mut Criterion) {
    let rotor: Rotor<4> = Rotor::new(
        350.0,
        1.9,
        0.0,
        4.0,
        &[Unbalance::new(1.2, 2e-3, 30f64.to_radians())],
        Some(ProcessLoad {
            per_length: 400.0,
            from: 0.5,
            to: 3.5,
            angle: 270f64.to_radians(),
        }),
    )
    .expect("rotor");
    let limits =
        Limits::new(6.3, 60.0, Some([8000.0, 8000.0]), DEFAULT_WARNING_FRACTION).expect("limits");
    let monitor = SupportAnalysis::new(&rotor, &limits)
        .expect("analysis")
        .monitor()
        .expect("monitor");
    let speeds: Vec<f32> = (0..64).map(|i| 60.0 * i as f32).collect();
    let mut g = c.benchmark_group("supports");
    g.throughput(Throughput::Elements(speeds.len() as u64));
    g.bench_function("update", |b| {
        b.iter(|| {
            for &w in &speeds {
                black_box(monitor.update(black_box(w)));
            }
        })
    });
    g.finish();
    c.bench_function("supports/analysis", |b| {
        b.iter(|| black_box(SupportAnalysis::new(black_box(&rotor), &limits)))
    });
}

fn bench_drive(c: &mut Criterion) {
    let model = |harmonics: &[Harmonic]| {
        DriveModel::new(
            Parabola::new(145.0, 36.0, 158.0).expect("motor").into(),
            Load::new(24.0, harmonics).expect("load"),
            0.323,
            0.0,
        )
        .expect("drive")
    };
    let h = |order, amplitude, phase| Harmonic::new(order, amplitude, phase).expect("harmonic");
    let one = [h(0.125, 12.0, 0.0)];
    let two = [h(0.125, 12.0, 0.0), h(0.5, 6.0, 1.0)];
    let seed = model(&one);
    c.bench_function("drive/new+predict 1 harmonic", |b| {
        b.iter(|| black_box(model(black_box(&one)).predict()))
    });
    c.bench_function("drive/new+predict 2 harmonics", |b| {
        b.iter(|| black_box(model(black_box(&two)).predict()))
    });
    c.bench_function("drive/flywheel_for 1 harmonic", |b| {
        b.iter(|| black_box(black_box(&seed).flywheel_for(0.01)))
    });
}

fn main() {
    let mut c = Criterion::default()
        .sample_size(20)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_millis(600))
        .configure_from_args();
    bench_monitor(&mut c);
    bench_crank(&mut c);
    bench_supports(&mut c);
    bench_drive(&mut c);
    c.final_summary();
}
