//! Auto-balancer regimes of one-, two- and three-mass vibration machines (seed 001).
//!
//! A ball, roller or pendulum auto-balancer with `N ≥ 2` loads sits on one platform (the
//! *exciter platform*) of a machine of 1–3 platforms that move in translation on
//! elastic-viscous supports and are joined by elastic-viscous couplings. Depending on the
//! rotor speed the loads either take the auto-balancing position (*balancing*) or gather and
//! turn together as one unbalance (*gathering*: the machine becomes a resonant vibration
//! exciter). This module
//!
//! 1. validates the machine in SI units ([`MachineConfig`]) and derives the seed's
//!    dimensionless parameters ([`Dimensionless`]);
//! 2. computes the undamped characteristic speeds ([`Machine::resonant_speeds`],
//!    [`Machine::additional_speeds`]);
//! 3. finds, with the damping, the zones where balancing is stable ([`Machine::zones`]) and
//!    the Sommerfeld capture windows ([`Machine::capture_windows`]);
//! 4. classifies a measured speed at run time in f32 ([`Classifier`], [`RegimeTracker`]),
//!    from the criterion's zones ([`Classifier::new`]) or from an exact [`RegimeTable`]
//!    computed on the host and shipped as data ([`Classifier::from_table`], module
//!    [`table`]).
//!
//! Steps 1–3 run once at configuration time in f64; step 4 is the per-update path.
//!
//! # The criterion (seed eq. 1–3) in physical form
//!
//! Let the loads form a constant unbalance `S = N·m·R` turning at speed `ω`. Its reaction on
//! the exciter platform `e` is the force `F(t) = S·ω²·sin ωt` along the platform's guide
//! (the seed writes it as `−N·m·R·s̈_y`; eq. 11 and 15 carry compensating sign slips, the
//! physics fixes the sign: below the first resonance the platform moves *towards* the
//! unbalance and the loads gather). With `Z(ω) = K − ω²M + iωC` and the driving-point
//! receptance `H(ω) = [Z(ω)⁻¹]_ee` (displacement per force, `H = 1/(k − mω² + icω)` for one
//! platform) the steady displacement is `Y = S·ω²·(Re H·sin ωt + Im H·cos ωt)`, and the
//! seed's functional is the mean over a turn
//!
//! `f = ⟨S·sin ωt · Y⟩ = ½·S²·ω²·Re H(ω)`.
//!
//! So balancing is stable exactly where `Re H(ω) < 0` and the loads gather where
//! `Re H(ω) > 0`. In the seed's variables `Re H̃ = f(q)/Δ(q)` (eq. 31 with eq. 29, two
//! platforms) and `Re H̃ = Δ₃(q)/Δ(q)` (eq. 51–53, three platforms), with `Δ(q) > 0` and
//! `H̃ = M_eΣ·ω̃²·H`; the tests check these identities.
//!
//! Undamped, `H_ee = det Z_oo / det Z`: it changes sign at the poles (the resonant speeds,
//! eigenfrequencies of `(K, M)`) and at the zeros (the *additional* speeds: antiresonances
//! of the exciter platform, i.e. the eigenfrequencies of the machine with platform `e`
//! held fixed). Cauchy interlacing gives the seed's order `q1 ≤ q̃1 ≤ q2 ≤ q̃2 ≤ q3`.
//!
//! # Mapping to the seed's dimensionless parameters
//!
//! See [`Dimensionless`]. The exciter platform's moving mass is
//! `M_eΣ = mass + housing_mass + N·load_mass` (seed eq. 7, 21). The seed leaves `ω̃` free for
//! two and three platforms; here `ω̃ = √(k_e / M_eΣ)` (the exciter platform's support
//! frequency), which is the seed's `ω̃` for one platform (eq. 8) and makes `n_e = 1`. The seed
//! puts the auto-balancer on platform 2; any platform is accepted here and the formulas are
//! the seed's with the platforms relabelled (`e` plays the role of the seed's platform 2).

mod complex;
mod damped;
mod modal;
mod poly;
mod runtime;
mod scanned;
pub mod table;
#[cfg(test)]
mod tests;

pub use runtime::{
    Advice, Classifier, Regime, RegimeEvent, RegimeStatus, RegimeTracker, SpeedBand,
    DEFAULT_MARGIN, TABLE_MARGIN,
};
pub use table::{BistableReason, RegimeSegment, RegimeTable};

use crate::error::{finite, non_negative, positive, ConfigError};

/// Largest number of platforms.
pub const MAX_PLATFORMS: usize = 3;
/// Largest number of couplings (one per pair of platforms).
pub const MAX_COUPLINGS: usize = 3;
/// Largest number of zones (`2·platforms − 1` characteristic speeds give at most 6 zones).
pub const MAX_ZONES: usize = 2 * MAX_PLATFORMS;

/// One platform: its own mass and its elastic-viscous support to the ground.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Platform {
    /// Mass in kg, without the auto-balancer (its housing and loads are added for the
    /// exciter platform).
    pub mass: f64,
    /// Support stiffness to the ground, N/m (must be positive).
    pub stiffness: f64,
    /// Support damping (viscosity) to the ground, N·s/m.
    pub damping: f64,
}

/// An elastic-viscous coupling between two platforms.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Coupling {
    /// The two platforms, numbered from 1 as in the scene file.
    pub between: [u8; 2],
    /// Coupling stiffness, N/m (zero allowed: the platforms are then uncoupled).
    pub stiffness: f64,
    /// Coupling damping, N·s/m.
    pub damping: f64,
}

impl Coupling {
    /// The two platforms as indices from 0 (kept in range for any `between`).
    pub(crate) fn indices(&self) -> [usize; 2] {
        self.between
            .map(|p| usize::from(p).saturating_sub(1) % MAX_PLATFORMS)
    }
}

/// Type of auto-balancer; fixes the inertia factor `κ` of the loads (seed eq. 9).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum BalancerKind {
    /// Balls rolling in a race, `κ = 7/5`.
    Ball,
    /// Rollers, `κ = 3/2`.
    Roller,
    /// Pendulums, `κ = 1 + J_c/(m·R²)`.
    Pendulum {
        /// Moment of inertia of one pendulum about its centre of mass, kg·m².
        inertia: f64,
    },
}

/// The auto-balancer (vibration exciter) and where it sits.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct AutoBalancer {
    /// Ball, roller or pendulum.
    pub kind: BalancerKind,
    /// The platform carrying it, numbered from 1 (the seed: 1 for one platform, else 2).
    pub platform: u8,
    /// Number of loads `N ≥ 2`.
    pub loads: u16,
    /// Mass of one load, kg.
    pub load_mass: f64,
    /// Radius of the circle of the loads' centres of mass, m.
    pub radius: f64,
    /// Housing mass, kg (moves with the exciter platform).
    pub housing_mass: f64,
    /// Viscous resistance of a load moving relative to the housing, N·s/m: the force is
    /// `viscosity·R·(φ̇ − ω)`, the torque `viscosity·R²·(φ̇ − ω)` (the seed's `b_w`).
    pub viscosity: f64,
}

/// A validated machine in SI units.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MachineConfig {
    platforms: [Platform; MAX_PLATFORMS],
    n_platforms: u8,
    couplings: [Coupling; MAX_COUPLINGS],
    n_couplings: u8,
    balancer: AutoBalancer,
    kappa: f64,
}

const NO_PLATFORM: Platform = Platform {
    mass: 0.0,
    stiffness: 0.0,
    damping: 0.0,
};
const NO_COUPLING: Coupling = Coupling {
    between: [0, 0],
    stiffness: 0.0,
    damping: 0.0,
};

impl MachineConfig {
    /// Validates a machine.
    ///
    /// Errors: `Capacity("platforms")` for 0 or more than 3 platforms,
    /// `Capacity("couplings")` for more than 3 couplings; non-finite values give
    /// `NonFinite`; platform `mass`/`stiffness`, `load_mass`, `radius` and load `viscosity`
    /// must be positive (`NotPositive`); dampings, coupling stiffness, `housing_mass` and
    /// pendulum `inertia` must not be negative (`Negative`, subnormals `OutOfRange`);
    /// `loads < 2` and a balancer or coupling naming a missing platform give `OutOfRange`;
    /// a platform coupled to itself or a pair coupled twice gives `Inconsistent`.
    pub fn new(
        platforms: &[Platform],
        couplings: &[Coupling],
        balancer: AutoBalancer,
    ) -> Result<Self, ConfigError> {
        if platforms.is_empty() || platforms.len() > MAX_PLATFORMS {
            return Err(ConfigError::Capacity("platforms"));
        }
        if couplings.len() > MAX_COUPLINGS {
            return Err(ConfigError::Capacity("couplings"));
        }
        let n = platforms.len();
        let mut ps = [NO_PLATFORM; MAX_PLATFORMS];
        for (slot, p) in ps.iter_mut().zip(platforms) {
            *slot = Platform {
                mass: positive("platform mass", p.mass)?,
                stiffness: positive("platform stiffness", p.stiffness)?,
                damping: non_negative("platform damping", p.damping)?,
            };
        }
        let mut cs = [NO_COUPLING; MAX_COUPLINGS];
        for (i, c) in couplings.iter().enumerate() {
            let [a, b] = c.between;
            if a == 0 || b == 0 || usize::from(a) > n || usize::from(b) > n {
                return Err(ConfigError::OutOfRange("coupling between"));
            }
            if a == b {
                return Err(ConfigError::Inconsistent("coupling between"));
            }
            let (lo, hi) = if a < b { (a, b) } else { (b, a) };
            if cs
                .iter()
                .take(i)
                .any(|o| o.between[0] == lo && o.between[1] == hi)
            {
                return Err(ConfigError::Inconsistent("duplicate coupling"));
            }
            if let Some(slot) = cs.get_mut(i) {
                *slot = Coupling {
                    between: [lo, hi],
                    stiffness: non_negative("coupling stiffness", c.stiffness)?,
                    damping: non_negative("coupling damping", c.damping)?,
                };
            }
        }
        let b = balancer;
        if b.platform == 0 || usize::from(b.platform) > n {
            return Err(ConfigError::OutOfRange("autobalancer platform"));
        }
        if b.loads < 2 {
            return Err(ConfigError::OutOfRange("autobalancer loads"));
        }
        let load_mass = positive("load mass", b.load_mass)?;
        let radius = positive("radius", b.radius)?;
        let housing_mass = non_negative("housing mass", b.housing_mass)?;
        let viscosity = positive("load viscosity", b.viscosity)?;
        let kind = match b.kind {
            BalancerKind::Pendulum { inertia } => BalancerKind::Pendulum {
                inertia: non_negative("pendulum inertia", inertia)?,
            },
            k => k,
        };
        let kappa = match kind {
            BalancerKind::Ball => 7.0 / 5.0,
            BalancerKind::Roller => 3.0 / 2.0,
            BalancerKind::Pendulum { inertia } => 1.0 + inertia / (load_mass * radius * radius),
        };
        let kappa = finite("pendulum inertia", kappa)?;
        let cfg = MachineConfig {
            platforms: ps,
            n_platforms: n as u8,
            couplings: cs,
            n_couplings: couplings.len() as u8,
            balancer: AutoBalancer {
                kind,
                load_mass,
                radius,
                housing_mass,
                viscosity,
                ..b
            },
            kappa,
        };
        // Derived quantities must stay finite (e.g. N·m or M_eΣ overflowing).
        finite("exciter mass", cfg.exciter_mass())?;
        let d = cfg.dimensionless();
        finite("autobalancer loads", d.epsilon)?;
        positive("load viscosity", d.beta)?;
        Ok(cfg)
    }

    /// The platforms, in order.
    pub fn platforms(&self) -> &[Platform] {
        self.platforms
            .get(..usize::from(self.n_platforms))
            .unwrap_or(&[])
    }

    /// The couplings, each with `between` sorted ascending.
    pub fn couplings(&self) -> &[Coupling] {
        self.couplings
            .get(..usize::from(self.n_couplings))
            .unwrap_or(&[])
    }

    /// The auto-balancer.
    pub fn balancer(&self) -> &AutoBalancer {
        &self.balancer
    }

    /// Index (from 0) of the exciter platform.
    pub fn exciter_index(&self) -> usize {
        usize::from(self.balancer.platform).saturating_sub(1)
    }

    /// Inertia factor `κ` of the loads (seed eq. 9).
    pub fn kappa(&self) -> f64 {
        self.kappa
    }

    /// Total unbalance of the gathered loads `N·m·R`, kg·m.
    pub fn gathered_unbalance(&self) -> f64 {
        f64::from(self.balancer.loads) * self.balancer.load_mass * self.balancer.radius
    }

    /// Moving mass of the exciter platform `M_eΣ = mass + housing + N·m` (seed eq. 7, 21).
    pub fn exciter_mass(&self) -> f64 {
        let b = &self.balancer;
        let own = self
            .platforms
            .get(self.exciter_index())
            .map_or(0.0, |p| p.mass);
        own + b.housing_mass + f64::from(b.loads) * b.load_mass
    }

    /// Moving mass of platform `i` (from 0): its own mass, plus the auto-balancer for the
    /// exciter platform.
    pub fn moving_mass(&self, i: usize) -> f64 {
        if i == self.exciter_index() {
            self.exciter_mass()
        } else {
            self.platforms.get(i).map_or(0.0, |p| p.mass)
        }
    }

    /// The seed's dimensionless parameters (see [`Dimensionless`]).
    pub fn dimensionless(&self) -> Dimensionless {
        let e = self.exciter_index();
        let me = self.exciter_mass();
        let ke = self.platforms.get(e).map_or(0.0, |p| p.stiffness);
        let w = libm::sqrt(ke / me);
        let mut d = Dimensionless {
            omega_ref: w,
            n_sq: [0.0; MAX_PLATFORMS],
            h: [0.0; MAX_PLATFORMS],
            rho: [0.0; MAX_PLATFORMS],
            n_sq_coupling: [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS],
            h_coupling: [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS],
            epsilon: 0.0,
            beta: 0.0,
        };
        for (i, p) in self.platforms().iter().enumerate() {
            let mi = self.moving_mass(i);
            d.n_sq[i] = p.stiffness / (mi * w * w);
            d.h[i] = p.damping / (2.0 * mi * w);
            d.rho[i] = me / mi;
        }
        for c in self.couplings() {
            let [a, b] = c.indices();
            let n2 = c.stiffness / (me * w * w);
            let h = c.damping / (2.0 * me * w);
            d.n_sq_coupling[a][b] = n2;
            d.n_sq_coupling[b][a] = n2;
            d.h_coupling[a][b] = h;
            d.h_coupling[b][a] = h;
        }
        let bl = &self.balancer;
        let nm = f64::from(bl.loads) * bl.load_mass;
        d.epsilon = nm / (self.kappa * me);
        d.beta = bl.viscosity * me / (nm * bl.load_mass * w);
        d
    }
}

/// The seed's dimensionless parameters (eq. 6, 19–20, 41–42), indexed by platform from 0.
///
/// With `e` the exciter platform, `M_i` the moving masses (`M_e = M_eΣ`) and
/// `ω̃ = √(k_e/M_eΣ)`:
/// `n_i² = k_i/(M_i·ω̃²)`, `h_i = b_i/(2·M_i·ω̃)`, `ρ_i = M_eΣ/M_i`,
/// `n_ij² = k_ij/(M_eΣ·ω̃²)`, `h_ij = b_ij/(2·M_eΣ·ω̃)`, `ε = N·m/(κ·M_eΣ)`,
/// `β = b_w·M_eΣ/(N·m²·ω̃)`, the dimensionless speed is `q = ω/ω̃`, time `τ = ω̃·t`, and the
/// displacements are `y_i = Y_i/(ρ_i·Ỹ)` with `Ỹ = N·m·R/M_eΣ`. For the seed's two- and
/// three-platform machines (exciter on platform 2) `ρ = ρ_1 = rho[0]`, `ρ_3 = rho[2]`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Dimensionless {
    /// `ω̃`, rad/s.
    pub omega_ref: f64,
    /// `n_i²` (zero for absent platforms).
    pub n_sq: [f64; MAX_PLATFORMS],
    /// `h_i`.
    pub h: [f64; MAX_PLATFORMS],
    /// `ρ_i = M_eΣ/M_i` (1 at the exciter platform).
    pub rho: [f64; MAX_PLATFORMS],
    /// `n_ij²`, symmetric, zero where there is no coupling.
    pub n_sq_coupling: [[f64; MAX_PLATFORMS]; MAX_PLATFORMS],
    /// `h_ij`, symmetric.
    pub h_coupling: [[f64; MAX_PLATFORMS]; MAX_PLATFORMS],
    /// `ε = N·m/(κ·M_eΣ)`.
    pub epsilon: f64,
    /// `β = b_w·M_eΣ/(N·m²·ω̃)`.
    pub beta: f64,
}

/// Settings of the damped zone and capture search.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct SearchOptions {
    /// The zone search takes the sign of `Re H_ee` at this multiple of the highest zone
    /// boundary candidate or undamped characteristic speed, and doubles it while the sign
    /// there still says gathering (the reference scan ends its scan there).
    pub max_factor: f64,
    /// Scan density. [`Machine::new`]'s capture scan evaluates `nodes_per_interval / 4` f32
    /// nodes per gathering zone (half log-spaced, half closing in on the zone's end); the
    /// reference scan of [`Machine::new_scanned`] evaluates this many log-spaced nodes in each
    /// interval between consecutive undamped characteristic speeds and per gathering zone.
    pub nodes_per_interval: u16,
    /// Relative bracket width to which a zone boundary is refined.
    pub rel_tol: f64,
}

impl Default for SearchOptions {
    fn default() -> Self {
        SearchOptions {
            max_factor: 4.0,
            nodes_per_interval: 256,
            rel_tol: 1e-12,
        }
    }
}

impl SearchOptions {
    /// Validated options: `max_factor ≥ 1.5`, `nodes_per_interval ≥ 8`,
    /// `rel_tol` in `[1e-15, 1e-3]`.
    pub fn new(
        max_factor: f64,
        nodes_per_interval: u16,
        rel_tol: f64,
    ) -> Result<Self, ConfigError> {
        let max_factor = finite("max_factor", max_factor)?;
        if max_factor < 1.5 {
            return Err(ConfigError::OutOfRange("max_factor"));
        }
        if nodes_per_interval < 8 {
            return Err(ConfigError::OutOfRange("nodes_per_interval"));
        }
        let rel_tol = finite("rel_tol", rel_tol)?;
        if !(1e-15..=1e-3).contains(&rel_tol) {
            return Err(ConfigError::OutOfRange("rel_tol"));
        }
        Ok(SearchOptions {
            max_factor,
            nodes_per_interval,
            rel_tol,
        })
    }
}

/// What the criterion predicts in a zone.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ZoneKind {
    /// `Re H < 0`: the auto-balancing position is locally stable.
    Balancing,
    /// `Re H > 0`: the loads gather (exciter mode).
    Gathering,
}

impl ZoneKind {
    /// Lower-case name as used in the host's JSON: `"balancing"` or `"gathering"`.
    pub fn name(self) -> &'static str {
        match self {
            ZoneKind::Balancing => "balancing",
            ZoneKind::Gathering => "gathering",
        }
    }
}

/// A speed zone `[from, to)` in rad/s; `to == None` for the last, open-ended zone.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Zone {
    /// Lower edge, rad/s (0 for the first zone).
    pub from: f64,
    /// Upper edge, rad/s; `None` for the last zone.
    pub to: Option<f64>,
    /// Regime predicted by the criterion.
    pub kind: ZoneKind,
}

/// Narrowest capture window kept, relative to its lower edge: where the maximum of `Ω + D(Ω)`
/// sits at the zone's end with next to no lag the window is rounding wide (1.8e-13 of 2.2e6
/// rad/s met on a random machine, printed and tabled as a band), no band a drive could hold.
pub const MIN_CAPTURE_WIDTH: f64 = 1e-9;

/// Sommerfeld capture window above one gathering zone: loads gathered in that zone can stay
/// captured (turning at `Ω < ω`) for rotor speeds up to `until`, at least
/// [`MIN_CAPTURE_WIDTH`] above `from` (no window otherwise).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct CaptureWindow {
    /// Upper edge of the gathering zone (a damped characteristic speed), rad/s.
    pub from: f64,
    /// Rotor speed above which capture in this zone is impossible,
    /// `max over Ω in the zone of Ω + D(Ω)`, rad/s.
    pub until: f64,
    /// Load speed `Ω` at which that maximum is reached, rad/s.
    pub at: f64,
}

/// A machine's analysis as plain data, borrowed from a [`Machine`] ([`Machine::table`]) or
/// written as a `const` by `drive-sim predict SCENE --emit rust`, so firmware can build its
/// [`Classifier`] at compile time ([`Classifier::from_table`] is a `const fn`) without
/// analysing the machine at all.
///
/// All speeds in rad/s. A table from [`Machine::table`] is always valid;
/// [`Classifier::from_table`] checks a hand-written one. The fields are public so the table
/// can be written as a literal; more may be added (the emitted file is regenerated with
/// them, and a host test keeps the checked-in one current).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct MachineTable<'a> {
    /// Undamped resonant speeds, ascending ([`Machine::resonant_speeds`]).
    pub resonant: &'a [f64],
    /// Undamped additional speeds, ascending ([`Machine::additional_speeds`]).
    pub additional: &'a [f64],
    /// Damped zones, ascending, covering `[0, ∞)` with alternating kinds: the first starts
    /// at 0, each ends where the next starts, the last is open (`to: None`)
    /// ([`Machine::zones`]).
    pub zones: &'a [Zone],
    /// Sommerfeld capture windows, at most one per platform ([`Machine::capture_windows`]).
    pub captures: &'a [CaptureWindow],
}

/// A machine analysed once at configuration time: characteristic speeds, zones, capture.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Machine {
    config: MachineConfig,
    resonant: [f64; MAX_PLATFORMS],
    n_resonant: u8,
    additional: [f64; MAX_PLATFORMS - 1],
    n_additional: u8,
    zones: [Zone; MAX_ZONES],
    n_zones: u8,
    captures: [CaptureWindow; MAX_PLATFORMS],
    n_captures: u8,
}

impl Machine {
    /// Analyses a validated machine: the undamped characteristic speeds, then the damped
    /// zones from the roots of `Re H_ee`'s numerator (a polynomial in `ω²`) polished on the
    /// pivoted solve, and the capture windows from an f32 scan refined in f64 on the exact
    /// slope of `Ω + D(Ω)` (the `damped` module's notes in the source give the method). Fails
    /// only if the zone search finds more sign changes than a machine of this size can have
    /// (`Capacity("zones")`), which would mean the criterion could not be evaluated reliably.
    ///
    /// Against the reference [`Machine::new_scanned`] (the tests compare the two on the
    /// bundled machines, every test machine and 1 200 random ones): the same characteristic
    /// speeds, zones and windows; boundaries and capture `from` within `1e-9` relative;
    /// `until` within `1e-9` plus what the boundaries' own difference moves it; `at` within
    /// `1e-7` (the scan's golden section stops near `√ε` of a flat maximum). Where they
    /// differ more, the scan has missed a maximum lying between its last node and the zone's
    /// end, which this search finds (72 of the 1 538 windows of the test's random machines).
    ///
    /// Cost on a Cortex-M4F (soft-float f64): under 1 M instructions for the bundled
    /// three-mass machine (`bash examples/qemu/run.sh` prints it as
    /// `bench balancer::Machine::new`), where the scan took tens of millions.
    pub fn new(config: MachineConfig, options: SearchOptions) -> Result<Self, ConfigError> {
        let (sys, mut m) = Self::undamped(config);
        damped::analyse(&sys, &mut m, &options)?;
        Ok(m)
    }

    /// The reference analysis by scanning: the zone search evaluates the pivoted solve at
    /// `nodes_per_interval` log-spaced nodes between consecutive undamped characteristic
    /// speeds and bisects every sign change to `rel_tol`; the capture windows scan the same
    /// number of nodes per gathering zone in f64 and refine the best by golden section.
    ///
    /// This is the algorithm [`Machine::new`] used before, kept so the faster search can be
    /// checked against it (the tests compare the two on the bundled machines, the test
    /// machines and random ones). It is slow on a microcontroller: thousands of solves and
    /// `pow` calls for three platforms, tens of millions of instructions on a Cortex-M4F.
    pub fn new_scanned(config: MachineConfig, options: SearchOptions) -> Result<Self, ConfigError> {
        let (sys, mut m) = Self::undamped(config);
        scanned::find_zones(&sys, &mut m, &options)?;
        scanned::find_captures(&sys, &mut m, &options);
        Ok(m)
    }

    /// The machine with its undamped characteristic speeds, one open gathering zone and no
    /// capture windows.
    fn undamped(config: MachineConfig) -> (modal::System, Self) {
        let sys = modal::System::new(&config);
        let (resonant, n_resonant) = sys.resonant_speeds();
        let (additional, n_additional) = sys.additional_speeds();
        let m = Machine {
            config,
            resonant,
            n_resonant: n_resonant as u8,
            additional,
            n_additional: n_additional as u8,
            zones: [Zone {
                from: 0.0,
                to: None,
                kind: ZoneKind::Gathering,
            }; MAX_ZONES],
            n_zones: 1,
            captures: [CaptureWindow {
                from: 0.0,
                until: 0.0,
                at: 0.0,
            }; MAX_PLATFORMS],
            n_captures: 0,
        };
        (sys, m)
    }

    /// The validated configuration.
    pub fn config(&self) -> &MachineConfig {
        &self.config
    }

    /// Undamped resonant speeds (eigenfrequencies of `(K, M)`), ascending, rad/s.
    pub fn resonant_speeds(&self) -> &[f64] {
        self.resonant
            .get(..usize::from(self.n_resonant))
            .unwrap_or(&[])
    }

    /// Undamped additional speeds (antiresonances of the exciter platform), ascending, rad/s.
    pub fn additional_speeds(&self) -> &[f64] {
        self.additional
            .get(..usize::from(self.n_additional))
            .unwrap_or(&[])
    }

    /// Damped zones, ascending, covering `[0, ∞)`, alternating kinds, starting with
    /// `Gathering` and ending with an open-ended `Balancing` zone.
    pub fn zones(&self) -> &[Zone] {
        self.zones.get(..usize::from(self.n_zones)).unwrap_or(&[])
    }

    /// Capture windows, one per gathering zone that ends at a finite speed.
    pub fn capture_windows(&self) -> &[CaptureWindow] {
        self.captures
            .get(..usize::from(self.n_captures))
            .unwrap_or(&[])
    }

    /// The analysis as plain data: what [`Classifier::from_table`] needs, and what
    /// `drive-sim predict SCENE --emit rust` writes as a `const` for firmware that should not
    /// analyse the machine itself.
    pub fn table(&self) -> MachineTable<'_> {
        MachineTable {
            resonant: self.resonant_speeds(),
            additional: self.additional_speeds(),
            zones: self.zones(),
            captures: self.capture_windows(),
        }
    }

    /// Zone kind at `omega` rad/s (`|omega|` is used; NaN falls in the first zone).
    pub fn zone_kind_at(&self, omega: f64) -> ZoneKind {
        let w = libm::fabs(omega);
        let mut kind = ZoneKind::Gathering;
        for z in self.zones() {
            if w >= z.from {
                kind = z.kind;
            }
        }
        kind
    }

    /// Driving-point receptance of the exciter platform `H(ω)` in m/N as `(re, im)`.
    pub fn receptance(&self, omega: f64) -> (f64, f64) {
        let h = modal::System::new(&self.config).receptance(omega);
        (h.re, h.im)
    }

    /// Lag `D(Ω) = ω − Ω` of gathered loads turning steadily at `Ω` rad/s behind a rotor
    /// at `ω`, rad/s:
    ///
    /// `D(Ω) = N·m²·Ω⁴·(−Im H(Ω)) / (2·b_w)`.
    ///
    /// Derivation. A load at angle `φ` on the circle of radius `R` about the exciter axis,
    /// on a platform moving by `Y(t)` along its guide, sits at `(R·cos φ, Y + R·sin φ)`.
    /// Lagrange's equation for `φ` (gravity neglected) is
    /// `κ·m·R²·φ̈ + b_w·R²·(φ̇ − ω) + m·R·Ÿ·cos φ = 0`
    /// (the seed's eq. 4 with `ÿ`, in SI units; `κ` is the ball/roller/pendulum factor:
    /// the translational coupling term carries the load mass `m` only, for all three kinds).
    /// With all `N` loads gathered and turning at `Ω` (`φ = Ωt`) the platform is driven by
    /// `S·Ω²·sin Ωt`, `S = N·m·R`, and moves by
    /// `Y = S·Ω²·(Re H·sin Ωt + Im H·cos Ωt)`, so `Ÿ = −Ω²·Y` and the mean over a turn is
    /// `⟨Ÿ·cos Ωt⟩ = −½·S·Ω⁴·Im H`. The mean of `φ̈` vanishes in steady state, so
    /// `b_w·R²·(ω − Ω) = m·R·⟨Ÿ·cos Ωt⟩ = −½·m·R·S·Ω⁴·Im H`, i.e.
    /// `ω − Ω = −N·m²·Ω⁴·Im H(Ω)/(2·b_w)` (`R` cancels; units
    /// `kg²·s⁻⁴·(m/N)/(N·s/m) = s⁻¹`). `κ` drops out of the mean balance: the result is the
    /// same for balls, rollers and pendulums (`κ` matters for the transient only). For a
    /// passive machine `−Im H ≥ 0`, so the loads lag, and `N·b_w·R²·(ω − Ω)·Ω` equals the
    /// power the platform motion dissipates in the dampers (a test checks this). In the
    /// seed's variables `n − q = −q⁴·Im H̃(q)/(2β)`.
    ///
    /// A captured state at `Ω` needs `Ω` in a gathering zone (the gathered unbalance stays
    /// gathered, seed eq. 3 at the loads' speed) and `1 + D'(Ω) > 0` (the drag torque, which
    /// falls as `Ω` rises, crosses the resisting torque from above: a stable balance).
    pub fn capture_lag(&self, load_speed: f64) -> f64 {
        damped::capture_lag(&modal::System::new(&self.config), &self.config, load_speed)
    }

    /// Predicted speed `Ω` of gathered loads captured near a resonance when the rotor turns
    /// at `omega` rad/s: the lowest `Ω` inside a gathering zone with `Ω + D(Ω) = omega`
    /// reached from below (the branch a slow run-up follows). `None` if capture is impossible.
    pub fn capture_speed(&self, omega: f64) -> Option<f64> {
        damped::capture_speed(&modal::System::new(&self.config), self, omega)
    }
}
