//! Vibration machine with a ball, roller or pendulum auto-balancer (seed 001), in physical units.
//!
//! # Model
//!
//! `P` (1 to 3) platforms move in translation along one fixed direction `Y` (the seed's
//! platforms "can only move rectilinearly progressively owing to fixed guides"), each held to
//! the ground by a spring `k_i` (N/m) and a dashpot `b_i` (N·s/m), and joined pairwise by
//! couplings `k_ij`, `b_ij`. `Y_i` is measured from static equilibrium; gravity is neglected,
//! as in the seed. The auto-balancer housing (mass `M_c`, rotor included, centre on the shaft
//! axis K) sits on the exciter platform `e` (platform 1 of a single-mass machine, platform 2
//! otherwise, as in the seed; configurable). It carries `N` (0 to [`MAX_LOADS`]) identical loads
//! of mass `m` whose centres run on a circle of radius `R` about K. `φ_j` is the absolute angle
//! of load `j`, measured from the axis `X` perpendicular to the motion, so the load centre is at
//! `(R·cos φ_j, Y_e + R·sin φ_j)`. The rotor (shaft angle `φ`, speed `ω`, supplied by the
//! [`Shaft`]) carries a static unbalance `D` (kg·m) at angle `φ + θ`.
//!
//! Kinetic energy (`M_eΣ = M_e + M_c + N·m`, the seed's eq. 7/21), potential energy and
//! Rayleigh function:
//!
//! ```text
//! T = ½ Σ_{i≠e} M_i·Ẏ_i² + ½ M_eΣ·Ẏ_e² + Σ_j [ m·R·Ẏ_e·cos φ_j·φ̇_j + ½ κ·m·R²·φ̇_j² ]
//!     + D·Ẏ_e·ω·cos(φ + θ)                                      (+ terms in ω only)
//! V = ½ Σ_i k_i·Y_i² + ½ Σ_{i<l} k_il·(Y_i − Y_l)²
//! F = ½ Σ_i b_i·Ẏ_i² + ½ Σ_{i<l} b_il·(Ẏ_i − Ẏ_l)² + ½ Σ_j b_w·R²·(φ̇_j − ω)²
//! ```
//!
//! `κ` (eq. 9) is 7/5 for a ball, 3/2 for a roller and `1 + J_c/(m·R²)` for a pendulum: the
//! load's own rotation adds `(κ − 1)·m·R²` to its inertia about K. The viscous force on a load
//! moving relative to the housing has modulus `b_w·R·|φ̇_j − ω|` (seed, §5.1.1), so `b_w` is in
//! N·s/m and the drag torque of one load is `b_w·R²·(φ̇_j − ω)`. Lagrange's equations give, with
//! `F_i = −k_i·Y_i − b_i·Ẏ_i − Σ_l [k_il·(Y_i − Y_l) + b_il·(Ẏ_i − Ẏ_l)]`:
//!
//! ```text
//! platform i ≠ e:  M_i·Ÿ_i = F_i
//! platform e:      M_eΣ·Ÿ_e + m·R·Σ_j (cos φ_j·φ̈_j − sin φ_j·φ̇_j²) − D·ω²·sin(φ + θ) = F_e
//! load j:          κ·m·R²·φ̈_j + b_w·R²·(φ̇_j − ω) + m·R·Ÿ_e·cos φ_j = 0
//! shaft torque:    τ = Σ_j b_w·R²·(φ̇_j − ω) − D·Ÿ_e·cos(φ + θ)
//! ```
//!
//! The torque `τ` is what the machine applies to the shaft: the drag of the loads (it drives
//! the shaft when the loads run ahead) and the moment of the unbalance's inertial force in the
//! accelerating platform frame. The loads' and the exciter platform's accelerations are coupled
//! through the mass matrix; the load equations give `φ̈_j` in terms of `Ÿ_e`, which substituted
//! in the platform equation gives `Ÿ_e` explicitly (no linear solve, no allocation):
//!
//! ```text
//! [M_e + M_c + (m/κ)·Σ_j (κ − cos² φ_j)]·Ÿ_e
//!     = F_e + (b_w·R/κ)·Σ_j cos φ_j·(φ̇_j − ω) + m·R·Σ_j sin φ_j·φ̇_j² + D·ω²·sin(φ + θ)
//! φ̈_j = −(b_w/(κ·m))·(φ̇_j − ω) − Ÿ_e·cos φ_j/(κ·R)
//! ```
//!
//! The bracket is at least `M_e + M_c > 0`, so the elimination is always well posed.
//!
//! Terms proportional to the shaft's angular acceleration `ω̇` are not modelled: the
//! [`Shaft`] does not carry `ω̇`, and the seed assumes `ω` constant. They are the tangential
//! unbalance force `D·ω̇·cos(φ + θ)` in the platform equation and, for rolling loads, the
//! rolling constraint's coupling `(κ − 1)·(1 + r/R)·m·R²·ω̇` (`r` the ball or roller radius) in
//! the load equation with its reaction on the shaft. All vanish at constant speed, which is
//! where the regime questions are asked; the inertia of housing, rotor and the loads'
//! co-rotation belongs in the shaft's reduced inertia `J`.
//!
//! # Dimensionless form (seed 001, eq. 4, 17, 39, misprints corrected)
//!
//! With a speed scale `ω̃` (eq. 8: `ω̃ = √(k/M_Σ)` for a single mass), `τ = ω̃·t`,
//! `Ỹ = N·m·R/M_eΣ`, `ρ_i = M_eΣ/M_i` (`ρ_e = 1`), `y_i = Y_i/(ρ_i·Ỹ)`,
//! `s_y = (1/N)·Σ sin φ_j`, and
//!
//! ```text
//! h_i = b_i/(2·M_i·ω̃)   n_i² = k_i/(M_i·ω̃²)   (M_e read as M_eΣ)
//! h_il = b_il/(2·M_eΣ·ω̃)   n_il² = k_il/(M_eΣ·ω̃²)   n = ω/ω̃
//! ε = N·m/(κ·M_eΣ)   β = b_w·M_eΣ/(N·m²·ω̃)
//! ```
//!
//! the equations above (with `D = 0`, as in the seed) become
//!
//! ```text
//! y_i'' + 2h_i·y_i' + n_i²·y_i + Σ_l [2h_il·(ρ_i·y_i' − ρ_l·y_l') + n_il²·(ρ_i·y_i − ρ_l·y_l)]
//!       + δ_ie·s_y'' = 0
//! φ_j'' + ε·β·(φ_j' − n) + ε·y_e''·cos φ_j = 0
//! ```
//!
//! which is eq. 4 for one platform (with `ÿ`, not the printed `ẏ`, in the load equation), eq. 17
//! for two and eq. 39 for three (whose third equation ends in `n23²·(y2 − ρ3·y3)`, not the
//! printed `(y2 − ρ1·y1)`). [`VibrationMachine::dimensionless`] computes these groups;
//! `tests/vibration.rs` evaluates eq. 4, 17 and 39 as printed (corrected) and compares them
//! with this module's right-hand side state by state.
//!
//! # State vector
//!
//! `[Y_0 … Y_{P−1}, Ẏ_0 … Ẏ_{P−1}, φ_1 … φ_N, φ̇_1 … φ̇_N]` (m, m/s, rad, rad/s), angles
//! unwrapped.
//!
//! # Regimes
//!
//! [`regime`] holds the observable (the residual unbalance `D·e^{i(φ+θ)} + m·R·Σ e^{iφ_j}`,
//! kg·m), the analytic auto-balancing positions and the classification of a completed run.

pub mod floquet;
pub mod regime;

use crate::engine::model::{Effect, Shaft};
use drive_monitor::error::{finite, non_negative, positive, ConfigError};
use serde::Deserialize;

pub use regime::{
    balancing_angles_two, balancing_fan, classify, Regime, RegimeCriteria, RegimeReport,
    RegimeSample,
};

/// Most platforms a machine may have (the seed treats one, two and three).
pub const MAX_PLATFORMS: usize = 3;
/// Most loads an auto-balancer may carry.
pub const MAX_LOADS: usize = 8;
/// Length of the largest state vector.
pub const MAX_DIM: usize = 2 * MAX_PLATFORMS + 2 * MAX_LOADS;

/// One platform: its own mass and its support to the ground.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PlatformParams {
    /// Platform mass without the auto-balancer, kg (`M_i`).
    pub mass: f64,
    /// Stiffness of the support to the ground, N/m (`k_i`; the engine takes 0, but scenes and
    /// the core's analysis need at least 1e-6: the seed's dimensionless variables are scaled by
    /// the exciter platform's, and a platform hung only on its couplings takes 1e-6).
    pub stiffness: f64,
    /// Viscous damping of the support to the ground, N·s/m (`b_i`).
    #[serde(default)]
    pub damping: f64,
}

/// An elastic-viscous coupling between two platforms.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CouplingParams {
    /// Indices (0-based) of the two platforms joined.
    pub between: [usize; 2],
    /// Coupling stiffness, N/m (`k_il`).
    pub stiffness: f64,
    /// Coupling viscous damping, N·s/m (`b_il`).
    #[serde(default)]
    pub damping: f64,
}

/// Type of the auto-balancer's loads, which fixes `κ` (seed 001, eq. 9).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(tag = "type", rename_all = "snake_case", deny_unknown_fields)]
pub enum LoadKind {
    /// Balls rolling in a race: `κ = 7/5`.
    Ball,
    /// Rollers rolling in a race: `κ = 3/2`.
    Roller,
    /// Pendulums on the shaft: `κ = 1 + J_c/(m·R²)`.
    Pendulum {
        /// Moment of inertia of one pendulum about its own centre of mass, kg·m² (`J_c`).
        centroidal_inertia: f64,
    },
}

impl LoadKind {
    /// `κ` for loads of mass `m` (kg) on radius `r` (m).
    pub fn kappa(&self, m: f64, r: f64) -> f64 {
        match *self {
            LoadKind::Ball => 7.0 / 5.0,
            LoadKind::Roller => 3.0 / 2.0,
            LoadKind::Pendulum { centroidal_inertia } => 1.0 + centroidal_inertia / (m * r * r),
        }
    }
}

/// The auto-balancer (vibration exciter) and the rotor unbalance it carries.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AutoBalancerParams {
    /// Index of the platform carrying it; default 0 for one platform, 1 otherwise (seed).
    #[serde(default)]
    pub platform: Option<usize>,
    /// Number of loads `N` (0 gives a plain unbalanced rotor on the platforms).
    pub loads: usize,
    /// Mass of one load, kg (`m`).
    pub load_mass: f64,
    /// Radius of the circle the load centres run on, m (`R`).
    pub radius: f64,
    /// Type of the loads.
    pub kind: LoadKind,
    /// Mass of the housing with the rotor, kg (`M_c`).
    pub housing_mass: f64,
    /// Viscous resistance to the loads' motion relative to the housing, N·s/m (`b_w`); the
    /// drag torque of one load is `b_w·R²·(φ̇_j − ω)`.
    pub load_viscosity: f64,
    /// Rotor static unbalance, kg·m (`D`, mass times eccentricity).
    #[serde(default)]
    pub rotor_unbalance: f64,
    /// Angle of the rotor unbalance relative to the shaft angle, rad (`θ`).
    #[serde(default)]
    pub rotor_unbalance_angle: f64,
}

/// How the loads are placed at `t = 0`.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(tag = "placement", rename_all = "snake_case", deny_unknown_fields)]
pub enum LoadPlacement {
    /// The loads gathered together: equally spaced over an arc of `spread` rad centred on
    /// the absolute angle `angle`. With `spread = 0` the loads coincide, and since identical
    /// loads obey identical equations they then stay together for ever (an invariant but
    /// possibly unstable motion); a small spread lets them part when they tend to.
    Together {
        /// Centre of the group, rad.
        angle: f64,
        /// Arc the loads span, rad (default 0).
        #[serde(default)]
        spread: f64,
    },
    /// The auto-balancing position ([`balancing_fan`]) for the initial rotor angle, with load 1
    /// turned forward by `perturbation` rad. Needs `N ≠ 1` (nothing to place for `N = 0`). When
    /// the loads cannot balance the rotor (`D > N·m·R`) they start at their limit instead:
    /// all together opposite the unbalance, the residual `D − N·m·R`.
    Balanced {
        /// Forward offset of load 1 from the balancing position, rad.
        perturbation: f64,
    },
    /// Explicit absolute angles, rad, one per load.
    Angles {
        /// The angles, rad.
        angles: Vec<f64>,
    },
}

/// Initial conditions. Platforms always start at rest in static equilibrium.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct InitialParams {
    /// Where the loads start.
    pub loads: LoadPlacement,
    /// Initial angular speed of every load, rad/s (0: at rest; the rotor speed: turning with
    /// the rotor).
    #[serde(default)]
    pub load_speed: f64,
    /// The shaft angle at `t = 0`, rad (used by [`LoadPlacement::Balanced`]).
    #[serde(default)]
    pub rotor_angle: f64,
}

impl Default for InitialParams {
    fn default() -> Self {
        InitialParams {
            loads: LoadPlacement::Balanced { perturbation: 0.0 },
            load_speed: 0.0,
            rotor_angle: 0.0,
        }
    }
}

/// Everything that defines a vibration machine, as read from a scene file.
#[derive(Debug, Clone, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VibrationMachineParams {
    /// The platforms (1 to [`MAX_PLATFORMS`]).
    pub platforms: Vec<PlatformParams>,
    /// Couplings between platform pairs.
    #[serde(default)]
    pub couplings: Vec<CouplingParams>,
    /// The auto-balancer on the exciter platform.
    pub balancer: AutoBalancerParams,
    /// Initial conditions.
    #[serde(default)]
    pub initial: InitialParams,
}

/// A single-mass machine given by the seed's dimensionless groups (eq. 5–9) plus the physical
/// scales they leave free. See [`VibrationMachineParams::from_seed_single_mass`].
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SeedSingleMass {
    /// Support damping ratio `h = b/(2·M_Σ·ω̃)`.
    pub h: f64,
    /// Load mass ratio `ε = N·m/(κ·M_Σ)`.
    pub epsilon: f64,
    /// Load viscosity `β = b_w·M_Σ/(N·m²·ω̃)`.
    pub beta: f64,
    /// Number of loads `N`.
    pub loads: usize,
    /// Type of the loads (fixes `κ`).
    pub kind: LoadKind,
    /// Natural frequency `ω̃ = √(k/M_Σ)`, rad/s.
    pub omega_scale: f64,
    /// Mass of one load `m`, kg.
    pub load_mass: f64,
    /// Load radius `R`, m.
    pub radius: f64,
    /// Housing mass `M_c`, kg.
    pub housing_mass: f64,
    /// Rotor unbalance `D`, kg·m (the seed has none: 0).
    #[serde(default)]
    pub rotor_unbalance: f64,
}

impl VibrationMachineParams {
    /// The physical machine with the seed's groups: `M_Σ = N·m/(κ·ε)`, platform mass
    /// `M = M_Σ − M_c − N·m`, `k = M_Σ·ω̃²`, `b = 2h·M_Σ·ω̃`, `b_w = β·N·m²·ω̃/M_Σ`.
    /// Errors when an input is not positive/finite or the resulting platform mass is negative
    /// (`ε` too large for the housing mass).
    pub fn from_seed_single_mass(
        g: &SeedSingleMass,
        initial: InitialParams,
    ) -> Result<Self, ConfigError> {
        let m = positive("load_mass", g.load_mass)?;
        let r = positive("radius", g.radius)?;
        let w = positive("omega_scale", g.omega_scale)?;
        let eps = positive("epsilon", g.epsilon)?;
        let h = non_negative("h", g.h)?;
        let beta = non_negative("beta", g.beta)?;
        let housing = non_negative("housing_mass", g.housing_mass)?;
        if g.loads == 0 {
            return Err(ConfigError::NotPositive("loads"));
        }
        let nm = g.loads as f64 * m;
        let total = nm / (g.kind.kappa(m, r) * eps);
        let platform = total - housing - nm;
        if platform < 0.0 {
            return Err(ConfigError::Inconsistent("epsilon"));
        }
        Ok(VibrationMachineParams {
            platforms: vec![PlatformParams {
                mass: platform,
                stiffness: total * w * w,
                damping: 2.0 * h * total * w,
            }],
            couplings: Vec::new(),
            balancer: AutoBalancerParams {
                platform: None,
                loads: g.loads,
                load_mass: m,
                radius: r,
                kind: g.kind,
                housing_mass: housing,
                load_viscosity: beta * nm * m * w / total,
                rotor_unbalance: g.rotor_unbalance,
                rotor_unbalance_angle: 0.0,
            },
            initial,
        })
    }
}

/// The seed's dimensionless groups for a machine (see the module docs for the definitions).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Dimensionless {
    /// Speed scale `ω̃`, rad/s.
    pub omega_scale: f64,
    /// Displacement scale `Ỹ = N·m·R/M_eΣ`, m.
    pub y_scale: f64,
    /// `ε = N·m/(κ·M_eΣ)`.
    pub epsilon: f64,
    /// `β = b_w·M_eΣ/(N·m²·ω̃)`.
    pub beta: f64,
    /// `κ`.
    pub kappa: f64,
    /// `ρ_i = M_eΣ/M_i` (1 for the exciter platform).
    pub rho: [f64; MAX_PLATFORMS],
    /// `n_i² = k_i/(M_i·ω̃²)` (with `M_eΣ` for the exciter platform).
    pub n2: [f64; MAX_PLATFORMS],
    /// `h_i = b_i/(2·M_i·ω̃)` (with `M_eΣ` for the exciter platform).
    pub h: [f64; MAX_PLATFORMS],
    /// `n_il² = k_il/(M_eΣ·ω̃²)`, symmetric, zero diagonal.
    pub n2_coupling: [[f64; MAX_PLATFORMS]; MAX_PLATFORMS],
    /// `h_il = b_il/(2·M_eΣ·ω̃)`, symmetric, zero diagonal.
    pub h_coupling: [[f64; MAX_PLATFORMS]; MAX_PLATFORMS],
}

/// A validated vibration machine; implements [`Effect`].
#[derive(Debug, Clone, PartialEq)]
pub struct VibrationMachine {
    platforms: usize,
    exciter: usize,
    /// `M_i`, with `M_eΣ` at the exciter.
    mass: [f64; MAX_PLATFORMS],
    /// `M_e + M_c`: the exciter's mass without the loads.
    exciter_base_mass: f64,
    stiffness: [f64; MAX_PLATFORMS],
    damping: [f64; MAX_PLATFORMS],
    coupling_stiffness: [[f64; MAX_PLATFORMS]; MAX_PLATFORMS],
    coupling_damping: [[f64; MAX_PLATFORMS]; MAX_PLATFORMS],
    loads: usize,
    load_mass: f64,
    radius: f64,
    kappa: f64,
    load_viscosity: f64,
    rotor_unbalance: f64,
    rotor_unbalance_angle: f64,
    initial: [f64; MAX_DIM],
}

impl VibrationMachine {
    /// Validates `p` and builds the machine.
    ///
    /// Errors name the offending key: counts beyond [`MAX_PLATFORMS`]/[`MAX_LOADS`]
    /// (`Capacity`), non-finite, negative or zero masses, radius and `J_c`, couplings of a
    /// platform to itself or to a missing one, or explicit angles whose count is not `N`. A
    /// rotor unbalance larger than the loads can balance is not an error: it is a design
    /// result ([`VibrationMachine::residual_floor`]).
    pub fn new(p: &VibrationMachineParams) -> Result<Self, ConfigError> {
        let np = p.platforms.len();
        if np == 0 {
            return Err(ConfigError::OutOfRange("platforms"));
        }
        if np > MAX_PLATFORMS {
            return Err(ConfigError::Capacity("platforms"));
        }
        let b = &p.balancer;
        let exciter = b.platform.unwrap_or(if np == 1 { 0 } else { 1 });
        if exciter >= np {
            return Err(ConfigError::OutOfRange("balancer.platform"));
        }
        if b.loads > MAX_LOADS {
            return Err(ConfigError::Capacity("balancer.loads"));
        }
        let mut mass = [0.0; MAX_PLATFORMS];
        let mut stiffness = [0.0; MAX_PLATFORMS];
        let mut damping = [0.0; MAX_PLATFORMS];
        for (i, pl) in p.platforms.iter().enumerate() {
            mass[i] = non_negative("platforms.mass", pl.mass)?;
            stiffness[i] = non_negative("platforms.stiffness", pl.stiffness)?;
            damping[i] = non_negative("platforms.damping", pl.damping)?;
            if i != exciter && mass[i] == 0.0 {
                return Err(ConfigError::NotPositive("platforms.mass"));
            }
        }
        let load_mass = positive("balancer.load_mass", b.load_mass)?;
        let radius = positive("balancer.radius", b.radius)?;
        let housing = non_negative("balancer.housing_mass", b.housing_mass)?;
        let load_viscosity = non_negative("balancer.load_viscosity", b.load_viscosity)?;
        let rotor_unbalance = non_negative("balancer.rotor_unbalance", b.rotor_unbalance)?;
        let rotor_unbalance_angle =
            finite("balancer.rotor_unbalance_angle", b.rotor_unbalance_angle)?;
        if let LoadKind::Pendulum { centroidal_inertia } = b.kind {
            non_negative("balancer.kind.centroidal_inertia", centroidal_inertia)?;
        }
        let kappa = b.kind.kappa(load_mass, radius);
        let exciter_base_mass = positive("platforms.mass", mass[exciter] + housing)?;
        mass[exciter] = exciter_base_mass + b.loads as f64 * load_mass;

        let mut coupling_stiffness = [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS];
        let mut coupling_damping = [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS];
        for c in &p.couplings {
            let [i, l] = c.between;
            if i >= np || l >= np || i == l {
                return Err(ConfigError::OutOfRange("couplings.between"));
            }
            let k = non_negative("couplings.stiffness", c.stiffness)?;
            let d = non_negative("couplings.damping", c.damping)?;
            coupling_stiffness[i][l] += k;
            coupling_stiffness[l][i] += k;
            coupling_damping[i][l] += d;
            coupling_damping[l][i] += d;
        }

        let mut m = VibrationMachine {
            platforms: np,
            exciter,
            mass,
            exciter_base_mass,
            stiffness,
            damping,
            coupling_stiffness,
            coupling_damping,
            loads: b.loads,
            load_mass,
            radius,
            kappa,
            load_viscosity,
            rotor_unbalance,
            rotor_unbalance_angle,
            initial: [0.0; MAX_DIM],
        };
        m.initial = m.initial_state(&p.initial)?;
        Ok(m)
    }

    fn initial_state(&self, ini: &InitialParams) -> Result<[f64; MAX_DIM], ConfigError> {
        let mut y = [0.0; MAX_DIM];
        let n = self.loads;
        let off = 2 * self.platforms;
        let speed = finite("initial.load_speed", ini.load_speed)?;
        let rotor = finite("initial.rotor_angle", ini.rotor_angle)?;
        let angles = &mut y[off..off + n];
        match &ini.loads {
            LoadPlacement::Together { angle, spread } => {
                let a = finite("initial.loads.angle", *angle)?;
                let s = finite("initial.loads.spread", *spread)?;
                let centre = (n as f64 - 1.0) / 2.0;
                let step = if n > 1 { s / (n as f64 - 1.0) } else { 0.0 };
                for (k, x) in angles.iter_mut().enumerate() {
                    *x = a + (k as f64 - centre) * step;
                }
            }
            LoadPlacement::Balanced { perturbation } => {
                let dp = finite("initial.loads.perturbation", *perturbation)?;
                if n == 1 {
                    return Err(ConfigError::Inconsistent("initial.loads"));
                }
                if n > 1 {
                    let towards = rotor + self.rotor_unbalance_angle;
                    // A balancer too small for the rotor starts at its limit: every load
                    // opposite the unbalance ([`VibrationMachine::residual_floor`]).
                    let fan =
                        balancing_fan(n, self.load_unbalance(), self.rotor_unbalance, towards)
                            .unwrap_or([towards + core::f64::consts::PI; MAX_LOADS]);
                    angles.copy_from_slice(&fan[..n]);
                    angles[0] += dp;
                }
            }
            LoadPlacement::Angles { angles: a } => {
                if a.len() != n {
                    return Err(ConfigError::Inconsistent("initial.loads.angles"));
                }
                for (x, v) in angles.iter_mut().zip(a) {
                    *x = finite("initial.loads.angles", *v)?;
                }
            }
        }
        y[off + n..off + 2 * n].iter_mut().for_each(|x| *x = speed);
        Ok(y)
    }

    /// Number of platforms `P`.
    pub fn platforms(&self) -> usize {
        self.platforms
    }
    /// Index of the platform carrying the auto-balancer.
    pub fn exciter(&self) -> usize {
        self.exciter
    }
    /// Number of loads `N`.
    pub fn loads(&self) -> usize {
        self.loads
    }
    /// `κ` of the loads.
    pub fn kappa(&self) -> f64 {
        self.kappa
    }
    /// Unbalance one load creates, `m·R`, kg·m.
    pub fn load_unbalance(&self) -> f64 {
        self.load_mass * self.radius
    }
    /// Rotor static unbalance `D`, kg·m.
    pub fn rotor_unbalance(&self) -> f64 {
        self.rotor_unbalance
    }
    /// Total mass of the exciter platform with housing and loads, `M_eΣ`, kg.
    pub fn exciter_total_mass(&self) -> f64 {
        self.mass[self.exciter]
    }
    /// Offset of the load angles in the state vector (`2·P`).
    pub fn load_offset(&self) -> usize {
        2 * self.platforms
    }

    /// `√(k_e/M_eΣ)`, rad/s: the single-mass natural frequency and the seed's speed scale
    /// `ω̃` (eq. 8) for one platform.
    pub fn natural_scale(&self) -> f64 {
        (self.stiffness[self.exciter] / self.mass[self.exciter]).sqrt()
    }

    /// The seed's dimensionless groups for the speed scale `omega_scale` (rad/s).
    pub fn dimensionless(&self, omega_scale: f64) -> Dimensionless {
        let w = omega_scale;
        let me = self.mass[self.exciter];
        let nm = self.loads as f64 * self.load_mass;
        let mut d = Dimensionless {
            omega_scale: w,
            y_scale: nm * self.radius / me,
            epsilon: nm / (self.kappa * me),
            beta: self.load_viscosity * me / (nm * self.load_mass * w),
            kappa: self.kappa,
            rho: [0.0; MAX_PLATFORMS],
            n2: [0.0; MAX_PLATFORMS],
            h: [0.0; MAX_PLATFORMS],
            n2_coupling: [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS],
            h_coupling: [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS],
        };
        for i in 0..self.platforms {
            d.rho[i] = me / self.mass[i];
            d.n2[i] = self.stiffness[i] / (self.mass[i] * w * w);
            d.h[i] = self.damping[i] / (2.0 * self.mass[i] * w);
            for l in 0..self.platforms {
                d.n2_coupling[i][l] = self.coupling_stiffness[i][l] / (me * w * w);
                d.h_coupling[i][l] = self.coupling_damping[i][l] / (2.0 * me * w);
            }
        }
        d
    }

    /// Residual unbalance `D·e^{i(φ+θ)} + m·R·Σ_j e^{iφ_j}` (kg·m, components along X and Y) for
    /// the shaft angle `rotor_angle` and the effect's state `y`. NaN if `y` is too short.
    pub fn residual_unbalance(&self, rotor_angle: f64, y: &[f64]) -> [f64; 2] {
        let off = self.load_offset();
        let Some(angles) = y.get(off..off + self.loads) else {
            return [f64::NAN; 2];
        };
        let (s, c) = (rotor_angle + self.rotor_unbalance_angle).sin_cos();
        let mr = self.load_unbalance();
        let mut u = [self.rotor_unbalance * c, self.rotor_unbalance * s];
        for a in angles {
            let (s, c) = a.sin_cos();
            u[0] += mr * c;
            u[1] += mr * s;
        }
        u
    }

    /// The regime observables at one instant (feed a run's samples to [`classify`]).
    pub fn sample(&self, t: f64, shaft: Shaft, y: &[f64]) -> RegimeSample {
        let off = self.load_offset();
        let n = self.loads;
        let u = self.residual_unbalance(shaft.phi, y);
        let (mut cx, mut sy, mut mean) = (0.0, 0.0, 0.0);
        if let Some(angles) = y.get(off..off + n) {
            for a in angles {
                let (s, c) = a.sin_cos();
                cx += c;
                sy += s;
                mean += a;
            }
        }
        let nf = n.max(1) as f64;
        RegimeSample {
            t,
            residual: u[0].hypot(u[1]),
            coherence: cx.hypot(sy) / nf,
            mean_load_angle: mean / nf,
            rotor_angle: shaft.phi,
        }
    }

    /// `N·m·R`: the largest unbalance the loads can balance, kg·m.
    pub fn capacity(&self) -> f64 {
        self.loads as f64 * self.load_unbalance()
    }

    /// The least residual unbalance the loads can leave, `max(0, D − N·m·R)` kg·m: zero when
    /// they can balance the rotor, else what remains with every load opposite the unbalance.
    pub fn residual_floor(&self) -> f64 {
        (self.rotor_unbalance - self.capacity()).max(0.0)
    }

    /// The thresholds a run of this machine is judged by: [`RegimeCriteria::new`] with
    /// [`VibrationMachine::reference_unbalance`] and [`VibrationMachine::residual_floor`].
    pub fn regime_criteria(&self) -> RegimeCriteria {
        RegimeCriteria {
            floor: self.residual_floor(),
            ..RegimeCriteria::new(self.reference_unbalance())
        }
    }

    /// The residual unbalance a run is judged against: `D`, or `N·m·R` when the rotor has no
    /// unbalance (the seed's case, where the loads alone form the exciter), kg·m.
    pub fn reference_unbalance(&self) -> f64 {
        if self.rotor_unbalance > 0.0 {
            self.rotor_unbalance
        } else {
            self.loads as f64 * self.load_unbalance()
        }
    }
}

impl Effect for VibrationMachine {
    fn name(&self) -> &'static str {
        "vibration_machine"
    }

    fn dim(&self) -> usize {
        2 * self.platforms + 2 * self.loads
    }

    fn init(&self, y: &mut [f64]) {
        for (d, s) in y.iter_mut().zip(&self.initial) {
            *d = *s;
        }
    }

    fn eval(&self, _t: f64, shaft: Shaft, y: &[f64], dy: &mut [f64]) -> f64 {
        let np = self.platforms;
        let n = self.loads;
        let dim = self.dim();
        if y.len() < dim || dy.len() < dim {
            dy.iter_mut().for_each(|x| *x = f64::NAN);
            return f64::NAN;
        }
        let (pos, rest) = y.split_at(np);
        let (vel, rest) = rest.split_at(np);
        let (phi, rest) = rest.split_at(n);
        let dphi = &rest[..n];
        let w = shaft.omega;

        // Support and coupling forces F_i.
        let mut force = [0.0; MAX_PLATFORMS];
        for i in 0..np {
            let mut f = -self.stiffness[i] * pos[i] - self.damping[i] * vel[i];
            for l in 0..np {
                f -= self.coupling_stiffness[i][l] * (pos[i] - pos[l])
                    + self.coupling_damping[i][l] * (vel[i] - vel[l]);
            }
            force[i] = f;
        }

        // Exciter acceleration with the loads' accelerations eliminated.
        let (m, r, k, bw) = (self.load_mass, self.radius, self.kappa, self.load_viscosity);
        let (su, cu) = (shaft.phi + self.rotor_unbalance_angle).sin_cos();
        let mut cos_phi = [0.0; MAX_LOADS];
        let mut rhs = force[self.exciter] + self.rotor_unbalance * w * w * su;
        let mut spread = 0.0;
        for j in 0..n {
            let (s, c) = phi[j].sin_cos();
            cos_phi[j] = c;
            let slip = dphi[j] - w;
            rhs += bw * r / k * c * slip + m * r * s * dphi[j] * dphi[j];
            // κ − cos² written as (κ − 1) + sin²: no cancellation when κ → 1 and cos² → 1.
            spread += (k - 1.0) + s * s;
        }
        let a = rhs / (self.exciter_base_mass + m / k * spread);

        for i in 0..np {
            dy[i] = vel[i];
            dy[np + i] = if i == self.exciter {
                a
            } else {
                force[i] / self.mass[i]
            };
        }
        let mut torque = -self.rotor_unbalance * a * cu;
        for j in 0..n {
            let slip = dphi[j] - w;
            dy[2 * np + j] = dphi[j];
            dy[2 * np + n + j] = -bw / (k * m) * slip - a * cos_phi[j] / (k * r);
            torque += bw * r * r * slip;
        }
        torque
    }
}
