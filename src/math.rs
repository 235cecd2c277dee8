//! Math backends for the f32 paths that run on the target.
//!
//! Hot paths that need a transcendental function are generic over [`Math`], so one build can
//! carry both backends and the benchmarks can measure each: [`Libm`] (correctly rounded or
//! within 1 ulp) and [`Micromath`] (fast approximations with a stated error). Paths that only
//! add, multiply and divide do not take a backend.

/// The f32 functions a hot path may call.
pub trait Math {
    /// Square root; NaN for negative input.
    fn sqrt(x: f32) -> f32;
    /// Sine of `x` radians.
    fn sin(x: f32) -> f32;
    /// Cosine of `x` radians.
    fn cos(x: f32) -> f32;
    /// Four-quadrant arctangent of `y / x`.
    fn atan2(y: f32, x: f32) -> f32;
}

/// Accurate backend: the `libm` crate (a port of musl's libm).
#[derive(Debug, Clone, Copy, Default)]
pub struct Libm;

impl Math for Libm {
    #[inline]
    fn sqrt(x: f32) -> f32 {
        libm::sqrtf(x)
    }
    #[inline]
    fn sin(x: f32) -> f32 {
        libm::sinf(x)
    }
    #[inline]
    fn cos(x: f32) -> f32 {
        libm::cosf(x)
    }
    #[inline]
    fn atan2(y: f32, x: f32) -> f32 {
        libm::atan2f(y, x)
    }
}

/// Fast backend: the `micromath` crate's approximations (sqrt within about 1e-3 relative,
/// sin/cos within about 1e-3 absolute; see the accuracy tables in the README).
#[derive(Debug, Clone, Copy, Default)]
pub struct Micromath;

impl Math for Micromath {
    #[inline]
    fn sqrt(x: f32) -> f32 {
        micromath::F32(x).sqrt().0
    }
    #[inline]
    fn sin(x: f32) -> f32 {
        micromath::F32(x).sin().0
    }
    #[inline]
    fn cos(x: f32) -> f32 {
        micromath::F32(x).cos().0
    }
    #[inline]
    fn atan2(y: f32, x: f32) -> f32 {
        micromath::F32(y).atan2(micromath::F32(x)).0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check<M: Math>(tol: f32) {
        for i in 1..200 {
            let x = i as f32 * 0.05;
            assert!((M::sqrt(x) - (x as f64).sqrt() as f32).abs() <= tol * M::sqrt(x));
            assert!((M::sin(x) - (x as f64).sin() as f32).abs() <= tol);
            assert!((M::cos(x) - (x as f64).cos() as f32).abs() <= tol);
            let (y, xx) = ((x as f64).sin(), -(x as f64).cos());
            assert!((M::atan2(y as f32, xx as f32) - y.atan2(xx) as f32).abs() <= tol * 4.0);
        }
    }

    #[test]
    fn libm_is_accurate() {
        check::<Libm>(2e-7);
    }

    #[test]
    fn micromath_is_within_its_stated_error() {
        check::<Micromath>(2e-3);
    }
}
