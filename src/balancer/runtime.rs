//! Run-time classification of a measured speed (f32, O(log zones), total).

use super::{Machine, ZoneKind, MAX_PLATFORMS, MAX_ZONES};
use crate::error::{non_negative_f32, ConfigError};

/// Segments: the zones, with balancing zones split where a capture window ends.
const MAX_SEGMENTS: usize = MAX_ZONES + MAX_PLATFORMS;
/// Characteristic speeds (zone boundaries).
const MAX_BOUNDS: usize = MAX_ZONES - 1;

/// The regime expected at a speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Regime {
    /// The auto-balancing position is stable and loads gathered below cannot stay captured.
    Balancing,
    /// The loads gather: the machine works as a vibration exciter.
    Gathering,
    /// The criterion says balancing, but it is not assured: gathered loads can stay captured
    /// near the resonance below (Sommerfeld effect), and direct simulation finds the
    /// balancing position itself unstable just above the resonance (on random machines
    /// balancing set in a median 17 % above it, `docs/criterion.md`). Which regime sets in
    /// depends on the machine and its history.
    Bistable,
    /// Within the margin band around a damped characteristic speed, where the criterion is
    /// not to be relied on.
    NearCharacteristic,
    /// The speed is not a number or infinite.
    Unknown,
}

impl Regime {
    /// Lower-case name as used in the host's JSON: `"balancing"`, `"gathering"`,
    /// `"bistable"`, `"near-characteristic"` or `"unknown"`.
    pub fn name(self) -> &'static str {
        match self {
            Regime::Balancing => "balancing",
            Regime::Gathering => "gathering",
            Regime::Bistable => "bistable",
            Regime::NearCharacteristic => "near-characteristic",
            Regime::Unknown => "unknown",
        }
    }
}

/// A band of speeds `[from, to)`, rad/s.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SpeedBand {
    /// Lower edge, rad/s.
    pub from: f32,
    /// Upper edge, rad/s.
    pub to: f32,
}

/// What the operator can do at a speed (the seed's discussion, section 6).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Advice {
    /// When balancing (or bistable) at this speed: to get the loads to gather again (re-enter
    /// the exciter mode), drop the speed below this, rad/s; the speed can be raised again
    /// once the loads are stuck. `None` when the loads already tend to gather here.
    pub drop_below: Option<f32>,
    /// The gathering zone to run a vibration exciter in: the highest gathering zone starting
    /// at or below this speed, shrunk by the margin at both finite edges. `None` if the
    /// margins leave nothing.
    pub exciter_band: Option<SpeedBand>,
}

/// Run-time zone table in f32, built once from a [`Machine`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Classifier {
    seg_from: [f32; MAX_SEGMENTS],
    seg_regime: [Regime; MAX_SEGMENTS],
    n_seg: u8,
    /// Kind of each zone; zone `i > 0` starts at `bounds[i − 1]`, zone 0 at 0.
    zone_kind: [ZoneKind; MAX_ZONES],
    bounds: [f32; MAX_BOUNDS],
    n_bounds: u8,
    margin: f32,
    hysteresis: f32,
}

/// Default margin band about each damped characteristic speed: 5 %.
///
/// Sized from simulation (`drive-sim criterion`, `docs/criterion.md`): on 120 random machines
/// with `ε` in [0.005, 0.1], `h` in [0.01, 0.2] and `β` in [1, 50], the band an additional
/// speed's boundary (balancing below, gathering above) needs for the classifier to match the
/// simulation on both sides was 0.3 % at the median and 2.0 % at the 90th percentile; 5 %
/// covers 69 of the 71 boundaries (in the other two the gathering zone above the additional
/// speed shrinks or vanishes in simulation). The needed band did not change measurably with
/// `ε` (medians and maxima flat across the range; a power-law fit gives `ε^−0.01`), so it is
/// one constant, not a function of `ε`. The boundaries at the resonances move further, upwards, and are covered by the
/// capture band ([`Regime::Bistable`]), not by this margin.
pub const DEFAULT_MARGIN: f32 = 0.05;

impl Classifier {
    /// Builds the table. `margin`: relative half-width of the band around each damped
    /// characteristic speed reported as [`Regime::NearCharacteristic`] (e.g. 0.03);
    /// `hysteresis`: relative distance past a boundary the speed must go before
    /// [`RegimeTracker`] leaves a segment (e.g. 0.01). Both in `[0, 0.5)`.
    pub fn new(machine: &Machine, margin: f32, hysteresis: f32) -> Result<Self, ConfigError> {
        let margin = non_negative_f32("margin", margin)?;
        let hysteresis = non_negative_f32("hysteresis", hysteresis)?;
        if margin >= 0.5 {
            return Err(ConfigError::OutOfRange("margin"));
        }
        if hysteresis >= 0.5 {
            return Err(ConfigError::OutOfRange("hysteresis"));
        }
        let mut c = Classifier {
            seg_from: [0.0; MAX_SEGMENTS],
            seg_regime: [Regime::Gathering; MAX_SEGMENTS],
            n_seg: 0,
            zone_kind: [ZoneKind::Gathering; MAX_ZONES],
            bounds: [0.0; MAX_BOUNDS],
            n_bounds: 0,
            margin,
            hysteresis,
        };
        for (i, z) in machine.zones().iter().enumerate() {
            if let Some(k) = c.zone_kind.get_mut(i) {
                *k = z.kind;
            }
            if i > 0 {
                if let Some(b) = c.bounds.get_mut(i - 1) {
                    *b = z.from as f32;
                }
            }
            match z.kind {
                ZoneKind::Gathering => c.push_segment(z.from, Regime::Gathering)?,
                ZoneKind::Balancing => {
                    // Capture is possible up to the largest `until` of the windows below.
                    let until = machine
                        .capture_windows()
                        .iter()
                        .filter(|w| w.from <= z.from)
                        .fold(0.0f64, |u, w| u.max(w.until));
                    let to = z.to.unwrap_or(f64::INFINITY);
                    if until > z.from {
                        c.push_segment(z.from, Regime::Bistable)?;
                        if until < to {
                            c.push_segment(until, Regime::Balancing)?;
                        }
                    } else {
                        c.push_segment(z.from, Regime::Balancing)?;
                    }
                }
            }
        }
        c.n_bounds = machine.zones().len().clamp(1, MAX_ZONES) as u8 - 1;
        Ok(c)
    }

    /// Appends a segment starting at `from` rad/s.
    fn push_segment(&mut self, from: f64, regime: Regime) -> Result<(), ConfigError> {
        let i = usize::from(self.n_seg);
        let (Some(f), Some(r)) = (self.seg_from.get_mut(i), self.seg_regime.get_mut(i)) else {
            return Err(ConfigError::Capacity("segments"));
        };
        *f = from as f32;
        *r = regime;
        self.n_seg += 1;
        Ok(())
    }

    fn segs(&self) -> &[f32] {
        self.seg_from.get(..usize::from(self.n_seg)).unwrap_or(&[])
    }

    fn bounds(&self) -> &[f32] {
        self.bounds.get(..usize::from(self.n_bounds)).unwrap_or(&[])
    }

    /// The damped characteristic speeds (zone boundaries), ascending, rad/s.
    pub fn characteristic_speeds(&self) -> &[f32] {
        self.bounds()
    }

    /// Index of the segment containing `s ≥ 0` (binary search).
    fn segment(&self, s: f32) -> usize {
        self.segs().partition_point(|&f| f <= s).saturating_sub(1)
    }

    fn segment_regime(&self, i: usize) -> Regime {
        self.seg_regime.get(i).copied().unwrap_or(Regime::Unknown)
    }

    /// `[from, to)` of segment `i` (`to = ∞` for the last).
    fn segment_range(&self, i: usize) -> (f32, f32) {
        let from = self.seg_from.get(i).copied().unwrap_or(0.0);
        let to = if i + 1 < usize::from(self.n_seg) {
            self.seg_from.get(i + 1).copied().unwrap_or(f32::INFINITY)
        } else {
            f32::INFINITY
        };
        (from, to)
    }

    /// Whether `s ≥ 0` lies within the margin band of a characteristic speed.
    fn near(&self, s: f32) -> bool {
        let b = self.bounds();
        let i = b.partition_point(|&x| x <= s);
        let close = |x: Option<&f32>| x.is_some_and(|&x| (s - x).abs() <= self.margin * x);
        close(b.get(i)) || close(i.checked_sub(1).and_then(|j| b.get(j)))
    }

    /// Classifies a speed in rad/s without hysteresis. The sign is ignored (the regime does
    /// not depend on the direction of rotation); NaN and ±∞ give [`Regime::Unknown`].
    pub fn classify(&self, speed: f32) -> Regime {
        if !speed.is_finite() {
            return Regime::Unknown;
        }
        let s = speed.abs();
        if self.near(s) {
            return Regime::NearCharacteristic;
        }
        self.segment_regime(self.segment(s))
    }

    /// What to do at `speed` rad/s (see [`Advice`]). NaN and ±∞ give no advice.
    pub fn advice(&self, speed: f32) -> Advice {
        let none = Advice {
            drop_below: None,
            exciter_band: None,
        };
        if !speed.is_finite() {
            return none;
        }
        let s = speed.abs();
        let bounds = self.bounds();
        // Zone `i` is `[from(i), bounds[i])`; `s ≥ 0` lies in the zone after every boundary
        // at or below it.
        let from = |i: usize| match i.checked_sub(1) {
            None => Some(0.0),
            Some(b) => bounds.get(b).copied(),
        };
        let zi = bounds.partition_point(|&f| f <= s);
        let kind = self.zone_kind.get(zi).copied();
        let drop_below = match kind {
            Some(ZoneKind::Balancing) => from(zi).map(|f| f * (1.0 - self.margin)),
            _ => None,
        };
        // The highest gathering zone starting at or below s.
        let gi = if kind == Some(ZoneKind::Gathering) {
            Some(zi)
        } else {
            zi.checked_sub(1)
        };
        let exciter_band = gi.and_then(|g| {
            let from = from(g)?;
            let to = bounds.get(g).copied()?;
            let band = SpeedBand {
                from: from * (1.0 + self.margin),
                to: to * (1.0 - self.margin),
            };
            (band.from < band.to).then_some(band)
        });
        Advice {
            drop_below,
            exciter_band,
        }
    }
}

/// A change of the (hysteretic) regime.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegimeEvent {
    /// Regime held before (`Unknown` on the first valid speed).
    pub from: Regime,
    /// Regime held now.
    pub to: Regime,
    /// The speed that caused the change, rad/s.
    pub speed: f32,
}

/// Result of one [`RegimeTracker::update`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegimeStatus {
    /// The held regime (`Balancing`, `Gathering`, `Bistable`; `Unknown` for a non-finite
    /// speed or before the first valid one).
    pub regime: Regime,
    /// The speed is within the margin band of a characteristic speed.
    pub near_characteristic: bool,
    /// Set when the held regime changed on this update.
    pub event: Option<RegimeEvent>,
}

/// Hysteresis state: holds a segment until the speed is past its edges by the relative
/// hysteresis, so a speed sitting on a boundary does not chatter.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegimeTracker {
    held: Option<u8>,
}

impl RegimeTracker {
    /// A tracker holding nothing yet.
    pub const fn new() -> Self {
        RegimeTracker { held: None }
    }

    /// Feeds one speed in rad/s (sign ignored). A non-finite speed keeps the held segment
    /// and reports `Unknown` without an event.
    pub fn update(&mut self, c: &Classifier, speed: f32) -> RegimeStatus {
        if !speed.is_finite() {
            return RegimeStatus {
                regime: Regime::Unknown,
                near_characteristic: false,
                event: None,
            };
        }
        let s = speed.abs();
        let raw = c.segment(s);
        let before = self.held.map(usize::from);
        let next = match before {
            None => raw,
            Some(h) if h == raw => h,
            Some(h) => {
                let (lo, hi) = c.segment_range(h);
                if s >= hi * (1.0 + c.hysteresis) || s < lo * (1.0 - c.hysteresis) {
                    raw
                } else {
                    h
                }
            }
        };
        self.held = Some(next.min(MAX_SEGMENTS) as u8);
        let from = before.map_or(Regime::Unknown, |h| c.segment_regime(h));
        let to = c.segment_regime(next);
        RegimeStatus {
            regime: to,
            near_characteristic: c.near(s),
            event: (from != to).then_some(RegimeEvent { from, to, speed: s }),
        }
    }
}
