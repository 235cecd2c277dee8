//! A minimal complex number for the configuration-time receptance (1–3 dof), in f64 for the
//! results and in f32 (the Cortex-M4F's hardware float) for the capture scan that only
//! locates a maximum before it is refined in f64.

use core::ops::{Add, Div, Mul, Neg, Sub};

/// The real types the complex arithmetic runs on (f64 and f32).
pub(crate) trait Real:
    Copy
    + PartialOrd
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
{
    const ZERO: Self;
    const ONE: Self;
}

impl Real for f64 {
    const ZERO: f64 = 0.0;
    const ONE: f64 = 1.0;
}

impl Real for f32 {
    const ZERO: f32 = 0.0;
    const ONE: f32 = 1.0;
}

/// `re + i·im`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Cx<T> {
    pub re: T,
    pub im: T,
}

/// The f64 complex number of the configuration-time results.
pub(crate) type C64 = Cx<f64>;

impl<T: Real> Cx<T> {
    pub const ONE: Self = Cx {
        re: T::ONE,
        im: T::ZERO,
    };
    pub const ZERO: Self = Cx {
        re: T::ZERO,
        im: T::ZERO,
    };

    pub const fn new(re: T, im: T) -> Self {
        Cx { re, im }
    }

    pub fn conj(self) -> Self {
        Cx::new(self.re, -self.im)
    }

    pub fn norm_sq(self) -> T {
        self.re * self.re + self.im * self.im
    }

    /// `self / d`; a zero divisor gives non-finite parts (never a panic).
    pub fn div(self, d: Self) -> Self {
        let n = self * d.conj();
        let s = d.norm_sq();
        Cx::new(n.re / s, n.im / s)
    }

    /// `1 / self`: the value of `ONE.div(self)` without its multiplications by one (the same
    /// bits, but for the sign of a zero imaginary part).
    pub fn recip(self) -> Self {
        let s = self.norm_sq();
        Cx::new(self.re / s, -self.im / s)
    }
}

impl<T: Real> Add for Cx<T> {
    type Output = Self;
    fn add(self, o: Self) -> Self {
        Cx::new(self.re + o.re, self.im + o.im)
    }
}

impl<T: Real> Sub for Cx<T> {
    type Output = Self;
    fn sub(self, o: Self) -> Self {
        Cx::new(self.re - o.re, self.im - o.im)
    }
}

impl<T: Real> Mul for Cx<T> {
    type Output = Self;
    fn mul(self, o: Self) -> Self {
        Cx::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}
