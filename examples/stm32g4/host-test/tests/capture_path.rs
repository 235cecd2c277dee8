//! The firmware's capture bookkeeping against a simulated DMA ring.
//!
//! The DMA model writes one capture per step into a ring of `RING` slots, raising the
//! half-transfer flag when it fills slot `HALF - 1` and the transfer-complete flag when it
//! fills the last slot and wraps, like DMA1 in circular mode. The CPU model takes the flags
//! and reads the write position the way the firmware's handlers do (`feed.rs`), with the DMA
//! allowed to move on between those reads, and hands the blocks to the core with the
//! firmware's own `ring::feed_block` (the batch entry point `on_captures`, split at index
//! pulses) and `ring::release_indices`.

use drive_monitor::encoder::EncoderConfig;
use drive_monitor::monitor::{DeltaMonitor, Diagnostics, MonitorConfig, WindowOutcome};
use drive_monitor::speed::Direction;
use drive_monitor_stm32g4_host_test::config::{self, Monitor};
use drive_monitor_stm32g4_host_test::ring::{
    feed_block, release_indices, Cursor, IndexQueue, Step, HALF, RING,
};

/// xorshift64*: a fixed, seedable sequence.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }

    /// Uniform in `0..n`.
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// DMA1 channel 1 in circular mode, writing captures into the ring.
struct Dma {
    ring: [u32; RING],
    write: usize,
    half: bool,
    complete: bool,
    /// Captures written since the pending flag went up.
    since_flag: u64,
}

impl Dma {
    fn new() -> Self {
        Dma {
            ring: [0; RING],
            write: 0,
            half: false,
            complete: false,
            since_flag: 0,
        }
    }

    fn put(&mut self, value: u32) {
        if self.pending() {
            self.since_flag += 1;
        }
        self.ring[self.write] = value;
        self.write += 1;
        if self.write == HALF {
            self.half = true;
        }
        if self.write == RING {
            self.complete = true;
            self.write = 0;
        }
    }

    fn pending(&self) -> bool {
        self.half || self.complete
    }

    /// Takes and clears the flags, as `capture::take_dma_events` does.
    fn take(&mut self) -> (bool, bool) {
        let flags = (self.half, self.complete);
        self.half = false;
        self.complete = false;
        self.since_flag = 0;
        flags
    }
}

/// Runs the stream `0..n` through the DMA model and the cursor; returns what was fed and the
/// number of overruns. A handler runs once the DMA has written up to `max_latency` captures
/// after a flag (more if a poll's race writes came first); the DMA writes up to `race`
/// captures between a handler's two register reads.
fn run_cursor(seed: u64, n: u32, max_latency: u64, race: u64) -> (Vec<u32>, u32) {
    let mut rng = Rng(seed);
    let mut dma = Dma::new();
    let mut cursor = Cursor::new();
    let mut fed = Vec::new();
    let mut overruns = 0;
    let mut next = 0u32;
    let mut latency = rng.below(max_latency + 1);

    let feed = |step: Step, dma: &Dma, fed: &mut Vec<u32>, overruns: &mut u32| match step {
        Step::Feed { start, end } => {
            assert!(start < end && end <= RING && end - start <= HALF);
            assert!(start / HALF == (end - 1) / HALF, "a block within one half");
            fed.extend_from_slice(&dma.ring[start..end]);
        }
        Step::Overrun => *overruns += 1,
        Step::Idle => {}
    };
    let write_more = |dma: &mut Dma, next: &mut u32, k: u64| {
        for _ in 0..k {
            if *next < n {
                dma.put(*next);
                *next += 1;
            }
        }
    };

    while next < n {
        write_more(&mut dma, &mut next, 1);
        // DMA1_CHANNEL1's handler: the flags, then (after the DMA moved on) the position.
        if dma.pending() && dma.since_flag >= latency {
            let (half, complete) = dma.take();
            write_more(&mut dma, &mut next, rng.below(race + 1));
            let step = cursor.on_dma(half, complete, dma.write);
            feed(step, &dma, &mut fed, &mut overruns);
            latency = rng.below(max_latency + 1);
        }
        // SysTick's poll: the position, then (after the DMA moved on) the flags.
        if rng.below(8) == 0 {
            let write = dma.write;
            write_more(&mut dma, &mut next, rng.below(race + 1));
            if !dma.pending() {
                let step = cursor.on_poll(write);
                feed(step, &dma, &mut fed, &mut overruns);
            }
        }
    }
    // The stream has ended: the handler takes what is flagged, then a poll the rest.
    if dma.pending() {
        let (half, complete) = dma.take();
        let step = cursor.on_dma(half, complete, dma.write);
        feed(step, &dma, &mut fed, &mut overruns);
    }
    let step = cursor.on_poll(dma.write);
    feed(step, &dma, &mut fed, &mut overruns);
    (fed, overruns)
}

/// The configuration the compiler validated (`config::CONFIG`) is the one validated at run
/// time for the same clock, and the firmware's monitor takes it.
#[test]
fn the_compile_time_configuration_is_the_run_time_one() {
    let now = MonitorConfig::new(
        config::encoder(f64::from(std::hint::black_box(config::TIMER_HZ))),
        config::window(),
        Some(config::alarm()),
    )
    .expect("the firmware's configuration is valid");
    assert_eq!(now, config::CONFIG);
    let mut m = Monitor::unconfigured();
    m.apply(&config::CONFIG)
        .expect("the wheel fits the monitor");
    assert_eq!(usize::from(m.encoder().edges()), config::CAPACITY);
    assert_eq!(m.window_revolutions(), 8);
}

#[test]
fn every_capture_is_fed_once_in_order_when_the_handlers_keep_up() {
    // The handler reads the position fewer than HALF captures after the flag: at most
    // max_latency, + race + 1 written by a poll before the check, + race of its own.
    for seed in 1..=200 {
        let race = seed % 4;
        let max_latency = HALF as u64 - 2 - 2 * race;
        let n = 5_000 + seed as u32 * 7;
        let (fed, overruns) = run_cursor(seed, n, max_latency, race);
        assert_eq!(overruns, 0, "seed {seed}");
        assert_eq!(fed.len(), n as usize, "seed {seed}");
        assert!(
            fed.iter().zip(0u32..).all(|(&f, k)| f == k),
            "seed {seed}: fed out of order or twice"
        );
    }
}

#[test]
fn a_late_handler_is_an_overrun_and_nothing_stale_is_fed() {
    let mut total_overruns = 0;
    for seed in 1..=200 {
        // Handlers up to three rings late.
        let (fed, overruns) = run_cursor(seed, 20_000, 3 * RING as u64, 3);
        total_overruns += overruns;
        assert!(
            fed.windows(2).all(|w| w[0] < w[1]),
            "seed {seed}: a capture fed twice or out of order"
        );
        if overruns == 0 {
            assert_eq!(
                fed.len(),
                20_000,
                "seed {seed}: captures lost without an overrun"
            );
        } else {
            assert!(fed.len() < 20_000, "seed {seed}");
        }
    }
    assert!(
        total_overruns > 0,
        "the late handlers never overran: the test is vacuous"
    );
}

#[test]
fn an_index_is_due_at_or_before_its_edge_across_the_wrap() {
    let mut q = IndexQueue::new();
    assert!(q.push(u32::MAX - 5));
    assert_eq!(q.due(u32::MAX - 6), None, "an edge before the index");
    assert_eq!(
        q.due(u32::MAX - 5),
        Some(u32::MAX - 5),
        "an edge at the index's tick is after it"
    );
    assert_eq!(q.due(u32::MAX - 5), None, "delivered once");
    assert!(q.is_empty());
    assert!(q.push(u32::MAX - 1));
    assert_eq!(
        q.due(3),
        Some(u32::MAX - 1),
        "an edge after the counter wrapped"
    );
    for k in 0..4 {
        assert!(q.push(k));
    }
    assert!(!q.push(4), "a fifth pending index is reported lost");
}

/// Capture timestamps (TIM2 ticks at 170 MHz, not yet wrapped) of a `lines`-line disc on a
/// shaft running ω(φ) = ω̄·(1 + ε·sin(φ/8))·(1 + 0.004·φ/Φ) over the run's angle Φ (the slow
/// drift makes every window differ from the one shifted by an edge, so misframing shows),
/// and the index pulse of every revolution, `index_lead` ticks before its tooth 0 (0: at its
/// tick).
fn stream(
    lines: usize,
    omega: f64,
    revolutions: usize,
    start: u64,
    index_lead: u64,
) -> (Vec<u64>, Vec<u64>) {
    const EPS: f64 = 0.015;
    let pitch = core::f64::consts::TAU / lines as f64;
    let run = pitch * (lines * revolutions) as f64;
    let mut t = 0.0f64;
    let mut edges = Vec::new();
    let mut indices = Vec::new();
    for i in 0..lines * revolutions {
        let mid = (i as f64 + 0.5) * pitch;
        let w = omega * (1.0 + EPS * (mid / 8.0).sin()) * (1.0 + 0.004 * mid / run);
        t += pitch / w;
        let ticks = start + (t * 170e6) as u64;
        if i % lines == 0 {
            indices.push(ticks - index_lead);
        }
        edges.push(ticks);
    }
    (edges, indices)
}

/// The firmware's monitor, configured in place as `main` does it, with `encoder` (the
/// firmware's, `config::encoder`, or a variant of it).
fn monitor(encoder: EncoderConfig) -> Monitor {
    let mut m = Monitor::unconfigured();
    m.configure_from(encoder, config::window(), Some(config::alarm()))
        .expect("the firmware's configuration is valid");
    m
}

/// What a run reported.
#[derive(Debug)]
struct Run {
    outcomes: Vec<WindowOutcome>,
    diagnostics: Diagnostics,
    overruns: u32,
    /// Length of every block handed to `feed_block`.
    blocks: Vec<usize>,
}

/// The firmware's path, modelled: TIM2 latches the index, DMA1 fills the ring, DMA1_CHANNEL1's
/// handler and a 100 Hz poll feed what the cursor gives them with the firmware's `feed_block`,
/// and the poll hands over the index pulses no edge has followed with `release_indices`.
fn run_firmware_path(mut m: Monitor, seed: u64, edges: &[u64], indices: &[u64]) -> Run {
    const POLL_TICKS: u64 = 1_700_000; // 100 Hz at 170 MHz
    const SETTLE_TICKS: u32 = 1_700; // `Feeder::settle_ticks`
    let mut rng = Rng(seed);
    let mut dma = Dma::new();
    let mut cursor = Cursor::new();
    let mut queue = IndexQueue::new();
    let mut latch: Option<u32> = None;
    let mut outcomes = Vec::new();
    let mut blocks = Vec::new();
    let mut latency = rng.below(HALF as u64 / 2);
    let mut next_poll = edges[0] - edges[0] % POLL_TICKS + POLL_TICKS;
    let mut overruns = 0;
    let (mut e, mut x) = (0, 0);

    // `Feeder::feed_slots` and `Feeder::feed`.
    let mut feed = |m: &mut Monitor, queue: &mut IndexQueue, dma: &Dma, start, end| {
        let block = dma.ring[start..end].to_vec();
        blocks.push(block.len());
        feed_block(m, queue, &block, |o| outcomes.push(o));
    };
    let collect = |latch: &mut Option<u32>, queue: &mut IndexQueue| {
        if let Some(ticks) = latch.take() {
            assert!(queue.push(ticks));
        }
    };

    while e < edges.len() {
        let edge_time = edges[e];
        let index_time = indices.get(x).copied().unwrap_or(u64::MAX);
        if next_poll < edge_time.min(index_time) {
            // SysTick: position, now, flags; then the index latch, the partial half, poll,
            // and the indices no edge has followed.
            let write = dma.write;
            let now = next_poll as u32;
            next_poll += POLL_TICKS;
            if dma.pending() {
                continue;
            }
            collect(&mut latch, &mut queue);
            if let Step::Feed { start, end } = cursor.on_poll(write) {
                feed(&mut m, &mut queue, &dma, start, end);
            }
            if let Some(o) = m.poll(now) {
                // Through `feed`'s closure too: `outcomes` is borrowed by it.
                panic!("a running shaft was taken for a stopped one: {o:?}");
            }
            release_indices(&mut m, &mut queue, now.wrapping_sub(SETTLE_TICKS));
            continue;
        }
        if index_time <= edge_time {
            // TIM2 latches CCR2; its handler takes it now or a later handler does.
            assert!(
                latch.replace(index_time as u32).is_none(),
                "index overcapture"
            );
            if rng.below(2) == 0 {
                collect(&mut latch, &mut queue);
            }
            x += 1;
            continue;
        }
        dma.put(edge_time as u32);
        e += 1;
        // DMA1_CHANNEL1's handler, up to HALF/2 captures after the flag: in time.
        if dma.pending() && dma.since_flag >= latency {
            let (half, complete) = dma.take();
            match cursor.on_dma(half, complete, dma.write) {
                Step::Feed { start, end } => {
                    collect(&mut latch, &mut queue);
                    feed(&mut m, &mut queue, &dma, start, end);
                }
                Step::Overrun => overruns += 1,
                Step::Idle => {}
            }
            latency = rng.below(HALF as u64 / 2);
        }
    }
    if dma.pending() {
        let (half, complete) = dma.take();
        if let Step::Feed { start, end } = cursor.on_dma(half, complete, dma.write) {
            collect(&mut latch, &mut queue);
            feed(&mut m, &mut queue, &dma, start, end);
        }
    }
    if let Step::Feed { start, end } = cursor.on_poll(dma.write) {
        feed(&mut m, &mut queue, &dma, start, end);
    }
    Run {
        outcomes,
        diagnostics: m.diagnostics(),
        overruns,
        blocks,
    }
}

/// The reference: every edge straight into the monitor by `on_edge`, each index by
/// `on_index` with its timestamp just before the first edge at or after it.
fn run_edge_by_edge<const N: usize>(
    mut m: DeltaMonitor<N>,
    edges: &[u64],
    indices: &[u64],
) -> (Vec<WindowOutcome>, Diagnostics) {
    let mut outcomes = Vec::new();
    let mut x = 0;
    for &t in edges {
        while x < indices.len() && indices[x] <= t {
            m.on_index(indices[x] as u32);
            x += 1;
        }
        if let Some(o) = m.on_edge(t as u32, Some(Direction::Forward)) {
            outcomes.push(o);
        }
    }
    (outcomes, m.diagnostics())
}

/// Runs the firmware path over six seeds (handler latencies, when the index latch is taken)
/// and checks it reports exactly the windows and counters of edge-by-edge feeding; returns
/// the runs.
fn assert_same_windows(
    encoder: EncoderConfig,
    edges: &[u64],
    indices: &[u64],
    what: &str,
) -> Vec<Run> {
    let (reference, diagnostics) = run_edge_by_edge(monitor(encoder), edges, indices);
    let valid = reference.iter().filter(|o| o.report.valid()).count();
    assert!(
        valid >= 2,
        "{what}: only {valid} valid windows, the comparison is weak: {reference:?}"
    );
    let mut runs = Vec::new();
    for seed in 1..=6 {
        let run = run_firmware_path(monitor(encoder), seed, edges, indices);
        assert_eq!(run.overruns, 0, "{what}, seed {seed}");
        assert_eq!(run.outcomes, reference, "{what}, seed {seed}");
        assert_eq!(run.diagnostics, diagnostics, "{what}, seed {seed}");
        assert_eq!(
            run.blocks.iter().sum::<usize>(),
            edges.len(),
            "{what}, seed {seed}: every capture fed once"
        );
        runs.push(run);
    }
    runs
}

/// The fraction of captures that reached the core in whole halves of the ring.
fn in_whole_halves(run: &Run) -> f64 {
    let whole: usize = run.blocks.iter().filter(|&&n| n == HALF).sum();
    whole as f64 / run.blocks.iter().sum::<usize>() as f64
}

#[test]
fn the_firmware_path_reports_the_windows_of_edge_by_edge_feeding() {
    // 134 rad/s, starting 1 ms before the 32-bit counter wraps; index at tooth 0's tick, and
    // half a pitch early.
    let start = (1u64 << 32) - 170_000;
    for lead in [0, 3_900] {
        let (edges, indices) = stream(usize::from(config::LINES), 134.0, 8 * 4 + 2, start, lead);
        let what = format!("134 rad/s, index {lead} ticks early");
        for run in assert_same_windows(config::encoder(170e6), &edges, &indices, &what) {
            // A half fills in 1.5 ms and the poll comes every 10 ms: most captures reach the
            // core through the DMA interrupt, a whole half per `on_captures`.
            let whole = in_whole_halves(&run);
            assert!(
                whole > 0.7,
                "{what}: {whole} of the captures in whole halves"
            );
        }
    }
}

#[test]
fn a_slow_shaft_is_not_taken_for_a_stopped_one_while_its_half_fills() {
    // 2 rad/s: 64 captures take 196 ms, far beyond the 6 ms standstill timeout, so the poll
    // must feed the part of the half filled so far. The run crosses two counter wraps.
    for lead in [0, 260_000] {
        let (edges, indices) = stream(usize::from(config::LINES), 2.0, 8 * 2 + 3, 1_000, lead);
        let what = format!("2 rad/s, index {lead} ticks early");
        for run in assert_same_windows(config::encoder(170e6), &edges, &indices, &what) {
            let whole = in_whole_halves(&run);
            assert!(
                whole < 0.1,
                "{what}: {whole} of the captures in whole halves"
            );
        }
    }
}

#[test]
fn prescaled_captures_take_the_same_path() {
    // The timer's input prescaler at 4 (`config::EDGES_PER_CAPTURE`): one capture every fourth
    // line, starting at the second, so the index falls between captures; the core is told
    // `prescaler = 4`.
    let mut encoder = config::encoder(170e6);
    encoder.prescaler = 4;
    let start = (1u64 << 32) - 170_000;
    let (edges, indices) = stream(usize::from(config::LINES), 134.0, 8 * 4 + 2, start, 0);
    let captured: Vec<u64> = edges.iter().skip(1).step_by(4).copied().collect();
    for run in assert_same_windows(encoder, &captured, &indices, "prescaler 4") {
        // A half (256 lines) takes 11.7 ms, longer than the poll's 10 ms: most halves reach
        // the core in two parts, each still a batch.
        let mean = captured.len() as f64 / run.blocks.len() as f64;
        assert!(mean > 16.0, "{mean} captures per block");
    }
}

#[test]
fn feed_block_splits_at_every_index_whatever_the_block_boundaries() {
    // A 16-line disc: a block of up to 60 captures holds up to four index pulses (as many as
    // the queue holds), and a block may end at, just before or just after one.
    let lines = 16;
    let mut encoder = EncoderConfig::indexed(lines as u16, 170e6);
    encoder.min_speed = config::MIN_SPEED;
    let make = || {
        let mut m = DeltaMonitor::<16>::unconfigured();
        m.configure_from(encoder, config::window(), Some(config::alarm()))
            .expect("valid");
        m
    };
    for lead in [0, 1, 20_000] {
        let (edges, indices) = stream(lines, 8.0, 8 * 6 + 1, (1u64 << 32) - 9_000_000, lead);
        let (reference, diagnostics) = run_edge_by_edge(make(), &edges, &indices);
        assert!(reference.iter().filter(|o| o.report.valid()).count() >= 4);
        let wrapped: Vec<u32> = edges.iter().map(|&t| t as u32).collect();
        for seed in 1..=20 {
            let mut rng = Rng(seed);
            let mut m = make();
            let mut queue = IndexQueue::new();
            let mut outcomes = Vec::new();
            let (mut k, mut x) = (0, 0);
            while k < wrapped.len() {
                let n = (1 + rng.below(60) as usize).min(wrapped.len() - k);
                let block = &wrapped[k..k + n];
                // Every index captured up to the block's last edge is queued.
                while x < indices.len() && indices[x] <= edges[k + n - 1] {
                    assert!(queue.push(indices[x] as u32));
                    x += 1;
                }
                feed_block(&mut m, &mut queue, block, |o| outcomes.push(o));
                k += n;
            }
            assert_eq!(outcomes, reference, "index {lead} ticks early, seed {seed}");
            assert_eq!(m.diagnostics(), diagnostics, "seed {seed}");
        }
    }
}
