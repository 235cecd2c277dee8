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

/// Fast backend: the `micromath` crate's approximations. Measured worst errors on (0, 10]
/// (see the unit test): sqrt 6.1 % relative, sin/cos 1.1e-3 absolute, atan2 2.9e-3 rad.
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

    /// Worst errors against f64 over (0, 10]: sqrt relative, sin, cos, atan2 absolute.
    fn worst<M: Math>() -> [f64; 4] {
        let mut e = [0f64; 4];
        for i in 1..20_000 {
            let x = i as f32 * 0.0005;
            let xd = x as f64;
            e[0] = e[0].max((M::sqrt(x) as f64 / xd.sqrt() - 1.0).abs());
            e[1] = e[1].max((M::sin(x) as f64 - xd.sin()).abs());
            e[2] = e[2].max((M::cos(x) as f64 - xd.cos()).abs());
            let (y, xx) = ((xd.sin() as f32) as f64, (-xd.cos() as f32) as f64);
            e[3] = e[3].max((M::atan2(y as f32, xx as f32) as f64 - y.atan2(xx)).abs());
        }
        e
    }

    #[test]
    fn libm_is_accurate() {
        let e = worst::<Libm>();
        assert!(
            e[0] < 1.2e-7 && e[1] < 1e-6 && e[2] < 1e-6 && e[3] < 1e-6,
            "{e:?}"
        );
    }

    #[test]
    fn micromath_is_within_its_stated_error() {
        let e = worst::<Micromath>();
        assert!(
            e[0] < 0.062 && e[1] < 1.1e-3 && e[2] < 1.1e-3 && e[3] < 2.9e-3,
            "{e:?}"
        );
    }
}
