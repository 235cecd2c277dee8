//! A minimal complex number for the configuration-time receptance (f64, 1–3 dof).

use core::ops::{Add, Mul, Sub};

/// `re + i·im`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct C64 {
    pub re: f64,
    pub im: f64,
}

impl C64 {
    pub const ONE: C64 = C64 { re: 1.0, im: 0.0 };
    pub const ZERO: C64 = C64 { re: 0.0, im: 0.0 };

    pub const fn new(re: f64, im: f64) -> Self {
        C64 { re, im }
    }

    pub fn conj(self) -> Self {
        C64::new(self.re, -self.im)
    }

    pub fn norm_sq(self) -> f64 {
        self.re * self.re + self.im * self.im
    }

    /// `self / d`; a zero divisor gives non-finite parts (never a panic).
    pub fn div(self, d: C64) -> C64 {
        let n = self * d.conj();
        let s = d.norm_sq();
        C64::new(n.re / s, n.im / s)
    }
}

impl Add for C64 {
    type Output = C64;
    fn add(self, o: C64) -> C64 {
        C64::new(self.re + o.re, self.im + o.im)
    }
}

impl Sub for C64 {
    type Output = C64;
    fn sub(self, o: C64) -> C64 {
        C64::new(self.re - o.re, self.im - o.im)
    }
}

impl Mul for C64 {
    type Output = C64;
    fn mul(self, o: C64) -> C64 {
        C64::new(
            self.re * o.re - self.im * o.im,
            self.re * o.im + self.im * o.re,
        )
    }
}
