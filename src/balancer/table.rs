//! The regime table the run-time [`Classifier`](super::Classifier) is built from: a short,
//! ascending list of speeds at which the expected regime changes.
//!
//! The table is data. A machine's exact table (the stability of the balancing position from
//! the Floquet multipliers of the model, the capture windows, the criterion's zones) is
//! computed at design time on the host (`drive-sim predict`) and shipped to the target as a
//! `const`; the target only validates it once ([`Classifier::from_table`]) and looks speeds up
//! in it. [`Classifier::new`] builds the seed criterion's table from a [`Machine`] instead.
//!
//! A table for the firmware is written as
//!
//! ```
//! use drive_monitor::balancer::{BistableReason, Classifier, Regime, RegimeSegment, RegimeTable};
//!
//! const REGIMES: RegimeTable<'static> = RegimeTable {
//!     segments: &[
//!         RegimeSegment { from: 0.0, regime: Regime::Gathering },
//!         RegimeSegment { from: 60.1, regime: Regime::Bistable(BistableReason::Capture) },
//!         RegimeSegment { from: 66.4, regime: Regime::Balancing },
//!     ],
//! };
//! let c = Classifier::from_table(&REGIMES, 0.02, 0.01)?;
//! assert_eq!(c.classify(30.0), Regime::Gathering);
//! assert_eq!(c.classify(63.0), Regime::Bistable(BistableReason::Capture));
//! assert_eq!(c.classify(100.0), Regime::Balancing);
//! # Ok::<(), drive_monitor::ConfigError>(())
//! ```
//!
//! [`Classifier::from_table`]: super::Classifier::from_table
//! [`Classifier::new`]: super::Classifier::new
//! [`Machine`]: super::Machine

use super::Regime;
use crate::error::ConfigError;

/// Most segments a table may have.
pub const MAX_SEGMENTS: usize = 16;

/// Why the classifier does not commit to a regime at a speed where the balancing position is
/// locally stable: another, non-balancing state can persist there too, and which one the
/// machine is in depends on its history.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BistableReason {
    /// Sommerfeld capture: a capture window below reaches past this speed, so loads gathered
    /// near a resonance in a run-up can stay captured there, turning slower than the rotor,
    /// while loads near the balancing position stay balanced.
    Capture,
    /// The seed's criterion says the gathered loads hold together here (`Re H > 0`): loads
    /// that gathered can stay gathered, while loads near the balancing position stay balanced.
    Coexisting,
    /// Three or more loads: the equally spaced fan of balancing positions is unstable here, but
    /// another balancing position of their family is stable, so the loads can balance there or
    /// gather, depending on where they start.
    Family,
}

impl BistableReason {
    /// Lower-case name as used in the host's JSON: `"capture"`, `"coexisting"` or `"family"`.
    pub fn name(self) -> &'static str {
        match self {
            BistableReason::Capture => "capture",
            BistableReason::Coexisting => "coexisting",
            BistableReason::Family => "family",
        }
    }
}

/// One segment of a [`RegimeTable`]: the regime from `from` rad/s up to the next segment's
/// `from` (the last segment is open-ended).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegimeSegment {
    /// Lower edge, rad/s (0 for the first segment).
    pub from: f32,
    /// `Balancing`, `Gathering` or `Bistable(_)`.
    pub regime: Regime,
}

impl RegimeSegment {
    /// A segment from an f64 speed, rejecting speeds f32 cannot hold: a speed that is not
    /// finite, negative, or that would round to f32 infinity or to zero or an f32 subnormal
    /// gives `OutOfRange(name)` (`NonFinite(name)` for NaN and infinities).
    pub fn new(name: &'static str, from: f64, regime: Regime) -> Result<Self, ConfigError> {
        Ok(RegimeSegment {
            from: speed_f32(name, from)?,
            regime,
        })
    }
}

/// `x` rad/s as an f32 speed: 0 stays 0; any other value must be finite, positive and land
/// on a finite, normal f32 (`NonFinite`, `Negative`, `OutOfRange` naming `name`).
pub const fn speed_f32(name: &'static str, x: f64) -> Result<f32, ConfigError> {
    if !x.is_finite() {
        return Err(ConfigError::NonFinite(name));
    }
    if x < 0.0 {
        return Err(ConfigError::Negative(name));
    }
    if x == 0.0 {
        return Ok(0.0);
    }
    let f = x as f32;
    if f.is_finite() && f >= f32::MIN_POSITIVE {
        Ok(f)
    } else {
        Err(ConfigError::OutOfRange(name))
    }
}

/// The regimes over all speeds: segments ascending from 0, each with the regime that holds
/// from its `from` up to the next one's. Plain data, so a table can be a `const` (see the
/// module docs); [`Classifier::from_table`](super::Classifier::from_table) validates it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct RegimeTable<'a> {
    /// The segments: 1 to [`MAX_SEGMENTS`], the first from 0, `from` strictly ascending and
    /// finite, neighbours of different regimes, regimes only `Balancing`, `Gathering` and
    /// `Bistable(_)`.
    pub segments: &'a [RegimeSegment],
}

impl RegimeTable<'_> {
    /// Checks the table as documented on [`RegimeTable::segments`]: `Capacity("segments")`,
    /// `OutOfRange("segments.from")` for a first segment not from 0 or a `from` that is not
    /// a finite, normal f32, `Inconsistent("segments.from")` for speeds not strictly
    /// ascending, `OutOfRange("segments.regime")` for `NearCharacteristic` or `Unknown`,
    /// `Inconsistent("segments.regime")` for two neighbours of the same regime.
    pub const fn validate(&self) -> Result<(), ConfigError> {
        let s = self.segments;
        if s.is_empty() || s.len() > MAX_SEGMENTS {
            return Err(ConfigError::Capacity("segments"));
        }
        if s[0].from != 0.0 {
            return Err(ConfigError::OutOfRange("segments.from"));
        }
        let mut i = 0;
        while i < s.len() {
            let seg = s[i];
            if matches!(seg.regime, Regime::NearCharacteristic | Regime::Unknown) {
                return Err(ConfigError::OutOfRange("segments.regime"));
            }
            if i > 0 {
                let prev = s[i - 1];
                if !(seg.from.is_finite() && seg.from >= f32::MIN_POSITIVE) {
                    return Err(ConfigError::OutOfRange("segments.from"));
                }
                if seg.from <= prev.from {
                    return Err(ConfigError::Inconsistent("segments.from"));
                }
                if same_regime(seg.regime, prev.regime) {
                    return Err(ConfigError::Inconsistent("segments.regime"));
                }
            }
            i += 1;
        }
        Ok(())
    }
}

/// `a == b`, in a form a `const fn` can call.
pub(crate) const fn same_regime(a: Regime, b: Regime) -> bool {
    match (a, b) {
        (Regime::Bistable(x), Regime::Bistable(y)) => matches!(
            (x, y),
            (BistableReason::Capture, BistableReason::Capture)
                | (BistableReason::Coexisting, BistableReason::Coexisting)
                | (BistableReason::Family, BistableReason::Family)
        ),
        (Regime::Balancing, Regime::Balancing)
        | (Regime::Gathering, Regime::Gathering)
        | (Regime::NearCharacteristic, Regime::NearCharacteristic)
        | (Regime::Unknown, Regime::Unknown) => true,
        _ => false,
    }
}
