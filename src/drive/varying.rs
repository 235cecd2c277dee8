//! The steady state with a reduced inertia that depends on the shaft angle,
//! `J(φ) = J0 + Σ a_k·cos(n_k·φ + ψ_k)` (a crank mechanism; seed 000, eq. 1).
//!
//! ## Derivation
//! Eq. 1, `J(φ)·ω·dω/dφ + ½·ω²·dJ/dφ = A·ω² + B − M_c(φ)`, has on its left `½·d(J·ω²)/dφ`
//! (`d(J·ω²)/dφ = ω²·dJ/dφ + 2·J·ω·dω/dφ`). With the parabola motor `A·ω² = A·w/J` for
//! `w = J·ω²` (twice the kinetic energy), so eq. 1 is exactly linear in `w`:
//!
//! `dw/dφ = p(φ)·w + q(φ)`, `p = 2A/J(φ) < 0`, `q = 2·(B − M_c(φ))`,
//!
//! with coefficients periodic over the common period `T` of the load and inertia orders. Over
//! a period `∫p < 0`, so exactly one solution is periodic and every other one converges to it.
//! Averaging the equation over `T` gives `2a·mean(w/J) = 2·(B − M1)`: the mean of ω² over the
//! shaft angle is `ū = (B − M1)/a`, the same as with a constant inertia.
//!
//! ## The periodic solution
//! Split `p = p̄ + p̃` into its mean and a zero-mean part with periodic antiderivative `P̃`.
//! With `v = w·e^{−P̃}` the equation becomes `dv/dφ = p̄·v + g(φ)`, `g = q·e^{−P̃}` periodic and
//! analytic, whose periodic solution is, mode by mode (`θ_m = m·2π/T`),
//! `v = Σ_m ĝ_m·e^{iθ_m φ}/(iθ_m − p̄)`: the integrating-factor formula over one period with
//! the one non-periodic factor, `e^{p̄·(φ − s)}`, integrated exactly. The coefficients `ĝ_m`
//! (and those of `1/J`, which give `P̃`) are integrals of smooth periodic functions over a full
//! period, taken by the trapezoid rule on `N` equally spaced nodes (a radix-2 FFT): for an
//! analytic periodic integrand its error falls geometrically with `N`, the rule being exact for
//! every trigonometric term of degree below `N`. Then `w = e^{P̃}·v` and `ω = √(w/J)`.
//!
//! `N` is the smallest power of two giving 16 nodes per cycle of the fastest order (64 at
//! least; the node scan for the extrema needs that), doubled until the spectra of `1/J` and of
//! `g` hold nothing above their rounding floor (1e-15 of their largest coefficient) beyond
//! `|m| > 3N/8`: coefficients that decay geometrically are then further below the floor from
//! `N/2` on, where the rule would alias them. At most [`MAX_NODES`]; a drive that needs more is
//! rejected when it is built.
//!
//! ## Precision for tiny swings
//! The solution is assembled from mean and oscillating parts kept apart: the oscillating parts
//! of the load and of `1/J` alone, `e^{±P̃} − 1` by `expm1`, so that the swing
//! `s = ω² − w̄/J0 = (J0·w̃ − w̄·J̃)/(J0·J)` is computed from small quantities with their own
//! relative precision, never as the difference of two nearly equal ω² (form chosen so that δ
//! keeps its relative precision when the swing is tiny, as the constant-J form does), and the
//! integrating factor `e^{P̃}` stays bounded over the period (no `e^{±∫p}` growth).
//!
//! Bounded, not small: `w = e^{P̃}·v` gives back `w` from a `v` that spans `e^{ΔP̃}`
//! (`ΔP̃ = max P̃ − min P̃`), and the rounding of `v`'s spectrum at its largest values comes
//! back multiplied by that span. A motor stiff against the inertia's swing (`4a·|J̃|/(J0²·n)`
//! large, whatever the magnitudes: 1e7 N·m on 1 kg·m² swinging by 1 %, as well as 5e260 N·m on
//! an inertia swinging by 7e-252 of itself) makes `ΔP̃` large and the result noise. A drive
//! whose `ΔP̃` exceeds [`MAX_FACTOR_SWING`] is not solved here: the model shoots it with the
//! parabola instead.
//!
//! ## Cost
//! One solution: five FFTs of `N` points (building the model solves once more for each node
//! count it tries). One prediction: a solution, two more FFTs for the node scan, and up to 16
//! golden-section refinements of an extremum, each 66 evaluations of the series (`O(N)` each).
//! The solution keeps its spectrum on the stack: 256 complex values (4 KiB) when the drive is
//! resolved on that many nodes (the usual case), [`MAX_NODES`] (64 KiB) only when it needs
//! more, each size in functions of its own kept out of line, so that neither the
//! constant-inertia path nor a small drive carries the large frame. It is design-time
//! code; the monitor's per-edge paths never run it.

use super::load::{checked_term, Harmonic};
use crate::error::{positive, ConfigError};
use core::f64::consts::PI;

/// Fixed capacity of inertia harmonics.
pub const MAX_INERTIA_HARMONICS: usize = 8;
/// Largest number of trapezoid nodes over one common period.
pub const MAX_NODES: usize = 4096;
/// Nodes a solution holds when that is enough (4 KiB of stack): the usual drive needs 64 to
/// 256; only one that needs more takes the [`MAX_NODES`] solution's 64 KiB.
pub(super) const SMALL_NODES: usize = 256;
/// Fewest nodes over one common period.
const MIN_NODES: usize = 64;
/// Nodes per cycle of the fastest order, at least.
const NODES_PER_CYCLE: u64 = 16;
/// A spectrum is resolved when nothing beyond `|m| > 3N/8` exceeds this fraction of its largest
/// coefficient (or its rounding floor).
const TAIL_TOLERANCE: f64 = 1e-15;
/// Extremum candidates refined per direction, at most.
const MAX_CANDIDATES: usize = 8;
/// Largest swing `max P̃ − min P̃` of the integrating factor's exponent over the period.
/// `v = w·e^{−P̃}` spans `e^{ΔP̃}` between its extremes, its spectrum is rounded at `ε` of the
/// largest, and `w = e^{P̃}·v` multiplies that rounding by `e^{P̃}` again where `v` is smallest:
/// the error in ω² is about `ε·e^{ΔP̃}` of ω² (measured against the shooting with the parabola
/// on a drive whose swing sweeps through 1 to 78: 1e-12 relative in δ up to ΔP̃ ≈ 7, 5e-10 at
/// 12, 8e-9 at 16, 4e-6 at 21, 3e-3 at 27, and from about 35 a stall with `u_min` of −1e4 to
/// −1e26 s⁻² for a drive that runs steadily at δ = 0.075). `ΔP̃ ≈ 4a·|J̃|/(J0²·n)`, so this
/// bounds a motor stiff against the inertia (`a/J0` large against the orders) times the
/// inertia's swing. At 12 the integrating factor costs at most about five of f64's sixteen
/// digits; a drive beyond it is shot with the parabola instead.
pub(super) const MAX_FACTOR_SWING: f64 = 12.0;

/// One harmonic `amplitude·cos(order·φ + phase)` of the reduced inertia.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct InertiaHarmonic {
    order: f64,
    amplitude: f64,
    phase: f64,
}

impl InertiaHarmonic {
    /// A harmonic of `order` cycles per revolution (positive, at most [`MAX_ORDER`](super::MAX_ORDER); may be
    /// fractional), `amplitude` in kg·m² (any sign) and `phase` in rad (|phase| ≤ 1e9).
    pub fn new(order: f64, amplitude: f64, phase: f64) -> Result<Self, ConfigError> {
        let order = positive("inertia_harmonic.order", order)?;
        let [order, amplitude, phase] = checked_term(
            [
                "inertia_harmonic.order",
                "inertia_harmonic.amplitude",
                "inertia_harmonic.phase",
            ],
            order,
            amplitude,
            phase,
        )?;
        Ok(Self {
            order,
            amplitude,
            phase,
        })
    }

    /// Order (cycles per shaft revolution).
    pub fn order(&self) -> f64 {
        self.order
    }

    /// Amplitude, kg·m².
    pub fn amplitude(&self) -> f64 {
        self.amplitude
    }

    /// Phase, rad.
    pub fn phase(&self) -> f64 {
        self.phase
    }

    /// Value at shaft angle `phi`, kg·m².
    pub fn inertia(&self, phi: f64) -> f64 {
        self.amplitude * libm::cos(self.order * phi + self.phase)
    }
}

/// A complex number, for the FFT.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct C {
    re: f64,
    im: f64,
}

impl C {
    const ZERO: C = C { re: 0.0, im: 0.0 };
    fn add(self, o: C) -> C {
        C {
            re: self.re + o.re,
            im: self.im + o.im,
        }
    }
    fn sub(self, o: C) -> C {
        C {
            re: self.re - o.re,
            im: self.im - o.im,
        }
    }
    fn mul(self, o: C) -> C {
        C {
            re: self.re * o.re - self.im * o.im,
            im: self.re * o.im + self.im * o.re,
        }
    }
    fn conj(self) -> C {
        C {
            re: self.re,
            im: -self.im,
        }
    }
    fn scale(self, k: f64) -> C {
        C {
            re: self.re * k,
            im: self.im * k,
        }
    }
    fn div(self, o: C) -> C {
        // Smith's algorithm: no overflow for large |o|.
        if libm::fabs(o.re) >= libm::fabs(o.im) {
            let r = o.im / o.re;
            let d = o.re + o.im * r;
            C {
                re: (self.re + self.im * r) / d,
                im: (self.im - self.re * r) / d,
            }
        } else {
            let r = o.re / o.im;
            let d = o.re * r + o.im;
            C {
                re: (self.re * r + self.im) / d,
                im: (self.im * r - self.re) / d,
            }
        }
    }
    fn abs(self) -> f64 {
        libm::hypot(self.re, self.im)
    }
    fn cis(t: f64) -> C {
        C {
            re: libm::cos(t),
            im: libm::sin(t),
        }
    }
}

/// In-place radix-2 FFT of `buf` (length a power of two): `X_m = Σ_j x_j·e^{∓2πi·jm/N}`,
/// the minus sign forward; unnormalised.
fn fft(buf: &mut [C], inverse: bool) {
    let n = buf.len();
    let mut j = 0usize;
    for i in 1..n {
        let mut bit = n >> 1;
        while j & bit != 0 {
            j ^= bit;
            bit >>= 1;
        }
        j |= bit;
        if i < j {
            buf.swap(i, j);
        }
    }
    let sign = if inverse { 1.0 } else { -1.0 };
    let mut len = 2;
    while len <= n {
        let half = len / 2;
        for k in 0..half {
            let w = C::cis(sign * 2.0 * PI * k as f64 / len as f64);
            let mut i = k;
            while i < n {
                let u = buf[i];
                let v = buf[i + half].mul(w);
                buf[i] = u.add(v);
                buf[i + half] = u.sub(v);
                i += len;
            }
        }
        len <<= 1;
    }
}

/// Signed frequency index of FFT bin `k` of `n` (the Nyquist bin counts as `n/2`).
fn signed(k: usize, n: usize) -> i64 {
    if k <= n / 2 {
        k as i64
    } else {
        k as i64 - n as i64
    }
}

/// Whether the spectrum `x` has nothing above `max(tolerance·largest, floor)` at `|m| > 3N/8`.
fn resolved(x: &[C], floor: f64) -> bool {
    let n = x.len();
    let (mut head, mut tail) = (0.0f64, 0.0f64);
    for (k, c) in x.iter().enumerate() {
        let a = c.abs();
        if !a.is_finite() {
            return false;
        }
        head = head.max(a);
        if signed(k, n).unsigned_abs() > (3 * n / 8) as u64 {
            tail = tail.max(a);
        }
    }
    tail <= (TAIL_TOLERANCE * head).max(floor)
}

/// The drive as the J(φ) solution sees it.
#[derive(Debug, Clone, Copy)]
pub(super) struct Drive<'a> {
    /// `a = −A`, N·m·s².
    pub a: f64,
    /// `q̄ = 2·(B − mean load)`, N·m.
    pub q_mean: f64,
    /// `J0`: machine inertia plus flywheel, kg·m².
    pub j0: f64,
    pub inertia: &'a [InertiaHarmonic],
    /// The load's harmonics (order-0 ones are in `q_mean` and skipped here).
    pub load: &'a [Harmonic],
    /// Common period of all orders, rad.
    pub period: f64,
}

impl Drive<'_> {
    fn j_osc(&self, phi: f64) -> f64 {
        self.inertia.iter().map(|h| h.inertia(phi)).sum()
    }
    /// `|q̄| + 2·Σ|M2k|` (1 if 0): the scale of `q`, N·m.
    fn q_scale(&self) -> f64 {
        let s = libm::fabs(self.q_mean)
            + 2.0
                * self
                    .load
                    .iter()
                    .filter(|h| h.order() > 0.0)
                    .map(|h| libm::fabs(h.amplitude()))
                    .sum::<f64>();
        if s > 0.0 && s.is_finite() {
            s
        } else {
            1.0
        }
    }

    /// The oscillating part of `q`: `−2·Σ M2k·sin(n_k·φ + ψ_k)` over orders > 0.
    fn q_osc(&self, phi: f64) -> f64 {
        -2.0 * self
            .load
            .iter()
            .filter(|h| h.order() > 0.0)
            .map(|h| h.torque(phi))
            .sum::<f64>()
    }
}

/// Nodes whose neighbourhoods the golden section refines.
#[derive(Debug, Clone, Copy, Default)]
struct Candidates {
    idx: [usize; MAX_CANDIDATES],
    len: usize,
}

impl Candidates {
    /// Keeps the `MAX_CANDIDATES` nodes of largest `key` (`keys` holds the kept ones' keys).
    fn offer(&mut self, i: usize, key: f64, keys: &mut [f64; MAX_CANDIDATES]) {
        if self.len < MAX_CANDIDATES {
            self.idx[self.len] = i;
            keys[self.len] = key;
            self.len += 1;
            return;
        }
        let mut worst = 0;
        for k in 1..self.len {
            if keys[k] < keys[worst] {
                worst = k;
            }
        }
        if key > keys[worst] {
            self.idx[worst] = i;
            keys[worst] = key;
        }
    }
}

/// The periodic solution over one period, as the spectrum of `ṽ + i·P̃` on `N` nodes.
pub(super) struct Solution<'a, const N: usize> {
    drive: Drive<'a>,
    nodes: usize,
    /// `2π/T`.
    base: f64,
    /// Spectrum of `z = ṽ/v_scale + i·P̃` (normalised: `z(φ) = Σ Z_m·e^{i·m·base·φ}`).
    z: [C; N],
    v_mean: f64,
    /// The scale ṽ is stored at: `Z` holds the spectrum of `ṽ/v_scale + i·P̃`.
    v_scale: f64,
    /// Mean of `(e^{P̃} − 1)·v` over the nodes.
    mean_e: f64,
    /// Mean of `w` over the period.
    w_mean: f64,
}

/// Extrema of the swing and where they are.
#[derive(Debug, Clone, Copy)]
pub(super) struct SwingExtremes {
    /// `w̄/J0`, s⁻²: ω² = centre + s.
    pub centre: f64,
    pub s_max: f64,
    pub s_min: f64,
    pub phi_max: f64,
    pub phi_min: f64,
}

/// Why no solution was computed.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Unresolved {
    /// More than [`MAX_NODES`] nodes would be needed.
    Nodes,
    /// A value overflowed f64.
    Overflow,
    /// The integrating factor swings by more than `e^MAX_FACTOR_SWING` over the period: a
    /// motor too stiff against the inertia's swing for f64 to carry the solution.
    Stiff,
}

/// The swing `s = (J0·w̃ − w̄·J̃)/(J0·J)` at `phi` from `ṽ` and `P̃` there, with
/// `w̃ = ((e^{P̃} − 1)·v − mean_e) + ṽ`; as `(w̃ − (w̄/J0)·J̃)/J`, without forming `J0²` (which
/// overflows for a huge inertia).
fn swing_of(
    d: &Drive<'_>,
    v_mean: f64,
    mean_e: f64,
    centre: f64,
    phi: f64,
    vt: f64,
    pt: f64,
) -> f64 {
    let wt = (libm::expm1(pt) * (v_mean + vt) - mean_e) + vt;
    let jt = d.j_osc(phi);
    (wt - centre * jt) / (d.j0 + jt)
}

/// Nodes to start from: 16 per cycle of the fastest order (`fastest` cycles per period).
pub(super) fn initial_nodes(fastest: u64) -> Option<usize> {
    let n = fastest.checked_mul(NODES_PER_CYCLE)?.max(MIN_NODES as u64);
    let n = n.checked_next_power_of_two()?;
    (n <= MAX_NODES as u64).then_some(n as usize)
}

impl<'a, const N: usize> Solution<'a, N> {
    /// The solution on `nodes` nodes, or with `adapt` the first power of two from `nodes` on
    /// that resolves both spectra; [`Unresolved::Nodes`] when that is more than `N`.
    pub(super) fn solve(
        drive: Drive<'a>,
        mut nodes: usize,
        adapt: bool,
    ) -> Result<Self, Unresolved> {
        if nodes > N {
            return Err(Unresolved::Nodes);
        }
        let mut s = Solution {
            drive,
            nodes,
            base: 2.0 * PI / drive.period,
            z: [C::ZERO; N],
            v_mean: 0.0,
            v_scale: 1.0,
            mean_e: 0.0,
            w_mean: 0.0,
        };
        loop {
            s.nodes = nodes;
            match s.fill() {
                Ok(true) => return Ok(s),
                Ok(false) if !adapt => return Ok(s),
                Ok(false) if nodes < N => nodes *= 2,
                Ok(false) => return Err(Unresolved::Nodes),
                Err(e) => return Err(e),
            }
        }
    }

    /// The node count.
    pub(super) fn nodes(&self) -> usize {
        self.nodes
    }

    fn node(&self, j: usize) -> f64 {
        self.drive.period / self.nodes as f64 * j as f64
    }

    /// Computes the spectrum on `self.nodes` nodes; `Ok(false)` if it is not resolved.
    fn fill(&mut self) -> Result<bool, Unresolved> {
        let n = self.nodes;
        let d = self.drive;
        let a2 = 2.0 * d.a;
        let inv_n = 1.0 / n as f64;
        let h = d.period * inv_n;
        let mut ok = true;
        // 1/J − 1/J0 = −J̃/(J0·J) at the nodes, and its spectrum.
        let mut floor = 0.0f64;
        for j in 0..n {
            let phi = d.period * inv_n * j as f64;
            let jt = d.j_osc(phi);
            let r = -jt / (d.j0 * (d.j0 + jt));
            floor = floor.max(libm::fabs(r));
            self.z[j] = C { re: r, im: 0.0 };
        }
        let buf = &mut self.z[..n];
        fft(buf, false);
        for c in buf.iter_mut() {
            *c = c.scale(inv_n);
        }
        ok &= resolved(buf, 16.0 * f64::EPSILON * floor);
        // p = −2a/J: mean p̄ = −2a·(1/J0 + mean r̃), P̃ = Σ −2a·R_m/(i·m·base)·e^{i·m·base·φ}.
        let p_mean = -a2 * (1.0 / d.j0 + buf[0].re);
        if !(p_mean < 0.0 && p_mean.is_finite()) {
            return Err(Unresolved::Overflow);
        }
        buf[0] = C::ZERO;
        buf[n / 2] = C::ZERO;
        for (k, c) in buf.iter_mut().enumerate().skip(1) {
            let m = signed(k, n) as f64 * self.base;
            // −2a·R/(i·m) = 2a·R·i/m.
            *c = C {
                re: -a2 * c.im / m,
                im: a2 * c.re / m,
            };
        }
        fft(buf, true);
        // The integrating factor may swing by at most e^MAX_FACTOR_SWING over the period (see
        // there): beyond it the solution below is rounding noise, not a number to report.
        let (lo, hi) = buf
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), c| {
                (lo.min(c.re), hi.max(c.re))
            });
        if hi - lo > MAX_FACTOR_SWING || !(hi - lo).is_finite() {
            return Err(Unresolved::Stiff);
        }
        // g̃ = q̄·(e^{−P̃} − 1) + q̃·e^{−P̃}, packed with P̃: x = g̃/q_s + i·P̃ (two real signals,
        // both dimensionless so that the rounding of one does not leak into the other at a
        // foreign scale).
        let q_scale = d.q_scale();
        let mut floor = 0.0f64;
        for (j, c) in buf.iter_mut().enumerate() {
            let phi = h * j as f64;
            let pt = c.re;
            let e = libm::expm1(-pt);
            let qt = d.q_osc(phi);
            let (x, y) = (d.q_mean * e, qt * (1.0 + e));
            floor = floor.max(libm::fabs(x) + libm::fabs(y));
            *c = C {
                re: (x + y) / q_scale,
                im: pt,
            };
        }
        fft(buf, false);
        for c in buf.iter_mut() {
            *c = c.scale(inv_n);
        }
        // Separate: G_m = (X_m + conj X_−m)/2, Π_m = (X_m − conj X_−m)/(2i); then
        // V_m = G_m/(i·m·base − p̄) and Z_m = V_m + i·Π_m. Bins m and N − m together.
        let g0 = buf[0].re * q_scale;
        let pi0 = buf[0].im;
        self.v_mean = (d.q_mean + g0) / -p_mean;
        // ṽ is packed as ṽ/v_s, v_s the scale of w.
        let v_scale = q_scale / -p_mean;
        self.v_scale = v_scale;
        let mut tail = 0.0f64;
        let mut head = libm::fabs(g0);
        for k in 1..n / 2 {
            let (xp, xm) = (buf[k], buf[n - k].conj());
            let g = xp.add(xm).scale(0.5 * q_scale);
            let pd = xp.sub(xm).scale(0.5);
            // (a + ib)/(2i)·2 = pd/i = (b − ia): Π_m = (pd.im, −pd.re).
            let pi = C {
                re: pd.im,
                im: -pd.re,
            };
            let ga = g.abs();
            head = head.max(ga);
            if k > 3 * n / 8 {
                tail = tail.max(ga);
            }
            let m = k as f64 * self.base;
            let v = g.div(C { re: -p_mean, im: m });
            let v_neg = g.conj().div(C {
                re: -p_mean,
                im: -m,
            });
            let i_pi = C {
                re: -pi.im,
                im: pi.re,
            };
            let i_pi_neg = C {
                re: pi.im,
                im: pi.re,
            };
            buf[k] = v.scale(1.0 / v_scale).add(i_pi);
            buf[n - k] = v_neg.scale(1.0 / v_scale).add(i_pi_neg);
        }
        let gn = buf[n / 2].abs() * q_scale;
        tail = tail.max(gn);
        if !(head.is_finite() && tail.is_finite()) {
            return Err(Unresolved::Overflow);
        }
        ok &= tail <= (TAIL_TOLERANCE * head).max(16.0 * f64::EPSILON * floor);
        buf[0] = C { re: 0.0, im: pi0 };
        buf[n / 2] = C::ZERO;
        // Nodes: ṽ + i·P̃; the mean of (e^{P̃} − 1)·v.
        fft(buf, true);
        let mut sum = 0.0;
        for c in buf.iter() {
            sum += libm::expm1(c.im) * (self.v_mean + c.re * v_scale);
        }
        self.mean_e = sum * inv_n;
        self.w_mean = self.v_mean + self.mean_e;
        // Every node's swing is a finite number (else the parameters overflow f64 somewhere).
        let (v_mean, mean_e, centre) = (self.v_mean, self.mean_e, self.w_mean / d.j0);
        for (j, c) in buf.iter().enumerate() {
            let s = swing_of(
                &d,
                v_mean,
                mean_e,
                centre,
                h * j as f64,
                c.re * v_scale,
                c.im,
            );
            if !s.is_finite() {
                return Err(Unresolved::Overflow);
            }
        }
        fft(buf, false);
        for c in buf.iter_mut() {
            *c = c.scale(inv_n);
        }
        if !(self.v_mean.is_finite() && self.w_mean.is_finite()) {
            return Err(Unresolved::Overflow);
        }
        Ok(ok)
    }

    /// `(ṽ, P̃)` at `phi`: the series, its rotation re-anchored every 32 terms.
    fn z_at(&self, phi: f64) -> (f64, f64) {
        let n = self.nodes;
        let t = self.base * phi;
        let mut acc = self.z[0];
        let step = C::cis(t);
        let mut rot = step;
        for k in 1..n / 2 {
            if k % 32 == 0 {
                rot = C::cis(k as f64 * t);
            }
            acc = acc
                .add(self.z[k].mul(rot))
                .add(self.z[n - k].mul(rot.conj()));
            rot = rot.mul(step);
        }
        (acc.re * self.v_scale, acc.im)
    }

    /// The swing `s = ω² − w̄/J0` at `phi`, from its small parts.
    pub(super) fn swing(&self, phi: f64) -> f64 {
        let (vt, pt) = self.z_at(phi);
        self.swing_from(phi, vt, pt)
    }

    fn swing_from(&self, phi: f64, vt: f64, pt: f64) -> f64 {
        swing_of(
            &self.drive,
            self.v_mean,
            self.mean_e,
            self.centre(),
            phi,
            vt,
            pt,
        )
    }

    /// `w̄/J0`, s⁻².
    pub(super) fn centre(&self) -> f64 {
        self.w_mean / self.drive.j0
    }

    /// ω² at `phi`, s⁻².
    pub(super) fn omega_squared(&self, phi: f64) -> f64 {
        self.centre() + self.swing(phi)
    }

    /// The extrema of the swing: a scan of the nodes, then golden section on the series around
    /// every node that is a local extremum within the scan's resolution of the best (the 8 best
    /// each way at most).
    pub(super) fn extremes(&mut self) -> SwingExtremes {
        let n = self.nodes;
        let inv_n = 1.0 / n as f64;
        // The node values ṽ + i·P̃, scanned, then the spectrum back.
        fft(&mut self.z[..n], true);
        let at = |me: &Self, j: i64| {
            let j = j.rem_euclid(n as i64) as usize;
            me.swing_from(me.node(j), me.z[j].re * me.v_scale, me.z[j].im)
        };
        let (mut best_max, mut best_min) = (f64::NEG_INFINITY, f64::INFINITY);
        let (mut i_max, mut i_min) = (0usize, 0usize);
        let (mut curvature, mut size) = (0.0f64, 0.0f64);
        let (mut prev, mut cur) = (at(self, -1), at(self, 0));
        for j in 0..n {
            let next = at(self, j as i64 + 1);
            if cur > best_max {
                best_max = cur;
                i_max = j;
            }
            if cur < best_min {
                best_min = cur;
                i_min = j;
            }
            curvature = curvature.max(libm::fabs(next - 2.0 * cur + prev));
            size = size.max(libm::fabs(cur));
            prev = cur;
            cur = next;
        }
        // A node within h/2 of an extremum is off by at most ½·|s''|·(h/2)² ≈ |Δ²s|/8; the
        // margin is eight times that, plus rounding.
        let margin = curvature + 8.0 * f64::EPSILON * size;
        let (mut maxima, mut minima) = (Candidates::default(), Candidates::default());
        let mut keys_max = [f64::NEG_INFINITY; MAX_CANDIDATES];
        let mut keys_min = [f64::NEG_INFINITY; MAX_CANDIDATES];
        let (mut prev, mut cur) = (at(self, -1), at(self, 0));
        for j in 0..n {
            let next = at(self, j as i64 + 1);
            if cur >= best_max - margin && cur >= prev && cur >= next {
                maxima.offer(j, cur, &mut keys_max);
            }
            if cur <= best_min + margin && cur <= prev && cur <= next {
                minima.offer(j, -cur, &mut keys_min);
            }
            prev = cur;
            cur = next;
        }
        fft(&mut self.z[..n], false);
        for c in self.z[..n].iter_mut() {
            *c = c.scale(inv_n);
        }
        let mut out = SwingExtremes {
            centre: self.centre(),
            s_max: best_max,
            s_min: best_min,
            phi_max: self.node(i_max),
            phi_min: self.node(i_min),
        };
        let h = self.drive.period * inv_n;
        let period = self.drive.period;
        for &j in &maxima.idx[..maxima.len] {
            let c = self.node(j);
            let (phi, v) = super::model::golden(|p| self.swing(p), c - h, c + h, 1.0);
            if v > out.s_max {
                out.s_max = v;
                out.phi_max = super::model::wrap(phi, period);
            }
        }
        for &j in &minima.idx[..minima.len] {
            let c = self.node(j);
            let (phi, v) = super::model::golden(|p| self.swing(p), c - h, c + h, -1.0);
            if v < out.s_min {
                out.s_min = v;
                out.phi_min = super::model::wrap(phi, period);
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The solution most drives use holds 256 nodes: about 4 KiB, not the 64 KiB of the
    /// largest.
    #[test]
    fn the_small_solution_is_a_sixteenth_of_the_large() {
        let small = core::mem::size_of::<Solution<'static, SMALL_NODES>>();
        let large = core::mem::size_of::<Solution<'static, MAX_NODES>>();
        assert!(small < 4096 + 256, "{small}");
        assert!(large > 65536, "{large}");
    }

    #[test]
    fn fft_matches_the_direct_sum() {
        for n in [8usize, 64, 512] {
            let mut buf = [C::ZERO; 512];
            let x = |j: usize| C {
                re: libm::sin(0.3 * j as f64) + 0.1 * j as f64,
                im: libm::cos(1.7 * j as f64),
            };
            for (j, c) in buf[..n].iter_mut().enumerate() {
                *c = x(j);
            }
            fft(&mut buf[..n], false);
            let mut worst = 0.0f64;
            for (m, got) in buf[..n].iter().enumerate() {
                let mut acc = C::ZERO;
                for j in 0..n {
                    acc = acc.add(x(j).mul(C::cis(-2.0 * PI * ((j * m) % n) as f64 / n as f64)));
                }
                worst = worst.max(acc.sub(*got).abs());
            }
            assert!(worst < 1e-12 * n as f64);
        }
    }
}
