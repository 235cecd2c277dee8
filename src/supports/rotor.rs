//! The rotor model: mass, centre of mass, two support planes, unbalances and an optional
//! distributed process load; the unbalance algebra of seed 002 (eq. 2–7, 30–39, Table 1).

use super::vector::{moment, resultant, split, Vec2};
use super::MIN_PLANE_SEPARATION;
use crate::error::{finite, non_negative, positive, ConfigError};

/// Standard gravity, m/s² (the default static body load of a horizontal rotor).
pub const STANDARD_GRAVITY: f64 = 9.80665;

/// Direction of gravity in the default installation: 270° (−y), radians.
pub const GRAVITY_ANGLE: f64 = 1.5 * core::f64::consts::PI;

/// One unbalance: `amount = m·r` (kg·m) at `angle` (radians, fixed to the rotor) in the
/// plane at axial position `z` (m).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Unbalance {
    /// Axial position, m (any finite value; the rotor may overhang either support).
    pub z: f64,
    /// Amount `m·r`, kg·m (finite, not negative).
    pub amount: f64,
    /// Angle, radians (any finite value).
    pub angle: f64,
}

impl Unbalance {
    /// An unbalance of `amount` kg·m at `angle` radians in the plane at `z` m.
    pub const fn new(z: f64, amount: f64, angle: f64) -> Self {
        Unbalance { z, amount, angle }
    }

    /// The unbalance as a vector, kg·m.
    pub fn vector(&self) -> Vec2 {
        Vec2::from_polar(self.amount, self.angle)
    }
}

/// A uniform distributed process load (snow, soil) of `per_length` N/m over the axial
/// interval `[from, to]`, acting in the fixed direction `angle` (radians).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct ProcessLoad {
    /// Load per unit length, N/m (finite, not negative).
    pub per_length: f64,
    /// Start of the loaded interval, m.
    pub from: f64,
    /// End of the loaded interval, m (`to > from`).
    pub to: f64,
    /// Direction of the load, radians (270° = −y is "down").
    pub angle: f64,
}

impl ProcessLoad {
    /// The resultant force `q·(to − from)` in the load direction, N.
    pub fn resultant(&self) -> Vec2 {
        Vec2::from_polar(self.per_length * (self.to - self.from), self.angle)
    }

    /// Where the resultant acts: the middle of the interval (a uniform load), m.
    pub fn centre(&self) -> f64 {
        self.from + 0.5 * (self.to - self.from)
    }

    fn validate(self) -> Result<Self, ConfigError> {
        non_negative("process_load.per_length", self.per_length)?;
        finite("process_load.from", self.from)?;
        finite("process_load.to", self.to)?;
        finite("process_load.angle", self.angle)?;
        let length = self.to - self.from;
        if length <= 0.0 {
            return Err(ConfigError::Inconsistent("process_load.to"));
        }
        if !length.is_finite() || !self.resultant().is_finite() {
            return Err(ConfigError::OutOfRange("process_load.per_length"));
        }
        Ok(self)
    }
}

/// Check that two planes are separated by at least [`MIN_PLANE_SEPARATION`] times `scale`
/// (the largest absolute axial coordinate in the problem); return the signed separation.
pub(crate) fn separation(
    z1: f64,
    z2: f64,
    scale: f64,
    name: &'static str,
) -> Result<f64, ConfigError> {
    let d = z2 - z1;
    if d.is_finite() && d.abs() >= MIN_PLANE_SEPARATION * scale && d != 0.0 {
        Ok(d)
    } else {
        Err(ConfigError::Inconsistent(name))
    }
}

/// Static and moment parts of the equivalent support-plane unbalances (seed 002, eq. 5–7).
///
/// With `L_A = z_m − z_A`, `L_B = z_B − z_m` (signed, measured from the centre of mass z_m)
/// and `L = z_B − z_A`: `D_stA = D_st·L_B/L`, `D_stB = D_st·L_A/L`, `D_MA = −M_D/L`,
/// `D_MB = +M_D/L`, and `D_A = D_stA + D_MA`, `D_B = D_stB + D_MB`. The seed's eq. 6 states
/// only `D_MA = −D_MB`; the sign here follows from the moment balance about z_m with
/// `M_D = Σ (z_i − z_m)·D_i`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct PlaneSplit {
    /// `D_stA`, the static part in plane A, kg·m.
    pub static_a: Vec2,
    /// `D_stB`, the static part in plane B, kg·m.
    pub static_b: Vec2,
    /// `D_MA`, the moment (couple) part in plane A, kg·m.
    pub moment_a: Vec2,
    /// `D_MB = −D_MA`, the moment part in plane B, kg·m.
    pub moment_b: Vec2,
}

/// A rigid rotor on two supports with up to `N` unbalances (a fixed capacity, no heap).
///
/// Unbalance algebra (seed 002): each unbalance `D_i` is a 2-D vector at axial position
/// `z_i`; at speed ω it produces the rotating force `D_i·ω²`. Any set of unbalances is
/// equivalent (same resultant force, same moment) to exactly one pair of vectors in any two
/// distinct planes; the pair in the support planes, `D_A`, `D_B`, gives the rotating
/// support loads `|D_A|·ω²`, `|D_B|·ω²`. Every split here solves that 2×2 force/moment balance
/// with vectors, so angles never pass through tan/atan (no quadrant errors, cf. the seed's
/// eq. 33/37) and planes outside the span (overhung rotors) need no special case.
///
/// Gravity: a horizontal rotor's supports carry its weight, so by default the rotor's own
/// weight `m·g` ([`STANDARD_GRAVITY`] at 270°, −y) acts at the centre of mass as a static
/// load, beside the process load. [`Rotor::with_gravity`] changes or removes it (a vertical
/// rotor: `g = 0`).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Rotor<const N: usize> {
    mass: f64,
    centre_of_mass: f64,
    support_a: f64,
    support_b: f64,
    items: [Unbalance; N],
    vectors: [Vec2; N],
    len: usize,
    process_load: Option<ProcessLoad>,
    gravity: Vec2,
    scale: f64,
    support_unbalance: [Vec2; 2],
    static_load: [Vec2; 2],
}

impl<const N: usize> Rotor<N> {
    /// A validated rotor.
    ///
    /// * `mass` kg: positive. `centre_of_mass`, `support_a`, `support_b` m: finite (zero,
    ///   negative and subnormal coordinates are ordinary positions).
    /// * `unbalances`: at most `N` ([`ConfigError::Capacity`]), each with finite `z` and
    ///   `angle` and a finite, non-negative `amount` (subnormal amounts are rejected).
    /// * `process_load`: non-negative `per_length`, finite ends with `to > from`, finite angle.
    /// * The support planes must be separated by at least [`MIN_PLANE_SEPARATION`] times the
    ///   largest absolute axial coordinate of the model, else
    ///   `ConfigError::Inconsistent("support_b")`.
    /// * Results that would overflow are `ConfigError::OutOfRange`.
    pub fn new(
        mass: f64,
        centre_of_mass: f64,
        support_a: f64,
        support_b: f64,
        unbalances: &[Unbalance],
        process_load: Option<ProcessLoad>,
    ) -> Result<Self, ConfigError> {
        let mass = positive("mass", mass)?;
        let centre_of_mass = finite("centre_of_mass", centre_of_mass)?;
        let support_a = finite("support_a", support_a)?;
        let support_b = finite("support_b", support_b)?;
        if unbalances.len() > N {
            return Err(ConfigError::Capacity("unbalances"));
        }
        let mut items = [Unbalance::default(); N];
        let mut vectors = [Vec2::ZERO; N];
        let mut scale = support_a
            .abs()
            .max(support_b.abs())
            .max(centre_of_mass.abs());
        for ((slot, vslot), u) in items.iter_mut().zip(vectors.iter_mut()).zip(unbalances) {
            finite("unbalance.z", u.z)?;
            non_negative("unbalance.amount", u.amount)?;
            finite("unbalance.angle", u.angle)?;
            *slot = *u;
            *vslot = u.vector();
            scale = scale.max(u.z.abs());
        }
        let process_load = match process_load {
            Some(p) => {
                let p = p.validate()?;
                scale = scale.max(p.from.abs()).max(p.to.abs());
                Some(p)
            }
            None => None,
        };
        separation(support_a, support_b, scale, "support_b")?;
        let mut rotor = Rotor {
            mass,
            centre_of_mass,
            support_a,
            support_b,
            items,
            vectors,
            len: unbalances.len(),
            process_load,
            gravity: Vec2::from_polar(STANDARD_GRAVITY, GRAVITY_ANGLE),
            scale,
            support_unbalance: [Vec2::ZERO; 2],
            static_load: [Vec2::ZERO; 2],
        };
        rotor.support_unbalance = split(rotor.pairs(), support_a, support_b);
        let [da, db] = rotor.support_unbalance;
        if !(da.is_finite() && db.is_finite() && rotor.static_unbalance().is_finite()) {
            return Err(ConfigError::OutOfRange("unbalances"));
        }
        rotor.update_static_load()?;
        Ok(rotor)
    }

    /// The same rotor with gravity `g` m/s² (finite, not negative; 0 removes the body load)
    /// acting in the fixed direction `angle` radians.
    pub fn with_gravity(mut self, g: f64, angle: f64) -> Result<Self, ConfigError> {
        let g = non_negative("gravity", g)?;
        let angle = finite("gravity.angle", angle)?;
        self.gravity = Vec2::from_polar(g, angle);
        self.update_static_load()?;
        Ok(self)
    }

    fn update_static_load(&mut self) -> Result<(), ConfigError> {
        let weight = self.gravity * self.mass;
        if !weight.is_finite() {
            return Err(ConfigError::OutOfRange("mass"));
        }
        let mut loads = [(self.centre_of_mass, weight), (0.0, Vec2::ZERO)];
        if let (Some(p), Some(slot)) = (self.process_load, loads.get_mut(1)) {
            *slot = (p.centre(), p.resultant());
        }
        let s = split(loads, self.support_a, self.support_b);
        if !(s[0].is_finite() && s[1].is_finite()) {
            return Err(ConfigError::OutOfRange("process_load.per_length"));
        }
        self.static_load = s;
        Ok(())
    }

    /// `(z_i, D_i)` for every unbalance.
    pub fn pairs(&self) -> impl Iterator<Item = (f64, Vec2)> + Clone + '_ {
        self.unbalances()
            .iter()
            .zip(self.vectors.iter())
            .map(|(u, v)| (u.z, *v))
    }

    /// Rotor mass, kg.
    pub fn mass(&self) -> f64 {
        self.mass
    }
    /// Axial position of the centre of mass, m.
    pub fn centre_of_mass(&self) -> f64 {
        self.centre_of_mass
    }
    /// Axial position of support A, m.
    pub fn support_a(&self) -> f64 {
        self.support_a
    }
    /// Axial position of support B, m.
    pub fn support_b(&self) -> f64 {
        self.support_b
    }
    /// Signed span `L = z_B − z_A`, m.
    pub fn span(&self) -> f64 {
        self.support_b - self.support_a
    }
    /// The unbalances as given.
    pub fn unbalances(&self) -> &[Unbalance] {
        self.items.get(..self.len).unwrap_or(&[])
    }
    /// The process load, if any.
    pub fn process_load(&self) -> Option<ProcessLoad> {
        self.process_load
    }
    /// The gravity vector, m/s².
    pub fn gravity(&self) -> Vec2 {
        self.gravity
    }
    /// The largest absolute axial coordinate of the model, m (the scale of the plane
    /// separation test).
    pub fn axial_scale(&self) -> f64 {
        self.scale
    }

    /// Resultant static unbalance `D_st = Σ D_i`, kg·m (seed 002, eq. 2 and 4).
    pub fn static_unbalance(&self) -> Vec2 {
        resultant(self.pairs())
    }

    /// Moment unbalance about the centre of mass, `M_D = Σ (z_i − z_m)·D_i`, kg·m² (seed 002,
    /// eq. 3–4). Returned in the radial plane like the unbalances: the moment vector of the
    /// seed, `Σ l_i × D_i`, is this vector turned by +90° about the axis.
    pub fn moment_unbalance(&self) -> Vec2 {
        moment(self.pairs(), self.centre_of_mass)
    }

    /// The static/moment decomposition of the support-plane unbalances (eq. 5–7).
    pub fn plane_split(&self) -> PlaneSplit {
        let l = self.span();
        let d_st = self.static_unbalance();
        let [static_a, static_b] = split(
            [(self.centre_of_mass, d_st)],
            self.support_a,
            self.support_b,
        );
        let m = self.moment_unbalance();
        let moment_b = Vec2::new(m.x / l, m.y / l);
        PlaneSplit {
            static_a,
            static_b,
            moment_a: -moment_b,
            moment_b,
        }
    }

    /// The equivalent unbalances in the support planes, `[D_A, D_B]`, kg·m (eq. 7, 30–32):
    /// same resultant and same moment as all the unbalances. Computed directly from the
    /// unbalances (not as `D_stA + D_MA`, which can cancel).
    pub fn support_unbalance(&self) -> [Vec2; 2] {
        self.support_unbalance
    }

    /// The equivalent unbalances in any two planes `z1`, `z2` (eq. 34–37, Table 1, both
    /// schemes: the planes may lie inside or outside the span). Planes closer than
    /// [`MIN_PLANE_SEPARATION`] times the model's axial scale are
    /// `ConfigError::Inconsistent("correction_plane_2")`; non-finite positions are
    /// `ConfigError::NonFinite`.
    pub fn equivalent_in(&self, z1: f64, z2: f64) -> Result<[Vec2; 2], ConfigError> {
        let z1 = finite("correction_plane_1", z1)?;
        let z2 = finite("correction_plane_2", z2)?;
        let scale = self.scale.max(z1.abs()).max(z2.abs());
        separation(z1, z2, scale, "correction_plane_2")?;
        let e = split(self.pairs(), z1, z2);
        if e[0].is_finite() && e[1].is_finite() {
            Ok(e)
        } else {
            Err(ConfigError::OutOfRange("correction_plane_2"))
        }
    }

    /// What to add in planes `z1`, `z2` to balance the rotor: the negatives of
    /// [`Rotor::equivalent_in`]. Rotor plus corrections has zero resultant and zero moment.
    pub fn corrections(&self, z1: f64, z2: f64) -> Result<[Vec2; 2], ConfigError> {
        let [a, b] = self.equivalent_in(z1, z2)?;
        Ok([-a, -b])
    }

    /// Static support loads `[S_A, S_B]`, N: the weight `m·g` at the centre of mass and the
    /// process-load resultant at the middle of its interval, split by the lever rule (beam
    /// statics of a rigid two-support rotor; loads outside the span give a support load
    /// opposite to the applied load, handled by the same signed statics).
    ///
    /// The seed's eq. 12 and 16 add a process-load term `q·(2/3)L·(1/2)L` and a helicoid-area
    /// term to squared unbalances; those terms do not share units with `D²` (kg²·m²). This
    /// model keeps the consistent split instead: static loads in N here, rotating loads
    /// `|D|·ω²` in N, combined per support by [`LoadRange::at`].
    pub fn static_load(&self) -> [Vec2; 2] {
        self.static_load
    }

    /// Load range on each support over one turn at speed `omega` rad/s (f64, for analysis;
    /// the runtime path is [`super::SupportMonitor`]).
    pub fn loads(&self, omega: f64) -> [LoadRange; 2] {
        let w2 = omega * omega;
        let [sa, sb] = self.static_load;
        let [da, db] = self.support_unbalance;
        [
            LoadRange::at(sa.norm(), da.norm(), w2),
            LoadRange::at(sb.norm(), db.norm(), w2),
        ]
    }
}

/// Magnitudes of the load on one support over one turn, N.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct LoadRange {
    /// `|S|`, the static load.
    pub static_load: f64,
    /// `|D|·ω²`, the rotating load.
    pub rotating: f64,
    /// `|S| + |D|·ω²`, the largest load over one turn (rotating load aligned with static).
    pub peak: f64,
    /// `||S| − |D|·ω²|`, the smallest load over one turn (rotating load opposing static).
    pub min: f64,
}

impl LoadRange {
    /// The range for static load magnitude `s`, unbalance magnitude `d` and `w2 = ω²`.
    pub fn at(s: f64, d: f64, w2: f64) -> Self {
        // 0·∞ is taken as 0: no unbalance, no rotating load at any speed.
        let rotating = if d == 0.0 { 0.0 } else { d * w2 };
        LoadRange {
            static_load: s,
            rotating,
            peak: s + rotating,
            min: (s - rotating).abs(),
        }
    }
}

/// The equivalent of the unbalances `(z_i, D_i)` in planes `planes[0]`, `planes[1]`
/// (seed 002, eq. 30–37 and Table 1 in either direction: support planes to correction planes
/// and back, inboard scheme I and overhung scheme II alike, with signed axial positions).
///
/// Errors: non-finite input is `NonFinite`; planes closer than [`MIN_PLANE_SEPARATION`] times
/// the largest absolute coordinate are `Inconsistent("correction_plane_2")`; overflow is
/// `OutOfRange`.
pub fn equivalent_planes(
    unbalances: &[(f64, Vec2)],
    planes: [f64; 2],
) -> Result<[Vec2; 2], ConfigError> {
    let [z1, z2] = planes;
    let mut scale = finite("correction_plane_1", z1)?
        .abs()
        .max(finite("correction_plane_2", z2)?.abs());
    for (z, v) in unbalances {
        finite("unbalance.z", *z)?;
        if !v.is_finite() {
            return Err(ConfigError::NonFinite("unbalance"));
        }
        scale = scale.max(z.abs());
    }
    separation(z1, z2, scale, "correction_plane_2")?;
    let e = split(unbalances.iter().copied(), z1, z2);
    if e[0].is_finite() && e[1].is_finite() {
        Ok(e)
    } else {
        Err(ConfigError::OutOfRange("unbalance"))
    }
}
