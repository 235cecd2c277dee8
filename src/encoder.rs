//! Encoder geometry and capture-timer setup, validated once.
//!
//! An [`EncoderConfig`] names the wheel and how its revolutions are framed ([`Wheel`]: a
//! uniform disc with an index pulse, a uniform disc without one, or a toothed wheel whose
//! [`Pattern`] of missing or extra teeth frames the revolution), the capture timer (clock,
//! counter width, input prescaler), the speed estimator and the tolerances of the edge checks
//! ([`Tolerances`]). [`Encoder::new`] validates it once and derives everything the per-edge
//! path needs as integers: the timeout and the acceptance band as tick arithmetic, the pitch of
//! every tooth in angle units.
//!
//! # Angle units
//!
//! Angles are integers: one unit is `2π / (positions · 2^16)`, so a nominal pitch (one grid
//! position) is exactly [`PITCH_UNITS`] = 65 536 units and a turn at most 2^30 (positions are at
//! most [`MAX_LINES`]). A speed sample is a span of units over a count of ticks, both exact,
//! and speeds are compared by 64-bit cross products: no float and no rounding on the per-edge
//! path. A learned per-tooth correction fits in 16 bits ([`crate::pitch::Corrected`]).
//!
//! # Teeth and frames
//!
//! Edges are numbered within a revolution: tooth 0 is the frame tooth — the first edge after
//! the index pulse, or on a pattern wheel the edge that ends its most distinctive pitch (the
//! gap of a missing-tooth wheel, the extra tooth of a `12+1` wheel). `pitch(k)` is the angle
//! from edge k−1 to edge k; on a 60-2 wheel `pitch(0)` spans the gap (three positions).

// The per-edge path runs through this module: no integer operation here may overflow or
// divide by zero, and no index may fail, in a debug build either (`panic-free.sh dev` in
// examples/qemu checks the image).
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::indexing_slicing)
)]

use crate::error::{positive, tri, ConfigError};
use crate::math;

/// Largest number of lines (grid positions) per revolution: a turn is at most 2^30 units.
pub const MAX_LINES: u16 = 16_384;
/// Largest grid of a [`Pattern`] (its teeth are a `u128` bit mask).
pub const MAX_PATTERN_POSITIONS: u8 = 128;
/// Most teeth a [`Pattern`] may have (its alignment search is a `u64` bit mask).
pub const MAX_PATTERN_TEETH: usize = 64;
/// Largest `K` of the `K`-edge speed estimator (the length of the timestamp ring).
pub const MAX_SPAN: usize = 32;
/// Angle units per grid position (one nominal pitch).
pub const PITCH_UNITS: u32 = 1 << 16;

// Ring and history indices are masked with these: they must be powers of two.
const _: () = assert!(MAX_SPAN.is_power_of_two() && MAX_PATTERN_TEETH.is_power_of_two());

/// A toothed wheel: teeth at some of `positions` equally spaced grid positions.
///
/// The pattern frames the revolution, so it must not look the same after any rotation short of
/// a full turn (a wheel with three equal gaps 120° apart cannot tell its revolutions apart) and
/// must have at least one pitch that differs from the most common one. Examples:
///
/// - `Pattern::missing_teeth(60, 2)`: 60-2 (58 teeth, one gap of three pitches);
/// - `Pattern::with_gaps(36, &[(0, 2), (12, 2), (27, 2)])`: a 36-2-2-2 wheel;
/// - `Pattern::from_teeth(24, &[0, 1, 2, 4, ..., 22])`: a 12+1 wheel on a half-pitch grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Pattern {
    positions: u8,
    present: u128,
}

impl Pattern {
    /// The wheel whose teeth are the set bits of `present` (bit `i` = a tooth at grid position
    /// `i` of `positions`). Checked by [`Encoder::new`].
    pub const fn from_mask(positions: u8, present: u128) -> Self {
        Pattern { positions, present }
    }

    /// A wheel of `positions` positions with the last `missing` of them absent: one gap.
    /// `missing_teeth(36, 2)` is the common 36-2 crank wheel.
    pub const fn missing_teeth(positions: u8, missing: u8) -> Self {
        let teeth = positions.saturating_sub(missing) as u32;
        let present = if teeth >= 128 {
            u128::MAX
        } else {
            (1u128 << teeth).wrapping_sub(1)
        };
        Pattern { positions, present }
    }

    /// A wheel of `positions` positions with gaps `(first missing position, count)`.
    pub const fn with_gaps(positions: u8, gaps: &[(u8, u8)]) -> Result<Self, ConfigError> {
        if positions == 0 || positions > MAX_PATTERN_POSITIONS {
            return Err(ConfigError::OutOfRange("pattern.positions"));
        }
        let mut present = mask_of(positions);
        let mut rest = gaps;
        while let [(start, count), tail @ ..] = rest {
            let (start, count) = (*start, *count);
            // Two u8 in a u16: the sum does not wrap (and within a u8 past this check).
            if start >= positions || count == 0 || (start as u16).wrapping_add(count as u16) > 255 {
                return Err(ConfigError::OutOfRange("pattern.gaps"));
            }
            let mut p = start;
            while p < start.wrapping_add(count) {
                // A gap may run past the last position onto the first ones.
                let at = match p.checked_rem(positions) {
                    Some(at) => at,
                    None => 0,
                };
                present &= !(1u128 << at);
                p = p.wrapping_add(1);
            }
            rest = tail;
        }
        Ok(Pattern { positions, present })
    }

    /// A wheel of `positions` positions with teeth at the listed positions.
    pub const fn from_teeth(positions: u8, teeth: &[u8]) -> Result<Self, ConfigError> {
        if positions == 0 || positions > MAX_PATTERN_POSITIONS {
            return Err(ConfigError::OutOfRange("pattern.positions"));
        }
        let mut present = 0u128;
        let mut rest = teeth;
        while let [p, tail @ ..] = rest {
            if *p >= positions {
                return Err(ConfigError::OutOfRange("pattern.teeth"));
            }
            present |= 1u128 << *p;
            rest = tail;
        }
        Ok(Pattern { positions, present })
    }

    /// Grid positions per revolution.
    pub const fn positions(&self) -> u8 {
        self.positions
    }

    /// The present teeth as a bit mask over the grid positions.
    pub const fn present(&self) -> u128 {
        self.present
    }

    /// Number of teeth.
    pub const fn teeth(&self) -> u32 {
        (self.present & mask_of(self.positions)).count_ones()
    }
}

/// Whether this build takes pattern wheels (the `pattern-wheels` feature).
const PATTERNS: bool = cfg!(feature = "pattern-wheels");

/// Bits `0..n` set.
const fn mask_of(n: u8) -> u128 {
    if n >= 128 {
        u128::MAX
    } else {
        (1u128 << n).wrapping_sub(1)
    }
}

/// The wheel, and with it how revolutions are framed. There is no default: a configuration
/// names its framing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Wheel {
    /// A uniform disc of `lines` lines and a separate index pulse once per revolution,
    /// reported with its timestamp through `on_index`.
    Indexed {
        /// Lines per revolution (2 to [`MAX_LINES`]).
        lines: u16,
    },
    /// A uniform disc without a once-per-revolution marker: teeth cannot be told apart,
    /// "revolutions" are counted in edges from the first, and a fault is found from the
    /// intervals alone.
    Unframed {
        /// Lines per revolution (2 to [`MAX_LINES`]).
        lines: u16,
    },
    /// A toothed wheel whose missing or extra teeth frame the revolution (needs the
    /// `pattern-wheels` feature, on by default; refused as `ConfigError::Unsupported("wheel")`
    /// without it).
    Pattern(Pattern),
}

impl Wheel {
    /// Grid positions per revolution (lines of a uniform disc).
    pub const fn positions(&self) -> u16 {
        match *self {
            Wheel::Indexed { lines } | Wheel::Unframed { lines } => lines,
            Wheel::Pattern(p) => p.positions as u16,
        }
    }
}

/// How the speed sample at each edge is estimated.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Estimator {
    /// Angle over the interval of the last `k` edges (1 = per-edge interval). Averaging `k`
    /// edges divides the quantization error by `k` and attenuates a load cycle of `E` edges by
    /// about (π·k/E)²/6, negligible while `k` ≪ `E`.
    Edges(u16),
}

/// Tolerances of the edge checks. The defaults suit index discs and the common crank wheels
/// (36-1, 36-2, 60-2, 8-1, 36-2-2-2, 12+1) from cranking to full speed; see each field.
///
/// Terms: the *per-pitch interval* of an edge is its interval divided by the nominal pitch it
/// spans (a gap of two missing teeth spans three); the *swing* is the ratio of consecutive
/// per-pitch intervals. Real cranking swings between about 0.5 and 2 from tooth to tooth
/// (compression strokes on an 8-1 wheel reach 1.6; a clean signal stays within 0.45–2.2).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Tolerances {
    /// Edges whose swing lies within `[1/accept, accept]` are taken at once (the fast path);
    /// others are judged with the two edges that follow them. Default 1.45: steady running
    /// and ordinary ripple stay inside, so the careful judgement costs nothing on average.
    /// 1.05 to 2.
    pub accept: f32,
    /// An edge arriving before this fraction of the expected interval is a glitch outright,
    /// whatever follows: no real tooth swings that far (1/2.2 = 0.45 is the fastest real
    /// swing, less a margin). Default 0.35. 0.05 to 0.6.
    pub glitch_fraction: f32,
    /// How much better (in squared log swings summed over the judged intervals) a fault must
    /// explain the intervals than a clean tooth before it is called. Default 0.3: a steady
    /// shaft with one tooth missing scores 0.96 in favour of the fault and a noise pulse
    /// between 30 and 70 % of a tooth at least 0.96; a compression swing of 1.6 for one tooth
    /// scores 0.34 in favour of a missing tooth that is not there, so the margin keeps it a
    /// tooth. At a long pitch of p pitches (a wheel's gap) every fault leaves less evidence (a
    /// lost tooth stretches the gap by (p + 1)/p only; a noise pulse late in it looks like a
    /// gap a pitch shorter): there the margin is this one times (ln((p + 1)/p)/ln 2)² (0.05 at
    /// a 60-2 wheel's gap, where a lost first tooth scores 0.17). 0.05 to 2.
    pub fault_margin: f32,
}

impl Tolerances {
    /// The defaults (see each field), as a `const`.
    pub const DEFAULT: Tolerances = Tolerances {
        accept: 1.45,
        glitch_fraction: 0.35,
        fault_margin: 0.3,
    };
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances::DEFAULT
    }
}

/// Encoder and capture-timer description, in SI units. Built by a constructor that names the
/// wheel ([`EncoderConfig::indexed`], [`EncoderConfig::unframed`], [`EncoderConfig::pattern`],
/// [`EncoderConfig::missing_teeth`]), then adjusted field by field.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EncoderConfig {
    /// The wheel and its framing.
    pub wheel: Wheel,
    /// Capture timer clock, Hz.
    pub timer_hz: f64,
    /// Width of the capture counter in bits (16 to 32); timestamps wrap modulo 2^bits.
    pub counter_bits: u8,
    /// Input prescaler of the capture: one capture every `prescaler` edges (1, 2, 4 or 8;
    /// uniform discs only, and `lines` must be a multiple of it).
    pub prescaler: u8,
    /// Slowest speed still considered running, rad/s: an edge later than the longest pitch at
    /// this speed means the shaft stood still (timeout).
    pub min_speed: f64,
    /// Speed estimator.
    pub estimator: Estimator,
    /// Tolerances of the edge checks.
    pub tolerances: Tolerances,
}

impl EncoderConfig {
    const fn with_wheel(wheel: Wheel, timer_hz: f64) -> Self {
        EncoderConfig {
            wheel,
            timer_hz,
            counter_bits: 32,
            prescaler: 1,
            min_speed: 1.0,
            estimator: Estimator::Edges(1),
            tolerances: Tolerances::DEFAULT,
        }
    }

    /// A uniform disc of `lines` lines framed by an index pulse; a 32-bit timer at `timer_hz`,
    /// per-edge speed, a minimum speed of 1 rad/s, default tolerances.
    pub const fn indexed(lines: u16, timer_hz: f64) -> Self {
        Self::with_wheel(Wheel::Indexed { lines }, timer_hz)
    }

    /// A uniform disc of `lines` lines without a frame marker (otherwise as
    /// [`EncoderConfig::indexed`]).
    pub const fn unframed(lines: u16, timer_hz: f64) -> Self {
        Self::with_wheel(Wheel::Unframed { lines }, timer_hz)
    }

    /// A toothed wheel framed by its pattern (otherwise as [`EncoderConfig::indexed`]).
    pub const fn pattern(pattern: Pattern, timer_hz: f64) -> Self {
        Self::with_wheel(Wheel::Pattern(pattern), timer_hz)
    }

    /// A missing-tooth wheel such as 60-2: `positions` positions, the last `missing` absent.
    pub const fn missing_teeth(positions: u8, missing: u8, timer_hz: f64) -> Self {
        Self::pattern(Pattern::missing_teeth(positions, missing), timer_hz)
    }
}

/// How the frame is found, derived from the [`Wheel`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Framing {
    /// An index pulse.
    Index,
    /// The wheel's pattern.
    Pattern,
    /// None.
    None,
}

/// A validated encoder: the configuration and the integers the per-edge path works with.
/// Memory: about 130 bytes whatever the wheel (a pattern's pitches are one byte per tooth).
#[derive(Debug, Clone, PartialEq)]
pub struct Encoder {
    config: EncoderConfig,
    framing: Framing,
    edges: u16,
    k: u16,
    mask: u32,
    timeout: u32,
    /// The accept band as 0.32 fixed-point fractions of the sum of the last `K` intervals: its
    /// lower end `1/(accept·K)` and half its width `(accept − 1/accept)/(2K)` (below 1 for
    /// `accept` ≤ 2).
    band_lo: u32,
    band_half_width: u32,
    /// The largest `K`-interval sum whose band stays within the timeout (above it the shaft
    /// is near the minimum speed and every edge is judged carefully).
    band_sum_max: u32,
    /// Most intervals whose total is sure to fit in 32 bits (each within the timeout).
    bulk_max: u32,
    timer_hz: f32,
    /// Radians per angle unit.
    unit_rad: f32,
    /// Nominal pitch of every tooth in grid positions (pattern wheels only).
    pattern: [u8; MAX_PATTERN_TEETH],
    /// Grid positions of the most common pitch.
    base: u8,
    /// Teeth whose pitch is longer / shorter than the base (pattern wheels), bit k = tooth k.
    long: u64,
    short: u64,
    /// Span of `k` nominal pitches on a uniform disc, units.
    uniform_span: u32,
    /// `R⁹`, `R` the wheel's pitch ratio nearest 1 among its long and short pitches (the
    /// smallest long pitch over the base, or the base over the largest short one); +∞ on a
    /// uniform disc. A swing of `R^0.9` or more (`s¹⁰ ≥ R⁹`) is nearly as large as the
    /// pattern itself.
    pattern_swing: f32,
    /// Whether every tooth has the same nominal pitch.
    uniform: bool,
}

impl Encoder {
    /// Copies `other` in place field by field (a whole-struct copy of its ~190 bytes would
    /// call `memcpy`, which configuration would then link); the list names every field.
    pub(crate) fn copy_from(&mut self, other: &Encoder) {
        let Encoder {
            config,
            framing,
            edges,
            k,
            mask,
            timeout,
            band_lo,
            band_half_width,
            band_sum_max,
            bulk_max,
            timer_hz,
            unit_rad,
            pattern,
            base,
            long,
            short,
            uniform_span,
            pattern_swing,
            uniform,
        } = self;
        *config = other.config;
        (*framing, *edges, *k, *mask) = (other.framing, other.edges, other.k, other.mask);
        (*timeout, *band_lo, *band_half_width) =
            (other.timeout, other.band_lo, other.band_half_width);
        (*band_sum_max, *bulk_max, *timer_hz) =
            (other.band_sum_max, other.bulk_max, other.timer_hz);
        (*unit_rad, *base, *long, *short) = (other.unit_rad, other.base, other.long, other.short);
        (*uniform_span, *pattern_swing, *uniform) =
            (other.uniform_span, other.pattern_swing, other.uniform);
        // Without pattern wheels every encoder's pattern is all zeros: nothing to copy.
        if PATTERNS {
            *pattern = other.pattern;
        }
    }

    /// The encoder of an unconfigured monitor: no edges, so the monitor ignores everything
    /// until `configure` replaces it.
    pub const UNCONFIGURED: Encoder = Encoder {
        config: EncoderConfig {
            wheel: Wheel::Unframed { lines: 0 },
            timer_hz: 0.0,
            counter_bits: 32,
            prescaler: 1,
            min_speed: 0.0,
            estimator: Estimator::Edges(1),
            tolerances: Tolerances::DEFAULT,
        },
        framing: Framing::None,
        edges: 0,
        k: 1,
        mask: u32::MAX,
        timeout: 0,
        band_lo: 0,
        band_half_width: 0,
        band_sum_max: 0,
        bulk_max: 0,
        timer_hz: 0.0,
        unit_rad: 0.0,
        pattern: [0; MAX_PATTERN_TEETH],
        base: 1,
        long: 0,
        short: 0,
        uniform_span: 0,
        pattern_swing: f32::INFINITY,
        uniform: true,
    };

    /// Validates `config` and derives the per-edge constants.
    ///
    /// Besides each field's range, the timer must fit the speed range: the longest pitch at
    /// `min_speed` must last fewer ticks than the counter holds (`Inconsistent("min_speed")`)
    /// and at least 2 ticks (`Inconsistent("timer_hz")`), and `K` of them must fit in 32 bits
    /// (`Inconsistent("estimator.edges")`).
    pub const fn new(config: EncoderConfig) -> Result<Self, ConfigError> {
        let mut pattern = [0u8; MAX_PATTERN_TEETH];
        let prescaler = config.prescaler;
        if !matches!(prescaler, 1 | 2 | 4 | 8) {
            return Err(ConfigError::OutOfRange("prescaler"));
        }
        let (framing, positions, edges, base, long, short) = match config.wheel {
            Wheel::Indexed { lines } | Wheel::Unframed { lines } => {
                if lines < 2 || lines > MAX_LINES {
                    return Err(ConfigError::OutOfRange("lines"));
                }
                // 1, 2, 4 or 8: never a division by zero.
                let p = prescaler as u16;
                let (rest, per) = match (lines.checked_rem(p), lines.checked_div(p)) {
                    (Some(r), Some(q)) => (r, q),
                    _ => (1, 0),
                };
                if rest != 0 || per < 2 {
                    return Err(ConfigError::Inconsistent("prescaler"));
                }
                let framing = match config.wheel {
                    Wheel::Indexed { .. } => Framing::Index,
                    _ => Framing::None,
                };
                (framing, lines, per, prescaler, 0, 0)
            }
            Wheel::Pattern(p) => {
                if !PATTERNS {
                    return Err(ConfigError::Unsupported("wheel"));
                }
                if prescaler != 1 {
                    return Err(ConfigError::Inconsistent("prescaler"));
                }
                let (edges, base, long, short) = tri!(pattern_table(p, &mut pattern));
                (
                    Framing::Pattern,
                    p.positions as u16,
                    edges,
                    base,
                    long,
                    short,
                )
            }
        };
        let timer_hz = tri!(positive("timer_hz", config.timer_hz));
        if timer_hz < 1.0 || timer_hz > 1.0e10 {
            return Err(ConfigError::OutOfRange("timer_hz"));
        }
        if config.counter_bits < 16 || config.counter_bits > 32 {
            return Err(ConfigError::OutOfRange("counter_bits"));
        }
        let mask = if config.counter_bits == 32 {
            u32::MAX
        } else {
            (1u32 << config.counter_bits).wrapping_sub(1)
        };
        let min_speed = tri!(positive("min_speed", config.min_speed));
        let Estimator::Edges(k) = config.estimator;
        if k == 0 || k > edges || k as usize > MAX_SPAN {
            return Err(ConfigError::OutOfRange("estimator.edges"));
        }
        let t = config.tolerances;
        tri!(check_range("tolerances.accept", t.accept, 1.05, 2.0));
        tri!(check_range(
            "tolerances.glitch_fraction",
            t.glitch_fraction,
            0.05,
            0.6
        ));
        tri!(check_range(
            "tolerances.fault_margin",
            t.fault_margin,
            0.05,
            2.0
        ));
        let longest = if matches!(framing, Framing::Pattern) {
            longest_pitch(&pattern, edges)
        } else {
            base
        };
        let grid = core::f64::consts::TAU / positions as f64;
        let timeout = grid * longest as f64 / min_speed * timer_hz;
        // Intervals are measured modulo the counter: a timeout beyond its range cannot be seen.
        if !timeout.is_finite() || timeout >= mask as f64 {
            return Err(ConfigError::Inconsistent("min_speed"));
        }
        // A pitch at the minimum speed shorter than 2 ticks carries no speed information.
        if timeout < 2.0 {
            return Err(ConfigError::Inconsistent("timer_hz"));
        }
        // A K-edge sample (a sum of K intervals) must fit in 32 bits even at the slowest speed.
        if timeout * k as f64 >= u32::MAX as f64 {
            return Err(ConfigError::Inconsistent("estimator.edges"));
        }
        let uniform = long == 0 && short == 0;
        let accept = t.accept as f64;
        Ok(Encoder {
            config,
            framing,
            edges,
            k,
            mask,
            timeout: math::ceil(timeout) as u32,
            band_lo: fraction_q32(1.0 / accept / k as f64),
            band_half_width: fraction_q32((accept - 1.0 / accept) / 2.0 / k as f64),
            // The band's top is mean·accept + 2 ticks at most: keep it at or below the timeout.
            band_sum_max: {
                let m = (math::floor(timeout) - 4.0) * k as f64 / accept;
                if m <= 0.0 {
                    0
                } else if m >= u32::MAX as f64 {
                    u32::MAX
                } else {
                    m as u32
                }
            },
            bulk_max: (u32::MAX as f64 / math::ceil(timeout)) as u32,
            timer_hz: timer_hz as f32,
            unit_rad: (grid / PITCH_UNITS as f64) as f32,
            pattern,
            base,
            long,
            short,
            // At most 32 · 255 · 2^16 (< 2^30): no wrap.
            uniform_span: (k as u32)
                .wrapping_mul(base as u32)
                .wrapping_mul(PITCH_UNITS),
            pattern_swing: if uniform || !matches!(framing, Framing::Pattern) {
                f32::INFINITY
            } else {
                let r = nearest_ratio(&pattern, edges, base);
                let r3 = r * r * r;
                (r3 * r3 * r3) as f32
            },
            uniform,
        })
    }

    /// The configuration this encoder was built from.
    pub const fn config(&self) -> &EncoderConfig {
        &self.config
    }
    /// How revolutions are framed.
    pub const fn framing(&self) -> Framing {
        // Without pattern wheels in the build, a pattern framing is never returned, so every
        // test for it folds away (it cannot be stored: `new` refuses pattern wheels then).
        match self.framing {
            Framing::Pattern if !PATTERNS => Framing::None,
            f => f,
        }
    }
    /// Captured edges per revolution (teeth, or lines over the prescaler).
    pub const fn edges(&self) -> u16 {
        self.edges
    }
    /// Edges averaged per speed sample.
    pub const fn samples_span(&self) -> u16 {
        self.k
    }
    /// The noise floor a δ window reports at a steady mean speed `omega` rad/s (sign
    /// ignored): one tick of quantisation at each end of a `K`-edge sample, on the wheel's
    /// shortest `K`-edge span Θ, `2·ω/(Θ·timer_hz)` (`2/(K·ticks per captured edge)` on a
    /// uniform disc; on a wheel with gaps the ordinary teeth's, which the window's extreme
    /// samples are on a steady shaft: [`crate::irregularity::Measurement::noise_floor`]),
    /// for judging beforehand whether a configuration resolves a δ (the alarm judges a window
    /// only when its floor is at most [`crate::alarm::AlarmConfig::floor_fraction`] of the
    /// limit). Configuration-time work: one pass over the teeth.
    pub fn noise_floor_at(&self, omega: f32) -> f32 {
        let (e, k) = (self.edges, self.k.max(1));
        // The K pitches ending at each tooth in turn, as a running sum (u64: no overflow).
        let pitch = |j: u16| u64::from(self.nominal_pitch(j.checked_rem(e).unwrap_or(0)));
        let mut span: u64 = (0..k).map(pitch).sum();
        let mut least = span;
        for j in 0..e {
            span = span
                .saturating_add(pitch(j.wrapping_add(k)))
                .saturating_sub(pitch(j));
            least = least.min(span);
        }
        2.0 * omega.abs() / (least as f32 * self.unit_rad * self.timer_hz)
    }
    /// Counter mask (2^bits − 1).
    pub const fn mask(&self) -> u32 {
        self.mask
    }
    /// Ticks without an edge after which the shaft is at standstill.
    pub const fn timeout_ticks(&self) -> u32 {
        self.timeout
    }
    /// The longest time between two [`crate::monitor::DeltaMonitor::poll`]s, in ticks, that is
    /// sure to see a standstill. The time since the last edge is read modulo the counter, and
    /// of the `2^bits − timeout` ticks after the timeout before the counter wraps past the last
    /// edge, the first half is where a poll sees the stop; the second half is where a `now`
    /// read a little before the last edge fed lands (the capture interrupt fed an edge between
    /// the periodic task's reading of the timer and its poll), which is no stop. Firmware polls
    /// at least this often and reads `now` at most this long before the last capture it fed
    /// (with a 16-bit counter and a minimum speed near its limit this can be a small part of
    /// the counter's period).
    pub const fn poll_interval_ticks(&self) -> u32 {
        // `new` keeps the timeout below the mask.
        let half = self.mask.saturating_sub(self.timeout) / 2;
        if half == 0 {
            1
        } else {
            half
        }
    }
    /// Timer clock, Hz.
    pub const fn timer_hz(&self) -> f32 {
        self.timer_hz
    }
    /// Radians per angle unit.
    pub const fn unit_rad(&self) -> f32 {
        self.unit_rad
    }
    /// Whether the counter is 32 bits wide: the captures of a batch are then the times the
    /// interval ring holds (with a narrower counter it holds them counted on past its wraps).
    #[inline(always)]
    pub(crate) fn ring_times(&self) -> bool {
        self.mask == u32::MAX
    }
    /// Most intervals a batch may take in one run (their total fits in 32 bits).
    pub(crate) fn bulk_max(&self) -> usize {
        self.bulk_max as usize
    }
    /// Whether every tooth has the same nominal pitch (a uniform disc).
    pub const fn is_uniform(&self) -> bool {
        !PATTERNS || self.uniform
    }
    /// Nominal pitch of `tooth` (the angle from the edge before it) in units; 0 beyond the
    /// wheel.
    pub fn nominal_pitch(&self, tooth: u16) -> u32 {
        // A grid pitch is under 256 positions: no wrap.
        self.grid_pitch(tooth).wrapping_mul(PITCH_UNITS)
    }
    /// Nominal pitch of `tooth` in grid positions (0 beyond the wheel).
    #[inline]
    pub(crate) fn grid_pitch(&self, tooth: u16) -> u32 {
        if tooth >= self.edges {
            0
        } else if self.framing() != Framing::Pattern {
            u32::from(self.base)
        } else {
            self.pattern
                .get(usize::from(tooth))
                .map_or(0, |&p| u32::from(p))
        }
    }
    /// Grid positions of the most common pitch.
    pub(crate) fn base_pitch(&self) -> u32 {
        u32::from(self.base)
    }
    /// `R⁹` for the wheel's pitch ratio `R` nearest 1 (+∞ on a uniform disc): see
    /// [`crate::speed`]'s recorded swings.
    pub(crate) fn pattern_swing(&self) -> f32 {
        if PATTERNS {
            self.pattern_swing
        } else {
            f32::INFINITY
        }
    }
    /// The smallest long pitch and the largest short one, in grid positions (`u8::MAX` and 0
    /// without such a pitch; always so without a pattern).
    #[cfg(feature = "pattern-wheels")]
    pub(crate) fn extreme_pitches(&self) -> (u8, u8) {
        if PATTERNS && matches!(self.framing, Framing::Pattern) {
            extreme_pitches(&self.pattern, self.edges, self.base)
        } else {
            (u8::MAX, 0)
        }
    }
    /// Teeth whose pitch is longer than the base (bit k = tooth k; pattern wheels).
    pub(crate) fn long_teeth(&self) -> u64 {
        if PATTERNS {
            self.long
        } else {
            0
        }
    }
    /// Teeth whose pitch is shorter than the base (bit k = tooth k; pattern wheels).
    pub(crate) fn short_teeth(&self) -> u64 {
        if PATTERNS {
            self.short
        } else {
            0
        }
    }
    /// Teeth that end two short pitches which together span at most one base pitch: the
    /// second half of a pitch split by an extra tooth (bit k = tooth k; pattern wheels).
    #[cfg(feature = "pattern-wheels")]
    pub(crate) fn pair_teeth(&self) -> u64 {
        if self.short_teeth() == 0 {
            return 0;
        }
        let mut pairs = 0u64;
        for t in 0..self.edges.min(64) {
            let prev = if t == 0 { self.edges } else { t }.wrapping_sub(1);
            let both = self.short.checked_shr(u32::from(t)).unwrap_or(0) & 1 == 1
                && self.short.checked_shr(u32::from(prev)).unwrap_or(0) & 1 == 1;
            if both
                && self.grid_pitch(t).wrapping_add(self.grid_pitch(prev)) <= u32::from(self.base)
            {
                pairs |= 1u64.checked_shl(u32::from(t)).unwrap_or(0);
            }
        }
        pairs
    }
    /// Span of `samples_span()` teeth on a uniform disc, units.
    pub const fn uniform_span(&self) -> u32 {
        self.uniform_span
    }
    /// The accept band around the mean of the last `K` intervals, whose sum is `sum`:
    /// `[mean/accept, mean·accept]`, widened by a tick each way for quantization, as
    /// `(lo, width)` for the modular test `dt − lo ≤ width` (`lo` may wrap below 0 for one-tick
    /// intervals: the test stays right). `None` near the minimum speed (a sum above
    /// `band_sum_max`), where the band would reach past the timeout.
    #[inline]
    pub(crate) fn band(&self, sum: u32) -> Option<(u32, u32)> {
        if sum > self.band_sum_max {
            return None;
        }
        let lo = mul_hi(sum, self.band_lo).wrapping_sub(1);
        let width = (mul_hi(sum, self.band_half_width) << 1).wrapping_add(3);
        Some((lo, width))
    }
}

/// `(x·f) >> 32`: the high word of the 64-bit product, one instruction on a Cortex-M4.
#[inline(always)]
fn mul_hi(x: u32, f: u32) -> u32 {
    (u64::from(x).wrapping_mul(u64::from(f)) >> 32) as u32
}

/// `x` (in `[0, 1)`) as a 0.32 fixed-point fraction.
const fn fraction_q32(x: f64) -> u32 {
    let q = math::round(x * 4_294_967_296.0);
    if q >= 4_294_967_295.0 {
        u32::MAX
    } else if q <= 0.0 {
        0
    } else {
        q as u32
    }
}

const fn check_range(name: &'static str, x: f32, lo: f32, hi: f32) -> Result<(), ConfigError> {
    if !x.is_finite() {
        return Err(ConfigError::NonFinite(name));
    }
    if x < lo || x > hi {
        return Err(ConfigError::OutOfRange(name));
    }
    Ok(())
}

/// The longest of the first `edges` pitches of `table`.
const fn longest_pitch(table: &[u8; MAX_PATTERN_TEETH], edges: u16) -> u8 {
    let mut longest = 0u8;
    let mut rest: &[u8] = table;
    let mut left = edges;
    while let [p, tail @ ..] = rest {
        if left == 0 {
            break;
        }
        if *p > longest {
            longest = *p;
        }
        left = left.wrapping_sub(1);
        rest = tail;
    }
    longest
}

/// The pitch ratio nearest 1 of a pattern of `edges` teeth with base pitch `base`: the
/// smallest long pitch over the base, or the base over the largest short pitch, whichever is
/// smaller (+∞ without either).
const fn nearest_ratio(pattern: &[u8; MAX_PATTERN_TEETH], edges: u16, base: u8) -> f64 {
    let (min_long, max_short) = extreme_pitches(pattern, edges, base);
    let r_long = if min_long < u8::MAX {
        min_long as f64 / base as f64
    } else {
        f64::INFINITY
    };
    let r_short = if max_short > 0 {
        base as f64 / max_short as f64
    } else {
        f64::INFINITY
    };
    if r_long < r_short {
        r_long
    } else {
        r_short
    }
}

/// The smallest pitch longer than `base` and the largest shorter one among the first `edges`
/// of `pattern`, in grid positions (`u8::MAX` and 0 without such a pitch).
// `i` stays under `MAX_PATTERN_TEETH`, the array's length: nothing can fail. A `while` loop:
// this is a `const fn`.
#[allow(clippy::indexing_slicing)]
const fn extreme_pitches(pattern: &[u8; MAX_PATTERN_TEETH], edges: u16, base: u8) -> (u8, u8) {
    let (mut min_long, mut max_short, mut i) = (u8::MAX, 0u8, 0usize);
    while i < edges as usize && i < MAX_PATTERN_TEETH {
        let p = pattern[i];
        if p > base && p < min_long {
            min_long = p;
        } else if p < base && p > max_short {
            max_short = p;
        }
        i = i.wrapping_add(1);
    }
    (min_long, max_short)
}

/// Validates a pattern and writes the grid pitch of every tooth, tooth 0 first, into `table`.
/// Returns (teeth, base pitch, long-teeth mask, short-teeth mask).
// Configuration only (not on a per-edge path). Every index below is under `teeth`, itself at
// most the arrays' length (`MAX_PATTERN_TEETH`, checked first), or a sum of two such indices
// brought back under it: nothing can fail. Loops are `while` loops: this is a `const fn`.
#[allow(clippy::indexing_slicing)]
const fn pattern_table(
    p: Pattern,
    table: &mut [u8; MAX_PATTERN_TEETH],
) -> Result<(u16, u8, u64, u64), ConfigError> {
    let n = p.positions;
    if n < 3 || n > MAX_PATTERN_POSITIONS {
        return Err(ConfigError::OutOfRange("pattern.positions"));
    }
    let present = p.present;
    if present & !mask_of(n) != 0 {
        return Err(ConfigError::OutOfRange("pattern.teeth"));
    }
    let teeth = present.count_ones() as usize;
    if teeth < 3 {
        return Err(ConfigError::OutOfRange("pattern.teeth"));
    }
    if teeth > MAX_PATTERN_TEETH {
        return Err(ConfigError::Capacity("pattern.teeth"));
    }
    // `i + shift` for `i`, `shift` < `teeth`, brought back under `teeth`.
    const fn around(i: usize, shift: usize, teeth: usize) -> usize {
        let j = i.wrapping_add(shift);
        if j >= teeth {
            j.wrapping_sub(teeth)
        } else {
            j
        }
    }
    // Pitches in grid order: tooth i ends the pitch from the tooth before it.
    let mut pitch = [0u8; MAX_PATTERN_TEETH];
    let mut pos = [0u8; MAX_PATTERN_TEETH];
    let mut j = 0usize;
    let mut q = 0u8;
    while q < n {
        if present & (1u128 << q) != 0 {
            // `j` counts the set bits below `q`: under `teeth`.
            pos[j] = q;
            j = j.wrapping_add(1);
        }
        q = q.wrapping_add(1);
    }
    let mut i = 0usize;
    while i < teeth {
        let here = pos[i] as u16;
        let before = pos[around(i, teeth.wrapping_sub(1), teeth)] as u16;
        // `here`, `before` < `n`: the difference modulo `n` without a division.
        let mut d = here.wrapping_add(n as u16).wrapping_sub(before);
        if d >= n as u16 {
            d = d.wrapping_sub(n as u16);
        }
        pitch[i] = if d == 0 { n } else { d as u8 };
        i = i.wrapping_add(1);
    }
    // The base pitch is the most common one; special teeth differ from it.
    let mut base = 0u8;
    let mut best = 0usize;
    let mut a = 0usize;
    while a < teeth {
        let c = pitch[a];
        let mut count = 0usize;
        let mut b = 0usize;
        while b < teeth {
            if pitch[b] == c {
                count = count.wrapping_add(1);
            }
            b = b.wrapping_add(1);
        }
        if count > best || (count == best && c < base) {
            best = count;
            base = c;
        }
        a = a.wrapping_add(1);
    }
    if best == teeth {
        return Err(ConfigError::Inconsistent(
            "pattern (uniform: use an indexed or unframed disc)",
        ));
    }
    // Special pitches must be told from the base at a glance: at least 1.5× or at most 0.75×.
    let mut i = 0usize;
    while i < teeth {
        // u8 values in u16: the products do not wrap.
        let (c, b) = (pitch[i] as u16, base as u16);
        if c != b && c.wrapping_mul(4) > b.wrapping_mul(3) && c.wrapping_mul(2) < b.wrapping_mul(3)
        {
            return Err(ConfigError::Inconsistent(
                "pattern (a pitch too close to the base)",
            ));
        }
        i = i.wrapping_add(1);
    }
    // The frame tooth: the one whose pitch differs most from the base (ratio in either
    // direction), the first in grid order among equals.
    const fn distinct(c: u8, base: u8) -> u32 {
        let (c, b) = (c as u32, base as u32);
        // Compare max(c/b, b/c) without division: scale both ways by b·c.
        // (u8 values in u32: the products do not wrap; pitches are at least 1.)
        let square = if c >= b {
            c.wrapping_mul(c)
        } else {
            b.wrapping_mul(b)
        };
        match square.saturating_mul(1000).checked_div(b.wrapping_mul(c)) {
            Some(q) => q,
            None => 0,
        }
    }
    let mut frame = 0usize;
    let mut i = 0usize;
    while i < teeth {
        if distinct(pitch[i], base) > distinct(pitch[frame], base) {
            frame = i;
        }
        i = i.wrapping_add(1);
    }
    // A pattern that repeats after a fraction of a turn cannot frame a revolution.
    let mut shift = 1usize;
    while shift < teeth {
        if matches!(teeth.checked_rem(shift), Some(0)) {
            let mut same = true;
            let mut i = 0usize;
            while i < teeth {
                if pitch[i] != pitch[around(i, shift, teeth)] {
                    same = false;
                }
                i = i.wrapping_add(1);
            }
            if same {
                return Err(ConfigError::Inconsistent(
                    "pattern (rotationally symmetric)",
                ));
            }
        }
        shift = shift.wrapping_add(1);
    }
    let (mut long, mut short) = (0u64, 0u64);
    let mut i = 0usize;
    while i < teeth {
        let c = pitch[around(frame, i, teeth)];
        table[i] = c;
        // `i` < `teeth` ≤ 64.
        if c > base {
            long |= 1 << i;
        } else if c < base {
            short |= 1 << i;
        }
        i = i.wrapping_add(1);
    }
    Ok((teeth as u16, base, long, short))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Encoders built by the compiler (in a `const`) are the ones built at run time: the
    /// `const fn` rounding and loops give the same integers as the run-time path, wheel by
    /// wheel (a pattern with three gaps, a 12+1, an index disc with 8-edge samples on a 16-bit
    /// counter, a 60-2 at its tightest tolerances).
    #[test]
    fn encoders_built_by_the_compiler_are_the_ones_built_at_run_time() {
        const fn ok<T: Copy>(r: Result<T, ConfigError>) -> T {
            match r {
                Ok(v) => v,
                Err(_) => panic!("rejected"),
            }
        }
        const GAPS: Pattern = ok(Pattern::with_gaps(36, &[(0, 2), (12, 2), (27, 2)]));
        const PLUS_ONE: Pattern = ok(Pattern::from_teeth(
            24,
            &[0, 1, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22],
        ));
        const INDEXED: EncoderConfig = {
            let mut c = EncoderConfig::indexed(1000, 84e6);
            c.estimator = Estimator::Edges(8);
            c.counter_bits = 16;
            c.min_speed = 200.0;
            c
        };
        const SIXTY_TWO: EncoderConfig = {
            let mut c = EncoderConfig::missing_teeth(60, 2, 1e6);
            c.tolerances.accept = 1.05;
            c.tolerances.glitch_fraction = 0.6;
            c.min_speed = 3.7;
            c
        };
        const BUILT: [Result<Encoder, ConfigError>; 4] = [
            Encoder::new(EncoderConfig::pattern(GAPS, 1e6)),
            Encoder::new(EncoderConfig::pattern(PLUS_ONE, 2e6)),
            Encoder::new(INDEXED),
            Encoder::new(SIXTY_TWO),
        ];
        let gaps = Pattern::with_gaps(36, &std::hint::black_box([(0, 2), (12, 2), (27, 2)]));
        let plus_one = Pattern::from_teeth(
            24,
            &std::hint::black_box([0, 1, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22]),
        );
        assert_eq!(gaps, Ok(GAPS));
        assert_eq!(plus_one, Ok(PLUS_ONE));
        let now = [
            EncoderConfig::pattern(GAPS, 1e6),
            EncoderConfig::pattern(PLUS_ONE, 2e6),
            INDEXED,
            SIXTY_TWO,
        ]
        .map(|c| Encoder::new(std::hint::black_box(c)));
        for (built, now) in BUILT.iter().zip(&now) {
            let built = built.as_ref().expect("valid");
            assert_eq!(Ok(built), now.as_ref());
            assert!(built.timeout_ticks() > 0 && built.uniform_span() > 0);
        }
    }

    #[test]
    fn uniform_discs_have_exact_integer_pitches() {
        let mut c = EncoderConfig::indexed(1000, 84e6);
        c.estimator = Estimator::Edges(8);
        let e = Encoder::new(c).unwrap();
        assert_eq!(e.edges(), 1000);
        assert_eq!(e.nominal_pitch(3), PITCH_UNITS);
        assert_eq!(e.uniform_span(), 8 * PITCH_UNITS);
        assert!(e.is_uniform());
        let turn = f64::from(e.unit_rad()) * 1000.0 * f64::from(PITCH_UNITS);
        assert!((turn - core::f64::consts::TAU).abs() < 1e-6);
        assert_eq!(e.mask(), u32::MAX);
        assert_eq!(e.framing(), Framing::Index);
    }

    #[test]
    fn a_prescaler_makes_each_capture_span_several_lines() {
        let mut c = EncoderConfig::indexed(1024, 84e6);
        c.prescaler = 4;
        c.estimator = Estimator::Edges(4);
        let e = Encoder::new(c).unwrap();
        assert_eq!(e.edges(), 256);
        assert_eq!(e.nominal_pitch(0), 4 * PITCH_UNITS);
        assert_eq!(e.uniform_span(), 16 * PITCH_UNITS);
        c.prescaler = 3;
        assert_eq!(
            Encoder::new(c).err(),
            Some(ConfigError::OutOfRange("prescaler"))
        );
        let mut c = EncoderConfig::indexed(1022, 84e6);
        c.prescaler = 4;
        assert_eq!(
            Encoder::new(c).err(),
            Some(ConfigError::Inconsistent("prescaler"))
        );
        let mut c = EncoderConfig::missing_teeth(36, 2, 1e6);
        c.prescaler = 2;
        assert_eq!(
            Encoder::new(c).err(),
            Some(ConfigError::Inconsistent("prescaler"))
        );
    }

    #[test]
    fn missing_tooth_gap_is_tooth_zero() {
        let mut c = EncoderConfig::missing_teeth(60, 2, 1e6);
        c.estimator = Estimator::Edges(2);
        let e = Encoder::new(c).unwrap();
        assert_eq!(e.edges(), 58);
        assert_eq!(e.framing(), Framing::Pattern);
        assert_eq!(e.nominal_pitch(0), 3 * PITCH_UNITS);
        assert_eq!(e.nominal_pitch(1), PITCH_UNITS);
        assert_eq!(e.nominal_pitch(57), PITCH_UNITS);
        assert_eq!(e.nominal_pitch(58), 0);
        assert_eq!(e.long_teeth(), 1);
        assert_eq!(e.short_teeth(), 0);
        assert!(!e.is_uniform());
        // The timeout covers the gap at the minimum speed.
        let gap = 3.0 * core::f64::consts::TAU / 60.0;
        assert_eq!(e.timeout_ticks(), libm::ceil(gap / 1.0 * 1e6) as u32);
    }

    #[test]
    fn general_patterns_are_numbered_from_their_most_distinctive_tooth() {
        // 36-2-1: a gap of two and a gap of one; tooth 0 ends the larger.
        let p = Pattern::with_gaps(36, &[(10, 1), (30, 2)]).unwrap();
        let e = Encoder::new(EncoderConfig::pattern(p, 1e6)).unwrap();
        assert_eq!(e.edges(), 33);
        assert_eq!(e.nominal_pitch(0), 3 * PITCH_UNITS);
        // Teeth 32..=35 → 0..3 after the big gap; the small gap (position 10) ends at the tooth
        // at position 11: after 0..9 (10 teeth) → tooth 4 + 10 = 14.
        assert_eq!(e.long_teeth(), 1 | 1 << 14);
        // 12+1 on a half-pitch grid: the extra tooth at position 7 splits a pitch in two.
        let mut teeth = [0u8; 13];
        for (i, t) in teeth.iter_mut().take(12).enumerate() {
            *t = 2 * i as u8;
        }
        teeth[12] = 7;
        let p = Pattern::from_teeth(24, &teeth).unwrap();
        let e = Encoder::new(EncoderConfig::pattern(p, 1e6)).unwrap();
        assert_eq!(e.edges(), 13);
        assert_eq!(e.base_pitch(), 2);
        assert_eq!(e.nominal_pitch(0), PITCH_UNITS);
        assert_eq!(e.nominal_pitch(1), PITCH_UNITS);
        assert_eq!(e.short_teeth(), 0b11);
        assert_eq!(e.long_teeth(), 0);
    }

    #[test]
    fn patterns_that_cannot_frame_are_rejected() {
        let bad = |p: Pattern| Encoder::new(EncoderConfig::pattern(p, 1e6)).err();
        // Three equal gaps 120° apart look the same after a third of a turn.
        let sym = Pattern::with_gaps(36, &[(0, 2), (12, 2), (24, 2)]).unwrap();
        assert_eq!(
            bad(sym),
            Some(ConfigError::Inconsistent(
                "pattern (rotationally symmetric)"
            ))
        );
        // Uneven gaps frame.
        let asym = Pattern::with_gaps(36, &[(0, 2), (12, 2), (27, 2)]).unwrap();
        assert_eq!(bad(asym), None);
        assert!(matches!(
            bad(Pattern::from_mask(36, (1u128 << 36) - 1)),
            Some(ConfigError::Inconsistent(_))
        ));
        assert_eq!(
            bad(Pattern::from_mask(36, 1 << 40)),
            Some(ConfigError::OutOfRange("pattern.teeth"))
        );
        assert_eq!(
            bad(Pattern::missing_teeth(100, 2)),
            Some(ConfigError::Capacity("pattern.teeth"))
        );
        assert_eq!(
            Pattern::with_gaps(36, &[(40, 2)]).err(),
            Some(ConfigError::OutOfRange("pattern.gaps"))
        );
    }

    #[test]
    fn bad_configs_name_the_parameter() {
        let ok = EncoderConfig::indexed(100, 1e6);
        let with = |f: &dyn Fn(&mut EncoderConfig)| {
            let mut c = ok;
            f(&mut c);
            Encoder::new(c).err()
        };
        assert_eq!(with(&|_| ()), None);
        assert_eq!(
            with(&|c| c.timer_hz = f64::NAN),
            Some(ConfigError::NonFinite("timer_hz"))
        );
        assert_eq!(
            with(&|c| c.timer_hz = 0.0),
            Some(ConfigError::NotPositive("timer_hz"))
        );
        assert_eq!(
            with(&|c| c.timer_hz = 1e-320),
            Some(ConfigError::NotPositive("timer_hz"))
        );
        assert_eq!(
            with(&|c| c.min_speed = f64::INFINITY),
            Some(ConfigError::NonFinite("min_speed"))
        );
        assert_eq!(
            with(&|c| c.wheel = Wheel::Indexed { lines: 1 }),
            Some(ConfigError::OutOfRange("lines"))
        );
        assert_eq!(
            with(&|c| c.wheel = Wheel::Unframed { lines: 20_000 }),
            Some(ConfigError::OutOfRange("lines"))
        );
        assert_eq!(
            with(&|c| c.counter_bits = 8),
            Some(ConfigError::OutOfRange("counter_bits"))
        );
        assert_eq!(
            with(&|c| c.estimator = Estimator::Edges(0)),
            Some(ConfigError::OutOfRange("estimator.edges"))
        );
        assert_eq!(
            with(&|c| c.estimator = Estimator::Edges(33)),
            Some(ConfigError::OutOfRange("estimator.edges"))
        );
        assert_eq!(
            with(&|c| c.tolerances.accept = f32::NAN),
            Some(ConfigError::NonFinite("tolerances.accept"))
        );
        assert_eq!(
            with(&|c| c.tolerances.glitch_fraction = 0.9),
            Some(ConfigError::OutOfRange("tolerances.glitch_fraction"))
        );
        assert_eq!(
            with(&|c| c.tolerances.fault_margin = -1.0),
            Some(ConfigError::OutOfRange("tolerances.fault_margin"))
        );
        // A 16-bit counter at 84 MHz wraps every 780 µs: 1 rad/s on 100 lines is 63 ms per edge.
        assert_eq!(
            with(&|c| {
                c.counter_bits = 16;
                c.timer_hz = 84e6
            }),
            Some(ConfigError::Inconsistent("min_speed"))
        );
    }
}
