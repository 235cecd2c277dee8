//! The per-speed-update path: f32, O(1), total.

use super::limits::SupportAnalysis;
use crate::error::ConfigError;
use crate::math::Math;

/// Where a value stands against its limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Level {
    /// At or below the warning threshold (`fraction·limit`).
    Normal,
    /// Above the warning threshold, at or below the limit.
    Warning,
    /// Above the limit.
    Over,
    /// Not known: the speed was not a number, or there is no limit to judge against.
    Unknown,
}

impl Level {
    #[inline]
    fn of(value: f32, warn: f32, limit: f32) -> Level {
        if value > limit {
            Level::Over
        } else if value > warn {
            Level::Warning
        } else if value <= warn {
            Level::Normal
        } else {
            Level::Unknown
        }
    }
}

/// The result of one speed update.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SupportStatus {
    /// False when the speed was NaN (loads are then NaN and their levels `Unknown`).
    pub speed_valid: bool,
    /// Largest load on supports A and B over one turn, `|S| + |D|·ω²`, N.
    pub peak_load: [f32; 2],
    /// Smallest load over one turn, `||S| − |D|·ω²|`, N.
    pub min_load: [f32; 2],
    /// Peak load against each support's allowed load (`Unknown` without load limits).
    pub load: [Level; 2],
    /// Equivalent unbalance in each support plane against its permissible share.
    pub unbalance: [Level; 2],
    /// Maximum safe speed over both supports, rad/s (`None` without load limits).
    pub max_safe_speed: Option<f32>,
}

/// Precomputed f32 numbers for the speed updates: a few multiplies and compares per update.
///
/// Speed enters only as ω², so a negative speed (reverse rotation) loads the supports like the
/// positive one; an infinite speed gives infinite rotating loads (flagged `Over`) unless the
/// unbalance is zero; NaN gives `speed_valid = false`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SupportMonitor {
    unbalance: [f32; 2],
    permissible: [f32; 2],
    permissible_warn: [f32; 2],
    static_load: [f32; 2],
    load_limit: Option<[f32; 2]>,
    load_warn: [f32; 2],
    max_speed: [f32; 2],
}

impl SupportMonitor {
    /// Precompute from an analysis (configuration time).
    ///
    /// Every number is converted to f32 once, here, and checked: an unbalance, static load,
    /// load limit or permissible unbalance that is not finite as an f32 (beyond 3.4e38), or a
    /// permissible unbalance or load limit below f32's normal range (0 or subnormal), is an `OutOfRange` error naming
    /// the rotor's parameter (`unbalances`, `process_load.per_length`, `support_load_limit.a`
    /// or `.b`, `grade`); unchecked, the monitor would judge against infinities and report
    /// infinite or NaN loads for a finite speed. A maximum safe speed beyond f32 becomes
    /// infinity (no speed an f32 holds reaches it).
    pub fn new(analysis: &SupportAnalysis) -> Result<Self, ConfigError> {
        let w = analysis.warning_fraction;
        let [da, db] = analysis.unbalance;
        let [sa, sb] = analysis.static_load;
        let p = analysis.permissible;
        let max_speed = analysis.max_speed.unwrap_or([f64::INFINITY; 2]);
        let load_limit = match analysis.load_limit {
            Some([a, b]) => Some([
                to_f32_positive(a, "support_load_limit.a")?,
                to_f32_positive(b, "support_load_limit.b")?,
            ]),
            None => None,
        };
        Ok(SupportMonitor {
            unbalance: [
                to_f32(da.norm(), "unbalances")?,
                to_f32(db.norm(), "unbalances")?,
            ],
            permissible: [
                to_f32_positive(p.a, "grade")?,
                to_f32_positive(p.b, "grade")?,
            ],
            permissible_warn: [(w * p.a) as f32, (w * p.b) as f32],
            static_load: [
                to_f32(sa.norm(), "process_load.per_length")?,
                to_f32(sb.norm(), "process_load.per_length")?,
            ],
            load_warn: analysis.load_limit.map_or([f32::INFINITY; 2], |[a, b]| {
                [(w * a) as f32, (w * b) as f32]
            }),
            load_limit,
            max_speed: [max_speed[0] as f32, max_speed[1] as f32],
        })
    }

    /// Loads and flags at speed `omega` rad/s. Total: any f32 gives a defined status. For a
    /// δ window, pass its fastest speed ([`crate::irregularity::Measurement::omega_max`]): the
    /// unbalance load |D|·ω² peaks there, about (1 + δ/2)² times its value at the mean speed.
    pub fn update(&self, omega: f32) -> SupportStatus {
        let w2 = omega * omega;
        let valid = !w2.is_nan();
        let mut peak = [f32::NAN; 2];
        let mut min = [f32::NAN; 2];
        let mut load = [Level::Unknown; 2];
        let limits = self.load_limit.unwrap_or([f32::INFINITY; 2]);
        for i in 0..2 {
            let (d, s) = (pick(self.unbalance, i), pick(self.static_load, i));
            if valid {
                // 0·∞ is taken as 0: no unbalance, no rotating load at any speed.
                let rot = if d == 0.0 { 0.0 } else { d * w2 };
                set(&mut peak, i, s + rot);
                set(&mut min, i, (s - rot).abs());
                if self.load_limit.is_some() {
                    let l = Level::of(s + rot, pick(self.load_warn, i), pick(limits, i));
                    set(&mut load, i, l);
                }
            }
        }
        SupportStatus {
            speed_valid: valid,
            peak_load: peak,
            min_load: min,
            load,
            unbalance: self.unbalance_levels(),
            max_safe_speed: self.max_safe_speed(),
        }
    }

    fn unbalance_levels(&self) -> [Level; 2] {
        let l = |i| {
            Level::of(
                pick(self.unbalance, i),
                pick(self.permissible_warn, i),
                pick(self.permissible, i),
            )
        };
        [l(0), l(1)]
    }

    /// Maximum safe speed over both supports, rad/s; `None` without load limits.
    pub fn max_safe_speed(&self) -> Option<f32> {
        self.load_limit
            .map(|_| self.max_speed[0].min(self.max_speed[1]))
    }

    /// Equivalent unbalance magnitudes `[|D_A|, |D_B|]` in use, kg·m.
    pub fn unbalance(&self) -> [f32; 2] {
        self.unbalance
    }

    /// Replace the equivalent unbalance magnitudes (e.g. from a measurement) and recompute
    /// the maximum safe speed (one square root per support through `M`). Values that are
    /// not finite or are negative are refused: the previous values stay and `false` is
    /// returned.
    pub fn set_unbalance<M: Math>(&mut self, a: f32, b: f32) -> bool {
        if !(a.is_finite() && b.is_finite() && a >= 0.0 && b >= 0.0) {
            return false;
        }
        self.unbalance = [a, b];
        if let Some(f) = self.load_limit {
            for i in 0..2 {
                let (s, fi, d) = (
                    pick(self.static_load, i),
                    pick(f, i),
                    pick(self.unbalance, i),
                );
                let w = if s > fi {
                    0.0
                } else if d == 0.0 {
                    f32::INFINITY
                } else {
                    M::sqrt((fi - s) / d)
                };
                set(&mut self.max_speed, i, w);
            }
        }
        true
    }
}

#[inline]
fn pick(a: [f32; 2], i: usize) -> f32 {
    if i == 0 {
        a[0]
    } else {
        a[1]
    }
}

#[inline]
fn set<T: Copy>(a: &mut [T; 2], i: usize, v: T) {
    if let Some(slot) = a.get_mut(i) {
        *slot = v;
    }
}

/// `x` (finite, not negative) as a finite f32, else `OutOfRange(name)`.
fn to_f32(x: f64, name: &'static str) -> Result<f32, ConfigError> {
    let y = x as f32;
    if y.is_finite() && y >= 0.0 {
        Ok(y)
    } else {
        Err(ConfigError::OutOfRange(name))
    }
}

/// Like [`to_f32`], and a normal f32 (not 0 or subnormal: a positive f64 below f32's range).
fn to_f32_positive(x: f64, name: &'static str) -> Result<f32, ConfigError> {
    match to_f32(x, name)? {
        y if y >= f32::MIN_POSITIVE => Ok(y),
        _ => Err(ConfigError::OutOfRange(name)),
    }
}
