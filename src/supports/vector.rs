//! Unbalances and loads as 2-D vectors in the plane perpendicular to the rotor axis, and the
//! compensated lever sums every plane split is built from.

use core::ops::{Add, Mul, Neg, Sub};

/// A 2-D vector in the plane perpendicular to the rotor axis, fixed to the rotor for
/// unbalances (kg·m) and fixed in space for static loads (N). Angle 0 is the x axis,
/// angles grow towards y (counter-clockwise seen from the positive axial direction).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Vec2 {
    /// Component along x.
    pub x: f64,
    /// Component along y.
    pub y: f64,
}

impl Vec2 {
    /// The zero vector.
    pub const ZERO: Vec2 = Vec2 { x: 0.0, y: 0.0 };

    /// The vector with components `x`, `y`.
    pub const fn new(x: f64, y: f64) -> Self {
        Vec2 { x, y }
    }

    /// The vector of length `r` at `angle` radians.
    pub fn from_polar(r: f64, angle: f64) -> Self {
        Vec2 {
            x: r * libm::cos(angle),
            y: r * libm::sin(angle),
        }
    }

    /// Length, without intermediate overflow or underflow (`hypot`).
    pub fn norm(self) -> f64 {
        libm::hypot(self.x, self.y)
    }

    /// Direction in radians in (−π, π], from the four-quadrant arctangent (0 for the zero
    /// vector). No tan/atan quadrant ambiguity can arise.
    pub fn angle(self) -> f64 {
        libm::atan2(self.y, self.x)
    }

    /// Both components finite.
    pub fn is_finite(self) -> bool {
        self.x.is_finite() && self.y.is_finite()
    }
}

impl Add for Vec2 {
    type Output = Vec2;
    fn add(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x + o.x, self.y + o.y)
    }
}

impl Sub for Vec2 {
    type Output = Vec2;
    fn sub(self, o: Vec2) -> Vec2 {
        Vec2::new(self.x - o.x, self.y - o.y)
    }
}

impl Neg for Vec2 {
    type Output = Vec2;
    fn neg(self) -> Vec2 {
        Vec2::new(-self.x, -self.y)
    }
}

impl Mul<f64> for Vec2 {
    type Output = Vec2;
    fn mul(self, k: f64) -> Vec2 {
        Vec2::new(self.x * k, self.y * k)
    }
}

/// Error-free sum: `a + b = s + e` exactly (Knuth's TwoSum).
#[inline]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bp = s - a;
    let ap = s - bp;
    (s, (a - ap) + (b - bp))
}

/// Error-free product: `a·b = p + e` exactly (fused multiply-add).
#[inline]
fn two_prod(a: f64, b: f64) -> (f64, f64) {
    let p = a * b;
    (p, libm::fma(a, b, -p))
}

/// Compensated dot product (Ogita–Rump–Oishi "Dot2"): the result is as accurate as if it
/// were computed in twice the working precision and then rounded, so sums of lever moments
/// that cancel (a pure couple, unbalances that nearly cancel) keep their small remainder.
#[derive(Debug, Clone, Copy, Default)]
struct Dot2 {
    s: f64,
    c: f64,
}

impl Dot2 {
    #[inline]
    fn add(&mut self, a: f64, b: f64) {
        let (p, ep) = two_prod(a, b);
        let (s, es) = two_sum(self.s, p);
        self.s = s;
        self.c += es + ep;
    }
    #[inline]
    fn value(self) -> f64 {
        self.s + self.c
    }
}

/// Compensated `Σ v_i·k_i` for 2-D vectors `v_i` and scalars `k_i`.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct VecDot2 {
    x: Dot2,
    y: Dot2,
}

impl VecDot2 {
    #[inline]
    pub(crate) fn add(&mut self, v: Vec2, k: f64) {
        self.x.add(v.x, k);
        self.y.add(v.y, k);
    }
    /// Adds `v·(a − b)` with the lever arm `a − b` taken exactly (as a rounded difference
    /// plus its rounding error), so no lever rounding enters a sum that cancels.
    #[inline]
    pub(crate) fn add_lever(&mut self, v: Vec2, a: f64, b: f64) {
        let (d, e) = two_sum(a, -b);
        self.add(v, d);
        self.add(v, e);
    }
    #[inline]
    pub(crate) fn value(self) -> Vec2 {
        Vec2::new(self.x.value(), self.y.value())
    }
}

/// Compensated resultant `Σ v_i`.
pub(crate) fn resultant<I: IntoIterator<Item = (f64, Vec2)>>(items: I) -> Vec2 {
    let mut acc = VecDot2::default();
    for (_, v) in items {
        acc.add(v, 1.0);
    }
    acc.value()
}

/// Compensated moment `Σ (z_i − about)·v_i`.
pub(crate) fn moment<I: IntoIterator<Item = (f64, Vec2)>>(items: I, about: f64) -> Vec2 {
    let mut acc = VecDot2::default();
    for (z, v) in items {
        acc.add_lever(v, z, about);
    }
    acc.value()
}

/// The two vectors in planes `z1`, `z2` with the same resultant and the same moment as the
/// `(z_i, v_i)` system: `E1 = Σ v_i·(z2 − z_i)/(z2 − z1)`, `E2 = Σ v_i·(z_i − z1)/(z2 − z1)`.
/// The caller guarantees `z2 − z1` is well separated (see [`super::MIN_PLANE_SEPARATION`]).
pub(crate) fn split<I: IntoIterator<Item = (f64, Vec2)>>(items: I, z1: f64, z2: f64) -> [Vec2; 2] {
    let span = z2 - z1;
    let mut e1 = VecDot2::default();
    let mut e2 = VecDot2::default();
    for (z, v) in items {
        // Stability: lever arms are exact differences of coordinates (rounded difference plus
        // its error) and the sums are compensated, never 1 − share or products of absolute
        // coordinates.
        e1.add_lever(v, z2, z);
        e2.add_lever(v, z, z1);
    }
    let (a, b) = (e1.value(), e2.value());
    [
        Vec2::new(a.x / span, a.y / span),
        Vec2::new(b.x / span, b.y / span),
    ]
}
