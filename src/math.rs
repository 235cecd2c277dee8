//! Math backends for the f32 paths that run on the target.
//!
//! Hot paths that need a transcendental function are generic over [`Math`], so one build can
//! carry both backends and the benchmarks can measure each: [`Libm`] (correctly rounded or
//! within 1 ulp) and [`Micromath`] (fast approximations with a stated error). Paths that only
//! add, multiply and divide do not take a backend.
//!
//! Also here: the rounding configuration needs, as `const fn` ([`trunc`], [`floor`], [`ceil`],
//! [`round`]), so that a configuration can be validated by the compiler, where `libm` cannot
//! be called.

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

/// 2^52: at and beyond it every f64 is an integer.
const TWO_52: f64 = 4_503_599_627_370_496.0;

/// `x` rounded toward zero, exact for every f64 (NaN and infinities returned as they are; the
/// sign of a zero result is not kept). As `libm::trunc`, but a `const fn`.
pub const fn trunc(x: f64) -> f64 {
    if !(x > -TWO_52 && x < TWO_52) {
        return x;
    }
    // |x| < 2^52: the integer part fits an i64 and converts back exactly.
    (x as i64) as f64
}

/// The largest integer not above `x` (as `libm::floor`, a `const fn`).
pub const fn floor(x: f64) -> f64 {
    let t = trunc(x);
    if t > x {
        t - 1.0
    } else {
        t
    }
}

/// The smallest integer not below `x` (as `libm::ceil`, a `const fn`).
pub const fn ceil(x: f64) -> f64 {
    let t = trunc(x);
    if t < x {
        t + 1.0
    } else {
        t
    }
}

/// `x` rounded to the nearest integer, halves away from zero (as `libm::round`, a `const fn`).
pub const fn round(x: f64) -> f64 {
    let t = trunc(x);
    // The fraction x − trunc(x) is exact (no `x + 0.5`, which rounds 0.49999999999999994 up).
    let d = x - t;
    if d >= 0.5 {
        t + 1.0
    } else if d <= -0.5 {
        t - 1.0
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn same(a: f64, b: f64) -> bool {
        a == b || (a.is_nan() && b.is_nan())
    }

    fn check_rounding(x: f64) {
        assert!(same(trunc(x), libm::trunc(x)), "trunc({x:e})");
        assert!(same(floor(x), libm::floor(x)), "floor({x:e})");
        assert!(same(ceil(x), libm::ceil(x)), "ceil({x:e})");
        assert!(same(round(x), libm::round(x)), "round({x:e})");
    }

    #[test]
    fn const_rounding_matches_libm_at_the_edges() {
        let two52 = TWO_52;
        for x in [
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.5,
            2.5,
            -2.5,
            0.49999999999999994,
            -0.49999999999999994,
            1.0 - f64::EPSILON / 2.0,
            two52 - 0.5,
            -(two52 - 0.5),
            two52,
            two52 + 1.0,
            2.0 * two52 + 2.0,
            4_294_967_295.5,
            4_294_967_296.0 * 0.999_999_999,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            5e-324,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ] {
            check_rounding(x);
        }
    }

    proptest! {
        #[test]
        fn const_rounding_matches_libm_on_any_f64(bits in any::<u64>()) {
            check_rounding(f64::from_bits(bits));
        }

        #[test]
        fn const_rounding_matches_libm_on_moderate_values(x in -1e7f64..1e7) {
            check_rounding(x);
            check_rounding(x * 1e-7);
            check_rounding(x * 4.5e8);
        }
    }

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
