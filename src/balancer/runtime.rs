//! Run-time classification of a measured speed (f32, O(log zones), total).

use super::{Machine, MachineTable, ZoneKind, MAX_PLATFORMS, MAX_ZONES};
use crate::error::ConfigError;

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

/// A relative band in `[0, 0.5)`: the checks of `non_negative_f32` (non-finite, negative, an
/// f32 subnormal) then the upper limit, in a form a `const fn` can call.
const fn fraction(name: &'static str, x: f32) -> Result<f32, ConfigError> {
    if x.is_nan() || x.is_infinite() {
        Err(ConfigError::NonFinite(name))
    } else if x < 0.0 {
        Err(ConfigError::Negative(name))
    } else if (x != 0.0 && x < f32::MIN_POSITIVE) || x >= 0.5 {
        Err(ConfigError::OutOfRange(name))
    } else {
        Ok(x)
    }
}

/// Checks a [`MachineTable`] the way [`Machine`] builds one: 1 to [`MAX_ZONES`] zones, the
/// first gathering from 0, finite and strictly ascending, each ending where the next starts
/// (`Inconsistent("zones")` otherwise), kinds alternating, the last open; at most
/// [`MAX_PLATFORMS`] capture windows; every speed finite (`NonFinite`, naming the field).
const fn check_table(t: &MachineTable) -> Result<(), ConfigError> {
    let zones = t.zones;
    if zones.is_empty() {
        return Err(ConfigError::Inconsistent("zones"));
    }
    if zones.len() > MAX_ZONES {
        return Err(ConfigError::Capacity("zones"));
    }
    if t.captures.len() > MAX_PLATFORMS {
        return Err(ConfigError::Capacity("captures"));
    }
    let mut i = 0;
    while i < zones.len() {
        let z = zones[i];
        let to_finite = match z.to {
            Some(to) => to.is_finite(),
            None => true,
        };
        if !z.from.is_finite() || !to_finite {
            return Err(ConfigError::NonFinite("zones"));
        }
        let first_ok = i > 0 || (z.from == 0.0 && matches!(z.kind, ZoneKind::Gathering));
        let next_ok = match (z.to, i + 1 < zones.len()) {
            (None, false) => true,
            (Some(to), true) => {
                let next = zones[i + 1];
                let alternates = !matches!(
                    (z.kind, next.kind),
                    (ZoneKind::Gathering, ZoneKind::Gathering)
                        | (ZoneKind::Balancing, ZoneKind::Balancing)
                );
                to == next.from && to > z.from && alternates
            }
            _ => false,
        };
        if !first_ok || !next_ok {
            return Err(ConfigError::Inconsistent("zones"));
        }
        i += 1;
    }
    let mut j = 0;
    while j < t.captures.len() {
        let w = t.captures[j];
        if !(w.from.is_finite() && w.until.is_finite() && w.at.is_finite()) {
            return Err(ConfigError::NonFinite("captures"));
        }
        j += 1;
    }
    let mut k = 0;
    while k < t.resonant.len() || k < t.additional.len() {
        if k < t.resonant.len() && !t.resonant[k].is_finite() {
            return Err(ConfigError::NonFinite("resonant"));
        }
        if k < t.additional.len() && !t.additional[k].is_finite() {
            return Err(ConfigError::NonFinite("additional"));
        }
        k += 1;
    }
    Ok(())
}

impl Classifier {
    /// Builds the table. `margin`: relative half-width of the band around each damped
    /// characteristic speed reported as [`Regime::NearCharacteristic`] (e.g. 0.03);
    /// `hysteresis`: relative distance past a boundary the speed must go before
    /// [`RegimeTracker`] leaves a segment (e.g. 0.01). Both in `[0, 0.5)`.
    pub fn new(machine: &Machine, margin: f32, hysteresis: f32) -> Result<Self, ConfigError> {
        Self::from_table(&machine.table(), margin, hysteresis)
    }

    /// [`Classifier::new`] from a machine's analysis as plain data, as a `const fn`: firmware
    /// that includes the table `drive-sim predict SCENE --emit rust` writes can build its
    /// classifier in a `const` item, so neither the analysis nor this runs on the target
    /// (an invalid table or band is then a compile error). The same table gives the same
    /// classifier as [`Classifier::new`] on the machine it came from.
    ///
    /// Errors: those of [`Classifier::new`] for `margin` and `hysteresis`; for a table that is
    /// not as [`Machine::table`] makes one, `Inconsistent("zones")` (no zone, a first zone not
    /// gathering from 0, zones not ascending, not adjoining, not alternating, or a last one
    /// not open), `Capacity("zones")` (more than [`MAX_ZONES`]), `Capacity("captures")` (more
    /// than one window per platform) and `NonFinite` naming the field with a NaN or ±∞.
    pub const fn from_table(
        table: &MachineTable,
        margin: f32,
        hysteresis: f32,
    ) -> Result<Self, ConfigError> {
        let margin = match fraction("margin", margin) {
            Ok(x) => x,
            Err(e) => return Err(e),
        };
        let hysteresis = match fraction("hysteresis", hysteresis) {
            Ok(x) => x,
            Err(e) => return Err(e),
        };
        if let Err(e) = check_table(table) {
            return Err(e);
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
        let zones = table.zones;
        let mut i = 0;
        // check_table: 1 ≤ zones.len() ≤ MAX_ZONES (the bounds tests only spare the panic).
        while i < zones.len() && i < MAX_ZONES {
            let z = zones[i];
            c.zone_kind[i] = z.kind;
            if i > 0 && i - 1 < MAX_BOUNDS {
                c.bounds[i - 1] = z.from as f32;
            }
            let pushed = match z.kind {
                ZoneKind::Gathering => c.with_segment(z.from, Regime::Gathering),
                ZoneKind::Balancing => {
                    // Capture is possible up to the largest `until` of the windows below.
                    let mut until = 0.0f64;
                    let mut j = 0;
                    while j < table.captures.len() {
                        let w = table.captures[j];
                        if w.from <= z.from && w.until > until {
                            until = w.until;
                        }
                        j += 1;
                    }
                    let to = match z.to {
                        Some(to) => to,
                        None => f64::INFINITY,
                    };
                    if until > z.from {
                        match c.with_segment(z.from, Regime::Bistable) {
                            Ok(next) if until < to => next.with_segment(until, Regime::Balancing),
                            other => other,
                        }
                    } else {
                        c.with_segment(z.from, Regime::Balancing)
                    }
                }
            };
            c = match pushed {
                Ok(next) => next,
                Err(e) => return Err(e),
            };
            i += 1;
        }
        c.n_bounds = i as u8 - 1;
        Ok(c)
    }

    /// The classifier with a segment appended, starting at `from` rad/s.
    const fn with_segment(mut self, from: f64, regime: Regime) -> Result<Self, ConfigError> {
        let i = self.n_seg as usize;
        if i >= MAX_SEGMENTS {
            return Err(ConfigError::Capacity("segments"));
        }
        self.seg_from[i] = from as f32;
        self.seg_regime[i] = regime;
        self.n_seg += 1;
        Ok(self)
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

#[cfg(test)]
mod tests {
    use super::fraction;
    use crate::error::{non_negative_f32, ConfigError};

    /// The const band check gives exactly what `non_negative_f32` followed by the `< 0.5`
    /// limit gave before, for every class of f32 (a sweep over bit patterns, both signs,
    /// subnormals, infinities and NaNs included).
    #[test]
    fn const_band_check_matches_the_validators() {
        let reference = |x: f32| -> Result<f32, ConfigError> {
            let x = non_negative_f32("margin", x)?;
            if x >= 0.5 {
                return Err(ConfigError::OutOfRange("margin"));
            }
            Ok(x)
        };
        let mut bits = 0u32;
        let mut checked = 0;
        loop {
            let x = f32::from_bits(bits);
            match (reference(x), fraction("margin", x)) {
                (Ok(a), Ok(b)) => assert_eq!(a.to_bits(), b.to_bits(), "{x:e}"),
                (a, b) => assert_eq!(a.err(), b.err(), "{x:e}"),
            }
            checked += 1;
            bits = match bits.checked_add(0x0000_7fff) {
                Some(b) => b,
                None => break,
            };
        }
        for x in [0.0, -0.0, 0.5, f32::MIN_POSITIVE, 1e-40, -1e-40, 0.4999999] {
            assert_eq!(reference(x).ok(), fraction("margin", x).ok(), "{x:e}");
        }
        assert!(checked > 100_000);
    }
}
