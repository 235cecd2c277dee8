//! Limits: ISO 21940-11 permissible residual unbalance allocated to the support planes, the
//! supports' allowed dynamic loads, and the maximum safe speed they imply.

use super::rotor::Rotor;
use super::runtime::SupportMonitor;
use super::vector::Vec2;
use crate::error::{positive, ConfigError};

/// Default start of the warning band, as a fraction of each limit.
pub const DEFAULT_WARNING_FRACTION: f64 = 0.8;

/// ISO 21940-11: for an inboard rotor neither support plane is allocated less than this
/// fraction of the permissible residual unbalance …
pub const ISO_SHARE_MIN: f64 = 0.3;
/// … nor more than this fraction.
pub const ISO_SHARE_MAX: f64 = 0.7;

/// Validated limits for a rotor.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Limits {
    grade: f64,
    service_speed: f64,
    load_limit: Option<[f64; 2]>,
    warning_fraction: f64,
}

impl Limits {
    /// Limits from the balance quality grade `grade` (G, mm/s, e.g. 6.3), the maximum service
    /// speed `service_speed` (rad/s), the allowed dynamic load of supports A and B
    /// (`support_load_limit`, N, or `None`) and the start of the warning band
    /// (`warning_fraction` of each limit, in (0, 1], e.g. [`DEFAULT_WARNING_FRACTION`]).
    /// Each number must be positive ([`positive`]); a fraction above 1 is `OutOfRange`.
    pub fn new(
        grade: f64,
        service_speed: f64,
        support_load_limit: Option<[f64; 2]>,
        warning_fraction: f64,
    ) -> Result<Self, ConfigError> {
        let grade = positive("grade", grade)?;
        let service_speed = positive("service_speed", service_speed)?;
        let load_limit = match support_load_limit {
            Some([a, b]) => Some([
                positive("support_load_limit.a", a)?,
                positive("support_load_limit.b", b)?,
            ]),
            None => None,
        };
        let warning_fraction = positive("warning_fraction", warning_fraction)?;
        if warning_fraction > 1.0 {
            return Err(ConfigError::OutOfRange("warning_fraction"));
        }
        Ok(Limits {
            grade,
            service_speed,
            load_limit,
            warning_fraction,
        })
    }

    /// Balance quality grade G, mm/s.
    pub fn grade(&self) -> f64 {
        self.grade
    }
    /// Maximum service speed, rad/s.
    pub fn service_speed(&self) -> f64 {
        self.service_speed
    }
    /// Allowed dynamic loads of supports A and B, N.
    pub fn support_load_limit(&self) -> Option<[f64; 2]> {
        self.load_limit
    }
    /// Start of the warning band as a fraction of each limit.
    pub fn warning_fraction(&self) -> f64 {
        self.warning_fraction
    }
}

/// ISO 21940-11 permissible residual unbalance `U_per = G·m/ω`, kg·m, for grade `grade_mm_s`
/// (mm/s, converted to m/s), rotor mass `mass` (kg) and maximum service speed `omega` (rad/s).
/// (In the standard's units, `U_per[g·mm] = 1000·G[mm/s]·m[kg]/ω[rad/s]`.)
pub fn permissible_residual_unbalance(grade_mm_s: f64, mass: f64, omega: f64) -> f64 {
    grade_mm_s * 1e-3 * mass / omega
}

/// How the permissible residual unbalance was allocated to the support planes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum Allocation {
    /// Centre of mass between the supports (or on one): ISO 21940-11's rule,
    /// `U_perA = U_per·L_B/L`, `U_perB = U_per·L_A/L`, each held within
    /// [`ISO_SHARE_MIN`]·U_per … [`ISO_SHARE_MAX`]·U_per.
    Inboard,
    /// Centre of mass outside the span (overhung rotor). This product's rule, not an ISO
    /// factor: each plane is allowed the magnitude of the plane equivalent of `U_per` placed
    /// at the centre of mass, `U_perA = U_per·|L_B|/L`, `U_perB = U_per·|L_A|/L` (static
    /// split), the far plane (the one away from the overhang) held at least at
    /// [`ISO_SHARE_MIN`]·U_per as ISO holds an inboard rotor's planes. A rotor whose whole
    /// residual unbalance is `U_per` at its centre of mass then sits exactly on the near
    /// plane's limit and within the far one's; the near plane is allowed more than `U_per`
    /// because it carries the lever. Where the centre of mass crosses a support the far
    /// plane's limit is continuous (30 % on both sides; without the floor it fell to
    /// `U_per·|L_A|/L` → 0, and a rotor 1 mm overhung on a 4 m span was allowed 1/1200 of its
    /// inboard limit there) and the near plane's rises from 70 % to 100 % of `U_per`.
    /// Narrow rotors are not treated separately.
    Overhung,
}

/// Permissible residual unbalance and its allocation to the support planes, kg·m.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Permissible {
    /// `U_per = G·m/ω`, kg·m.
    pub total: f64,
    /// Allowed residual unbalance in plane A, kg·m.
    pub a: f64,
    /// Allowed residual unbalance in plane B, kg·m.
    pub b: f64,
    /// The rule used.
    pub allocation: Allocation,
}

/// Allocate `u_per` to the support planes at `support_a`, `support_b` for a centre of mass at
/// `centre_of_mass` (see [`Allocation`]). `L_A = z_m − z_A`, `L_B = z_B − z_m`, `L = z_B − z_A`
/// are signed, so the supports may be given in either order.
pub fn allocate(u_per: f64, support_a: f64, support_b: f64, centre_of_mass: f64) -> Permissible {
    let l = support_b - support_a;
    let share_a = (support_b - centre_of_mass) / l;
    let share_b = (centre_of_mass - support_a) / l;
    if share_a >= 0.0 && share_b >= 0.0 {
        Permissible {
            total: u_per,
            a: u_per * share_a.clamp(ISO_SHARE_MIN, ISO_SHARE_MAX),
            b: u_per * share_b.clamp(ISO_SHARE_MIN, ISO_SHARE_MAX),
            allocation: Allocation::Inboard,
        }
    } else {
        // The near plane's share is above 1: only the far plane's floor can bind.
        Permissible {
            total: u_per,
            a: u_per * share_a.abs().max(ISO_SHARE_MIN),
            b: u_per * share_b.abs().max(ISO_SHARE_MIN),
            allocation: Allocation::Overhung,
        }
    }
}

/// The largest speed (rad/s) at which `static_load + unbalance·ω² ≤ allowed`:
/// `ω = √((allowed − static_load)/unbalance)`. `+∞` when `unbalance` is 0 and the static load
/// is within the limit; `0` when the static load alone exceeds the limit (no speed is safe).
/// Arguments are magnitudes (N, kg·m, N).
pub fn max_safe_speed(static_load: f64, unbalance: f64, allowed: f64) -> f64 {
    if static_load > allowed {
        0.0
    } else if unbalance == 0.0 {
        f64::INFINITY
    } else {
        libm::sqrt((allowed - static_load) / unbalance)
    }
}

/// Everything the supports need, computed once at configuration time (f64).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SupportAnalysis {
    /// Equivalent unbalance in the support planes `[D_A, D_B]`, kg·m.
    pub unbalance: [Vec2; 2],
    /// Static support loads `[S_A, S_B]`, N.
    pub static_load: [Vec2; 2],
    /// Permissible residual unbalance and its allocation.
    pub permissible: Permissible,
    /// Allowed dynamic loads, N, if given.
    pub load_limit: Option<[f64; 2]>,
    /// Maximum safe speed per support, rad/s (see [`max_safe_speed`]), if load limits are given.
    pub max_speed: Option<[f64; 2]>,
    /// Start of the warning band as a fraction of each limit.
    pub warning_fraction: f64,
}

/// The numbers `drive-sim predict --json` prints under `supports`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SupportsReport {
    /// `|D_A|`, kg·m.
    pub unbalance_a: f64,
    /// `|D_B|`, kg·m.
    pub unbalance_b: f64,
    /// Permissible residual unbalance allocated to plane A, kg·m.
    pub permissible_a: f64,
    /// Permissible residual unbalance allocated to plane B, kg·m.
    pub permissible_b: f64,
    /// Maximum safe speed over both supports, rad/s; `None` without load limits. May be
    /// `+∞` (no unbalance) or `0` (the static load alone exceeds a limit).
    pub max_speed: Option<f64>,
}

impl SupportAnalysis {
    /// Analyse `rotor` against `limits`.
    ///
    /// Errors when a result is not usable: a permissible residual unbalance `G·m/ω` that is
    /// not a positive finite f64 (`OutOfRange("grade")`), or a number the f32
    /// [`SupportMonitor`] would hold as infinity or zero (see [`SupportMonitor::new`]). An
    /// analysis from here always gives a monitor.
    pub fn new<const N: usize>(rotor: &Rotor<N>, limits: &Limits) -> Result<Self, ConfigError> {
        let unbalance = rotor.support_unbalance();
        let static_load = rotor.static_load();
        let u_per =
            permissible_residual_unbalance(limits.grade, rotor.mass(), limits.service_speed);
        // Grade, mass and speed are each positive and finite; their quotient need not be.
        positive("grade", u_per).map_err(|_| ConfigError::OutOfRange("grade"))?;
        let permissible = allocate(
            u_per,
            rotor.support_a(),
            rotor.support_b(),
            rotor.centre_of_mass(),
        );
        let max_speed = limits.load_limit.map(|[fa, fb]| {
            let [sa, sb] = static_load;
            let [da, db] = unbalance;
            [
                max_safe_speed(sa.norm(), da.norm(), fa),
                max_safe_speed(sb.norm(), db.norm(), fb),
            ]
        });
        let analysis = SupportAnalysis {
            unbalance,
            static_load,
            permissible,
            load_limit: limits.load_limit,
            max_speed,
            warning_fraction: limits.warning_fraction,
        };
        SupportMonitor::new(&analysis)?;
        Ok(analysis)
    }

    /// Maximum safe speed over both supports, rad/s; `None` without load limits.
    pub fn max_safe_speed(&self) -> Option<f64> {
        self.max_speed.map(|[a, b]| a.min(b))
    }

    /// The host CLI's summary.
    pub fn report(&self) -> SupportsReport {
        let [da, db] = self.unbalance;
        SupportsReport {
            unbalance_a: da.norm(),
            unbalance_b: db.norm(),
            permissible_a: self.permissible.a,
            permissible_b: self.permissible.b,
            max_speed: self.max_safe_speed(),
        }
    }

    /// The f32 runtime monitor for the speed updates. Never fails for an analysis built by
    /// [`SupportAnalysis::new`] and left as it was (its fields are public: see
    /// [`SupportMonitor::new`] for what is checked).
    pub fn monitor(&self) -> Result<SupportMonitor, ConfigError> {
        SupportMonitor::new(self)
    }
}
