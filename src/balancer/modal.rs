//! Mass, stiffness and damping matrices; undamped resonant and additional speeds.
//!
//! Resonant speeds are the eigenfrequencies of `(K, M)`; additional speeds are those of the
//! system with the exciter platform held fixed (the zeros of its driving-point receptance).
//!
//! * One platform: `√(k/M_Σ)` (seed eq. 8, 12).
//! * Two degrees of freedom (two-platform resonances, three-platform additional speeds):
//!   the quadratic `λ² − b·λ + c` of seed eq. 34–36 / 56–59 with every coefficient written
//!   as a sum of positive terms (`c` from the corrected eq. 57, `d = b² − 4c` from the
//!   corrected eq. 59), the large root `(b + √d)/2` and the small root by Vieta.
//! * Three platforms: the cubic in `q²` is not solved as a cubic. Its roots are the
//!   eigenvalues of the symmetric `A = M^{-1/2}·K·M^{-1/2}`, found by cyclic Jacobi
//!   rotations. A symmetric eigenproblem is perfectly conditioned for (nearly) equal roots,
//!   where a cubic's roots lose half their digits, zero coupling is a diagonal matrix
//!   (returned exactly), and with the stopping rule `|a_pq| ≤ ε·√(a_pp·a_qq)` Jacobi is
//!   accurate relative to each eigenvalue for graded matrices (Demmel & Veselić 1992): the
//!   relevant condition number is that of `diag(K)^{-1/2}·K·diag(K)^{-1/2}`, which does not
//!   depend on the masses, so a 1e6 mass ratio costs nothing.

use super::complex::{Cx, Real, C64};
use super::poly::Poly;
use super::{MachineConfig, MAX_PLATFORMS};

/// The machine as matrices (SI units), plus the raw support and coupling values that the
/// positive-sum closed forms use.
#[derive(Debug, Clone, Copy)]
pub(crate) struct System {
    pub n: usize,
    pub e: usize,
    pub m: [f64; MAX_PLATFORMS],
    /// Support stiffness and damping to the ground.
    pub ks: [f64; MAX_PLATFORMS],
    pub cs: [f64; MAX_PLATFORMS],
    /// Coupling stiffness and damping (symmetric, zero diagonal).
    pub kc: [[f64; MAX_PLATFORMS]; MAX_PLATFORMS],
    pub cc: [[f64; MAX_PLATFORMS]; MAX_PLATFORMS],
}

impl System {
    pub fn new(cfg: &MachineConfig) -> Self {
        let mut s = System {
            n: cfg.platforms().len().min(MAX_PLATFORMS),
            e: cfg.exciter_index() % MAX_PLATFORMS,
            m: [0.0; MAX_PLATFORMS],
            ks: [0.0; MAX_PLATFORMS],
            cs: [0.0; MAX_PLATFORMS],
            kc: [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS],
            cc: [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS],
        };
        for (i, p) in cfg.platforms().iter().enumerate().take(MAX_PLATFORMS) {
            s.m[i] = cfg.moving_mass(i);
            s.ks[i] = p.stiffness;
            s.cs[i] = p.damping;
        }
        for c in cfg.couplings() {
            let [a, b] = c.indices();
            s.kc[a][b] = c.stiffness;
            s.kc[b][a] = c.stiffness;
            s.cc[a][b] = c.damping;
            s.cc[b][a] = c.damping;
        }
        s
    }

    /// Stiffness matrix entry `K_ij`.
    pub fn k(&self, i: usize, j: usize) -> f64 {
        if i == j {
            self.ks[i] + self.kc[i].iter().sum::<f64>()
        } else {
            -self.kc[i][j]
        }
    }

    /// Damping matrix entry `C_ij`.
    pub fn c(&self, i: usize, j: usize) -> f64 {
        if i == j {
            self.cs[i] + self.cc[i].iter().sum::<f64>()
        } else {
            -self.cc[i][j]
        }
    }

    /// The platforms other than the exciter, ascending.
    pub fn others(&self) -> ([usize; 2], usize) {
        let mut o = [0usize; 2];
        let mut n = 0;
        for i in 0..self.n {
            if i != self.e && n < 2 {
                o[n] = i;
                n += 1;
            }
        }
        (o, n)
    }

    /// Undamped resonant speeds, ascending, rad/s.
    pub fn resonant_speeds(&self) -> ([f64; MAX_PLATFORMS], usize) {
        let mut out = [0.0; MAX_PLATFORMS];
        match self.n {
            1 => out[0] = libm::sqrt(self.ks[0] / self.m[0]),
            2 => {
                let (lo, hi) = two_dof(self.ks[0], self.ks[1], self.kc[0][1], self.m[0], self.m[1]);
                out[0] = libm::sqrt(lo);
                out[1] = libm::sqrt(hi);
            }
            _ => {
                let mut a = [[0.0; 3]; 3];
                for (i, row) in a.iter_mut().enumerate() {
                    for (j, x) in row.iter_mut().enumerate() {
                        *x = self.k(i, j) / libm::sqrt(self.m[i] * self.m[j]);
                    }
                }
                let l = jacobi3(a);
                for (o, x) in out.iter_mut().zip(l) {
                    *o = libm::sqrt(x);
                }
            }
        }
        (out, self.n)
    }

    /// Undamped additional speeds (antiresonances of the exciter platform), ascending, rad/s.
    pub fn additional_speeds(&self) -> ([f64; MAX_PLATFORMS - 1], usize) {
        let mut out = [0.0; MAX_PLATFORMS - 1];
        let e = self.e;
        let ([a, b], n) = self.others();
        match n {
            1 => out[0] = libm::sqrt((self.ks[a] + self.kc[a][e]) / self.m[a]),
            2 => {
                // With the exciter held fixed, its couplings act as supports of a and b.
                let (lo, hi) = two_dof(
                    self.ks[a] + self.kc[a][e],
                    self.ks[b] + self.kc[b][e],
                    self.kc[a][b],
                    self.m[a],
                    self.m[b],
                );
                out[0] = libm::sqrt(lo);
                out[1] = libm::sqrt(hi);
            }
            _ => {}
        }
        (out, n)
    }

    /// Dynamic stiffness `Z(ω) = K − ω²M + iωC` entry.
    #[cfg(test)]
    pub fn z(&self, i: usize, j: usize, w: f64) -> C64 {
        let m = if i == j { self.m[i] } else { 0.0 };
        C64::new(self.k(i, j) - w * w * m, w * self.c(i, j))
    }

    /// Driving-point receptance `H_ee(ω) = [Z(ω)⁻¹]_ee`, m/N: the exciter's entry of the
    /// solution of `Z·y = e_e`, by complex Gaussian elimination with partial pivoting (see
    /// [`Solver::receptance`]).
    pub fn receptance(&self, w: f64) -> C64 {
        Solver::new(self).receptance(w)
    }

    /// `Re H_ee(ω)`: positive where the loads gather, negative where balancing is stable.
    /// Stability: taken from the pivoted solve, which is backward stable, so its sign changes
    /// lie within rounding of a nearby machine's poles and zeros, never from the determinant
    /// form `Re(det Z_oo·conj(det Z))`, which has a triple root where a double pole cancels
    /// against a zero (equal partial frequencies) and loses two thirds of its digits there.
    pub fn criterion(&self, w: f64) -> f64 {
        self.receptance(w).re
    }

    /// The same system with masses divided by `m_s`, stiffness by `k_s` and damping by
    /// `√(k_s·m_s)`: speeds in units of `√(k_s/m_s)`, receptance in units of `1/k_s`.
    pub fn scaled(&self, k_s: f64, m_s: f64) -> System {
        let c_s = libm::sqrt(k_s * m_s);
        let mut s = *self;
        for i in 0..MAX_PLATFORMS {
            s.m[i] /= m_s;
            s.ks[i] /= k_s;
            s.cs[i] /= c_s;
            for j in 0..MAX_PLATFORMS {
                s.kc[i][j] /= k_s;
                s.cc[i][j] /= c_s;
            }
        }
        s
    }
}

impl System {
    /// The numerator of `Re H_ee` over `|det Z|²` as a real polynomial in `x = ω²`, and a
    /// bound on its rounding.
    ///
    /// With `s = iω` every entry of `Z = K + s·C + s²·M` is a real quadratic in `s`, so the
    /// cofactor `N(s) = det Z_oo` and `Δ(s) = det Z` are real polynomials in `s` and
    /// `H_ee = N/Δ = N(s)·Δ(−s)/|Δ|²` (`conj s = −s`). `Re H_ee`'s numerator is the even part of
    /// `N(s)·Δ(−s)`: degree `2·n − 1` in `x`, positive at 0 (`det K_oo·det K`), negative
    /// leading coefficient (`−Π M_o·Π M`). With `bound`, the same expansion with every term's
    /// absolute value instead (`|K|`, `|C|`, `M`, sums for differences): `b` with
    /// `64·ε·b(x)` bounding the rounding of `p(x)` as computed here.
    pub fn re_numerator(&self, bound: bool) -> Poly {
        let ([a0, a1], n_others) = self.others();
        let order = match n_others {
            0 => [self.e, 0, 0],
            1 => [a0, self.e, 0],
            _ => [a0, a1, self.e],
        };
        let n = n_others.min(2) + 1;
        let z = |i: usize, j: usize, abs: bool| {
            let (ri, cj) = (order[i % 3], order[j % 3]);
            let m = if ri == cj { self.m[ri] } else { 0.0 };
            let (k, c) = (self.k(ri, cj), self.c(ri, cj));
            if abs {
                Poly::quadratic(libm::fabs(k), libm::fabs(c), m)
            } else {
                Poly::quadratic(k, c, m)
            }
        };
        let both = |abs: bool| {
            let sign = if abs { 1.0 } else { -1.0 };
            // det of the symmetric 2×2 block (i, j): z_ii·z_jj − z_ij².
            let det2 = |i: usize, j: usize| {
                z(i, i, abs)
                    .mul(&z(j, j, abs))
                    .add_scaled(&z(i, j, abs).mul(&z(i, j, abs)), sign)
            };
            let (cof, det) = match n {
                1 => (Poly::ONE, z(0, 0, abs)),
                2 => (z(0, 0, abs), det2(0, 1)),
                _ => {
                    // Expansion along the first row of the symmetric 3×3.
                    let m12 = z(0, 1, abs)
                        .mul(&z(2, 2, abs))
                        .add_scaled(&z(1, 2, abs).mul(&z(0, 2, abs)), sign);
                    let m13 = z(0, 1, abs)
                        .mul(&z(1, 2, abs))
                        .add_scaled(&z(1, 1, abs).mul(&z(0, 2, abs)), sign);
                    let det = z(0, 0, abs)
                        .mul(&det2(1, 2))
                        .add_scaled(&z(0, 1, abs).mul(&m12), sign)
                        .add_scaled(&z(0, 2, abs).mul(&m13), 1.0);
                    (det2(0, 1), det)
                }
            };
            if abs {
                cof.mul(&det)
            } else {
                cof.mul(&det.reflect())
            }
        };
        if bound {
            both(true).even_abs()
        } else {
            both(false).even_at_i_omega()
        }
    }
}

/// The dynamic stiffness of a machine, ordered with the exciter last and its matrices
/// assembled once, for repeated solves at configuration time (f64) and for the capture scan
/// (f32, see [`Solver::narrowed`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Solver<T> {
    k: [[T; MAX_PLATFORMS]; MAX_PLATFORMS],
    c: [[T; MAX_PLATFORMS]; MAX_PLATFORMS],
    m: [T; MAX_PLATFORMS],
}

impl Solver<f64> {
    /// The machine's `K`, `C`, `M` with the exciter last. Fewer than three platforms are
    /// padded in front with unit-stiffness, massless, undamped rows that nothing couples to:
    /// elimination passes over them without touching the others (their multipliers are
    /// zero), so one 3×3 solve serves every machine.
    pub fn new(sys: &System) -> Self {
        let ([a0, a1], n_others) = sys.others();
        let n = n_others.min(2) + 1;
        let pad = MAX_PLATFORMS - n;
        let order = match n_others {
            0 => [sys.e, 0, 0],
            1 => [a0, sys.e, 0],
            _ => [a0, a1, sys.e],
        };
        let mut s = Solver {
            k: [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS],
            c: [[0.0; MAX_PLATFORMS]; MAX_PLATFORMS],
            m: [0.0; MAX_PLATFORMS],
        };
        for i in 0..pad {
            s.k[i][i] = 1.0;
        }
        for (i, &ri) in order.iter().enumerate().take(n) {
            s.m[pad + i] = sys.m[ri];
            for (j, &cj) in order.iter().enumerate().take(n) {
                s.k[pad + i][pad + j] = sys.k(ri, cj);
                s.c[pad + i][pad + j] = sys.c(ri, cj);
            }
        }
        s
    }

    /// The same solver in f32 (entries rounded; a scaled system's entries are within f32's
    /// range for any machine of physical proportions).
    pub fn narrowed(&self) -> Solver<f32> {
        Solver {
            k: self.k.map(|r| r.map(|x| x as f32)),
            c: self.c.map(|r| r.map(|x| x as f32)),
            m: self.m.map(|x| x as f32),
        }
    }
}

impl<T: Real> Solver<T> {
    /// Forward elimination of `Z(w)·y = e_e` with partial pivoting (`N = 3`: padded rows for
    /// fewer platforms, see [`Solver::new`]).
    fn eliminate<const N: usize>(&self, w: T) -> ([[Cx<T>; N]; N], [Cx<T>; N]) {
        let mut a = [[Cx::ZERO; N]; N];
        let w2 = w * w;
        for (i, (row, (k, c))) in a.iter_mut().zip(self.k.iter().zip(&self.c)).enumerate() {
            for (j, (x, (&kij, &cij))) in row.iter_mut().zip(k.iter().zip(c)).enumerate() {
                let re = if i == j { kij - w2 * self.m[i] } else { kij };
                *x = Cx::new(re, w * cij);
            }
        }
        let mut y = [Cx::ZERO; N];
        if let Some(last) = y.last_mut() {
            *last = Cx::ONE;
        }
        for p in 0..N.saturating_sub(1) {
            let mut piv = p;
            for i in p + 1..N {
                if a[i][p].norm_sq() > a[piv][p].norm_sq() {
                    piv = i;
                }
            }
            a.swap(p, piv);
            y.swap(p, piv);
            let inv = a[p][p].recip();
            let (pivot_row, yp) = (a[p], y[p]);
            let rhs = yp != Cx::ZERO;
            for i in p + 1..N {
                let l = a[i][p] * inv;
                for (x, &u) in a[i].iter_mut().zip(&pivot_row).skip(p + 1) {
                    *x = *x - l * u;
                }
                if rhs {
                    y[i] = y[i] - l * yp;
                }
            }
        }
        (a, y)
    }

    fn receptance_n<const N: usize>(&self, w: T) -> Cx<T> {
        let (a, y) = self.eliminate::<N>(w);
        match (y.last(), a.last().and_then(|r| r.last())) {
            (Some(&y), Some(&d)) => y.div(d),
            _ => Cx::ZERO,
        }
    }

    /// Driving-point receptance `H_ee(w) = [Z(w)⁻¹]_ee`: the exciter's entry of the solution
    /// of `Z·y = e_e`, by complex Gaussian elimination with partial pivoting. The exciter is
    /// ordered last, so its unknown is the last pivot's quotient (no back substitution).
    /// Stability: the pivoted solve is backward stable, so the sign changes of `Re H_ee` it
    /// gives lie within rounding of a nearby machine's poles and zeros; the determinant form
    /// `Re(det Z_oo·conj(det Z))` has a triple root where a double pole cancels against a zero
    /// (equal partial frequencies) and loses two thirds of its digits there.
    #[inline(never)]
    pub fn receptance(&self, w: T) -> Cx<T> {
        self.receptance_n::<MAX_PLATFORMS>(w)
    }

    fn receptance_slope_n<const N: usize>(&self, w: T) -> (Cx<T>, T) {
        let (a, rhs) = self.eliminate::<N>(w);
        let mut y = [Cx::ZERO; N];
        for i in (0..N).rev() {
            let mut s = rhs[i];
            for (&aij, &yj) in a[i].iter().zip(&y).skip(i + 1) {
                s = s - aij * yj;
            }
            y[i] = s.div(a[i][i]);
        }
        // yᵀ·Z'·y = −2w·Σ m_i·y_i² + i·Σ c_ij·y_i·y_j, and Im(dH/dw) = Im(−yᵀ·Z'·y)
        // = 2w·Σ m_i·Im(y_i²) − Σ c_ij·Re(y_i·y_j), with C symmetric.
        let two_w = w + w;
        let mut mass = T::ZERO;
        let mut damp = T::ZERO;
        for i in 0..N {
            let (re, im) = (y[i].re, y[i].im);
            mass = mass + self.m[i] * (re * im + re * im);
            let mut cy = self.c[i][i] * (re * re - im * im);
            for (&cij, yj) in self.c[i].iter().zip(&y).skip(i + 1) {
                cy = cy + (cij + cij) * (re * yj.re - im * yj.im);
            }
            damp = damp + cy;
        }
        (y.last().copied().unwrap_or(Cx::ZERO), two_w * mass - damp)
    }

    /// `(H_ee(w), Im dH_ee/dw)`. With `y = Z⁻¹·e_e` (back substitution after the same
    /// elimination) and `Z` symmetric, `dH_ee/dw = −yᵀ·Z'(w)·y`, `Z' = −2w·M + i·C`.
    #[inline(never)]
    pub fn receptance_slope(&self, w: T) -> (Cx<T>, T) {
        self.receptance_slope_n::<MAX_PLATFORMS>(w)
    }
}

/// Eigenvalues `(lo, hi)` of two masses with supports `sa`, `sb` and coupling `kab`:
/// `λ² − bλ + c = 0` with `b = pa + pb`, `c = (sa·(sb + kab) + kab·sb)/(ma·mb)`,
/// `d = (pa − pb)² + 4·kab²/(ma·mb)`, `pa = (sa + kab)/ma`, `pb = (sb + kab)/mb`.
fn two_dof(sa: f64, sb: f64, kab: f64, ma: f64, mb: f64) -> (f64, f64) {
    let pa = (sa + kab) / ma;
    let pb = (sb + kab) / mb;
    let b = pa + pb;
    let c = (sa * (sb + kab) / ma + kab * sb / ma) / mb;
    let g = kab / libm::sqrt(ma * mb);
    let d = (pa - pb) * (pa - pb) + 4.0 * g * g;
    let hi = 0.5 * (b + libm::sqrt(d));
    // Numerical stability: c and d are sums of positive terms and the small root is c/hi
    // (Vieta), never (b − √d)/2, which cancels when the roots are far apart.
    (c / hi, hi)
}

/// Eigenvalues of a symmetric 3×3 matrix, ascending, by cyclic Jacobi rotations with the
/// relative stopping rule `|a_pq| ≤ ε·√(|a_pp·a_qq|)`.
pub(crate) fn jacobi3(mut a: [[f64; 3]; 3]) -> [f64; 3] {
    const PAIRS: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];
    for _sweep in 0..50 {
        let mut rotated = false;
        for &(p, q) in &PAIRS {
            let apq = a[p][q];
            if libm::fabs(apq) <= f64::EPSILON * libm::sqrt(libm::fabs(a[p][p] * a[q][q])) {
                a[p][q] = 0.0;
                a[q][p] = 0.0;
                continue;
            }
            rotated = true;
            let theta = (a[q][q] - a[p][p]) / (2.0 * apq);
            // t = tan of the rotation angle, the smaller root of t² + 2θt − 1 = 0.
            let t = if libm::fabs(theta) > 1e150 {
                0.5 / theta
            } else {
                let s = libm::sqrt(theta * theta + 1.0);
                let t = 1.0 / (libm::fabs(theta) + s);
                if theta < 0.0 {
                    -t
                } else {
                    t
                }
            };
            let c = 1.0 / libm::sqrt(t * t + 1.0);
            let s = t * c;
            let r = 3 - p - q;
            a[p][p] -= t * apq;
            a[q][q] += t * apq;
            a[p][q] = 0.0;
            a[q][p] = 0.0;
            let arp = a[r][p];
            let arq = a[r][q];
            a[r][p] = c * arp - s * arq;
            a[p][r] = a[r][p];
            a[r][q] = s * arp + c * arq;
            a[q][r] = a[r][q];
        }
        if !rotated {
            break;
        }
    }
    let mut l = [a[0][0], a[1][1], a[2][2]];
    // Sort three values ascending without a library sort.
    if l[0] > l[1] {
        l.swap(0, 1);
    }
    if l[1] > l[2] {
        l.swap(1, 2);
    }
    if l[0] > l[1] {
        l.swap(0, 1);
    }
    l
}
