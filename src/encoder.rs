//! Encoder geometry and capture-timer setup, validated once.
//!
//! An [`EncoderConfig`] describes the disc (tooth positions, how revolutions are framed),
//! the capture timer (clock, counter width) and the speed estimator. [`Encoder::new`]
//! validates it and precomputes the tables the per-edge path reads: the angle from each
//! edge to the next (uniform by default, or a learned/imported table) and the angle spanned
//! by the last `K` edges ending at each tooth, so the per-edge work is a table lookup.
//!
//! Edges are numbered within a revolution: tooth 0 is the first edge after the frame marker
//! (the index pulse, or the edge that ends the missing-tooth gap). `pitch(k)` is the angle
//! travelled from edge k−1 to edge k; for a missing-tooth disc `pitch(0)` spans the gap.

use crate::error::{positive, ConfigError};

/// Full turn in f64, for configuration-time sums.
const TAU64: f64 = core::f64::consts::TAU;

/// How revolutions are framed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Framing {
    /// No once-per-revolution marker: teeth cannot be told apart, so only a uniform disc can be
    /// used, revolutions are counted in edges, and a missing edge is detected by its long
    /// interval only.
    None,
    /// A separate index pulse once per revolution, reported with [`crate::speed::SpeedTracker::on_index`].
    Index,
    /// `missing` consecutive tooth positions are absent (e.g. 60-2 has `missing = 2`); the long
    /// interval across the gap frames the revolution.
    MissingTooth {
        /// Number of absent positions, 1 to 3.
        missing: u8,
    },
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

/// Encoder and capture-timer description, in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct EncoderConfig {
    /// Tooth positions per revolution on the disc, including missing ones (e.g. 1024 lines, or
    /// 60 for a 60-2 wheel).
    pub positions: u16,
    /// Revolution framing.
    pub framing: Framing,
    /// Capture timer clock, Hz.
    pub timer_hz: f64,
    /// Width of the capture counter in bits (16 to 32); timestamps wrap modulo 2^bits.
    pub counter_bits: u8,
    /// Slowest speed still considered running, rad/s: an edge later than the longest pitch at
    /// this speed means the shaft stood still (timeout).
    pub min_speed: f64,
    /// Speed estimator.
    pub estimator: Estimator,
    /// An edge whose interval is shorter than this fraction of the interval expected from the
    /// previous one is rejected as a glitch (0.05 to 0.95; 0.5 is usual).
    pub glitch_fraction: f32,
}

impl EncoderConfig {
    /// A uniform disc with `positions` lines framed by an index pulse, a 32-bit timer, per-edge
    /// speed, glitch fraction 0.5 and a minimum speed of 1 rad/s.
    pub fn new(positions: u16, timer_hz: f64) -> Self {
        EncoderConfig {
            positions,
            framing: Framing::Index,
            timer_hz,
            counter_bits: 32,
            min_speed: 1.0,
            estimator: Estimator::Edges(1),
            glitch_fraction: 0.5,
        }
    }
}

/// A validated encoder with its per-tooth tables. `N` is the capacity: the largest number of
/// edges per revolution this instance can hold (memory: 8·N bytes).
#[derive(Debug, Clone, PartialEq)]
pub struct Encoder<const N: usize> {
    config: EncoderConfig,
    edges: u16,
    k: u16,
    mask: u32,
    timeout_ticks: u32,
    timer_hz: f32,
    inv_timer_hz: f32,
    gap_ratio: f32,
    uniform: f32,
    /// Angle from edge k−1 to edge k, rad.
    pitch: [f32; N],
    /// Angle spanned by the `k` edges ending at edge k (sum of `k` pitches), rad.
    span: [f32; N],
}

impl<const N: usize> Encoder<N> {
    /// Validates `config` and builds the uniform tables.
    ///
    /// Besides each field's range, the timer must fit the speed range: the longest pitch at
    /// `min_speed` must last fewer ticks than the counter holds (`Inconsistent("min_speed")`)
    /// and at least 2 ticks (`Inconsistent("timer_hz")`).
    pub fn new(config: EncoderConfig) -> Result<Self, ConfigError> {
        let missing = match config.framing {
            Framing::MissingTooth { missing } => {
                if !(1..=3).contains(&missing) {
                    return Err(ConfigError::OutOfRange("framing.missing"));
                }
                missing as u16
            }
            _ => 0,
        };
        if config.positions < 2 {
            return Err(ConfigError::OutOfRange("positions"));
        }
        let edges = config.positions.saturating_sub(missing);
        if edges < 2 || missing > 0 && edges < 2 * missing + 2 {
            return Err(ConfigError::OutOfRange("positions"));
        }
        if edges as usize > N {
            return Err(ConfigError::Capacity("positions"));
        }
        let timer_hz = positive("timer_hz", config.timer_hz)?;
        if !(1.0..=1.0e10).contains(&timer_hz) {
            return Err(ConfigError::OutOfRange("timer_hz"));
        }
        if !(16..=32).contains(&config.counter_bits) {
            return Err(ConfigError::OutOfRange("counter_bits"));
        }
        let mask = if config.counter_bits == 32 {
            u32::MAX
        } else {
            (1u32 << config.counter_bits) - 1
        };
        let min_speed = positive("min_speed", config.min_speed)?;
        let Estimator::Edges(k) = config.estimator;
        if k == 0 || k > edges || k as usize > crate::speed::MAX_SPAN {
            return Err(ConfigError::OutOfRange("estimator.edges"));
        }
        let g = config.glitch_fraction;
        if !g.is_finite() {
            return Err(ConfigError::NonFinite("glitch_fraction"));
        }
        if !(0.05..=0.95).contains(&g) {
            return Err(ConfigError::OutOfRange("glitch_fraction"));
        }
        let pitch = TAU64 / config.positions as f64;
        let longest = pitch * (missing as f64 + 1.0);
        let timeout = longest / min_speed * timer_hz;
        // Intervals are measured modulo the counter: a timeout beyond its range cannot be seen.
        if !timeout.is_finite() || timeout >= mask as f64 {
            return Err(ConfigError::Inconsistent("min_speed"));
        }
        // A pitch at the minimum speed shorter than 2 ticks carries no speed information: every
        // interval the tracker accepts would be a single tick.
        if timeout < 2.0 {
            return Err(ConfigError::Inconsistent("timer_hz"));
        }
        // A K-edge sample must fit in u32 ticks even at the slowest speed.
        if timeout * k as f64 >= u32::MAX as f64 {
            return Err(ConfigError::Inconsistent("estimator.edges"));
        }
        let mut enc = Encoder {
            config,
            edges,
            k,
            mask,
            timeout_ticks: libm::ceil(timeout) as u32,
            timer_hz: timer_hz as f32,
            inv_timer_hz: (1.0 / timer_hz) as f32,
            // Midway between a normal pitch (1) and the gap (missing + 1).
            gap_ratio: 1.0 + 0.5 * missing as f32,
            uniform: pitch as f32,
            pitch: [0.0; N],
            span: [0.0; N],
        };
        let mut table = [0.0f64; N];
        for (i, p) in table.iter_mut().enumerate().take(edges as usize) {
            *p = if i == 0 { longest } else { pitch };
        }
        enc.load(&table);
        Ok(enc)
    }

    /// Replaces the per-tooth pitch table (rad, edge k−1 to edge k, `edges()` entries), e.g. a
    /// learned correction restored after a reboot. Each pitch must be positive and within 50 %
    /// of its nominal value, and the table must close the turn (sum 2π within 1e-4 rad).
    pub fn with_pitches(mut self, pitches: &[f32]) -> Result<Self, ConfigError> {
        if self.config.framing == Framing::None {
            return Err(ConfigError::Inconsistent("pitches (teeth unframed)"));
        }
        if pitches.len() != self.edges as usize {
            return Err(ConfigError::OutOfRange("pitches.len"));
        }
        let mut table = [0.0f64; N];
        let mut sum = 0.0f64;
        for (i, (&p, t)) in pitches.iter().zip(table.iter_mut()).enumerate() {
            let p = positive("pitches", p as f64)?;
            let nominal = self.nominal_pitch(i);
            if (p / nominal - 1.0).abs() > 0.5 {
                return Err(ConfigError::OutOfRange("pitches"));
            }
            *t = p;
            sum += p;
        }
        if (sum - TAU64).abs() > 1e-4 {
            return Err(ConfigError::Inconsistent("pitches (sum)"));
        }
        // Rescale so the stored table closes the turn to f64 rounding.
        for t in table.iter_mut() {
            *t *= TAU64 / sum;
        }
        self.load(&table);
        Ok(self)
    }

    fn nominal_pitch(&self, tooth: usize) -> f64 {
        let p = TAU64 / self.config.positions as f64;
        match self.config.framing {
            Framing::MissingTooth { missing } if tooth == 0 => p * (missing as f64 + 1.0),
            _ => p,
        }
    }

    fn load(&mut self, table: &[f64; N]) {
        let n = self.edges as usize;
        let k = self.k as usize;
        for i in 0..n {
            self.pitch[i] = table[i] as f32;
            // Each span summed in f64 from the pitches, not as a difference of cumulative angles
            // (which would cancel): exact to one f32 rounding.
            let mut s = 0.0f64;
            for j in 0..k {
                s += table[(i + n - j) % n];
            }
            self.span[i] = s as f32;
        }
    }

    /// The configuration this encoder was built from.
    pub fn config(&self) -> &EncoderConfig {
        &self.config
    }
    /// Edges per revolution (positions less missing ones).
    pub fn edges(&self) -> u16 {
        self.edges
    }
    /// Edges averaged per speed sample.
    pub fn samples_span(&self) -> u16 {
        self.k
    }
    /// Counter mask (2^bits − 1).
    pub fn mask(&self) -> u32 {
        self.mask
    }
    /// Ticks without an edge after which the shaft is at standstill.
    pub fn timeout_ticks(&self) -> u32 {
        self.timeout_ticks
    }
    /// Timer clock, Hz.
    pub fn timer_hz(&self) -> f32 {
        self.timer_hz
    }
    /// Timer period, s.
    pub fn tick_seconds(&self) -> f32 {
        self.inv_timer_hz
    }
    /// Interval ratio above which an interval is taken as the missing-tooth gap.
    pub(crate) fn gap_ratio(&self) -> f32 {
        self.gap_ratio
    }
    /// Nominal pitch of one tooth position, 2π/positions.
    pub fn uniform_pitch(&self) -> f32 {
        self.uniform
    }
    /// Angle from edge `tooth − 1` to edge `tooth` (0 for an index beyond the table).
    pub fn pitch(&self, tooth: u16) -> f32 {
        self.pitch.get(tooth as usize).copied().unwrap_or(0.0)
    }
    /// Angle of the `samples_span()` edges ending at `tooth`.
    pub fn span(&self, tooth: u16) -> f32 {
        self.span.get(tooth as usize).copied().unwrap_or(0.0)
    }
    /// The pitch table in use (`edges()` entries).
    pub fn pitches(&self) -> &[f32] {
        self.pitch.get(..self.edges as usize).unwrap_or(&[])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_tables_close_the_turn() {
        let mut c = EncoderConfig::new(1000, 84e6);
        c.estimator = Estimator::Edges(8);
        let e = Encoder::<1024>::new(c).unwrap();
        let sum: f64 = e.pitches().iter().map(|&p| p as f64).sum();
        assert!((sum - TAU64).abs() < 1e-5);
        assert!((e.span(3) as f64 - 8.0 * TAU64 / 1000.0).abs() < 1e-8);
        assert_eq!(e.mask(), u32::MAX);
    }

    #[test]
    fn missing_tooth_gap_spans_the_absent_positions() {
        let mut c = EncoderConfig::new(60, 1e6);
        c.framing = Framing::MissingTooth { missing: 2 };
        c.estimator = Estimator::Edges(2);
        let e = Encoder::<64>::new(c).unwrap();
        assert_eq!(e.edges(), 58);
        let p = TAU64 / 60.0;
        assert!((e.pitch(0) as f64 - 3.0 * p).abs() < 1e-7);
        assert!((e.pitch(1) as f64 - p).abs() < 1e-7);
        // The span ending at tooth 0 covers tooth 57 and the gap.
        assert!((e.span(0) as f64 - 4.0 * p).abs() < 1e-7);
        assert!((e.gap_ratio() - 2.0).abs() < 1e-6);
    }

    #[test]
    fn bad_configs_name_the_parameter() {
        let ok = EncoderConfig::new(100, 1e6);
        let with = |f: &dyn Fn(&mut EncoderConfig)| {
            let mut c = ok;
            f(&mut c);
            Encoder::<128>::new(c).err()
        };
        assert_eq!(
            with(&|c| c.timer_hz = f64::NAN),
            Some(ConfigError::NonFinite("timer_hz"))
        );
        assert_eq!(
            with(&|c| c.timer_hz = 0.0),
            Some(ConfigError::NotPositive("timer_hz"))
        );
        assert_eq!(
            with(&|c| c.timer_hz = -1.0),
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
            with(&|c| c.positions = 1),
            Some(ConfigError::OutOfRange("positions"))
        );
        assert_eq!(
            with(&|c| c.positions = 200),
            Some(ConfigError::Capacity("positions"))
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
            with(&|c| c.glitch_fraction = f32::NAN),
            Some(ConfigError::NonFinite("glitch_fraction"))
        );
        assert_eq!(
            with(&|c| c.framing = Framing::MissingTooth { missing: 4 }),
            Some(ConfigError::OutOfRange("framing.missing"))
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

    #[test]
    fn imported_pitches_are_checked() {
        let e = Encoder::<8>::new(EncoderConfig::new(8, 1e6)).unwrap();
        let p = (TAU64 / 8.0) as f32;
        let mut t = [p; 8];
        t[0] *= 1.01;
        t[1] *= 0.99;
        let e2 = e.clone().with_pitches(&t).unwrap();
        assert!((e2.pitch(0) - t[0]).abs() < 1e-6);
        assert_eq!(
            e.clone().with_pitches(&t[..7]).err(),
            Some(ConfigError::OutOfRange("pitches.len"))
        );
        t[2] = f32::NAN;
        assert_eq!(
            e.clone().with_pitches(&t).err(),
            Some(ConfigError::NonFinite("pitches"))
        );
        let t = [p * 1.01; 8];
        assert_eq!(
            e.with_pitches(&t).err(),
            Some(ConfigError::Inconsistent("pitches (sum)"))
        );
    }
}
