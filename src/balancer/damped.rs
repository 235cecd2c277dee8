//! Damped zones (sign changes of `Re H_ee`) and Sommerfeld capture windows.
//!
//! Both run on the system scaled to unit largest mass and stiffness (no overflow for any
//! units; speeds in units of `w_s = √(k_s/m_s)`), and every result is decided by the pivoted
//! solve ([`Solver::receptance`]), which is backward stable. What changed against the scan
//! kept as the reference ([`super::scanned`], [`Machine::new_scanned`]) is *where* the solve
//! is evaluated: at a few points placed by an exact method instead of at thousands of nodes.
//!
//! # Zone search
//!
//! `Re H_ee = p(ω²)/|det Z|²`, with `p` a real polynomial of degree `d = 2·platforms − 1`
//! ([`System::re_numerator`]), so the zone boundaries are the positive roots of `p` of odd
//! multiplicity. They are found, then each is *polished on the solve*:
//!
//! 1. Newton's iteration on `p` from each of the `d` undamped characteristic speeds (where
//!    the roots sit for light damping); if that gives `d` distinct roots across which the
//!    sign of `p` alternates, they are all of `p`'s roots, simple and certified
//!    ([`poly::roots_near`]). Each is then checked by the sign of the solve at `(1 ± 0.45·tol)`
//!    times it: two solves per boundary. Only if the sign does not change across that, the
//!    bracket the rounding of `p` allows, `x ± 4·E(x)/|p'(x)|` with `E(x) = 64·ε·b(x)` (`b` the
//!    same expansion in absolute values), is searched as well.
//! 2. Otherwise (heavy damping: fewer real roots than speeds; or roots `p` cannot tell apart)
//!    the roots are isolated exactly, in exact arithmetic, by the sign changes of `p`'s
//!    derivatives ([`poly::sign_changes`]), each with the bracket its rounding allows; a local
//!    extremum with `|p| ≤ 4·E` (a pair of roots `p` cannot resolve may hide there) gets the
//!    bracket where `p` could vanish, `2·√(8·E/|p''|)`; and the sign of the solve is taken at
//!    every bracket's ends and centre and between consecutive distinct undamped
//!    characteristic speeds (which separate the boundaries of a lightly damped machine
//!    however close they lie).
//! 3. The sign is also taken at `0` and at `max_factor ×` the highest point so far or
//!    undamped characteristic speed (doubled while it still says gathering: at high speed
//!    `H_ee → −1/(M_eΣ·ω²)`). Every pair of consecutive points with different signs holds a
//!    boundary, refined by a bracketing Illinois (regula falsi) iteration on the smooth
//!    `Re H/(1 + |H|²)`, which has a simple zero both where `H` vanishes and where it has a
//!    pole, to the relative width `rel_tol`.
//!
//! So the solve decides every sign, as in the scan; the polynomial only says where to look,
//! and a boundary the polynomial misplaces still shows as a sign change between the points
//! and is refined there. Pairs of boundaries closer than `1e3·rel_tol` (relative) are
//! dropped, as by the scan: such a zone is below the resolution of the search (a pole and a
//! zero that nearly cancel). For the bundled three-mass machine this is 12 solves.
//!
//! # Capture windows
//!
//! `Ω + D(Ω)` is maximised over each gathering zone `[max(from, 10⁻³·to), to]`. A scan in
//! f32 (the same pivoted solve on the Cortex-M4F's hardware float: it only has to tell which
//! node is highest) of `nodes_per_interval / 8` log-spaced nodes, and as many whose distance
//! below the zone's end falls geometrically to `10⁻⁶` of it (where the peak of a lightly
//! damped resonance sits when it lies inside the zone), finds the local maxima within `10⁻⁵`
//! of the highest (the zone's end, a node of both passes, once, with the narrower bracket).
//! Each is refined in f64 between its neighbouring nodes (moved uphill first if the slopes
//! there show the f32 rounding picked a neighbour of the highest node), where the maximum is
//! the zero of the exact slope `1 + D'(Ω)` (from `dH/dω = −yᵀ·Z'·y`,
//! [`Solver::receptance_slope`]), bracketed to `1e-9` and until the slopes at the bracket's
//! ends bound the value to `1e-13`. A maximum at the zone's end with a non-negative slope
//! there costs one f64 solve. A zone narrower than `10⁻³` (relative), which f32 nodes cannot
//! resolve, is searched in f64 from its two ends alone.

use super::modal::{Solver, System};
use super::poly::{self, Poly};
use super::{
    CaptureWindow, ConfigError, Machine, MachineConfig, SearchOptions, Zone, ZoneKind,
    MAX_PLATFORMS, MAX_ZONES,
};

/// Boundaries collected before merging (noise can add pairs; a physical machine has ≤ 5).
const MAX_RAW: usize = 32;
/// Candidate points of the zone search: roots and near-zero extrema of `p`.
const MAX_CANDIDATES: usize = 2 * poly::MAX_DEG;
/// Factor of `ε·b(x)` bounding the rounding of the computed `p(x)` (a few dozen roundings:
/// products of up to six entries, sums of up to 36 terms, Horner's rule), with room to spare.
const ROUNDING: f64 = 64.0 * f64::EPSILON;
/// Local maxima of the f32 capture scan refined in f64: those within this (relative) of the
/// highest node (f32's rounding of `Ω + D(Ω)` is far below it)...
const PEAK_TIE: f32 = 1e-5;
/// ...at most this many of them.
const MAX_PEAKS: usize = 3;
/// Zones narrower than this (relative) are searched for capture in f64 from their ends.
const NARROW: f64 = 1e-3;
/// Relative precision of a capture maximum's location `at`.
const AT_TOL: f64 = 1e-9;
/// Relative precision of a capture maximum's value `until`.
const VALUE_TOL: f64 = 1e-13;

/// The system scaled to unit largest mass and stiffness.
pub(crate) struct Scaled {
    pub sys: System,
    /// Speed unit, rad/s.
    pub w_s: f64,
    /// Mass unit, kg.
    pub m_s: f64,
}

pub(crate) fn scaled(sys: &System) -> Scaled {
    let mut k_s = 0.0f64;
    let mut m_s = 0.0f64;
    for i in 0..sys.n {
        k_s = k_s.max(sys.k(i, i));
        m_s = m_s.max(sys.m[i]);
    }
    Scaled {
        sys: sys.scaled(k_s, m_s),
        w_s: libm::sqrt(k_s / m_s),
        m_s,
    }
}

/// The undamped characteristic speeds of `m` in scaled units, ascending (coinciding ones
/// kept: they are the hints of [`poly::roots_near`], one per root of `p`).
pub(crate) fn characteristic(m: &Machine, w_s: f64) -> ([f64; 2 * MAX_PLATFORMS], usize) {
    let mut c = [0.0; 2 * MAX_PLATFORMS];
    let mut n = 0;
    for &x in m.resonant_speeds().iter().chain(m.additional_speeds()) {
        if let Some(slot) = c.get_mut(n) {
            *slot = x / w_s;
            n += 1;
        }
    }
    insertion_sort(c.get_mut(..n).unwrap_or(&mut []));
    (c, n)
}

fn insertion_sort(v: &mut [f64]) {
    for i in 1..v.len() {
        let mut j = i;
        while j > 0 && v[j - 1] > v[j] {
            v.swap(j - 1, j);
            j -= 1;
        }
    }
}

/// A sign of the criterion and a smooth value carrying it: `(gathering, value)` with
/// `value > 0` exactly when `gathering`.
type Signed = (bool, f64);

/// `Re H_ee(w) > 0` (the loads gather) and `Re H/(1 + |H|²)`, which is smooth through the
/// poles of `H` as well as its zeros (the value for the refinement; NaN or an infinite `H`
/// gives a tiny value of the right sign).
fn criterion(solver: &Solver<f64>, w: f64) -> Signed {
    // Stability: the sign is the pivoted solve's, never `p`'s, whose roots lose two thirds of
    // their digits where a double pole cancels a zero (equal partial frequencies).
    let h = solver.receptance(w);
    let gathering = h.re > 0.0;
    let v = h.re / (1.0 + h.norm_sq());
    (gathering, signed(gathering, v))
}

/// `v` if its sign agrees with `positive` and it is finite and nonzero, else the smallest
/// normal number of that sign.
fn signed(positive: bool, v: f64) -> f64 {
    if v.is_finite() && v != 0.0 && (v > 0.0) == positive {
        v
    } else if positive {
        f64::MIN_POSITIVE
    } else {
        -f64::MIN_POSITIVE
    }
}

/// The sign change of `f` in `[a, b]` (`fa`, `fb` of different signs) to relative bracket
/// width `tol`, by the Illinois variant of regula falsi: superlinear on a smooth simple zero,
/// each step kept `tol/4` inside the bracket so it always shrinks, and a bisection when the
/// interpolation is not a number. Returns the bracket's midpoint.
#[inline(never)]
fn refine(
    f: impl Fn(f64) -> Signed,
    (mut a, fa): (f64, Signed),
    (mut b, fb): (f64, Signed),
    tol: f64,
) -> f64 {
    let side_a = fa.0;
    let (mut va, mut vb) = (fa.1, fb.1);
    let mut last = 0i8;
    for _ in 0..200 {
        let width = b - a;
        if width.is_nan() || width <= tol * b {
            break;
        }
        let guard = 0.25 * tol * b;
        let x = a + width * (va / (va - vb));
        let x = if x.is_nan() {
            a + 0.5 * width
        } else {
            x.clamp(a + guard, b - guard)
        };
        if x <= a || x >= b {
            break;
        }
        let (s, v) = f(x);
        if s == side_a {
            a = x;
            va = v;
            if last == -1 {
                vb *= 0.5;
            }
            last = -1;
        } else {
            b = x;
            vb = v;
            if last == 1 {
                va *= 0.5;
            }
            last = 1;
        }
    }
    a + 0.5 * (b - a)
}

/// Zone boundaries as a search finds them (scaled speeds, ascending), before merging.
pub(super) struct Boundaries {
    b: [f64; MAX_RAW],
    n: usize,
}

impl Boundaries {
    pub(super) const EMPTY: Boundaries = Boundaries {
        b: [0.0; MAX_RAW],
        n: 0,
    };

    pub(super) fn push(&mut self, x: f64) -> Result<(), ConfigError> {
        let slot = self
            .b
            .get_mut(self.n)
            .ok_or(ConfigError::Capacity("zones"))?;
        *slot = x;
        self.n += 1;
        Ok(())
    }

    /// Writes the zones into `m`: pairs of boundaries closer than the search resolves (relative
    /// `tol`) dropped, gathering below the first, alternating after each; `platforms` bounds
    /// their number, `w_s` scales them back to rad/s.
    pub(super) fn into_zones(
        mut self,
        m: &mut Machine,
        tol: f64,
        platforms: usize,
        w_s: f64,
    ) -> Result<(), ConfigError> {
        // Drop pairs of boundaries closer than the search can resolve.
        let merge = 1e3 * tol;
        let mut i = 0;
        while i + 1 < self.n {
            if self.b[i + 1] - self.b[i] <= merge * self.b[i + 1] {
                for j in i..self.n - 2 {
                    self.b[j] = self.b[j + 2];
                }
                self.n -= 2;
                i = i.saturating_sub(1);
            } else {
                i += 1;
            }
        }
        if self.n + 1 > MAX_ZONES || self.n + 1 > 2 * platforms {
            return Err(ConfigError::Capacity("zones"));
        }
        let mut kind = ZoneKind::Gathering;
        let mut from = 0.0;
        for (i, &b) in self.b.iter().take(self.n).enumerate() {
            m.zones[i] = Zone {
                from,
                to: Some(b * w_s),
                kind,
            };
            from = b * w_s;
            kind = match kind {
                ZoneKind::Gathering => ZoneKind::Balancing,
                ZoneKind::Balancing => ZoneKind::Gathering,
            };
        }
        m.zones[self.n] = Zone {
            from,
            to: None,
            kind,
        };
        m.n_zones = (self.n + 1) as u8;
        Ok(())
    }
}

/// A point where the zone search took the sign of the solve.
#[derive(Clone, Copy)]
struct Node {
    w: f64,
    s: Signed,
}

/// A root (or near-zero extremum) of `p` in scaled speed: its centre and the bracket its
/// rounding allows (`lo == hi == w` until that is computed).
#[derive(Clone, Copy)]
struct Candidate {
    w: f64,
    lo: f64,
    hi: f64,
}

impl Candidate {
    /// About `x = w²` with radius `r` in `x`, at most a factor 2 either way in `w`.
    fn new(x: f64, r: f64) -> Self {
        let r = if r.is_finite() {
            r.min(0.75 * x)
        } else {
            0.75 * x
        };
        Candidate {
            w: libm::sqrt(x),
            lo: libm::sqrt(x - r),
            hi: libm::sqrt(x + r),
        }
    }
}

/// `Re H_ee`'s numerator `p` and, computed when first needed, its rounding bound.
struct Numerator<'a> {
    sys: &'a System,
    p: Poly,
    bound: Option<Poly>,
}

impl Numerator<'_> {
    fn bound(&mut self) -> Poly {
        let sys = self.sys;
        *self.bound.get_or_insert_with(|| sys.re_numerator(true))
    }

    /// The bracket a root `x` of the computed `p` may be off by: `4·E(x)/|p'(x)|`.
    fn root(&mut self, x: f64) -> Candidate {
        let b = self.bound();
        let (_, d) = poly::eval_d(self.p.coefficients(), x);
        let e = ROUNDING * poly::eval(b.coefficients(), x);
        Candidate::new(x, 4.0 * e / libm::fabs(d))
    }
}

/// Candidates about the roots of `p`, ascending by centre. `hints`: the undamped
/// characteristic speeds (scaled), where the roots start for light damping. When every root
/// is found near a hint with the count certified ([`poly::roots_near`]), the brackets are
/// left to be computed on demand; otherwise the roots come from the full isolation
/// ([`poly::sign_changes`]), each with its bracket, and the local extrema with `|p| ≤ 4·E`
/// (where a pair of roots `p` cannot resolve may hide) are added with a bracket
/// `2·√(8·E/|p''|)` wide.
#[inline(never)]
fn candidates(
    num: &mut Numerator,
    hints: &[f64],
    tol: f64,
) -> ([Candidate; MAX_CANDIDATES], usize, bool) {
    let none = Candidate {
        w: 0.0,
        lo: 0.0,
        hi: 0.0,
    };
    let mut out = [none; MAX_CANDIDATES];
    let mut n = 0;
    let mut squares = [0.0; 2 * MAX_PLATFORMS];
    for (s, &h) in squares.iter_mut().zip(hints) {
        *s = h * h;
    }
    let squares = squares.get(..hints.len()).unwrap_or(&[]);
    let p = num.p;
    let p = p.coefficients();
    if let Some(found) = poly::roots_near(p, squares, 0.05 * tol) {
        for (slot, &x) in out.iter_mut().zip(found.roots()) {
            *slot = Candidate::new(x, 0.0);
            n += 1;
        }
        return (out, n, true);
    }
    let Some((lo, hi)) = poly::root_bounds(p) else {
        return (out, 0, false);
    };
    let found = poly::sign_changes(p, 0.5 * lo, 2.0 * hi, squares, 0.05 * tol);
    for &x in found.roots() {
        if let Some(slot) = out.get_mut(n) {
            *slot = num.root(x);
            n += 1;
        }
    }
    let b = num.bound();
    for &x in found.extrema() {
        let (v, _, dd) = poly::eval_dd(p, x);
        let e = ROUNDING * poly::eval(b.coefficients(), x);
        if libm::fabs(v) <= 4.0 * e {
            if let Some(slot) = out.get_mut(n) {
                *slot = Candidate::new(x, 2.0 * libm::sqrt(8.0 * e / libm::fabs(dd)));
                n += 1;
            }
        }
    }
    // Roots and extrema interleave; sort by centre (≤ 9 entries).
    let s = out.get_mut(..n).unwrap_or(&mut []);
    for i in 1..s.len() {
        let mut j = i;
        while j > 0 && s[j - 1].w > s[j].w {
            s.swap(j - 1, j);
            j -= 1;
        }
    }
    (out, n, false)
}

/// The walk over the points where the solve's sign is taken, in ascending order: every
/// change of sign between consecutive points is refined into a boundary.
struct Walk<'a> {
    solver: &'a Solver<f64>,
    tol: f64,
    prev: Node,
    out: Boundaries,
}

impl Walk<'_> {
    fn eval(&self, w: f64) -> Node {
        Node {
            w,
            s: criterion(self.solver, w),
        }
    }

    /// Steps to `here` (skipped unless above the previous point).
    fn visit(&mut self, here: Node) -> Result<(), ConfigError> {
        if here.w <= self.prev.w {
            return Ok(());
        }
        if here.s.0 != self.prev.s.0 {
            let solver = self.solver;
            let f = |w: f64| criterion(solver, w);
            let b = refine(f, (self.prev.w, self.prev.s), (here.w, here.s), self.tol);
            self.out.push(b)?;
        }
        self.prev = here;
        Ok(())
    }

    fn visit_at(&mut self, w: f64) -> Result<(), ConfigError> {
        if w <= self.prev.w {
            return Ok(());
        }
        let here = self.eval(w);
        self.visit(here)
    }
}

/// Zones and capture windows of `m` (whose undamped speeds are set), see the module notes.
pub(crate) fn analyse(
    sys_si: &System,
    m: &mut Machine,
    opt: &SearchOptions,
) -> Result<(), ConfigError> {
    let scaled = scaled(sys_si);
    let solver = Solver::new(&scaled.sys);
    find_zones(&scaled, &solver, m, opt)?;
    find_captures(&scaled, &solver, m, opt);
    Ok(())
}

#[inline(never)]
fn find_zones(
    scaled: &Scaled,
    solver: &Solver<f64>,
    m: &mut Machine,
    opt: &SearchOptions,
) -> Result<(), ConfigError> {
    let Scaled { sys, w_s, .. } = scaled;
    let w_s = *w_s;
    let (chars, n_chars) = characteristic(m, w_s);
    let chars = chars.get(..n_chars).unwrap_or(&[]);
    let tol = opt.rel_tol;
    let mut num = Numerator {
        sys,
        p: sys.re_numerator(false),
        bound: None,
    };
    let (cands, n_cands, certified) = candidates(&mut num, chars, tol);
    let cands = cands.get(..n_cands).unwrap_or(&[]);

    let mut walk = Walk {
        solver,
        tol,
        prev: Node {
            w: 0.0,
            s: criterion(solver, 0.0),
        },
        out: Boundaries::EMPTY,
    };
    if certified {
        // Every root of p is simple and accounted for: for each, first the narrowest
        // bracket the tolerance allows; only if the sign does not change across it, the
        // bracket its rounding allows.
        for c in cands {
            let (tl, th) = (c.w * (1.0 - 0.45 * tol), c.w * (1.0 + 0.45 * tol));
            let (nl, nh) = (walk.eval(tl), walk.eval(th));
            if nl.s.0 == nh.s.0 {
                let wide = num.root(c.w * c.w);
                walk.visit_at(wide.lo.min(tl))?;
                walk.visit(nl)?;
                walk.visit(nh)?;
                walk.visit_at(wide.hi.max(th))?;
            } else {
                walk.visit(nl)?;
                walk.visit(nh)?;
            }
        }
    } else {
        // Roots p may not resolve: the sign at every candidate's bracket ends and centre, and
        // between consecutive distinct undamped characteristic speeds (which separate the
        // boundaries of a lightly damped machine however close they are).
        let mut nodes = [0.0; 3 * MAX_CANDIDATES + 2 * MAX_PLATFORMS];
        let mut k = 0;
        let mut push = |w: f64| {
            if let Some(slot) = nodes.get_mut(k) {
                *slot = w;
                k += 1;
            }
        };
        for c in cands {
            push(c.lo);
            push(c.w);
            push(c.hi);
        }
        for pair in chars.windows(2) {
            if let [a, b] = *pair {
                if b > a * (1.0 + tol) {
                    push(libm::sqrt(a) * libm::sqrt(b));
                }
            }
        }
        let nodes = nodes.get_mut(..k).unwrap_or(&mut []);
        insertion_sort(nodes);
        for &w in nodes.iter() {
            walk.visit_at(w)?;
        }
    }
    let highest = walk.prev.w.max(chars.last().copied().unwrap_or(1.0));
    let mut top = highest * opt.max_factor;
    walk.visit_at(top)?;
    let mut doublings = 0;
    while walk.prev.s.0 && doublings < 60 {
        top *= 2.0;
        walk.visit_at(top)?;
        doublings += 1;
    }
    if walk.prev.s.0 {
        return Err(ConfigError::Inconsistent("zone search"));
    }
    walk.out.into_zones(m, tol, sys.n, w_s)
}

/// `D(Ω) = ω − Ω` for gathered loads turning at `Ω`; see [`Machine::capture_lag`].
pub(crate) fn capture_lag(sys: &System, cfg: &MachineConfig, load_speed: f64) -> f64 {
    let w = libm::fabs(load_speed);
    let h = sys.receptance(w);
    let b = cfg.balancer();
    let n = f64::from(b.loads);
    let w2 = w * w;
    n * b.load_mass * b.load_mass * w2 * w2 * (-h.im) / (2.0 * b.viscosity)
}

/// `Ω + D(Ω)` and its derivative in scaled units: `w + g·w⁴·(−Im H)`, `g` the scaled lag
/// gain.
struct RotorSpeed<'a> {
    solver: &'a Solver<f64>,
    narrow: Solver<f32>,
    gain: f64,
    gain32: f32,
}

/// `Ω + D(Ω)` and `1 + D'(Ω)` at a point.
#[derive(Clone, Copy)]
struct Sample {
    w: f64,
    value: f64,
    slope: f64,
}

impl RotorSpeed<'_> {
    /// The value and slope at `w`; a value that is not a number (the solve singular: `w` on
    /// an undamped resonance) is −∞, never a maximum.
    fn sample(&self, w: f64) -> Sample {
        let (h, dh) = self.solver.receptance_slope(w);
        let w2 = w * w;
        let w4 = w2 * w2;
        let value = w + self.gain * w4 * (-h.im);
        Sample {
            w,
            value: if value.is_nan() {
                f64::NEG_INFINITY
            } else {
                value
            },
            slope: 1.0 + self.gain * (4.0 * w2 * w * (-h.im) + w4 * (-dh)),
        }
    }

    /// The sample at a zone's end `hi`, or, where the solve is singular there (an undamped
    /// resonance), the nearest finite one inside the zone, `4^k·ε` below it.
    #[inline(never)]
    fn at_end(&self, hi: f64, lo: f64) -> Sample {
        let mut step = 4.0 * f64::EPSILON;
        let mut s = self.sample(hi);
        while !s.value.is_finite() && step < 0.25 {
            let w = hi * (1.0 - step);
            if w <= lo {
                break;
            }
            s = self.sample(w);
            step *= 4.0;
        }
        s
    }

    /// `Ω + D(Ω)` in f32 (for the scan only); NaN as −∞.
    fn narrow(&self, w: f32) -> f32 {
        let h = self.narrow.receptance(w);
        let w2 = w * w;
        let v = w + self.gain32 * (w2 * w2) * (-h.im);
        if v.is_nan() {
            f32::NEG_INFINITY
        } else {
            v
        }
    }

    /// The largest `Ω + D(Ω)` on `[lo.w, hi.w]`: at an end, or where the slope falls through
    /// zero between them. That zero is bracketed by Illinois steps on the slope until the
    /// bracket is within [`AT_TOL`] and, with the slopes at its ends, bounds the rise above
    /// the highest point evaluated to [`VALUE_TOL`] of its value (near a maximum `Ω + D(Ω)`
    /// is concave: it rises above an end by at most that end's slope times the width).
    ///
    /// If the slopes at the ends do not bracket a maximum (the f32 scan's rounding can pick
    /// a node next to the highest), the bracket first moves uphill by its own width, up to
    /// eight times, within the zone `[zone.0, zone.1]`.
    #[inline(never)]
    fn maximum(&self, lo: Sample, hi: Sample, zone: (f64, f64)) -> Sample {
        let (mut a, mut b) = (lo, hi);
        let mut best = if hi.value >= lo.value { hi } else { lo };
        for _ in 0..8 {
            let width = b.w - a.w;
            if a.slope <= 0.0 && b.slope <= 0.0 && a.w > zone.0 {
                b = a;
                a = self.sample((a.w - width).max(zone.0));
            } else if a.slope >= 0.0 && b.slope >= 0.0 && b.w < zone.1 {
                a = b;
                b = self.sample((b.w + width).min(zone.1));
            } else {
                break;
            }
            for s in [a, b] {
                if s.value > best.value {
                    best = s;
                }
            }
        }
        if !(a.slope > 0.0 && b.slope < 0.0) {
            return best;
        }
        let (mut fa, mut fb) = (a.slope, b.slope);
        let mut kept = 0i8;
        for _ in 0..200 {
            let width = b.w - a.w;
            let steep = a.slope.min(-b.slope);
            let target = (AT_TOL * b.w).min(VALUE_TOL * libm::fabs(best.value) / steep);
            let floor = 4.0 * f64::EPSILON * b.w;
            if width.is_nan() || width <= target || width <= floor {
                break;
            }
            // Each step at least a quarter of the target inside, so both ends close in.
            let guard = 0.25 * target.max(floor);
            let x = a.w + width * (fa / (fa - fb));
            let x = if x.is_nan() {
                a.w + 0.5 * width
            } else {
                x.clamp(a.w + guard, b.w - guard)
            };
            let s = self.sample(x);
            if s.value > best.value {
                best = s;
            }
            if s.slope > 0.0 {
                a = s;
                fa = s.slope;
                if kept == 1 {
                    fb *= 0.5;
                }
                kept = 1;
            } else {
                b = s;
                fb = s.slope;
                if kept == -1 {
                    fa *= 0.5;
                }
                kept = -1;
            }
        }
        best
    }
}

/// A local maximum of the f32 scan: its node and the neighbouring nodes (scaled speeds).
#[derive(Clone, Copy)]
struct Peak {
    lo: f64,
    at: f64,
    hi: f64,
    value: f32,
}

/// The [`MAX_PEAKS`] highest peaks of the scan, highest first.
#[derive(Clone, Copy)]
struct Peaks([Option<Peak>; MAX_PEAKS]);

impl Peaks {
    fn keep(&mut self, p: Peak) {
        // The zone's end is a node of both passes: keep its narrower bracket once.
        for q in self.0.iter_mut().flatten() {
            if q.at == p.at {
                if p.hi - p.lo < q.hi - q.lo {
                    *q = p;
                }
                return;
            }
        }
        let mut p = Some(p);
        for slot in self.0.iter_mut() {
            match (*slot, p) {
                (None, _) => {
                    *slot = p;
                    return;
                }
                (Some(s), Some(q)) if q.value > s.value => {
                    *slot = p;
                    p = Some(s);
                }
                _ => {}
            }
        }
    }

    /// One ordered pass of the scan over `nodes` (ascending, the last one the zone's end):
    /// every node higher than both neighbours (or than its only one) is a peak.
    #[inline(never)]
    fn pass(&mut self, rs: &RotorSpeed, nodes: impl Iterator<Item = f32>, end: f64) {
        let mut before: Option<(f32, f32)> = None;
        let mut prev: Option<(f32, f32)> = None;
        for x in nodes {
            let v = rs.narrow(x);
            if let Some((px, pv)) = prev {
                if before.is_none_or(|(_, bv)| pv >= bv) && pv > v {
                    self.keep(Peak {
                        lo: f64::from(before.map_or(px, |(bx, _)| bx)),
                        at: f64::from(px),
                        hi: f64::from(x),
                        value: pv,
                    });
                }
            }
            before = prev;
            prev = Some((x, v));
        }
        if let Some((px, pv)) = prev {
            if before.is_none_or(|(_, bv)| pv >= bv) {
                self.keep(Peak {
                    lo: f64::from(before.map_or(px, |(bx, _)| bx)),
                    at: end,
                    hi: end,
                    value: pv,
                });
            }
        }
    }
}

/// Peaks of the f32 scan of `Ω + D(Ω)` on `[lo, hi]` (scaled): `half` nodes log-spaced over
/// the zone, and `half` more whose distances below `hi` fall geometrically from `hi − lo` to
/// `10⁻⁶·hi` (f32 resolves that), where the peak of a lightly damped resonance sits when it lies inside the zone.
#[inline(never)]
fn scan(rs: &RotorSpeed, lo: f64, hi: f64, half: u32) -> Peaks {
    let mut peaks = Peaks([None; MAX_PEAKS]);
    let steps = half.max(2) as f32;
    // Node positions only need f32 (the f64 refinement starts from the nodes found).
    let ratio = libm::expf(libm::logf((hi / lo) as f32) / steps);
    let (lo32, hi32) = (lo as f32, hi as f32);
    let log_nodes = (0..half.max(2)).scan(lo32, |x, _| {
        let here = *x;
        *x *= ratio;
        Some(here)
    });
    peaks.pass(rs, log_nodes.chain(core::iter::once(hi32)), hi);
    let span = hi - lo;
    let shrink = libm::expf(libm::logf((1e-6 * hi / span) as f32) / steps);
    let end_nodes = (0..half.max(2)).scan(span as f32, |d, _| {
        let here = hi32 - *d;
        *d *= shrink;
        Some(here)
    });
    peaks.pass(rs, end_nodes.chain(core::iter::once(hi32)), hi);
    peaks
}

#[inline(never)]
fn find_captures(scaled: &Scaled, solver: &Solver<f64>, m: &mut Machine, opt: &SearchOptions) {
    let (w_s, m_s) = (scaled.w_s, scaled.m_s);
    let b = *m.config.balancer();
    // D(Ω)/w_s = g·w⁴·(−Im H_s) with w = Ω/w_s, H_s = k_s·H: g = N·m²·w_s/(2·b_w·m_s).
    let gain = f64::from(b.loads) * b.load_mass / (2.0 * b.viscosity) * (b.load_mass / m_s) * w_s;
    let rs = RotorSpeed {
        solver,
        narrow: solver.narrowed(),
        gain,
        gain32: gain as f32,
    };
    let half = u32::from(opt.nodes_per_interval) / 8;
    let mut n = 0;
    let zones = m.zones;
    for z in zones.iter().take(usize::from(m.n_zones)).copied() {
        let (ZoneKind::Gathering, Some(end)) = (z.kind, z.to) else {
            continue;
        };
        let hi = end / w_s;
        let lo = (z.from / w_s).max(hi * 1e-3);
        let at_hi = rs.at_end(hi, lo);
        let best = if hi.partial_cmp(&lo) != Some(core::cmp::Ordering::Greater) {
            at_hi
        } else if hi - lo < NARROW * hi {
            rs.maximum(rs.sample(lo), at_hi, (lo, at_hi.w))
        } else {
            let peaks = scan(&rs, lo, hi, half);
            let top = peaks
                .0
                .iter()
                .flatten()
                .fold(f32::NEG_INFINITY, |t, p| t.max(p.value));
            let mut best = at_hi;
            for p in peaks.0.iter().flatten() {
                if p.value.is_nan() || p.value < top - PEAK_TIE * libm::fabsf(top) {
                    continue;
                }
                let found = if p.at >= hi && at_hi.slope >= 0.0 {
                    // Rising into the zone's end: the maximum is there.
                    at_hi
                } else {
                    let a = rs.sample(p.lo.max(lo));
                    let c = if p.hi >= hi { at_hi } else { rs.sample(p.hi) };
                    rs.maximum(a, c, (lo, at_hi.w))
                };
                if found.value > best.value {
                    best = found;
                }
            }
            best
        };
        let until = best.value * w_s;
        if until <= end * (1.0 + super::MIN_CAPTURE_WIDTH) {
            continue;
        }
        if let Some(slot) = m.captures.get_mut(n) {
            *slot = CaptureWindow {
                from: end,
                until,
                at: if best.w >= at_hi.w { end } else { best.w * w_s },
            };
            n += 1;
        }
    }
    m.n_captures = n as u8;
}

pub(crate) fn capture_speed(sys: &System, m: &Machine, omega: f64) -> Option<f64> {
    let cfg = m.config;
    let omega = libm::fabs(omega);
    if !omega.is_finite() || omega <= 0.0 {
        return None;
    }
    let nodes = 4 * u32::from(SearchOptions::default().nodes_per_interval);
    let phi = |x: f64| x + capture_lag(sys, &cfg, x) - omega;
    for z in m.zones() {
        if z.kind != ZoneKind::Gathering || z.from >= omega {
            continue;
        }
        // Ω < omega, and Ω must lie inside the gathering zone.
        let hi = z.to.map_or(omega, |t| t.min(omega));
        let lo = z.from.max(hi * 1e-3);
        let mut prev = (lo, phi(lo) >= 0.0);
        for i in 1..=nodes {
            let x = lo * libm::pow(hi / lo, f64::from(i) / f64::from(nodes));
            let s = phi(x) >= 0.0;
            if s && !prev.1 {
                let r = super::scanned::bisect(prev.0, x, 1e-13, |y| phi(y) >= 0.0);
                if z.to.is_none_or(|t| r < t) {
                    return Some(r);
                }
            }
            prev = (x, s);
        }
    }
    None
}
