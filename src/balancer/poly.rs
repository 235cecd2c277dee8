//! Small real polynomials (fixed capacity, no allocation) and their real roots.
//!
//! Used at configuration time to place the damped zone boundaries: `Re H_ee`'s numerator is a
//! real polynomial in `x = ω²` of degree `2·platforms − 1 ≤ 5` ([`super::modal::System`]
//! builds it). The roots found here are only candidates; the zone search polishes each on the
//! pivoted solve (`super::damped`).

/// Coefficients held (degree ≤ 10: a degree-4 cofactor times a degree-6 determinant in `s`).
pub(crate) const CAP: usize = 11;
/// Largest degree whose real roots [`sign_changes`] isolates.
pub(crate) const MAX_DEG: usize = 5;

/// `Σ c[k]·s^k`, coefficients ascending; `len` of them are used.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Poly {
    pub c: [f64; CAP],
    pub len: usize,
}

impl Poly {
    pub const ZERO: Poly = Poly {
        c: [0.0; CAP],
        len: 0,
    };
    pub const ONE: Poly = Poly {
        c: [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        len: 1,
    };

    /// `a + b·s + c·s²`.
    pub fn quadratic(a: f64, b: f64, c: f64) -> Poly {
        let mut p = Poly::ZERO;
        p.c[0] = a;
        p.c[1] = b;
        p.c[2] = c;
        p.len = 3;
        p
    }

    pub fn coefficients(&self) -> &[f64] {
        self.c.get(..self.len).unwrap_or(&[])
    }

    /// `self·o`; terms beyond the capacity are dropped (never reached: degrees ≤ 10).
    #[inline(never)]
    pub fn mul(&self, o: &Poly) -> Poly {
        let mut r = Poly::ZERO;
        for (i, &a) in self.coefficients().iter().enumerate() {
            for (j, &b) in o.coefficients().iter().enumerate() {
                if let Some(x) = r.c.get_mut(i + j) {
                    *x += a * b;
                }
            }
        }
        r.len = (self.len + o.len).saturating_sub(1).min(CAP);
        r
    }

    /// `self + sign·o`.
    pub fn add_scaled(&self, o: &Poly, sign: f64) -> Poly {
        let mut r = *self;
        for (x, &b) in r.c.iter_mut().zip(o.coefficients()) {
            *x += sign * b;
        }
        r.len = self.len.max(o.len);
        r
    }

    /// `p(−s)`.
    pub fn reflect(&self) -> Poly {
        let mut r = *self;
        for x in r.c.iter_mut().skip(1).step_by(2) {
            *x = -*x;
        }
        r
    }

    /// The even part `Σ c[2j]·s^{2j}` at `s = iω`, as a polynomial in `x = ω²`:
    /// `Σ c[2j]·(−x)^j`.
    pub fn even_at_i_omega(&self) -> Poly {
        let mut r = Poly::ZERO;
        for (j, x) in r.c.iter_mut().enumerate() {
            let v = self.c.get(2 * j).copied().unwrap_or(0.0);
            *x = if j % 2 == 0 { v } else { -v };
        }
        r.len = self.len.div_ceil(2);
        r
    }

    /// Like [`Poly::even_at_i_omega`] with every term's absolute value: `Σ |c[2j]|·x^j`.
    pub fn even_abs(&self) -> Poly {
        let mut r = Poly::ZERO;
        for (j, x) in r.c.iter_mut().enumerate() {
            *x = libm::fabs(self.c.get(2 * j).copied().unwrap_or(0.0));
        }
        r.len = self.len.div_ceil(2);
        r
    }
}

/// `p(x)` by Horner's rule.
#[inline(never)]
pub(crate) fn eval(p: &[f64], x: f64) -> f64 {
    p.iter().rev().fold(0.0, |acc, &c| acc * x + c)
}

/// `(p(x), p'(x))` by Horner's rule.
#[inline(never)]
pub(crate) fn eval_d(p: &[f64], x: f64) -> (f64, f64) {
    let mut v = 0.0;
    let mut d = 0.0;
    for &c in p.iter().rev() {
        d = d * x + v;
        v = v * x + c;
    }
    (v, d)
}

/// `(p(x), p'(x), p''(x))` by Horner's rule.
#[inline(never)]
pub(crate) fn eval_dd(p: &[f64], x: f64) -> (f64, f64, f64) {
    let mut v = 0.0;
    let mut d = 0.0;
    let mut dd = 0.0;
    for &c in p.iter().rev() {
        dd = dd * x + d;
        d = d * x + v;
        v = v * x + c;
    }
    (v, d, 2.0 * dd)
}

/// The real roots of odd multiplicity (sign changes) of a polynomial of degree ≤ 5 in an
/// interval, ascending, and the sign changes of its derivative there (its local extrema).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct RealRoots {
    pub roots: [f64; MAX_DEG],
    pub n_roots: usize,
    pub extrema: [f64; MAX_DEG],
    pub n_extrema: usize,
}

impl RealRoots {
    pub fn roots(&self) -> &[f64] {
        self.roots.get(..self.n_roots).unwrap_or(&[])
    }
    pub fn extrema(&self) -> &[f64] {
        self.extrema.get(..self.n_extrema).unwrap_or(&[])
    }
}

/// All roots of `p` (degree `d ≤ 5`) when they are real, simple and each near one of `d`
/// hints: Newton's iteration from every hint, then a certificate that nothing was missed —
/// the sign of `p` alternates across the `d + 1` points between and beyond the roots found,
/// which makes `d` sign changes, as many as a degree-`d` polynomial has roots. `None` if
/// an iteration fails to converge, two meet the same root, or the signs do not alternate
/// (then [`sign_changes`] isolates the roots from the derivatives). For a lightly damped
/// machine, with the undamped characteristic speeds as hints, this costs a few Newton steps
/// per root instead of the isolation of every derivative's roots.
#[inline(never)]
pub(crate) fn roots_near(p: &[f64], hints: &[f64], precision: f64) -> Option<RealRoots> {
    let mut deg = p.len().min(MAX_DEG + 1);
    while deg > 0 && p.get(deg - 1).copied().unwrap_or(0.0) == 0.0 {
        deg -= 1;
    }
    let d = deg.checked_sub(1)?;
    if d == 0 || hints.len() != d {
        return None;
    }
    let rel = precision.max(8.0 * f64::EPSILON);
    let mut out = RealRoots {
        roots: [0.0; MAX_DEG],
        n_roots: 0,
        extrema: [0.0; MAX_DEG],
        n_extrema: 0,
    };
    for (slot, &h) in out.roots.iter_mut().zip(hints) {
        let mut x = h;
        let mut converged = false;
        for _ in 0..40 {
            let (v, dv) = eval_d(p, x);
            let step = v / dv;
            let next = x - step;
            if !(next > 0.0 && next.is_finite()) {
                return None;
            }
            x = next;
            if libm::fabs(step) <= rel * x {
                converged = true;
                break;
            }
        }
        if !converged {
            return None;
        }
        *slot = x;
    }
    let roots = out.roots.get_mut(..d)?;
    for i in 1..d {
        let mut j = i;
        while j > 0 && roots[j - 1] > roots[j] {
            roots.swap(j - 1, j);
            j -= 1;
        }
    }
    // Alternating signs at 0 (p(0) is the constant term), between the roots, and beyond.
    let mut sign = p.first().copied().unwrap_or(0.0);
    if sign == 0.0 {
        return None;
    }
    for i in 0..=d {
        let x = match i {
            0 => 0.5 * roots[0],
            i if i < d => libm::sqrt(roots[i - 1]) * libm::sqrt(roots[i]),
            _ => 2.0 * roots[d - 1],
        };
        let v = eval(p, x);
        let expect_positive = if i % 2 == 0 { sign > 0.0 } else { sign < 0.0 };
        if i > 0 && roots[i - 1] >= x || v == 0.0 || (v > 0.0) != expect_positive {
            return None;
        }
        if i == 0 {
            sign = v;
        }
    }
    out.n_roots = d;
    Some(out)
}

/// Relative precision of the derivatives' sign changes (the ends of the monotone pieces):
/// an error `δ` there changes `p` by `p''·δ²/2`, far below its own rounding at `1e-10`.
const PIECE_PRECISION: f64 = 1e-10;

/// Sign changes of `p` (ascending coefficients, trailing zeros allowed, degree ≤ 5 used) in
/// `(lo, hi)`, `0 < lo < hi`, by isolation on the derivatives: the sign changes of `p^(k+1)`
/// split `(lo, hi)` into pieces on which `p^(k)` is monotone, so each piece holds at most one
/// sign change of `p^(k)`, found by a bracketed Newton iteration. Exact in exact arithmetic,
/// whatever the spacing of the roots; in floating point a cluster of roots closer than the
/// polynomial's own rounding may show as fewer sign changes (the caller polishes and checks
/// every candidate on the stable solve). `hints`: ascending points near which the roots are
/// expected (iterations start there); `precision`: relative precision of `p`'s own roots
/// (at least `4·ε`).
#[inline(never)]
pub(crate) fn sign_changes(
    p: &[f64],
    lo: f64,
    hi: f64,
    hints: &[f64],
    precision: f64,
) -> RealRoots {
    let mut deg = p.len().min(MAX_DEG + 1);
    while deg > 0 && p.get(deg - 1).copied().unwrap_or(0.0) == 0.0 {
        deg -= 1;
    }
    let mut out = RealRoots {
        roots: [0.0; MAX_DEG],
        n_roots: 0,
        extrema: [0.0; MAX_DEG],
        n_extrema: 0,
    };
    if deg < 2 {
        return out;
    }
    // derivs[k] = p^(k), coefficients ascending (degree deg − 1 − k).
    let mut derivs = [[0.0f64; MAX_DEG + 1]; MAX_DEG + 1];
    for (d, &c) in derivs[0].iter_mut().zip(p.iter().take(deg)) {
        *d = c;
    }
    for k in 1..deg {
        let prev = derivs[k - 1];
        for (i, d) in derivs[k].iter_mut().enumerate().take(deg - k) {
            *d = prev.get(i + 1).copied().unwrap_or(0.0) * (i + 1) as f64;
        }
    }
    let precision = precision.max(4.0 * f64::EPSILON);
    // Roots of the previous (higher) derivative level, ascending.
    let mut crit = [0.0f64; MAX_DEG];
    let mut n_crit = 0usize;
    // The highest derivative with a root is linear: level deg − 2.
    for k in (0..deg - 1).rev() {
        let q = derivs[k].get(..deg - k).unwrap_or(&[]);
        // The pieces' ends: lo, the sign changes of q', hi, with q's values there.
        let mut pts = [(0.0f64, 0.0f64); MAX_DEG + 2];
        let n_pts = n_crit + 2;
        for (i, pt) in pts.iter_mut().enumerate().take(n_pts) {
            let x = match i {
                0 => lo,
                i if i <= n_crit => crit[i - 1],
                _ => hi,
            };
            *pt = (x, eval(q, x));
        }
        let rel = if k == 0 { precision } else { PIECE_PRECISION };
        let mut found = [0.0f64; MAX_DEG];
        let mut n_found = 0usize;
        for i in 1..n_pts {
            let (a, fa) = pts[i - 1];
            let (b, fb) = pts[i];
            let root = if fa != 0.0 && fb != 0.0 && (fa < 0.0) != (fb < 0.0) {
                // Start from the middle hint inside the piece: for light damping the roots
                // of p sit near the hints and those of its derivatives between them.
                let mut inside = hints.iter().copied().filter(|&h| h > a && h < b);
                let count = inside.clone().count();
                let start = inside.nth(count / 2);
                Some(bracketed_newton(q, (a, fa), (b, fb), start, rel))
            } else if fb == 0.0 && i + 1 < n_pts {
                // q vanishes exactly at an inner end: a sign change only if q has opposite
                // signs on the two pieces meeting there (q is monotone on each).
                let after = pts[i + 1].1;
                (fa != 0.0 && after != 0.0 && (fa < 0.0) != (after < 0.0)).then_some(b)
            } else {
                None
            };
            if let (Some(r), Some(slot)) = (root, found.get_mut(n_found)) {
                *slot = r;
                n_found += 1;
            }
        }
        if k == 0 {
            out.roots = found;
            out.n_roots = n_found;
            out.extrema = crit;
            out.n_extrema = n_crit;
        }
        crit = found;
        n_crit = n_found;
    }
    out
}

/// The root of `q` in `[a, b]`, `0 < a < b`, where `q` is monotone and changes sign (the
/// brackets carry `q`'s values), to relative precision `rel`, starting from `start` if it lies
/// inside: Newton steps kept inside the shrinking bracket; when a step would leave it, an
/// Illinois (regula falsi) step on the bracket, or a bisection (geometric while the bracket
/// spans more than a factor 4: the roots of a physical machine span decades) if that is not a
/// number inside.
#[inline(never)]
fn bracketed_newton(
    q: &[f64],
    (mut a, mut fa): (f64, f64),
    (mut b, mut fb): (f64, f64),
    start: Option<f64>,
    rel: f64,
) -> f64 {
    let inside = |x: f64, a: f64, b: f64| x > a && x < b;
    let a_negative = fa < 0.0;
    // Illinois: the value of the end kept twice in a row is halved.
    let mut kept = 0i8;
    let fallback = |a: f64, fa: f64, b: f64, fb: f64| {
        let x = a - fa * ((b - a) / (fb - fa));
        if inside(x, a, b) {
            x
        } else if b > 4.0 * a {
            libm::sqrt(a) * libm::sqrt(b)
        } else {
            a + 0.5 * (b - a)
        }
    };
    let mut x = match start {
        Some(x) if inside(x, a, b) => x,
        _ => fallback(a, fa, b, fb),
    };
    for _ in 0..200 {
        let (v, d) = eval_d(q, x);
        if v == 0.0 {
            return x;
        }
        if (v < 0.0) == a_negative {
            a = x;
            fa = v;
            if kept == 1 {
                fb *= 0.5;
            }
            kept = 1;
        } else {
            b = x;
            fb = v;
            if kept == -1 {
                fa *= 0.5;
            }
            kept = -1;
        }
        if b - a <= rel * b {
            break;
        }
        let step = v / d;
        let next = x - step;
        x = if inside(next, a, b) {
            if libm::fabs(step) <= rel * libm::fabs(x) {
                return next;
            }
            next
        } else {
            fallback(a, fa, b, fb)
        };
    }
    a + 0.5 * (b - a)
}

/// A lower bound on the moduli of the nonzero roots and an upper bound on all roots' moduli of
/// `p` (Cauchy): `|p0|/(|p0| + max|p_i|)` and `1 + max|p_i/p_d|`; `None` if `p(0) = 0` or the
/// degree is below one.
pub(crate) fn root_bounds(p: &[f64]) -> Option<(f64, f64)> {
    let mut deg = p.len();
    while deg > 0 && p.get(deg - 1).copied().unwrap_or(0.0) == 0.0 {
        deg -= 1;
    }
    let lead = libm::fabs(p.get(deg.checked_sub(1)?).copied().unwrap_or(0.0));
    let c0 = libm::fabs(p.first().copied().unwrap_or(0.0));
    if deg < 2 || c0 == 0.0 {
        return None;
    }
    let rest = p.get(1..deg).unwrap_or(&[]);
    let max_hi = p
        .get(..deg - 1)
        .unwrap_or(&[])
        .iter()
        .fold(0.0f64, |m, &c| m.max(libm::fabs(c) / lead));
    let max_lo = rest.iter().fold(0.0f64, |m, &c| m.max(libm::fabs(c)));
    Some((c0 / (c0 + max_lo), 1.0 + max_hi))
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;
    use std::vec::Vec;

    fn from_roots(roots: &[f64], lead: f64) -> Vec<f64> {
        let mut c = std::vec![lead];
        for &r in roots {
            let mut next = std::vec![0.0; c.len() + 1];
            for (i, &a) in c.iter().enumerate() {
                next[i + 1] += a;
                next[i] -= r * a;
            }
            c = next;
        }
        c
    }

    #[test]
    fn isolates_separated_and_clustered_roots() {
        // Distinct roots over six decades, relative accuracy 1e-14.
        let want = [1e-3, 0.37, 2.0, 55.0, 900.0];
        let p = from_roots(&want, -3.0);
        let r = sign_changes(&p, 1e-6, 1e4, &[], 0.0);
        assert_eq!(r.roots().len(), 5, "{r:?}");
        for (g, w) in r.roots().iter().zip(want) {
            assert!((g - w).abs() <= 1e-13 * w, "{g} vs {w}");
        }
        // A double root is no sign change; a triple root is one.
        let p = from_roots(&[1.0, 1.0, 3.0], 1.0);
        let r = sign_changes(&p, 0.1, 10.0, &[], 0.0);
        assert_eq!(r.roots().len(), 1, "{r:?}");
        assert!((r.roots()[0] - 3.0).abs() < 1e-12);
        let p = from_roots(&[2.0, 2.0, 2.0, 5.0], 1.0);
        let r = sign_changes(&p, 0.1, 10.0, &[], 0.0);
        assert_eq!(r.roots().len(), 2, "{r:?}");
        assert!((r.roots()[0] - 2.0).abs() < 1e-4);
        // Roots 1e-7 apart (relative) are still told apart.
        let p = from_roots(&[1.0, 1.0 + 1e-7, 4.0], 1.0);
        let r = sign_changes(&p, 0.1, 10.0, &[], 0.0);
        assert_eq!(r.roots().len(), 3, "{r:?}");
        assert_eq!(r.extrema().len(), 2, "{r:?}");
    }

    #[test]
    fn bounds_enclose_the_roots() {
        let p = from_roots(&[1e-3, 2.0, 900.0], 5.0);
        let (lo, hi) = root_bounds(&p).unwrap();
        assert!(lo <= 1e-3 && hi >= 900.0, "{lo} {hi}");
        assert_eq!(root_bounds(&[0.0, 1.0, 1.0]), None);
    }

    #[test]
    fn roots_near_hints_are_certified_or_refused() {
        // Five real roots, hints 1 % off: all found to 1e-14 and certified.
        let want = [0.01, 0.37, 2.0, 2.2, 55.0];
        let p = from_roots(&want, -0.5);
        let hints: Vec<f64> = want.iter().map(|w| w * 1.01).collect();
        let r = roots_near(&p, &hints, 1e-15).unwrap();
        assert_eq!(r.roots().len(), 5);
        for (g, w) in r.roots().iter().zip(want) {
            assert!((g - w).abs() <= 1e-14 * w, "{g} vs {w}");
        }
        // The same as the isolation finds.
        let iso = sign_changes(&p, 1e-3, 1e3, &hints, 1e-15);
        for (a, b) in r.roots().iter().zip(iso.roots()) {
            assert!((a - b).abs() <= 1e-14 * b, "{a} vs {b}");
        }
        // Two hints running into one root: refused.
        let p = from_roots(&[1.0, 3.0, 5.0], 1.0);
        assert!(roots_near(&p, &[1.0, 1.01, 5.0], 1e-15).is_none());
        // A complex pair (x² + 1)·(x − 2): only one real root, refused.
        let p = [-2.0, 1.0, -2.0, 1.0];
        assert!(roots_near(&p, &[0.5, 1.0, 2.0], 1e-15).is_none());
        // Wrong number of hints: refused.
        assert!(roots_near(&[1.0, -1.0, 0.25], &[2.0], 1e-15).is_none());
    }
}
