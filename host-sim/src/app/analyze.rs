//! `drive-sim analyze`: the core on a recorded capture.
//!
//! A capture file ([`crate::app::logic`]) is read row by row; the edges of the chosen polarity
//! on the encoder channel become capture timestamps as a real input-capture timer would latch
//! them — `⌊t·timer_hz⌋` masked to the counter width — and go to the core's [`DeltaMonitor`]
//! (the code that runs on the target), the edges of the index channel to its `on_index`.
//! Between edges the analyzer polls the monitor as a firmware's periodic task would
//! ([`poll_interval`]), and once at the end of the capture. An [`EdgeSink`] observer records
//! every decision the core takes (a tooth and its number, a glitch, a missing edge...).
//!
//! The report: the windows (where they start and end, δ, validity and fault), the faults with
//! their times, the sync state and when it was acquired or lost, the edges and revolutions
//! counted, and a decimated speed trace for the plot. Memory stays bounded whatever the length
//! of the capture: the speed trace is decimated to at most [`MAX_TRACE`] points, and at most
//! [`MAX_LISTED`] windows and faults are listed (the counters count them all).

use std::collections::VecDeque;
use std::io::BufRead;

use serde::Serialize;

use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator};
use drive_monitor::irregularity::{WindowConfig, WindowReport};
use drive_monitor::monitor::{DeltaMonitor, WindowOutcome};
use drive_monitor::speed::{Direction, EdgeSink, Fault, SyncState, Tooth};

use crate::app::logic::{CaptureError, CaptureFormat, CaptureReader, Level};
use crate::app::run::MAX_LINES;

/// Most windows and faults listed in a report (the counters count them all).
pub const MAX_LISTED: usize = 10_000;
/// Most points of the decimated speed trace.
pub const MAX_TRACE: usize = 20_000;
/// Longest interval between two polls of the monitor, s (a firmware's periodic task; shorter
/// when the counter wraps sooner, see [`poll_interval`]).
pub const POLL_INTERVAL: f64 = 1e-3;

/// Which edges of a channel are the capture unit's events.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum Polarity {
    /// Low to high.
    Rising,
    /// High to low.
    Falling,
}

/// A channel of the capture: by name as the header gives it, or by 0-based column among the
/// channels.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Channel {
    /// The n-th channel column (0 = the first after the time).
    Column(usize),
    /// The channel of this name.
    Name(String),
}

impl std::str::FromStr for Channel {
    type Err = std::convert::Infallible;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Ok(match s.trim().parse::<usize>() {
            Ok(n) => Channel::Column(n),
            Err(_) => Channel::Name(s.trim().to_string()),
        })
    }
}

/// What to analyze and how.
#[derive(Debug, Clone)]
pub struct AnalyzeConfig {
    /// The encoder as the firmware would configure it: wheel, timer clock, counter width,
    /// tolerances, estimator, minimum speed.
    pub encoder: EncoderConfig,
    /// The δ window.
    pub window: WindowConfig,
    /// The encoder channel.
    pub channel: Channel,
    /// The index channel (index discs).
    pub index_channel: Option<Channel>,
    /// Whether the index channel is the default (no `--index-channel` given).
    pub index_channel_default: bool,
    /// The quadrature B channel that gives each edge its direction, and which of A and B
    /// leads when running forward.
    pub direction: Option<(Channel, Lead)>,
    /// The edges taken, as `--edge` gave them; `None`: not given, rising edges taken (a file
    /// of edge times, which has no levels to take an edge of, refuses one given). See
    /// [`AnalyzeConfig::polarity`].
    pub edge: Option<Polarity>,
    /// What the configuration leaves out, each a WARNING (a window that does not hold the
    /// scene's load cycle).
    pub warnings: Vec<String>,
    /// The disc of `--lines` is unframed because `--framing` was not given (the report says
    /// so, and names a channel that pulses once a revolution).
    pub framing_default: bool,
}

impl AnalyzeConfig {
    /// The edges taken: `--edge`'s, rising by default.
    pub fn polarity(&self) -> Polarity {
        self.edge.unwrap_or(Polarity::Rising)
    }
}

/// Which channel of a quadrature pair leads when the shaft runs forward.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum Lead {
    /// A (the encoder channel) leads B by a quarter pitch: B is low at A's rising edge.
    ALeads,
    /// B leads A: B is high at A's rising edge.
    BLeads,
}

impl Lead {
    /// The direction of an edge of A to level `a`, with B at level `b`.
    fn direction(self, a: bool, b: bool) -> Direction {
        // A leading B: B still holds A's previous level when A changes.
        if (a != b) == (self == Lead::ALeads) {
            Direction::Forward
        } else {
            Direction::Reverse
        }
    }
}

/// A ×4 quadrature count of A (the encoder channel) and B (the direction channel).
#[derive(Debug, Default)]
struct Quadrature {
    count: i64,
    at_capture: i64,
}

impl Quadrature {
    /// Counts the step from levels `from` to `to` of A and B: one forward or backward,
    /// none where both changed within a sample or a level is unknown.
    fn step(&mut self, lead: Lead, from: [Level; 2], to: [Level; 2]) {
        // The place of a pair of levels along a forward cycle.
        let place = |[a, b]: [Level; 2]| -> Option<i64> {
            let (a, b) = match (a, b) {
                (Level::Unknown, _) | (_, Level::Unknown) => return None,
                (a, b) => (a == Level::High, b == Level::High),
            };
            let (a, b) = if lead == Lead::ALeads { (a, b) } else { (b, a) };
            Some(match (a, b) {
                (false, false) => 0,
                (true, false) => 1,
                (true, true) => 2,
                (false, true) => 3,
            })
        };
        if let (Some(x), Some(y)) = (place(from), place(to)) {
            match (y - x).rem_euclid(4) {
                1 => self.count += 1,
                3 => self.count -= 1,
                _ => {}
            }
        }
    }

    /// The steps the count moved since the last capture (this one now the last): 4 a pitch
    /// forward, −4 a pitch backward, about 0 across a line edge and back.
    fn since_capture(&mut self) -> i64 {
        let steps = self.count - self.at_capture;
        self.at_capture = self.count;
        steps
    }
}

/// A decision of the core on one edge, with its capture time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Decision {
    /// Capture time, s.
    pub time: f64,
    /// What the core decided.
    pub kind: DecisionKind,
}

/// What the core decided about an edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum DecisionKind {
    /// Accepted as a tooth.
    Tooth {
        /// Tooth number within the revolution (meaningful when `synced`).
        tooth: u16,
        /// The teeth were identified.
        synced: bool,
        /// Tooth 0 of a revolution counted in sync.
        frame: bool,
        /// The speed sample ending here, rad/s.
        speed: Option<f64>,
    },
    /// A fault (a rejected glitch, a missing edge, a timeout...).
    Fault(Fault),
}

/// One δ window.
#[derive(Debug, Clone, Serialize)]
pub struct WindowOut {
    /// Capture time of its first edge, s.
    pub start: f64,
    /// Capture time of its last edge (or of the fault that ended it), s.
    pub end: f64,
    /// Accepted-edge numbers it spans.
    pub start_edge: u32,
    /// Last accepted edge in it.
    pub end_edge: u32,
    /// Whole revolutions covered.
    pub revolutions: u16,
    /// Complete and without fault.
    pub valid: bool,
    /// Why not, when invalid.
    pub fault: Option<&'static str>,
    /// δ (valid windows).
    pub delta: Option<f64>,
    /// Mean speed, rad/s.
    pub omega_mean: Option<f64>,
    /// Largest and smallest speed sample, rad/s.
    pub omega_max: Option<f64>,
    /// Smallest speed sample, rad/s.
    pub omega_min: Option<f64>,
    /// Bound on δ's error from timer quantization.
    pub noise_floor: Option<f64>,
    /// The bound with the capture's sampling added (when its sample rate is known, or the
    /// grid its times lie on): each timestamp is known to a sample period besides the timer's
    /// tick, so the floor is `noise_floor · (1 + timer_hz / sample_rate)`.
    pub floor_with_sampling: Option<f64>,
    /// The resolution of the times, s, that `floor_with_sampling` takes: the sample period
    /// (stated, or the grid of the whole file) or, where coarser, the coarsest of the
    /// window's rows (each block of [`BLOCK_ROWS`] rows: the step its times lie on, or the
    /// spacing of f64 numbers at them and at their products with the timer clock).
    pub time_resolution: Option<f64>,
    /// The mean speed was within the steady tolerance (2 % unless the scene says otherwise)
    /// of the previous valid window's (valid windows; never the first one after sync). δ of
    /// a window that is not steady includes the change of speed (a run-up or run-down).
    pub steady: Option<bool>,
    /// δ exceeds the floor given (`floor_with_sampling` when there is one, else
    /// `noise_floor`; valid windows): otherwise δ is not resolved from the quantization and
    /// its value is no measurement of the ripple, only a bound on it.
    pub resolved: Option<bool>,
    /// One edge of the window (or of its first samples) lies off the line of its neighbours
    /// by enough to make half the window's δ or more by itself (valid windows): δ is then
    /// that edge's, not the shaft's (`DisplacedEdges` in the module's source).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub displaced_edge: Option<DisplacedEdge>,
}

/// How far the edges lie off the cubic through their neighbours ([`AnalyzeReport::edge_scatter`]):
/// a sensor's or comparator's timing jitter, or the shaft's own speed changes from tooth to
/// tooth, which the edges cannot tell apart.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct EdgeScatter {
    /// The timing jitter that would give it, standard deviation in pitches.
    pub pitches: f64,
    /// About the most δ such jitter reads in a window of the capture's K-edge samples.
    pub delta: f64,
    /// The windows' median noise floor, for comparison.
    pub floor: f64,
}

/// An edge off the line of its neighbours ([`WindowOut::displaced_edge`]).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct DisplacedEdge {
    /// Its capture time, s.
    pub time: f64,
    /// How far off, in pitches (0.3: a tooth's edge 30 % of a pitch early or late).
    pub pitches: f64,
}

/// The valid windows whose δ an edge off its neighbours' line can make by itself
/// ([`AnalyzeReport::displaced_edges`]).
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct DisplacedWindows {
    /// How many of the listed windows.
    pub windows: u64,
    /// The first such edge's time, s.
    pub first: f64,
    /// The largest displacement, pitches.
    pub largest: f64,
}

/// A fault with its time.
#[derive(Debug, Clone, Serialize)]
pub struct FaultOut {
    /// Capture time, s.
    pub time: f64,
    /// What (`glitch`, `missing-edge`, `extra-edge`, `missing-frame`, `reversal`, `timeout`).
    pub fault: &'static str,
}

/// A change of the sync state.
#[derive(Debug, Clone, Serialize)]
pub struct SyncOut {
    /// Capture time of the edge after which the state changed, s.
    pub time: f64,
    /// The new state: `searching`, `confirming` or `synced`.
    pub state: &'static str,
}

/// Encoder captures between consecutive index pulses, against the revolution the
/// configuration expects: a disc with another number of lines than configured never syncs.
#[derive(Debug, Clone, Copy, Serialize, PartialEq, Eq)]
pub struct IndexPeriod {
    /// The most common number of captures from one index pulse to the next.
    pub captures: u64,
    /// How many of the intervals between index pulses had that many.
    pub times: u64,
    /// Intervals between index pulses.
    pub of: u64,
    /// Captures per revolution of the configured wheel.
    pub expected: u16,
    /// How many intervals between index pulses had one capture fewer and one more than
    /// `expected`: both in numbers, an index pulse at a line edge, jittering to either side.
    pub early_late: (u64, u64),
}

/// Whether the index pulses fall to either side of a line edge: intervals between them a
/// capture short and a capture long of a revolution, twice each or more, a tenth of them or
/// more, and about as many of each (an index jittering across a line edge makes them in
/// turn, so their numbers differ by one at most; a lost or extra line edge makes one of the
/// two alone).
fn index_at_a_line_edge(p: &IndexPeriod) -> bool {
    let (early, late) = p.early_late;
    early >= 2
        && late >= 2
        && (early + late) * 10 >= p.of
        && early.abs_diff(late) <= 1 + (early + late) / 5
}

/// How much of a speed ripple's δ the windows read: a ripple of `order` cycles a revolution,
/// read at `min` to `max` of its δ depending on its phase against the teeth.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct RippleReading {
    /// Cycles a revolution.
    pub order: u32,
    /// The least of its δ read, over the ripple's phase.
    pub min: f64,
    /// The most of its δ read, over the ripple's phase.
    pub max: f64,
}

/// Ripple orders [`ripple_readings`] reports.
pub const RIPPLE_ORDERS: u32 = 12;

/// The angles (radians from the frame) of the edges the core samples a revolution of `enc`'s
/// wheel at: a pattern's present teeth, or a disc's lines, one in `prescaler`.
fn edge_angles(enc: &EncoderConfig) -> Vec<f64> {
    use drive_monitor::encoder::Wheel;
    use std::f64::consts::TAU;
    match enc.wheel {
        Wheel::Indexed { lines } | Wheel::Unframed { lines } => {
            let step = u16::from(enc.prescaler.max(1));
            (0..lines / step)
                .map(|k| TAU * f64::from(k * step) / f64::from(lines))
                .collect()
        }
        Wheel::Pattern(p) => {
            let n = u32::from(p.positions());
            (0..n)
                .filter(|&k| p.present() >> k & 1 == 1)
                .map(|k| TAU * f64::from(k) / f64::from(n))
                .collect()
        }
    }
}

/// The mean of sin(order·φ + ψ) over each speed sample's angle, as `(c, d)` with the mean
/// `c·cos ψ + d·sin ψ`: each sample is the angle of the last `K` edges over their time, so to
/// first order in a ripple's amplitude it reads the ripple's mean over that angle. Empty where
/// the wheel has fewer sampled edges than `K`.
fn sample_means(enc: &EncoderConfig, order: u32) -> Vec<(f64, f64)> {
    use drive_monitor::encoder::Estimator;
    use std::f64::consts::TAU;
    let angles = edge_angles(enc);
    let n = angles.len();
    let Estimator::Edges(k) = enc.estimator;
    let k = usize::from(k).max(1);
    if n == 0 || k > n {
        return Vec::new();
    }
    let z = f64::from(order);
    (0..n)
        .map(|j| {
            // The sample ending at edge j, from edge j − K (a revolution back where it wraps).
            let end = angles[j];
            let start = if j >= k {
                angles[j - k]
            } else {
                angles[j + n - k] - TAU
            };
            // (cos(zs + ψ) − cos(ze + ψ)) / (z(e − s)), split over cos ψ and sin ψ.
            let w = z * (end - start);
            let ((ss, cs), (se, ce)) = ((z * start).sin_cos(), (z * end).sin_cos());
            ((cs - ce) / w, (se - ss) / w)
        })
        .collect()
}

/// Half the spread of the samples' means at ripple phase `phase`: the share of the ripple's
/// δ they read.
fn spread_at(means: &[(f64, f64)], phase: f64) -> f64 {
    let (sin, cos) = phase.sin_cos();
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &(c, d) in means {
        let s = c * cos + d * sin;
        lo = lo.min(s);
        hi = hi.max(s);
    }
    if means.is_empty() {
        0.0
    } else {
        (hi - lo) / 2.0
    }
}

/// The share of the δ of a small speed ripple ω̄(1 + a·sin(order·φ + phase)) that the core's
/// windows read on `enc`'s wheel: each speed sample is the angle of the last `K` edges over
/// their time, which to first order in `a` is ω̄(1 + a·s) with `s` the mean of the sine over
/// the sample's angle; a window holds the samples ending at each edge of its revolutions, so
/// it reads δ = a·(max s − min s) of the true 2a. Samples few against the ripple's cycle miss
/// its peaks, and long ones average it away.
pub fn ripple_reading(enc: &EncoderConfig, order: u32, phase: f64) -> f64 {
    spread_at(&sample_means(enc, order), phase)
}

/// [`ripple_reading`] for orders 1 to [`RIPPLE_ORDERS`], each at its least and most over 360
/// phases (the samples' means worked out once an order: a phase costs two multiplies a
/// sample, no trigonometry).
pub fn ripple_readings(enc: &EncoderConfig) -> Vec<RippleReading> {
    (1..=RIPPLE_ORDERS)
        .map(|order| {
            let means = sample_means(enc, order);
            let (mut min, mut max) = (f64::INFINITY, 0.0f64);
            for i in 0..360 {
                let r = spread_at(&means, std::f64::consts::TAU * f64::from(i) / 360.0);
                min = min.min(r);
                max = max.max(r);
            }
            RippleReading { order, min, max }
        })
        .collect()
}

/// Counts the captures between index pulses (at most [`MAX_PERIODS`] distinct counts kept).
#[derive(Default)]
struct IndexPeriods {
    since: Option<u64>,
    counts: std::collections::BTreeMap<u64, u64>,
    of: u64,
}

/// Most distinct capture counts between index pulses kept (memory bounded).
const MAX_PERIODS: usize = 1024;

impl IndexPeriods {
    fn index(&mut self) {
        if let Some(n) = self.since {
            self.of += 1;
            if self.counts.len() < MAX_PERIODS || self.counts.contains_key(&n) {
                *self.counts.entry(n).or_insert(0) += 1;
            }
        }
        self.since = Some(0);
    }

    fn capture(&mut self) {
        if let Some(n) = &mut self.since {
            *n += 1;
        }
    }

    /// The most common count (the smallest of equally common ones).
    fn period(&self, expected: u16) -> Option<IndexPeriod> {
        let mut best: Option<(u64, u64)> = None;
        for (&captures, &times) in &self.counts {
            if best.is_none_or(|(_, t)| times > t) {
                best = Some((captures, times));
            }
        }
        let times_of = |n: u64| self.counts.get(&n).copied().unwrap_or(0);
        let n = u64::from(expected);
        best.map(|(captures, times)| IndexPeriod {
            captures,
            times,
            of: self.of,
            expected,
            early_late: (times_of(n.saturating_sub(1)), times_of(n + 1)),
        })
    }
}

/// A channel of the capture and how often its level changed.
#[derive(Debug, Clone, Serialize, PartialEq, Eq)]
pub struct ChannelChanges {
    /// The channel's name in the header.
    pub name: String,
    /// Level changes (0 to 1 or 1 to 0; not to or from an unknown `X`).
    pub changes: u64,
}

/// What the core found in a capture.
#[derive(Debug, Clone, Serialize, Default)]
pub struct AnalyzeReport {
    /// The capture file.
    pub file: String,
    /// Its format.
    pub format: &'static str,
    /// The channel analyzed and the index channel.
    pub channel: String,
    /// The index channel, if any.
    pub index_channel: Option<String>,
    /// The quadrature B channel giving the direction of each edge, if any.
    pub direction_channel: Option<String>,
    /// Which of A and B leads running forward (with a direction channel).
    pub forward: Option<Lead>,
    /// Edges fed without a direction: B changed in the same sample as A (the capture sampled
    /// too slowly to resolve the quadrature) or was unknown (`X`).
    pub direction_unknown: u64,
    /// The edges taken: `rising` or `falling`; `listed` for a file of edge times (each row
    /// one captured edge).
    pub edge: &'static str,
    /// The wheel, as the core frames it (e.g. `pattern 36 positions, 34 teeth`).
    pub wheel: String,
    /// When `--lines` was given without `--framing`: that the disc was taken as unframed, and
    /// a channel not read that pulses once every revolution of edges (an index channel).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub framing_note: Option<String>,
    /// Emulated capture timer clock, Hz.
    pub timer_hz: f64,
    /// Emulated counter width, bits.
    pub counter_bits: u8,
    /// The capture's sample rate, Hz, when known (a sigrok file's, or `--sample-rate`).
    pub sample_rate: Option<f64>,
    /// A Saleae Logic 1.x export with sample numbers for times: the column's heading (every
    /// time is its sample number over `sample_rate`, the rate `--sample-rate` gave).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub sample_numbers: Option<String>,
    /// The threshold the values of an analog record were read through (`--threshold`,
    /// `--hysteresis`), when they were.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub threshold: Option<crate::app::logic::Threshold>,
    /// Without a known sample rate: the step, s, that every row's time lies on from the first
    /// row's (in whole nanoseconds, when 2 ns or more: the analyzer's sample period, as a
    /// Saleae export's nine decimals show it), taken as the sampling for the floor.
    pub time_grid: Option<f64>,
    /// The coarsest resolution of the times in a block of rows, s, where it is coarser than
    /// the sampling above (half again, and at least 0.1 timer tick), and the time of the first
    /// block so coarse: a file written to a fixed number of significant digits resolves its later times
    /// less finely, and an f64 resolves times far from their origin only so far (see
    /// [`WindowOut::time_resolution`]).
    pub coarser_times: Option<(f64, f64)>,
    /// When `time_grid` is a whole multiple of the period of one of [`ODD_RATES`] (a period
    /// not whole nanoseconds), found to the precision the times are written to.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub grid_of_rate: Option<RateGridFound>,
    /// When every transition's time, as written, lies on a power-of-two grid of seconds
    /// coarser than the precision it is written to: the times were held as floats (an f64
    /// near a Unix time resolves 2^-22 s), and the floor includes that grid.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub float_grid: Option<FloatSpacing>,
    /// When every transition's time, as written, is a value of one float type at its own
    /// magnitude (an f32 resolves 2^-24 of it) and the times span magnitudes where that
    /// spacing differs, so no one grid holds them (f32 times from 0 s): each window's floor
    /// includes the spacing at its latest time.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub float_times: Option<FloatTimes>,
    /// The resolution of the times the floor takes from the file as a whole, s: the sample
    /// period (stated, or the grid found) with the digits' rounding of each time, or the
    /// grid of the floats the times were held in (before each window's own rows).
    pub sampling_resolution: Option<f64>,
    /// When `time_grid` is the precision the times are written to: what sampling it may
    /// hide, and the resolution the floor takes.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub digits_grid: Option<DigitsGrid>,
    /// What the configuration leaves out, each a WARNING ([`AnalyzeConfig::warnings`]).
    pub warnings: Vec<String>,
    /// The unit the file's times are read in (`s`, `ms`, `us`, `ns`: its header's, or
    /// `--time-unit`'s).
    pub time_unit: &'static str,
    /// Whether the file or `--time-unit` states that unit (a file of edge times or a plain CSV
    /// without either is read in seconds, and a speed implausibly slow is said to be what
    /// times in ms or µs read as seconds give).
    pub time_unit_stated: bool,
    /// The smallest and largest value of the channel read, where it is read through
    /// `--threshold`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub values: Option<[f64; 2]>,
    /// The channel read changing level twice at one time stamp (a pulse of no width as
    /// written), where it does.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub same_stamp: Option<SameStamp>,
    /// Rows read.
    pub rows: u64,
    /// First and last time in the capture, s, counted from `time_origin`.
    pub span: [f64; 2],
    /// Whole seconds subtracted, exactly, from every time the file writes (the first time's,
    /// when it is 10 000 s or more, such as a Unix time; else 0): every time reported is
    /// counted from it.
    pub time_origin: i64,
    /// Edges of the chosen polarity on the encoder channel.
    pub edges: u64,
    /// Of them, those captured and fed to the core: one in `prescaler` (all without one).
    pub captured: u64,
    /// Captures at the same timer tick as the one before, at a later time: the timer is too
    /// slow to resolve the edges (the report warns).
    pub captures_at_one_tick: u64,
    /// Captures whose time, as the file writes it, is the one before's (0 s apart, which no
    /// timer resolves): a duplicated row, or times written more coarsely than the edges came
    /// (the report warns, naming the first line).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub repeated_times: Option<RepeatedTimes>,
    /// Where the channel read had no data (a Saleae `X`, a VCD `x` or `z`): how many spans,
    /// their time in all, s, and the first `[from, to]` (the report warns: edges there were
    /// not seen, and the faults there are the capture's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub no_data: Option<NoData>,
    /// Edges of the channel read that came just after the edge before, as a transition that
    /// rings or bounces gives them (the report warns: each is a glitch to the core, and a
    /// window holding one is invalid).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ringing: Option<Ringing>,
    /// The channel's edges of the polarity NOT read ring (and those read do not): each such
    /// transition crosses back, an edge of the polarity read, so the edges read hold one
    /// crossing a transition besides the teeth, a clean pulse train at up to twice the speed
    /// (the report warns: its windows can be valid and wrong). `of` counts that polarity's
    /// edges.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub ringing_other_polarity: Option<Ringing>,
    /// The edges' scatter about the cubic through their neighbours, where what it can read
    /// as δ is more than twice the windows' median floor (the report notes it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub edge_scatter: Option<EdgeScatter>,
    /// Valid windows whose δ one edge off the line of its neighbours makes by itself (half
    /// of it or more: [`WindowOut::displaced_edge`]); the report warns.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub displaced_edges: Option<DisplacedWindows>,
    /// The emulated capture's input prescaler: one capture every this many edges.
    pub prescaler: u8,
    /// Edges on the index channel (fed to the core).
    pub index_pulses: u64,
    /// Edges the core accepted as teeth.
    pub accepted: u32,
    /// Revolutions counted in sync.
    pub revolutions: u32,
    /// Revolutions a window spans (`--window-revolutions`, or the scene's).
    pub window_revolutions: u16,
    /// Faults by kind: glitches, missing edges, extra edges, missing frames, reversals,
    /// timeouts, unexplained edges.
    pub glitches: u32,
    /// Missing edges.
    pub missing: u32,
    /// Extra edges.
    pub extra: u32,
    /// Missing frames.
    pub missing_frames: u32,
    /// Reversals.
    pub reversals: u32,
    /// Timeouts.
    pub timeouts: u32,
    /// Edges taken as teeth that no judgement explained (two faults close together, most
    /// likely).
    pub unexplained: u32,
    /// Times the frame was found and confirmed, and lost.
    pub syncs: u32,
    /// Times sync was lost.
    pub sync_losses: u32,
    /// Edges captured after sync was first acquired while it was not held (the count searched
    /// or confirmed again after a sync loss): the core judges no fault among them.
    pub edges_unsynced: u64,
    /// When sync was first acquired, s.
    pub sync_acquired: Option<f64>,
    /// The sync state at the end.
    pub sync_state: &'static str,
    /// How many encoder captures came between consecutive index pulses (with an index
    /// channel and at least two pulses).
    pub index_period: Option<IndexPeriod>,
    /// How much of a speed ripple's δ the windows read, by its order (see
    /// [`ripple_reading`]): few samples a revolution read high orders low.
    pub ripple: Vec<RippleReading>,
    /// Why sync was never acquired (or was lost again and again and the capture ended
    /// without it), from the evidence of the capture; `None` when the core synced.
    pub sync_hint: Option<SyncHint>,
    /// Every change of the sync state (at most [`MAX_LISTED`]).
    pub sync: Vec<SyncOut>,
    /// Valid and invalid windows.
    pub valid_windows: u32,
    /// Invalid windows.
    pub invalid_windows: u32,
    /// The windows (at most [`MAX_LISTED`], the first).
    pub windows: Vec<WindowOut>,
    /// The faults (at most [`MAX_LISTED`], the first).
    pub faults: Vec<FaultOut>,
    /// How many windows the capture gave in all, and how many of them `windows` lists.
    pub windows_total: u64,
    /// How many windows `windows` lists (the first; fewer than `windows_total` past the cap).
    pub windows_listed: u64,
    /// How many faults the capture gave in all (each counter above's), and how many `faults`
    /// lists.
    pub faults_total: u64,
    /// How many faults `faults` lists (the first).
    pub faults_listed: u64,
    /// How many changes of the sync state there were in all.
    pub sync_changes_total: u64,
    /// How many changes `sync` lists (the first).
    pub sync_changes_listed: u64,
    /// Edges fed in reverse (with a direction channel): the core takes none as a tooth.
    pub reverse_edges: u64,
    /// Of them, captures with no step forward of the quadrature count (the encoder and
    /// direction channels) since the capture before, itself so, and less than a pitch back
    /// (no pitch: a shaft rocking across a line edge), fed as reverse.
    pub no_pitch: u64,
    /// Of them, captures a pitch or more backward of the capture before (the quadrature count
    /// stepped back by 4 or more): the disc turning the other way, or a `--forward` the wrong
    /// way round for the wiring when it is most of the capture.
    pub backward_pitches: u64,
    /// Edges of A at which B read reverse but pulsed: B changed just before the edge and back
    /// just after, both within an eighth of a pitch (at the speed of the capture before), with
    /// the quadrature count forward since the capture before: a noise pulse on the direction
    /// channel, fed as forward (not counted in `reverse_edges`).
    pub direction_glitches: u64,
    /// Edges fed running forward that were neither taken as teeth nor rejected as glitches:
    /// the last edges of the capture, waiting for the two that would confirm them, and the
    /// first edge after a standstill or a reversal (a time reference only).
    pub unjudged_at_end: u64,
    /// Every channel of the capture and how often its level changed (0 or 1 to 0 or 1).
    pub channel_changes: Vec<ChannelChanges>,
    /// The speed samples against time, decimated (for the plot).
    #[serde(skip)]
    pub speed_trace: Vec<(f64, f64)>,
    /// δ against each window's end, of every `delta_every`-th window of the capture (for the
    /// plot: every window, not only those listed, decimated to at most [`MAX_TRACE`] points).
    #[serde(skip)]
    pub delta_trace: Vec<(f64, f64)>,
    /// The decimation of `delta_trace` (1: every window).
    #[serde(skip)]
    pub delta_every: u64,
}

impl AnalyzeReport {
    /// The capture is a file of edge times: each row a captured edge (`edge` is `listed`).
    pub fn edges_listed(&self) -> bool {
        self.edge == "listed"
    }
}

/// Why the core did not sync, from the capture: each cause the evidence shows, in words, and
/// the evidence.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct SyncHint {
    /// Each cause the evidence shows, in words (or that none of them shows).
    pub causes: Vec<String>,
    /// The long intervals that recur in the capture (a wheel with a pattern).
    pub gaps: Option<GapsSeen>,
    /// Long intervals seen (each more than [`LONG_RATIO`] times both neighbours' geometric
    /// mean).
    pub long_intervals: u64,
    /// The captured edges in revolutions of the configured wheel.
    pub revolutions_of_edges: f64,
    /// Intervals less than [`SHORT_RATIO`] times both neighbours' geometric mean and next to
    /// no long interval (noise pulses split a tooth's interval so).
    pub irregular_intervals: u64,
    /// Intervals between captures longer than the timeout `--min-speed` implies.
    pub beyond_timeout: u64,
    /// The timeout, s.
    pub timeout: f64,
    /// The configured minimum speed, rad/s.
    pub min_speed: f64,
    /// The slowest speed of an interval, rad/s (its pitches read from its ratio to its
    /// neighbours, at most the configured wheel's longest gap).
    pub slowest_speed: Option<f64>,
}

/// Long intervals that recur: how many edges lie between consecutive ones, and how long they
/// are against their neighbours.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct GapsSeen {
    /// The most common number of edges from one long interval to the next.
    pub every: u64,
    /// How many of the spacings had that many.
    pub times: u64,
    /// Spacings between consecutive long intervals.
    pub of: u64,
    /// The median ratio of those long intervals to the geometric mean of their neighbours.
    pub ratio: f64,
    /// Every spacing that recurs about as often as the most common one (a wheel with several
    /// gaps has one a gap), in the order they came round the wheel; the most common alone on a
    /// wheel with one gap.
    pub spacings: Vec<SpacingSeen>,
}

/// One recurring number of edges from one long interval to the next.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct SpacingSeen {
    /// Edges from the long interval before.
    pub every: u64,
    /// How many of the spacings had that many.
    pub times: u64,
    /// The median ratio of the long intervals ending them to their neighbours' geometric mean.
    pub ratio: f64,
}

impl SpacingSeen {
    /// The pitches of the long interval ending it, as its ratio reads them.
    fn pitches(&self) -> u64 {
        self.ratio.round() as u64
    }
}

/// An interval more than this many times the geometric mean of its two neighbours is long (a
/// gap): a 36-1 wheel's is 2, a tooth's on a cranking shaft stays well below.
pub const LONG_RATIO: f64 = 1.5;

/// Displacement, in pitches, above which an edge is kept as a candidate for
/// [`DisplacedEdges`] (a half per cent: with 16-edge samples it alone can make δ 6e-4).
const DISPLACED_CANDIDATE: f64 = 0.005;

/// Candidates [`DisplacedEdges`] keeps (beyond, the signal is rough everywhere and no edge
/// stands out).
const MAX_DISPLACED: usize = 100_000;

/// Edges per block of [`DisplacedEdges`]'s running scatter.
const DISPLACED_BLOCK: u64 = 64;

/// Edges that lie off the line of their neighbours: the edge one capture moved (a noise
/// pulse that merged with a tooth, starting before it, makes its edge early), which the core
/// takes as a tooth (its intervals, (1 − f) and (1 + f) pitches, are in its band) and which
/// makes δ 2·f/K by itself with `K`-edge samples (0.6 for a tooth 30 % early, per edge, on a
/// constant shaft). Each edge's time against the cubic through the two edges either side,
/// `(−t₋₂ + 4·t₋₁ + 4·t₊₁ − t₊₂)/6`, in pitches of their mean spacing: exactly `f` for an
/// edge moved by `f` pitches, and near 0 where the speed changes smoothly from tooth to
/// tooth (the cubic follows it to the fourth order). Edges beside intervals more than 1.9
/// apart (a wheel's gap) are left out. Candidates above [`DISPLACED_CANDIDATE`] are kept with
/// their time, and the mean of every block of [`DISPLACED_BLOCK`] edges, so that each window
/// can be judged at the end.
#[derive(Default)]
struct DisplacedEdges {
    /// The last five capture times, newest last, and how many there are.
    times: [f64; 5],
    have: usize,
    /// (time, displacement in pitches) of the candidates.
    candidates: Vec<(f64, f64)>,
    /// (first time, mean displacement) per block, and the block being summed.
    blocks: Vec<(f64, f64)>,
    block_start: f64,
    block_sum: f64,
    block_n: u64,
}

impl DisplacedEdges {
    /// A reversal or a stop: the intervals before it are no neighbours of those after.
    fn reset(&mut self) {
        self.have = 0;
    }

    /// A forward capture at `t`.
    fn capture(&mut self, t: f64) {
        self.times.rotate_left(1);
        self.times[4] = t;
        self.have = (self.have + 1).min(5);
        if self.have < 5 {
            return;
        }
        let [t0, t1, t2, t3, t4] = self.times;
        let d = [t1 - t0, t2 - t1, t3 - t2, t4 - t3];
        let even = d.windows(2).all(|p| {
            let ratio = p[1] / p[0];
            ratio.is_finite() && ratio > 0.0 && (1.0 / 1.9..=1.9).contains(&ratio)
        });
        if !even {
            return;
        }
        let pitch = (t4 - t0) / 4.0;
        let expected = (-t0 + 4.0 * t1 + 4.0 * t3 - t4) / 6.0;
        self.edge(t2, ((expected - t2) / pitch).abs());
    }

    fn edge(&mut self, at: f64, f: f64) {
        if f >= DISPLACED_CANDIDATE && self.candidates.len() < MAX_DISPLACED {
            self.candidates.push((at, f));
        }
        if self.block_n == 0 {
            self.block_start = at;
        }
        self.block_sum += f;
        self.block_n += 1;
        if self.block_n == DISPLACED_BLOCK {
            self.close_block();
        }
    }

    fn close_block(&mut self) {
        if self.block_n > 0 {
            self.blocks
                .push((self.block_start, self.block_sum / self.block_n as f64));
        }
        (self.block_sum, self.block_n) = (0.0, 0);
    }

    /// The scatter of the edges about the cubic through their neighbours, as the standard
    /// deviation of a timing jitter that would give it, in pitches: the median of the blocks'
    /// mean displacements over 1.112 (white jitter σ leaves each edge off that cubic by a
    /// normal error of σ·√(1 + 34/36), whose mean magnitude is 1.112·σ). `None` without a
    /// block.
    fn jitter(&self) -> Option<f64> {
        let mut means: Vec<f64> = self.blocks.iter().map(|b| b.1).collect();
        if means.is_empty() {
            return None;
        }
        means.sort_by(f64::total_cmp);
        Some(means[means.len() / 2] / ((1.0 + 34.0 / 36.0) * 2.0 / std::f64::consts::PI).sqrt())
    }

    /// The edge of `[start, end]` that lies farthest off its neighbours' line, with its
    /// displacement (pitches), when it stands out: at least ten times the mean displacement
    /// of the blocks in the window (one of its edges excepted), so that it is one edge, not a
    /// rough signal or a shaft whose speed swings from tooth to tooth.
    fn standout(&self, start: f64, end: f64) -> Option<(f64, f64)> {
        let from = self.candidates.partition_point(|c| c.0 < start);
        let (at, f) = self.candidates[from..]
            .iter()
            .take_while(|c| c.0 <= end)
            .copied()
            .max_by(|a, b| a.1.total_cmp(&b.1))?;
        let b0 = self
            .blocks
            .partition_point(|b| b.0 < start)
            .saturating_sub(1);
        let blocks: Vec<f64> = self.blocks[b0..]
            .iter()
            .take_while(|b| b.0 <= end)
            .map(|b| b.1)
            .collect();
        if blocks.is_empty() {
            return None;
        }
        // The mean over the window's blocks, less the candidate's own share of its block.
        let n = blocks.len() as f64 * DISPLACED_BLOCK as f64;
        let mean = (blocks.iter().sum::<f64>() * DISPLACED_BLOCK as f64 - f).max(0.0) / (n - 1.0);
        (f >= 10.0 * mean).then_some((at, f))
    }
}

/// The raw intervals between forward captures, as they come: the long ones and their spacing,
/// the longest, in bounded memory.
#[derive(Default)]
struct Intervals {
    last: Option<f64>,
    /// The two intervals before the newest, older first.
    before: Option<f64>,
    middle: Option<f64>,
    /// Intervals seen (the newest's number).
    n: u64,
    last_long: Option<u64>,
    longs: u64,
    /// Edges from one long interval to the next: how often, and the ratios of the long
    /// intervals ending them (the first [`MAX_RATIOS`] of each).
    spacings: std::collections::BTreeMap<u64, (u64, Vec<f64>)>,
    /// The first [`MAX_ORDER`] spacings, as they came.
    order: Vec<u64>,
    of: u64,
    beyond: u64,
    /// The longest time a pitch took, s.
    slowest_pitch: f64,
    /// Whether the interval before the middle one was long, and whether the middle one is
    /// short against both its neighbours (settled when the next is judged).
    long_before: bool,
    short_middle: bool,
    /// Intervals short against both neighbours and next to no long one: a noise pulse's.
    irregular: u64,
    /// Intervals short against both neighbours ([`SHORT_RATIO`]), and of them those that
    /// are a small part of them ([`RING_RATIO`]: an edge just after another, as a ringing
    /// transition gives), with the longest of those, s.
    short: u64,
    ringing: u64,
    longest_ring: f64,
    /// The configured wheel's longest gap, in pitches (as `capture` was last given it).
    longest: f64,
    /// Of the short intervals, those under [`BOUNCE_RATIO`] of their neighbours, with the
    /// longest of them, s (the test of the polarity not read).
    bounces: u64,
    longest_bounce: f64,
}

/// The pitches an interval `b` spans judged against one neighbour `a` alone: as many as its
/// ratio rounds to where it is a long one ([`LONG_RATIO`]), up to the wheel's `longest` gap;
/// else one.
fn pitches_against(b: f64, a: f64, longest: f64) -> f64 {
    let ratio = b / a;
    if ratio > LONG_RATIO {
        ratio.round().clamp(1.0, longest.max(1.0))
    } else {
        1.0
    }
}

/// An interval less than this many times the geometric mean of its two neighbours is an edge
/// just after the one before: a transition that rang or bounced, crossing the threshold again
/// (a noise pulse between teeth splits an interval at 30–70 %, 0.43 times its neighbours and
/// more).
pub const RING_RATIO: f64 = 0.1;

/// On the polarity not read, an interval less than this many times the geometric mean of its
/// two neighbours is a transition's crossing back and again (a 1024-line disc at 150 rad/s
/// whose falling transitions bounced for 4 µs, 0.10 of the 37 µs beside them; a noise pulse
/// between teeth splits an interval at 30–70 %, 0.43 times its neighbours and more). Looser
/// than [`RING_RATIO`]: those edges are not fed to the core, only tested.
pub const BOUNCE_RATIO: f64 = 0.25;

/// An interval less than this many times the geometric mean of its two neighbours, and next
/// to no long one, is a noise pulse's (a tooth's next to a 3-pitch gap is 0.58 times).
pub const SHORT_RATIO: f64 = 0.75;

/// Ratios kept for each spacing (for their median).
const MAX_RATIOS: usize = 1000;

/// Spacings kept in the order they came (for the order of a wheel's gaps).
const MAX_ORDER: usize = 256;

impl Intervals {
    /// A reversal: the intervals before it are no neighbours of those after.
    fn reset(&mut self) {
        self.finish();
        (self.last, self.before, self.middle) = (None, None, None);
        self.last_long = None;
        (self.long_before, self.short_middle) = (false, false);
    }

    /// The newest interval, never judged against a next one: against the one before it.
    fn finish(&mut self) {
        if let Some(b) = self.middle {
            let pitches = self
                .before
                .map_or(1.0, |a| pitches_against(b, a, self.longest));
            self.slowest_pitch = self.slowest_pitch.max(b / pitches);
        }
    }

    /// A forward capture at `t`: with `timeout` (s) and `longest` (the configured wheel's
    /// longest gap, in pitches).
    fn capture(&mut self, t: f64, timeout: f64, longest: f64) {
        self.longest = longest;
        let Some(t0) = self.last.replace(t) else {
            return;
        };
        let i = t - t0;
        self.n += 1;
        if i > timeout {
            self.beyond += 1;
        }
        match (self.before, self.middle) {
            (Some(a), Some(b)) => {
                let ratio = b / (a * i).sqrt();
                // Its pitches, as its ratio reads them, up to the wheel's longest gap (a
                // longer pause is a slow shaft, not a gap).
                let mut pitches = 1.0;
                let long = ratio > LONG_RATIO;
                // The interval before the middle one: short, and neither of its neighbours
                // long (the one before it was checked with it).
                if self.short_middle && !long {
                    self.irregular += 1;
                }
                self.short_middle = ratio < SHORT_RATIO && !self.long_before;
                if ratio < SHORT_RATIO {
                    self.short += 1;
                }
                if ratio < RING_RATIO {
                    self.ringing += 1;
                    self.longest_ring = self.longest_ring.max(b);
                }
                if ratio < BOUNCE_RATIO {
                    self.bounces += 1;
                    self.longest_bounce = self.longest_bounce.max(b);
                }
                self.long_before = long;
                if long {
                    pitches = ratio.round().clamp(1.0, longest);
                    self.longs += 1;
                    // The middle one is interval n − 1.
                    let here = self.n - 1;
                    if let Some(prev) = self.last_long.replace(here) {
                        let count = here - prev;
                        if self.spacings.len() < MAX_PERIODS || self.spacings.contains_key(&count) {
                            let e = self.spacings.entry(count).or_insert((0, Vec::new()));
                            e.0 += 1;
                            if e.1.len() < MAX_RATIOS {
                                e.1.push(ratio);
                            }
                        }
                        if self.order.len() < MAX_ORDER {
                            self.order.push(count);
                        }
                        self.of += 1;
                    }
                }
                self.slowest_pitch = self.slowest_pitch.max(b / pitches);
            }
            // The first interval has no neighbour before it: judged against the one after (a
            // capture that starts in a gap had its 3 pitches read as one, the shaft 3 times
            // slower than it ran).
            (None, Some(b)) => {
                self.slowest_pitch = self.slowest_pitch.max(b / pitches_against(b, i, longest));
            }
            _ => {}
        }
        (self.before, self.middle) = (self.middle, Some(i));
    }

    /// The most common spacing, when it recurs: at least twice, and at least a third of them;
    /// with it every spacing that recurs at least half as often (a wheel with several gaps).
    fn gaps(&self) -> Option<GapsSeen> {
        let median = |ratios: &[f64]| {
            let mut r = ratios.to_vec();
            r.sort_by(f64::total_cmp);
            r[r.len() / 2]
        };
        let mut best: Option<(u64, &(u64, Vec<f64>))> = None;
        for (&count, e) in &self.spacings {
            if best.is_none_or(|(_, b)| e.0 > b.0) {
                best = Some((count, e));
            }
        }
        let (every, (times, ratios)) = best?;
        if *times < 2 || times * 3 < self.of {
            return None;
        }
        // The others, in the order they first came after the most common one's first.
        let first = self.order.iter().position(|&c| c == every).unwrap_or(0);
        let mut spacings: Vec<SpacingSeen> = Vec::new();
        let (head, tail) = self.order.split_at(first);
        let by_order = tail.iter().chain(head).copied();
        let rest = self.spacings.keys().copied();
        for count in by_order.chain(rest) {
            let Some((t, r)) = self.spacings.get(&count) else {
                continue;
            };
            if *t >= 2 && t * 2 >= *times && !spacings.iter().any(|s| s.every == count) {
                spacings.push(SpacingSeen {
                    every: count,
                    times: *t,
                    ratio: median(r),
                });
            }
        }
        Some(GapsSeen {
            every,
            times: *times,
            of: self.of,
            ratio: median(ratios),
            spacings,
        })
    }

    /// Whether the long intervals (of the first [`MAX_ORDER`]) come at the same places every
    /// `edges` edges: over three turns of `edges` or more, nine in ten of them at a place
    /// (their count from the first, modulo `edges`) met three times or more, and at most
    /// `edges / 2` places. Edges added or lost between them (noise pulses, lost teeth, a
    /// wheel of another count) move the places on, and they spread.
    fn recur_every(&self, edges: u64) -> bool {
        if edges < 4 || self.order.len() < 8 {
            return false;
        }
        let mut places = std::collections::BTreeMap::new();
        let mut at = 0u64;
        *places.entry(0).or_insert(0u64) += 1;
        for &s in &self.order {
            at += s;
            *places.entry(at % edges).or_insert(0) += 1;
        }
        let longs = self.order.len() as u64 + 1;
        let recurring: u64 = places.values().filter(|&&c| c >= 3).sum();
        at >= 3 * edges && places.len() as u64 * 2 <= edges && recurring * 10 >= longs * 9
    }
}

/// A pattern's runs of teeth, in order round the wheel: (teeth in the run, pitches of the gap
/// after it); empty without a gap.
fn pattern_runs(p: &drive_monitor::encoder::Pattern) -> Vec<(u64, u64)> {
    let n = u32::from(p.positions());
    let present = |k: u32| p.present() >> (k % n) & 1 == 1;
    let Some(start) = (0..n).find(|&k| present(k) && !present(k + n - 1)) else {
        return Vec::new();
    };
    let mut runs = Vec::new();
    let mut k = start;
    while k < start + n {
        let teeth = (k..start + n).take_while(|&j| present(j)).count() as u32;
        k += teeth;
        let missing = (k..start + n).take_while(|&j| !present(j)).count() as u32;
        k += missing;
        runs.push((u64::from(teeth), u64::from(missing) + 1));
    }
    runs
}

/// "a, b and c".
fn in_words(items: &[String]) -> String {
    match items {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// What long intervals at the same places every `teeth` edges say of a capture that did not
/// sync ([`Intervals::recur_every`]).
fn swinging(teeth: u32) -> String {
    format!(
        "and the long intervals come at the same places every {teeth} edges, as many as the wheel \
         has teeth \
         (none added or lost): unless its teeth are placed otherwise, the speed swings within a \
         revolution (a cranking engine's compression strokes) so much that its gap cannot be \
         told from its teeth; a steadier or faster stretch of the shaft's running syncs"
    )
}

/// The recurring gaps of a capture in words, with the wheel they suggest (`guess`).
fn seen_gaps(g: &GapsSeen, guess: bool) -> String {
    if let [s] = g.spacings.as_slice() {
        let missing = s.pitches().saturating_sub(1);
        let guess = if guess && missing >= 1 && s.every + missing <= 255 {
            format!(" (a {}-{missing} wheel?)", s.every + missing)
        } else {
            String::new()
        };
        return format!(
            "an interval about {:.1} times its neighbours comes every {} edges ({} of {} \
             times){guess}",
            s.ratio, s.every, s.times, g.of
        );
    }
    let words = |f: &dyn Fn(&SpacingSeen) -> String| {
        in_words(&g.spacings.iter().map(f).collect::<Vec<_>>())
    };
    let positions: u64 = g
        .spacings
        .iter()
        .map(|s| s.every + s.pitches().saturating_sub(1))
        .sum();
    let gaps = g.spacings.len();
    format!(
        "intervals about {} times their neighbours come after {} edges in turn ({} of {} \
         times){}",
        words(&|s| format!("{:.1}", s.ratio)),
        words(&|s| s.every.to_string()),
        words(&|s| s.times.to_string()),
        g.of,
        if guess {
            format!(
                " (a wheel of {positions} positions with {gaps} gaps? describe it in a scene's \
                 [encoder] by lines and gaps, and analyze with --scene)"
            )
        } else {
            String::new()
        }
    )
}

/// The direction channel, when it changed less than once in four captured edges of the
/// encoder channel (a quadrature B channel changes twice a pitch): its name and changes.
fn quiet_direction(r: &AnalyzeReport) -> Option<(&str, u64)> {
    let name = r.direction_channel.as_deref()?;
    let changes = r.channel_changes.iter().find(|c| c.name == name)?.changes;
    (r.captured >= 16 && changes.saturating_mul(4) < r.captured).then_some((name, changes))
}

/// Why the core did not sync on this capture, from the evidence in it (`runs`: the pattern's,
/// see [`pattern_runs`]).
fn sync_hint(
    r: &AnalyzeReport,
    enc: &Encoder,
    runs: &[(u64, u64)],
    intervals: &Intervals,
    timeout: f64,
    busier: Option<&Busier>,
) -> SyncHint {
    use drive_monitor::encoder::{Pattern, Wheel};
    let cfg = enc.config();
    let per_rev = f64::from(enc.edges().max(1));
    let revolutions_of_edges = r.captured as f64 / per_rev;
    let pattern = match cfg.wheel {
        Wheel::Pattern(p) => Some(p),
        _ => None,
    };
    let pitch = std::f64::consts::TAU * f64::from(cfg.prescaler.max(1))
        / f64::from(cfg.wheel.positions().max(1));
    let slowest_speed = (intervals.slowest_pitch > 0.0).then(|| pitch / intervals.slowest_pitch);
    let mut causes = Vec::new();
    let short = revolutions_of_edges < 3.0;
    // Noise: the core's counts (while it judged edges), or the raw intervals out of step
    // (while it searched, it judges none).
    let counted = u64::from(r.glitches) + u64::from(r.unexplained) + u64::from(r.extra);
    let noisy = [counted, intervals.irregular]
        .iter()
        .any(|&n| n >= 3 && n * 50 >= r.captured);
    // The long intervals come at the same places every as many edges as the configured wheel
    // has teeth: no edge was added or lost between them, so the wheel's teeth are all there
    // and no noise pulse is. Where such a capture does not sync, its speed swings within a
    // revolution (a cranking engine's compression strokes), so that the gap reads at another
    // ratio and ordinary teeth look long or short against their neighbours: a clean 12-1
    // wheel at 200 rpm with a 45 % swing four times a revolution was told it was a 14-3 or a
    // 4-1 wheel and its signal noisy.
    let teeth_counted = pattern.is_some_and(|p| intervals.recur_every(u64::from(p.teeth())));
    let swung = teeth_counted && counted == 0 && noisy;
    let noisy = noisy && !swung;
    // In a noisy signal the half of a tooth's interval a pulse leaves is long against the
    // other: such "gaps" recur too (every other edge under a pulse a tooth), so there the
    // recurring spacings must account for two thirds of all to name a wheel by them.
    let gaps = intervals.gaps().filter(|g| {
        let recurring: u64 = g.spacings.iter().map(|s| s.times).sum();
        !noisy || recurring * 3 >= g.of * 2
    });
    // Another channel has the edges the one read lacks: the capture is long enough, and the
    // long intervals of a channel pulsing among its edges are no stop.
    if let Some(b) = busier {
        // Both channels' edges as the lines give them, before the input prescaler (the
        // busier channel's are counted so): a revolution is the wheel's lines then.
        let prescaler = u64::from(cfg.prescaler.max(1));
        let lines_per_rev = u64::from(enc.edges().max(1)) * prescaler;
        causes.push(format!(
            "no sync: `{}`, the channel read, has {} edges ({:.1} revolutions of the configured \
             wheel, {} edges a revolution{}), where `{}` has {} ({:.1} revolutions){}: the \
             encoder is likely `{}`: read it with --channel {}{}",
            r.channel,
            r.edges,
            r.edges as f64 / lines_per_rev as f64,
            lines_per_rev,
            if prescaler > 1 {
                format!(
                    "; edges on the channel, before the input prescaler of {prescaler}, which \
                     captures {} a revolution",
                    enc.edges()
                )
            } else {
                String::new()
            },
            b.name,
            b.edges,
            b.revolutions,
            match b.pulses_every {
                Some(e) => format!(
                    ", and it pulses once every {e} edges of `{}`, as an index or a cam signal \
                     does (its long intervals are no stop of the shaft)",
                    b.name
                ),
                None => String::new(),
            },
            b.name,
            b.column,
            match b.index_of {
                Some(c) => format!(" --index-channel {c}"),
                None => String::new(),
            }
        ));
    } else if threshold_miss(r).is_some() && r.edges == 0 {
        causes.push(
            "no sync: no edge was read: the values never cross the band of --threshold and \
             --hysteresis (their range above), not a short capture"
                .to_string(),
        );
    } else if let Some(m) = r.same_stamp.filter(|m| short && m.timescale.is_some()) {
        causes.push(format!(
            "no sync: {} captured edges, {:.1} revolutions of the configured wheel ({} edges a \
             revolution), over {:.6} s: at {} time stamp(s) `{}` changes and changes back \
             within the dump's time unit ({:.3e} s), which leaves no pulse: edges are lost to \
             the time unit, not to a short capture (see the WARNING)",
            r.captured,
            revolutions_of_edges,
            per_rev,
            r.span[1] - r.span[0],
            m.times,
            r.channel,
            m.timescale.unwrap_or(0.0)
        ));
    } else if short {
        causes.push(format!(
            "no sync: the capture is too short: its {} captured edges are {:.1} revolutions of \
             the configured wheel ({} edges a revolution), and acquiring sync takes about 2–3",
            r.captured, revolutions_of_edges, per_rev
        ));
    }
    if let Some(p) = pattern {
        let name = if runs.len() == 1
            && p == Pattern::missing_teeth(p.positions(), (runs[0].1 - 1) as u8)
        {
            format!("{}-{} wheel", p.positions(), runs[0].1 - 1)
        } else {
            format!("wheel ({})", r.wheel)
        };
        let expected = if runs.len() == 1 {
            format!(
                "has {} teeth a revolution and a gap of {} pitches",
                p.teeth(),
                runs[0].1
            )
        } else {
            let list: Vec<String> = runs
                .iter()
                .map(|(t, g)| format!("{g} pitches after {t} teeth"))
                .collect();
            format!(
                "has {} teeth a revolution and gaps of {}",
                p.teeth(),
                list.join(", ")
            )
        };
        match &gaps {
            Some(g) => {
                // Each recurring gap the wheel has: a run of as many teeth ending in a gap of
                // as many pitches.
                let agree = g
                    .spacings
                    .iter()
                    .all(|s| runs.contains(&(s.every, s.pitches())));
                if teeth_counted && (!agree || swung) {
                    causes.push(format!(
                        "no sync: the configured {name} {expected}; in the capture {}, {}",
                        seen_gaps(g, false),
                        swinging(p.teeth())
                    ));
                } else if !agree {
                    causes.push(format!(
                        "no sync: the configured {name} {expected}; in the capture {}",
                        seen_gaps(g, true)
                    ));
                }
            }
            None if swung => causes.push(format!(
                "no sync: the configured {name} {expected}; in the capture {} interval(s) are \
                 more than {LONG_RATIO} times their neighbours, {}",
                intervals.longs,
                swinging(p.teeth())
            )),
            None if !short && !noisy && quiet_direction(r).is_some() => {
                if let Some((name, changes)) = quiet_direction(r) {
                    causes.push(format!(
                        "no sync: the direction channel `{name}` changed {changes} time(s) over \
                         the {} captured edges, so nearly every edge came with no step forward \
                         of the quadrature count and was fed as reverse, which no gap can be \
                         counted among (see the WARNING)",
                        r.captured
                    ));
                }
            }
            None if !short && !noisy => causes.push(format!(
                "no sync: the configured {name} {expected}, but no gap recurs in the capture \
                 ({} interval(s) more than {LONG_RATIO} times their neighbours, at no regular \
                 count of edges): {}",
                intervals.longs,
                // A file of edge times has no other channel or polarity to read.
                if r.edges_listed() {
                    "a uniform disc (use --lines N), or times of another wheel's edges"
                } else {
                    "the wrong channel or edge polarity (--channel, --edge), or a uniform disc \
                     (use --lines N --framing index|none)"
                }
            )),
            None => {}
        }
    }
    let pulses_among = busier.is_some_and(|b| b.pulses_every.is_some());
    if (intervals.beyond > 0 || r.timeouts > 1) && !pulses_among {
        causes.push(format!(
            "no sync: the shaft stopped or ran below --min-speed {} rad/s: {} interval(s) \
             between edges longer than the {:.3} s timeout it implies, {} timeout(s); the \
             slowest speed seen is about {}{}",
            fmt_number(cfg.min_speed),
            intervals.beyond,
            timeout,
            r.timeouts,
            slowest_speed.map_or("unknown".into(), |w| format!("{} rad/s", fmt_speed(w))),
            if slowest_speed.is_some_and(|w| w < SLOW_FOR_SECONDS) && !r.time_unit_stated {
                format!("; {}", unit_hint())
            } else {
                String::new()
            }
        ));
    }
    if noisy {
        causes.push(format!(
            "no sync: the signal is noisy: of {} captured edges, {} interval(s) are short against \
             both neighbours and next to no gap (a noise pulse's){}; the core counted {} \
             glitches, {} extra and {} unexplained edges (check the wiring, the probe's ground \
             and the threshold)",
            r.captured,
            intervals.irregular,
            if gaps.is_none() && pattern.is_some() {
                ", and no wheel's gaps can be told among them"
            } else {
                ""
            },
            r.glitches,
            r.extra,
            r.unexplained
        ));
    }
    if let Some(why) = other_way(r) {
        causes.push(format!(
            "no sync: the edges ran backward, a pitch at each capture,{why}"
        ));
    }
    // An index disc whose index pulses disagree with its lines has its own `index:` line.
    let index_says = r
        .index_period
        .is_some_and(|p| p.captures != u64::from(p.expected));
    if causes.is_empty() && !index_says {
        causes.push(format!(
            "no sync: none of the usual causes shows in the capture ({:.1} revolutions of edges, \
             {}no interval beyond the {:.3} s timeout, {} glitches and {} unexplained edges in \
             {}): see the fault list",
            revolutions_of_edges,
            if pattern.is_some() {
                "gaps that agree with the wheel, "
            } else {
                ""
            },
            timeout,
            r.glitches,
            r.unexplained,
            r.captured
        ));
    }
    SyncHint {
        causes,
        gaps,
        long_intervals: intervals.longs,
        irregular_intervals: intervals.irregular,
        revolutions_of_edges,
        beyond_timeout: intervals.beyond,
        timeout,
        min_speed: cfg.min_speed,
        slowest_speed,
    }
}

/// The channel read changing level twice at one time stamp.
#[derive(Debug, Clone, Copy, Serialize, PartialEq)]
pub struct SameStamp {
    /// How many times.
    pub times: u64,
    /// The first, s.
    pub first: f64,
    /// A value change dump's time unit, s, when the file is one: its changes at one stamp
    /// leave one row of the last levels, and the pulse is lost; in rows it is two rows at one
    /// time with opposite levels.
    pub timescale: Option<f64>,
}

/// Why the channel read through `--threshold` can have no edge, if its values say: the range
/// they span against the band the threshold reads them through.
fn threshold_miss(r: &AnalyzeReport) -> Option<String> {
    let (t, [min, max]) = (r.threshold?, r.values?);
    let (lo, hi) = (t.volts - 0.5 * t.hysteresis, t.volts + 0.5 * t.hysteresis);
    let never = match (max <= hi, min >= lo) {
        (true, true) => format!("never above {hi} nor below {lo}"),
        (true, false) => format!("never above {hi}, so never high"),
        (false, true) => format!("never below {lo}, so never low"),
        (false, false) => return None,
    };
    Some(format!(
        "the values of `{}` range from {min} to {max}, {never} (--threshold {} with --hysteresis \
         {}: high above {hi}, low below {lo}): give a --threshold within their range (their \
         midpoint is {}) and a --hysteresis narrower than it ({})",
        r.channel,
        fmt_number(t.volts),
        fmt_number(t.hysteresis),
        fmt_value(0.5 * (min + max)),
        fmt_value(max - min)
    ))
}

/// A value to four significant digits or so (`0.0002`, `2.102`, `1.234e-5`).
fn fmt_value(x: f64) -> String {
    if x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:.3e}")
    } else {
        let s = format!("{x:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    }
}

/// A mean speed below this, rad/s (under 10 rpm), read from times whose unit the file does not
/// state, is said to be what times in ms or µs read as seconds would give.
const SLOW_FOR_SECONDS: f64 = 1.0;

/// What a speed read from times of unstated unit is, should they be ms or µs.
fn unit_hint() -> &'static str {
    "the file does not state the unit of its times and they are read as seconds: if they are \
     milliseconds or microseconds, every speed is 1000 or 1 000 000 times this (δ is the same): \
     give --time-unit ms or --time-unit us (or a header `time_ms`, `time_us`)"
}

/// A speed, rad/s, to three decimals, or to three significant digits below 0.1 (a speed of
/// 5e-5 rad/s is not 0.000).
fn fmt_speed(w: f64) -> String {
    if w != 0.0 && w.abs() < 0.1 {
        format!("{w:.3e}")
    } else {
        format!("{w:.3}")
    }
}

/// A number given on the command line as it reads: as written for the usual magnitudes, in
/// exponent form beyond them (`1e300`, not its 301 digits).
pub fn fmt_number(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        x.to_string()
    }
}

/// What the observer saw during one call to the monitor.
#[derive(Default)]
struct Seen {
    events: Vec<(u32, Event)>,
}

#[derive(Clone, Copy)]
enum Event {
    Tooth(Tooth),
    Fault(Fault),
}

impl EdgeSink for Seen {
    fn tooth(&mut self, tooth: &Tooth) {
        self.events.push((tooth.time, Event::Tooth(*tooth)));
    }
    fn fault(&mut self, fault: Fault, time: u32) {
        self.events.push((time, Event::Fault(fault)));
    }
}

/// The poll interval for `enc`: [`POLL_INTERVAL`], a quarter of the counter's period, or half
/// of [`Encoder::poll_interval_ticks`] (the window after the timeout in which a poll sees a
/// standstill before the counter wraps past the last edge), whichever is shortest (elapsed
/// time is measured modulo the counter).
pub fn poll_interval(enc: &Encoder) -> f64 {
    let hz = f64::from(enc.timer_hz());
    let period = (f64::from(enc.mask()) + 1.0) / hz;
    let window = f64::from(enc.poll_interval_ticks()) / hz;
    POLL_INTERVAL
        .min(period / 4.0)
        .min(window / 2.0)
        .max(MIN_POLL_INTERVAL)
}

/// The shortest poll interval: a configuration whose standstill window
/// ([`Encoder::poll_interval_ticks`]) is shorter than twice this can have a stop missed
/// between two polls.
pub const MIN_POLL_INTERVAL: f64 = 1e-5;

/// Converts capture times to ticks and back.
struct Clock {
    hz: f64,
    mask: u64,
    /// Recent raw events: (ticks, time, whether a capture of the encoder channel), newest
    /// last.
    recent: VecDeque<(u32, f64, bool)>,
    latest: (u32, f64),
}

impl Clock {
    fn ticks(&self, t: f64) -> u32 {
        // A real timer latches the count of whole ticks elapsed.
        let n = (t * self.hz).floor() as i64;
        (n as u64 & self.mask) as u32
    }

    fn note(&mut self, ticks: u32, t: f64, capture: bool) {
        if self.recent.len() == 64 {
            self.recent.pop_front();
        }
        self.recent.push_back((ticks, t, capture));
        self.latest = (ticks, t);
    }

    /// The capture time of `ticks`: the recent capture latched at it (an index pulse or a
    /// poll at the same tick is not the edge the core reports: a window ending at a frame
    /// edge was shown ending at its index pulse, 0.6 µs later, at 1 MHz), else the recent
    /// event latched at it, else counted back from the latest event (the core reports times
    /// of recent edges and polls).
    fn time(&self, ticks: u32) -> f64 {
        let at = |capture: bool| {
            self.recent
                .iter()
                .rev()
                .find(|&&(k, _, c)| k == ticks && (c || !capture))
                .map(|&(_, t, _)| t)
        };
        if let Some(t) = at(true).or_else(|| at(false)) {
            return t;
        }
        let back = (u64::from(self.latest.0).wrapping_sub(u64::from(ticks))) & self.mask;
        self.latest.1 - back as f64 / self.hz
    }
}

fn sync_name(s: SyncState) -> &'static str {
    match s {
        SyncState::Searching => "searching",
        SyncState::Confirming => "confirming",
        SyncState::Synced => "synced",
    }
}

/// The wheel as the core frames it, in words.
pub fn wheel_text(e: &Encoder) -> String {
    use drive_monitor::encoder::Wheel;
    match e.config().wheel {
        Wheel::Indexed { lines } => format!("{lines} lines with an index pulse"),
        Wheel::Unframed { lines } => format!("{lines} lines, no frame marker"),
        Wheel::Pattern(p) => format!(
            "pattern of {} teeth on {} positions",
            p.teeth(),
            p.positions()
        ),
    }
}

/// The number a channel's name ends with (`Channel 3`, `D3`, `CH3`: 3).
fn name_number(name: &str) -> Option<usize> {
    let name = name.trim();
    let digits = name.len() - name.trim_end_matches(|c: char| c.is_ascii_digit()).len();
    name[name.len() - digits..].parse().ok()
}

/// The channel names, each that another channel shares followed by its number
/// (`Channel 0 (channel 1)`).
fn distinct_names(channels: &[String]) -> Vec<String> {
    channels
        .iter()
        .enumerate()
        .map(|(k, name)| {
            if channels.iter().filter(|&n| n == name).count() > 1 {
                format!("{name} (channel {k})")
            } else {
                name.clone()
            }
        })
        .collect()
}

fn column(channels: &[String], c: &Channel, option: &str) -> Result<usize, String> {
    // A channel whose name carries the number given, at another column: the number is read
    // as a column, but the analyzer's own numbering may be what was meant.
    let named = |n: usize| {
        channels
            .iter()
            .position(|x| name_number(x) == Some(n))
            .filter(|&k| k != n)
    };
    match c {
        Channel::Column(n) if *n < channels.len() => match named(*n) {
            None => Ok(*n),
            Some(k) => Err(format!(
                "{option} {n} is ambiguous: the channel {n} counted from 0 is `{}`, and \
                 `{}` (counted {k}) has {n} in its name; give the name: {option} \"{}\"",
                channels[*n], channels[k], channels[k]
            )),
        },
        Channel::Name(name) => {
            let at: Vec<usize> = (0..channels.len())
                .filter(|&k| channels[k] == *name)
                .collect();
            match at.as_slice() {
                [k] => Ok(*k),
                [] => {
                    // A value change dump names channels that share a name by their scopes.
                    let scoped: Vec<&str> = channels
                        .iter()
                        .filter(|c| c.ends_with(&format!(".{name}")))
                        .map(String::as_str)
                        .collect();
                    Err(format!(
                        "{option} {name}: no such channel (the capture has {}){}",
                        channels.join(", "),
                        if scoped.is_empty() {
                            String::new()
                        } else {
                            format!(
                                "; channels that share the name `{name}` are named by their \
                                 scopes: {}",
                                scoped.join(", ")
                            )
                        }
                    ))
                }
                many => Err(format!(
                    "{option} {name}: {} channels have that name (numbers {}, counted from 0): \
                     give the number of the one to read",
                    many.len(),
                    many.iter()
                        .map(usize::to_string)
                        .collect::<Vec<_>>()
                        .join(", ")
                )),
            }
        }
        Channel::Column(n) => Err(format!(
            "{option} {n}: the capture has {} channel{} ({}), numbered from 0{}",
            channels.len(),
            if channels.len() == 1 { "" } else { "s" },
            channels.join(", "),
            match named(*n) {
                Some(k) => format!(
                    "; for the channel named {n} give its name: {option} \"{}\"",
                    channels[k]
                ),
                None => String::new(),
            }
        )),
    }
}

/// Why an analysis failed: the file, or the options.
#[derive(Debug)]
pub enum AnalyzeError {
    /// The capture file.
    Capture(CaptureError),
    /// An option that does not fit the capture or the core.
    Option(String),
}

impl std::fmt::Display for AnalyzeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AnalyzeError::Capture(e) => write!(f, "{e}"),
            AnalyzeError::Option(m) => write!(f, "{m}"),
        }
    }
}

impl From<CaptureError> for AnalyzeError {
    fn from(e: CaptureError) -> Self {
        AnalyzeError::Capture(e)
    }
}

/// Analyzes the capture `reader` with `cfg`; `on_decision` is told every decision of the
/// core, in order.
pub fn analyze<R: BufRead>(
    reader: &mut CaptureReader<R>,
    cfg: &AnalyzeConfig,
    on_decision: &mut dyn FnMut(&Decision),
) -> Result<AnalyzeReport, AnalyzeError> {
    let enc = Encoder::new(cfg.encoder)
        .map_err(|e| AnalyzeError::Option(format!("the encoder configuration: {e}")))?;
    let mut monitor: DeltaMonitor<MAX_LINES> = DeltaMonitor::new(enc.clone(), cfg.window, None)
        .map_err(|e| AnalyzeError::Option(format!("the monitor configuration: {e}")))?;
    let channels = reader.channels().to_vec();
    // A file of edge times: every row is a captured edge of the encoder, and it has nothing
    // else (no level to take an edge of, no index, no B channel).
    let times = reader.format() == CaptureFormat::Times;
    if times {
        let refused = if cfg.index_channel.is_some() {
            Some(
                "a file of edge times holds the encoder's captured edges alone, no index \
                 channel to frame a revolution by: analyze it as a disc framed by nothing \
                 (--lines N, --framing none) or a wheel with a gap (--wheel N-M)",
            )
        } else if cfg.direction.is_some() {
            Some(
                "--direction-channel: a file of edge times has one column, the captured edges, \
                 and no quadrature B channel to give their direction",
            )
        } else if cfg.edge.is_some() {
            Some(
                "--edge: a file of edge times lists the edges the capture took, one a row, and \
                 no levels to take rising or falling edges of: leave --edge out",
            )
        } else {
            None
        };
        if let Some(m) = refused {
            return Err(AnalyzeError::Option(m.to_string()));
        }
    }
    let ch = column(&channels, &cfg.channel, "--channel").map_err(AnalyzeError::Option)?;
    let ich = match &cfg.index_channel {
        Some(c) => Some(
            column(&channels, c, "--index-channel")
                .map_err(|e| {
                    if cfg.index_channel_default {
                        format!("no --index-channel was given, so the default applies: {e}")
                    } else {
                        e
                    }
                })
                .map_err(AnalyzeError::Option)?,
        ),
        None => None,
    };
    if ich == Some(ch) {
        return Err(AnalyzeError::Option(if cfg.index_channel_default {
            format!(
                "no --index-channel was given, so the default applies: `{}`, the encoder channel \
                 itself (--channel): give --index-channel",
                channels[ch]
            )
        } else {
            "--index-channel is the encoder channel itself".into()
        }));
    }
    let dch = match &cfg.direction {
        Some((c, lead)) => {
            let d = column(&channels, c, "--direction-channel").map_err(AnalyzeError::Option)?;
            if d == ch || Some(d) == ich {
                return Err(AnalyzeError::Option(format!(
                    "--direction-channel is the {} channel itself: give the quadrature B channel",
                    if d == ch { "encoder" } else { "index" }
                )));
            }
            Some((d, *lead))
        }
        None => None,
    };
    // From here on, channels as the report names them: a name two columns share with its
    // number (`Channel 0 (channel 1)`), so that the one read is told.
    let channels = distinct_names(&channels);
    // Only the channels read must hold levels (an analog column beside them is no data).
    let read: Vec<usize> = [Some(ch), ich, dch.map(|(d, _)| d)]
        .into_iter()
        .flatten()
        .collect();
    reader.read_only(&read);
    let mut report = AnalyzeReport {
        format: reader.format().name(),
        channel: channels[ch].clone(),
        index_channel: ich.map(|i| channels[i].clone()),
        direction_channel: dch.map(|(d, _)| channels[d].clone()),
        forward: dch.map(|(_, lead)| lead),
        edge: match cfg.polarity() {
            _ if times => "listed",
            Polarity::Rising => "rising",
            Polarity::Falling => "falling",
        },
        wheel: wheel_text(&enc),
        timer_hz: cfg.encoder.timer_hz,
        counter_bits: cfg.encoder.counter_bits,
        prescaler: cfg.encoder.prescaler,
        sample_rate: reader.sample_rate(),
        sample_numbers: reader.sample_column().map(str::to_string),
        threshold: reader.threshold(),
        time_unit: reader.time_unit().name(),
        time_unit_stated: reader.time_unit_stated(),
        sync_state: "searching",
        ripple: ripple_readings(&cfg.encoder),
        ..Default::default()
    };
    let mut clock = Clock {
        hz: cfg.encoder.timer_hz,
        mask: u64::from(enc.mask()),
        recent: VecDeque::new(),
        latest: (0, 0.0),
    };
    let mut polls = Polls {
        every: poll_interval(&enc),
        timeout: f64::from(enc.timeout_ticks()) / cfg.encoder.timer_hz,
        last: f64::NEG_INFINITY,
    };
    let mut st = State {
        seen: Seen::default(),
        frames: VecDeque::new(),
        sync: SyncState::Searching,
        speeds: Decimated::default(),
        deltas: Decimated::default(),
        max_revs: usize::from(monitor.window_revolutions()),
        frames_listed: 0,
    };
    let mut prev: Vec<Level> = Vec::new();
    // The read channel's last change of level, and its changes at that same time.
    let (mut last_change, mut same_stamp, mut same_stamp_first) = (None::<f64>, 0u64, None::<f64>);
    let mut periods = IndexPeriods::default();
    let mut last_event: Option<f64> = None;
    let mut end = 0.0;
    let mut changes = vec![0u64; channels.len()];
    // Each other channel's pulses among the read channel's edges (an index's come once a
    // revolution of lines), and the read channel's among each other's (read where the index
    // is, it pulses once every so many of the encoder's).
    let (mut no_data, mut no_data_from): (Vec<(f64, f64)>, Option<f64>) = (Vec::new(), None);
    let mut among_read = vec![Spacing::default(); channels.len()];
    let mut read_among = vec![Spacing::default(); channels.len()];
    let mut grid = TimeGrid::default();
    let mut rate_grid = RateGrid::default();
    let mut float_grid = FloatGrid::default();
    let mut float_values = FloatValues::default();
    // The finest precision a transition's time is written to, s: the digits' rounding of
    // every time where they are written to fixed decimals (and no more where a time printed
    // as its shortest decimal ends early).
    let mut written_finest = f64::INFINITY;
    let mut resolution = Resolution {
        hz: cfg.encoder.timer_hz,
        ..Resolution::default()
    };
    // A stated sample rate (a sigrok file's, or --sample-rate) cannot have recorded two rows
    // less than a sample period apart: the rate or the file is wrong.
    let period = reader.sample_rate().map(|r| 1.0 / r);
    let mut previous_time: Option<f64> = None;
    // (A file of edge times lists the captures themselves: each is fed, and spans as many
    // lines as the prescaler says.)
    let prescaler = if times {
        1
    } else {
        u32::from(cfg.encoder.prescaler.max(1))
    };
    let mut last_capture: Option<u32> = None;
    // The time of that capture, s, as the file writes it.
    let mut last_capture_time: Option<f64> = None;
    let mut prescaled = 0u32;
    // The quadrature count of the encoder and direction channels, and whether the capture
    // before the last moved it forward (the first counts as moved).
    let (mut quadrature, mut moved_before) = (Quadrature::default(), true);
    let mut intervals = Intervals::default();
    // The channel's edges of the other polarity, for their ringing alone: a transition of
    // that polarity that rings crosses back (an edge of the polarity read) and again, so the
    // edges read hold a crossing at every such transition, half a pitch on, which reads as a
    // clean pulse train at twice the speed (valid windows, the wrong δ).
    let mut other = Intervals::default();
    let mut other_edges = 0u64;
    let mut displaced = DisplacedEdges::default();
    let polarity = cfg.polarity();
    // A pattern's runs of teeth and gaps (for the hint on a wheel that never syncs).
    let runs = match cfg.encoder.wheel {
        drive_monitor::encoder::Wheel::Pattern(p) => pattern_runs(&p),
        _ => Vec::new(),
    };
    let longest_gap = runs.iter().map(|&(_, g)| g as f64).fold(1.0, f64::max);
    // A row read ahead (to see whether B comes back just after an edge of A), and the time
    // of B's last change and of the capture before.
    // (With the precision its time is written to.)
    let mut ahead: Option<(f64, Vec<Level>, f64)> = None;
    let mut row: Vec<Level> = Vec::new();
    let (mut b_changed_at, mut captured_at) = (f64::NEG_INFINITY, None::<f64>);
    loop {
        let (t, precision) = match ahead.take() {
            Some((t, l, p)) => {
                row = l;
                (t, p)
            }
            None => match reader.next_row()? {
                Some((t, l)) => {
                    row.clear();
                    row.extend_from_slice(l);
                    (t, reader.time_precision())
                }
                None => break,
            },
        };
        let levels = &row[..];
        if report.rows == 0 {
            report.span[0] = t;
            prev = levels.to_vec();
        }
        // The times' grid from the transitions alone (every row of a file of edge times): a
        // row where no level changes (a first row of the initial levels, a last at the end of
        // the recording, a dump's `#0`, a binary export's begin time) need lie on no sample
        // grid, and one such row off it had made the step found a fifth of the sampling's.
        let transition = times
            || prev
                .iter()
                .zip(levels)
                .any(|(a, b)| a != b && *a != Level::Unknown && *b != Level::Unknown);
        if transition {
            grid.row(t);
            if period.is_none() {
                rate_grid.row(t, precision);
            }
            float_grid.row(t, precision);
            float_values.row(t, precision, reader.time_origin());
            written_finest = written_finest.min(precision);
        }
        // (Every row to the resolution of the blocks: a row off the grid only makes a block's
        // step finer, and the floor never takes a block's finer than the grid above.)
        resolution.row(t);
        for ((n, a), b) in changes.iter_mut().zip(&prev).zip(levels) {
            if a != b && *a != Level::Unknown && *b != Level::Unknown {
                *n += 1;
            }
        }
        // The channel read changing again at the time of its last change: two rows at one
        // time with opposite levels, a pulse of no width as written.
        let (a, b) = (prev[ch], levels[ch]);
        if a != b && a != Level::Unknown && b != Level::Unknown {
            if last_change == Some(t) {
                same_stamp += 1;
                same_stamp_first.get_or_insert(t);
            }
            last_change = Some(t);
        }
        // The channel read without data: from the row it went unknown to the row it came back
        // (or the end of the capture).
        match (prev.get(ch), levels.get(ch)) {
            (Some(&a), Some(&Level::Unknown)) if a != Level::Unknown || report.rows == 0 => {
                no_data_from = Some(t);
            }
            (Some(&Level::Unknown), Some(&b)) if b != Level::Unknown => {
                if let Some(f) = no_data_from.take() {
                    no_data.push((f, t));
                }
            }
            _ => {}
        }
        report.rows += 1;
        end = t;
        let edge = |c: usize| -> Option<Polarity> {
            match (prev[c], levels[c]) {
                (Level::Low, Level::High) => Some(Polarity::Rising),
                (Level::High, Level::Low) => Some(Polarity::Falling),
                _ => None,
            }
        };
        let index_edge = ich.and_then(edge) == Some(polarity);
        let channel_edge = times || edge(ch) == Some(polarity);
        if !times && edge(ch).is_some_and(|p| p != polarity) {
            other_edges += 1;
            other.capture(t, f64::INFINITY, longest_gap);
        }
        if channel_edge {
            report.edges += 1;
        }
        for (k, (a, b)) in among_read.iter_mut().zip(&mut read_among).enumerate() {
            if k == ch {
                continue;
            }
            if channel_edge {
                a.other_edge();
                b.pulse();
            }
            if edge(k) == Some(polarity) {
                a.pulse();
                b.other_edge();
            }
        }
        // The timer's input prescaler: one capture in `prescaler` edges of the channel, the
        // first at the prescaler-th (a noise pulse's edge counts like any other).
        let encoder_edge = channel_edge && {
            prescaled += 1;
            prescaled == prescaler
        };
        if encoder_edge {
            prescaled = 0;
        }
        // B's level as A changes; unknown when B changed in the same sample.
        let mut direction = match dch {
            Some((d, lead)) if encoder_edge && prev[d] == levels[d] => match levels[d] {
                Level::Low => Some(lead.direction(levels[ch] == Level::High, false)),
                Level::High => Some(lead.direction(levels[ch] == Level::High, true)),
                Level::Unknown => None,
            },
            _ => None,
        };
        if let Some((d, lead)) = dch {
            quadrature.step(lead, [prev[ch], prev[d]], [levels[ch], levels[d]]);
            if encoder_edge {
                // A forward pitch moves the quadrature count on by four between captures of
                // A. A capture that is no step forward since the one before, itself so, is no
                // pitch: the shaft rocks across a line edge (each backward crossing is an edge
                // not captured), which read as a steady forward pulse train. Fed as reverse:
                // no tooth, and no running until the shaft moves on. (One such capture alone
                // is left to the core: a noise pulse just before a real edge.)
                let steps = quadrature.since_capture();
                let moved = steps > 0;
                // A pitch or more backward: the disc turns the other way (B says so too),
                // which is no rocking at rest.
                let backward = steps <= -4;
                if !moved && !moved_before {
                    direction = Some(Direction::Reverse);
                    if !backward {
                        report.no_pitch += 1;
                    }
                }
                if backward && direction == Some(Direction::Reverse) {
                    report.backward_pitches += 1;
                }
                moved_before = moved;
            }
        }
        if encoder_edge && dch.is_some() && direction.is_none() {
            report.direction_unknown += 1;
        }
        // Whether B's level at this edge of A is half of a pulse, B then to come back.
        let b_pulse = match dch {
            Some((d, _)) if prev[d] != levels[d] => {
                b_changed_at = t;
                None
            }
            // (`moved_before` is now this capture's: a step forward since the one before.)
            Some((d, _))
                if encoder_edge && moved_before && direction == Some(Direction::Reverse) =>
            {
                let pitch = captured_at.map(|c| (t - c) / f64::from(prescaler));
                pitch
                    .filter(|&p| t - b_changed_at <= p / 8.0)
                    .map(|p| (d, b_changed_at + p / 8.0))
            }
            _ => None,
        };
        if encoder_edge {
            captured_at = Some(t);
        }
        prev.copy_from_slice(levels);
        if let (Some(p), Some(t0)) = (period, previous_time) {
            // (Rows at one time are allowed: a level shown twice. Slack for the rounding of
            // the times: 1e-9 of the period, and a few units in the last place of the times
            // themselves, whose difference loses that much; with the first alone, rows one
            // sample apart read as closer from 0.25 s on at 24 MHz, and every sigrok export of
            // a sample a row longer than that was refused.)
            let slack = 1e-9 * p + 4.0 * f64::EPSILON * t.abs().max(t0.abs());
            if t > t0 && t - t0 < p - slack {
                return Err(AnalyzeError::Capture(reader.err_here(&format!(
                    "this row is {:.3e} s after the previous one, less than one period \
                     ({:.3e} s) of the sample rate {} Hz: the rate is wrong, or the file was \
                     not sampled at it",
                    t - t0,
                    p,
                    1.0 / p,
                ))));
            }
        }
        previous_time = Some(t);
        if let Some((d, until)) = b_pulse {
            // B back to its level before the pulse within an eighth of a pitch of leaving it,
            // A unchanged: the shaft stepped forward (the pulse's three steps back would be
            // three quarters of a pitch in that time), and B's level at A's edge was noise.
            if let Some((t2, l)) = reader.next_row()? {
                if t2 <= until && l[d] != levels[d] && l[d] != Level::Unknown && l[ch] == levels[ch]
                {
                    direction = Some(Direction::Forward);
                    report.direction_glitches += 1;
                }
                ahead = Some((t2, l.to_vec(), 0.0));
            }
            if let Some(a) = ahead.as_mut() {
                a.2 = reader.time_precision();
            }
        }
        if direction == Some(Direction::Reverse) {
            report.reverse_edges += 1;
        }
        if !index_edge && !encoder_edge {
            continue;
        }
        // The periodic task between the last event and this one.
        if let Some(t0) = last_event {
            for p in polls.between(t0, t) {
                let ticks = clock.ticks(p);
                clock.note(ticks, p, false);
                st.poll(&mut monitor, &clock, ticks, &mut report, on_decision);
            }
        }
        let ticks = clock.ticks(t);
        clock.note(ticks, t, encoder_edge);
        last_event = Some(t);
        if index_edge {
            report.index_pulses += 1;
            periods.index();
            monitor.on_index(ticks);
        }
        if encoder_edge {
            report.captured += 1;
            if direction == Some(Direction::Reverse) {
                intervals.reset();
                displaced.reset();
            } else {
                intervals.capture(t, polls.timeout, longest_gap);
                displaced.capture(t);
            }
            let before = last_capture_time.replace(t);
            if let Some(p) = last_capture.replace(ticks) {
                // Two captures at one time as written: the file repeats a row (no timer
                // resolves 0 s). Two at one tick otherwise: the timer cannot resolve the edges.
                if before == Some(t) {
                    let r = report.repeated_times.get_or_insert(RepeatedTimes {
                        rows: 0,
                        first_line: reader.line(),
                        time: t,
                    });
                    r.rows += 1;
                } else if ticks.wrapping_sub(p) & enc.mask() == 0
                    && direction != Some(Direction::Reverse)
                {
                    report.captures_at_one_tick += 1;
                }
            }
            periods.capture();
            if report.sync_acquired.is_some() && st.sync != SyncState::Synced {
                report.edges_unsynced += 1;
            }
            let o = monitor.on_edge_observed(ticks, direction, &mut st.seen);
            st.after(&mut monitor, &clock, o, &mut report, on_decision);
        }
    }
    report.span[1] = end;
    report.values = reader.value_range(ch).map(|(a, b)| [a, b]);
    let (merged, merged_at) = reader.merged_changes(ch);
    if let Some(first) = [merged_at, same_stamp_first]
        .into_iter()
        .flatten()
        .reduce(f64::min)
    {
        report.same_stamp = Some(SameStamp {
            times: merged + same_stamp,
            first,
            timescale: reader.timescale(),
        });
    }
    no_data.extend(no_data_from.map(|f| (f, end)));
    if let Some(&first) = no_data.first() {
        report.no_data = Some(NoData {
            spans: no_data.len() as u64,
            seconds: no_data.iter().map(|(a, b)| b - a).sum(),
            first: [first.0, first.1],
        });
    }
    report.time_origin = reader.time_origin();
    report.warnings.clone_from(&cfg.warnings);
    // The end of the recording: the periodic task up to it (a shaft that stopped before the
    // recording did times out where a firmware's poll would see it, not at the end of the
    // file), and a last poll there.
    if let Some(t0) = last_event {
        for p in polls.between(t0, end).into_iter().chain([end]) {
            let ticks = clock.ticks(p);
            clock.note(ticks, p, false);
            st.poll(&mut monitor, &clock, ticks, &mut report, on_decision);
        }
        // A window held for the edge after its frame, which the recording does not have, and
        // a second window the last call ended (handed by the next call): until none is left.
        loop {
            let o = monitor.release_held();
            let last = o.is_none();
            st.after(&mut monitor, &clock, o, &mut report, on_decision);
            if last {
                break;
            }
        }
    }
    let d = monitor.diagnostics();
    let e = d.edges;
    report.accepted = e.accepted;
    report.revolutions = e.revolutions;
    report.window_revolutions = monitor.window_revolutions();
    report.glitches = e.glitches;
    report.missing = e.missing;
    report.extra = e.extra;
    report.missing_frames = e.missing_frames;
    report.reversals = e.reversals;
    report.timeouts = e.timeouts;
    report.unexplained = e.unexplained;
    report.syncs = e.syncs;
    report.sync_losses = e.sync_losses;
    report.valid_windows = d.valid_windows;
    report.windows_listed = report.windows.len() as u64;
    report.faults_listed = report.faults.len() as u64;
    report.sync_changes_listed = report.sync.len() as u64;
    report.delta_every = st.deltas.stride.max(1);
    report.invalid_windows = d.invalid_windows;
    report.sync_state = sync_name(monitor.sync_state());
    report.index_period = periods.period(enc.edges());
    intervals.finish();
    // Ringing: most short intervals are an edge just after another, and they are a
    // hundredth of the captures or more.
    if intervals.ringing >= 3
        && intervals.ringing * 2 >= intervals.short
        && intervals.ringing * 100 >= report.captured
    {
        report.ringing = Some(Ringing {
            edges: intervals.ringing,
            of: report.captured,
            longest: intervals.longest_ring,
        });
    }
    // The same test on the other polarity's edges: where they ring and the edges read do
    // not, the crossings back are among the edges read as teeth.
    other.finish();
    if report.ringing.is_none()
        && other.bounces >= 3
        && other.bounces * 2 >= other.short
        && other.bounces * 100 >= other_edges
    {
        report.ringing_other_polarity = Some(Ringing {
            edges: other.bounces,
            of: other_edges,
            longest: other.longest_bounce,
        });
    }
    // Forward edges fed but neither accepted nor rejected: still waiting for their lookahead,
    // or time references after a standstill or a reversal.
    report.unjudged_at_end = report
        .captured
        .saturating_sub(u64::from(e.accepted) + u64::from(e.glitches) + report.reverse_edges);
    if report.sample_rate.is_none() {
        // The whole-nanosecond step, or a whole multiple of the period of an analyser's rate
        // that is not whole nanoseconds, to the precision the times are written to, if one
        // is longer.
        let whole = grid.step();
        match rate_grid.step() {
            Some(r) if whole.is_none_or(|w| r.period > w * (1.0 + 1e-9)) => {
                report.time_grid = Some(r.period);
                report.grid_of_rate = Some(r);
            }
            _ => report.time_grid = whole,
        }
    }
    // A grid of the sampling finer than the floats' is the digits' own (Unix times in an f64
    // printed to seven decimals lie on 100 ns, and on 2^-22 s to their rounding): no sample
    // period.
    let float_step = float_grid.step().map(|(e, _, _)| 2f64.powi(-e));
    if report.time_grid.zip(float_step).is_some_and(|(g, f)| g < f) {
        (report.time_grid, report.grid_of_rate) = (None, None);
    }
    report.float_grid = float_grid
        .step()
        .map(|(e, at, written)| FloatSpacing::of(e, at, written, report.time_origin));
    // Float values whose spacing grows over the capture (f32 times from 0 s) lie on no grid
    // coarser than their first spacing; each window takes the spacing at its own times. (Where
    // one grid holds them all, the float grid above says it.)
    report.float_times = float_values.found().filter(|f| {
        report
            .float_grid
            .as_ref()
            .is_none_or(|g| f.spacing_to > g.step)
    });
    if let Some(f) = &report.float_times {
        report.float_grid = None;
        // A grid of the rows finer than the floats' largest spacing is the digits' own.
        if report.time_grid.is_some_and(|g| g < f.spacing_to) {
            (report.time_grid, report.grid_of_rate) = (None, None);
        }
    }
    // A grid that is the digits' own step (times written to 100 ns lie on 100 ns whatever
    // sampled them) shows no sampling: one finer than the step lies hidden under it, and so
    // does a listed rate's whose period the digits cannot tell (6 MHz's 166.7 ns: every time
    // written to 100 ns lies within 50 ns of a point of it). The floor takes the digits'
    // rounding and the longest such period, else one more step.
    if let Some(g) = report.time_grid.filter(|_| report.grid_of_rate.is_none()) {
        let written = rate_grid.coarsest;
        if written > 0.0 && (g / written - 1.0).abs() < 1e-6 {
            let hidden_rate = rate_grid.slowest_fitting().filter(|r| 1.0 / r > g);
            report.digits_grid = Some(DigitsGrid {
                step: g,
                hidden_rate,
                resolution: g + hidden_rate.map_or(g, |r| 1.0 / r),
            });
        }
    }
    // The grid's resolution: a listed rate's period, to the digits' rounding of each time.
    let grid_resolution = match (&report.digits_grid, &report.grid_of_rate) {
        (Some(d), _) => Some(d.resolution),
        (None, Some(_)) => report
            .time_grid
            .map(|g| g + digits_rounding(g, written_finest)),
        (None, None) => report.time_grid,
    };
    // Each window's floor takes the file's sampling, or the resolution of its own rows where
    // that is coarser (a time is known to no better than either), and the grid of the floats
    // the times were held in where that is coarser still.
    // (A stated rate's period, too, with the digits' rounding of each time.)
    let file_step = report
        .sample_rate
        .map(|r| 1.0 / r + digits_rounding(1.0 / r, written_finest))
        .or(grid_resolution)
        .unwrap_or(0.0)
        .max(report.float_grid.as_ref().map_or(0.0, |f| f.resolution));
    report.sampling_resolution = (file_step > 0.0).then_some(file_step);
    let tick = 1.0 / cfg.encoder.timer_hz;
    for w in &mut report.windows {
        let local = resolution.over(w.start, w.end);
        let res = if local > file_step && local >= 0.1 * tick {
            local
        } else {
            file_step
        };
        let origin = report.time_origin as f64;
        let res = report.float_times.map_or(res, |f| {
            let at = (origin + w.start).abs().max((origin + w.end).abs());
            res.max(f.resolution(at))
        });
        if res > 0.0 {
            w.time_resolution = Some(res);
            w.floor_with_sampling = w.noise_floor.map(|f| f * (1.0 + res / tick));
        }
    }
    // Said where a block's resolution is coarser than the sampling (half again, and at least a
    // tenth of a tick): the coarsest, and from where it holds.
    let worst = resolution
        .changes
        .iter()
        .fold(0.0f64, |m, &(_, r)| m.max(r));
    if worst > 1.5 * file_step && worst >= 0.1 * tick {
        let from = resolution
            .changes
            .iter()
            .find(|&&(_, r)| r == worst)
            .map_or(0.0, |&(t, _)| t);
        report.coarser_times = Some((worst, from));
    }
    for w in &mut report.windows {
        if let (Some(d), Some(f)) = (w.delta, w.floor_with_sampling.or(w.noise_floor)) {
            w.resolved = Some(d > f);
        }
    }
    // Valid windows whose δ one edge off its neighbours' line can make by itself (half of it
    // or more): that edge's 2·f/K ([`DisplacedEdges`]).
    displaced.close_block();
    let Estimator::Edges(k) = cfg.encoder.estimator;
    let k = f64::from(k.max(1));
    // What the edges' scatter about their neighbours' cubic can read as δ, where it is more
    // than the floor: jitter σ (pitches) moves each K-edge sample by √2·σ/K, and the extremes
    // of N samples lie about 2·√(2·ln N) of that apart.
    let floors: Vec<f64> = report
        .windows
        .iter()
        .filter(|w| w.valid)
        .filter_map(|w| w.floor_with_sampling.or(w.noise_floor))
        .collect();
    if let (Some(sigma), false) = (displaced.jitter(), floors.is_empty()) {
        let n = report
            .windows
            .iter()
            .filter(|w| w.valid)
            .map(|w| f64::from(w.end_edge.wrapping_sub(w.start_edge)))
            .fold(2.0f64, f64::max);
        let delta = 2.0 * (2.0 * n.ln()).sqrt() * std::f64::consts::SQRT_2 * sigma / k;
        let mut sorted = floors;
        sorted.sort_by(f64::total_cmp);
        let floor = sorted[sorted.len() / 2];
        if delta > 2.0 * floor {
            report.edge_scatter = Some(EdgeScatter {
                pitches: sigma,
                delta,
                floor,
            });
        }
    }
    for w in &mut report.windows {
        // (A δ within its floor is said to be no measurement already.)
        let Some(d) = w.delta.filter(|_| w.valid && w.resolved != Some(false)) else {
            continue;
        };
        // Its first samples start K edges before its first.
        let edges = f64::from(w.end_edge.wrapping_sub(w.start_edge).max(1));
        let back = (w.end - w.start) * k / edges;
        if let Some((at, f)) = displaced.standout(w.start - back, w.end) {
            if 2.0 * f / k >= 0.5 * d {
                w.displaced_edge = Some(DisplacedEdge {
                    time: at,
                    pitches: f,
                });
                let e = report.displaced_edges.get_or_insert(DisplacedWindows {
                    windows: 0,
                    first: at,
                    largest: 0.0,
                });
                e.windows += 1;
                e.largest = e.largest.max(f);
            }
        }
    }
    report.channel_changes = channels
        .iter()
        .zip(changes)
        .map(|(name, changes)| ChannelChanges {
            name: name.clone(),
            changes,
        })
        .collect();
    if let Some((name, changes)) = quiet_direction(&report) {
        report.warnings.push(format!(
            "WARNING: the direction channel `{name}` changed {changes} time(s) over the {} \
             captured edges of `{}`, where a quadrature B channel changes twice a pitch: it is \
             not this encoder's B, or not connected (or the shaft only rocked across one of \
             A's line edges). Each edge of `{}` without a change of B is \
             no step forward of the quadrature count, and two such are fed as reverse (a shaft \
             at rest rocking across a line edge): leave --direction-channel out, or name the B \
             channel",
            report.captured, report.channel, report.channel
        ));
    }
    if cfg.framing_default {
        report.framing_note = Some(framing_note(&report, enc.config().wheel, ch, &among_read));
    }
    if let Some(w) = read_as_index(&report, ch, &read_among, enc.edges()) {
        report.warnings.push(w);
    }
    // Never synced, or lost again and again and not synced at the end: why, from the capture
    // (and from the other channels: the encoder may be another).
    if report.sync_acquired.is_none() || (report.sync_losses >= 2 && report.sync_state != "synced")
    {
        let busier = busier_channel(&report, &enc, ch, &read_among, dch.map(|(d, _)| d), ich);
        report.sync_hint = Some(sync_hint(
            &report,
            &enc,
            &runs,
            &intervals,
            polls.timeout,
            busier.as_ref(),
        ));
    }
    report.speed_trace.shrink_to_fit();
    Ok(report)
}

/// When most of a capture's edges came a pitch backward each (steadily the other way, not
/// rocking): that the disc may turn forward with the direction the other way round, and the
/// `--forward` that reads it so.
fn other_way(r: &AnalyzeReport) -> Option<String> {
    let lead = r.forward?;
    if r.backward_pitches * 2 <= r.captured {
        return None;
    }
    let d = r.direction_channel.as_deref().unwrap_or("B");
    let (a_leads, b_leads) = (
        format!("`{}` leading `{d}`", r.channel),
        format!("`{d}` leading `{}`", r.channel),
    );
    let (taken, other, option) = match lead {
        Lead::ALeads => (a_leads, b_leads, "b-leads"),
        Lead::BLeads => (b_leads, a_leads, "a-leads"),
    };
    Some(format!(
        " for most of the capture ({} of {} captures): a disc turning in reverse, or one turning \
         forward with {other} where the analysis took {taken}: if it turned forward, give \
         --forward {option}",
        r.backward_pitches, r.captured
    ))
}

/// The line saying that a disc of `--lines` without `--framing` was taken as unframed, naming
/// each other channel whose pulses come once every so many of the encoder channel's edges
/// (`among[k]`, at least 9 in 10 of its spacings within 1 % or one edge of that count), as an
/// index pulse does: once a revolution of `--lines`, or of another count, which `--lines`
/// then misstates (a count of pulses against edges alone read a 1000-line disc's index as
/// once a revolution of 1024).
fn framing_note(
    r: &AnalyzeReport,
    wheel: drive_monitor::encoder::Wheel,
    ch: usize,
    among: &[Spacing],
) -> String {
    let lines = u64::from(wheel.positions());
    let index_like: Vec<String> = r
        .channel_changes
        .iter()
        .zip(among)
        .enumerate()
        .filter(|&(k, _)| k != ch)
        .filter_map(|(k, (c, sp))| {
            let (every, n, total) = sp.regular().filter(|&(e, _, _)| e >= 2)?;
            // The index channel's default is the second column.
            let flag = if k == 1 {
                String::new()
            } else {
                format!(" --index-channel {k}")
            };
            let head = format!(
                "`{}` pulses once every {every} edges of `{}` ({n} of its {total} spacings)",
                c.name, r.channel
            );
            Some(if every == lines {
                format!(
                    "{head}: once a revolution of {lines} lines, as an index does; --framing \
                     index{flag} frames each revolution by it"
                )
            } else {
                format!(
                    "{head}, not every {lines} as an index of --lines {lines} would: if it is \
                     the index, the disc has {every} lines (--lines {every} --framing \
                     index{flag}), and speeds read with --lines {lines} are off by \
                     {every}/{lines}"
                )
            })
        })
        .collect();
    let mut s = "framing: none, the default without --framing: no index channel is read and the \
                 revolutions are counted from the first edges (a scene's [encoder] lines = N is \
                 framed by its index)"
        .to_string();
    for c in index_like {
        s.push_str("; ");
        s.push_str(&c);
    }
    s
}

/// Another channel with edges enough for 3 revolutions of the configured wheel and four times
/// as many as the channel read, which did not sync (`direction`: the B channel, which is not
/// it; the index channel `index` may be, the two swapped): its column, name and edges (half
/// its level changes), how many of its edges the channel read pulses once every, when it does
/// so regularly (as an index, or a cam signal), and whether it is the index channel. The channel read is likely not the encoder then: "too short" and
/// "stopped" would misname why it did not sync.
fn busier_channel(
    r: &AnalyzeReport,
    enc: &Encoder,
    ch: usize,
    among: &[Spacing],
    direction: Option<usize>,
    index: Option<usize>,
) -> Option<Busier> {
    let per_rev = u64::from(enc.edges().max(1)) * u64::from(enc.config().prescaler.max(1));
    let (k, c) = r
        .channel_changes
        .iter()
        .enumerate()
        .filter(|&(k, _)| k != ch && Some(k) != direction)
        .max_by_key(|&(_, c)| c.changes)?;
    let edges = c.changes / 2;
    if edges < 3 * per_rev || edges < 4 * r.edges.max(1) {
        return None;
    }
    Some(Busier {
        column: k,
        name: c.name.clone(),
        edges,
        revolutions: edges as f64 / per_rev as f64,
        pulses_every: among
            .get(k)
            .and_then(Spacing::regular)
            .map(|(e, _, _)| e)
            .filter(|&e| e >= 4),
        index_of: (Some(k) == index).then_some(ch),
    })
}

/// A channel busier than the one read ([`busier_channel`]).
struct Busier {
    column: usize,
    name: String,
    edges: u64,
    revolutions: f64,
    pulses_every: Option<u64>,
    /// It is the index channel: the channel read (this column) is then the index.
    index_of: Option<usize>,
}

/// A WARNING when the channel read pulses once every so many (4 or more) edges of another
/// channel (`among[k]`, regular as [`Spacing::regular`] says), as an index pulses among an
/// encoder's lines: the channels are likely the other way round (an index read as a disc of
/// lines reads a speed some lines-fold low, without another word). Each pulse is read as one
/// of the configured wheel's `edges` pitches: the speeds read are that many times too low,
/// whatever the other channel's count (they agree only where the wheel configured is the
/// encoder's).
fn read_as_index(r: &AnalyzeReport, ch: usize, among: &[Spacing], edges: u16) -> Option<String> {
    let (k, (every, n, total)) = among
        .iter()
        .enumerate()
        .filter(|&(k, _)| k != ch)
        .filter_map(|(k, sp)| sp.regular().filter(|&(e, _, _)| e >= 4).map(|x| (k, x)))
        .max_by_key(|&(_, (e, _, _))| e)?;
    let other = &r.channel_changes.get(k)?.name;
    Some(format!(
        "WARNING: `{read}`, the channel read, pulses once every {every} edges of `{other}` ({n} of \
         its {total} spacings), as an index pulses once a revolution of a disc's lines: if \
         `{other}` is the encoder, read it with --channel {k} (and frame by `{read}` with \
         --framing index --index-channel {ch}); read as it is, each of its pulses is taken for \
         one of the {edges} pitches a revolution configured, and the speeds are about {edges} \
         times too low",
        read = r.channel,
    ))
}

/// Edges that came just after the edge before ([`AnalyzeReport::ringing`]): most of the
/// intervals short against their neighbours are [`RING_RATIO`] of them or less, so the
/// signal crosses the threshold again at a transition, not a noise pulse between teeth.
#[derive(Debug, Clone, Serialize, PartialEq)]
pub struct Ringing {
    /// Captures less than [`RING_RATIO`] times their neighbours' geometric mean after the
    /// capture before.
    pub edges: u64,
    /// Captures of the channel read.
    pub of: u64,
    /// The longest of those intervals, s: an input filter must hold a level longer.
    pub longest: f64,
}

/// Captures at the time of the one before ([`AnalyzeReport::repeated_times`]).
#[derive(Debug, Clone, Default, Serialize)]
pub struct RepeatedTimes {
    /// How many.
    pub rows: u64,
    /// The file's line of the first, 1-based.
    pub first_line: u64,
    /// Its time, s, counted from `time_origin`.
    pub time: f64,
}

/// Spans without data on the channel read ([`AnalyzeReport::no_data`]).
#[derive(Debug, Clone, Default, Serialize)]
pub struct NoData {
    /// Spans.
    pub spans: u64,
    /// Their time in all, s.
    pub seconds: f64,
    /// The first span, s.
    pub first: [f64; 2],
}

/// How one channel's pulses (edges of the analysed polarity) fall among another channel's:
/// the other's edges counted between consecutive pulses, the distinct counts tallied (up to
/// [`SPACINGS`] of them; the rest only counted). The first pulse starts the count.
#[derive(Debug, Clone, Default)]
struct Spacing {
    since: u64,
    started: bool,
    tally: Vec<(u64, u64)>,
    untallied: u64,
}

/// Distinct spacings a [`Spacing`] tallies.
const SPACINGS: usize = 16;

impl Spacing {
    /// An edge of the other channel.
    fn other_edge(&mut self) {
        self.since += 1;
    }

    /// A pulse of this channel.
    fn pulse(&mut self) {
        if self.started {
            let s = self.since;
            let room = self.tally.len() < SPACINGS;
            match self.tally.iter_mut().find(|v| v.0 == s) {
                Some(v) => v.1 += 1,
                None if room => self.tally.push((s, 1)),
                None => self.untallied += 1,
            }
        }
        self.started = true;
        self.since = 0;
    }

    /// The count most spacings share, when at least 2 spacings and 9 in 10 of them lie within
    /// 1 % or one edge of it (a noise pulse adds an edge now and then): `(count, spacings
    /// near it, spacings)`.
    fn regular(&self) -> Option<(u64, u64, u64)> {
        let total = self.tally.iter().map(|v| v.1).sum::<u64>() + self.untallied;
        let &(every, _) = self.tally.iter().max_by_key(|v| (v.1, v.0))?;
        let near = self
            .tally
            .iter()
            .filter(|v| v.0.abs_diff(every) <= (every / 100).max(1))
            .map(|v| v.1)
            .sum::<u64>();
        (near >= 2 && 10 * near >= 9 * total).then_some((every, near, total))
    }
}

/// The step every row's time lies on, from the first row's, in whole nanoseconds (the
/// greatest common divisor of the offsets): a capture's sample period when the file does not
/// state its rate (Saleae Logic 2 writes nine decimals).
#[derive(Default)]
struct TimeGrid {
    first: Option<i64>,
    /// The divisor so far (0: no offset yet); `None` once a time is not whole nanoseconds.
    gcd: Option<u64>,
}

impl TimeGrid {
    fn row(&mut self, t: f64) {
        let ns = t * 1e9;
        let whole = ns.round();
        // Not whole nanoseconds (to the rounding of the decimal time), or beyond 1e5 s where
        // f64 no longer tells them: no grid.
        if !(whole.abs() < 1e14 && (ns - whole).abs() <= 1e-2 + 1e-15 * whole.abs()) {
            self.gcd = None;
            self.first = Some(0);
            return;
        }
        let n = whole as i64;
        match self.first {
            None => {
                self.first = Some(n);
                self.gcd = Some(0);
            }
            Some(f) => {
                if let Some(g) = self.gcd {
                    let (mut a, mut b) = (g, n.abs_diff(f));
                    while b != 0 {
                        (a, b) = (b, a % b);
                    }
                    self.gcd = Some(a);
                }
            }
        }
    }

    /// The step, s, when it is at least 2 ns.
    fn step(&self) -> Option<f64> {
        self.gcd.filter(|&g| g >= 2).map(|g| g as f64 * 1e-9)
    }
}

/// Sample rates of logic analysers whose period is not a whole number of nanoseconds (the
/// FX2-based analysers' 48, 24, 16, 12, 6 and 3 MHz), Hz: a file that writes their times to
/// the nanosecond lies on no whole-nanosecond grid ([`TimeGrid`]), nor one written to finer
/// digits on any whole-unit grid, and is tested against each ([`RateGrid`]), and so is a rate
/// whose period is a whole multiple of one of theirs (750 kHz, 4 periods of 3 MHz).
pub const ODD_RATES: [f64; 6] = [48e6, 24e6, 16e6, 12e6, 6e6, 3e6];

/// Transitions a grid test needs whose time is written finely enough to tell the grid (the
/// precision a quarter of its step or less) before it names a grid: such a time lies on a
/// grid by chance at most one time in two, 64 of them practically never.
const GRID_ROWS: u64 = 64;

/// The greatest common divisor (`gcd(0, b)` is `b`).
fn gcd(mut a: u64, mut b: u64) -> u64 {
    while b != 0 {
        (a, b) = (b, a % b);
    }
    a
}

/// How far a time, written to `precision` s, may lie from the instant it stands for, s: half
/// the precision, and the rounding of an f64 near `t` (a few units in the last place, as
/// times computed in floating point and written in full carry).
fn written_tolerance(t: f64, precision: f64) -> f64 {
    0.5 * precision + 8.0 * f64::EPSILON * t.abs()
}

/// A grid of a whole multiple of the period of one of [`ODD_RATES`], from [`RateGrid`].
#[derive(Debug, Clone, Copy, Serialize)]
pub struct RateGridFound {
    /// The grid's step, s: `multiple` periods of `rate`.
    pub period: f64,
    /// The analyser rate whose grid the times lie on, Hz.
    pub rate: f64,
    /// How many of its periods the step is (the greatest common divisor of every
    /// transition's count of periods from the first).
    pub multiple: u64,
    /// The coarsest precision the transitions' times are written to, s.
    pub written_to: f64,
}

/// For each of [`ODD_RATES`]: whether every transition's time lies on its grid from the first
/// transition's, to the precision each is written to (a 12 MS/s capture's times in a Saleae
/// export: 83.333 ns apart, rounded to the nanosecond, or to 1e-15 s in Logic 1.x's fifteen
/// decimals, or to a value change dump's picosecond), and the greatest common divisor of their
/// counts of periods (a 750 kS/s capture lies on the 3 MHz grid too, every fourth point).
#[derive(Default)]
struct RateGrid {
    /// The first transition's time and precision.
    first: Option<(f64, f64)>,
    dead: [bool; ODD_RATES.len()],
    multiple: [u64; ODD_RATES.len()],
    /// What the transitions tell of the grid, in bits: a time within `tol` of the grid by
    /// chance has odds `2·tol/period`, and each counts `log2(period/(2·tol))`, at most 1 (a
    /// time written to a quarter of the period or finer counts 1; one written to 1e-7 s of a
    /// 3 MHz grid, 0.74; one whose tolerance spans half the period or more, nothing).
    telling: [f64; ODD_RATES.len()],
    coarsest: f64,
}

impl RateGrid {
    fn row(&mut self, t: f64, precision: f64) {
        self.coarsest = self.coarsest.max(precision);
        let Some((t0, p0)) = self.first else {
            self.first = Some((t, precision));
            return;
        };
        let d = t - t0;
        if self.dead.iter().all(|&d| d) {
            return;
        }
        let tol = written_tolerance(t, precision) + written_tolerance(t0, p0);
        for (i, rate) in ODD_RATES.iter().enumerate() {
            if self.dead[i] {
                continue;
            }
            let period = 1.0 / rate;
            let k = (d * rate).round();
            if !(k < 9e15 && (d - k * period).abs() <= tol) {
                self.dead[i] = true;
                continue;
            }
            if 2.0 * tol < period {
                self.telling[i] += (period / (2.0 * tol)).log2().min(1.0);
            }
            if self.multiple[i] != 1 {
                self.multiple[i] = gcd(self.multiple[i], k as u64);
            }
        }
    }

    /// The longest step every transition lies on, of the rates alive once the transitions
    /// tell their grid by [`GRID_ROWS`] bits.
    fn step(&self) -> Option<RateGridFound> {
        (0..ODD_RATES.len())
            .filter(|&i| {
                !self.dead[i] && self.telling[i] >= GRID_ROWS as f64 && self.multiple[i] > 0
            })
            .map(|i| RateGridFound {
                period: self.multiple[i] as f64 / ODD_RATES[i],
                rate: ODD_RATES[i],
                multiple: self.multiple[i],
                written_to: self.coarsest,
            })
            // The slowest rate of a step found on several (750 kHz: 4 periods of 3 MHz, not
            // 8 of 6 MHz).
            .reduce(|a, b| {
                if b.period >= a.period * (1.0 - 1e-9) {
                    b
                } else {
                    a
                }
            })
    }
}

impl RateGrid {
    /// The slowest of [`ODD_RATES`] every transition lies on, told or not: a grid of one the
    /// digits cannot tell (6 MHz's 166.7 ns in times written to 100 ns) may have sampled
    /// them.
    fn slowest_fitting(&self) -> Option<f64> {
        (0..ODD_RATES.len())
            .filter(|&i| self.first.is_some() && !self.dead[i])
            .map(|i| ODD_RATES[i])
            .reduce(f64::min)
    }
}

/// What rounding to `written` s adds to a time known to a sample `period` (s): the
/// precision, up to one period, where the period is no whole number of it (333.33 ns written
/// to 100 ns; a period of 20 ns written to 1 ns, or a dump's samples in its time unit, are
/// exact), and none where it is below a thousandth of the period.
fn digits_rounding(period: f64, written: f64) -> f64 {
    let n = period / written;
    if !(written > 0.0 && written.is_finite() && n < 1e3) || (n - n.round()).abs() < 1e-6 * n {
        0.0
    } else {
        written.min(period)
    }
}

/// A grid of the rows that is the precision their times are written to (100 ns at seven
/// decimals): the digits' own step, under which any sampling finer than it, and that of a rate
/// the digits cannot tell, lies hidden (a 6 MHz capture written to 100 ns).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct DigitsGrid {
    /// The step, s: the grid the rows show and the precision they are written to.
    pub step: f64,
    /// The slowest analyser rate of [`ODD_RATES`] every transition fits, when its period is
    /// longer than the step, Hz.
    pub hidden_rate: Option<f64>,
    /// The resolution taken for the floor, s: the digits' rounding (the step) and a sampling
    /// hidden under them (that rate's period, else up to one step).
    pub resolution: f64,
}

/// A power-of-two grid of seconds that every transition's time lies on, coarser than the
/// precision they are written to: times held as floats before they were written (an f64 near
/// a Unix time of 1.76e9 s resolves 2^-22 s, 0.24 µs; an f32 at 5 s 2^-21 s), which a reader
/// of their decimals cannot see.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct FloatSpacing {
    /// The grid, s (2^-`exponent`).
    pub step: f64,
    /// The resolution taken for the floor, s: the grid (a float rounds the instant to the
    /// nearest point of it), and the precision the times are written to, up to one step
    /// more (printed from the float, a time lies within half a step of it: `5.001029` for an
    /// f32 at 5 s).
    pub resolution: f64,
    /// The grid's exponent: the step is 2^-exponent s.
    pub exponent: i32,
    /// The first transition's time, s, as the file writes it (before the whole seconds are
    /// counted off).
    pub at: f64,
    /// The float whose spacing the grid is at that time: `f64`, `f32`, or none of them (a
    /// sample clock of a power of two of Hz).
    pub float: Option<&'static str>,
}

impl FloatSpacing {
    /// The grid `2^-exponent` s found on times from `first` s (counted from `origin` s).
    fn of(exponent: i32, first: f64, written_to: f64, origin: i64) -> Self {
        let at = origin as f64 + first;
        let step = 2f64.powi(-exponent);
        // Spacing of a float of `bits` mantissa bits (the leading one included) at `at`.
        let spacing = |bits: i32| 2f64.powi(at.abs().log2().floor() as i32 - (bits - 1));
        let float = if at == 0.0 {
            None
        } else if spacing(53) == step {
            Some("f64")
        } else if spacing(24) == step {
            Some("f32")
        } else {
            None
        };
        FloatSpacing {
            step,
            resolution: step + written_to.min(step),
            exponent,
            at,
            float,
        }
    }
}

/// Exponents of the power-of-two grids [`FloatGrid`] tests: 2^0 down to 2^-63 s.
const FLOAT_EXPONENTS: usize = 64;

/// Which power-of-two grids of seconds every transition's time lies on, to the precision it
/// is written to, and how many of them tell each grid (written to a quarter of its step or
/// finer). Times counted from whole seconds lie on such a grid of 1 s or finer as the
/// absolute times do.
///
/// A time within `tol` of a point of 2^-e s lies within `2·tol` of one of 2^-(e+1) s, which is
/// the same tolerance on that grid: the grids a time lies on are every one from some exponent
/// on, and those every time lies on are every one from the largest such exponent (`from`). So
/// each row is tested at `from` alone (and `from` moved on while it fails), and a row tells
/// every grid up to its own exponent ([`Self::telling`] counts rows by it).
#[derive(Default)]
struct FloatGrid {
    /// The coarsest grid every time so far lies on: 2^-`from` s (`FLOAT_EXPONENTS`: none).
    from: usize,
    /// Rows by the finest grid they tell (its exponent).
    telling: Vec<u64>,
    first: Option<f64>,
    /// The coarsest precision of the times.
    coarsest: f64,
}

impl FloatGrid {
    fn row(&mut self, t: f64, precision: f64) {
        if self.telling.is_empty() {
            self.telling = vec![0; FLOAT_EXPONENTS];
        }
        self.first.get_or_insert(t);
        self.coarsest = self.coarsest.max(precision);
        let tol = written_tolerance(t, precision);
        while self.from < FLOAT_EXPONENTS {
            let scale = f64::from_bits((1023 + self.from as u64) << 52);
            let x = t * scale;
            if (x - x.round()).abs() <= tol * scale {
                break;
            }
            self.from += 1;
        }
        // The finest grid 2^-e s with 4·tol·2^e ≤ 1: tol = m·2^q (1 ≤ m < 2) tells down to
        // e = −q − 2, one less when m > 1 (a normal tol; a subnormal one tells every grid).
        let bits = tol.to_bits();
        let q = ((bits >> 52) & 0x7ff) as i64 - 1023;
        let finest = if tol > 0.0 && q > -1023 {
            -q - 2 - i64::from(bits & ((1 << 52) - 1) != 0)
        } else {
            (FLOAT_EXPONENTS - 1) as i64
        };
        if let Ok(e) = usize::try_from(finest) {
            self.telling[e.min(FLOAT_EXPONENTS - 1)] += 1;
        }
    }

    /// The coarsest grid every time lies on that [`GRID_ROWS`] transitions or more tell: its
    /// exponent, the first transition's time, and the coarsest precision the times are
    /// written to.
    fn step(&self) -> Option<(i32, f64, f64)> {
        let from = self.from;
        let told: u64 = self.telling.get(from..)?.iter().sum();
        (told >= GRID_ROWS).then_some((from as i32, self.first?, self.coarsest))
    }
}

/// Mantissa bits (the leading one included) of the floats [`FloatValues`] tests: f32, f64.
const FLOAT_BITS: [(i32, &str); 2] = [(24, "f32"), (53, "f64")];

/// The spacing of floats of `bits` mantissa bits at `x` (s): 2^-(bits-1) of the power of two
/// at or below |x|; 0 at 0.
fn float_spacing(x: f64, bits: i32) -> f64 {
    if x == 0.0 || !x.is_finite() {
        return 0.0;
    }
    let e = ((x.abs().to_bits() >> 52) & 0x7ff) as i32 - 1023;
    2f64.powi(e - (bits - 1))
}

/// Times held as floats of one type, from a capture whose times span magnitudes where the
/// float's spacing differs (from [`FloatValues`]).
#[derive(Debug, Clone, Copy, Serialize)]
pub struct FloatTimes {
    /// `f32` or `f64`.
    pub float: &'static str,
    /// Mantissa bits, the leading one included: the spacing at a time is 2^-(bits-1) of the
    /// power of two at or below it.
    pub bits: i32,
    /// The smallest magnitude of the transitions' times, s, as the file writes them (before
    /// whole seconds are counted off).
    pub from: f64,
    /// The largest.
    pub to: f64,
    /// The float's spacing at `from`, s.
    pub spacing_from: f64,
    /// The float's spacing at `to`, s.
    pub spacing_to: f64,
    /// The coarsest precision the times are written to, s.
    pub written_to: f64,
    /// The finest.
    pub finest_written: f64,
}

impl FloatTimes {
    /// The resolution of a time of magnitude up to `at` s (as written): the float's spacing
    /// there (the float rounds the instant to its nearest value), and the digits' rounding:
    /// their precision, where times are written to fixed decimals, but no more than the
    /// spacing where they are written as the shortest decimal that reads back as the float.
    pub fn resolution(&self, at: f64) -> f64 {
        let spacing = float_spacing(at, self.bits);
        spacing + self.written_to.min(spacing.max(self.finest_written))
    }
}

/// Whether every transition's time, as written, is a value of f32 (or f64) at its own
/// magnitude, to the precision it is written to: the test [`FloatGrid`] makes, with the grid
/// the float's spacing at each time rather than one for the file (an f32 near 0.001 s
/// resolves 1.2e-10 s, near 0.1 s 7.5e-9 s, near 1 s 1.2e-7 s). A time tells its float when
/// written to a quarter of the spacing or finer; [`GRID_ROWS`] such rows are needed.
#[derive(Default)]
struct FloatValues {
    /// Per float of [`FLOAT_BITS`]: a time off its values, and rows that tell it.
    dead: [bool; FLOAT_BITS.len()],
    telling: [u64; FLOAT_BITS.len()],
    /// Smallest and largest magnitude of the times, s (as written).
    from: f64,
    to: f64,
    written_to: f64,
    finest_written: f64,
    rows: u64,
}

impl FloatValues {
    /// A transition at `t` s counted from `origin` whole seconds, written to `precision` s.
    fn row(&mut self, t: f64, precision: f64, origin: i64) {
        let at = (origin as f64 + t).abs();
        if self.rows == 0 {
            (self.from, self.to, self.finest_written) = (at, at, precision);
        }
        self.rows += 1;
        self.from = self.from.min(at);
        self.to = self.to.max(at);
        self.written_to = self.written_to.max(precision);
        self.finest_written = self.finest_written.min(precision);
        let tol = written_tolerance(t, precision);
        for (i, &(bits, _)) in FLOAT_BITS.iter().enumerate() {
            if self.dead[i] || at == 0.0 {
                continue;
            }
            let spacing = float_spacing(at, bits);
            // Whole seconds (and the origin, a whole number) lie on every spacing up to 1 s.
            if !(spacing > 0.0 && spacing <= 1.0) {
                self.dead[i] = true;
                continue;
            }
            let x = t / spacing;
            if (x - x.round()).abs() > tol / spacing {
                self.dead[i] = true;
                continue;
            }
            if 4.0 * tol <= spacing {
                self.telling[i] += 1;
            }
        }
    }

    /// The narrowest float every time is a value of, when [`GRID_ROWS`] rows tell it.
    fn found(&self) -> Option<FloatTimes> {
        let i = (0..FLOAT_BITS.len()).find(|&i| !self.dead[i] && self.telling[i] >= GRID_ROWS)?;
        let (bits, float) = FLOAT_BITS[i];
        Some(FloatTimes {
            float,
            bits,
            from: self.from,
            to: self.to,
            spacing_from: float_spacing(self.from, bits),
            spacing_to: float_spacing(self.to, bits),
            written_to: self.written_to,
            finest_written: self.finest_written,
        })
    }
}

/// Rows a block of [`Resolution`] holds: few enough to follow a resolution that changes along
/// the file, enough that times on a fine grid practically never share a coarser step by chance
/// (31 offsets all even: 1 in 2·10⁹; with 16 rows, 1 in 32 768 blocks, and a capture of 10
/// minutes has some 40 000).
pub const BLOCK_ROWS: usize = 32;

/// The resolution of the times along the file, block by block of [`BLOCK_ROWS`] rows: the step
/// the block's times lie on ([`TimeGrid`]) as decimal times written to fewer digits resolve
/// (the largest power of ten of nanoseconds dividing it), or what f64 numbers resolve at its
/// largest time, whichever is coarser. Kept where it changes, for at most [`MAX_LISTED`]
/// changes.
///
/// A block whose rows come equally spaced says nothing of the step: a steady signal on a fine
/// grid lies on its own spacing (the kneader's capture at 50 MS/s, 1166 samples between rows
/// where the speed turns, read as times resolved to 23.32 µs, and every window of δ 0.031 as
/// within a floor of 0.064); nor does a step of such a signal's few spacings that no power of
/// ten divides. (A steady signal whose spacings are all multiples of a power of ten coarser
/// than the grid still reads as resolved to it: 20 and 40 µs to 10 µs.)
#[derive(Default)]
struct Resolution {
    /// The timer clock, Hz.
    hz: f64,
    block: TimeGrid,
    rows: usize,
    start: f64,
    largest: f64,
    /// The block's previous row's time, the spacing before it (whole ns; rows at one time
    /// left out), and whether two spacings differ.
    previous: Option<f64>,
    spacing: Option<i64>,
    varied: bool,
    /// (the first row's time of a block, its resolution) where the resolution changes.
    changes: Vec<(f64, f64)>,
}

impl Resolution {
    fn row(&mut self, t: f64) {
        if self.rows == 0 {
            self.block = TimeGrid::default();
            (self.start, self.largest) = (t, 0.0);
            (self.previous, self.spacing, self.varied) = (None, None, false);
        }
        if let Some(t0) = self.previous.replace(t) {
            let ns = ((t - t0) * 1e9).round() as i64;
            if ns != 0 {
                self.varied |= self.spacing.is_some_and(|s| s != ns);
                self.spacing = Some(ns);
            }
        }
        self.block.row(t);
        self.largest = self.largest.max(t.abs());
        self.rows += 1;
        if self.rows == BLOCK_ROWS {
            self.close();
        }
    }

    /// Ends a whole block (a shorter one at the end of the file is left out: a few offsets
    /// share a coarser step by chance too often).
    fn close(&mut self) {
        if self.rows == BLOCK_ROWS && self.largest.is_finite() {
            // A time read to the nearest f64, and its ticks the floor of its product with the
            // clock rounded to the nearest f64: the spacings at both (in s).
            let spacing = |x: f64| f64::from_bits(x.to_bits() + 1) - x;
            let f64s = spacing(self.largest) + spacing(self.largest * self.hz) / self.hz;
            let step = self
                .block
                .gcd
                .filter(|_| self.varied)
                .map_or(0.0, |g| decimal_step(g) as f64 * 1e-9);
            let res = step.max(f64s);
            let full = self.changes.len() >= MAX_LISTED;
            match self.changes.last_mut() {
                Some((_, r)) if *r == res => {}
                // Memory bounded whatever the file's length: past the last entry kept, the
                // coarsest is kept (a floor only widens).
                Some((_, r)) if full => *r = r.max(res),
                _ => self.changes.push((self.start, res)),
            }
        }
        self.rows = 0;
    }

    /// The coarsest resolution of the blocks over `[start, end]` (0 when none is known).
    fn over(&self, start: f64, end: f64) -> f64 {
        let from = self
            .changes
            .partition_point(|&(t, _)| t <= start)
            .saturating_sub(1);
        self.changes[from..]
            .iter()
            .take_while(|&&(t, _)| t <= end)
            .fold(0.0, |r, &(_, x)| r.max(x))
    }
}

/// The largest power of ten dividing `ns` (1 for 0).
fn decimal_step(mut ns: u64) -> u64 {
    let mut p = 1;
    while ns != 0 && ns % 10 == 0 {
        (ns, p) = (ns / 10, p * 10);
    }
    p
}

/// The firmware's periodic task between two events.
struct Polls {
    /// Poll interval, s.
    every: f64,
    /// The core's timeout, s.
    timeout: f64,
    /// When the last poll was made, s.
    last: f64,
}

impl Polls {
    /// The times of the polls after the event at `t0` and before `t`, every [`Polls::every`],
    /// taken as made. A poll finds nothing until the timeout has passed: only the ones around
    /// it are made.
    fn between(&mut self, t0: f64, t: f64) -> Vec<f64> {
        let mut times = Vec::new();
        let mut p = self.last.max(t0 + self.timeout - 2.0 * self.every).max(t0) + self.every;
        while p < t && p <= t0 + self.timeout + 2.0 * self.every {
            times.push(p);
            self.last = p;
            p += self.every;
        }
        times
    }
}

/// A plot's trace kept to at most [`MAX_TRACE`] points: every `stride`-th point offered,
/// the stride doubled and the trace halved each time it fills.
#[derive(Default)]
struct Decimated {
    /// Keep every `stride`-th point (0 before the first: 1); `skipped` since the last kept.
    stride: u64,
    skipped: u64,
}

impl Decimated {
    fn offer(&mut self, trace: &mut Vec<(f64, f64)>, point: Option<(f64, f64)>) {
        self.stride = self.stride.max(1);
        self.skipped += 1;
        if self.skipped < self.stride {
            return;
        }
        self.skipped = 0;
        if let Some(p) = point {
            trace.push(p);
        }
        if trace.len() >= MAX_TRACE {
            // Halve the trace and keep every other point from now on.
            let kept: Vec<(f64, f64)> = trace.iter().step_by(2).copied().collect();
            *trace = kept;
            self.stride *= 2;
        }
    }
}

/// The analysis state between calls to the monitor.
struct State {
    seen: Seen,
    /// Times of recent frame teeth by accepted-edge number (window starts).
    frames: VecDeque<(u32, f64)>,
    sync: SyncState,
    /// The decimation of the speed trace and of the δ trace.
    speeds: Decimated,
    deltas: Decimated,
    max_revs: usize,
    /// Missing frames accounted for in the fault list (listed, or left out past its cap).
    frames_listed: u32,
}

impl State {
    /// Polls the monitor at `ticks`, observing what the poll decides (the edges it judges
    /// once the shaft has stopped, the timeout) like any edge.
    fn poll(
        &mut self,
        monitor: &mut DeltaMonitor<MAX_LINES>,
        clock: &Clock,
        ticks: u32,
        report: &mut AnalyzeReport,
        on_decision: &mut dyn FnMut(&Decision),
    ) {
        let o = monitor.poll_observed(ticks, &mut self.seen);
        self.after(monitor, clock, o, report, on_decision);
    }

    /// Takes what the monitor reported during one call.
    fn after(
        &mut self,
        monitor: &mut DeltaMonitor<MAX_LINES>,
        clock: &Clock,
        outcome: Option<WindowOutcome>,
        report: &mut AnalyzeReport,
        on_decision: &mut dyn FnMut(&Decision),
    ) {
        let unit = f64::from(monitor.encoder().unit_rad());
        let hz = clock.hz;
        // The first synced tooth of these events.
        let mut synced_at = None;
        for (ticks, ev) in self.seen.events.drain(..) {
            let time = clock.time(ticks);
            let kind = match ev {
                Event::Tooth(t) => {
                    let speed = t
                        .sample
                        .filter(|s| s.ticks > 0)
                        .map(|s| f64::from(s.span) * unit * hz / f64::from(s.ticks));
                    if t.frame {
                        if self.frames.len() > self.max_revs + 4 {
                            self.frames.pop_front();
                        }
                        self.frames.push_back((t.index, time));
                    }
                    if let Some(w) = speed.filter(|_| t.synced) {
                        self.speeds.offer(&mut report.speed_trace, Some((time, w)));
                    }
                    if t.synced && synced_at.is_none() {
                        synced_at = Some(time);
                    }
                    DecisionKind::Tooth {
                        tooth: t.tooth,
                        synced: t.synced,
                        frame: t.frame,
                        speed,
                    }
                }
                Event::Fault(f) => {
                    if f == Fault::MissingFrame {
                        self.frames_listed += 1;
                    }
                    report.faults_total += 1;
                    if report.faults.len() < MAX_LISTED {
                        report.faults.push(FaultOut {
                            time,
                            fault: f.name(),
                        });
                    }
                    DecisionKind::Fault(f)
                }
            };
            on_decision(&Decision { time, kind });
        }
        // The core counts some missing frames without a fault event (a search of three
        // revolutions' worth of edges that found no frame, an index pulse that framed no edge,
        // one dropped when four waited): each is listed at the edge or poll after which it
        // was counted, so that the list agrees with the count.
        let counted = monitor.diagnostics().edges.missing_frames;
        while self.frames_listed < counted {
            self.frames_listed += 1;
            let time = clock.latest.1;
            report.faults_total += 1;
            if report.faults.len() < MAX_LISTED {
                report.faults.push(FaultOut {
                    time,
                    fault: Fault::MissingFrame.name(),
                });
            }
            on_decision(&Decision {
                time,
                kind: DecisionKind::Fault(Fault::MissingFrame),
            });
        }
        let s = monitor.sync_state();
        if s != self.sync {
            self.sync = s;
            // Synced at the tooth the count begins at (judged with the edges after it: listed
            // at the last of them, the list disagreed with the tooth's time); the first such
            // is when sync was acquired.
            let time = match (s, synced_at) {
                (SyncState::Synced, Some(t)) => t,
                _ => clock.latest.1,
            };
            if s == SyncState::Synced && report.sync_acquired.is_none() {
                report.sync_acquired = Some(time);
            }
            report.sync_changes_total += 1;
            if report.sync.len() < MAX_LISTED {
                report.sync.push(SyncOut {
                    time,
                    state: sync_name(s),
                });
            }
        }
        if let Some(o) = outcome {
            self.window(&o.report, clock, report);
        }
    }

    fn window(&mut self, r: &WindowReport, clock: &Clock, report: &mut AnalyzeReport) {
        let at = |edge: u32, ticks: u32| {
            self.frames
                .iter()
                .rev()
                .find(|(i, _)| *i == edge)
                .map_or_else(|| clock.time(ticks), |&(_, t)| t)
        };
        let m = r.measurement();
        let end = if r.valid() {
            at(r.end_edge, r.end_ticks)
        } else {
            clock.time(r.end_ticks)
        };
        // Every window to the δ plot (those with a δ), every `stride`-th past MAX_TRACE.
        self.deltas.offer(
            &mut report.delta_trace,
            m.map(|m| (end, f64::from(m.delta))),
        );
        report.windows_total += 1;
        if report.windows.len() >= MAX_LISTED {
            return;
        }
        let f = |x: f32| Some(f64::from(x));
        report.windows.push(WindowOut {
            start: at(r.start_edge, r.start_ticks),
            end,
            start_edge: r.start_edge,
            end_edge: r.end_edge,
            revolutions: r.revolutions,
            valid: r.valid(),
            fault: r.fault().map(Fault::name),
            delta: m.and_then(|m| f(m.delta)),
            omega_mean: m.and_then(|m| f(m.omega_mean)),
            omega_max: m.and_then(|m| f(m.omega_max)),
            omega_min: m.and_then(|m| f(m.omega_min)),
            noise_floor: m.and_then(|m| f(m.noise_floor)),
            floor_with_sampling: None,
            time_resolution: None,
            steady: m.map(|m| m.steady),
            resolved: None,
            displaced_edge: None,
        });
    }
}

/// The report as text.
pub fn text(r: &AnalyzeReport) -> String {
    use std::fmt::Write as _;
    let mut s = String::new();
    let _ = writeln!(
        s,
        "capture: {} ({} format, {} rows, {:.6} s to {:.6} s)",
        r.file, r.format, r.rows, r.span[0], r.span[1]
    );
    if let (Some(column), Some(rate)) = (&r.sample_numbers, r.sample_rate) {
        let _ = writeln!(
            s,
            "times: the sample numbers of `{column}` over --sample-rate {rate} Hz (a rate other \
             than the capture's scales every time and speed by its error)"
        );
    }
    if r.time_unit != "s" {
        let _ = writeln!(
            s,
            "times: in {} (the header's unit, or --time-unit's), converted to seconds below",
            r.time_unit
        );
    }
    if r.time_origin != 0 {
        let _ = writeln!(
            s,
            "times: counted from {} s, the whole seconds of the file's first time (read exactly)",
            r.time_origin
        );
    }
    let _ = writeln!(
        s,
        "channel: {} ({}){}{}",
        r.channel,
        match (r.edges_listed(), r.threshold) {
            (true, _) => "edge times: each row a captured edge".to_string(),
            (false, None) => format!("{} edges", r.edge),
            (false, Some(t)) => format!(
                "{} edges of its values read at --threshold {} with --hysteresis {}: high above \
                 {}, low below {}; each edge at the first sample past its level, and the floors \
                 below the timing's alone: the signal's noise moves a crossing by the noise \
                 over the signal's slope there, which they do not hold",
                r.edge,
                t.volts,
                t.hysteresis,
                t.volts + 0.5 * t.hysteresis,
                t.volts - 0.5 * t.hysteresis
            ),
        },
        r.index_channel
            .as_ref()
            .map_or(String::new(), |i| format!(", index channel {i}")),
        match (&r.direction_channel, r.forward) {
            (Some(d), Some(lead)) => format!(
                ", direction from {d} (forward: {} leads)",
                if lead == Lead::ALeads {
                    r.channel.as_str()
                } else {
                    d.as_str()
                }
            ),
            _ => String::new(),
        }
    );
    for w in &r.warnings {
        let _ = writeln!(s, "{w}");
    }
    if let Some(n) = &r.no_data {
        let _ = writeln!(
            s,
            "WARNING: `{}` had no data (unknown level) over {} span(s), {:.6} s in all, the first \
             from {:.6} to {:.6} s: its edges there were not seen, and the missing edges, sync \
             losses and invalid windows there are the capture's, not the encoder's",
            r.channel, n.spans, n.seconds, n.first[0], n.first[1]
        );
    }
    if let Some(g) = &r.ringing {
        let _ = writeln!(
            s,
            "WARNING: `{}` rings: {} of its {} captured edges came within {:.3e} s of the edge \
             before (a tenth of the intervals beside them or less): the signal crosses the \
             threshold again at a transition (ringing, or a contact's bounce), and each crossing \
             is an edge; the core rejects them as glitches or counts them as extra edges, but a \
             window holding either is invalid. The edges of the other polarity are no cure: a crossing back is one of \
             them. Filter the crossings out before the edges are timed (analyze takes the edges \
             as recorded): a Schmitt-trigger input or the sensor's own hysteresis on the line, \
             or the capture timer's input filter, which takes a level only once it has held \
             longer than its setting (the example firmware's TIM2 filter, for 47 ns): here more \
             than {:.3e} s, and the edge it takes is then the ringing's last crossing",
            r.channel, g.edges, g.of, g.longest, g.longest
        );
    }
    if let Some(e) = &r.displaced_edges {
        let _ = writeln!(
            s,
            "WARNING: in {} valid window(s) one edge lies off the line of its neighbours by up \
             to {:.1} % of a pitch (the first at {:.6} s), enough to make half the window's δ or \
             more by itself (2·f/K with K-edge samples): their δ is that edge's, not the \
             shaft's. A noise pulse that merges with a tooth moves its edge so (the core takes \
             it, its intervals being within the accept band); so does one tooth's pitch error, \
             every revolution (a per-tooth correction learns that). Marked \"δ from one edge\" \
             below",
            e.windows,
            100.0 * e.largest,
            e.first
        );
    }
    if let Some(g) = &r.ringing_other_polarity {
        let (read, other) = match r.edge {
            "falling" => ("falling", "rising"),
            _ => ("rising", "falling"),
        };
        let _ = writeln!(
            s,
            "WARNING: `{}` rings at its {other} transitions: {} of its {} {other} edges came \
             within {:.3e} s of the one before (a quarter of the intervals beside them or \
             less). \
             Such a transition crosses the threshold back and again, and the crossing back is a \
             {read} edge: the {read} edges read hold one at each ringing transition besides \
             the teeth, a pulse train up to twice the teeth's that the core can take as clean, \
             so the speed and δ of its windows can be wrong although valid. Filter the \
             crossings out before the edges are timed (a Schmitt-trigger input, the sensor's \
             hysteresis, or the capture timer's input filter set longer than {:.3e} s), or \
             read the {other} edges (`--edge {other}`) to see the ringing counted as glitches",
            r.channel, g.edges, g.of, g.longest, g.longest
        );
    }
    if let Some(m) = &r.same_stamp {
        let _ = match m.timescale {
            Some(unit) => writeln!(
                s,
                "WARNING: `{}` changes level and back at one time stamp {} time(s) (the first at \
                 {:.6} s): a pulse shorter than the dump's time unit ({unit:.3e} s, its \
                 `$timescale`) leaves no row, and its edges are lost (missing edges, or too few \
                 to sync); record the dump with a finer time unit",
                r.channel, m.times, m.first
            ),
            None => writeln!(
                s,
                "WARNING: `{}` changes level twice at one time {} time(s) (the first at {:.6} s: \
                 two rows at that time with opposite levels): a pulse of no width as written, \
                 its two edges 0 s apart, which no timer resolves (the core takes the second \
                 as a glitch); the times are written more coarsely than the pulses came, or \
                 the rows are wrong",
                r.channel, m.times, m.first
            ),
        };
    }
    if let Some(d) = &r.repeated_times {
        let _ = writeln!(
            s,
            "WARNING: line {} repeats the time of the edge before it, {} s ({}): a \
             duplicated row in the file, or times written more coarsely than the edges came; \
             no timer resolves two edges 0 s apart, and each repeat shows as a glitch",
            d.first_line,
            d.time,
            if d.rows == 1 {
                "1 row repeats the one before".to_string()
            } else {
                format!("{} rows in all repeat the one before", d.rows)
            }
        );
    }
    if r.captures_at_one_tick > 0 {
        let _ = writeln!(
            s,
            "WARNING: {} of {} captures came at the same timer tick as the one before: the {} Hz \
             timer cannot resolve the edges, and what it merges shows as glitches and missing \
             edges; raise --timer-hz{}",
            r.captures_at_one_tick,
            r.captured,
            r.timer_hz,
            if r.prescaler < 8 {
                " or capture through --prescaler"
            } else {
                ""
            }
        );
    }
    if r.direction_unknown > 0 {
        let _ = writeln!(
            s,
            "{} edge(s) without a direction: the direction channel changed in the same sample \
             (the capture's sample rate is too low for the quadrature) or had no data",
            r.direction_unknown
        );
    }
    let _ = writeln!(
        s,
        "wheel: {}; timer {} Hz, {}-bit counter",
        r.wheel, r.timer_hz, r.counter_bits
    );
    if let Some(f) = &r.framing_note {
        let _ = writeln!(s, "{f}");
    }
    match r.sample_rate {
        Some(rate) => {
            let known = r.sampling_resolution.unwrap_or(1.0 / rate);
            let _ = writeln!(
                s,
                "sampling: {rate} Hz (a time known to {:.3e} s, {:.3} timer ticks{}): the \
                 floor below includes it, {:.3} times the timer's alone",
                known,
                r.timer_hz * known,
                if known >= 1.01 / rate {
                    ", the period and the digits' rounding"
                } else {
                    ""
                },
                1.0 + r.timer_hz * known
            );
        }
        None => match r.time_grid {
            Some(g) if r.digits_grid.is_some() => {
                let d = r.digits_grid.unwrap_or(DigitsGrid {
                    step: g,
                    hidden_rate: None,
                    resolution: 2.0 * g,
                });
                let _ = writeln!(
                    s,
                    "sampling: rate not stated; every transition's time lies on a {g:.3e} s grid \
                     ({:.3} timer ticks), the precision the times are written to: the digits' \
                     own step, which shows no sample period: {}, so the floor below takes their \
                     resolution as {:.3e} s (the digits' rounding and that period, {:.3} timer \
                     ticks), {:.3} times the timer's alone (give --sample-rate to state the \
                     rate, or export the times to more decimals)",
                    r.timer_hz * g,
                    match d.hidden_rate {
                        Some(rate) => format!(
                            "a {rate:.0} Hz analyser's {:.3e} s fits every row (the digits \
                             cannot tell its grid), and so does any finer",
                            1.0 / rate
                        ),
                        None => "an analyser's period up to the step fits every row, hidden \
                                 under the digits"
                            .to_string(),
                    },
                    d.resolution,
                    r.timer_hz * d.resolution,
                    1.0 + r.timer_hz * d.resolution
                );
            }
            Some(g) => {
                let _ = writeln!(
                    s,
                    "sampling: rate not stated; every transition's time lies on a {g:.3e} s \
                     grid{} ({:.3} timer ticks): the longest step the rows show, which the floor \
                     below takes as their resolution{}, {:.3} times the timer's alone; no sample \
                     period is stated: the analyser's is this step or a whole fraction of it \
                     (where the transitions fell on every other sample, or every k-th, only), \
                     which the rows cannot tell, and a finer one would only narrow the floor \
                     (give --sample-rate to state the rate)",
                    match r.grid_of_rate {
                        Some(f) => format!(
                            ", to the {} its times are written to ({})",
                            if f.written_to == 1e-9 {
                                "nanosecond".to_string()
                            } else {
                                format!("{:.0e} s", f.written_to)
                            },
                            if f.multiple == 1 {
                                format!("a {:.0} Hz analyser's", f.rate)
                            } else {
                                format!(
                                    "{:.0} Hz: {} periods of a {:.0} Hz analyser's, the longest \
                                     step every one lies on",
                                    1.0 / g,
                                    f.multiple,
                                    f.rate
                                )
                            }
                        ),
                        None => String::new(),
                    },
                    r.timer_hz * g,
                    match r.sampling_resolution {
                        Some(res) if res >= 1.01 * g =>
                            format!(" with the digits' rounding ({res:.3e} s in all)"),
                        _ => String::new(),
                    },
                    1.0 + r.timer_hz * r.sampling_resolution.unwrap_or(g)
                );
            }
            None if r.float_grid.is_some() || r.float_times.is_some() => {
                let _ = writeln!(
                    s,
                    "sampling: rate not stated (give --sample-rate); the floor below includes \
                     the times' float {} (below), and a capture sampled more slowly still \
                     resolves δ less finely",
                    if r.float_grid.is_some() {
                        "grid"
                    } else {
                        "spacing"
                    }
                );
            }
            None => {
                let _ = writeln!(
                    s,
                    "sampling: rate not stated (give --sample-rate): the floor below is the \
                     timer's alone, and a capture sampled slower than the timer resolves δ less \
                     finely"
                );
            }
        },
    }
    if let Some(f) = &r.float_grid {
        let _ = writeln!(
            s,
            "times: every transition's time lies on a 2^-{} s grid ({:.3e} s, {:.3} timer \
             ticks), coarser than the digits they are written to: {}; their resolution is \
             taken as {:.3e} s (the grid, and the digits' rounding up to one step more), and \
             the floor below includes it",
            f.exponent,
            f.step,
            f.step * r.timer_hz,
            match f.float {
                Some(kind) => format!(
                    "the spacing of {} numbers at {:.0} s, so the times were held as {kind} \
                     before they were written, and each is off its instant by up to half of it",
                    if kind == "f64" {
                        "64-bit float (f64)"
                    } else {
                        "32-bit float (f32)"
                    },
                    f.at
                ),
                None => "a power of two of seconds, as floats held the times or a clock of \
                         a power of two of Hz sampled them"
                    .to_string(),
            },
            f.resolution
        );
    }
    if let Some(f) = &r.float_times {
        let kind = if f.float == "f64" {
            "64-bit float (f64)"
        } else {
            "32-bit float (f32)"
        };
        let _ = writeln!(
            s,
            "times: every transition's time, as written to {:.0e} s, is a {kind} value: they \
             were held as {} before they were written, and each is off its instant by up to \
             half the float's spacing at it, 2^-{} of the power of two at or below it: {:.3e} s at {:.6} s to \
             {:.3e} s ({:.3} timer ticks) at {:.6} s, so no one grid holds them; each window's \
             floor includes the spacing at its latest time and the digits' rounding (up to \
             {:.3e} s)",
            f.written_to,
            f.float,
            f.bits - 1,
            f.spacing_from,
            f.from,
            f.spacing_to,
            f.spacing_to * r.timer_hz,
            f.to,
            f.resolution(f.to)
        );
    }
    if let Some((worst, from)) = r.coarser_times {
        let _ = writeln!(
            s,
            "sampling: the times resolve less finely in places: to {worst:.3e} s ({:.3} timer \
             ticks) from {from:.6} s on (times written to a fixed number of significant digits, \
             or far from their origin, where an f64 resolves them so, or a capture resampled \
             from a slower one, such as a value change dump imported by sigrok at its time \
             unit); each window's floor includes the resolution of its own rows",
            worst * r.timer_hz
        );
    }
    let _ = writeln!(
        s,
        "δ = 2(ω_max − ω_min)/(ω_max + ω_min) over each window's speed samples (seed 000's \
         definition); the ω mean column is the window's mean speed, not (ω_max + ω_min)/2"
    );
    // Where the samples resolve a ripple less than to 5 %: said, so that a low δ is not
    // taken for a smooth shaft.
    if let Some(at) = r.ripple.iter().position(|q| q.min < 0.95) {
        let first = &r.ripple[at];
        let listed: Vec<String> = r.ripple[at..]
            .iter()
            .take(6)
            .map(|q| format!("{}: {:.2}–{:.2}", q.order, q.min, q.max))
            .collect();
        let _ = writeln!(
            s,
            "resolution: δ of a speed ripple of order {} and up (cycles a revolution) reads low \
             on this wheel's samples, by the ripple's phase against the teeth (order: share of \
             its δ read, {}; see --json for orders to 12)",
            first.order,
            listed.join(", ")
        );
    }
    let _ = writeln!(
        s,
        "δ is measured against the wheel's nominal tooth angles: the disc's own pitch errors \
         (lines or teeth unevenly placed, run-out) read as irregularity, and the floor does not \
         include them (the core's per-tooth learner, learn::ToothLearner, measures and removes \
         them)"
    );
    let slowest = r
        .windows
        .iter()
        .filter(|w| w.valid)
        .filter_map(|w| w.omega_mean)
        .fold(f64::INFINITY, f64::min);
    if slowest < SLOW_FOR_SECONDS && !r.time_unit_stated {
        let _ = writeln!(
            s,
            "NOTE: the valid windows' mean speeds are as slow as {} rad/s: {}",
            fmt_speed(slowest),
            unit_hint()
        );
    }
    if let Some(e) = &r.edge_scatter {
        let _ = writeln!(
            s,
            "NOTE: the edges scatter about the cubic through their neighbours as a timing \
             jitter of {:.2e} pitch (standard deviation) would: a sensor's or comparator's \
             jitter, or the shaft's own speed changing from tooth to tooth, which the edges \
             cannot tell apart. Jitter that size reads as δ up to about {:.2e} in a window, \
             beyond the floor ({:.2e}, the timer's and the sampling's resolution only): a δ \
             within it of the truth may be jitter",
            e.pitches, e.delta, e.floor
        );
    }
    let _ = writeln!(
        s,
        "edges: {} fed, {} accepted as teeth{}; revolutions counted in sync: {}",
        if r.prescaler > 1 && r.edges_listed() {
            format!(
                "{} captured (each {} lines: the input prescaler) and",
                r.captured, r.prescaler
            )
        } else if r.prescaler > 1 {
            format!(
                "{} on the channel, {} captured (one in {}, the input prescaler) and",
                r.edges, r.captured, r.prescaler
            )
        } else {
            r.captured.to_string()
        },
        r.accepted,
        if r.index_pulses > 0 {
            format!(", {} index pulses", r.index_pulses)
        } else {
            String::new()
        },
        r.revolutions
    );
    let quiet = |name: &str, option: &str| {
        let others: Vec<String> = r
            .channel_changes
            .iter()
            .filter(|c| c.changes > 0 && c.name != name)
            .map(|c| format!("{} ({} changes)", c.name, c.changes))
            .collect();
        format!(
            "no {} edge on {option} `{name}` in the capture: check {option}; {}",
            r.edge,
            if others.is_empty() {
                "no channel of the capture changes level".to_string()
            } else {
                format!("channels that change: {}", others.join(", "))
            }
        )
    };
    if r.edges == 0 && r.edges_listed() {
        let _ = writeln!(s, "no edge: the file of edge times lists none");
    } else if r.edges == 0 {
        match threshold_miss(r) {
            Some(why) => {
                let _ = writeln!(s, "no {} edge on --channel `{}`: {why}", r.edge, r.channel);
            }
            None => {
                let _ = writeln!(s, "{}", quiet(&r.channel, "--channel"));
            }
        }
    }
    if let Some(i) = r.index_channel.as_deref().filter(|_| r.index_pulses == 0) {
        let _ = writeln!(s, "{}", quiet(i, "--index-channel"));
    }
    let _ = writeln!(
        s,
        "faults: {} glitches, {} missing edges, {} extra edges, {} missing frames, {} reversals, {} timeouts, {} unexplained edges",
        r.glitches, r.missing, r.extra, r.missing_frames, r.reversals, r.timeouts, r.unexplained
    );
    if u64::from(r.missing) > r.captured {
        // The core counts the teeth a long interval lost as how many of the last interval
        // it judged fit in it (after the only interval since a new reference it counts an
        // extra edge instead: ringing read 27 lost teeth a tooth that way).
        let _ = writeln!(
            s,
            "  (more missing edges than the {} captured: the core counts the teeth lost in a \
             long interval as how many of the interval it judged before fit in it; a count of \
             the core's judgement, not of edges seen)",
            r.captured
        );
    }
    match r.sync_acquired {
        Some(t) => {
            let _ = writeln!(
                s,
                "sync: acquired at {t:.6} s; {} times synced, {} times lost; {} at the end",
                r.syncs, r.sync_losses, r.sync_state
            );
        }
        None => {
            let _ = writeln!(s, "sync: never acquired ({} at the end)", r.sync_state);
        }
    }
    if r.edges_unsynced > 0 {
        let _ = writeln!(
            s,
            "sync lost: {} of the {} captured edges came while the count was searched for \
             again: the core judges no fault among them, so the fault counts above leave them \
             out (a signal losing teeth or carrying noise there shows only as the sync losses)",
            r.edges_unsynced, r.captured
        );
    }
    for c in r.sync_hint.iter().flat_map(|h| &h.causes) {
        let _ = writeln!(s, "{c}");
    }
    if let Some(p) = r
        .index_period
        .filter(|p| p.captures != u64::from(p.expected) && !index_at_a_line_edge(p))
    {
        let _ = writeln!(
            s,
            "index: {} captures from one index pulse to the next ({} of {} times), but a \
             revolution of the configured wheel is {}: check the number of lines, the edge \
             polarity and --index-channel",
            p.captures, p.times, p.of, p.expected
        );
    }
    if let Some(p) = r.index_period.filter(index_at_a_line_edge) {
        let _ = writeln!(
            s,
            "index: {} of {} intervals between index pulses are a capture short of the \
             revolution's {} and {} a capture long: the index pulse comes at a line edge and \
             falls to either side of it, so the count is framed a line early or late (extra or \
             missing edges, missing frames, where the lines may be clean); capture the lines' \
             other edge (--edge), where the index lies mid-pitch, or place the index against \
             the lines so",
            p.early_late.0, p.of, p.expected, p.early_late.1
        );
    }
    for e in r.sync.iter().take(20) {
        let _ = writeln!(s, "  {:>12.6} s  {}", e.time, e.state);
    }
    if r.sync_changes_total > 20 {
        let _ = writeln!(
            s,
            "  ... {} more changes{}",
            r.sync_changes_total - 20,
            where_listed(r.sync_changes_total, r.sync_changes_listed, "changes", "")
        );
    }
    if r.reverse_edges > 0 {
        let _ = writeln!(
            s,
            "{} edge(s) running in reverse (not taken as teeth)",
            r.reverse_edges
        );
    }
    if r.backward_pitches > 0 {
        let _ = writeln!(
            s,
            "{} of them came a pitch or more backward of the capture before (the quadrature \
             count stepped back by 4 or more, as the direction channel says): the disc turned \
             the other way{}",
            r.backward_pitches,
            other_way(r).unwrap_or_default()
        );
    }
    if r.no_pitch > 0 {
        let _ = writeln!(
            s,
            "{} of them came with no step forward of the quadrature count since the capture \
             before, itself so, and less than a pitch back: no pitch (a shaft at rest rocking \
             across a line edge, or turning back across one), fed as reverse",
            r.no_pitch
        );
    }
    if r.direction_glitches > 0 {
        let _ = writeln!(
            s,
            "direction channel: {} glitch(es) on {} at edges of {}, read as forward (it changed \
             and came back within an eighth of a pitch across the edge, the quadrature count \
             going on forward: a noise pulse, not a reversal)",
            r.direction_glitches,
            r.direction_channel.as_deref().unwrap_or("B"),
            r.channel
        );
    }
    if r.unjudged_at_end > 0 {
        let _ = writeln!(
            s,
            "{} edge(s) neither taken as teeth nor rejected: the last ones still waiting to be \
             judged, and the first after a standstill or reversal (a time reference only)",
            r.unjudged_at_end
        );
    }
    let _ = writeln!(
        s,
        "windows: {} valid, {} invalid{}",
        r.valid_windows,
        r.invalid_windows,
        // In sync, but too short a capture for one window: said, not left to be guessed.
        if r.valid_windows + r.invalid_windows == 0 && r.revolutions > 0 {
            format!(
                " (a window is {} revolution(s) and the capture has {} in sync)",
                r.window_revolutions, r.revolutions
            )
        } else {
            String::new()
        }
    );
    if !r.windows.is_empty() {
        let _ = writeln!(
            s,
            "  {:>12} {:>12} {:>5}  {:>10} {:>10} {:>10}  result",
            "start, s", "end, s", "revs", "δ", "ω mean", "floor"
        );
    }
    for w in r.windows.iter().take(40) {
        match (
            w.delta,
            w.omega_mean,
            w.floor_with_sampling.or(w.noise_floor),
        ) {
            (Some(d), Some(m), Some(f)) => {
                let _ = writeln!(
                    s,
                    "  {:>12.6} {:>12.6} {:>5}  {:>10.6} {:>10.3} {:>10.2e}  valid{}{}",
                    w.start,
                    w.end,
                    w.revolutions,
                    d,
                    m,
                    f,
                    match (w.steady == Some(true), w.resolved == Some(false)) {
                        (true, false) => "",
                        (false, false) => ", not steady",
                        (true, true) => ", δ within its floor: not resolved",
                        (false, true) => ", not steady, δ within its floor: not resolved",
                    },
                    w.displaced_edge.map_or(String::new(), |e| format!(
                        ", δ from one edge {:.1} % of a pitch off at {:.6} s",
                        100.0 * e.pitches,
                        e.time
                    ))
                );
            }
            _ => {
                let _ = writeln!(
                    s,
                    "  {:>12.6} {:>12.6} {:>5}  {:>10} {:>10} {:>10}  invalid: {}",
                    w.start,
                    w.end,
                    w.revolutions,
                    "-",
                    "-",
                    "-",
                    w.fault.unwrap_or("?")
                );
            }
        }
    }
    if r.windows_total > 40 {
        let _ = writeln!(
            s,
            "  ... {} more windows{}",
            r.windows_total - 40,
            where_listed(
                r.windows_total,
                r.windows_listed,
                "windows",
                ", and the δ plot (--plot) shows them all"
            )
        );
    }
    if !r.faults.is_empty() {
        let _ = writeln!(s, "fault list:");
        for f in r.faults.iter().take(40) {
            let _ = writeln!(s, "  {:>12.6} s  {}", f.time, f.fault);
        }
        if r.faults_total > 40 {
            let _ = writeln!(
                s,
                "  ... {} more faults{}",
                r.faults_total - 40,
                where_listed(r.faults_total, r.faults_listed, "faults", "")
            );
        }
    }
    s
}

/// Where the items of a list past the text's first are: `--json`, which lists them all or the
/// first [`MAX_LISTED`] (`total` of them, `listed` in `--json`; `also`: what else shows them).
fn where_listed(total: u64, listed: u64, what: &str, also: &str) -> String {
    if listed >= total {
        return " (see --json)".into();
    }
    format!(
        ": --json lists the first {listed} of the {total} {what} (the counts above count them \
         all); the other {} are in no list{also}",
        total - listed
    )
}

/// The speed plot (and δ per window) into `dir`: returns the files written.
pub fn plots(
    r: &AnalyzeReport,
    stem: &str,
    dir: &std::path::Path,
) -> Result<Vec<std::path::PathBuf>, String> {
    use crate::app::plot::{write_svg, Chart, Series};
    let mut files = Vec::new();
    let speed_at = |t: f64| -> f64 {
        let k = r.speed_trace.partition_point(|p| p.0 < t);
        r.speed_trace
            .get(k.min(r.speed_trace.len().saturating_sub(1)))
            .map_or(0.0, |p| p.1)
    };
    let mut series = vec![Series {
        label: "speed sample (synced teeth)".into(),
        points: r.speed_trace.clone(),
        markers: false,
    }];
    if !r.faults.is_empty() {
        series.push(Series {
            label: if r.faults_listed < r.faults_total {
                format!(
                    "fault (the first {} of {})",
                    r.faults_listed, r.faults_total
                )
            } else {
                "fault".into()
            },
            points: r
                .faults
                .iter()
                .map(|f| (f.time, speed_at(f.time)))
                .collect(),
            markers: true,
        });
    }
    let path = dir.join(format!("{stem}-speed.svg"));
    write_svg(
        &path,
        &Chart {
            title: "speed from the capture",
            x_label: "capture time, s",
            y_label: "ω, rad/s",
            series,
            marks: Vec::new(),
        },
    )?;
    files.push(path);
    // Every window of the capture (not only those listed), decimated past MAX_TRACE.
    let deltas = r.delta_trace.clone();
    let path = dir.join(format!("{stem}-delta.svg"));
    write_svg(
        &path,
        &Chart {
            title: "δ per valid window",
            x_label: "capture time at the window's end, s",
            y_label: "δ",
            series: vec![Series {
                label: match r.delta_every {
                    0 | 1 => "δ".into(),
                    k => format!("δ (one window in {k} of {}: decimated)", r.windows_total),
                },
                points: deltas,
                markers: true,
            }],
            marks: Vec::new(),
        },
    )?;
    files.push(path);
    Ok(files)
}

/// How an index or unframed disc is framed (`--framing`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum FramingArg {
    /// An index pulse on its own channel (`--index-channel`, default the second channel).
    Index,
    /// No frame marker.
    None,
}

/// The command line's description of an analysis, before it is checked.
#[derive(Debug, Clone, Default)]
pub struct AnalyzeOptions {
    /// `--wheel N-M`.
    pub wheel: Option<String>,
    /// `--lines N`.
    pub lines: Option<u16>,
    /// `--framing` (with `--lines`; `None`: unframed, and the report says so).
    pub framing: Option<FramingArg>,
    /// `--scene`: the scene and the path its errors name.
    pub scene: Option<(crate::app::scene::Scene, std::path::PathBuf)>,
    /// `--timer-hz`.
    pub timer_hz: Option<f64>,
    /// `--counter-bits`.
    pub counter_bits: Option<u8>,
    /// `--prescaler`.
    pub prescaler: Option<u8>,
    /// `--min-speed`.
    pub min_speed: Option<f64>,
    /// `--estimator-edges`.
    pub estimator_edges: Option<u16>,
    /// `--window-revolutions`.
    pub window_revolutions: Option<u16>,
    /// `--channel` (default the first).
    pub channel: Option<Channel>,
    /// `--index-channel`.
    pub index_channel: Option<Channel>,
    /// `--direction-channel`.
    pub direction_channel: Option<Channel>,
    /// `--forward` (default A leads).
    pub forward: Option<Lead>,
    /// `--edge` (default rising).
    pub edge: Option<Polarity>,
}

/// Default emulated timer clock without a scene, Hz.
pub const DEFAULT_TIMER_HZ: f64 = 1e6;

/// The command-line option a core parameter comes from.
fn option_of(parameter: &str) -> &'static str {
    match parameter {
        "timer_hz" => "--timer-hz",
        "min_speed" => "--min-speed",
        "counter_bits" => "--counter-bits",
        "prescaler" => "--prescaler",
        "estimator.edges" => "--estimator-edges",
        "lines" => "--lines",
        "window.revolutions" => "--window-revolutions",
        p if p.starts_with("pattern") => "--wheel",
        _ => "the scene's [encoder]",
    }
}

/// The option a core parameter comes from with the value it has (`--wheel 36-40`,
/// `--estimator-edges 33`), or where the scene gives it, the option alone.
fn option_given(o: &AnalyzeOptions, enc: &EncoderConfig, parameter: &str) -> String {
    use drive_monitor::encoder::{Estimator, Wheel};
    let option = option_of(parameter);
    let value = match parameter {
        p if p.starts_with("pattern") => o.wheel.clone(),
        "lines" => o.lines.map(|n| n.to_string()),
        "estimator.edges" => o.estimator_edges.map(|_| {
            let Estimator::Edges(k) = enc.estimator;
            k.to_string()
        }),
        "prescaler" => o.prescaler.map(|p| p.to_string()),
        "counter_bits" => o.counter_bits.map(|b| b.to_string()),
        "timer_hz" => o.timer_hz.map(fmt_number),
        "min_speed" => o.min_speed.map(fmt_number),
        "window.revolutions" => o.window_revolutions.map(|n| n.to_string()),
        _ => None,
    };
    match (value, enc.wheel) {
        (Some(v), _) => format!("{option} {v}"),
        // From a scene: its key, with the value.
        (None, Wheel::Indexed { lines } | Wheel::Unframed { lines }) if parameter == "lines" => {
            format!("the scene's `encoder.lines = {lines}`")
        }
        (None, _) => option.to_string(),
    }
}

/// The allowed values of an encoder parameter with a fixed range, as the options give them.
fn allowed(e: drive_monitor::ConfigError) -> Option<String> {
    use drive_monitor::encoder::{MAX_PATTERN_POSITIONS, MAX_PATTERN_TEETH, MAX_SPAN};
    use drive_monitor::ConfigError::{Capacity, NonFinite, NotPositive, OutOfRange};
    match e {
        OutOfRange("lines") => Some(format!(
            "a disc has 2 to {} lines",
            MAX_LINES.min(usize::from(drive_monitor::encoder::MAX_LINES))
        )),
        OutOfRange("estimator.edges") => Some(format!(
            "a speed sample spans 1 to {MAX_SPAN} edges, and no more than the edges captured in \
             a revolution"
        )),
        OutOfRange("prescaler") => Some("the input prescaler is 1, 2, 4 or 8".into()),
        OutOfRange("counter_bits") => Some("the counter is 16 to 32 bits wide".into()),
        OutOfRange("timer_hz") | NotPositive("timer_hz") | NonFinite("timer_hz") => {
            Some("the timer clock is 1 Hz to 10 GHz".into())
        }
        // (How slow a speed fits depends on the timer and the counter: said when it does not.)
        NotPositive("min_speed") | NonFinite("min_speed") => {
            Some("the slowest speed still running is above 0 rad/s".into())
        }
        OutOfRange("window.revolutions") => Some(format!(
            "a window is 1 to {} revolutions",
            drive_monitor::irregularity::MAX_WINDOW_REVS
        )),
        OutOfRange("pattern.positions" | "pattern.teeth" | "pattern.gaps")
        | Capacity("pattern.teeth") => Some(format!(
            "a wheel N-M has 3 to {MAX_PATTERN_POSITIONS} positions, of which M are missing and \
             at least 3 (at most {MAX_PATTERN_TEETH}) are teeth"
        )),
        _ => None,
    }
}

/// The message for a whole number given to `option` (`--window-revolutions`) that the type it
/// is held in cannot hold (beyond 65535, or negative): out of the option's range, said as
/// [`configure`] says a value out of it; `None` for an option without a fixed range.
pub fn out_of_range(option: &str, value: &str) -> Option<String> {
    let parameter = match option {
        "--lines" => "lines",
        "--counter-bits" => "counter_bits",
        "--prescaler" => "prescaler",
        "--estimator-edges" => "estimator.edges",
        "--window-revolutions" => "window.revolutions",
        _ => return None,
    };
    allowed(drive_monitor::ConfigError::OutOfRange(parameter))
        .map(|range| format!("{option} {value} is out of range: {range}"))
}

/// Checks the options and builds the analysis they describe.
pub fn configure(o: &AnalyzeOptions) -> Result<AnalyzeConfig, String> {
    use drive_monitor::encoder::{Estimator, Pattern};
    use drive_monitor::irregularity::WindowLength;
    let given = [o.wheel.is_some(), o.lines.is_some(), o.scene.is_some()];
    if given.iter().filter(|&&g| g).count() != 1 {
        return Err(
            "name the wheel once: --wheel N-M (a missing-tooth wheel), --lines N (with \
             --framing index|none, none by default), or --scene FILE (its [encoder])"
                .into(),
        );
    }
    if o.framing.is_some() && o.lines.is_none() {
        return Err("--framing goes with --lines (a --wheel or a scene names its framing)".into());
    }
    let timer_hz = o.timer_hz.unwrap_or(DEFAULT_TIMER_HZ);
    let (mut enc, mut window) = match (&o.wheel, o.lines, &o.scene) {
        (Some(w), _, _) => {
            let (n, m) =
                crate::app::scene::parse_wheel(w).map_err(|e| format!("--wheel {w}: {e}"))?;
            let n = u8::try_from(n).map_err(|_| {
                format!(
                    "--wheel {w}: at most {} positions",
                    drive_monitor::encoder::MAX_PATTERN_POSITIONS
                )
            })?;
            let mut c = EncoderConfig::pattern(Pattern::missing_teeth(n, m), timer_hz);
            c.counter_bits = 32;
            (c, None)
        }
        (None, Some(lines), _) => {
            let c = match o.framing.unwrap_or(FramingArg::None) {
                FramingArg::Index => EncoderConfig::indexed(lines, timer_hz),
                FramingArg::None => EncoderConfig::unframed(lines, timer_hz),
            };
            (c, None)
        }
        (None, None, Some((scene, path))) => {
            let e = crate::app::run::core_encoder(scene, path)
                .map_err(|e| e.to_string())?
                .ok_or_else(|| format!("{}: no [encoder] table", path.display()))?;
            (*e.config(), Some(crate::app::run::window_config(scene)))
        }
        (None, None, None) => unreachable_wheel()?,
    };
    if o.scene.is_none() || o.timer_hz.is_some() {
        enc.timer_hz = timer_hz;
    }
    if let Some(b) = o.counter_bits {
        enc.counter_bits = b;
    }
    if let Some(p) = o.prescaler {
        enc.prescaler = p;
    }
    if let Some(w) = o.min_speed {
        // The scene's `monitor.min_speed` range: beyond it no timer fits, and the core's
        // complaint would name the timer (with a speed written out to 301 digits).
        if !(1e-6..=1e5).contains(&w) {
            return Err(format!(
                "--min-speed {} is out of range: the slowest speed still running is 1e-6 to 1e5 \
                 rad/s (as a scene's monitor.min_speed)",
                fmt_number(w)
            ));
        }
        enc.min_speed = w;
    }
    if let Some(k) = o.estimator_edges {
        enc.estimator = Estimator::Edges(k);
    }
    if let Some(n) = o.window_revolutions {
        window = Some(WindowConfig {
            length: WindowLength::Revolutions(n),
            // (A scene's tolerance kept.)
            steady_tolerance: window.map_or(0.02, |w| w.steady_tolerance),
        });
    }
    // A scene knows its load: a window that does not hold the load's cycle is said, as `run`
    // and `predict` say it.
    let warnings: Vec<String> = match (&o.scene, o.window_revolutions) {
        (Some((scene, _)), Some(n)) => {
            crate::app::run::window_warning_for(scene, n, &format!("`--window-revolutions {n}`"))
                .into_iter()
                .collect()
        }
        (Some((scene, _)), None) => crate::app::run::window_warning(scene).into_iter().collect(),
        _ => Vec::new(),
    };
    let window = window.unwrap_or(WindowConfig {
        length: WindowLength::Revolutions(1),
        steady_tolerance: 0.02,
    });
    // A disc of more lines than the analysis's monitor holds (the core's own bound is wider).
    if let drive_monitor::encoder::Wheel::Indexed { lines }
    | drive_monitor::encoder::Wheel::Unframed { lines } = enc.wheel
    {
        if usize::from(lines) > MAX_LINES {
            return Err(format!(
                "{} is out of range: {}",
                option_given(o, &enc, "lines"),
                allowed(drive_monitor::ConfigError::OutOfRange("lines")).unwrap_or_default()
            ));
        }
    }
    Encoder::new(enc).map_err(|e| {
        // A value outside a fixed range: say the range in the option's own terms.
        if let Some(range) = allowed(e) {
            let mut m = format!(
                "{} is out of range: {range}",
                option_given(o, &enc, e.parameter())
            );
            // How many that is here, on a disc (a wheel's teeth are its own).
            if let (
                drive_monitor::ConfigError::OutOfRange("estimator.edges"),
                drive_monitor::encoder::Wheel::Indexed { lines }
                | drive_monitor::encoder::Wheel::Unframed { lines },
            ) = (e, enc.wheel)
            {
                let per = lines / u16::from(enc.prescaler.max(1));
                m.push_str(&format!(
                    " ({per} here: {lines} lines, one captured in {})",
                    enc.prescaler
                ));
            }
            if let (
                drive_monitor::ConfigError::OutOfRange("estimator.edges"),
                drive_monitor::encoder::Wheel::Pattern(p),
            ) = (e, enc.wheel)
            {
                m.push_str(&format!(" ({} here: the wheel's teeth)", p.teeth()));
            }
            return m;
        }
        // A prescaler the wheel cannot take: the wheel is the reason, not the timer.
        if e == drive_monitor::ConfigError::Inconsistent("prescaler") {
            let p = enc.prescaler;
            return match enc.wheel {
                drive_monitor::encoder::Wheel::Indexed { lines }
                | drive_monitor::encoder::Wheel::Unframed { lines } => format!(
                    "--prescaler {p} does not fit a disc of {lines} lines: it must divide \
                     the lines and leave at least 2 captures a revolution"
                ),
                _ => format!(
                    "--prescaler {p} does not fit a wheel with a pattern (--wheel, or the \
                     scene's): its teeth are captured one by one, the prescaler divides a \
                     uniform disc's lines (--lines)"
                ),
            };
        }
        // A minimum speed nobody gave is the default's: the options given are what to change.
        let head = if e.parameter() == "min_speed" && o.min_speed.is_none() && o.scene.is_none() {
            "--timer-hz and --counter-bits do not fit the default --min-speed".to_string()
        } else {
            format!("{} does not fit", option_of(e.parameter()))
        };
        let mut m = format!(
            "{head}: {e} (timer {} Hz, {}-bit counter, minimum speed {} rad/s)",
            enc.timer_hz, enc.counter_bits, enc.min_speed
        );
        let hint = crate::app::check::speed_range_hint(
            &enc,
            e,
            "--min-speed",
            "--timer-hz",
            "--counter-bits",
        );
        if let Some(h) = hint {
            m.push_str(": ");
            m.push_str(&h);
        }
        m
    })?;
    window.validate().map_err(|e| match allowed(e) {
        Some(range) => format!(
            "{} is out of range: {range}",
            option_given(o, &enc, e.parameter())
        ),
        None => format!("{}: {e}", option_of(e.parameter())),
    })?;
    let index = matches!(enc.wheel, drive_monitor::encoder::Wheel::Indexed { .. });
    if o.index_channel.is_some() && !index {
        return Err("--index-channel goes with an index disc (--lines N --framing index, or a scene whose framing is \"index\")".into());
    }
    if o.forward.is_some() && o.direction_channel.is_none() {
        return Err("--forward goes with --direction-channel (the quadrature B channel)".into());
    }
    Ok(AnalyzeConfig {
        direction: o
            .direction_channel
            .clone()
            .map(|c| (c, o.forward.unwrap_or(Lead::ALeads))),
        encoder: enc,
        window,
        channel: o.channel.clone().unwrap_or(Channel::Column(0)),
        index_channel: if index {
            Some(o.index_channel.clone().unwrap_or(Channel::Column(1)))
        } else {
            None
        },
        index_channel_default: index && o.index_channel.is_none(),
        edge: o.edge,
        warnings,
        framing_default: o.lines.is_some() && o.framing.is_none(),
    })
}

fn unreachable_wheel() -> Result<(EncoderConfig, Option<WindowConfig>), String> {
    Err("name the wheel: --wheel, --lines or --scene".into())
}

#[cfg(test)]
mod tests {
    use super::{decimal_step, Resolution, BLOCK_ROWS, MAX_LISTED};

    /// Blocks whose grid alternates (1 µs, then 10 µs) change the resolution every block: the
    /// changes kept stop at [`MAX_LISTED`], the last of them the coarsest met since, and each
    /// span reads the coarsest of its blocks.
    #[test]
    fn the_resolution_kept_is_bounded_and_the_coarsest() {
        let mut r = Resolution {
            hz: 1e6,
            ..Resolution::default()
        };
        let (mut t, mut us) = (0.0f64, 0u64);
        let blocks = MAX_LISTED + 100;
        for b in 0..blocks {
            // Rows 1 and 2 steps apart in turn, of 1 µs in even blocks and 10 µs in odd ones.
            let step = if b % 2 == 0 { 1 } else { 10 };
            for k in 0..BLOCK_ROWS {
                us += step * (1 + k as u64 % 2);
                t = us as f64 * 1e-6;
                r.row(t);
            }
        }
        assert_eq!(r.changes.len(), MAX_LISTED);
        assert!((r.changes[0].1 - 1e-6).abs() < 1e-12, "{:?}", r.changes[0]);
        assert!((r.changes[1].1 - 1e-5).abs() < 1e-12, "{:?}", r.changes[1]);
        assert!((r.changes[MAX_LISTED - 1].1 - 1e-5).abs() < 1e-12);
        assert!((r.over(0.0, t) - 1e-5).abs() < 1e-12);
        assert!((r.over(0.0, 1e-6) - 1e-6).abs() < 1e-12);
    }

    /// Rows equally spaced (a steady signal on a fine grid) say nothing of the step; rows
    /// whose few spacings share a step no power of ten divides neither: the block resolves no
    /// more coarsely than its 20 ns grid. Times on a decimal grid, unequally spaced, resolve
    /// to it.
    #[test]
    fn a_steady_signal_is_no_coarse_grid() {
        let resolution = |spacings: &[u64]| {
            let mut r = Resolution {
                hz: 1e6,
                ..Resolution::default()
            };
            let mut ns = 1_000_000_000u64;
            for k in 0..BLOCK_ROWS {
                ns += spacings[k % spacings.len()];
                r.row(ns as f64 * 1e-9);
            }
            r.changes[0].1
        };
        // 1166 and 700/1633 samples of 20 ns; 0.8 and 0.9 ms on a 100 µs grid.
        assert!(resolution(&[23_320]) < 1e-9);
        assert!(resolution(&[14_000, 32_660]) <= 2e-8);
        assert!((resolution(&[800_000, 900_000]) - 1e-4).abs() < 1e-15);
        assert_eq!(decimal_step(23_320), 10);
        assert_eq!(decimal_step(900_000), 100_000);
    }
}
