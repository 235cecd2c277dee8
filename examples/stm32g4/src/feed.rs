//! Where the captures meet the core: the blocks of the DMA ring and the index timestamps in,
//! δ windows, the alarm pin and the log out.
//!
//! [`Feeder::feed`] is the one place the monitor is given captures. Two paths lead to it, both
//! in interrupt handlers serialized by one critical section (`main`):
//! - DMA1 channel 1's half-transfer / transfer-complete interrupt: the half of the ring that
//!   has just filled ([`Feeder::on_dma`]);
//! - the periodic poll (SysTick): the part of the current half filled so far, so that edges
//!   waiting for their half to fill are not mistaken for a stopped shaft ([`Feeder::on_poll`]).
//!
//! Which slots each feeds is decided by [`crate::ring::Cursor`], so that every slot is fed once
//! and in order; the index pulses wait in [`crate::ring::IndexQueue`] until the block with the
//! edge after them is fed ([`crate::ring::feed_block`]) or a poll finds no edge after them yet
//! ([`crate::ring::release_indices`]). Those three are the hardware-free part, tested on the
//! host (`host-test/`).

use drive_monitor::alarm::{AlarmEvent, AlarmOutput};
use drive_monitor::monitor::{fault_name, WindowOutcome};
use embassy_stm32::gpio::Output;

use crate::capture::{self, DmaEvents, TimerEvents, CAPTURES};
use crate::config::Monitor;
use crate::ring::{self, Cursor, IndexQueue, Step, HALF};

/// What the capture path counted.
#[derive(Clone, Copy, Debug, Default, defmt::Format)]
pub struct Stats {
    /// Blocks given to the monitor.
    pub blocks: u32,
    /// Captures given to the monitor.
    pub captures: u32,
    /// Halves of the ring overwritten before they were read (the handler ran a half too late).
    pub overruns: u32,
    /// DMA transfer errors.
    pub transfer_errors: u32,
    /// Encoder captures lost in the timer (a second edge before the DMA read TIM2_CCR1).
    pub lost_captures: u32,
    /// Index pulses captured.
    pub indices: u32,
    /// Index pulses lost (overcapture, or the queue full).
    pub lost_indices: u32,
}

/// The monitor with its inputs and outputs.
pub struct Feeder {
    monitor: &'static mut Monitor,
    alarm: AlarmOutput<Output<'static>>,
    index: IndexQueue,
    cursor: Cursor,
    /// Ticks by which a capture is surely in the ring: the DMA copies CCR1 within a few bus
    /// cycles, this allows 10 µs.
    settle_ticks: u32,
    stats: Stats,
}

impl Feeder {
    /// A feeder for `monitor`, driving `alarm`, for a capture timer counting at `counter_hz`.
    pub fn new(
        monitor: &'static mut Monitor,
        alarm: AlarmOutput<Output<'static>>,
        counter_hz: u32,
    ) -> Self {
        Feeder {
            monitor,
            alarm,
            index: IndexQueue::new(),
            cursor: Cursor::new(),
            settle_ticks: counter_hz / 100_000,
            stats: Stats::default(),
        }
    }

    /// The monitor.
    pub fn monitor(&self) -> &Monitor {
        self.monitor
    }

    /// The capture path's counters.
    pub fn stats(&self) -> Stats {
        self.stats
    }

    /// Takes TIM2's index capture and overcapture flags: from TIM2's interrupt, and before
    /// every block so that an index captured before the block's last edge is in the queue.
    pub fn on_timer_events(&mut self, events: TimerEvents) {
        if let Some(ticks) = events.index {
            self.stats.indices = self.stats.indices.wrapping_add(1);
            if !self.index.push(ticks) {
                self.stats.lost_indices = self.stats.lost_indices.wrapping_add(1);
            }
        }
        if events.index_overcapture {
            self.stats.lost_indices = self.stats.lost_indices.wrapping_add(1);
        }
        if events.capture_overcapture {
            self.stats.lost_captures = self.stats.lost_captures.wrapping_add(1);
        }
    }

    /// DMA1 channel 1's interrupt: feeds the half of the ring that has just filled.
    pub fn on_dma(&mut self, events: DmaEvents) {
        if events.error {
            self.stats.transfer_errors = self.stats.transfer_errors.wrapping_add(1);
            defmt::error!("DMA transfer error: capture stopped");
        }
        let write = capture::write_position();
        match self.cursor.on_dma(events.half, events.complete, write) {
            Step::Feed { start, end } => {
                self.on_timer_events(capture::take_timer_events());
                self.feed_slots(start, end);
            }
            Step::Overrun => self.stats.overruns = self.stats.overruns.wrapping_add(1),
            Step::Idle => {}
        }
    }

    /// The periodic poll: feeds what the current half holds so far, delivers index pulses no
    /// edge has followed yet, and lets the monitor check for a stopped shaft.
    pub fn on_poll(&mut self) {
        // In this order: every capture fed below was in the ring when `write` was read, so it
        // was taken before `now`, and `now` minus the last fed edge never wraps.
        let write = capture::write_position();
        let now = capture::now();
        if capture::dma_block_pending() {
            // DMA1_CHANNEL1's handler is about to feed a block: edges are arriving.
            return;
        }
        self.on_timer_events(capture::take_timer_events());
        if let Step::Feed { start, end } = self.cursor.on_poll(write) {
            self.feed_slots(start, end);
        }

        if let Some(outcome) = self.monitor.poll(now) {
            report(&mut self.alarm, &outcome);
        }
        // Every capture taken before `settled` was in the ring when `write` was read and has
        // been fed. An index queued at or before `settled` therefore has no edge after it yet:
        // all that follow are still to come, so it can be handed over now, as it would be
        // just before its edge.
        let settled = now.wrapping_sub(self.settle_ticks);
        ring::release_indices(self.monitor, &mut self.index, settled);
    }

    /// Feeds ring slots `start..end` (within one half).
    fn feed_slots(&mut self, start: usize, end: usize) {
        let mut block = [0u32; HALF];
        let captures = CAPTURES.copy_block(start, end, &mut block);
        self.feed(captures);
    }

    /// The one place the monitor takes captures: a block of consecutive channel-A timestamps
    /// (raw TIM2 counts, wrapping modulo 2^32; one every `config::EDGES_PER_CAPTURE` edges),
    /// usually the half of the ring that has just filled. It goes to the core's batch entry
    /// point `on_captures` in one call, split only where a queued index pulse falls: that goes
    /// in by `on_index(ticks)` just before the first capture at or after it
    /// ([`ring::feed_block`]). Each window that ends is logged and shown on the alarm pin as it
    /// ends.
    fn feed(&mut self, captures: &[u32]) {
        self.stats.blocks = self.stats.blocks.wrapping_add(1);
        self.stats.captures = self.stats.captures.wrapping_add(captures.len() as u32);
        let alarm = &mut self.alarm;
        ring::feed_block(self.monitor, &mut self.index, captures, |outcome| {
            report(alarm, &outcome)
        });
    }
}

/// Logs a finished window and shows an alarm transition on the pin.
fn report(alarm: &mut AlarmOutput<Output<'static>>, outcome: &WindowOutcome) {
    let r = &outcome.report;
    match &r.result {
        Ok(m) => defmt::info!(
            "δ {=f32} | ω mean {=f32} rad/s, min {=f32}, max {=f32} | floor {=f32} | steady {=bool} | {=u16} rev, {=u32} samples | {}",
            m.delta,
            m.omega_mean,
            m.omega_min,
            m.omega_max,
            m.noise_floor,
            m.steady,
            r.revolutions,
            m.samples,
            outcome.verdict
        ),
        Err(fault) => defmt::warn!(
            "window invalid: {=str} after {=u16} rev",
            fault_name(*fault),
            r.revolutions
        ),
    }
    let active = match outcome.event {
        Some(AlarmEvent::Raised) => {
            defmt::warn!("δ alarm raised");
            true
        }
        Some(AlarmEvent::Cleared) => {
            defmt::info!("δ alarm cleared");
            false
        }
        None => return,
    };
    match alarm.show(active) {
        Ok(()) => {}
        Err(never) => match never {},
    }
}
