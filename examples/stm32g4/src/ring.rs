//! The bookkeeping of the capture path, without hardware: which slots of the DMA ring to feed
//! next ([`Cursor`]), when a queued index pulse is due ([`IndexQueue`]), and how a block of
//! captures and the index pulses among them are handed to the monitor ([`feed_block`],
//! [`release_indices`]).
//!
//! This file is also compiled on the host by `host-test/`, which runs it against a simulated
//! DMA and the real core.

use drive_monitor::monitor::{DeltaMonitor, WindowOutcome};
use drive_monitor::pitch::PitchTable;
use heapless::Deque;

/// Captures in the DMA ring. Each half (64 captures: 1/16 revolution of a 1024-line disc) is
/// one block for the monitor.
pub const RING: usize = 128;
/// Captures in one half of the ring.
pub const HALF: usize = RING / 2;
const _: () = assert!(
    RING % 2 == 0 && RING <= u16::MAX as usize,
    "DMA_CNDTR is 16-bit"
);

/// What to do with the ring.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Step {
    /// Feed slots `start..end` (within one half; `end` may be [`RING`]).
    Feed {
        /// First slot.
        start: usize,
        /// One past the last slot.
        end: usize,
    },
    /// The handler ran a half late: the slots it should have fed are being overwritten.
    /// Nothing is fed; reading resumes at the start of the half the DMA is writing, and the
    /// monitor sees the gap as lost teeth (counted missing; the count is given up and the
    /// frame found again).
    Overrun,
    /// Nothing to feed.
    Idle,
}

/// The next ring slot not yet fed. Every slot the DMA writes is fed once, in order, by the
/// interrupt that says its half has filled or, earlier, by a poll.
#[derive(Clone, Copy, Debug, Default)]
pub struct Cursor {
    consumed: usize,
}

impl Cursor {
    /// At slot 0, where the DMA starts.
    pub const fn new() -> Self {
        Cursor { consumed: 0 }
    }

    /// The DMA interrupt: `half` and `complete` are the flags it took (half transfer: slots
    /// `0..HALF` have filled; transfer complete: slots `HALF..RING` have, and the DMA wrapped),
    /// `write` the DMA's write position read after them.
    pub fn on_dma(&mut self, half: bool, complete: bool, write: usize) -> Step {
        // The half that has just filled, and whether the DMA is still writing the other one:
        // if it has come round into this half, or both flags are up, the handler ran a half
        // late.
        let (end, in_time) = match (half, complete) {
            (false, false) => return Step::Idle,
            (true, false) => (HALF, write >= HALF),
            (false, true) => (RING, write < HALF),
            (true, true) => (RING, false),
        };
        if !in_time || !(end - HALF..=end).contains(&self.consumed) {
            self.consumed = if write >= HALF { HALF } else { 0 };
            return Step::Overrun;
        }
        self.take(end)
    }

    /// The periodic poll: the slots written so far in the half the DMA is writing. `write`
    /// must have been read while neither flag was pending (no half left unfed).
    pub fn on_poll(&mut self, write: usize) -> Step {
        let start = if write >= HALF { HALF } else { 0 };
        if !(start..=write).contains(&self.consumed) {
            return Step::Idle;
        }
        self.take(write)
    }

    fn take(&mut self, end: usize) -> Step {
        let start = self.consumed;
        self.consumed = if end >= RING { 0 } else { end };
        if end > start {
            Step::Feed { start, end }
        } else {
            Step::Idle
        }
    }
}

/// Index timestamps waiting for the edge that follows them. One index per revolution, taken
/// at least at every half of the ring: more than one is pending only on a disc with fewer
/// lines than a half holds.
#[derive(Clone, Debug, Default)]
pub struct IndexQueue {
    queue: Deque<u32, 4>,
}

impl IndexQueue {
    /// Empty.
    pub const fn new() -> Self {
        IndexQueue {
            queue: Deque::new(),
        }
    }

    /// Queues an index captured at `ticks`; `false` if the queue was full (the pulse is lost).
    pub fn push(&mut self, ticks: u32) -> bool {
        self.queue.push_back(ticks).is_ok()
    }

    /// Pops the oldest index if it came at or before `ticks` and returns its timestamp: it is
    /// due before that edge (an edge at the very tick of the index counts as after it).
    /// Timestamps compare by their wrapped difference, valid while an index waits less than
    /// 2^31 ticks (12.6 s at 170 MHz); the poll delivers it well within that.
    pub fn due(&mut self, ticks: u32) -> Option<u32> {
        match self.queue.front() {
            Some(&index) if (ticks.wrapping_sub(index) as i32) >= 0 => self.queue.pop_front(),
            _ => None,
        }
    }

    /// Whether an index waits.
    pub fn is_empty(&self) -> bool {
        self.queue.is_empty()
    }
}

/// Hands a block of consecutive captures (raw timer counts, wrapping) to `monitor` in order,
/// with the index pulses queued in `index`: each goes in by `on_index` just before the first
/// capture at or after it, the captures between them by the batch entry point `on_captures`,
/// which passes every window that ends to `on_window`. An index after the block's last
/// capture stays queued.
///
/// This is what edge-by-edge feeding (`on_index` before the edge that follows the index, then
/// `on_edge` per capture) would do; the core gives the same results for a batch as for its
/// edges one by one. (The core also places an index handed over earlier by its timestamp, with
/// the same results, but it closes its fast path from `on_index` until the index's edge: the
/// split keeps the captures before the index on the fast path.)
pub fn feed_block<const N: usize, P: PitchTable>(
    monitor: &mut DeltaMonitor<N, P>,
    index: &mut IndexQueue,
    captures: &[u32],
    mut on_window: impl FnMut(WindowOutcome),
) {
    let mut rest = captures;
    while !index.is_empty() {
        // The first capture the oldest index is due before, if the block holds one.
        let mut split = None;
        for (k, &ticks) in rest.iter().enumerate() {
            if let Some(at) = index.due(ticks) {
                split = Some((k, at));
                break;
            }
        }
        let Some((k, at)) = split else {
            break;
        };
        let (before, after) = (rest.get(..k).unwrap_or(&[]), rest.get(k..).unwrap_or(&[]));
        monitor.on_captures(before, &mut on_window);
        monitor.on_index(at);
        rest = after;
    }
    monitor.on_captures(rest, on_window);
}

/// Hands `monitor` the queued index pulses at or before `settled`, a time by which every
/// capture taken has been fed: no capture after such an index has been seen yet, so it goes
/// in just before the next one, as [`feed_block`] would have put it.
pub fn release_indices<const N: usize, P: PitchTable>(
    monitor: &mut DeltaMonitor<N, P>,
    index: &mut IndexQueue,
    settled: u32,
) {
    while let Some(at) = index.due(settled) {
        monitor.on_index(at);
    }
}
