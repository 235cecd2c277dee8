//! Edge timing: from raw capture timestamps to framed, checked teeth and speed samples.
//!
//! [`SpeedTracker`] takes each capture timestamp as a raw counter value (ticks; the counter
//! wraps modulo 2^bits). Intervals are wrapping integer differences masked to the counter
//! width, and every per-edge decision is integer arithmetic against bounds derived from the
//! previous interval. An edge is *accepted* as a tooth, or *rejected* as a glitch; the tooth of
//! every accepted edge is known once the revolution is framed ([`SyncState::Synced`]).
//!
//! # Judging an edge
//!
//! The per-pitch interval (interval over the nominal pitch it spans) changes from tooth to
//! tooth by the *swing*. An edge whose swing lies within the accept band
//! ([`crate::encoder::Tolerances::accept`]) and which is not a special tooth (the frame, a gap,
//! an extra tooth) is taken at once: this is the path nearly every edge takes. Any other edge
//! is judged with the two edges that follow it, by how smoothly each explanation continues the
//! per-pitch intervals (the sum of squared log swings): the expected tooth; a glitch (the edge
//! is dropped and the next one is the tooth); one or two missing teeth; and, on a pattern
//! wheel, a count one ahead or behind (an earlier extra or missing edge). A fault must explain
//! the intervals better than the plain tooth by [`crate::encoder::Tolerances::fault_margin`]
//! (at a wheel's gap, where every fault leaves less evidence, by a margin scaled to it).
//! A real compression swing is therefore taken as a tooth, a noise pulse between two teeth is
//! rejected as a glitch and the real edge behind it kept, and a tooth lost mid-revolution moves
//! the count on by one instead of re-framing the revolution there (no cascade). An edge that
//! no fault explains better, but that costs the plain tooth more than that margin (two faults
//! within the lookahead, most likely), is taken as the tooth and reported as
//! [`Fault::Unexplained`]: no window spans it.
//!
//! # Framing
//!
//! - Index pulse ([`crate::encoder::Wheel::Indexed`]): the first edge after an index
//!   timestamp is tooth 0. The first index is a candidate; the revolution is framed once the
//!   next index comes exactly one revolution of edges later. In sync an index that does not
//!   fall where the count says is a fault (extra or missing edge) and the count is realigned
//!   to it; a revolution without its index is a [`Fault::MissingFrame`] and the count goes on.
//! - Pattern ([`crate::encoder::Wheel::Pattern`]): each interval is compared with both of its
//!   neighbours; an interval clearly longer than both is a long pitch (a gap), one clearly
//!   shorter a short pitch (an extra tooth), and each such observation rules out the
//!   alignments of the pattern it contradicts (a bit mask of the teeth the last edge could
//!   be). On a wheel of 6 to 16 teeth with gaps, the last revolution of intervals is also
//!   weighed as a whole against each alignment, a smooth speed profile taken out (see
//!   [`SpeedTracker::fit_alignment`]): a deep cranking ripple can make a small wheel's gap no
//!   longer than its neighbours. Once one alignment is left and the pattern's special teeth
//!   have been seen where due for a full revolution (or the revolution has decided the same
//!   alignment again), the revolution is framed; on such a small wheel only once its last
//!   revolution showed no fault and swings the judgement in sync can follow.
//! - None ([`crate::encoder::Wheel::Unframed`]): revolutions are counted in edges.
//!
//! # Shaft state
//!
//! [`ShaftState`] is explicit. An edge after standstill (or the first one) is only a time
//! reference: the shaft is running once an interval within the timeout is seen, so a shaft
//! creeping below the minimum speed stays at standstill instead of flipping state on every edge.
//! Timeouts and reversals are counted on leaving [`ShaftState::Running`] only.

// The per-edge path runs through this module: no integer operation here may overflow or
// divide by zero, and no index may fail, in a debug build either (`panic-free.sh dev` in
// examples/qemu checks the image).
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::indexing_slicing)
)]

use crate::encoder::{Encoder, Framing, MAX_PATTERN_TEETH, MAX_SPAN, PITCH_UNITS};
use crate::pitch::PitchTable;
use core::num::NonZeroU32;

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
    /// Edges stopped (none within the timeout), or too slow to be running.
    Standstill,
    /// Edges arriving in the forward direction within the timeout.
    Running,
    /// Edges arriving with the reverse direction flag (until two forward edges within the
    /// timeout).
    Reversed,
}

/// How far the revolution is framed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum SyncState {
    /// Looking for the frame (index pulse or pattern).
    Searching,
    /// A frame candidate is being confirmed over one revolution.
    Confirming,
    /// Teeth are identified.
    Synced,
}

/// Why an edge or a window could not be trusted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Fault {
    /// A spurious edge (a noise pulse between teeth), rejected.
    Glitch,
    /// A tooth edge was lost.
    MissingEdge,
    /// More edges than teeth were counted (an unidentified spurious edge).
    ExtraEdge,
    /// The frame marker (index pulse or pattern) was not seen where it was due, or was not
    /// found at all.
    MissingFrame,
    /// The direction input reported reverse rotation.
    Reversal,
    /// No edge within the timeout: the shaft stopped (or the signal was lost).
    Timeout,
    /// An edge that neither the expected tooth nor any single fault explains: two faults
    /// closer together than the judgement's lookahead, most likely (a noise pulse where a
    /// tooth was lost, two noise pulses in a row). Taken as the tooth; no window spans it.
    Unexplained,
}

impl Fault {
    /// A short name for logs and reports.
    pub fn name(self) -> &'static str {
        match self {
            Fault::Glitch => "glitch",
            Fault::MissingEdge => "missing-edge",
            Fault::ExtraEdge => "extra-edge",
            Fault::MissingFrame => "missing-frame",
            Fault::Reversal => "reversal",
            Fault::Timeout => "timeout",
            Fault::Unexplained => "unexplained",
        }
    }
}

/// A speed sample: `span` angle units travelled in `ticks` timer ticks.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Sample {
    /// Angle, units (see [`crate::encoder`]).
    pub span: u32,
    /// Interval, timer ticks (exact).
    pub ticks: u32,
}

/// An accepted edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tooth {
    /// Number of this accepted edge (the running count of accepted edges, wrapping).
    pub index: u32,
    /// Capture time (masked to the counter).
    pub time: u32,
    /// Ticks since the previous accepted edge (0 after a restart).
    pub dt: u32,
    /// Tooth number within the revolution (meaningful when `synced`).
    pub tooth: u16,
    /// Teeth are identified.
    pub synced: bool,
    /// This edge is tooth 0 of a revolution counted in sync.
    pub frame: bool,
    /// The speed sample ending at this edge, once `K` edges are known.
    pub sample: Option<Sample>,
}

/// Receives what the tracker finds, in order.
pub trait EdgeSink {
    /// Whether the sink looks at ordinary teeth at all. A sink that does not (the `()` sink)
    /// lets a batch of captures run through the tracker's bulk path, which reports no teeth.
    const WATCHES_TEETH: bool = true;
    /// An edge accepted as a tooth.
    fn tooth(&mut self, tooth: &Tooth);
    /// A fault found at `time` (a rejected glitch, a missing edge, a timeout...).
    fn fault(&mut self, fault: Fault, time: u32);
}

/// Counters of everything the tracker accepted or rejected.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EdgeCounters {
    /// Edges accepted as teeth.
    pub accepted: u32,
    /// Edges rejected as glitches.
    pub glitches: u32,
    /// Tooth edges lost.
    pub missing: u32,
    /// Extra edges counted in a revolution.
    pub extra: u32,
    /// Frame markers missed (and every three revolutions' worth of edges searched without a
    /// confirmed frame).
    pub missing_frames: u32,
    /// Changes to reverse rotation.
    pub reversals: u32,
    /// Timeouts (standstill or lost signal).
    pub timeouts: u32,
    /// Revolutions counted in sync.
    pub revolutions: u32,
    /// Times the frame was found and confirmed.
    pub syncs: u32,
    /// Times sync was lost (a timeout, a reversal, or faults the count could not absorb).
    pub sync_losses: u32,
    /// Edges taken as teeth that no judgement explained ([`Fault::Unexplained`]).
    pub unexplained: u32,
}

impl EdgeCounters {
    /// Nothing counted yet (the `Default`, as a `const`).
    pub const ZERO: EdgeCounters = EdgeCounters {
        accepted: 0,
        glitches: 0,
        missing: 0,
        extra: 0,
        missing_frames: 0,
        reversals: 0,
        timeouts: 0,
        revolutions: 0,
        syncs: 0,
        sync_losses: 0,
        unexplained: 0,
    };

    /// Back to [`EdgeCounters::ZERO`] in place, one store a counter. The zero is opaque to
    /// the optimizer: ten stores of a constant zero would become a call of `memset` (a run of
    /// more than 32 zero bytes is one on a Cortex-M), which configuration would then link.
    /// `z` is that opaque zero (one for all the monitor's state: each `black_box` is a store
    /// and a load of its own).
    pub(crate) fn clear(&mut self, z: u32) {
        *self = EdgeCounters {
            accepted: z,
            glitches: z,
            missing: z,
            extra: z,
            missing_frames: z,
            reversals: z,
            timeouts: z,
            revolutions: z,
            syncs: z,
            sync_losses: z,
            unexplained: z,
        };
    }
}

/// Pending raw edges awaiting judgement: the edge itself and two for lookahead.
const PENDING: usize = 3;
/// Index timestamps that may wait for their edge.
const INDEXES: usize = 4;
const _: () = assert!(INDEXES <= 8, "index places are bits of a byte");
/// The band is refreshed after every tooth whose number is a multiple of this (a power of
/// two), and whenever the fast path opens.
pub(crate) const BAND_REFRESH: u16 = 64;
/// Faults within one revolution after which the count is no longer trusted.
const FAULTS_TO_RESYNC: u8 = 3;
/// Teeth of the largest wheel whose frame is also sought over a whole revolution of intervals
/// ([`SpeedTracker::fit_alignment`]).
const FIT_TEETH: usize = 16;
/// The [`Revolution`]s a tracker keeps: one with pattern wheels, none without (no memory, no
/// code).
const FIT_KEPT: usize = if cfg!(feature = "pattern-wheels") {
    1
} else {
    0
};
/// The fewest teeth for that: fewer leave too few intervals to tell a ripple from a gap.
const FIT_MIN_TEETH: u16 = 6;
/// An interval's ratio to the same tooth's a revolution earlier follows on from the tooth
/// before's within this (log: 1.25×).
#[cfg(feature = "pattern-wheels")]
const FIT_PERIODIC: f32 = 0.223;
/// A revolution decides an alignment whose residual is at most `FIT_FITS` ln²R while every
/// other alignment's is at least `FIT_MISFITS` ln²R (`R` the smallest long pitch over the
/// base), both raised by what the edge jitter learnt leaves of a revolution (see
/// [`SpeedTracker::fit_alignment`]): a gap put one tooth off costs about 2 ln²R before the
/// ripple's share is taken out.
#[cfg(feature = "pattern-wheels")]
const FIT_FITS: f32 = 0.03;
#[cfg(feature = "pattern-wheels")]
const FIT_MISFITS: f32 = 0.12;
/// A pattern wheel's frame edge is unexplained where its squared log swing against the tooth
/// before exceeds this many times the mean of recent frames' (see
/// [`SpeedTracker::frame_as_usual`]) and a quarter of the margin shrunk at the gap: one
/// squared Gaussian exceeds 20 times its mean about once in 100 000.
const FRAME_NOISE: f32 = 20.0;
/// Frames the mean is learnt over (a running mean, then an exponential one).
const FRAME_MEMORY: u16 = 16;
/// Frames learnt before that rule applies: with none learnt, a quarter of the margin alone
/// decided, and edge jitter of 3 % of a pitch (σ) made the first frame after a recorded
/// revolution unexplained (more than half of that rule's false faults in `jitter_census`,
/// measured once with the rule's faults printed apart).
const FRAME_LEARNT: u16 = 2;
/// At a pattern wheel's gap the tooth is unexplained by its own cost (no single fault winning)
/// only above this many times the mean cost of the recent gaps' teeth, once `GAP_LEARNT` of
/// them are learnt (see [`SpeedTracker::gap_noise`]): under jitter alone, 1 in 500 of those
/// teeth cost more than 8 times the mean learnt before them (heavier-tailed than a sum of
/// three squared Gaussians: the swings recorded a revolution earlier jitter too; measured once
/// over `jitter_census`'s runs, with the costs printed).
const GAP_NOISE: f32 = 8.0;
const GAP_LEARNT: u16 = 4;
/// A frame is confirmed on such a wheel only where the alignment the revolution fits best
/// leaves a residual of at most this (ln²R): with more strokes than the profile resolves, the
/// speed swings between teeth can make another tooth's interval look like the gap every
/// revolution (a 12-1 wheel at ±40 % with five strokes was framed at a wrong tooth at 2 of
/// 12 phases, every window valid, its best residual 0.72 to 0.81). Over 3 to 6 strokes on
/// 8-1 to 16-2 wheels this bound costs syncs only from ±30 %.
#[cfg(feature = "pattern-wheels")]
const FIT_EXPLAINS: f32 = 0.5;
/// ... and whose profile's largest harmonic is at most this (log speed: a ripple of ±42 %).
#[cfg(feature = "pattern-wheels")]
const FIT_RIPPLE: f32 = 0.45;
/// A frame is confirmed only where every swing between neighbouring teeth stays this much
/// inside what the judgement weighs (see [`SpeedTracker::trackable`]): a swing scatters by
/// about that from revolution to revolution under edge jitter of 1 % of a pitch.
#[cfg(feature = "pattern-wheels")]
const TRACK_MARGIN: f32 = 1.02;

/// What a pattern wheel's tracker keeps beyond the per-tooth history: a small wheel's last
/// revolution of intervals, for its acquisition and the check of its count in sync (see
/// [`SpeedTracker::fit_push`]), and any pattern wheel's recent frame swings (see
/// [`SpeedTracker::frame_as_usual`]).
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(feature = "pattern-wheels"), allow(dead_code))]
struct Revolution {
    /// The log of the last unsynced intervals, the n-th since the search began in slot
    /// `n mod edges`.
    ln: [f32; FIT_TEETH],
    /// The next slot; how many slots hold an interval (one more once a ratio to a revolution
    /// before is known); how many intervals in a row followed on.
    pos: u16,
    len: u16,
    run: u16,
    /// The last interval's log ratio to its slot's, and the mean of those ratios over `run`
    /// (the speed trend of a revolution, in log).
    d: f32,
    trend: f32,
    /// The squared log swing of the frame edge against the tooth before (as recorded), learnt
    /// over the recent frames.
    frames: Learnt,
    /// The cost of the teeth after a gap (their chain of intervals against the recorded
    /// revolution, each at most the margin), learnt over the recent gaps.
    gaps: Learnt,
    /// The square of each step of `d` that followed on (the ratio to the revolution before,
    /// from tooth to tooth), learnt over the recent intervals: the edge jitter, as the fit sees
    /// it.
    scatter: Learnt,
    /// The last glitch and the last missing edge found in sync: the revolution and the tooth
    /// counted before each (see [`SpeedTracker::fault_repeats`]).
    last_faults: [Option<(u32, u16)>; 2],
    /// Which of them (bit 0 the glitch, bit 1 the missing edge) came at the same tooth as a
    /// revolution before.
    repeated: u8,
}

/// The two faults whose repetition at one tooth [`SpeedTracker::fault_repeats`] watches: their
/// slots in `last_faults` and their bits in `repeated`.
#[cfg(feature = "pattern-wheels")]
#[derive(Clone, Copy)]
enum Repeat {
    Glitch = 0,
    Missing = 1,
}

/// A mean learnt from the values met: a running mean over the first `FRAME_MEMORY`, then an
/// exponential one with that memory.
#[derive(Debug, Clone, Copy)]
#[cfg_attr(not(feature = "pattern-wheels"), allow(dead_code))]
struct Learnt {
    mean: f32,
    count: u16,
}

#[cfg_attr(not(feature = "pattern-wheels"), allow(dead_code))]
impl Learnt {
    const NEW: Learnt = Learnt {
        mean: 0.0,
        count: 0,
    };

    fn learn(&mut self, x: f32) {
        self.count = self.count.saturating_add(1);
        self.mean += (x - self.mean) / f32::from(self.count.min(FRAME_MEMORY));
    }

    /// The mean, once at least `n` values are learnt.
    fn after(&self, n: u16) -> Option<f32> {
        (self.count >= n).then_some(self.mean)
    }
}

impl Revolution {
    const NEW: Revolution = Revolution {
        ln: [0.0; FIT_TEETH],
        pos: 0,
        len: 0,
        run: 0,
        d: 0.0,
        trend: 0.0,
        frames: Learnt::NEW,
        gaps: Learnt::NEW,
        scatter: Learnt::NEW,
        last_faults: [None; 2],
        repeated: 0,
    };
}

/// Per-edge state of the timing front end. Total: every input sequence is handled without
/// panicking, and every path is O(1). Memory: about 580 bytes (the 32-slot interval ring and
/// the 64-tooth history of small wheels); 660 with pattern wheels (a small wheel's last
/// revolution of intervals, for its acquisition).
#[derive(Debug, Clone)]
pub struct SpeedTracker {
    state: ShaftState,
    sync: SyncState,
    /// `last` is a time reference (an accepted or starting edge): its capture time, counted on
    /// past a counter narrower than 32 bits from the last new reference (its low bits are the
    /// capture's, so intervals masked to the counter are the same).
    has_ref: bool,
    last: u32,
    /// Latest raw edge time while edges are pending (`last` otherwise).
    latest: u32,
    /// The previous accepted interval scaled to one base pitch (0: none), as of the last
    /// careful acceptance (the fast path's intervals are the ring's newest).
    prev: u32,
    /// Edges accepted by the careful path, and the tooth it last accepted: the fast path
    /// moves the tooth on without counting, so `accepted + (tooth − anchor)` is the count.
    accepted: u32,
    anchor: u16,
    /// Tooth of the last accepted edge.
    tooth: u16,
    /// The accept band of an ordinary interval, ticks: `[lo, lo + width]` (modular), around the
    /// mean of the last `K` intervals as of the last refresh. It is refreshed when the fast path
    /// opens and after every tooth whose number is a multiple of [`BAND_REFRESH`] (a rule of
    /// the tooth numbers alone, so a batch of captures reproduces it exactly).
    lo: u32,
    width: u32,
    /// The fast path stops after this tooth: the next one is special, or (`stop == tooth`)
    /// something needs the careful path first (not running or synced, edges pending, an index
    /// waiting, the ring not full).
    stop: u16,
    /// Faults since the last frame.
    faults: u8,
    /// The last accepted edges, newest at `pos − 1`, then `pos − 2`, … (`pos` runs on and the
    /// index is masked; a batch lays them out from the start again): their capture times,
    /// counted on past a counter narrower than 32 bits (see `last`), so that a `K`-edge sample
    /// is one difference, exact since `K` intervals within the timeout fit in 32 bits (and may
    /// last longer than the counter's period). `fill` of them (at most `K`) belong to the
    /// current run. (One kind of ring for every counter: a ring of intervals for a narrower
    /// one was a second copy of the fast path in every entry point, 100 bytes in firmware fed
    /// edge by edge.)
    ring: [u32; MAX_SPAN],
    pos: u32,
    fill: u8,
    /// Their sum (exact: `K` intervals within the timeout fit in 32 bits) and the angle they
    /// span in units (kept only when pitches differ): the latest speed sample.
    sum: u32,
    span: u32,
    /// Per-base interval of every tooth in the last revolution (wheels of up to
    /// [`MAX_PATTERN_TEETH`] teeth): cranking ripple repeats every turn, so each tooth's swing
    /// is judged against the same tooth's swing one revolution earlier. `history` once a
    /// whole revolution is recorded.
    hist: [u32; MAX_PATTERN_TEETH],
    hist_teeth: u16,
    history: bool,
    /// The last tooth's interval, written to `hist` only when the next tooth has been judged
    /// against the previous revolution (tooth, per-base interval).
    held: Option<(u16, u32)>,
    pending: [u32; PENDING],
    /// Arrival number of each pending edge (see `arrivals`).
    pending_seq: [u32; PENDING],
    npend: u8,
    /// `pending[0]` came with the fast path open and fell outside its band.
    out_of_band: bool,
    /// Accepted intervals from here on that form no sample: an edge was rejected as a glitch
    /// since the last accepted one, and the next accepted edge's interval spans it (1); where
    /// the judgement merged the glitch with the edge after it, that edge's time is the pair's
    /// either, and the interval after it forms none either (2).
    across: u8,
    /// The last accepted edge is the frame by the count (synced on an index disc), and its
    /// index had not been reported when it was accepted: reported after it at its own tick
    /// (a Z gated with A, captured on the same edge), it is that frame's, and the next edge
    /// settles it; else that revolution's frame is missing.
    owed: bool,
    /// The last frame of an index disc was realigned by its index (the count was a tooth
    /// off): a second in a row says the disc has another number of lines than configured.
    realigned: bool,
    /// The last index that framed an interval lay in its later half: by the frame edge, not
    /// by the tooth before it (which side of an edge the count decides on, see
    /// [`SpeedTracker::index_places`]).
    index_late: bool,
    /// Waiting index timestamps, each with the number of edges that had arrived when it was
    /// reported: an index belongs to an edge that arrived after it. (Modulo the counter a
    /// timestamp alone cannot say which edge it falls before once intervals approach the
    /// counter's period.)
    index: [(u32, u32); INDEXES],
    /// Edges that have reached the careful path (a running number; pending edges and index
    /// pulses are ordered by it).
    arrivals: u32,
    nidx: u8,
    /// Pattern acquisition: alignments still possible for the last accepted edge (bit k:
    /// it is tooth k), the three previous unsynced intervals, and the confirmation countdown.
    viable: u64,
    acq: [u32; 3],
    confirm: u16,
    seen_special: bool,
    /// A small pattern wheel's last intervals and a pattern wheel's frame swings.
    fit: [Revolution; FIT_KEPT],
    /// Edges accepted since the search for a frame began, while searching or confirming (a
    /// missing frame is counted every three revolutions' worth).
    searched: u16,
    counters: EdgeCounters,
}

#[cfg(test)]
impl SpeedTracker {
    /// Its state but for the slots [`SpeedTracker::reset`] leaves (the ring, the per-tooth
    /// history, the pending edges, the waiting index pulses), which read as `new()`'s.
    pub(crate) fn without_slots(&self) -> String {
        let new = SpeedTracker::new();
        let t = SpeedTracker {
            ring: new.ring,
            hist: new.hist,
            pending: new.pending,
            pending_seq: new.pending_seq,
            index: new.index,
            ..self.clone()
        };
        let mut t = t;
        for f in &mut t.fit {
            (f.ln, f.d, f.trend) = (Revolution::NEW.ln, 0.0, 0.0);
        }
        format!("{t:?}")
    }
}

impl Default for SpeedTracker {
    fn default() -> Self {
        Self::new()
    }
}

/// Squared natural log of `a/b` for tick counts known to ±1 tick: the ratio is taken at the
/// end of its quantization range nearest 1, so rounding alone never looks like a swing.
/// Careful path only (f32); out of line, one copy for every term of every hypothesis.
#[inline(never)]
fn log_sq(a: f32, b: f32) -> f32 {
    // Compared, not `f32::max`/`min` (which call `fmaxf`/`fminf` on this FPU): the same for
    // tick counts, which are never NaN.
    let (a, b) = if a >= b {
        let (x, y) = (a - 1.0, b + 1.0);
        (if x >= y { x } else { y }, y)
    } else {
        let (x, y) = (a + 1.0, b - 1.0);
        (if x <= y { x } else { y }, y)
    };
    if a <= 0.0 || b <= 0.0 {
        return 0.0;
    }
    let l = ln(a / b);
    l * l
}

/// The grid pitch of `tooth` (one of the wheel's) in base pitches: 1 but on a pattern wheel
/// (exactly what the quotient gives, so that without pattern wheels the compiler folds every
/// product and quotient with it away).
fn pitch_ratio(enc: &Encoder, tooth: u16) -> f32 {
    if enc.framing() != Framing::Pattern {
        return 1.0;
    }
    enc.grid_pitch(tooth) as f32 / enc.base_pitch() as f32
}

/// Natural log, accurate to about 1e-4 (ample for judging swings): exponent from the bits, a
/// short series on the mantissa. No `libm` call, so the careful path stays cheap.
fn ln(x: f32) -> f32 {
    // Not above 0 (or NaN): 0. (+∞ reads as 2^128: finite, and never met for a ratio of
    // tick counts.)
    if x.is_nan() || x <= 0.0 {
        return 0.0;
    }
    let bits = x.to_bits();
    let exp = (((bits >> 23) & 0xff) as i32).wrapping_sub(127); // in [−127, 128]
    let m = f32::from_bits((bits & 0x007f_ffff) | 0x3f80_0000); // in [1, 2)
                                                                // ln(m) = 2·atanh((m−1)/(m+1)), |s| ≤ 1/3: four terms give 1e-5.
    let s = (m - 1.0) / (m + 1.0);
    let s2 = s * s;
    let atanh = s * (1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0))));
    exp as f32 * core::f32::consts::LN_2 + 2.0 * atanh
}

/// Where a waiting index timestamp falls against the edge judged: it frames the interval
/// ending at that edge, is a later edge's, lost its edge, or is the owed frame's.
const PLACE_FRAMES: u8 = 0;
const PLACE_LATER: u8 = 1;
const PLACE_LOST: u8 = 2;
const PLACE_OWED: u8 = 3;
/// What [`SpeedTracker::index_place`] needs of the edge judged.
type PlaceAt = (u32, u32, u32, (u32, u32), (bool, bool));

/// What the judged edge is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Verdict {
    /// The expected tooth.
    Tooth,
    /// A glitch: drop it.
    Glitch,
    /// `n` teeth were lost before it.
    Missing(u16),
    /// The count was one ahead: it is the tooth before the expected one.
    Behind,
    /// The count was one behind: it is the tooth after the expected one.
    Ahead,
    /// Taken as the expected tooth, though that explains the edges worse than a fault would
    /// be called on ([`Fault::Unexplained`]).
    Unexplained,
    /// Not enough edges yet to judge.
    Wait,
    /// An interval longer than any two lost teeth explain (a run of captures lost, e.g. a DMA
    /// ring overrun), `n` teeth lost: a new time reference, the count given up. `n` = 0: the
    /// edge before was an extra one (the interval judged against was the only one since a
    /// new time reference or a fault).
    Dropout(u16),
}

impl SpeedTracker {
    /// A tracker that has seen nothing yet.
    pub const fn new() -> Self {
        SpeedTracker {
            state: ShaftState::NoSignal,
            sync: SyncState::Searching,
            has_ref: false,
            last: 0,
            latest: 0,
            prev: 0,
            accepted: 0,
            anchor: 0,
            lo: 0,
            width: 0,
            tooth: 0,
            stop: 0,
            faults: 0,
            ring: [0; MAX_SPAN],
            pos: 0,
            fill: 0,
            sum: 0,
            span: 0,
            hist: [0; MAX_PATTERN_TEETH],
            hist_teeth: 0,
            history: false,
            held: None,
            pending: [0; PENDING],
            pending_seq: [0; PENDING],
            npend: 0,
            out_of_band: false,
            across: 0,
            owed: false,
            realigned: false,
            index_late: false,
            index: [(0, 0); INDEXES],
            arrivals: 0,
            nidx: 0,
            viable: 0,
            acq: [0; 3],
            confirm: 0,
            seen_special: false,
            fit: [Revolution::NEW; FIT_KEPT],
            searched: 0,
            counters: EdgeCounters::ZERO,
        }
    }

    /// Back to [`SpeedTracker::new`] in place. The contents of the ring, the per-tooth
    /// history, the pending edges and the waiting index pulses are left: nothing reads a slot
    /// before writing it (`fill`, `pos`, `hist_teeth`, `history`, `npend` and `nidx` start at
    /// zero). Assigning `new()` would zero some 550 bytes with a call of `memset`, which
    /// configuration would then link; the numbers take an opaque zero for the same reason
    /// (see [`EdgeCounters::clear`]). The list names every field, so a new one is not missed.
    /// `z` is an opaque zero (see [`EdgeCounters::clear`]).
    pub(crate) fn reset(&mut self, z: u32) {
        // Most of it as a new time reference and a lost sync leave it: their out-of-line
        // stores, not a copy of them here (code size); the counters are cleared after.
        self.restart_at(z);
        self.lose_sync(false);
        let SpeedTracker {
            state,
            // (`restart_at`.)
            has_ref,
            last: _,
            latest: _,
            prev: _,
            npend: _,
            out_of_band: _,
            across: _,
            acq: _,
            // (`lose_sync`.)
            sync: _,
            owed: _,
            realigned: _,
            viable: _,
            confirm: _,
            seen_special: _,
            faults: _,
            searched: _,
            // (Both: `reset_ring`, `forget_history`.)
            pos: _,
            fill: _,
            sum: _,
            span: _,
            hist_teeth: _,
            history: _,
            held: _,
            accepted,
            anchor,
            lo,
            width,
            tooth,
            stop,
            ring: _,
            hist: _,
            pending: _,
            pending_seq: _,
            index_late,
            index: _,
            arrivals,
            nidx,
            fit,
            counters,
        } = self;
        (*state, *has_ref, *index_late) = (ShaftState::NoSignal, false, false);
        (*accepted, *lo, *width, *arrivals) = (z, z, z, z);
        (*anchor, *tooth, *stop, *nidx) = (0, 0, 0, 0);
        for f in fit {
            (f.frames, f.gaps, f.scatter) = (Learnt::NEW, Learnt::NEW, Learnt::NEW);
            (f.last_faults, f.repeated) = ([None; 2], 0);
        }
        counters.clear(z);
    }

    /// The shaft state.
    pub fn state(&self) -> ShaftState {
        self.state
    }

    /// How far the revolution is framed.
    pub fn sync_state(&self) -> SyncState {
        self.sync
    }

    /// Whether teeth are identified.
    pub fn synced(&self) -> bool {
        self.sync == SyncState::Synced
    }

    /// The tooth of the last accepted edge, when teeth are identified.
    pub fn tooth(&self) -> Option<u16> {
        self.synced().then_some(self.tooth)
    }

    /// The counters.
    pub fn counters(&self) -> EdgeCounters {
        EdgeCounters {
            accepted: self.accepted_now(),
            ..self.counters
        }
    }

    /// Edges accepted so far: the careful path's count plus the fast path's teeth since.
    #[inline(always)]
    fn accepted_now(&self) -> u32 {
        self.accepted
            .wrapping_add(u32::from(self.tooth.wrapping_sub(self.anchor)))
    }

    /// Brings the careful path's bookkeeping up to date with what the fast path did: the
    /// accepted count, and the previous interval (the ring's newest: fast teeth are ordinary
    /// teeth, so their interval is per base pitch already).
    fn settle(&mut self) {
        if self.tooth != self.anchor {
            self.accepted = self.accepted_now();
            self.anchor = self.tooth;
            self.prev = self.newest();
        }
    }

    /// The newest interval in the ring (the fast path's last interval).
    #[inline(never)] // careful path: one copy for its callers (code size)
    fn newest(&self) -> u32 {
        let at = |back: u32| {
            self.ring
                .get(self.pos.wrapping_sub(back) as usize & (MAX_SPAN - 1))
                .copied()
                .unwrap_or(0)
        };
        at(1).wrapping_sub(at(2))
    }

    /// The latest speed sample (the last `K` accepted intervals) while running; `None` before
    /// `K` intervals are known (and, on a pattern wheel, before the teeth are identified).
    pub fn recent_sample(&self, enc: &Encoder) -> Option<Sample> {
        if self.state != ShaftState::Running || u16::from(self.fill) < enc.samples_span() {
            return None;
        }
        if enc.framing() == Framing::Pattern && self.sync != SyncState::Synced {
            return None;
        }
        self.sample(if self.span == 0 {
            enc.uniform_span()
        } else {
            self.span
        })
    }

    /// The sample of the ring's sum over `span` units (none for an empty sum).
    #[inline(always)]
    fn sample(&self, span: u32) -> Option<Sample> {
        (self.sum > 0).then_some(Sample {
            span,
            ticks: self.sum,
        })
    }

    /// Whether the teeth are numbered: synced, or confirming a frame candidate. Out of line,
    /// one copy: inlined, the acceptance's paths were copied for each answer (116 bytes).
    #[inline(never)]
    fn teeth_known(&self, enc: &Encoder) -> bool {
        self.sync == SyncState::Synced
            || (self.sync == SyncState::Confirming && enc.framing() != Framing::None)
    }

    /// Pitch of `tooth` in units (nominal plus correction; a base pitch while the teeth are
    /// not numbered).
    #[inline(always)]
    fn pitch<P: PitchTable>(&self, enc: &Encoder, table: &P, tooth: u16) -> u32 {
        if !self.teeth_known(enc) {
            // A base pitch is under 256 grid positions: the product fits.
            return enc.base_pitch().wrapping_mul(PITCH_UNITS);
        }
        let nominal = enc.nominal_pitch(tooth);
        if P::NOMINAL {
            nominal
        } else {
            nominal.wrapping_add_signed(table.deviation(tooth))
        }
    }

    /// An index pulse captured at `ticks` (raw counter value). Report it before the captures
    /// that follow it; up to four may wait for their edge.
    pub fn on_index(&mut self, enc: &Encoder, ticks: u32) {
        // While the shaft runs backwards an index pulse marks no forward frame (no forward
        // edge will take it): it is not queued, so a reverse run is no string of missing
        // frames. The frame is found again from the first index once the shaft runs forward.
        if enc.framing() != Framing::Index || self.state == ShaftState::Reversed {
            return;
        }
        let t = ticks & enc.mask();
        if usize::from(self.nidx) >= INDEXES {
            // The oldest waiting index lost its edge: drop it (the others kept by the
            // acceptance's routine: moved here element by element, 22 bytes more code).
            self.keep_indexes(!1);
            self.counters.missing_frames = self.counters.missing_frames.wrapping_add(1);
        }
        if let Some(slot) = self.index.get_mut(usize::from(self.nidx)) {
            *slot = (t, self.arrivals);
            self.nidx = self.nidx.wrapping_add(1);
        }
        self.block_fast();
    }

    /// Checks for a timeout at time `now` (ticks). Call it at least once every
    /// [`Encoder::poll_interval_ticks`]: elapsed time is measured modulo the counter. Reports
    /// [`Fault::Timeout`] when a running shaft stops (once per stop). A `now` read before the
    /// last edge fed (a capture interrupt between reading the timer and this call) is no stop.
    pub fn poll<P: PitchTable, S: EdgeSink>(
        &mut self,
        enc: &Encoder,
        table: &P,
        now: u32,
        sink: &mut S,
    ) {
        if self.state == ShaftState::NoSignal || enc.edges() == 0 {
            return;
        }
        let latest = if self.npend > 0 {
            self.latest
        } else {
            self.last
        };
        let elapsed = (now & enc.mask()).wrapping_sub(latest) & enc.mask();
        // A stop is seen within the poll interval after the timeout. Beyond it the elapsed
        // time is that of a `now` read before the last edge (it wraps to just under the
        // counter's period: read as a stop, a poll racing a capture interrupt cut the window
        // and lost the sync, and a drive over its δ limit never raised the alarm).
        if elapsed.wrapping_sub(enc.timeout_ticks()).wrapping_sub(1) < enc.poll_interval_ticks() {
            self.settle();
            self.flush(enc, table, sink);
            self.stop_running(now & enc.mask(), sink);
            self.has_ref = false;
            self.update_fast(enc);
        }
    }

    /// Processes one captured edge at `ticks` (raw counter value).
    #[inline(always)]
    pub fn on_edge<P: PitchTable, S: EdgeSink>(
        &mut self,
        enc: &Encoder,
        table: &P,
        ticks: u32,
        direction: Option<Direction>,
        sink: &mut S,
    ) {
        if direction != Some(Direction::Reverse) {
            let uniform = enc.is_uniform() && P::NOMINAL;
            if let Some(tooth) = self.try_fast(enc, table, ticks, uniform) {
                sink.tooth(&tooth);
                return;
            }
        }
        self.careful(enc, table, ticks, direction, sink);
    }

    /// The path nearly every edge takes: running and synced with nothing pending, the next
    /// tooth an ordinary one, the interval within the accept band of the mean of the last `K`.
    /// Accepts the edge and returns it (never a frame, always with a sample); `None`, with
    /// nothing changed, when the edge needs the careful judgement. Integer arithmetic only, no
    /// branch that can panic. `uniform`: every sample spans the same angle.
    #[inline(always)]
    pub(crate) fn try_fast<P: PitchTable>(
        &mut self,
        enc: &Encoder,
        table: &P,
        ticks: u32,
        uniform: bool,
    ) -> Option<Tooth> {
        let mask = enc.mask();
        let t = ticks & mask;
        let dt = t.wrapping_sub(self.last) & mask;
        if self.tooth == self.stop || dt.wrapping_sub(self.lo) > self.width {
            return None;
        }
        // `stop` is at most the tooth before the frame (tooth 0 is always special), so the
        // next tooth does not wrap.
        let tooth = self.tooth.wrapping_add(1);
        self.tooth = tooth;
        // Counted on past the counter's wraps (see `last`): with a 32-bit counter, `t`.
        let time = self.last.wrapping_add(dt);
        self.last = time;
        // The ring is full on the fast path: the sample starts K edges back.
        let k = enc.samples_span();
        let pos = self.pos;
        let oldest = self
            .ring
            .get(pos.wrapping_sub(u32::from(k)) as usize & (MAX_SPAN - 1))
            .copied()
            .unwrap_or(0);
        if let Some(slot) = self.ring.get_mut(pos as usize & (MAX_SPAN - 1)) {
            *slot = time;
        }
        self.pos = pos.wrapping_add(1);
        let ticks = time.wrapping_sub(oldest);
        self.sum = ticks;
        if tooth & (BAND_REFRESH - 1) == 0 {
            self.refresh_band(enc);
        }
        let span = if uniform {
            enc.uniform_span()
        } else {
            let out = tooth_back(tooth, k, enc.edges());
            self.span = self
                .span
                .wrapping_add(self.pitch(enc, table, tooth))
                .wrapping_sub(self.pitch(enc, table, out));
            self.span
        };
        Some(Tooth {
            index: self.accepted_now(),
            time: t,
            dt,
            tooth,
            synced: self.sync == SyncState::Synced,
            frame: false,
            sample: Some(Sample { span, ticks }),
        })
    }

    /// The swing tooth `to` had against tooth `from` one revolution earlier (1 without a
    /// recorded revolution). A recorded swing nearly as large as the wheel's own pitch ratio
    /// nearest 1, `R^0.9` or more (or its inverse), cannot be told from the pattern: a count
    /// one tooth off records its misplaced gap as such a swing, which would then explain the
    /// gap away revolution after revolution. It informs nothing: 1. (`R^0.75`, the
    /// acquisition's evidence of a long pitch, is too low here: on an 8-1 wheel cranking at
    /// ±40 %, two strokes a revolution, neighbouring teeth differ by up to 1/0.6 = 1.67,
    /// against 2^0.75 = 1.68, and ignoring those swings made clean cranking show faults;
    /// 2^0.9 = 1.87.)
    /// `unrecorded` where either tooth has no record in the recorded revolution (its interval
    /// spanned a fault, or was not seen).
    /// Careful path only; out of line, one copy for every hypothesis.
    #[inline(never)]
    fn recorded_swing(&self, enc: &Encoder, from: u16, to: u16, unrecorded: f32) -> f32 {
        if !self.history {
            return 1.0;
        }
        let a = self.hist.get(usize::from(from)).copied().unwrap_or(0);
        let b = self.hist.get(usize::from(to)).copied().unwrap_or(0);
        if a == 0 || b == 0 {
            return unrecorded;
        }
        let s = b as f32 / a as f32;
        let s2 = s * s;
        let s10 = (s2 * s2) * (s2 * s2) * s2;
        // (`s¹⁰ ≥ R⁹` and `s¹⁰·R⁹ ≤ 1` compared, no root taken; +∞ for a uniform disc: never.)
        // Without pattern wheels `R⁹` is +∞ and `s¹⁰·R⁹` +∞ or NaN, never at most 1: the
        // second test is left out (24 bytes).
        let limit = enc.pattern_swing();
        if s10 >= limit || (cfg!(feature = "pattern-wheels") && s10 * limit <= 1.0) {
            1.0
        } else {
            s
        }
    }

    /// The pitches of teeth `from` to `to` (in base pitches), each scaled by the interval it
    /// had a revolution earlier against the one of `to` (by 1 where not recorded): what an
    /// interval over those teeth is, in units of the interval of `to` alone. Without a
    /// recorded revolution, the sum of the pitches.
    #[inline(never)]
    fn recorded_spans(&self, enc: &Encoder, from: u16, to: u16) -> f32 {
        let edges = enc.edges();
        let (mut sum, mut k) = (0.0, from);
        for _ in 0..edges {
            sum += pitch_ratio(enc, k) * self.raw_swing(to, k);
            if k == to {
                break;
            }
            k = tooth_after(k, 1, edges);
        }
        sum
    }

    /// The interval of tooth `to` over that of `from` a revolution earlier, as recorded (1
    /// where either is not, or without a recorded revolution).
    fn raw_swing(&self, from: u16, to: u16) -> f32 {
        let a = self.hist.get(usize::from(from)).copied().unwrap_or(0);
        let b = self.hist.get(usize::from(to)).copied().unwrap_or(0);
        if !self.history || a == 0 || b == 0 {
            1.0
        } else {
            b as f32 / a as f32
        }
    }

    /// Records the per-base interval of `tooth` (teeth known, small wheels).
    fn record(&mut self, enc: &Encoder, tooth: u16, per_base: u32) {
        if usize::from(enc.edges()) > MAX_PATTERN_TEETH {
            return;
        }
        if let Some((k, v)) = self.held.replace((tooth, per_base)) {
            if let Some(h) = self.hist.get_mut(usize::from(k)) {
                *h = v;
                self.hist_teeth = self.hist_teeth.saturating_add(1);
                if self.hist_teeth >= enc.edges() {
                    self.history = true;
                }
            }
        }
    }

    /// Every edge that is not the fast path's: start, restart, reversal, the frame and special
    /// teeth, out-of-band intervals, unsynced edges, at `ticks` (raw counter value). Out of
    /// line: it runs rarely. The monitor calls it directly for an edge its own fast path has
    /// just declined ([`SpeedTracker::try_fast`] returned `None`, which changes nothing).
    #[cold]
    #[inline(never)]
    pub(crate) fn careful<P: PitchTable, S: EdgeSink>(
        &mut self,
        enc: &Encoder,
        table: &P,
        ticks: u32,
        direction: Option<Direction>,
        sink: &mut S,
    ) {
        let t = ticks & enc.mask();
        if enc.edges() == 0 {
            // An unconfigured monitor ignores everything.
            return;
        }
        self.settle();
        self.arrivals = self.arrivals.wrapping_add(1);
        // With the fast path open, an ordinary edge comes here only from outside its band.
        let open = self.stop != self.tooth;
        self.block_fast();
        self.judge_edge(enc, table, t, open, direction, sink);
        // Whatever happened, the fast path opens again only where it may.
        self.update_fast(enc);
    }

    fn judge_edge<P: PitchTable, S: EdgeSink>(
        &mut self,
        enc: &Encoder,
        table: &P,
        t: u32,
        open: bool,
        direction: Option<Direction>,
        sink: &mut S,
    ) {
        if direction == Some(Direction::Reverse) {
            self.flush(enc, table, sink);
            self.settle_owed(t, sink);
            if self.state == ShaftState::Running {
                self.counters.reversals = self.counters.reversals.wrapping_add(1);
                sink.fault(Fault::Reversal, t);
                self.lose_sync(false);
            }
            // Reverse edges are no forward time reference: running forward again needs two
            // forward edges within the timeout.
            self.state = ShaftState::Reversed;
            self.restart_at(t);
            self.has_ref = false;
            return;
        }
        if !self.has_ref {
            self.restart_at(t);
            if self.state == ShaftState::NoSignal {
                self.state = ShaftState::Standstill;
            }
            self.index_at_reference(enc, t);
            return;
        }
        let latest = if self.npend > 0 {
            self.latest
        } else {
            self.last
        };
        let since_latest = t.wrapping_sub(latest) & enc.mask();
        if since_latest > enc.timeout_ticks() {
            // Too long since the last edge: whatever was pending is judged as it stands, and
            // this edge is a new time reference.
            self.flush(enc, table, sink);
            self.stop_running(t, sink);
            self.restart_at(t);
            return;
        }
        if since_latest == 0 {
            // A second capture at the same tick cannot be a tooth.
            self.reject(t, sink);
            return;
        }
        if self.state != ShaftState::Running {
            // A forward interval within the timeout: the shaft runs. The edge before it was
            // only a reference.
            self.state = ShaftState::Running;
            self.accept_unjudged(enc, table, t, sink);
            return;
        }
        if let Some(slot) = self.pending.get_mut(usize::from(self.npend)) {
            if self.npend == 0 {
                self.out_of_band = open;
            }
            *slot = t;
            if let Some(seq) = self.pending_seq.get_mut(usize::from(self.npend)) {
                *seq = self.arrivals;
            }
            self.npend = self.npend.wrapping_add(1);
        }
        self.latest = t;
        self.resolve(enc, table, false, sink);
    }

    /// Judges pending edges while there is enough lookahead (all of them if `flushing`).
    fn resolve<P: PitchTable, S: EdgeSink>(
        &mut self,
        enc: &Encoder,
        table: &P,
        flushing: bool,
        sink: &mut S,
    ) {
        while self.npend > 0 {
            let e1 = self.pending[0];
            let s1 = self.pending_seq[0];
            let verdict = self.judge(enc, flushing);
            // One tail for every verdict (a fault's bookkeeping, then one acceptance): the
            // careful path's code stays small.
            let (lost, within) = match verdict {
                Verdict::Wait => return,
                Verdict::Glitch => {
                    self.pop();
                    self.reject(e1, sink);
                    #[cfg(feature = "pattern-wheels")]
                    self.fault_repeats(enc, Repeat::Glitch);
                    // Merged with the edge after it (ringing just after a tooth, or a pulse
                    // just before one): the edge kept may be either of the pair, its time off
                    // by their spacing, so no sample starts at it either. (A pulse 1 to 16 % of
                    // a pitch after a 36-2 wheel's frame tooth, with jitter of 1 %, was kept
                    // and the real tooth rejected: the window starting at it was valid, its
                    // first one-edge sample too fast, δ 0.664 for 0.618.)
                    self.across = 2;
                    continue;
                }
                // An unexplained edge is taken as the tooth, and is a fault of its own: the
                // window around it is not vouched for, and in a revolution with others the
                // count is given up (a count two teeth off, left by two noise pulses in a row,
                // explains the gap with a lost tooth and a glitch in every revolution, two
                // faults, and would otherwise stay off for good).
                Verdict::Tooth | Verdict::Unexplained => {
                    self.pop();
                    let vouched = verdict == Verdict::Tooth;
                    if !vouched {
                        self.counters.unexplained = self.counters.unexplained.wrapping_add(1);
                        sink.fault(Fault::Unexplained, e1);
                        self.fault_in_revolution();
                    }
                    self.accept(enc, table, e1, s1, (true, vouched, 0), sink);
                    continue;
                }
                // Teeth lost before it, and of them those within its interval (`Missing` is 1
                // or 2, lost within it; `Ahead` one lost earlier, its interval the tooth's
                // own), or none: the count was one ahead.
                Verdict::Missing(n) => (n, n),
                // A run of teeth lost: counted below, then the count given up.
                Verdict::Dropout(n) => (n, 0),
                // The count was off since some earlier edge: the swings recorded since were
                // recorded against the wrong teeth, and would mislead the next judgements.
                Verdict::Ahead | Verdict::Behind => {
                    self.forget_history();
                    (u16::from(verdict == Verdict::Ahead), 0)
                }
            };
            self.pop();
            if lost == 0 {
                self.counters.extra = self.counters.extra.wrapping_add(1);
                sink.fault(Fault::ExtraEdge, e1);
            } else {
                self.counters.missing = self.counters.missing.wrapping_add(u32::from(lost));
                sink.fault(Fault::MissingEdge, e1);
            }
            if let Verdict::Dropout(_) = verdict {
                // The count is given up, and the edge is a new time reference: the next
                // interval is the first judged.
                self.lose_sync(false);
                self.last = e1;
                self.prev = 0;
                self.across = 0;
                continue;
            }
            self.fault_in_revolution();
            #[cfg(feature = "pattern-wheels")]
            if lost > 0 {
                self.fault_repeats(enc, Repeat::Missing);
            }
            if lost == 0 {
                self.tooth = tooth_back(self.tooth, 1, enc.edges());
                self.reset_ring();
            } else {
                self.advance_after_fault(enc, lost);
            }
            self.accept(enc, table, e1, s1, (false, false, within), sink);
            if within > 0 {
                self.prev = self.per_base_over(enc, within);
            }
        }
    }

    /// The per-base interval of the tooth just accepted when its interval also spanned the
    /// `lost` teeth before it: the interval over all their pitches, as the judgement took it
    /// (over the tooth's own pitch alone, the next edge would be judged against an interval
    /// `lost + 1` pitches long, and after a wheel's gap taken for a glitch).
    fn per_base_over(&self, enc: &Encoder, lost: u16) -> u32 {
        if enc.is_uniform() {
            // Every pitch the base (always so without pattern wheels: no other division).
            return self
                .prev
                .checked_div(u32::from(lost).wrapping_add(1))
                .unwrap_or(self.prev);
        }
        let own = enc.grid_pitch(self.tooth);
        let mut span = own;
        for i in 1..=lost {
            span = span.saturating_add(enc.grid_pitch(tooth_back(self.tooth, i, enc.edges())));
        }
        // A reference for judging, which is done in f32 anyway (no 64-bit division).
        if span == 0 {
            self.prev
        } else {
            (self.prev as f32 * (own as f32 / span as f32)) as u32
        }
    }

    #[inline(never)] // careful path: one copy for its callers (code size)
    fn pop(&mut self) {
        self.out_of_band = false;
        self.pending.copy_within(1.., 0);
        self.pending_seq.copy_within(1.., 0);
        self.npend = self.npend.saturating_sub(1);
    }

    /// Judges all pending edges with what is known (a timeout, a reversal, a poll).
    fn flush<P: PitchTable, S: EdgeSink>(&mut self, enc: &Encoder, table: &P, sink: &mut S) {
        if self.npend > 0 {
            self.resolve(enc, table, true, sink);
        }
    }

    /// The verdict on `pending[0]`.
    fn judge(&mut self, enc: &Encoder, flushing: bool) -> Verdict {
        let e1 = self.pending[0];
        let d1 = e1.wrapping_sub(self.last) & enc.mask();
        let r = self.prev;
        if r == 0 {
            return Verdict::Tooth;
        }
        let synced = self.sync == SyncState::Synced;
        let edges = enc.edges();
        let base = enc.base_pitch();
        let next = tooth_after(self.tooth, 1, edges);
        // Grid pitch of the expected tooth: unsynced, the shortest the wheel has (so only what
        // is short even against that is a glitch outright).
        // Unsynced on a pattern wheel, the previous interval may have been the longest pitch
        // and this one the shortest: only what is short even against that is a glitch.
        let expected = if synced || enc.framing() != Framing::Pattern {
            // Every pitch the base but on a pattern wheel (a power of two: the product and
            // the quotient were exact, and are left out).
            let per = if enc.framing() == Framing::Pattern {
                r as f32 * enc.grid_pitch(if synced { next } else { 0 }) as f32 / base as f32
            } else {
                r as f32
            };
            per * if synced {
                self.recorded_swing(enc, self.tooth, next, 1.0)
            } else {
                1.0
            }
        } else {
            let (lo, hi) = (0..edges).fold((u32::MAX, 0), |(lo, hi), k| {
                let p = enc.grid_pitch(k);
                (lo.min(p), hi.max(p))
            });
            r as f32 * lo as f32 / hi.max(1) as f32
        };
        let x = d1 as f32;
        let tol = enc.config().tolerances;
        // Synced on a pattern wheel, the count may be one tooth off (an extra or lost edge
        // taken earlier): only what is short even against the pitches of the teeth before
        // and after the expected one is a glitch outright (a real tooth, one short of a gap
        // the count puts one tooth early, is left for the judgement, which realigns).
        let outright = if synced && enc.framing() == Framing::Pattern {
            let own = enc.grid_pitch(next);
            let near = enc
                .grid_pitch(self.tooth)
                .min(enc.grid_pitch(tooth_after(next, 1, edges)));
            if near < own && own > 0 {
                expected * (near as f32 / own as f32)
            } else {
                expected
            }
        } else {
            expected
        };
        if x + 1.0 < tol.glitch_fraction * (outright - 1.0) {
            return Verdict::Glitch;
        }
        if x - 1.0 > 3.0 * tol.accept * (r as f32 + 1.0) && enc.is_uniform() {
            // A run of teeth lost: longer than three of the last interval by more than the
            // accept band. The judgement's longest fault, two teeth lost, would make a third of
            // it the interval the next edges are judged by, and the real teeth after it pairs
            // of glitches and teeth (64 captures lost: 8 glitches, 2 unexplained edges, the
            // sync lost; 5 lost: an unexplained edge, 3 missing frames). Against the last
            // interval, not the expected one a recorded swing scales: at least 3 teeth lost.
            // On a uniform disc only: on a wheel with a pattern a gap among the teeth lost
            // makes pitches no count of teeth (two lost before a 36-2 wheel's gap read as
            // four, and the sync lost). Lost: as many as the last interval fits in it, less
            // this edge.
            // Against the only interval since a new time reference or a fault (the ring
            // holds one), no count: that interval is as likely an extra edge's (ringing just
            // after a tooth) as the teeth are lost, and is counted so, one extra edge (a
            // 360-line disc ringing on the polarity read counted 27 teeth lost a tooth,
            // 78 400 in a capture of 5 762 edges). The ring's fill, not a flag of its own:
            // 16 bytes of code, a flag 24.
            // Through u32 (the FPU's saturating conversion) and clamped: the same as `as u16`,
            // 24 bytes less code (`as u16` compared the float with both ends).
            let lost = ((x / r as f32 - 0.5) as u32).min(u32::from(u16::MAX)) as u16;
            return Verdict::Dropout(lost.wrapping_mul(u16::from(self.fill != 1)));
        }
        if !synced && enc.framing() == Framing::Pattern {
            // Unsynced on a pattern wheel the expected pitch is unknown: take every edge that
            // is not a glitch outright; the acquisition judges the intervals.
            return Verdict::Tooth;
        }
        let special = synced && self.is_special(enc, next);
        let accept = tol.accept;
        // An ordinary tooth's band is the fast path's own, so both judge alike.
        // An ordinary edge that fell outside the fast path's band is judged with what follows,
        // so a batch of captures and edge-by-edge calls decide alike.
        let in_band = if self.out_of_band {
            false
        } else {
            x + 1.0 >= (expected - 1.0) / accept && x - 1.0 <= (expected + 1.0) * accept
        };
        // In the band an ordinary tooth is taken at once, and so is the frame of an index disc
        // when its index pulse is there (the count is checked on acceptance) or of an unframed
        // one; a pattern's special teeth are always judged with what follows.
        let plain = !special
            || enc.framing() == Framing::None
            || (enc.framing() == Framing::Index && self.index_covers(enc, e1, self.pending_seq[0]));
        if in_band && plain {
            return Verdict::Tooth;
        }
        // Judge with the following two edges.
        let n = usize::from(self.npend);
        if n < PENDING && !flushing {
            return Verdict::Wait;
        }
        let d2 = (n >= 2).then(|| self.pending[1].wrapping_sub(e1) & enc.mask());
        let d3 = (n >= 3).then(|| self.pending[2].wrapping_sub(self.pending[1]) & enc.mask());
        // The intervals after the judged edge, laid out once for the hypotheses that take them
        // as they are (passed by value, each call made a copy of its own: 40 bytes more code).
        let rest = [d2, d3];
        let p_next = pitch_ratio(enc, next);
        // Where the expected tooth ends a long pitch p (a gap), every fault leaves less
        // evidence than after an ordinary pitch: a tooth lost there stretches the gap by
        // (p + 1)/p only, not 2, and a noise pulse late in the gap, or a count one tooth off,
        // looks like a gap a pitch shorter. The margin shrinks with it, by
        // (ln((p + 1)/p)/ln 2)², so that a swing is called a fault at the same fraction of
        // the way to one as after an ordinary pitch (on a 60-2 wheel's gap a swing above 1.21
        // is a lost tooth, against 1.58 elsewhere, without a recorded revolution).
        // There, too, an interval after the judged one that no hypothesis here explains
        // (a tooth lost two teeth on) costs each hypothesis at most that margin: what calling
        // it a fault when it is judged will cost (else it would outweigh the evidence on the
        // judged edge itself).
        let gap = synced && enc.framing() == Framing::Pattern && p_next > 1.0;
        let (margin, cap) = if gap {
            let r = ln((p_next + 1.0) / p_next) / core::f32::consts::LN_2;
            let m = tol.fault_margin * if r < 1.0 { r * r } else { 1.0 };
            (m, m)
        } else {
            (tol.fault_margin, f32::INFINITY)
        };
        let here = self.tooth;
        let (mut expected_cost, mut recorded_cost) =
            self.chain_cost(enc, here, next, x / p_next, &rest, cap);
        if let (true, true, 0, Some(a)) = (cfg!(feature = "pattern-wheels"), gap, self.across, d2) {
            // After a gap, also the expected tooth with the tooth after it lost (a fault of
            // its own, judged next: the margin). The interval after it spans two pitches, the
            // swings into and out of it each cost the cap, twice the margin: the tooth after
            // the gap, which fits, was unexplained, and one tooth lost there counted as two
            // faults (on every wheel of `tests/start_flare.rs`, at every ripple). Only where
            // the loss explains the interval within a quarter of the margin shrunk there, and
            // the tooth's own interval spans no glitch: within the whole margin, a noise pulse
            // two thirds into a 12-1 wheel's gap (±40 %, three strokes, jitter of 2 % of a
            // pitch) fitted a tooth and a loss after it (0.038), was taken for the frame and
            // framed a window off; and where a count one tooth ahead had just taken the real tooth
            // before the gap for a glitch, the gap fitted a loss after the frame, and the
            // unexplained edge that gave that count up in the same revolution was not found.
            let (one, two) = (tooth_after(next, 1, edges), tooth_after(next, 2, edges));
            let (p1, p2) = (pitch_ratio(enc, one), pitch_ratio(enc, two));
            let own = a as f32 * p1 / (p1 + p2 * self.raw_swing(one, two));
            let (cost, recorded) =
                self.chain_cost(enc, here, next, x / p_next, &[Some(own as u32), None], cap);
            if recorded < 0.25 * margin {
                if cost + margin < expected_cost {
                    expected_cost = cost + margin;
                }
                if recorded < recorded_cost {
                    recorded_cost = recorded;
                }
            }
        }
        if let (Some(a), Some(b), true) = (d2, d3, in_band) {
            // A special tooth in the band: also the expected tooth with the edge after it a
            // glitch (a fault of its own, judged next: the margin). Else a noise pulse just
            // after the tooth weighs against it in both intervals it splits: after a gap,
            // where they cost at most the shrunk margin each, the tooth was taken as
            // unexplained beside the glitch. (Out of the band as well, it cost valid windows
            // in the sparse-fault census: 158 of 12 712 at 3 %.)
            let later =
                self.chain_cost(
                    enc,
                    here,
                    next,
                    x / p_next,
                    &[Some(a.wrapping_add(b)), None],
                    cap,
                )
                .0 + margin;
            if later < expected_cost {
                expected_cost = later;
            }
        }
        // The fault hypotheses compete on their costs alone, the first of equals kept; the
        // best of them must then beat the expected tooth by the margin. (Each compared with
        // the best so far plus the margin, the first fault considered that beat the tooth
        // could not be displaced by a later one that explains the edges better: a count one
        // tooth off, met at a gap as a lost tooth, stayed off for good.)
        let mut best = (f32::INFINITY, Verdict::Tooth);
        let mut consider = |cost: f32, v: Verdict| {
            if cost < best.0 {
                best = (cost, v);
            }
        };
        // A glitch: e1 and e2 merged are the expected tooth.
        let glitch = match d2 {
            Some(d2) => {
                self.chain_cost(enc, here, next, (x + d2 as f32) / p_next, &[d3, None], cap)
                    .0
            }
            None => f32::INFINITY,
        };
        consider(glitch, Verdict::Glitch);
        if synced {
            let mut spans = p_next;
            let mut tooth = next;
            for j in 1..=2u16 {
                tooth = tooth_after(tooth, 1, edges);
                spans += pitch_ratio(enc, tooth);
                // On a pattern wheel the teeth spanned are weighed by the intervals they had
                // a revolution earlier: cranking at ±30 %, a 12-1 wheel's gap is slow and the
                // pitch after it fast (a third of the gap), so the even share of the gap and
                // a lost tooth after it was 36 % longer than that pitch's, the loss cost more
                // than the tooth, and the count went a tooth behind with a valid window over
                // the loss.
                let spans = if enc.framing() == Framing::Pattern {
                    self.recorded_spans(enc, next, tooth)
                } else {
                    spans
                };
                // The frame tooth of an index disc is not skipped silently: the index decides.
                let mut cost = self.chain_cost(enc, here, tooth, x / spans, &rest, cap).0;
                if cfg!(feature = "pattern-wheels") && enc.framing() == Framing::Pattern {
                    // The tooth before the loss against the first after it as they were
                    // recorded, however far apart they swing: judging one tooth against the
                    // next, a swing beyond R^0.9 is taken for a count off and not trusted, but
                    // a tooth lost after a 12-1 wheel's gap at ±40 % spans a swing of 2.3, and
                    // weighed without it the loss cost more than the tooth (the count went a
                    // tooth behind, a window over a revolution and a pitch valid).
                    let (head, prev) = (x / spans, self.prev as f32);
                    cost += log_sq(head, prev * self.raw_swing(here, tooth))
                        - log_sq(head, prev * self.recorded_swing(enc, here, tooth, 1.0));
                }
                consider(
                    cost + margin * f32::from(j.wrapping_sub(1)),
                    Verdict::Missing(j),
                );
            }
            if enc.framing() == Framing::Pattern {
                // A count one tooth off needs a fault earlier that went unseen: it must explain
                // the edges better than a fault here by the margin (a tooth lost next to a gap
                // also fits a count one ahead, and the loss is the likelier).
                let behind = tooth_back(next, 1, edges);
                let before_behind = tooth_back(behind, 1, edges);
                consider(
                    self.chain_cost(
                        enc,
                        before_behind,
                        behind,
                        x / pitch_ratio(enc, behind),
                        &rest,
                        cap,
                    )
                    .0 + margin,
                    Verdict::Behind,
                );
                let ahead = tooth_after(next, 1, edges);
                consider(
                    self.chain_cost(enc, next, ahead, x / pitch_ratio(enc, ahead), &rest, cap)
                        .0
                        + margin,
                    Verdict::Ahead,
                );
            }
        }
        // At a gap, what the edges' jitter makes the teeth there cost (0 until learnt): the
        // two rules below that need no fault to win are held above it. From fewer than
        // `GAP_LEARNT` gaps only the tooth's own cost is, and only where no fault explains the
        // edges better at all, on a wheel larger than the fit keeps: held there above that
        // less certain estimate, a lost frame tooth of a 60-2 wheel cranking at ±30 % with two
        // gaps learnt was taken for the gap (8 wrong windows in the crank sweep's finer sweep
        // `near2`), and on a 12-1 wheel a noise pulse left a count a tooth off.
        let (floor, quarter) = if cfg!(feature = "pattern-wheels") && gap && self.history {
            let (early, learnt) = self.gap_noise(margin, expected_cost, best.0);
            let noise = if best.0 >= expected_cost && !fit_kept(enc) {
                early
            } else {
                learnt
            };
            (
                if noise > margin { noise } else { margin },
                if 0.5 * learnt > 0.25 * margin {
                    0.5 * learnt
                } else {
                    0.25 * margin
                },
            )
        } else {
            (margin, 0.25 * margin)
        };
        // At a gap, a tooth that costs more than the margin is unexplained only where it
        // still does with what the speed's trend changed since the recorded revolution taken
        // out (see `steady_cost`): a clean 12-1 wheel's frame tooth, where a start flare
        // began, was unexplained, the two intervals after it shorter than a revolution
        // earlier by a fifth and a third, on every stream of
        // `the_onset_of_a_start_flare_at_the_frame_is_no_fault`.
        // (The feature named: a compare with +∞ did not fold away without it, 56 bytes.)
        let trend = cfg!(feature = "pattern-wheels")
            && gap
            && self.steady_cost(enc, here, next, x / p_next, [d2, d3]) <= floor;
        if best.0 + margin < expected_cost {
            best.1
        } else if (expected_cost > floor && recorded_cost > floor && !trend)
            || (cfg!(feature = "pattern-wheels") && gap && best.0 + quarter < expected_cost)
            || (cfg!(feature = "pattern-wheels")
                && gap
                && next == 0
                && self.history
                && !self.frame_as_usual(enc, here, x / p_next, margin))
        {
            // After a gap, also where a fault explains the edges better than the tooth by a
            // quarter of the margin shrunk there: the evidence a fault leaves at a gap can be
            // that small (a tooth lost after an 8-1 or 12-1 wheel's gap while cranking at
            // ±30 %, the pitch after the gap fast, stretches the gap by a fifth of it), and a
            // count a tooth behind then vouched for a window over the loss (δ 0.67 for 0.54;
            // by half the margin, at ±40 % with jitter of 1 % of a pitch a lost frame tooth
            // of an 8-1 wheel still did, and a noise pulse late in its gap). (The feature
            // named: without it the compiler kept this test, 40 bytes.)
            // (Swings the recorded revolution does not hold, its teeth's intervals spanned by
            // a fault, count for the hypotheses, not here: against 1 the cranking swings after
            // a gap made the frame tooth unexplained a revolution after a noise pulse there;
            // uncounted in the hypotheses, a count one tooth off took a real tooth for a
            // glitch every revolution without a fault to give it up.)
            // The tooth costs more than a fault must win by, and no single fault wins: most
            // likely two faults within the lookahead (a noise pulse where a tooth was lost
            // looks like a tooth displaced by up to 30 %; two pulses in a row like the speed
            // doubling for four edges). Taken as the tooth, not vouched for: with the two rules
            // on samples and swings in `accept`, the sparse-fault census's wrong valid windows
            // (2 of 33 273 at 1 %, 9 of 12 247 at 3 %, 2 of 94 on unframed discs at 3 %) are
            // none (of 33 768, 12 712 and 82).
            Verdict::Unexplained
        } else {
            Verdict::Tooth
        }
    }

    /// Whether the frame edge of a pattern wheel, its interval `head` per pitch, is placed as
    /// the recent frames were against the tooth before, as recorded a revolution earlier; and
    /// learns from it where it is. The frame bounds the windows: a frame edge displaced within
    /// the margin shrunk at the gap makes the sample over the gap, and the window, wrong (a
    /// noise pulse from 0.45 of a pitch before a 12-1 wheel's frame tooth to 0.3 after it,
    /// exclusive-or'ed with the signal, replaces the tooth's edge with one early and one late:
    /// the early one was taken for the frame, 22 % early, within the margin, and the window
    /// ending there valid, δ 0.25 on a steady shaft; the late one was an extra edge a
    /// revolution on). Unexplained: a squared log swing above a quarter of the margin and
    /// above `FRAME_NOISE` times the mean of the recent frames' (the edges' jitter sets it).
    fn frame_as_usual(&mut self, enc: &Encoder, here: u16, head: f32, margin: f32) -> bool {
        let swing = self.recorded_swing(enc, here, 0, 1.0);
        let cost = log_sq(head, self.prev as f32 * swing);
        let Some(f) = self.fit.first_mut() else {
            return true;
        };
        if cost > margin {
            // The rules on faults decide (and a fault's cost is no jitter to learn).
            return true;
        }
        let usual = f.frames.after(FRAME_LEARNT);
        if usual.is_some_and(|m| cost > 0.25 * margin && cost > FRAME_NOISE * m) {
            return false;
        }
        f.frames.learn(cost);
        true
    }

    /// What the edges' jitter makes the tooth after a pattern wheel's gap cost: `GAP_NOISE`
    /// times the mean chain cost of the recent gaps' teeth (0 until `GAP_LEARNT` are learnt);
    /// and learns from this one (its chain cost `cost`, the best fault's `fault`). Where the
    /// tooth is unexplained with no fault winning, its cost must exceed this as well as the
    /// margin shrunk there, and a fault must beat it by half this as well as by a quarter of
    /// that margin: at the shrunk margin alone, edge jitter of 3 % of a pitch (σ) made the
    /// tooth after a 36-2 or 60-2 wheel's gap unexplained in some revolutions of nearly every
    /// run of 40, 2 % in a third of them.
    ///
    /// Returned twice: as learnt (0 before `GAP_LEARNT`), and from the first gap learnt on,
    /// where fewer than `GAP_LEARNT` are learnt, that mean's multiple raised by `GAP_LEARNT`
    /// over the gaps learnt (a mean of few costs is less certain). Weighed from the first gap
    /// where the judgement allows (see [`SpeedTracker::judge`]), the teeth after the first
    /// gaps in sync of 36-2 and 60-2 wheels under jitter of 3 % were unexplained 20 times in
    /// 80 runs, not 38 (`the_first_gaps_jitter_is_weighed_before_four_are_learnt`).
    fn gap_noise(&mut self, margin: f32, cost: f32, fault: f32) -> (f32, f32) {
        let Some(f) = self.fit.first_mut() else {
            return (0.0, 0.0);
        };
        let (n, mean) = (f.gaps.count, GAP_NOISE * f.gaps.mean);
        let noise = if n >= GAP_LEARNT {
            (mean, mean)
        } else if n > 0 {
            (mean * f32::from(GAP_LEARNT) / f32::from(n), 0.0)
        } else {
            (0.0, 0.0)
        };
        if fault + margin >= cost {
            // Not a fault by the hypotheses: jitter to learn from (at most the margin, so
            // that a fault's cost moves the mean by a sixteenth of it at most).
            f.gaps.learn(if cost > margin { margin } else { cost });
        }
        noise
    }

    /// The squared log swings of the expected tooth `first` (its per-pitch interval `head`,
    /// after tooth `before`) and of the two intervals `rest` after it against the swings the
    /// same teeth had a revolution earlier, less the middle one of the three swings: what is
    /// left of them once the part two of them share is taken out (+∞ with fewer than two
    /// intervals after it). A change of the speed's trend since the recorded revolution swings
    /// every interval the same way: an engine's start flare (the mean speed from 25 to 150
    /// rad/s over two revolutions, at a constant acceleration) makes each interval after a
    /// 12-1 wheel's gap a fifth to a third shorter against the one before than a revolution
    /// earlier. A fault swings them one way and back (a lost tooth +ln 2 then −ln 2, a noise
    /// pulse at f of a pitch ln f, ln((1 − f)/f), −ln(1 − f), two noise pulses in a row
    /// −ln 2 then none), or one alone: no two share a part the middle one takes out. The
    /// recorded swings however large (the judgement trusts none beyond R^0.9: taken as 1, a
    /// noise pulse two thirds into a 12-1 wheel's gap at ±40 % with three strokes, where the
    /// gap swings 1.87 against the tooth before, looked like the speed rising at every tooth);
    /// 1 where not recorded.
    #[inline(never)]
    fn steady_cost(
        &self,
        enc: &Encoder,
        before: u16,
        first: u16,
        head: f32,
        rest: [Option<u32>; 2],
    ) -> f32 {
        let mut e = [0.0f32; 3];
        e[0] = ln(head / (self.prev as f32 * self.raw_swing(before, first)));
        let (mut prev, mut tooth) = (head, first);
        for (i, d) in rest.iter().enumerate() {
            let Some(d) = d else {
                return f32::INFINITY;
            };
            let next = tooth_after(tooth, 1, enc.edges());
            let v = *d as f32 / pitch_ratio(enc, next);
            if let Some(slot) = e.get_mut(i.wrapping_add(1)) {
                *slot = ln(v / (prev * self.raw_swing(tooth, next)));
            }
            prev = v;
            tooth = next;
        }
        let [a, b, c] = e;
        let (lo, hi) = if a < b { (a, b) } else { (b, a) };
        let (lo, hi) = (if c < lo { c } else { lo }, if c > hi { c } else { hi });
        let mid = a + b + c - lo - hi;
        let (a, b, c) = (a - mid, b - mid, c - mid);
        a * a + b * b + c * c
    }

    /// The cost of a hypothesis on the pending edges: the first is tooth `first` with the
    /// per-pitch interval `head`, after the last accepted edge, which was tooth `before`; the
    /// intervals `rest` that follow are the teeth after `first`. The cost is the sum of the
    /// squared log swings of the per-pitch intervals against the swings the same teeth had one
    /// revolution earlier (against 1 without a recorded revolution), each after the first at
    /// most `cap`. One routine, out of line, for every hypothesis.
    #[inline(never)]
    fn chain_cost(
        &self,
        enc: &Encoder,
        before: u16,
        first: u16,
        head: f32,
        rest: &[Option<u32>; 2],
        cap: f32,
    ) -> (f32, f32) {
        let mut cost = log_sq(
            head,
            self.prev as f32 * self.recorded_swing(enc, before, first, 1.0),
        );
        // The same without the swings the recorded revolution does not hold.
        let mut recorded = cost;
        let (mut prev, mut tooth) = (head, first);
        let mut left: &[Option<u32>] = rest;
        while let Some((&d, tail)) = left.split_first() {
            // Opaque, so that the loop is neither unrolled nor turned into a skipping search
            // (24 bytes less code than `rest.iter().flatten()`).
            left = core::hint::black_box(tail);
            let Some(d) = d else {
                continue;
            };
            let next = tooth_after(tooth, 1, enc.edges());
            let v = d as f32 / pitch_ratio(enc, next);
            let s = self.recorded_swing(enc, tooth, next, 0.0);
            let swing = log_sq(v, prev * if s > 0.0 { s } else { 1.0 });
            // A compare, not `f32::min` (a call of `fminf` on this FPU); never NaN.
            let swing = if swing > cap { cap } else { swing };
            cost += swing;
            if s > 0.0 {
                recorded += swing;
            }
            prev = v;
            tooth = next;
        }
        (cost, recorded)
    }

    /// Whether `tooth` needs the careful judgement when it comes next.
    fn is_special(&self, enc: &Encoder, tooth: u16) -> bool {
        tooth == 0
            || (enc.framing() == Framing::Pattern
                && (enc.long_teeth() | enc.short_teeth())
                    .checked_shr(u32::from(tooth))
                    .unwrap_or(0)
                    & 1
                    == 1)
    }

    /// Whether a waiting index reported before the edge at `t` (arrival `seq`) lies between
    /// the last accepted edge and it.
    fn index_covers(&self, enc: &Encoder, t: u32, seq: u32) -> bool {
        self.index_places(enc, t, seq).0 != 0
    }

    /// Where the waiting index timestamps fall against the edge at `t` (arrival `seq`), bit
    /// `i` for timestamp `i`: those that frame the interval ending at it (reported before it
    /// arrived, timed after the last accepted edge and not after it), and those that are a
    /// later edge's (reported after it arrived, or timed after it). The others lost their
    /// edge. One scan, out of line, for the judgement and the acceptance alike.
    /// Also how many of them lost their edge (counted here: a count of the bits left would be
    /// a sequence of some 30 bytes in the acceptance).
    ///
    /// A timestamp near an edge's may lie before or after that edge (a Z gated with A,
    /// captured on the same edge, or jitter of the index against the lines): which edge it
    /// frames then depends on the order the two were reported in, or on the jitter, and
    /// flipped from revolution to revolution, each flip a missing or extra edge on a clean
    /// disc. Synced, the count decides near an edge (where an interval is more than two
    /// ticks): an index just before this edge where the count puts the frame at the next edge
    /// is the next edge's; one beside the last edge where the count puts the frame at this
    /// edge frames this edge; one beside the last edge where that edge was the frame and its
    /// index is owed is that frame's (the fourth result, [`SpeedTracker::owed`]). Near is an
    /// eighth of the interval on the side where the framing index lies (by the frame edge or
    /// by the tooth before it, [`SpeedTracker::index_late`]) and a tick on the other. Within a
    /// tick only, an index 0.04 pitch before a line edge with jitter of 0.03 pitch (σ) counted
    /// extra and missing edges and missing frames in most revolutions; within an eighth on
    /// both sides, such an index hid a count a tooth behind (a line edge lost unseen under
    /// wide timing tolerances) and left windows valid over 1.01 revolutions. A count a tooth
    /// off now goes unseen only by an index within a tick of its edge.
    #[inline(never)]
    fn index_places(&self, enc: &Encoder, t: u32, seq: u32) -> (u8, u8, u8, bool) {
        let m = enc.mask();
        let d = t.wrapping_sub(self.last) & m;
        let (mut frames, mut later, mut lost, mut owed) = (0u8, 0u8, 0u8, false);
        let synced = self.sync == SyncState::Synced;
        // Where the count puts this edge (the tooth after `self.tooth`, numbered below
        // `edges`): the tooth before the frame? The frame, or the edge after an owed frame?
        let last = enc.edges().wrapping_sub(1);
        let before_frame = synced && d > 2 && self.tooth.wrapping_add(1) == last;
        let near_last_frame = synced && d > 2 && (self.owed || self.tooth == last);
        // How near an edge the count decides: an eighth of the interval on the side where
        // the index lies (`index_late`), a tick on the other. An index that normally lies
        // just before its frame edge is near the tooth before the frame only when the count is
        // a tooth behind (a line edge lost unseen), and one that normally lies just after the
        // tooth before the frame is near the frame edge only when the count is a tooth ahead:
        // there the index must realign the count, not be taken as the count's.
        let wide = (d >> 3).max(1);
        let (late_side, early_side) = if self.index_late {
            (wide, 1)
        } else {
            (1, wide)
        };
        // The owed frame's index lies by the frame edge; the others by the tooth before it.
        let after = if self.owed { late_side } else { early_side };
        // One loop over the waiting slots, kept one turn long by `each_bit`, its classification
        // out of line: 136 bytes less than unrolled over the four slots, for 0.02 instructions
        // per edge more (it runs at every index pulse).
        let at = (
            m,
            d,
            seq,
            (early_side, after),
            (before_frame, near_last_frame),
        );
        each_bit(self.waiting(), |i| {
            // `i` < INDEXES ≤ 8: the bit is within the byte.
            let bit = 1u8.wrapping_shl(i as u32);
            match self.index_place(i, &at) {
                PLACE_FRAMES => frames |= bit,
                PLACE_LATER => later |= bit,
                PLACE_OWED => owed = true,
                _ => lost = lost.wrapping_add(1),
            }
        });
        (frames, later, lost, owed)
    }

    /// Where waiting index timestamp `i` falls (see [`SpeedTracker::index_places`]), given
    /// the counter mask, the interval of the edge judged, its arrival, how near an edge the
    /// count decides and where the count puts the edge (the tooth before the frame; the frame
    /// or the edge after an owed frame).
    #[inline(never)]
    fn index_place(
        &self,
        i: usize,
        &(m, d, seq, (before, after), (before_frame, near_last_frame)): &PlaceAt,
    ) -> u8 {
        let (x, q) = self.index.get(i).copied().unwrap_or((0, 0));
        let since = x.wrapping_sub(self.last) & m;
        if !reported_before(q, seq) {
            PLACE_LATER
        } else if near_last_frame && (since.wrapping_add(after) & m) <= after.wrapping_mul(2) {
            // Within `after` either side of the last edge (`after` ≤ d / 8 < m / 4).
            if self.owed {
                PLACE_OWED
            } else {
                PLACE_FRAMES
            }
        } else if (since > d && since < m / 2)
            || (before_frame && since.wrapping_add(before) >= d && since <= d)
        {
            PLACE_LATER
        } else if since <= d {
            // At the last accepted edge's own tick (`since` = 0) a timestamp still waiting
            // was reported after that edge arrived (before it, it would have framed that
            // edge): it frames this interval. An index a fraction of a tick after its edge
            // shares the edge's tick about as often as not; counted lost, it made most
            // revolutions a missing frame.
            PLACE_FRAMES
        } else {
            PLACE_LOST
        }
    }

    /// Drops waiting index timestamps up to `t`; returns whether one framed the interval
    /// ending at `t`. Timestamps older than the last accepted edge lost their edge: each is
    /// counted as a missing frame.
    /// Also whether the owed frame's index came.
    fn take_index(&mut self, enc: &Encoder, t: u32, seq: u32) -> (bool, bool) {
        let (frames, later, lost, owed) = self.index_places(enc, t, seq);
        // Where the framing index lies in its interval, late or early (an index beside the
        // last edge, before it, framed this edge by the count: not counted).
        if let Some(&(x, _)) = self.index.get(frames.trailing_zeros() as usize) {
            let m = enc.mask();
            let (since, d) = (x.wrapping_sub(self.last) & m, t.wrapping_sub(self.last) & m);
            if since <= d {
                self.index_late = since > d / 2;
            }
        }
        if self.sync == SyncState::Synced {
            // An index that framed no edge and is no later edge's: its edge was not seen.
            self.counters.missing_frames = self.counters.missing_frames.wrapping_add(lost.into());
        }
        self.keep_indexes(later);
        (frames != 0, owed)
    }

    /// Keeps the waiting index timestamps whose bit is set in `keep`, in order, and drops the
    /// others. Careful path: out of line, one copy for its callers (code size).
    #[inline(never)]
    fn keep_indexes(&mut self, keep: u8) {
        let mut n = 0usize;
        each_bit(keep & self.waiting(), |i| {
            let slot = self.index.get(i).copied().unwrap_or((0, 0));
            if let Some(to) = self.index.get_mut(n) {
                *to = slot;
            }
            n = n.wrapping_add(1);
        });
        self.nidx = n as u8;
    }

    /// The waiting index timestamps as bits (`nidx` ≤ INDEXES ≤ 8: within the byte).
    #[inline(never)] // one copy: less code than inlined (8 bytes)
    fn waiting(&self) -> u8 {
        1u8.wrapping_shl(u32::from(self.nidx)).wrapping_sub(1)
    }

    /// An index waiting before a new time reference `t` (within a timeout of it) makes that
    /// edge the frame candidate: the first index of a start is not lost to the reference edge.
    fn index_at_reference(&mut self, enc: &Encoder, t: u32) {
        if enc.framing() != Framing::Index || self.nidx == 0 {
            return;
        }
        let m = enc.mask();
        let (mut framed, mut later) = (false, 0u8);
        each_bit(self.waiting(), |i| {
            let (x, q) = self.index.get(i).copied().unwrap_or((0, 0));
            let before = t.wrapping_sub(x) & m;
            if !reported_before(q, self.arrivals) || before == 0 || before > m / 2 {
                // Reported after this edge arrived, at its tick, or ahead of it: the next
                // edge's (`i` < INDEXES ≤ 8: the bit is within the byte).
                later |= 1u8.wrapping_shl(i as u32);
            } else if before <= enc.timeout_ticks() {
                framed = true;
            }
        });
        self.keep_indexes(later);
        if framed {
            self.sync = SyncState::Confirming;
            // The anchor with it: the careful path settled the count on entry (anchor = tooth),
            // and `tooth − anchor` is what the fast path has counted since.
            self.tooth = 0;
            self.anchor = 0;
            self.searched = 0;
        }
    }

    /// Rejects the raw edge at `t` as a glitch.
    fn reject<S: EdgeSink>(&mut self, t: u32, sink: &mut S) {
        self.counters.glitches = self.counters.glitches.wrapping_add(1);
        sink.fault(Fault::Glitch, t);
        // Of a noise pulse and the real edge beside it, the later is the one judged: when the
        // pulse came first and was taken, the real edge is rejected, and the interval to the
        // next edge starts at the pulse. Samples restart at the next accepted edge, so none
        // spans a glitch.
        self.across = self.across.max(1);
    }

    /// A fault inside the current revolution: too many and the count is given up.
    #[inline(never)] // careful path: one copy for its callers (code size)
    fn fault_in_revolution(&mut self) {
        self.faults = self.faults.saturating_add(1);
        if self.faults >= FAULTS_TO_RESYNC && self.sync == SyncState::Synced {
            self.lose_sync(true);
        }
    }

    /// A glitch or a missing edge (`kind`) found in sync on a pattern wheel: where both
    /// came at the same tooth as a revolution before, one after the other, the count is given
    /// up. A count two teeth off explains the gap with a tooth lost just after it and takes
    /// the real tooth just before it for a glitch, every revolution: two faults either side
    /// of the frame, one in each revolution the frame counts, so never the three in one
    /// revolution that give a count up (after a dip to a tenth of the speed at the gap of a
    /// 36-1 wheel it stayed so for good, every window invalid).
    #[cfg(feature = "pattern-wheels")]
    #[inline(never)] // careful path: one copy for its callers (code size)
    fn fault_repeats(&mut self, enc: &Encoder, kind: Repeat) {
        if self.sync != SyncState::Synced || enc.framing() != Framing::Pattern {
            return;
        }
        let kind = kind as usize;
        let (rev, here) = (self.counters.revolutions, self.tooth);
        let mut lost = false;
        for f in &mut self.fit {
            let bit = 1u8 << kind;
            let before = f.last_faults.get(kind).copied().flatten();
            if before == Some((rev.wrapping_sub(1), here)) {
                f.repeated |= bit;
            } else {
                f.repeated &= !bit;
            }
            if let Some(slot) = f.last_faults.get_mut(kind) {
                *slot = Some((rev, here));
            }
            // The other fault repeated too, in this revolution or the one before.
            let other = f.last_faults.get(kind ^ 1).copied().flatten();
            let recent = other.is_some_and(|(r, _)| rev.wrapping_sub(r) <= 1);
            if f.repeated == 3 && recent {
                (f.last_faults, f.repeated) = ([None; 2], 0);
                lost = true;
            }
        }
        if lost {
            self.lose_sync(true);
        }
    }

    /// Moves the count on past `n` lost teeth (the edge being accepted is `n` teeth further).
    fn advance_after_fault(&mut self, enc: &Encoder, n: u16) {
        if self.sync == SyncState::Synced {
            self.tooth = tooth_after(self.tooth, n, enc.edges());
        }
        self.reset_ring();
    }

    /// Accepts the first edge of a running interval without judging it (no reference yet).
    fn accept_unjudged<P: PitchTable, S: EdgeSink>(
        &mut self,
        enc: &Encoder,
        table: &P,
        t: u32,
        sink: &mut S,
    ) {
        self.accept(enc, table, t, self.arrivals, (true, true, 0), sink);
    }

    /// Accepts the edge at `t` as the tooth after the current one (or as framed by an index).
    /// `clean`: its interval is its own (no fault within it); `vouched`: and may form a sample;
    /// `lost`: teeth lost within its interval, counted already (the count is past them).
    fn accept<P: PitchTable, S: EdgeSink>(
        &mut self,
        enc: &Encoder,
        table: &P,
        t: u32,
        seq: u32,
        (clean, vouched, lost): (bool, bool, u16),
        sink: &mut S,
    ) {
        let edges = enc.edges();
        let dt = t.wrapping_sub(self.last) & enc.mask();
        let clean = clean && self.across == 0;
        self.across = self.across.saturating_sub(1);
        // (Only the acquisition of a pattern changes it.)
        #[cfg_attr(not(feature = "pattern-wheels"), allow(unused_mut))]
        let mut vouched = clean && vouched;
        let mut tooth = tooth_after(self.tooth, 1, edges);
        let mut frame = false;
        let mut realigned = false;
        let was_synced = self.sync == SyncState::Synced;
        let was_known = self.teeth_known(enc);
        let old_tooth = self.tooth;
        match enc.framing() {
            Framing::Index => {
                let index_late = self.index_late;
                let (indexed, late) = self.take_index(enc, t, seq);
                match self.sync {
                    SyncState::Synced => {
                        // The last edge's frame, taken by the count: its index came late, at
                        // that edge's tick (the revolution it ended is counted now), or not
                        // (`late` only where one was owed).
                        if late {
                            self.owed = false;
                            self.counters.revolutions = self.counters.revolutions.wrapping_add(1);
                        }
                        self.settle_owed(t, sink);
                        if indexed && tooth != 0 && self.realigned {
                            // Disagreed at the frame before too: not a stray or lost edge but
                            // another number of lines than configured (one more: the index a
                            // tooth late every revolution), or a count off that the index
                            // disagrees with again. The count is given up, a missing frame (the
                            // window that ends here is not vouched for), and from this index it
                            // is confirmed again, which such a disc never is (missing frames are
                            // counted, as for one line fewer).
                            self.lose_sync(true);
                            self.missing_frame(t, sink);
                            self.sync = SyncState::Confirming;
                            tooth = 0;
                        } else if indexed && tooth != 0 && tooth <= lost {
                            // The frame edge was among the teeth lost within the interval, and
                            // its index came there: the count agrees (it realigned the count a
                            // tooth on, an extra edge counted and every later frame a tooth
                            // late). The revolution is counted; its window ended at the fault.
                            self.realigned = false;
                            self.counters.revolutions = self.counters.revolutions.wrapping_add(1);
                            // Nothing is learnt of where the index lies from an interval over
                            // the lost frame edge: by its edge, it lay mid-interval, was learnt
                            // early, and the next revolution's index, jittering just past its
                            // edge, realigned the count a line late for good.
                            self.index_late = index_late;
                        } else if indexed {
                            self.realigned = tooth != 0;
                            if tooth == 1 || tooth == edges.wrapping_sub(1) {
                                // One tooth off: a line edge lost or gained unseen. The index
                                // is authoritative: count the discrepancy, realign.
                                let ahead = tooth <= edges / 2;
                                if ahead {
                                    self.counters.extra = self.counters.extra.wrapping_add(1);
                                    sink.fault(Fault::ExtraEdge, t);
                                } else {
                                    self.counters.missing = self.counters.missing.wrapping_add(1);
                                    sink.fault(Fault::MissingEdge, t);
                                }
                                self.reset_ring();
                                tooth = 0;
                                realigned = true;
                            } else if tooth != 0 {
                                // Two teeth or more off: a stray pulse on the index line is
                                // likelier than as many line edges lost or gained unseen
                                // (realigned, one stray pulse framed the count three teeth
                                // off, blamed on the line as an extra edge). A missing frame;
                                // the count is kept, and given up if the next index disagrees
                                // too.
                                self.missing_frame(t, sink);
                            }
                            frame = tooth == 0;
                        } else if tooth == 0 {
                            // The frame by the count, its index not reported yet: it may still
                            // come at this edge's own tick, reported after it. The frame is
                            // taken (its window held by the monitor until the next edge) and
                            // the next edge settles it: the index came, or the frame was
                            // missing and the window is invalid (a missing frame found at the
                            // edge after the frame lies against it).
                            frame = true;
                            self.owed = true;
                        }
                    }
                    SyncState::Confirming => {
                        // Counted from the candidate, the index is due at tooth 0. Where it
                        // comes elsewhere, or tooth 0 comes without it, the confirmation
                        // failed: a revolution's worth of edges searched without a confirmed
                        // frame (the search's count goes on), so that a disc that never
                        // confirms (the wrong number of lines, an index misplaced) shows as
                        // missing frames, not as no windows and no fault.
                        if indexed && tooth == 0 {
                            self.sync = SyncState::Synced;
                            self.counters.syncs = self.counters.syncs.wrapping_add(1);
                            frame = true;
                        } else if indexed || tooth == 0 {
                            self.count_search(enc, enc.edges());
                        }
                        if indexed {
                            tooth = 0;
                        }
                    }
                    SyncState::Searching => {
                        if indexed {
                            self.sync = SyncState::Confirming;
                            tooth = 0;
                            self.searched = 0;
                        } else {
                            self.count_search(enc, 1);
                        }
                    }
                }
            }
            Framing::None => {
                if self.sync != SyncState::Synced {
                    self.sync = SyncState::Synced;
                    self.counters.syncs = self.counters.syncs.wrapping_add(1);
                    tooth = 0;
                } else if tooth == 0 {
                    frame = true;
                }
            }
            // Never met without pattern wheels (`framing` says so), and the acquisition is
            // then not compiled at all: the compiler did not always leave it out, nor did
            // the image stay the same size when it did.
            #[cfg(not(feature = "pattern-wheels"))]
            Framing::Pattern => {}
            #[cfg(feature = "pattern-wheels")]
            Framing::Pattern => {
                if self.sync == SyncState::Synced && self.count_contradicted(enc, dt, tooth) {
                    // The frame is not where the count puts it: the count is given up.
                    self.lose_sync(true);
                    self.missing_frame(t, sink);
                }
                if self.sync == SyncState::Synced {
                    frame = tooth == 0;
                } else {
                    // Acquisition: the evidence on the interval before this one, now that both
                    // its neighbours are known.
                    tooth = self.acquire(enc, dt);
                    frame = self.sync == SyncState::Synced && tooth == 0;
                    // The edge that syncs ends an interval taken unjudged (unsynced, every edge
                    // not a glitch outright is a tooth): no sample spans it (synced at a frame,
                    // a noise pulse where the tooth before the gap was lost made the gap a gap
                    // and a third, and the first window's δ wrong).
                    vouched &= self.sync != SyncState::Synced;
                }
            }
        }
        if frame && !realigned && was_synced && !self.owed {
            self.counters.revolutions = self.counters.revolutions.wrapping_add(1);
        }
        if frame {
            self.faults = 0;
        }
        self.tooth = tooth;
        let synced = self.sync == SyncState::Synced;
        let known = self.teeth_known(enc);
        if known != was_known || (known && tooth != tooth_after(old_tooth, 1, edges)) {
            // The numbering changed: spans summed under the old one must not mix with the new.
            self.reset_ring();
        }
        // The ring: the sample ends here. An interval across a fault, unexplained, or taken
        // unjudged before the sync is no sample.
        let sample = if vouched {
            self.push(enc, table, tooth, dt)
        } else {
            self.reset_ring();
            None
        };
        let had_ref = self.prev != 0 || dt != 0;
        let grid = if known {
            enc.grid_pitch(tooth)
        } else {
            enc.base_pitch()
        };
        // No pitch (grid 0): the interval as it is. A uniform disc's grid is always the base
        // or 0: said first, so that without pattern wheels the 64-bit division folds away.
        let per_base = if enc.is_uniform() || grid == enc.base_pitch() {
            dt
        } else {
            u64::from(dt)
                .wrapping_mul(u64::from(enc.base_pitch()))
                .checked_div(u64::from(grid))
                .map_or(dt, |q| q as u32)
        };
        if known && had_ref {
            // An interval across a fault records no swing: 0, which informs nothing. (Left
            // as it was, the tooth's swing recorded a revolution or more earlier, perhaps of a
            // noise pulse taken unjudged while the frame was confirmed, would judge this
            // tooth again next revolution, a fault again, and so on for good.) An unexplained
            // interval is the tooth's own, and recorded: as 0, a tooth whose swing only the
            // recorded revolution explains (a cranking gap) would be unexplained for good.
            self.record(enc, tooth, if clean { per_base } else { 0 });
        }
        if had_ref {
            self.prev = per_base;
        }
        // Counted on past the counter's wraps (see `last`): with a 32-bit counter, `t`.
        self.last = self.last.wrapping_add(dt);
        self.accepted = self.accepted.wrapping_add(1);
        self.anchor = tooth;
        sink.tooth(&Tooth {
            index: self.accepted,
            time: t,
            dt,
            tooth,
            synced,
            frame,
            sample,
        });
    }

    /// Counts `n` edges searched, and a missing frame for every three revolutions' worth of
    /// edges searched without one (finding and confirming a pattern takes up to two).
    #[inline(never)]
    fn count_search(&mut self, enc: &Encoder, n: u16) {
        self.searched = self.searched.saturating_add(n);
        if self.searched >= enc.edges().saturating_mul(3).max(6) {
            self.searched = 0;
            self.counters.missing_frames = self.counters.missing_frames.wrapping_add(1);
        }
    }

    /// Pattern acquisition on the edge at the end of interval `dt`: judges the interval before
    /// it (both neighbours known), narrows the alignments, and returns this edge's tooth (the
    /// alignment if unique, else a count).
    #[cfg(feature = "pattern-wheels")]
    fn acquire(&mut self, enc: &Encoder, dt: u32) -> u16 {
        let edges = enc.edges();
        let all = 1u64
            .checked_shl(u32::from(edges))
            .map_or(u64::MAX, |b| b.wrapping_sub(1));
        let [first, before, middle] = self.acq;
        self.acq = [before, middle, dt];
        if self.viable == 0 {
            self.viable = all;
        }
        self.fit_push(enc, dt);
        let fit = self.fit_alignment(enc);
        let fitted = fit.and_then(|(at, decisive, _)| decisive.then_some(at));
        if before > 0 && middle > 0 && dt > 0 {
            let (lo, hi) = if before < dt {
                (before, dt)
            } else {
                (dt, before)
            };
            let (long_thr, not_long_thr, short_thr) = acquisition_thresholds(enc);
            let m = middle as f32;
            let mut allowed = all;
            if enc.long_teeth() != 0 {
                // Long against both neighbours, or, on a wheel without short pitches, against
                // their geometric mean, which cancels a steady speed trend: cranking at ±40 %
                // on a 24-1 wheel leaves its gap only 1.55 times the pitch before it (2.76
                // times the one after, 2.07 their geometric mean), and ordinary teeth there
                // reach 1.2 against the mean (compared squared: m² against long² times the
                // neighbours' product, no root).
                let around = before as f32 * dt as f32;
                let trend_long = enc.short_teeth() == 0 && m * m >= long_thr * long_thr * around;
                if m >= long_thr * hi as f32 || trend_long {
                    allowed &= enc.long_teeth();
                } else if m <= not_long_thr * lo as f32 {
                    allowed &= !enc.long_teeth();
                }
            }
            if enc.short_teeth() != 0 && m <= short_thr * hi as f32 {
                allowed &= enc.short_teeth();
            }
            let pairs = enc.pair_teeth();
            if pairs != 0 && first > 0 {
                // An extra tooth splits a pitch in two: `before` and `middle` together span one
                // base pitch. Their sum over the geometric mean of the intervals either side
                // (which cancels a steady speed trend) is about 1 for a split pitch and about 2
                // for two ordinary ones; cranking at ±40 % on 12 teeth moves these to at most
                // 1.33 and at least 1.71, inside the thresholds √2 and 2^0.75.
                // Compared squared: (b + c)² against the thresholds² times a·d, no root.
                let sum = before as f32 + m;
                let (sq, around) = (sum * sum, first as f32 * dt as f32);
                if sq <= 2.0 * around {
                    allowed &= pairs;
                } else if sq >= NOT_A_PAIR_SQ * around {
                    allowed &= !pairs;
                }
            }
            // `viable` refers to the edge ending `middle` (the previous edge).
            let special = allowed != all;
            // Evidence that the interval is a special pitch (not only that it is not one):
            // what confirms a candidate. Evidence against special pitches elsewhere cannot
            // tell a candidate from one shifted onto a tooth that never looks special: at
            // ±40 % cranking ripple a 12-1 wheel's gap can look no longer than an ordinary
            // pitch on the slow stroke, and one noise pulse made such a pitch look long.
            let positive =
                special && allowed & !(enc.long_teeth() | enc.short_teeth() | pairs) == 0;
            // Where a revolution decides the alignment, evidence against a special pitch is
            // not weighed: at ±40 % ripple an 8-1 wheel's gap can be 1.17 times both its
            // neighbours, under `not_long`, and that ruled the true alignment out every
            // revolution.
            let narrowed = if fitted.is_some() && !positive {
                self.viable
            } else {
                self.viable & allowed
            };
            self.narrow(narrowed, allowed, positive);
        }
        // Move on to this edge.
        self.viable = rotate_left(self.viable, edges) & all;
        if let Some(at) = fitted {
            // The revolution's alignment, of this edge: it narrows as a special pitch does,
            // and confirms a candidate from the last edge of its revolution of confirmation on
            // (a revolution of intervals after the one that made it, none shared: a fault
            // makes one of them wrong, not both alike). Not on that edge alone: where edge
            // jitter left that one revolution undecided, only a pitch clearly special by its
            // neighbours could confirm, and a 12-1 wheel cranking at ±30 % with jitter of 2 %
            // of a pitch (σ) showed one 32 revolutions later.
            let allowed = 1u64.checked_shl(u32::from(at)).unwrap_or(0);
            self.narrow(self.viable & allowed, allowed, self.confirm <= 1);
        }
        if self.viable.count_ones() == 1 {
            let tooth = self.viable.trailing_zeros() as u16;
            match self.sync {
                SyncState::Searching => {
                    self.sync = SyncState::Confirming;
                    self.confirm = edges;
                    self.seen_special = false;
                    // The teeth are numbered anew: swings recorded under another candidate's
                    // numbering would judge the teeth once synced (a noise pulse while an 8-1
                    // wheel searched at ±40 % left such swings, and the first teeth in sync
                    // were taken for glitches, the count a tooth off).
                    self.forget_history();
                }
                SyncState::Confirming => {
                    self.confirm = self.confirm.saturating_sub(1);
                    // A small wheel's revolution fitting another alignment best is doubtful
                    // evidence (at ±45 % ripple with three strokes an 8-1 wheel showed a pitch
                    // clearly long at another tooth than the gap, and was framed there, its
                    // windows valid), and so is one that no alignment explains (see
                    // `FIT_EXPLAINS`).
                    let doubtful = fit.is_some_and(|(at, _, explains)| at != tooth || !explains);
                    if self.confirm == 0
                        && self.seen_special
                        && self.fit_settled(enc)
                        && !doubtful
                        && self.trackable(enc, tooth, dt)
                    {
                        self.sync = SyncState::Synced;
                        self.counters.syncs = self.counters.syncs.wrapping_add(1);
                        self.searched = 0;
                        self.faults = 0;
                        self.reset_ring();
                    }
                }
                SyncState::Synced => {}
            }
            if self.sync != SyncState::Synced {
                self.count_search(enc, 1);
            }
            tooth
        } else {
            if self.sync == SyncState::Confirming {
                self.sync = SyncState::Searching;
            }
            self.count_search(enc, 1);
            tooth_after(self.tooth, 1, edges)
        }
    }

    /// Narrows the candidate alignments to `narrowed` by the evidence `allowed`. None left: the
    /// evidence contradicts them, and the search starts over from it; else, while confirming,
    /// `confirms` says the candidate's special pitch was seen where due.
    #[cfg(feature = "pattern-wheels")]
    fn narrow(&mut self, narrowed: u64, allowed: u64, confirms: bool) {
        if narrowed == 0 {
            self.viable = allowed;
            self.sync = SyncState::Searching;
            self.confirm = 0;
            self.seen_special = false;
        } else {
            self.viable = narrowed;
            if self.sync == SyncState::Confirming && confirms {
                self.seen_special = true;
            }
        }
    }

    /// Keeps the log of the unsynced interval `dt` of a small wheel, and its ratio to the
    /// interval in its slot, one revolution before: the same tooth's, so that this ratio
    /// changes little from tooth to tooth (by the speed trend and the change of the ripple),
    /// unless an edge was lost or a noise pulse taken (the slots then hold other teeth, and
    /// the ratio jumps by the swings between them; the interval split or merged jumps
    /// itself). `run` counts the intervals in a row whose ratio followed on from the one
    /// before (after a jump, the interval that jumped is not counted: it may be the fault).
    #[cfg(feature = "pattern-wheels")]
    fn fit_push(&mut self, enc: &Encoder, dt: u32) {
        let edges = enc.edges();
        let Some(f) = self.fit.first_mut() else {
            return;
        };
        let slot = f.ln.get_mut(usize::from(f.pos));
        let (Some(slot), true) = (slot, dt > 0 && edges >= FIT_MIN_TEETH) else {
            (f.pos, f.len, f.run) = (0, 0, 0);
            return;
        };
        let l = ln(dt as f32);
        if f.len >= edges {
            let d = l - *slot;
            if f.len > edges && !(-FIT_PERIODIC..=FIT_PERIODIC).contains(&(d - f.d)) {
                f.run = 0;
            } else {
                if f.len > edges {
                    let step = d - f.d;
                    f.scatter.learn(step * step);
                }
                f.run = f.run.saturating_add(1).min(edges);
                f.trend = if f.run == 1 {
                    d
                } else {
                    f.trend + (d - f.trend) / f32::from(f.run)
                };
            }
            f.d = d;
        }
        *slot = l;
        // One more than the teeth: a ratio is known.
        f.len = f.len.saturating_add(1).min(edges.saturating_add(1));
        f.pos = tooth_after(f.pos, 1, edges);
    }

    /// Whether the teeth, numbered as the candidate numbers them, could be judged once synced:
    /// every swing between neighbouring teeth in the revolution recorded while confirming (the
    /// last tooth's still held) is one the judgement weighs, not one it ignores as a count
    /// off (see [`SpeedTracker::recorded_swing`]). A 10-1 wheel at ±38 % ripple with three
    /// strokes swings 1.89 from the gap to the tooth before it: synced, its gap was taken
    /// for a glitch, the count went a tooth off and windows were framed there.
    #[cfg(feature = "pattern-wheels")]
    fn trackable(&self, enc: &Encoder, tooth: u16, dt: u32) -> bool {
        let edges = enc.edges();
        if usize::from(edges) > MAX_PATTERN_TEETH {
            return true;
        }
        if self.hist_teeth.saturating_add(1) < edges {
            return false;
        }
        let limit = enc.pattern_swing();
        // The swing from each tooth to the next as last seen, per base pitch: the intervals
        // recorded, the last tooth's held, and this edge's own as the one after it (from this
        // tooth to the next, the judgement will weigh the last revolution's two recorded).
        let own = dt as f32 / pitch_ratio(enc, tooth);
        let at = |k: u16, second: bool| match self.held {
            _ if second && k == tooth => own,
            Some((t, v)) if t == k => v as f32,
            _ => self.hist.get(usize::from(k)).copied().unwrap_or(0) as f32,
        };
        (0..edges).all(|k| {
            let (a, b) = (at(k, false), at(tooth_after(k, 1, edges), true));
            if a <= 0.0 || b <= 0.0 {
                return true;
            }
            let s = b / a;
            let s = if s > 1.0 {
                s * TRACK_MARGIN
            } else {
                s / TRACK_MARGIN
            };
            let s2 = s * s;
            let s10 = (s2 * s2) * (s2 * s2) * s2;
            s10 < limit && s10 * limit > 1.0
        })
    }

    /// In sync on a small wheel whose intervals are kept: keeps this edge's interval `dt` (see
    /// [`SpeedTracker::fit_push`]) and says whether the last revolution of intervals decides another alignment than the count's
    /// for this edge (`tooth`). Weighed once a revolution, at the frame the count puts, and
    /// as soon as a revolution of intervals follows on again after a fault. The judgement in
    /// sync weighs each tooth against the same tooth a revolution earlier, which a count gone
    /// off records again under its own numbering: at ±40 % ripple with three strokes and
    /// jitter of 2 % of a pitch, a noise pulse and the faults after it moved an 8-1 wheel's
    /// count three teeth on, and every later window was valid, δ 0.93 for 0.62.
    #[cfg(feature = "pattern-wheels")]
    fn count_contradicted(&mut self, enc: &Encoder, dt: u32, tooth: u16) -> bool {
        if !fit_kept(enc) {
            return false;
        }
        let before = self.fit.first().map_or(0, |f| f.run);
        self.fit_push(enc, dt);
        let after = self.fit.first().map_or(0, |f| f.run);
        let edges = enc.edges();
        if tooth != 0 && !(after >= edges && before < edges) {
            return false;
        }
        matches!(self.fit_alignment(enc), Some((at, true, _)) if at != tooth)
    }

    /// Whether a frame may be confirmed now: on a wheel whose intervals are kept (see
    /// [`SpeedTracker::fit_push`]), only once the last revolution's each followed on from the
    /// one before, none a fault. (The swings recorded while confirming judge the teeth once
    /// synced: a noise pulse in them, while an 8-1 wheel searched at ±40 %, made the first
    /// teeth in sync glitches, the count a tooth off.)
    #[cfg(feature = "pattern-wheels")]
    fn fit_settled(&self, enc: &Encoder) -> bool {
        let edges = enc.edges();
        edges < FIT_MIN_TEETH
            || usize::from(edges) > FIT_TEETH
            || self.fit.first().is_none_or(|f| f.run >= edges)
    }

    /// The alignment a whole revolution of intervals favours on a small wheel with gaps (no
    /// short pitches), for the last edge, and whether it decides it. For each alignment: the
    /// log intervals over their pitches, the speed trend taken out, less the smooth speed
    /// profile of the revolution that fits them best (a mean and harmonics, each averaged over
    /// the pitch: with at most nine teeth the order 1, 2 or 3 alone; with more, 1 and 2
    /// together, 3 alone or 4 alone); it decides when its residual is small, every other
    /// alignment's large, and its profile no deeper than a ripple of ±42 %. Only a
    /// revolution whose intervals each followed on from the revolution before counts (see
    /// [`SpeedTracker::fit_push`]: a noise pulse or a lost tooth within it fits a wrong
    /// alignment now and then). Where the ripple is so deep that a gap on its fast stroke is
    /// no longer than a pitch on its slow one, the profile still tells them apart: an 8-1
    /// wheel at ±40 %, two strokes a revolution, has its gap 1.09 times its longer neighbour
    /// at worst, and the profile fits it to 0.005 ln²2, every other alignment to 0.15 ln²2 or
    /// more. Also whether the best alignment explains the revolution at all (`FIT_EXPLAINS`).
    /// `None`: not such a wheel, or no such revolution yet.
    #[cfg(feature = "pattern-wheels")]
    fn fit_alignment(&self, enc: &Encoder) -> Option<(u16, bool, bool)> {
        let edges = enc.edges();
        let e = usize::from(edges);
        let f = self.fit.first()?;
        if !fit_kept(enc) || f.run < edges {
            return None;
        }
        let base = enc.base_pitch() as f32;
        let unit = ln(f32::from(enc.extreme_pitches().0) / base);
        // Log intervals by slot and log pitch ratios by tooth, each less its mean (the
        // constant of every profile takes the means; taken out first, f32 keeps the residuals).
        let mut y = [0.0f32; FIT_TEETH];
        let mut q = [0.0f32; FIT_TEETH];
        let mut total = 0u32;
        let (mut y_mean, mut q_mean) = (0.0f32, 0.0f32);
        // The speed trend taken out: a revolution's ratio spread over its intervals, from the
        // oldest (slot `pos`) to the newest (a trend of 30 % a revolution left an 8-1
        // wheel's true alignment fitting no better than others).
        let slope = f.trend / f32::from(edges);
        let mid = f32::from(edges.saturating_sub(1)) / 2.0;
        for (k, (y, q)) in y.iter_mut().zip(q.iter_mut()).take(e).enumerate() {
            let p = enc.grid_pitch(k as u16);
            total = total.saturating_add(p);
            let age = tooth_back(k as u16, f.pos, edges);
            *y = f.ln.get(k).copied().unwrap_or(0.0) - slope * (f32::from(age) - mid);
            *q = ln(p as f32 / base);
            y_mean += *y;
            q_mean += *q;
        }
        let n = f32::from(edges);
        each_pair(&mut y, &[y_mean / n; FIT_TEETH], |y, m| *y -= m);
        each_pair(&mut q, &[q_mean / n; FIT_TEETH], |q, m| *q -= m);
        let turn = core::f32::consts::TAU / total.max(1) as f32;
        let step = (libm::cosf(turn), libm::sinf(turn));
        // The newest interval's slot: it ends at tooth `s` under alignment `s`, and tooth `k`
        // is in slot `newest − s + k`.
        let newest = tooth_back(f.pos, 1, edges);
        // Per alignment, the smallest residual and the largest harmonic of its profile.
        let mut rss = [f32::INFINITY; FIT_TEETH];
        let mut ripple = [0.0f32; FIT_TEETH];
        // Bit h: the order h harmonic.
        let models: [u8; 3] = if edges >= 10 {
            [0b0_0110, 0b0_1000, 0b1_0000]
        } else {
            [0b0010, 0b0100, 0b1000]
        };
        for model in models {
            // The profile's columns over the teeth, made orthonormal (Gram-Schmidt): the
            // constant, then cos and sin of each order, averaged over each tooth's pitch.
            let mut cols = [[0.0f32; FIT_TEETH]; 5];
            let mut m = 0;
            for (c, col) in cols.iter_mut().enumerate() {
                let h = match c {
                    0 => 0,
                    _ => match (1..=4u8)
                        .filter(|&h| model.checked_shr(u32::from(h)).unwrap_or(0) & 1 == 1)
                        .nth(c.wrapping_sub(1) / 2)
                    {
                        Some(h) => h,
                        None => break,
                    },
                };
                // The angle a tooth's pitch starts and ends at, as e^{iθ} turned a grid
                // position at a time (one sine and cosine a revolution, not two a tooth).
                let mut start = (1.0f32, 0.0f32);
                for (k, v) in col.iter_mut().take(e).enumerate() {
                    let p = enc.grid_pitch(k as u16);
                    let mut end = start;
                    for _ in 0..p {
                        end = rotate(end, step);
                    }
                    *v = if h == 0 {
                        1.0
                    } else {
                        let (mut a, mut b) = (start, end);
                        for _ in 1..h {
                            (a, b) = (rotate(a, start), rotate(b, end));
                        }
                        // The mean of cos hθ (c odd) or sin hθ over the pitch.
                        let w = f32::from(h) * p as f32 * turn;
                        if c & 1 == 1 {
                            (b.1 - a.1) / w
                        } else {
                            (a.0 - b.0) / w
                        }
                    };
                    start = end;
                }
                m = c.wrapping_add(1);
            }
            // `tri[c][d]`: column `c` of the profile on the orthonormal column `d` (d ≤ c).
            let mut tri = [[0.0f32; 5]; 5];
            for (c, row) in tri.iter_mut().enumerate().take(m) {
                let (done, rest) = cols.split_at_mut(c);
                let Some(col) = rest.first_mut() else { break };
                for (d, r) in done.iter().zip(row.iter_mut()) {
                    *r = dot(d, col);
                    each_pair(col, d, |v, u| *v -= *r * u);
                }
                let norm = libm::sqrtf(dot(col, col));
                // A column the others span (never on a wheel of six teeth or more): left out.
                let (norm, inv) = if norm > 1e-3 {
                    (norm, 1.0 / norm)
                } else {
                    (0.0, 0.0)
                };
                col.iter_mut().for_each(|v| *v *= inv);
                if let Some(r) = row.get_mut(c) {
                    *r = norm;
                }
            }
            for (s, (best, amp)) in rss.iter_mut().zip(ripple.iter_mut()).take(e).enumerate() {
                let mut z = [0.0f32; FIT_TEETH];
                for (k, (z, q)) in z.iter_mut().zip(q.iter()).take(e).enumerate() {
                    // Tooth `k` is in slot `newest − s + k` (no wrap: `k`, `s` under `e`).
                    let at = k.wrapping_add(e).wrapping_sub(s) as u16;
                    *z = y
                        .get(usize::from(tooth_after(newest, at, edges)))
                        .copied()
                        .unwrap_or(0.0)
                        - q;
                }
                let mut g = [0.0f32; 5];
                for (g, col) in g.iter_mut().zip(cols.iter()).take(m) {
                    *g = dot(col, &z);
                }
                let r = dot(&z, &z) - dot(&g, &g);
                if r < *best {
                    *best = r;
                    *amp = amplitude(&tri, g, m);
                }
            }
        }
        let (mut first, mut second, mut at) = (f32::INFINITY, f32::INFINITY, 0usize);
        for (s, &r) in rss.iter().take(e).enumerate() {
            if r < first {
                (second, first, at) = (first, r, s);
            } else if r < second {
                second = r;
            }
        }
        let scale = unit * unit;
        let smooth = ripple.get(at).is_some_and(|&a| a <= FIT_RIPPLE);
        // What edge jitter of σ (of a pitch) alone leaves of a revolution: each interval's log
        // scatters by 2σ², each step of `d` by 12σ² (three edges' second difference, in two
        // revolutions), and the profile takes little of either, so about `edges`/6 steps' worth.
        let jitter = f.scatter.mean * n / 6.0;
        // Both bounds raised alike: a wrong alignment's residual carries the jitter too, so
        // the gap between them that tells one from the other stays as it was set.
        let decisive =
            first <= FIT_FITS * scale + jitter && second >= FIT_MISFITS * scale + jitter && smooth;
        // (The best alignment explains the revolution at all: the profile and the pattern
        // leave little of it.)
        let explains = first <= FIT_EXPLAINS * scale;
        Some((at as u16, decisive, explains))
    }

    /// The tooth after which the fast path must stop (the next one is special).
    fn stop_after(&self, enc: &Encoder, tooth: u16) -> u16 {
        let edges = enc.edges();
        match enc.framing() {
            Framing::Index | Framing::None => edges.saturating_sub(1),
            Framing::Pattern => {
                let special = enc.long_teeth() | enc.short_teeth() | 1;
                let mut k = tooth_after(tooth, 1, edges);
                for _ in 0..edges {
                    if special.checked_shr(u32::from(k)).unwrap_or(0) & 1 == 1 {
                        return tooth_back(k, 1, edges);
                    }
                    k = tooth_after(k, 1, edges);
                }
                edges.saturating_sub(1)
            }
        }
    }

    /// Recomputes where the fast path must stop.
    fn update_fast(&mut self, enc: &Encoder) {
        // Confirming an index frame, the teeth are numbered by count already: ordinary teeth
        // take the fast path and the next index is checked where the count puts tooth 0.
        let numbered = self.sync == SyncState::Synced
            || (self.sync == SyncState::Confirming && enc.framing() == Framing::Index);
        let fast = self.state == ShaftState::Running
            && numbered
            && self.has_ref
            && self.prev != 0
            && self.npend == 0
            && self.nidx == 0
            && !self.owed
            && self.across == 0
            && !self.history
            // (Every interval of such a wheel reaches the careful path, where its count is
            // checked against whole revolutions, `count_contradicted`.)
            && !fit_kept(enc)
            && u16::from(self.fill) >= enc.samples_span();
        self.stop = if fast {
            self.refresh_band(enc);
            self.stop_after(enc, self.tooth)
        } else {
            self.tooth
        };
    }

    /// The next edge takes the careful path.
    #[inline]
    pub(crate) fn block_fast(&mut self) {
        self.stop = self.tooth;
    }

    /// The running shaft stopped (a timeout): count it once, lose sync.
    #[inline(never)] // careful path: one copy for its callers (code size)
    fn stop_running<S: EdgeSink>(&mut self, t: u32, sink: &mut S) {
        self.settle_owed(t, sink);
        if self.state == ShaftState::Running {
            self.counters.timeouts = self.counters.timeouts.wrapping_add(1);
            sink.fault(Fault::Timeout, t);
            self.lose_sync(false);
        }
        self.state = ShaftState::Standstill;
        self.block_fast();
    }

    /// An owed frame's index did not come by the edge after it, or no edge follows it (a stop,
    /// a reversal).
    #[inline(never)] // careful path: one copy for its callers (code size)
    fn settle_owed<S: EdgeSink>(&mut self, t: u32, sink: &mut S) {
        if core::mem::replace(&mut self.owed, false) {
            self.missing_frame(t, sink);
        }
    }

    /// A revolution's index did not come: the count goes on, but that revolution cannot be
    /// vouched for. Rare: one copy, out of line.
    #[inline(never)]
    fn missing_frame<S: EdgeSink>(&mut self, t: u32, sink: &mut S) {
        self.counters.missing_frames = self.counters.missing_frames.wrapping_add(1);
        sink.fault(Fault::MissingFrame, t);
    }

    /// `t` is a new time reference: no interval, nothing pending. Rare (a start, a timeout, a
    /// reversal): one copy, out of line.
    #[inline(never)]
    fn restart_at(&mut self, t: u32) {
        self.has_ref = true;
        self.last = t;
        self.latest = t;
        self.prev = 0;
        self.npend = 0;
        self.out_of_band = false;
        self.across = 0;
        self.block_fast();
        self.acq = [0; 3];
        self.forget_fit();
        self.forget_history();
        self.reset_ring();
    }

    #[inline(never)] // careful path: one copy for its callers (code size)
    fn reset_ring(&mut self) {
        self.fill = 0;
        self.pos = 0;
        self.sum = 0;
        self.span = 0;
    }

    /// Pushes the interval `dt` ending at `tooth` into the ring; the sample of the last `K`
    /// intervals once there are `K`.
    #[inline(never)] // careful path: its own routine is less code than inlined (62 bytes)
    fn push<P: PitchTable>(
        &mut self,
        enc: &Encoder,
        table: &P,
        tooth: u16,
        dt: u32,
    ) -> Option<Sample> {
        let k = enc.samples_span();
        if self.fill == 0 {
            // A run of times starts with the first interval's start.
            if let Some(slot) = self.ring.get_mut(self.pos as usize & (MAX_SPAN - 1)) {
                *slot = self.last;
            }
            self.pos = self.pos.wrapping_add(1);
        }
        // Counted on past the counter's wraps (see `last`).
        let time = self.last.wrapping_add(dt);
        let pos = self.pos;
        let oldest = self
            .ring
            .get(pos.wrapping_sub(u32::from(k)) as usize & (MAX_SPAN - 1))
            .copied()
            .unwrap_or(0);
        if let Some(slot) = self.ring.get_mut(pos as usize & (MAX_SPAN - 1)) {
            *slot = time;
        }
        self.pos = pos.wrapping_add(1);
        let uniform = enc.is_uniform() && P::NOMINAL;
        let refresh = tooth & (BAND_REFRESH - 1) == 0;
        if u16::from(self.fill) >= k {
            if !uniform {
                let out = tooth_back(tooth, k, enc.edges());
                self.span = self
                    .span
                    .wrapping_add(self.pitch(enc, table, tooth))
                    .wrapping_sub(self.pitch(enc, table, out));
            }
        } else {
            self.fill = self.fill.saturating_add(1);
            if !uniform {
                self.span = self.span.wrapping_add(self.pitch(enc, table, tooth));
            }
            if u16::from(self.fill) < k {
                return None;
            }
        }
        // The sample starts K times back (at the run's first time when K intervals have just
        // been reached).
        self.sum = time.wrapping_sub(oldest);
        if refresh {
            self.refresh_band(enc);
        }
        self.sample(if uniform {
            enc.uniform_span()
        } else {
            self.span
        })
    }

    /// Takes the leading captures of `caps` that the fast path would take one by one — forward
    /// running on a uniform wheel at its nominal pitches with a 32-bit counter — in tight
    /// loops, and returns how many, with the ticks they span; the extremes of their `K`-edge
    /// samples are folded into `extremes` (slowest and fastest, as tick counts of samples of
    /// equal span). The first capture it stops at (outside the band, or a special tooth next)
    /// is left for the careful path (the fast path declines it), but where the run was cut at
    /// `bulk_max` or where the ring's times wrap round its end (call it again). Identical results: the band test and its refresh points
    /// are the fast path's, and the state it leaves is the one the fast path would.
    ///
    /// Per capture: the interval and its band test, the `K`-edge sample as the difference of
    /// two capture times (exact: `K` intervals within the timeout fit in 32 bits), one range
    /// test for the extremes. The capture times before the batch are the ring's last `K`,
    /// read where they lie (where they wrap round its end, the run stops where they do), and
    /// the ring is written once, at the end, by a copy of fixed size. The loop itself is
    /// [`Run::batch`], out of line so that it keeps its state in registers.
    #[inline(never)]
    pub(crate) fn bulk(
        &mut self,
        enc: &Encoder,
        caps: &[u32],
        extremes: &mut (u32, u32),
    ) -> (usize, u64) {
        if self.stop == self.tooth || !enc.ring_times() || !enc.is_uniform() {
            return (0, 0);
        }
        let room = usize::from(self.stop.wrapping_sub(self.tooth));
        let k = usize::from(enc.samples_span());
        // The ring's last K times, read in one piece where they lie. Where they wrap round
        // its end, the run takes only the captures whose samples start before it (fewer than
        // K): written slot by slot, they bring the last K to the ring's start, where the next
        // call reads them in one piece. (Laying the ring out first, turned in place, was a
        // routine of 102 bytes and its call; laying the last K out whenever they were not at
        // the start, once a revolution, 48 bytes more.)
        let first = self.pos.wrapping_sub(k as u32) as usize & (MAX_SPAN - 1);
        let n = caps.len().min(room).min(enc.bulk_max());
        let mut caps = caps.get(..n).unwrap_or(&[]);
        let head = match self.ring.get(first..first.wrapping_add(k)) {
            Some(head) => head,
            None => {
                let head = self.ring.get(first..).unwrap_or(&[]);
                caps = caps.get(..head.len()).unwrap_or(caps);
                head
            }
        };
        // The batch writes the ring back as its last `m` times laid out from its start: `m`
        // is 16 or 32 (at least K), so that is a copy of fixed size (a few block moves).
        let m = if k <= LAID_SHORT {
            LAID_SHORT
        } else {
            MAX_SPAN
        };
        let last0 = self.last;
        let mut run = Run::new(last0, self.lo, self.width, *extremes);
        // Captures up to and including the next one on a refresh tooth.
        let refresh = usize::from(BAND_REFRESH.wrapping_sub(self.tooth & (BAND_REFRESH - 1)));
        let i = run.batch(enc, caps, head, refresh);
        if i == 0 {
            return (0, 0);
        }
        let from = if i > k {
            caps.get(i.wrapping_sub(1).wrapping_sub(k))
        } else {
            head.get(i.wrapping_sub(1))
        };
        let sum = run.last.wrapping_sub(from.copied().unwrap_or(0));
        // Leave what the fast path would have left: the last `m` times laid out from the
        // ring's start, ready for the next batch.
        let tail = i.checked_sub(m).and_then(|from| caps.get(from..i));
        if let Some(tail) = tail {
            // In copies of 16 times, each a few block moves inline (a longer one would call
            // `memcpy`): the first 16 to the ring's start, the next 16 (`m` = 32) after them.
            let (lo, hi) = self.ring.split_at_mut(LAID_SHORT);
            lay(lo, tail.first_chunk());
            lay(hi, tail.get(LAID_SHORT..).and_then(<[u32]>::first_chunk));
            self.pos = m as u32;
        } else {
            // A short batch (`i` < `m`, rare): its times follow in the ring slot by slot, as
            // the fast path writes them. One masked slot at a time: a plain copy loop would
            // become a call of `memcpy`. Not unrolled: 80 bytes less, for 10 instructions a
            // time instead of about 5.
            let mut pos = self.pos as usize;
            let mut taken = caps.get(..i).unwrap_or(&[]);
            while let Some((&c, rest)) = taken.split_first() {
                if let Some(d) = self.ring.get_mut(pos & (MAX_SPAN - 1)) {
                    *d = c;
                }
                pos = pos.wrapping_add(1);
                // Opaque, so that the loop is not unrolled (code size).
                taken = core::hint::black_box(rest);
            }
            self.pos = pos as u32;
        }
        self.tooth = self.tooth.wrapping_add(i as u16);
        self.last = run.last;
        self.sum = sum;
        self.lo = run.lo;
        self.width = run.width;
        *extremes = run.extremes();
        // At most `bulk_max` intervals within the timeout: their total fits in 32 bits.
        (i, u64::from(run.last.wrapping_sub(last0)))
    }

    /// Sets the band around the mean of the last `K` intervals (when the ring is full; an
    /// empty band otherwise, and near the minimum speed, so nothing but the careful path
    /// takes an edge).
    // Out of line, one copy: the fast path refreshes once every 64 teeth, and inlined there
    // its registers cost on every edge (on_edge 44.52 instructions, out of line 43.61).
    #[inline(never)]
    pub(crate) fn refresh_band(&mut self, enc: &Encoder) {
        let (lo, width) = if u16::from(self.fill) >= enc.samples_span() {
            enc.band(self.sum)
        } else {
            None
        }
        .unwrap_or((u32::MAX, 0));
        self.lo = lo;
        self.width = width;
    }

    /// Teeth are no longer identified. Rare: one copy, out of line.
    #[inline(never)]
    fn lose_sync(&mut self, counted: bool) {
        if self.sync == SyncState::Synced || counted {
            self.counters.sync_losses = self.counters.sync_losses.wrapping_add(1);
        }
        self.sync = SyncState::Searching;
        self.owed = false;
        self.realigned = false;
        self.viable = 0;
        self.confirm = 0;
        self.seen_special = false;
        self.faults = 0;
        self.searched = 0;
        self.block_fast();
        self.forget_fit();
        self.forget_history();
        self.reset_ring();
    }

    /// The intervals kept for [`SpeedTracker::fit_alignment`] no longer follow on.
    fn forget_fit(&mut self) {
        for f in &mut self.fit {
            (f.pos, f.len, f.run) = (0, 0, 0);
        }
    }

    fn forget_history(&mut self) {
        self.hist_teeth = 0;
        self.history = false;
        self.held = None;
    }
}

/// Times a batch lays out from the ring's start when `K` is at most this many (else all of
/// [`MAX_SPAN`]).
const LAID_SHORT: usize = 16;

/// Copies 16 times to the start of `to` (a copy of fixed size, inline), if there are.
#[inline(always)]
fn lay(to: &mut [u32], times: Option<&[u32; LAID_SHORT]>) {
    if let (Some(d), Some(t)) = (to.first_chunk_mut::<LAID_SHORT>(), times) {
        *d = *t;
    }
}

/// The state of a bulk run: the last capture, the band, the extremes.
#[derive(Clone, Copy)]
struct Run {
    last: u32,
    lo: u32,
    width: u32,
    /// The extremes as the fastest sample's ticks and the range up to the slowest's: with
    /// `fastest ≤ slowest`, one modular test `t − fastest ≤ range` says a sample is neither.
    fastest: u32,
    range: u32,
    /// The extremes are the wrong way round (a window that has just started holds `(0,
    /// u32::MAX)`, slower and faster than anything): the first sample sets both.
    fresh: bool,
}

impl Run {
    /// A run from the last capture, the band and the window's extremes `(slowest, fastest)`.
    #[inline(always)]
    fn new(last: u32, lo: u32, width: u32, (slowest, fastest): (u32, u32)) -> Self {
        Run {
            last,
            lo,
            width,
            fastest,
            range: slowest.wrapping_sub(fastest),
            fresh: fastest > slowest,
        }
    }

    /// The extremes `(slowest, fastest)`.
    #[inline(always)]
    fn extremes(&self) -> (u32, u32) {
        (self.fastest.wrapping_add(self.range), self.fastest)
    }

    /// Takes the leading captures of `caps` while their intervals are in the band, the first
    /// `K = head.len()` samples starting at `head`, the others `K` captures back in `caps`,
    /// and refreshes the band after capture `refresh − 1` and every [`BAND_REFRESH`] after it
    /// as the fast path does. Returns how many were taken. Out of line: the run's state stays
    /// in registers through its loop.
    ///
    /// One copy of the loop (four captures a turn) for both kinds of sample start, switching
    /// from the ring's times to the batch's own when they run out: 818 bytes, where a copy
    /// per kind was 1 194. Measured against this form (QEMU, instructions per edge in batches
    /// of 64): the new extreme as a branch (the slowest or the fastest), as the two copies
    /// had it, made the compiler move registers on every capture, +1.3; the loop out of line,
    /// called per stretch, +1.2, or once between refreshes with the switch inside it, +0.28
    /// and 88 bytes more; the first step refreshing the band through the loop's own refresh,
    /// +2.1; no first step (a stretch of its own), +0.9.
    #[inline(never)]
    fn batch(&mut self, enc: &Encoder, caps: &[u32], head: &[u32], mut refresh: usize) -> usize {
        let (n, k) = (caps.len(), head.len());
        let mut start = head;
        // Captures taken (at most `n`: the sums below do not wrap).
        let mut i = 0usize;
        if self.fresh || refresh == 1 {
            // The first sample folded in first: of a window that has just started, it is both
            // extremes (then `fastest ≤ slowest` holds); if the first capture is not taken,
            // nothing of the run is kept.
            let (Some(&c), Some(&s)) = (caps.first(), head.first()) else {
                return 0;
            };
            let t = c.wrapping_sub(s);
            let slowest = self.fastest.wrapping_add(self.range).max(t);
            self.fastest = self.fastest.min(t);
            self.range = slowest.wrapping_sub(self.fastest);
            if refresh == 1 {
                // A batch that starts on a refresh tooth (an aligned DMA half-buffer): its
                // first capture alone, with its own refresh (80 bytes).
                if c.wrapping_sub(self.last).wrapping_sub(self.lo) > self.width {
                    return 0;
                }
                self.last = c;
                (self.lo, self.width) = enc.band(t).unwrap_or((u32::MAX, 0));
                refresh = refresh.wrapping_add(usize::from(BAND_REFRESH));
                i = 1;
                start = head.get(1..).unwrap_or(&[]);
            }
        }
        let (mut lo, mut width) = (self.lo, self.width);
        let (mut last, mut fastest, mut range) = (self.last, self.fastest, self.range);
        // Per capture: the band test, the sample and the range test of the extremes; a new
        // extreme (a fifth of the samples of the bench's stream) without a branch, both
        // extremes recomputed.
        macro_rules! step {
            ($c:expr, $s:expr) => {{
                let c: u32 = $c;
                if c.wrapping_sub(last).wrapping_sub(lo) > width {
                    false
                } else {
                    let t = c.wrapping_sub($s);
                    if t.wrapping_sub(fastest) > range {
                        // A new extreme: the slowest or the fastest.
                        let slowest = fastest.wrapping_add(range).max(t);
                        fastest = fastest.min(t);
                        range = slowest.wrapping_sub(fastest);
                    }
                    last = c;
                    true
                }
            }};
        }
        // The samples start at the ring's times, then (once they are used up) at the batch's
        // own captures, K back: one copy of the loop for both.
        let taken = 'run: loop {
            let end = n.min(refresh);
            let mut now = caps.get(i..end).unwrap_or(&[]);
            while !now.is_empty() {
                if start.is_empty() {
                    start = caps;
                }
                let m = now.len().min(start.len());
                let (mut a, mut b) = (now.get(..m).unwrap_or(&[]), start.get(..m).unwrap_or(&[]));
                (now, start) = (now.get(m..).unwrap_or(&[]), start.get(m..).unwrap_or(&[]));
                // Four captures a turn. Slice patterns, not `chunks_exact` or `zip`: no
                // library precondition to check, in a debug build either.
                while let ([c0, c1, c2, c3, a_rest @ ..], [s0, s1, s2, s3, b_rest @ ..]) = (a, b) {
                    let here = end.wrapping_sub(now.len()).wrapping_sub(a.len());
                    if !step!(*c0, *s0) {
                        break 'run here;
                    }
                    if !step!(*c1, *s1) {
                        break 'run here.wrapping_add(1);
                    }
                    if !step!(*c2, *s2) {
                        break 'run here.wrapping_add(2);
                    }
                    if !step!(*c3, *s3) {
                        break 'run here.wrapping_add(3);
                    }
                    (a, b) = (a_rest, b_rest);
                }
                while let ([c, a_rest @ ..], [s, b_rest @ ..]) = (a, b) {
                    if !step!(*c, *s) {
                        break 'run end.wrapping_sub(now.len()).wrapping_sub(a.len());
                    }
                    (a, b) = (a_rest, b_rest);
                }
            }
            i = end;
            if i == refresh {
                // The fast path's refresh after this tooth: around the mean of the last K (`i`
                // = `refresh` ≥ 1).
                let from = if i > k {
                    caps.get(i.wrapping_sub(1).wrapping_sub(k))
                } else {
                    head.get(i.wrapping_sub(1))
                };
                (lo, width) = enc
                    .band(last.wrapping_sub(from.copied().unwrap_or(0)))
                    .unwrap_or((u32::MAX, 0));
                refresh = refresh.wrapping_add(usize::from(BAND_REFRESH));
            }
            if i >= n {
                break i;
            }
        };
        self.last = last;
        self.fastest = fastest;
        self.range = range;
        self.lo = lo;
        self.width = width;
        taken
    }
}

/// Two intervals at least 2^0.75 times the intervals either side are two ordinary pitches, not
/// one split by an extra tooth; squared, 2^1.5.
#[cfg(feature = "pattern-wheels")]
const NOT_A_PAIR_SQ: f32 = 2.828_427;

/// Evidence thresholds of pattern acquisition, from the wheel's pitches: an interval at least
/// `long`× both neighbours is a long pitch, at most `not_long`× both is not one, at most
/// `short`× the larger neighbour is a short pitch. With `R` the smallest long pitch over the
/// base: `long = R^0.75` (1.68 for one missing tooth, above the 1.6 compression swing of a
/// cranking 8-1 wheel), `not_long = R^0.25` (a gap seen through a swing of R^0.75 still
/// exceeds it); with `S` the largest short pitch over the base, `short = S^0.75` (0.59 for an
/// extra tooth halving a pitch, below the 0.63 of a 1.6 swing).
#[cfg(feature = "pattern-wheels")]
fn acquisition_thresholds(enc: &Encoder) -> (f32, f32, f32) {
    let base = enc.base_pitch() as f32;
    let (long, short) = enc.extreme_pitches();
    let r_long = if long < u8::MAX {
        f32::from(long) / base
    } else {
        f32::INFINITY
    };
    let r_short = f32::from(short) / base;
    let pow = |x: f32, e: f32| {
        if x > 0.0 && x.is_finite() {
            exp(e * ln(x))
        } else {
            x
        }
    };
    (pow(r_long, 0.75), pow(r_long, 0.25), pow(r_short, 0.75))
}

/// e^x for small |x| (a few units): range-reduced series. Configuration and acquisition only.
#[cfg(feature = "pattern-wheels")]
fn exp(x: f32) -> f32 {
    let n = (x / core::f32::consts::LN_2) as i32;
    let r = x - n as f32 * core::f32::consts::LN_2;
    let mut term = 1.0f32;
    let mut sum = 1.0f32;
    for i in 1..10 {
        term *= r / i as f32;
        sum += term;
    }
    let mut scale = 1.0f32;
    if n >= 0 {
        for _ in 0..n.min(60) {
            scale *= 2.0;
        }
    } else {
        for _ in 0..n.unsigned_abs().min(60) {
            scale *= 0.5;
        }
    }
    sum * scale
}

/// Whether a wheel's acquisition weighs whole revolutions of intervals (and its count in sync
/// is checked against them): 6 to 16 teeth, gaps and no extra tooth (never without pattern
/// wheels).
fn fit_kept(enc: &Encoder) -> bool {
    cfg!(feature = "pattern-wheels")
        && matches!(enc.framing(), Framing::Pattern)
        && (FIT_MIN_TEETH..=FIT_TEETH as u16).contains(&enc.edges())
        && enc.short_teeth() == 0
        && enc.long_teeth() != 0
}

/// `a` turned by `b` (complex numbers as (re, im)).
#[cfg(feature = "pattern-wheels")]
fn rotate(a: (f32, f32), b: (f32, f32)) -> (f32, f32) {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}

/// The dot product of two slices (as far as the shorter goes).
#[cfg(feature = "pattern-wheels")]
fn dot(a: &[f32], b: &[f32]) -> f32 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// The largest harmonic amplitude (log speed) of a profile fitted on `m` orthonormal columns
/// with coefficients `g`, `tri` the profile's columns on them: the constant, then the cos and
/// sin of each order (solved from the last column back).
#[cfg(feature = "pattern-wheels")]
fn amplitude(tri: &[[f32; 5]; 5], g: [f32; 5], m: usize) -> f32 {
    let mut beta = [0.0f32; 5];
    for c in (0..m.min(5)).rev() {
        let mut v = g.get(c).copied().unwrap_or(0.0);
        for (row, b) in tri.iter().zip(beta.iter()).skip(c.wrapping_add(1)).take(m) {
            v -= row.get(c).copied().unwrap_or(0.0) * b;
        }
        let diag = tri
            .get(c)
            .and_then(|row| row.get(c))
            .copied()
            .unwrap_or(0.0);
        if let Some(b) = beta.get_mut(c) {
            *b = if diag > 0.0 { v / diag } else { 0.0 };
        }
    }
    let [_, c1, s1, c2, s2] = beta;
    let (a1, a2) = (c1 * c1 + s1 * s1, c2 * c2 + s2 * s2);
    libm::sqrtf(if a1 > a2 { a1 } else { a2 })
}

/// Calls `f` on the pairs of `a` and `b` in turn, as far as the shorter goes: `zip` by slice
/// patterns. (A `zip` of two slices checks a library precondition in a debug build, with a
/// panic branch, when it is not inlined.)
#[inline(always)]
pub(crate) fn each_pair<A, B>(mut a: &mut [A], mut b: &[B], mut f: impl FnMut(&mut A, &B)) {
    while let ([x, a_rest @ ..], [y, b_rest @ ..]) = (a, b) {
        f(x, y);
        (a, b) = (a_rest, b_rest);
    }
}

/// Calls `f` with the number of every set bit of `bits`, lowest first. A loop of a count the
/// compiler does not know, which it keeps one turn long: the loops over the few waiting index
/// pulses (careful path) would otherwise be unrolled, at several times the code.
#[inline(always)]
fn each_bit(mut bits: u8, mut f: impl FnMut(usize)) {
    while bits != 0 {
        f(bits.trailing_zeros() as usize);
        bits &= bits.wrapping_sub(1);
    }
}

/// Whether an index numbered `index_seq` (the arrivals before it) was reported before the
/// edge numbered `edge_seq` arrived.
#[inline]
fn reported_before(index_seq: u32, edge_seq: u32) -> bool {
    (edge_seq.wrapping_sub(index_seq) as i32) > 0
}

/// `bits` rotated left by one within `n` bits (nothing left of them for `n` = 0).
#[cfg(feature = "pattern-wheels")]
fn rotate_left(bits: u64, n: u16) -> u64 {
    if n >= 64 {
        bits.rotate_left(1)
    } else {
        let n = u32::from(n);
        let top = bits.checked_shr(n.wrapping_sub(1)).unwrap_or(0) & 1;
        ((bits << 1) | top) & 1u64.checked_shl(n).map_or(u64::MAX, |b| b.wrapping_sub(1))
    }
}

/// The teeth of a wheel of `edges` teeth as a divisor (one for a wheel without teeth).
#[inline(always)]
fn wheel(edges: u16) -> NonZeroU32 {
    NonZeroU32::new(u32::from(edges)).unwrap_or(NonZeroU32::MIN)
}

/// The tooth `n` after `tooth` on a wheel of `edges` teeth.
#[inline(always)]
fn tooth_after(tooth: u16, n: u16, edges: u16) -> u16 {
    // Two u16 in a u32: the sum does not wrap.
    let s = u32::from(tooth).wrapping_add(u32::from(n));
    (s % wheel(edges)) as u16
}

/// The tooth `n` before `tooth` on a wheel of `edges` teeth.
#[inline(always)]
fn tooth_back(tooth: u16, n: u16, edges: u16) -> u16 {
    let e = wheel(edges);
    // `n mod e` < e ≤ tooth + e: no wrap.
    let s = (u32::from(tooth).wrapping_add(e.get())).wrapping_sub(u32::from(n) % e);
    (s % e) as u16
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`Run::batch`] against a capture-by-capture reference (the fast path's rules written
    /// plainly: band test, sample, `max`/`min` of the extremes, band refresh after every
    /// refresh tooth), on random batches: extremes from a window that has just started, equal,
    /// or at the ends of the range, bands that stop the run anywhere, refreshes anywhere.
    #[test]
    fn a_bulk_run_takes_what_capture_by_capture_takes() {
        let enc = Encoder::new(crate::encoder::EncoderConfig::indexed(1024, 84e6)).unwrap();
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move |m: u32| {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 16) as u32 % m
        };
        for _ in 0..20_000 {
            let most = if next(4) == 0 { 200 } else { 70 };
            let n = next(most) as usize;
            let k = 1 + next(32) as usize;
            let dt = 1 + next(4000);
            let jitter = next(3) * next(dt / 2 + 1);
            let mut t = next(u32::MAX);
            let mut times = Vec::new();
            for _ in 0..k + n {
                t = t
                    .wrapping_add(dt)
                    .wrapping_add(next(jitter + 1))
                    .wrapping_sub(jitter / 2);
                times.push(t);
            }
            let (head, caps) = times.split_at(k);
            let last = *head.last().unwrap();
            let (lo, width) = enc.band(dt.wrapping_mul(k as u32)).unwrap_or((u32::MAX, 0));
            let (lo, width) = match next(8) {
                0 => (lo.wrapping_add(next(50)), width.saturating_sub(next(50))),
                1 => (u32::MAX, 0),
                _ => (lo, width),
            };
            let extremes = match next(7) {
                0 => (0, u32::MAX),
                6 => {
                    let a = next(u32::MAX);
                    (a, next(u32::MAX))
                }
                1 => (0, 0),
                2 => (u32::MAX, 0),
                3 => {
                    let x = next(u32::MAX);
                    (x, x)
                }
                _ => {
                    let a = dt.wrapping_mul(k as u32);
                    let b = a.wrapping_sub(next(jitter * 4 + 1));
                    (a.max(b), a.min(b))
                }
            };
            let refresh = 1 + next(64) as usize;

            // The reference.
            let (mut r_last, mut r_lo, mut r_width) = (last, lo, width);
            let (mut slowest, mut fastest) = extremes;
            let (mut taken, mut r_refresh) = (0, refresh);
            for (j, &c) in caps.iter().enumerate() {
                let start = if j < k { head[j] } else { caps[j - k] };
                if c.wrapping_sub(r_last).wrapping_sub(r_lo) > r_width {
                    break;
                }
                let sample = c.wrapping_sub(start);
                slowest = slowest.max(sample);
                fastest = fastest.min(sample);
                r_last = c;
                taken += 1;
                if taken == r_refresh {
                    (r_lo, r_width) = enc.band(sample).unwrap_or((u32::MAX, 0));
                    r_refresh += usize::from(BAND_REFRESH);
                }
            }

            let mut run = Run::new(last, lo, width, extremes);
            let got = run.batch(&enc, caps, head, refresh);
            let case = (n, k, dt, jitter, lo, width, extremes, refresh);
            assert_eq!(got, taken, "{case:?}");
            assert_eq!(run.last, r_last, "{case:?}");
            assert_eq!((run.lo, run.width), (r_lo, r_width), "{case:?}");
            if taken > 0 {
                assert_eq!(run.extremes(), (slowest, fastest), "{case:?}");
            }
        }
    }

    #[test]
    fn log_is_accurate_enough_to_judge_swings() {
        for &x in &[1e-3f32, 0.1, 0.45, 0.5, 1.0, 1.45, 2.0, 3.0, 1e4] {
            assert!((ln(x) - x.ln()).abs() < 2e-4, "{x}");
        }
        assert!((exp(0.5) - 0.5f32.exp()).abs() < 1e-5);
        assert!((exp(-2.3) - (-2.3f32).exp()).abs() < 1e-5);
    }

    #[test]
    fn rotation_and_tooth_arithmetic_wrap() {
        assert_eq!(rotate_left(0b100, 3), 0b001);
        assert_eq!(rotate_left(1 << 63, 64), 1);
        assert_eq!(tooth_after(57, 2, 58), 1);
        assert_eq!(tooth_back(0, 1, 58), 57);
        assert_eq!(tooth_back(3, 60, 58), 1);
    }

    #[test]
    fn quantized_ratios_do_not_look_like_swings() {
        // 2 against 3 ticks may both be 2.5: no swing at all.
        assert_eq!(log_sq(3.0, 2.0), 0.0);
        assert!(log_sq(30.0, 10.0) > 0.9);
    }
}
