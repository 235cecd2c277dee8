//! Run-time classification of a measured speed (f32, a binary search over at most
//! [`MAX_SEGMENTS`] table entries, total).

use super::table::{same_regime, speed_f32, MAX_SEGMENTS};
use super::{
    BistableReason, Machine, MachineTable, RegimeSegment, RegimeTable, ZoneKind, MAX_PLATFORMS,
    MAX_ZONES,
};
use crate::error::ConfigError;

/// The regime expected at a speed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Regime {
    /// The loads balance the rotor: the auto-balancing position is stable and no other state
    /// is known to persist here.
    Balancing,
    /// The loads do not balance (they gather: the machine works as a vibration exciter). In an
    /// exact table ([`Classifier::from_table`]) the balancing position is unstable here; in the
    /// criterion's ([`Classifier::new`]) the criterion says the loads gather.
    Gathering,
    /// A balancing position is stable, but another state can persist too ([`BistableReason`]):
    /// which regime sets in depends on the machine's history.
    Bistable(BistableReason),
    /// Within the margin band about a boundary of the table, where the class is not to be
    /// relied on.
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
            Regime::Bistable(_) => "bistable",
            Regime::NearCharacteristic => "near-characteristic",
            Regime::Unknown => "unknown",
        }
    }

    /// Why the regime is bistable (`None` for the others).
    pub fn reason(self) -> Option<BistableReason> {
        match self {
            Regime::Bistable(r) => Some(r),
            _ => None,
        }
    }

    /// The classifier commits to this regime (`Balancing` or `Gathering`).
    pub fn committed(self) -> bool {
        matches!(self, Regime::Balancing | Regime::Gathering)
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
    /// When the balancing position is stable at this speed (`Balancing`, or `Bistable` for
    /// capture or coexisting loads): to
    /// get the loads to gather again (re-enter the exciter mode), drop the speed below this,
    /// the start of the stable stretch shrunk by the margin, rad/s; the speed can be raised
    /// again once the loads are stuck. `None` when the loads already gather here, or the
    /// balancing position is stable down to standstill.
    pub drop_below: Option<f32>,
    /// Where to run a vibration exciter: the highest `Gathering` segment starting at or below
    /// this speed, shrunk by the margin at both edges. `None` if the margins leave nothing or
    /// that segment is open-ended.
    pub exciter_band: Option<SpeedBand>,
}

/// Run-time regime table in f32, built once from a [`RegimeTable`] (or, for the seed's
/// criterion, from a [`Machine`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Classifier {
    seg_from: [f32; MAX_SEGMENTS],
    seg_regime: [Regime; MAX_SEGMENTS],
    n_seg: u8,
    margin: f32,
    hysteresis: f32,
}

/// Default margin band about each boundary of the seed criterion's table
/// ([`Classifier::new`]): 5 %.
///
/// Sized from simulation and from the exact boundaries (`drive-sim criterion`,
/// `docs/criterion.md`, 120 random machines): at the additional speeds the balancing position
/// stops being stable within 1.3 % of the criterion's boundary at the 90th percentile (−5.7 %
/// to +0.9 %), and with this band the criterion's classifier agrees with the simulation at
/// 98.6 % of the speeds it commits at. At the resonances the criterion's boundary is far off
/// (the balancing position is stable for good a median 17 % higher): its capture band
/// (`Bistable`) covers most of that, not this margin. An exact table ([`TABLE_MARGIN`]) needs
/// no such allowance.
pub const DEFAULT_MARGIN: f32 = 0.05;

/// Default margin band about each boundary of an exact table ([`Classifier::from_table`]):
/// 1 %.
///
/// The exact boundaries are placed to 1e-6; the band covers the speeds where a perturbation
/// grows or decays so slowly that the regime takes very long to show, and errors in the
/// machine's parameters. Sized from simulation (`drive-sim criterion`, `docs/criterion.md`,
/// 120 random machines, 4800 speeds): the committed classes agree with the simulation at every
/// speed more than 0.5 % from a boundary of the table (one miss closer), and each 1 % of
/// margin costs about 1.7 % of the speeds committed (79.7 % committed without a band, 77.9 %
/// with 1 %, 71.0 % with 5 %); 1 % leaves room for parameter errors the study cannot see.
pub const TABLE_MARGIN: f32 = 0.01;

/// A relative band in `[0, 0.5)`: non-finite, negative or f32-subnormal values rejected as
/// `non_negative_f32` does, then the upper limit, in a form a `const fn` can call.
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
const fn check_machine_table(t: &MachineTable) -> Result<(), ConfigError> {
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
    /// Builds the classifier of a validated [`RegimeTable`] (the exact table a host computed,
    /// see the module docs of [`super::table`]). `margin`: relative half-width of the band
    /// about each boundary of the table reported as [`Regime::NearCharacteristic`] (e.g.
    /// 0.02); `hysteresis`: relative distance past a boundary the speed must go before
    /// [`RegimeTracker`] leaves a segment (e.g. 0.01). Both in `[0, 0.5)`. Errors: those of
    /// [`RegimeTable::validate`], and `OutOfRange("margin")`/`OutOfRange("hysteresis")`.
    pub const fn from_table(
        table: &RegimeTable<'_>,
        margin: f32,
        hysteresis: f32,
    ) -> Result<Self, ConfigError> {
        if let Err(e) = table.validate() {
            return Err(e);
        }
        let mut c = match Self::empty(margin, hysteresis) {
            Ok(c) => c,
            Err(e) => return Err(e),
        };
        let mut i = 0;
        while i < table.segments.len() {
            c = match c.push_segment(table.segments[i]) {
                Ok(c) => c,
                Err(e) => return Err(e),
            };
            i += 1;
        }
        Ok(c)
    }

    /// Builds the seed criterion's classifier of `machine`: its damped zones
    /// ([`Machine::zones`]), with each balancing zone `Bistable(Capture)` up to where the
    /// capture windows below it end ([`Machine::capture_windows`]). The criterion is
    /// approximate (`docs/criterion.md`); a host's exact table ([`Classifier::from_table`])
    /// is not. `margin` and `hysteresis` as for [`Classifier::from_table`]. A zone or window
    /// speed f32 cannot hold (rounding to infinity, zero or a subnormal) gives
    /// `OutOfRange("zones.from")` or `OutOfRange("capture_windows.until")`.
    pub fn new(machine: &Machine, margin: f32, hysteresis: f32) -> Result<Self, ConfigError> {
        Self::from_machine_table(&machine.table(), margin, hysteresis)
    }

    /// [`Classifier::new`] from a machine's analysis as plain data, as a `const fn`: firmware
    /// that includes the table `drive-sim predict SCENE --emit rust` writes can build its
    /// classifier in a `const` item, so neither the analysis nor this runs on the target (an
    /// invalid table or band is then a compile error). The same table gives the same
    /// classifier as [`Classifier::new`] on the machine it came from.
    ///
    /// Errors: those of [`Classifier::new`]; for a table that is not as [`Machine::table`]
    /// makes one, `Inconsistent("zones")` (no zone, a first zone not gathering from 0, zones
    /// not ascending, not adjoining, not alternating, or a last one not open),
    /// `Capacity("zones")` (more than [`MAX_ZONES`]), `Capacity("captures")` (more than one
    /// window per platform) and `NonFinite` naming the field with a NaN or ±∞.
    pub const fn from_machine_table(
        table: &MachineTable,
        margin: f32,
        hysteresis: f32,
    ) -> Result<Self, ConfigError> {
        let mut c = match Self::empty(margin, hysteresis) {
            Ok(c) => c,
            Err(e) => return Err(e),
        };
        if let Err(e) = check_machine_table(table) {
            return Err(e);
        }
        let zones = table.zones;
        let mut i = 0;
        while i < zones.len() {
            let z = zones[i];
            let from = match speed_f32("zones.from", z.from) {
                Ok(f) => f,
                Err(e) => return Err(e),
            };
            let pushed = match z.kind {
                ZoneKind::Gathering => c.push_segment(RegimeSegment {
                    from,
                    regime: Regime::Gathering,
                }),
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
                        match c.push_segment(RegimeSegment {
                            from,
                            regime: Regime::Bistable(BistableReason::Capture),
                        }) {
                            Ok(next) if until < to => {
                                match speed_f32("capture_windows.until", until) {
                                    Ok(from) => next.push_segment(RegimeSegment {
                                        from,
                                        regime: Regime::Balancing,
                                    }),
                                    Err(e) => Err(e),
                                }
                            }
                            other => other,
                        }
                    } else {
                        c.push_segment(RegimeSegment {
                            from,
                            regime: Regime::Balancing,
                        })
                    }
                }
            };
            c = match pushed {
                Ok(c) => c,
                Err(e) => return Err(e),
            };
            i += 1;
        }
        if let Err(e) = c.check_table() {
            return Err(e);
        }
        Ok(c)
    }

    const fn empty(margin: f32, hysteresis: f32) -> Result<Self, ConfigError> {
        let margin = match fraction("margin", margin) {
            Ok(x) => x,
            Err(e) => return Err(e),
        };
        let hysteresis = match fraction("hysteresis", hysteresis) {
            Ok(x) => x,
            Err(e) => return Err(e),
        };
        Ok(Classifier {
            seg_from: [0.0; MAX_SEGMENTS],
            seg_regime: [Regime::Gathering; MAX_SEGMENTS],
            n_seg: 0,
            margin,
            hysteresis,
        })
    }

    /// The classifier with a segment appended. A segment starting where the last one starts
    /// (speeds equal once in f32) replaces it, and one of the last one's regime extends it, so
    /// the table stays strictly ascending with neighbours that differ.
    const fn push_segment(mut self, seg: RegimeSegment) -> Result<Self, ConfigError> {
        let mut n = self.n_seg as usize;
        if n > 0 && n <= MAX_SEGMENTS && seg.from <= self.seg_from[n - 1] {
            // The last segment is empty: drop it.
            n -= 1;
        }
        if n > 0 && n <= MAX_SEGMENTS && same_regime(self.seg_regime[n - 1], seg.regime) {
            self.n_seg = n as u8;
            return Ok(self);
        }
        if n >= MAX_SEGMENTS {
            return Err(ConfigError::Capacity("segments"));
        }
        self.seg_from[n] = if n == 0 { 0.0 } else { seg.from };
        self.seg_regime[n] = seg.regime;
        self.n_seg = n as u8 + 1;
        Ok(self)
    }

    /// Re-validates the built table (a machine's zones are validated by construction; this
    /// keeps the invariants `classify` relies on explicit).
    const fn check_table(&self) -> Result<(), ConfigError> {
        let mut segs = [RegimeSegment {
            from: 0.0,
            regime: Regime::Gathering,
        }; MAX_SEGMENTS];
        let n = self.n_seg as usize;
        let mut i = 0;
        while i < n && i < MAX_SEGMENTS {
            segs[i] = RegimeSegment {
                from: self.seg_from[i],
                regime: self.seg_regime[i],
            };
            i += 1;
        }
        match segs.split_at_checked(n) {
            Some((built, _)) => RegimeTable { segments: built }.validate(),
            None => Err(ConfigError::Capacity("segments")),
        }
    }

    /// The segments as a table (for printing it, or for shipping it to a target).
    pub fn segments(&self) -> impl Iterator<Item = RegimeSegment> + '_ {
        self.segs()
            .iter()
            .zip(&self.seg_regime)
            .map(|(&from, &regime)| RegimeSegment { from, regime })
    }

    fn segs(&self) -> &[f32] {
        self.seg_from.get(..usize::from(self.n_seg)).unwrap_or(&[])
    }

    /// The boundaries of the table (every segment's `from` but the first), ascending, rad/s:
    /// the speeds the margin band is placed about.
    pub fn boundaries(&self) -> &[f32] {
        self.segs().get(1..).unwrap_or(&[])
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

    /// Whether `s ≥ 0` lies within the margin band of a boundary.
    fn near(&self, s: f32) -> bool {
        let b = self.boundaries();
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

    /// The balancing position the loads balance at elsewhere (the equally spaced one of three
    /// or more) is stable in segment `i`: every regime but `Gathering` and
    /// `Bistable(Family)`.
    fn stable(&self, i: usize) -> bool {
        !matches!(
            self.seg_regime.get(i),
            Some(Regime::Gathering | Regime::Bistable(BistableReason::Family)) | None
        )
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
        let i = self.segment(s);
        // Where the balancing position is stable: the start of the stable run containing i.
        let drop_below = if self.stable(i) {
            let mut j = i;
            while j > 0 && self.stable(j - 1) {
                j -= 1;
            }
            self.seg_from
                .get(j)
                .copied()
                .filter(|&f| f > 0.0)
                .map(|f| f * (1.0 - self.margin))
        } else {
            None
        };
        // The highest segment where the loads gather, starting at or below s.
        let exciter_band = (0..=i)
            .rev()
            .find(|&g| self.seg_regime.get(g) == Some(&Regime::Gathering))
            .and_then(|g| {
                let (from, to) = self.segment_range(g);
                let band = SpeedBand {
                    from: from * (1.0 + self.margin),
                    to: to * (1.0 - self.margin),
                };
                (to.is_finite() && band.from < band.to).then_some(band)
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
    /// speed or before the first valid one). Where the table says `Bistable` but the loads
    /// are known to balance (see [`RegimeStatus::by_history`]), `Balancing`.
    pub regime: Regime,
    /// The regime comes from the loads' history, not from the speed alone: the table says
    /// [`Regime::Bistable`] here, and the speed reached this segment from a `Balancing` one
    /// through segments where the balancing position is stable, so the loads that balanced
    /// there still balance ([`RegimeTracker`]).
    pub by_history: bool,
    /// The speed is within the margin band of a characteristic speed.
    pub near_characteristic: bool,
    /// Set when the held regime changed on this update.
    pub event: Option<RegimeEvent>,
}

/// Hysteresis state: holds a segment until the speed is past its edges by the relative
/// hysteresis, so a speed sitting on a boundary does not chatter.
///
/// It also remembers whether the loads balance where the table alone cannot say. In a
/// `Bistable` segment the balancing position is stable and another state can persist too,
/// so which one the loads are in depends on how the speed got there. One history decides it:
/// loads that balanced in a `Balancing` segment stay at the balancing position while the
/// speed moves through segments where that position stays stable (every class but
/// `Gathering`), so there the tracker reports `Balancing` ([`RegimeStatus::by_history`]).
/// This is the seed's advice read backwards: to make the loads gather again the speed must
/// drop below the stable stretch ([`Advice::drop_below`]). Arriving from a `Gathering`
/// segment (a run-up through a resonance) or starting inside the segment leaves it
/// `Bistable`: a run-up captures the loads at most speeds of a capture band, but not at all
/// (`docs/criterion.md`). The history holds for speed changes that are slow against the loads'
/// relaxation: on 120 random machines, loads ramped into a bistable segment from a balancing
/// one within the machine's base run time stayed balanced at 830 of 831 speeds; the other was a
/// run-down from 571 to 68 rad/s, which left them captured.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegimeTracker {
    held: Option<u8>,
    /// The loads balanced in a `Balancing` segment and every segment held since has kept the
    /// balancing position stable.
    balanced: bool,
}

impl RegimeTracker {
    /// A tracker holding nothing yet.
    pub const fn new() -> Self {
        RegimeTracker {
            held: None,
            balanced: false,
        }
    }

    /// Feeds one speed in rad/s (sign ignored). A non-finite speed keeps the held segment
    /// and reports `Unknown` without an event. A tracker follows one classifier: for another
    /// table start a new tracker (a held segment the new classifier does not have is dropped,
    /// and the next speed starts afresh).
    pub fn update(&mut self, c: &Classifier, speed: f32) -> RegimeStatus {
        if !speed.is_finite() {
            return RegimeStatus {
                regime: Regime::Unknown,
                by_history: false,
                near_characteristic: false,
                event: None,
            };
        }
        let s = speed.abs();
        let raw = c.segment(s);
        // A segment beyond this classifier's (a tracker fed another table before) is no
        // history: held, it read as gathering at every speed for good.
        let before = self
            .held
            .map(usize::from)
            .filter(|&h| h < usize::from(c.n_seg));
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
        let was = before.map_or(Regime::Unknown, |h| self.resolved(c, h));
        if before != Some(next) {
            self.balanced = match c.segment_regime(next) {
                Regime::Balancing => true,
                // Still balanced only if every segment passed over kept the position stable
                // (a jump across a `Gathering` segment loses the history).
                Regime::Bistable(_) => {
                    self.balanced
                        && before.is_some_and(|h| (h.min(next)..=h.max(next)).all(|i| c.stable(i)))
                }
                _ => false,
            };
        }
        self.held = Some(next.min(MAX_SEGMENTS) as u8);
        let to = self.resolved(c, next);
        RegimeStatus {
            regime: to,
            by_history: to != c.segment_regime(next),
            near_characteristic: c.near(s),
            event: (was != to).then_some(RegimeEvent {
                from: was,
                to,
                speed: s,
            }),
        }
    }

    /// The regime of segment `i` with the loads' history: `Balancing` for a `Bistable`
    /// segment the loads arrived at balanced.
    fn resolved(&self, c: &Classifier, i: usize) -> Regime {
        match c.segment_regime(i) {
            Regime::Bistable(_) if self.balanced => Regime::Balancing,
            r => r,
        }
    }
}
