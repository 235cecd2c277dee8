//! Synthetic encoder: the capture timestamps an MCU timer would record for a slotted disc on
//! the simulated shaft.
//!
//! The disc has `lines` positions; position k passes the sensor when the shaft angle reaches
//! θ_k = 2π·k/lines + pitch error_k + (e/r)·sin(2π·k/lines + phase) (run-out e of the disc at
//! radius r seen as an angular error), plus 2π per revolution. Which positions carry a tooth is
//! the wheel's pattern: all of them, the ones listed in `teeth` (any pattern on the grid:
//! 36-2-2-2 with uneven gaps, 12+1 on a half-pitch grid), or all but the first `count` (a
//! missing-tooth gap, [`Reference::MissingTeeth`]). An index pulse on its own channel half a
//! pitch before position 0 is added by [`Reference::Index`].
//!
//! A sensor's output is a pulse per tooth: the rising edge at the tooth's angle and, when
//! `duty` is set, the falling edge `duty` grid pitches later ([`Edge::rising`] tells them
//! apart; without `duty` only rising edges are produced, as a capture unit set to one polarity
//! sees them). The index pulse has the same width.
//!
//! Edge times are located on the shaft angle's polynomial over each integration step (the
//! integrator's dense output, or the exact law of a prescribed shaft): turning points of the
//! angle inside the step are bracketed first (the derivative is sampled at 9 points of the
//! step, so reversals closer together than 1/8 of a step are not resolved — bound the step with
//! `max_step` for scenes that oscillate back and forth), then each crossing of the next mark
//! angle is solved by Newton's method safeguarded by bisection, to |Δθ| ≤ 1e-13 of the step
//! (in practice to rounding of t). A shaft moving backwards produces edges too, with
//! [`Direction::Reverse`].
//!
//! Then, like a capture unit: optional Gaussian jitter (std `jitter` s), quantisation
//! ticks = ⌊t·timer_hz⌋ + counter_start masked to `counter_bits`. Faults: each real tooth (or
//! index pulse) is dropped with probability `drop_probability` (its falling edge with it);
//! before each rising line edge a glitch edge is inserted with probability
//! `glitch_probability`, at a uniformly random fraction within `glitch_window` of the time
//! since the previous rising line edge (glitches are quantised without jitter). Dropped edges
//! are delivered too, marked [`Edge::dropped`], when `emit_dropped` is set (the ground truth of
//! a test); a capture unit never sees them. Edges are delivered in the order their marks are
//! crossed, which is true-time order except for a glitch, which comes just before the rising
//! edge it precedes (a falling edge or an index edge between the two may be later than it);
//! keep the jitter well below the edge spacing, or the captured ticks can run backwards. All
//! randomness comes from `seed` through independent ChaCha8 streams (jitter, drops, glitches,
//! pitch errors, falling-edge jitter), so enabling one fault or the falling edges does not
//! change the others' draws: the same seed gives identical ticks.

use core::f64::consts::TAU;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::Deserialize;

use drive_monitor::error::{finite, non_negative, positive, ConfigError};

use crate::engine::ode::ComponentPoly;

/// Reference mark framing each revolution.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Reference {
    /// No reference: the teeth alone (all positions, or the pattern of `teeth`), no index.
    #[default]
    None,
    /// An index pulse once per revolution, half a pitch before position 0, on its own channel.
    Index,
    /// The first `count` positions of each revolution are missing (a gap).
    MissingTeeth {
        /// Consecutive missing positions (1 ≤ count < lines).
        count: u32,
    },
}

/// Disc run-out: eccentricity e at reading radius r gives an angular error (e/r)·sin(θ + phase).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Runout {
    /// Eccentricity e, m.
    pub eccentricity: f64,
    /// Reading radius r, m.
    pub radius: f64,
    /// Phase, rad.
    #[serde(default)]
    pub phase: f64,
}

fn default_counter_bits() -> u32 {
    32
}

/// Encoder, timer and fault parameters. Deserializable from TOML, but scene files describe the
/// encoder with [`crate::app::scene::EncoderSpec`], which `drive-sim run` maps onto this.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EncoderConfig {
    /// Positions (lines) on the disc.
    pub lines: u32,
    /// Reference mark.
    #[serde(default)]
    pub reference: Reference,
    /// Capture timer clock, Hz.
    pub timer_hz: f64,
    /// Counter width, bits (16 or 32 on typical timers; 1–32 accepted).
    #[serde(default = "default_counter_bits")]
    pub counter_bits: u32,
    /// Counter value at t = 0, ticks.
    #[serde(default)]
    pub counter_start: u32,
    /// Standard deviation of the edge-time jitter, s.
    #[serde(default)]
    pub jitter: f64,
    /// Per-position pitch errors, rad (empty, or one per line).
    #[serde(default)]
    pub pitch_errors: Vec<f64>,
    /// Standard deviation of random per-position pitch errors (seeded), rad.
    #[serde(default)]
    pub pitch_error_std: f64,
    /// Disc run-out.
    #[serde(default)]
    pub runout: Option<Runout>,
    /// Probability that a real edge is lost.
    #[serde(default)]
    pub drop_probability: f64,
    /// Probability that a spurious edge precedes a line edge.
    #[serde(default)]
    pub glitch_probability: f64,
    /// Where a glitch falls between the previous rising line edge and the one it precedes, as
    /// fractions of that interval (drawn uniformly between them; default the whole interval).
    #[serde(default = "default_glitch_window")]
    pub glitch_window: [f64; 2],
    /// Grid positions carrying a tooth, ascending (`None`: every position, or all but the
    /// gap of [`Reference::MissingTeeth`]).
    #[serde(default)]
    pub teeth: Option<Vec<u32>>,
    /// Width of a tooth (and of the index pulse) in grid pitches, 0 < duty < 1: when set, the
    /// falling edge of every pulse is produced too.
    #[serde(default)]
    pub duty: Option<f64>,
    /// Deliver dropped edges too, marked [`Edge::dropped`] (ground truth for tests).
    #[serde(default)]
    pub emit_dropped: bool,
    /// Seed of all random draws.
    #[serde(default)]
    pub seed: u64,
}

fn default_glitch_window() -> [f64; 2] {
    [0.0, 1.0]
}

impl EncoderConfig {
    /// An ideal encoder: `lines` positions, no reference, a 32-bit timer at `timer_hz`, no
    /// errors or faults.
    pub fn ideal(lines: u32, timer_hz: f64) -> Self {
        EncoderConfig {
            lines,
            reference: Reference::None,
            timer_hz,
            counter_bits: 32,
            counter_start: 0,
            jitter: 0.0,
            pitch_errors: Vec::new(),
            pitch_error_std: 0.0,
            runout: None,
            drop_probability: 0.0,
            glitch_probability: 0.0,
            glitch_window: default_glitch_window(),
            teeth: None,
            duty: None,
            emit_dropped: false,
            seed: 0,
        }
    }
}

/// Direction of the shaft at an edge: the core's, as the capture unit reports it.
pub use drive_monitor::speed::Direction;

/// One captured edge.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Edge {
    /// Timer value at capture (wrapping, masked to the counter width).
    pub ticks: u32,
    /// Direction of motion.
    pub direction: Direction,
    /// On the index channel.
    pub index: bool,
    /// A spurious edge (ground truth; the capture unit cannot tell).
    pub glitch: bool,
    /// True time of the crossing, s (before jitter and quantisation).
    pub true_time: f64,
    /// Time the sensor's output changes, s: the true time plus the jitter (what a logic
    /// analyzer records, before its own sampling).
    pub seen_time: f64,
    /// Disc position 0 … lines−1 (0 for the index; for a glitch, the position of the line
    /// edge it precedes).
    pub tooth: u32,
    /// Revolution number of the mark (ground truth).
    pub revolution: i64,
    /// A rising edge (the leading edge of a tooth or index pulse, or a glitch); `false` for
    /// the falling edge ending a pulse (only with `duty`).
    pub rising: bool,
    /// The edge was lost: the capture unit never saw it (only with `emit_dropped`).
    pub dropped: bool,
}

/// One mark on the disc within a revolution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Mark {
    /// Shaft angle at which the mark passes the sensor, rad.
    pub angle: f64,
    /// Disc position.
    pub tooth: u32,
    /// On the index channel.
    pub index: bool,
    /// The leading edge of the pulse (`false`: its falling edge, with `duty`).
    pub rising: bool,
}

/// Counters of the edges produced.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EncoderStats {
    /// Rising edges delivered (line, index and glitch).
    pub edges: u64,
    /// Falling edges delivered (with `duty`).
    pub falling: u64,
    /// Index pulses delivered.
    pub index_pulses: u64,
    /// Real edges dropped.
    pub dropped: u64,
    /// Glitch edges delivered.
    pub glitches: u64,
    /// Real crossings located (delivered or dropped).
    pub crossings: u64,
}

/// Iteration limit of the safeguarded Newton solve (bisection alone would need 53).
const MAX_ITER: usize = 80;
/// Convergence on θ (fraction of the step).
const THETA_TOL: f64 = 1e-13;
/// Derivative samples per step for turning-point detection.
const TURN_SAMPLES: u32 = 8;

/// The encoder model with its fault generators and position state.
#[derive(Debug, Clone)]
pub struct Encoder {
    config: EncoderConfig,
    marks: Vec<Mark>,
    mask: u64,
    rng_jitter: ChaCha8Rng,
    rng_drop: ChaCha8Rng,
    rng_glitch: ChaCha8Rng,
    rng_falling: ChaCha8Rng,
    /// The last rising edge of the line and of the index channel was dropped: so is the
    /// falling edge that ends its pulse.
    pulse_dropped: [bool; 2],
    /// Index j of the last mark at or below φ (global: revolution·marks + slot).
    pos: i64,
    started: bool,
    last_line_time: Option<f64>,
    stats: EncoderStats,
}

fn gaussian(rng: &mut ChaCha8Rng) -> f64 {
    // Box–Muller; u1 in (0, 1] keeps the logarithm finite.
    let u1 = 1.0 - rng.gen::<f64>();
    let u2 = rng.gen::<f64>();
    (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
}

/// Stream `k` of `seed`: 0 jitter, 1 drops, 2 glitches, 3 pitch errors, 4 falling-edge
/// jitter.
fn stream(seed: u64, k: u64) -> ChaCha8Rng {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    rng.set_stream(k);
    rng
}

fn probability(name: &'static str, p: f64) -> Result<f64, ConfigError> {
    let p = non_negative(name, p)?;
    if p >= 1.0 {
        return Err(ConfigError::OutOfRange(name));
    }
    Ok(p)
}

impl Encoder {
    /// Validates `config` and builds the disc's mark table.
    pub fn new(config: EncoderConfig) -> Result<Self, ConfigError> {
        let lines = config.lines;
        if lines == 0 {
            return Err(ConfigError::NotPositive("encoder.lines"));
        }
        if lines > 1 << 24 {
            return Err(ConfigError::OutOfRange("encoder.lines"));
        }
        positive("encoder.timer_hz", config.timer_hz)?;
        if !(1..=32).contains(&config.counter_bits) {
            return Err(ConfigError::OutOfRange("encoder.counter_bits"));
        }
        non_negative("encoder.jitter", config.jitter)?;
        non_negative("encoder.pitch_error_std", config.pitch_error_std)?;
        probability("encoder.drop_probability", config.drop_probability)?;
        probability("encoder.glitch_probability", config.glitch_probability)?;
        if !config.pitch_errors.is_empty() && config.pitch_errors.len() != lines as usize {
            return Err(ConfigError::Inconsistent("encoder.pitch_errors"));
        }
        for &e in &config.pitch_errors {
            finite("encoder.pitch_errors", e)?;
        }
        if let Some(r) = config.runout {
            let e = non_negative("encoder.runout.eccentricity", r.eccentricity)?;
            let rad = positive("encoder.runout.radius", r.radius)?;
            finite("encoder.runout.phase", r.phase)?;
            if e >= rad {
                return Err(ConfigError::Inconsistent("encoder.runout.eccentricity"));
            }
        }
        let missing = match config.reference {
            Reference::MissingTeeth { count } => {
                if count == 0 || count >= lines {
                    return Err(ConfigError::OutOfRange("encoder.reference.count"));
                }
                if config.teeth.is_some() {
                    // One description of the wheel: a gap, or the list of teeth.
                    return Err(ConfigError::Inconsistent("encoder.teeth"));
                }
                count
            }
            _ => 0,
        };
        let mut present = vec![true; lines as usize];
        if let Some(teeth) = &config.teeth {
            if teeth.is_empty() || teeth.windows(2).any(|w| w[0] >= w[1]) {
                return Err(ConfigError::Inconsistent("encoder.teeth"));
            }
            if teeth.iter().any(|&k| k >= lines) {
                return Err(ConfigError::OutOfRange("encoder.teeth"));
            }
            present.iter_mut().for_each(|p| *p = false);
            for &k in teeth {
                present[k as usize] = true;
            }
        }
        for p in present.iter_mut().take(missing as usize) {
            *p = false;
        }
        let [g0, g1] = config.glitch_window;
        if !(g0.is_finite() && g1.is_finite() && 0.0 <= g0 && g0 <= g1 && g1 <= 1.0) {
            return Err(ConfigError::OutOfRange("encoder.glitch_window"));
        }
        if let Some(d) = config.duty {
            if !(d.is_finite() && d > 0.0 && d < 1.0) {
                return Err(ConfigError::OutOfRange("encoder.duty"));
            }
        }
        let pitch = TAU / f64::from(lines);
        let runout = |theta: f64| match config.runout {
            Some(r) => r.eccentricity / r.radius * (theta + r.phase).sin(),
            None => 0.0,
        };
        let mut rng_pitch = stream(config.seed, 3);
        // Rising marks of each channel (line, index), in angle order.
        let mut rising: [Vec<Mark>; 2] = [Vec::with_capacity(lines as usize), Vec::new()];
        if config.reference == Reference::Index {
            let nominal = -0.5 * pitch;
            rising[1].push(Mark {
                angle: nominal + runout(nominal),
                tooth: 0,
                index: true,
                rising: true,
            });
        }
        for k in 0..lines {
            let nominal = f64::from(k) * pitch;
            let mut err = config.pitch_errors.get(k as usize).copied().unwrap_or(0.0);
            if config.pitch_error_std > 0.0 {
                // Drawn for every position, present or not: a pattern does not change the
                // errors of the teeth it keeps.
                err += config.pitch_error_std * gaussian(&mut rng_pitch);
            }
            if !present[k as usize] {
                continue;
            }
            rising[0].push(Mark {
                angle: nominal + err + runout(nominal),
                tooth: k,
                index: false,
                rising: true,
            });
        }
        let mut marks = Vec::with_capacity(2 * (lines as usize + 1));
        for channel in &rising {
            let ordered = channel.windows(2).all(|w| w[0].angle < w[1].angle);
            let span_ok = match (channel.first(), channel.last()) {
                (Some(a), Some(b)) => b.angle - a.angle < TAU,
                _ => true,
            };
            if !ordered || !span_ok {
                // Errors so large that marks swap places or reach into the next revolution.
                return Err(ConfigError::Inconsistent("encoder.pitch_errors"));
            }
            for (i, m) in channel.iter().enumerate() {
                marks.push(*m);
                if let Some(d) = config.duty {
                    let fall = m.angle + d * pitch;
                    // The pulse must end before the next one of its channel starts.
                    let next = channel
                        .get(i + 1)
                        .map_or(channel[0].angle + TAU, |n| n.angle);
                    if fall >= next {
                        return Err(ConfigError::Inconsistent("encoder.duty"));
                    }
                    marks.push(Mark {
                        angle: fall,
                        rising: false,
                        ..*m
                    });
                }
            }
        }
        if rising[0].is_empty() {
            return Err(ConfigError::Inconsistent("encoder.teeth"));
        }
        // One table for both channels, by angle; a revolution starts at the first mark.
        marks.sort_by(|a, b| a.angle.total_cmp(&b.angle));
        let first = marks[0].angle;
        for m in &mut marks {
            if m.angle - first >= TAU {
                // A falling edge past the revolution's first mark belongs before it.
                m.angle -= TAU;
            }
        }
        marks.sort_by(|a, b| a.angle.total_cmp(&b.angle));
        // counter_bits ≤ 32 (checked above): the shift cannot overflow.
        let mask = (1u64 << config.counter_bits) - 1;
        let seed = config.seed;
        Ok(Encoder {
            config,
            marks,
            mask,
            rng_jitter: stream(seed, 0),
            rng_drop: stream(seed, 1),
            rng_glitch: stream(seed, 2),
            rng_falling: stream(seed, 4),
            pulse_dropped: [false; 2],
            pos: 0,
            started: false,
            last_line_time: None,
            stats: EncoderStats::default(),
        })
    }

    /// The validated configuration.
    pub fn config(&self) -> &EncoderConfig {
        &self.config
    }

    /// The marks of one revolution, sorted by angle.
    pub fn marks(&self) -> &[Mark] {
        &self.marks
    }

    /// Edge counters so far.
    pub fn stats(&self) -> EncoderStats {
        self.stats
    }

    /// Shaft angle of global mark `j` (revolution ⌊j/m⌋, slot j mod m), rad.
    pub fn mark_angle(&self, j: i64) -> f64 {
        let m = self.marks.len() as i64;
        let rev = j.div_euclid(m);
        let slot = j.rem_euclid(m) as usize;
        TAU * rev as f64 + self.marks[slot].angle
    }

    /// Timer value a capture at time `t` reads: ⌊t·timer_hz⌋ + counter_start, masked.
    pub fn quantize(&self, t: f64) -> u32 {
        let ticks = (t * self.config.timer_hz).floor() as i64;
        (ticks.wrapping_add(i64::from(self.config.counter_start)) as u64 & self.mask) as u32
    }

    fn locate(&mut self, phi: f64) {
        let m = self.marks.len() as i64;
        let a0 = self.marks[0].angle;
        let mut j = ((phi - a0) / TAU).floor() as i64 * m;
        while self.mark_angle(j + 1) <= phi {
            j += 1;
        }
        while self.mark_angle(j) > phi {
            j -= 1;
        }
        self.pos = j;
        self.started = true;
    }

    /// Generates the edges of the shaft-angle segment `seg` (φ over one step), in time
    /// order, calling `emit` for each. Segments must be passed in order and contiguous.
    pub fn process<F: FnMut(&Edge)>(&mut self, seg: &ComponentPoly, emit: &mut F) {
        if !self.started {
            self.locate(seg.base);
        }
        let (_, mut d_prev) = seg.eval_rel(0.0);
        let mut theta_prev = 0.0;
        let mut theta_a = 0.0;
        let mut p_a = 0.0;
        for j in 1..=TURN_SAMPLES {
            let theta = f64::from(j) / f64::from(TURN_SAMPLES);
            let (_, d) = seg.eval_rel(theta);
            if d_prev * d < 0.0 {
                let turn = bisect_derivative(seg, theta_prev, theta, d_prev);
                let (p_turn, _) = seg.eval_rel(turn);
                self.monotone(seg, theta_a, p_a, turn, p_turn, emit);
                theta_a = turn;
                p_a = p_turn;
            }
            if d != 0.0 {
                d_prev = d;
            }
            theta_prev = theta;
        }
        let (p_end, _) = seg.eval_rel(1.0);
        self.monotone(seg, theta_a, p_a, 1.0, p_end, emit);
    }

    fn monotone<F: FnMut(&Edge)>(
        &mut self,
        seg: &ComponentPoly,
        theta_a: f64,
        p_a: f64,
        theta_b: f64,
        p_b: f64,
        emit: &mut F,
    ) {
        let mut lo = theta_a;
        if p_b > p_a {
            loop {
                let target = self.mark_angle(self.pos + 1) - seg.base;
                if target > p_b {
                    break;
                }
                let theta = solve(seg, target, lo, theta_b, 1.0);
                self.pos += 1;
                self.crossing(seg.t0 + theta * seg.h, Direction::Forward, self.pos, emit);
                lo = theta;
            }
        } else if p_b < p_a {
            loop {
                let target = self.mark_angle(self.pos) - seg.base;
                if target <= p_b {
                    break;
                }
                let theta = solve(seg, target, lo, theta_b, -1.0);
                let j = self.pos;
                self.pos -= 1;
                self.crossing(seg.t0 + theta * seg.h, Direction::Reverse, j, emit);
                lo = theta;
            }
        }
    }

    fn crossing<F: FnMut(&Edge)>(&mut self, t: f64, direction: Direction, j: i64, emit: &mut F) {
        let m = self.marks.len() as i64;
        let mark = self.marks[j.rem_euclid(m) as usize];
        let revolution = j.div_euclid(m);
        let channel = usize::from(mark.index);
        self.stats.crossings += 1;
        if !mark.rising {
            // The end of a pulse: its own jitter stream; lost with the pulse's rising edge.
            let jitter = if self.config.jitter > 0.0 {
                self.config.jitter * gaussian(&mut self.rng_falling)
            } else {
                0.0
            };
            let dropped = std::mem::take(&mut self.pulse_dropped[channel]);
            self.deliver(t, jitter, direction, mark, revolution, dropped, emit);
            return;
        }
        let jitter = if self.config.jitter > 0.0 {
            self.config.jitter * gaussian(&mut self.rng_jitter)
        } else {
            0.0
        };
        let dropped = self.config.drop_probability > 0.0
            && self.rng_drop.gen::<f64>() < self.config.drop_probability;
        if !mark.index {
            if self.config.glitch_probability > 0.0
                && self.rng_glitch.gen::<f64>() < self.config.glitch_probability
            {
                let [lo, hi] = self.config.glitch_window;
                let u = lo + (hi - lo) * self.rng_glitch.gen::<f64>();
                if let Some(tp) = self.last_line_time {
                    let tg = tp + u * (t - tp);
                    self.stats.glitches += 1;
                    self.stats.edges += 1;
                    emit(&Edge {
                        ticks: self.quantize(tg),
                        direction,
                        index: false,
                        glitch: true,
                        true_time: tg,
                        seen_time: tg,
                        tooth: mark.tooth,
                        revolution,
                        rising: true,
                        dropped: false,
                    });
                }
            }
            self.last_line_time = Some(t);
        }
        self.pulse_dropped[channel] = dropped;
        self.deliver(t, jitter, direction, mark, revolution, dropped, emit);
    }

    /// Delivers the edge of `mark` crossed at `t` (or counts it as dropped).
    #[allow(clippy::too_many_arguments)]
    fn deliver<F: FnMut(&Edge)>(
        &mut self,
        t: f64,
        jitter: f64,
        direction: Direction,
        mark: Mark,
        revolution: i64,
        dropped: bool,
        emit: &mut F,
    ) {
        if dropped {
            self.stats.dropped += 1;
            if !self.config.emit_dropped {
                return;
            }
        } else if mark.rising {
            self.stats.edges += 1;
            if mark.index {
                self.stats.index_pulses += 1;
            }
        } else {
            self.stats.falling += 1;
        }
        emit(&Edge {
            ticks: self.quantize(t + jitter),
            direction,
            index: mark.index,
            glitch: false,
            true_time: t,
            seen_time: t + jitter,
            tooth: mark.tooth,
            revolution,
            rising: mark.rising,
            dropped,
        });
    }
}

/// θ in [lo, hi] where seg(θ) − base = target, for a segment monotone on [lo, hi] in the
/// direction `dir` (+1 increasing, −1 decreasing). Newton safeguarded by bisection.
fn solve(seg: &ComponentPoly, target: f64, mut lo: f64, mut hi: f64, dir: f64) -> f64 {
    // Start from the tangent at lo (the previous edge): accurate to O(Δθ²) when edges are
    // dense in the step.
    let (p_lo, d_lo) = seg.eval_rel(lo);
    let mut theta = if d_lo * dir > 0.0 {
        lo + (target - p_lo) / d_lo
    } else {
        0.5 * (lo + hi)
    };
    if !(theta > lo && theta < hi) {
        theta = 0.5 * (lo + hi);
    }
    for _ in 0..MAX_ITER {
        let (p, d) = seg.eval_rel(theta);
        let g = dir * (p - target);
        if g == 0.0 {
            return theta;
        }
        if g < 0.0 {
            lo = theta;
        } else {
            hi = theta;
        }
        let mut next = theta - (p - target) / d;
        if !(next > lo && next < hi) {
            next = 0.5 * (lo + hi);
        }
        let done = (next - theta).abs() <= THETA_TOL;
        theta = next;
        if done || hi - lo <= THETA_TOL {
            break;
        }
    }
    theta
}

/// Zero of dφ/dθ between a and b, where it changes sign (d_a is its value at a).
fn bisect_derivative(seg: &ComponentPoly, mut a: f64, mut b: f64, d_a: f64) -> f64 {
    let sa = d_a.signum();
    for _ in 0..60 {
        let m = 0.5 * (a + b);
        let (_, d) = seg.eval_rel(m);
        if d == 0.0 {
            return m;
        }
        if d.signum() == sa {
            a = m;
        } else {
            b = m;
        }
        if b - a <= THETA_TOL {
            break;
        }
    }
    0.5 * (a + b)
}

#[cfg(test)]
#[allow(clippy::unwrap_used, clippy::expect_used)]
mod tests {
    use super::*;

    fn line(t0: f64, h: f64, base: f64, rate: f64) -> ComponentPoly {
        let mut coeffs = [0.0; crate::engine::ode::MAX_DENSE_DEGREE];
        coeffs[0] = rate * h;
        ComponentPoly {
            t0,
            h,
            base,
            degree: 1,
            coeffs,
        }
    }

    #[test]
    fn mark_table_reflects_reference_and_errors() {
        let mut c = EncoderConfig::ideal(8, 1e6);
        c.reference = Reference::MissingTeeth { count: 2 };
        let e = Encoder::new(c.clone()).unwrap();
        assert_eq!(e.marks().len(), 6);
        assert_eq!(e.marks()[0].tooth, 2);
        c.reference = Reference::Index;
        let e = Encoder::new(c.clone()).unwrap();
        assert_eq!(e.marks().len(), 9);
        assert!(e.marks()[0].index && e.marks()[0].angle < 0.0);
        c.pitch_errors = vec![0.0; 8];
        c.pitch_errors[3] = 0.9 * TAU / 8.0;
        assert!(Encoder::new(c.clone()).is_ok());
        c.pitch_errors[3] = 1.1 * TAU / 8.0;
        assert_eq!(
            Encoder::new(c.clone()).err(),
            Some(ConfigError::Inconsistent("encoder.pitch_errors"))
        );
        c.pitch_errors.clear();
        c.runout = Some(Runout {
            eccentricity: 1e-4,
            radius: 0.02,
            phase: 0.3,
        });
        let e = Encoder::new(c.clone()).unwrap();
        let m3 = e.marks().iter().find(|m| m.tooth == 3 && !m.index).unwrap();
        let nominal = 3.0 * TAU / 8.0;
        assert!((m3.angle - nominal - 5e-3 * (nominal + 0.3).sin()).abs() < 1e-15);
        c.counter_bits = 33;
        assert!(Encoder::new(c).is_err());
    }

    #[test]
    fn reversal_inside_a_step_gives_backward_edges() {
        let mut e = Encoder::new(EncoderConfig::ideal(8, 1e9)).unwrap();
        let pitch = TAU / 8.0;
        // φ = pitch/2 + 3·pitch·θ − 4·pitch·θ²: peak 1.0625 pitch at θ = 3/8, end −pitch/2.
        let mut coeffs = [0.0; crate::engine::ode::MAX_DENSE_DEGREE];
        coeffs[0] = 3.0 * pitch;
        coeffs[1] = -4.0 * pitch;
        let seg = ComponentPoly {
            t0: 0.0,
            h: 1.0,
            base: 0.5 * pitch,
            degree: 2,
            coeffs,
        };
        let mut edges = Vec::new();
        e.process(&seg, &mut |ed| edges.push(*ed));
        let dirs: Vec<i8> = edges
            .iter()
            .map(|e| {
                if e.direction == Direction::Forward {
                    1
                } else {
                    -1
                }
            })
            .collect();
        let teeth: Vec<u32> = edges.iter().map(|e| e.tooth).collect();
        // Up across mark 1 (θ s.t. φ = pitch), then back down across 1 and 0.
        assert_eq!(dirs, vec![1, -1, -1]);
        assert_eq!(teeth, vec![1, 1, 0]);
        for ed in &edges {
            let th = ed.true_time;
            let phi = 0.5 * pitch + 3.0 * pitch * th - 4.0 * pitch * th * th;
            let k = f64::from(ed.tooth);
            assert!((phi - k * pitch).abs() < 1e-12, "{phi} vs {}", k * pitch);
        }
        // Then the next (forward) segment starting below zero re-crosses mark 0.
        let seg2 = line(1.0, 1.0, -0.5 * pitch, pitch);
        e.process(&seg2, &mut |ed| edges.push(*ed));
        let last = edges.last().unwrap();
        assert_eq!(
            (last.tooth, last.direction, last.revolution),
            (0, Direction::Forward, 0)
        );
        assert!((last.true_time - 1.5).abs() < 1e-12);
        assert_eq!(e.stats().crossings, 4);
    }

    #[test]
    fn patterns_pulses_and_truth_leave_the_rising_edges_alone() {
        // A 12+1 wheel on a 24-position grid, pulses half a grid pitch wide.
        let mut c = EncoderConfig::ideal(24, 1e6);
        let mut teeth: Vec<u32> = (0..12).map(|i| 2 * i).collect();
        teeth.insert(4, 7);
        c.teeth = Some(teeth.clone());
        c.jitter = 1e-6;
        c.drop_probability = 0.1;
        c.glitch_probability = 0.1;
        c.glitch_window = [0.3, 0.7];
        c.seed = 9;
        let edges = |c: &EncoderConfig| {
            let mut e = Encoder::new(c.clone()).unwrap();
            let mut out = Vec::new();
            e.process(&line(0.0, 1.0, 0.1, 20.0 * TAU), &mut |ed| out.push(*ed));
            out
        };
        let plain = edges(&c);
        assert!(plain.iter().all(|e| e.rising && !e.dropped));
        let positions: std::collections::BTreeSet<u32> = plain
            .iter()
            .filter(|e| !e.glitch)
            .map(|e| e.tooth)
            .collect();
        assert_eq!(positions.into_iter().collect::<Vec<_>>(), {
            let mut t = teeth.clone();
            t.sort_unstable();
            t
        });
        // Falling edges and the ground truth of dropped edges add edges, never change the
        // rising ones (their draws come from streams of their own).
        c.duty = Some(0.5);
        c.emit_dropped = true;
        let all = edges(&c);
        let rising: Vec<Edge> = all
            .iter()
            .filter(|e| e.rising && !e.dropped)
            .copied()
            .collect();
        // The same edges; the crossing solver starts from the previous crossing, so the last
        // digit of a time may differ.
        assert_eq!(rising.len(), plain.len());
        for (a, b) in rising.iter().zip(&plain) {
            assert!((a.true_time - b.true_time).abs() < 1e-12, "{a:?} {b:?}");
            let same = Edge {
                true_time: b.true_time,
                seen_time: b.seen_time,
                ..*a
            };
            assert_eq!(&same, b);
        }
        let pitch = TAU / 24.0;
        for e in all.iter().filter(|e| !e.rising && !e.dropped) {
            // Each pulse ends half a grid pitch after its tooth: 20 turns/s, 0.1 rad at t = 0.
            let angle = 0.1 + 20.0 * TAU * e.true_time;
            let off = (angle - f64::from(e.tooth) * pitch).rem_euclid(TAU);
            assert!((off - 0.5 * pitch).abs() < 1e-9, "{off}");
        }
        // A dropped tooth loses both its edges.
        let dropped: Vec<&Edge> = all.iter().filter(|e| e.dropped).collect();
        assert!(
            !dropped.is_empty() && dropped.len() % 2 == 0,
            "{}",
            dropped.len()
        );
        // Glitches fall within 30–70 % of the interval before the edge they precede.
        let line_edges: Vec<&Edge> = all.iter().filter(|e| e.rising && !e.glitch).collect();
        for g in all.iter().filter(|e| e.glitch) {
            let k = line_edges.partition_point(|e| e.true_time < g.true_time);
            if k == 0 || k >= line_edges.len() {
                continue;
            }
            let (a, b) = (line_edges[k - 1].true_time, line_edges[k].true_time);
            let u = (g.true_time - a) / (b - a);
            assert!((0.3 - 1e-9..=0.7 + 1e-9).contains(&u), "{u}");
        }
        // A pulse as wide as a pitch, or two descriptions of one wheel, are refused.
        c.duty = Some(1.0);
        assert_eq!(
            Encoder::new(c.clone()).err(),
            Some(ConfigError::OutOfRange("encoder.duty"))
        );
        c.duty = None;
        c.reference = Reference::MissingTeeth { count: 2 };
        assert_eq!(
            Encoder::new(c).err(),
            Some(ConfigError::Inconsistent("encoder.teeth"))
        );
    }

    #[test]
    fn quantize_floors_and_wraps() {
        let mut c = EncoderConfig::ideal(4, 1e6);
        c.counter_bits = 16;
        c.counter_start = 65530;
        let e = Encoder::new(c).unwrap();
        assert_eq!(e.quantize(0.0), 65530);
        assert_eq!(e.quantize(5.9e-6), 65535);
        assert_eq!(e.quantize(6.0e-6 + 1e-12), 0);
        assert_eq!(e.quantize(1.0), ((1_000_000u64 + 65530) & 0xFFFF) as u32);
    }
}
