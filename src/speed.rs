//! Edge timing: from raw capture timestamps to framed, checked speed samples.
//!
//! [`SpeedTracker`] takes each capture timestamp as a raw counter value (ticks; the counter
//! wraps modulo 2^bits). Intervals are taken with wrapping integer subtraction and masked to
//! the counter width; floats appear only after the subtraction. Every edge is classified:
//! accepted, or rejected as a glitch (impossibly early). Revolutions are framed by the index
//! pulse or the missing-tooth gap, and the tooth count of every revolution is checked: a
//! missing or extra edge is a [`Fault`], never interpolated. The shaft state is explicit
//! ([`ShaftState`]): no signal, standstill (no edge within the timeout derived from the minimum
//! speed), running, reversed.
//!
//! A speed sample is the angle of the last `K` teeth over their interval in ticks; both are
//! kept as exact numbers (the interval as an integer sum), so a sample carries no drift however
//! long the shaft runs.

use crate::encoder::{Encoder, Framing};

/// Largest `K` of the `K`-edge estimator (size of the interval ring).
pub const MAX_SPAN: usize = 64;

/// Direction of rotation reported with an edge (e.g. from the quadrature B channel).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Direction {
    /// Running forward (the measured direction).
    Forward,
    /// Running backwards.
    Reverse,
}

/// What the shaft is doing, as far as the edges tell.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ShaftState {
    /// No edge seen since start or reset.
    NoSignal,
    /// Edges stopped: none within the timeout.
    Standstill,
    /// Edges arriving in the forward direction.
    Running,
    /// Edges arriving with the reverse direction flag.
    Reversed,
}

/// Why an edge or a window could not be trusted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fault {
    /// An edge arrived impossibly early (or with a zero interval) and was rejected.
    Glitch,
    /// An interval spans more than one tooth, or a revolution had too few edges.
    MissingEdge,
    /// A revolution had more edges than the disc has.
    ExtraEdge,
    /// The frame marker (index pulse or gap) was not seen where it was due.
    MissingFrame,
    /// The direction input reported reverse rotation.
    Reversal,
    /// No edge within the timeout: the shaft stopped (or the signal was lost).
    Timeout,
}

/// A speed sample: `angle` radians travelled in `ticks` timer ticks, ending at `tooth`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SpeedSample {
    /// Angle of the averaged teeth, rad.
    pub angle: f32,
    /// Their interval, timer ticks (exact).
    pub ticks: u32,
    /// The tooth the sample ends at.
    pub tooth: u16,
}

impl SpeedSample {
    /// Speed in rad/s for a timer of `timer_hz`.
    #[inline]
    pub fn omega(&self, timer_hz: f32) -> f32 {
        self.angle * timer_hz / self.ticks as f32
    }
}

/// What one edge produced.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EdgeEvent {
    /// The accepted edge's interval in ticks and its tooth, when teeth are framed.
    pub interval: Option<(u32, u16)>,
    /// A speed sample ending at this edge.
    pub sample: Option<SpeedSample>,
    /// This edge is tooth 0 of a correctly counted revolution.
    pub frame: bool,
    /// A fault found at this edge.
    pub fault: Option<Fault>,
}

/// Counters of everything the tracker accepted or rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EdgeCounters {
    /// Edges accepted.
    pub accepted: u32,
    /// Edges rejected as glitches.
    pub glitches: u32,
    /// Missing edges detected (long intervals or short revolutions).
    pub missing: u32,
    /// Revolutions with too many edges.
    pub extra: u32,
    /// Frame markers missed.
    pub missing_frames: u32,
    /// Changes to reverse rotation.
    pub reversals: u32,
    /// Timeouts (standstill or lost signal).
    pub timeouts: u32,
    /// Correctly counted revolutions.
    pub revolutions: u32,
}

/// The exact interval sum of a full ring of `k` intervals, from the sum modulo 2^32, saturated
/// at `u32::MAX`.
///
/// Each interval is 1 to `timeout` ticks (0 is a glitch, more is a timeout) and the encoder
/// checks K·timeout < 2^32 before rounding `timeout` up to whole ticks, so the exact sum is at
/// least `k` and below 2^32 + `k`. A sum modulo 2^32 below `k` therefore means it wrapped, and
/// the exact sum is at least 2^32: saturate. Keeping the running sum in one 32-bit word instead
/// of a u64 pair keeps it in registers on the per-edge path.
#[inline]
fn full_ring_ticks(sum: u32, k: u16) -> u32 {
    if sum < u32::from(k) {
        u32::MAX
    } else {
        sum
    }
}

/// Per-edge state of the timing front end. Total: every input sequence is handled without
/// panicking, and every path is O(1).
#[derive(Debug, Clone)]
pub struct SpeedTracker {
    /// `Running` or `Reversed` exactly when `last` holds the previous edge's time.
    state: ShaftState,
    last: u32,
    /// Previous accepted interval and the pitch it spanned (0 when none).
    prev_dt: u32,
    prev_pitch: f32,
    synced: bool,
    /// Tooth of the last accepted edge (valid when `synced`).
    tooth: u16,
    index_pending: bool,
    ring: [u32; MAX_SPAN],
    ring_pos: u16,
    ring_fill: u16,
    /// Sum of the ring's intervals modulo 2^32 (see [`full_ring_ticks`]).
    ring_sum: u32,
    counters: EdgeCounters,
}

impl Default for SpeedTracker {
    fn default() -> Self {
        Self::new()
    }
}

impl SpeedTracker {
    /// A tracker that has seen nothing yet.
    pub const fn new() -> Self {
        SpeedTracker {
            state: ShaftState::NoSignal,
            last: 0,
            prev_dt: 0,
            prev_pitch: 0.0,
            synced: false,
            tooth: 0,
            index_pending: false,
            ring: [0; MAX_SPAN],
            ring_pos: 0,
            ring_fill: 0,
            ring_sum: 0,
            counters: EdgeCounters {
                accepted: 0,
                glitches: 0,
                missing: 0,
                extra: 0,
                missing_frames: 0,
                reversals: 0,
                timeouts: 0,
                revolutions: 0,
            },
        }
    }

    /// The shaft state.
    pub fn state(&self) -> ShaftState {
        self.state
    }

    /// Whether teeth are identified (the revolution is framed).
    pub fn synced(&self) -> bool {
        self.synced
    }

    /// The counters.
    pub fn counters(&self) -> EdgeCounters {
        self.counters
    }

    #[cold]
    fn lose_sync(&mut self) {
        self.synced = false;
        self.index_pending = false;
        self.clear_ring();
    }

    #[cold]
    fn count(&mut self, f: Fault) -> Fault {
        let c = &mut self.counters;
        let n = match f {
            Fault::Glitch => &mut c.glitches,
            Fault::MissingEdge => &mut c.missing,
            Fault::ExtraEdge => &mut c.extra,
            Fault::MissingFrame => &mut c.missing_frames,
            Fault::Reversal => &mut c.reversals,
            Fault::Timeout => &mut c.timeouts,
        };
        *n = n.wrapping_add(1);
        f
    }

    fn clear_ring(&mut self) {
        self.ring_fill = 0;
        self.ring_pos = 0;
        self.ring_sum = 0;
    }

    /// An index pulse was captured. Call it before the edge that follows the pulse.
    pub fn on_index(&mut self) {
        self.index_pending = true;
    }

    /// Checks for a timeout at time `now` (ticks). Call it at least once per counter period:
    /// elapsed time is measured modulo the counter.
    pub fn poll<const N: usize>(&mut self, enc: &Encoder<N>, now: u32) -> Option<Fault> {
        if !self.has_last() {
            return None;
        }
        let elapsed = now.wrapping_sub(self.last) & enc.mask();
        if elapsed > enc.timeout_ticks() {
            self.enter_standstill();
            return Some(Fault::Timeout);
        }
        None
    }

    /// Whether `last` holds the time of the previous edge (running forward or reversed).
    fn has_last(&self) -> bool {
        matches!(self.state, ShaftState::Running | ShaftState::Reversed)
    }

    #[cold]
    fn enter_standstill(&mut self) {
        self.state = ShaftState::Standstill;
        self.prev_dt = 0;
        self.count(Fault::Timeout);
        self.lose_sync();
    }

    /// Processes one captured edge at `ticks` (raw counter value).
    pub fn on_edge<const N: usize>(
        &mut self,
        enc: &Encoder<N>,
        ticks: u32,
        direction: Option<Direction>,
    ) -> EdgeEvent {
        let ticks = ticks & enc.mask();
        // Only a shaft running forward gives an interval: after start, standstill or reversal
        // the edge is a new time reference.
        if direction == Some(Direction::Reverse) || self.state != ShaftState::Running {
            return self.restart(enc, ticks, direction);
        }
        let dt = ticks.wrapping_sub(self.last) & enc.mask();
        if dt > enc.timeout_ticks() {
            return self.restart_after_timeout(ticks);
        }
        self.on_interval(enc, dt, ticks)
    }

    /// An edge that gives no interval: reverse rotation, or the first edge after start,
    /// standstill or reversal. Off the per-edge path.
    #[cold]
    #[inline(never)]
    fn restart<const N: usize>(
        &mut self,
        enc: &Encoder<N>,
        ticks: u32,
        direction: Option<Direction>,
    ) -> EdgeEvent {
        let mut ev = EdgeEvent::default();
        if direction == Some(Direction::Reverse) {
            if self.state != ShaftState::Reversed {
                self.state = ShaftState::Reversed;
                ev.fault = Some(self.count(Fault::Reversal));
            }
            self.lose_sync();
            self.last = ticks;
            self.prev_dt = 0;
            return ev;
        }
        // First edge after start, standstill or reversal: only a time reference, but an
        // index pulse before it still frames it as tooth 0.
        self.state = ShaftState::Running;
        self.last = ticks;
        self.prev_dt = 0;
        if self.index_pending && enc.config().framing == Framing::Index {
            self.index_pending = false;
            self.synced = true;
            self.tooth = 0;
            self.clear_ring();
        }
        ev
    }

    /// The shaft stopped and restarted between two polls.
    #[cold]
    #[inline(never)]
    fn restart_after_timeout(&mut self, ticks: u32) -> EdgeEvent {
        self.enter_standstill();
        self.state = ShaftState::Running;
        self.last = ticks;
        EdgeEvent {
            fault: Some(Fault::Timeout),
            ..EdgeEvent::default()
        }
    }

    /// An edge `dt` ticks after the previous accepted one, at `ticks`; the shaft is running
    /// forward (and stays so: a glitch or a fault does not change the state).
    #[inline(always)]
    fn on_interval<const N: usize>(&mut self, enc: &Encoder<N>, dt: u32, ticks: u32) -> EdgeEvent {
        let mut ev = EdgeEvent::default();
        let edges = enc.edges();
        let next = if self.synced {
            if self.tooth + 1 >= edges {
                0
            } else {
                self.tooth + 1
            }
        } else {
            1
        };
        let uniform = enc.uniform_pitch();
        let was_synced = self.synced;
        let next_pitch = if was_synced { enc.pitch(next) } else { uniform };
        // This interval's ticks scaled by the previous pitch, `num`: against
        // `prev_dt·uniform` it is the apparent pitch in uniform pitches (compared by
        // cross-multiplying: no division on the per-edge path).
        let num = if self.prev_dt > 0 {
            dt as f32 * self.prev_pitch
        } else {
            1.0
        };
        let gap_framing = matches!(enc.config().framing, Framing::MissingTooth { .. });
        let glitch_fraction = enc.config().glitch_fraction;
        // Unsynced on a gapped disc the next interval may be a gap or follow one: only an
        // interval short even against that (ratio below glitch_fraction / gap_ratio / 2) is a
        // glitch.
        // Both counts are quantized to ±1 tick: an interval is a glitch only if its ratio is
        // below the limit even at its largest, (dt + 1)/(prev − 1), and "long" (a missing edge)
        // only if above 1.5 even at its smallest, (dt − 1)/(prev + 1); a coarse timer's
        // rounding is then neither.
        let (num_hi, den_lo, num_lo, den_hi) = if self.prev_dt > 0 {
            let (d, p) = (dt as f32, self.prev_dt as f32);
            (
                (d + 1.0) * self.prev_pitch,
                (p - 1.0) * next_pitch,
                (d - 1.0) * self.prev_pitch,
                (p + 1.0) * next_pitch,
            )
        } else {
            (1.0, 1.0, 1.0, 1.0)
        };
        let glitch = if !self.synced && gap_framing {
            num_hi * (2.0 * enc.gap_ratio()) < glitch_fraction * den_lo
        } else {
            num_hi < glitch_fraction * den_lo
        };
        if dt == 0 || glitch {
            ev.fault = Some(self.count(Fault::Glitch));
            return ev;
        }
        self.last = ticks;
        self.counters.accepted = self.counters.accepted.wrapping_add(1);

        let mut tooth = next;
        // Apparent pitch of this interval in uniform pitches, `num / uniform_den`: ≈1 for a
        // tooth, ≈m+1 for a gap.
        let uniform_den = self.prev_dt as f32 * uniform;
        let long = self.prev_dt > 0 && num_lo > 1.5 * den_hi;
        match enc.config().framing {
            Framing::MissingTooth { .. } => {
                let gap = self.prev_dt > 0 && num > enc.gap_ratio() * uniform_den;
                if self.synced {
                    if gap && next != 0 {
                        // Too few edges before the gap; the gap itself still frames tooth 0.
                        ev.fault = Some(self.count(Fault::MissingEdge));
                        self.clear_ring();
                        tooth = 0;
                    } else if !gap && next == 0 {
                        ev.fault = Some(self.count(Fault::ExtraEdge));
                        self.lose_sync();
                    } else if !gap && long {
                        ev.fault = Some(self.count(Fault::MissingEdge));
                        self.lose_sync();
                    } else if next == 0 {
                        ev.frame = true;
                    }
                } else if gap {
                    self.synced = true;
                    self.clear_ring();
                    tooth = 0;
                }
            }
            Framing::Index => {
                let index = self.index_pending;
                self.index_pending = false;
                if self.synced {
                    if index && next != 0 {
                        let f = if next > edges / 2 {
                            Fault::MissingEdge
                        } else {
                            Fault::ExtraEdge
                        };
                        ev.fault = Some(self.count(f));
                        self.clear_ring();
                        tooth = 0;
                    } else if !index && next == 0 {
                        ev.fault = Some(self.count(Fault::MissingFrame));
                        self.lose_sync();
                    } else if long {
                        ev.fault = Some(self.count(Fault::MissingEdge));
                        self.lose_sync();
                    } else if next == 0 {
                        ev.frame = true;
                    }
                } else if index {
                    self.synced = true;
                    self.clear_ring();
                    tooth = 0;
                }
            }
            Framing::None => {
                if !self.synced {
                    // Without a marker the first accepted interval starts the count.
                    self.synced = true;
                    tooth = 0;
                } else if long {
                    ev.fault = Some(self.count(Fault::MissingEdge));
                    self.clear_ring();
                } else if next == 0 {
                    ev.frame = true;
                }
            }
        }
        let pitch = if self.synced {
            if was_synced && tooth == next {
                next_pitch
            } else {
                enc.pitch(tooth)
            }
        } else {
            // Unframed: the interval spanned a whole number of uniform pitches.
            let apparent = if self.prev_dt > 0 {
                num / uniform_den
            } else {
                1.0
            };
            uniform * libm::roundf(apparent).max(1.0)
        };
        self.prev_dt = dt;
        self.prev_pitch = pitch;
        if !self.synced {
            return ev;
        }
        self.tooth = tooth;
        if ev.frame {
            self.counters.revolutions = self.counters.revolutions.wrapping_add(1);
        }
        ev.interval = Some((dt, tooth));
        // K-edge ring: exact integer running sum (add the new interval, drop the oldest).
        let k = enc.samples_span().min(MAX_SPAN as u16);
        let pos = usize::from(self.ring_pos) % MAX_SPAN;
        let oldest = match self.ring.get_mut(pos) {
            Some(slot) => core::mem::replace(slot, dt),
            None => 0,
        };
        if self.ring_fill >= k {
            self.ring_sum = self.ring_sum.wrapping_sub(oldest);
        } else {
            self.ring_fill += 1;
        }
        self.ring_sum = self.ring_sum.wrapping_add(dt);
        self.ring_pos = if self.ring_pos + 1 >= k {
            0
        } else {
            self.ring_pos + 1
        };
        if self.ring_fill >= k {
            ev.sample = Some(SpeedSample {
                angle: enc.span(tooth),
                ticks: full_ring_ticks(self.ring_sum, k),
                tooth,
            });
        }
        ev
    }
}
