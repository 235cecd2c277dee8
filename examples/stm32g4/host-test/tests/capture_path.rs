//! The firmware's capture bookkeeping against a simulated DMA ring.
//!
//! The DMA model writes one capture per step into a ring of `RING` slots, raising the
//! half-transfer flag when it fills slot `HALF - 1` and the transfer-complete flag when it
//! fills the last slot and wraps, like DMA1 in circular mode. The CPU model takes the flags
//! and reads the write position the way the firmware's handlers do (`feed.rs`), with the DMA
//! allowed to move on between those reads.

use drive_monitor::monitor::WindowOutcome;
use drive_monitor::speed::Direction;
use drive_monitor_stm32g4_host_test::config;
use drive_monitor_stm32g4_host_test::ring::{Cursor, IndexQueue, Step, HALF, RING};

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
    assert!(!q.due(u32::MAX - 6), "an edge before the index");
    assert!(
        q.due(u32::MAX - 5),
        "an edge at the index's tick is after it"
    );
    assert!(!q.due(u32::MAX - 5), "delivered once");
    assert!(q.push(u32::MAX - 1));
    assert!(q.due(3), "an edge after the counter wrapped");
    for k in 0..4 {
        assert!(q.push(k));
    }
    assert!(!q.push(4), "a fifth pending index is reported lost");
}

/// Capture timestamps (TIM2 ticks at 170 MHz, not yet wrapped) of a 1024-line disc on a shaft
/// running ω(φ) = ω̄·(1 + ε·sin(φ/8))·(1 + 0.004·φ/Φ) over the run's angle Φ (the slow drift
/// makes every window differ from the one shifted by an edge, so misframing shows), and the
/// index pulse of every revolution, `index_lead` ticks before its tooth 0 (0: at its tick).
fn stream(omega: f64, revolutions: usize, start: u64, index_lead: u64) -> (Vec<u64>, Vec<u64>) {
    const EPS: f64 = 0.015;
    let lines = usize::from(config::LINES);
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

/// The firmware's path, modelled: TIM2 latches the index, DMA1 fills the ring, DMA1_CHANNEL1's
/// handler and a 100 Hz poll feed what the cursor gives them, with `feed.rs`'s loop.
fn run_firmware_path(seed: u64, edges: &[u64], indices: &[u64]) -> (Vec<WindowOutcome>, u32) {
    const POLL_TICKS: u64 = 1_700_000; // 100 Hz at 170 MHz
    const SETTLE_TICKS: u32 = 1_700; // `Feeder::settle_ticks`
    let mut rng = Rng(seed);
    let mut monitor = config::monitor(170e6).expect("the firmware's configuration is valid");
    let mut dma = Dma::new();
    let mut cursor = Cursor::new();
    let mut queue = IndexQueue::new();
    let mut latch: Option<u32> = None;
    let mut outcomes = Vec::new();
    let mut latency = rng.below(HALF as u64 / 2);
    let mut next_poll = edges[0] - edges[0] % POLL_TICKS + POLL_TICKS;
    let mut overruns = 0;
    let (mut e, mut x) = (0, 0);

    // `Feeder::feed`.
    let feed = |monitor: &mut config::Monitor,
                queue: &mut IndexQueue,
                captures: &[u32],
                outcomes: &mut Vec<WindowOutcome>| {
        for &ticks in captures {
            while queue.due(ticks) {
                monitor.on_index();
            }
            if let Some(o) = monitor.on_edge(ticks, Some(Direction::Forward)) {
                outcomes.push(o);
            }
        }
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
                let block = dma.ring[start..end].to_vec();
                feed(&mut monitor, &mut queue, &block, &mut outcomes);
            }
            if let Some(o) = monitor.poll(now) {
                outcomes.push(o);
            }
            while queue.due(now.wrapping_sub(SETTLE_TICKS)) {
                monitor.on_index();
            }
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
                    let block = dma.ring[start..end].to_vec();
                    feed(&mut monitor, &mut queue, &block, &mut outcomes);
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
            let block = dma.ring[start..end].to_vec();
            feed(&mut monitor, &mut queue, &block, &mut outcomes);
        }
    }
    if let Step::Feed { start, end } = cursor.on_poll(dma.write) {
        let block = dma.ring[start..end].to_vec();
        feed(&mut monitor, &mut queue, &block, &mut outcomes);
    }
    (outcomes, overruns)
}

/// The reference: every edge straight into the monitor, `on_index` just before each tooth 0.
fn run_edge_by_edge(edges: &[u64]) -> Vec<WindowOutcome> {
    let lines = usize::from(config::LINES);
    let mut monitor = config::monitor(170e6).expect("the firmware's configuration is valid");
    let mut outcomes = Vec::new();
    for (i, &t) in edges.iter().enumerate() {
        if i % lines == 0 {
            monitor.on_index();
        }
        if let Some(o) = monitor.on_edge(t as u32, Some(Direction::Forward)) {
            outcomes.push(o);
        }
    }
    outcomes
}

fn assert_same_windows(omega: f64, revolutions: usize, start: u64, index_lead: u64) {
    let (edges, indices) = stream(omega, revolutions, start, index_lead);
    let reference = run_edge_by_edge(&edges);
    let valid = reference.iter().filter(|o| o.report.valid()).count();
    assert!(
        valid >= 2,
        "ω̄ {omega}: only {valid} valid windows, the comparison is weak"
    );
    for seed in 1..=6 {
        let (outcomes, overruns) = run_firmware_path(seed, &edges, &indices);
        assert_eq!(overruns, 0);
        assert_eq!(
            outcomes, reference,
            "ω̄ {omega}, index {index_lead} ticks early, seed {seed}"
        );
    }
}

#[test]
fn the_firmware_path_reports_the_windows_of_edge_by_edge_feeding() {
    // 134 rad/s, starting 1 ms before the 32-bit counter wraps; index at tooth 0's tick, and
    // half a pitch early.
    let start = (1u64 << 32) - 170_000;
    assert_same_windows(134.0, 8 * 4 + 2, start, 0);
    assert_same_windows(134.0, 8 * 4 + 2, start, 3_900);
}

#[test]
fn a_slow_shaft_is_not_taken_for_a_stopped_one_while_its_half_fills() {
    // 2 rad/s: 64 captures take 196 ms, far beyond the 6 ms standstill timeout, so the poll
    // must feed the part of the half filled so far. The run crosses two counter wraps.
    assert_same_windows(2.0, 8 * 2 + 3, 1_000, 0);
    assert_same_windows(2.0, 8 * 2 + 3, 1_000, 260_000);
}
