//! The bookkeeping of the capture path, without hardware: which slots of the DMA ring to feed
//! next ([`Cursor`]), and when a queued index pulse is due ([`IndexQueue`]).
//!
//! This file is also compiled on the host by `host-test/`, which runs it against a simulated
//! DMA and the real core.

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
    /// monitor sees the gap as missing edges.
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

    /// Pops the oldest index if it came at or before `ticks`: it is due before that edge (an
    /// edge at the very tick of the index counts as after it). Timestamps compare by their
    /// wrapped difference, valid while an index waits less than 2^31 ticks (12.6 s at
    /// 170 MHz); the poll delivers it well within that.
    pub fn due(&mut self, ticks: u32) -> bool {
        match self.queue.front() {
            Some(&index) if (ticks.wrapping_sub(index) as i32) >= 0 => {
                self.queue.pop_front();
                true
            }
            _ => false,
        }
    }
}
