//! Configuration errors: every constructor validates once and names the bad value.
//!
//! The per-sample paths never fail; everything that could go wrong is rejected here.

/// Why a configuration was rejected. Each variant names the offending parameter.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub enum ConfigError {
    /// The parameter is NaN or infinite.
    NonFinite(&'static str),
    /// The parameter must be strictly positive (and not subnormal).
    NotPositive(&'static str),
    /// The parameter must not be negative.
    Negative(&'static str),
    /// The parameter is outside its documented range.
    OutOfRange(&'static str),
    /// More items than the fixed capacity allows.
    Capacity(&'static str),
    /// Parameters that are each valid but contradict each other.
    Inconsistent(&'static str),
    /// A valid value this build leaves out (a cargo feature of the core is off: the
    /// pattern wheels of `wheel` need `pattern-wheels`).
    Unsupported(&'static str),
}

impl ConfigError {
    /// The name of the parameter that was rejected.
    pub const fn parameter(&self) -> &'static str {
        match *self {
            ConfigError::NonFinite(p)
            | ConfigError::NotPositive(p)
            | ConfigError::Negative(p)
            | ConfigError::OutOfRange(p)
            | ConfigError::Capacity(p)
            | ConfigError::Inconsistent(p)
            | ConfigError::Unsupported(p) => p,
        }
    }
}

impl core::fmt::Display for ConfigError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match *self {
            ConfigError::NonFinite(p) => write!(f, "`{p}` must be finite"),
            ConfigError::NotPositive(p) => write!(f, "`{p}` must be positive"),
            ConfigError::Negative(p) => write!(f, "`{p}` must not be negative"),
            ConfigError::OutOfRange(p) => write!(f, "`{p}` is out of range"),
            ConfigError::Capacity(p) => write!(f, "`{p}` exceeds the fixed capacity"),
            ConfigError::Inconsistent(p) => write!(f, "`{p}` contradicts other parameters"),
            ConfigError::Unsupported(p) => {
                write!(f, "`{p}` is not supported by this build (a feature is off)")
            }
        }
    }
}

impl core::error::Error for ConfigError {}

/// `?` for a `const fn`, where the operator is not available: the value of `Ok`, or return the
/// error.
macro_rules! tri {
    ($e:expr) => {
        match $e {
            Ok(v) => v,
            Err(e) => return Err(e),
        }
    };
}
pub(crate) use tri;

// The validators are `const fn`, so that a configuration written as a `const` is checked by
// the compiler (a bad value stops the build) and no checking code reaches the firmware.

/// `x` if it is finite and positive (subnormals rejected: they are not physical and lose
/// their digits in the first division), else the error naming `name`.
pub const fn positive(name: &'static str, x: f64) -> Result<f64, ConfigError> {
    let x = tri!(finite(name, x));
    if x >= f64::MIN_POSITIVE {
        Ok(x)
    } else {
        Err(ConfigError::NotPositive(name))
    }
}

/// `x` if it is finite and not negative (a subnormal positive value is rejected).
pub const fn non_negative(name: &'static str, x: f64) -> Result<f64, ConfigError> {
    let x = tri!(finite(name, x));
    if x == 0.0 || x >= f64::MIN_POSITIVE {
        Ok(x)
    } else if x < 0.0 {
        Err(ConfigError::Negative(name))
    } else {
        Err(ConfigError::OutOfRange(name))
    }
}

/// `x` if it is finite and positive as an f32: like [`positive`], with f32's own subnormals
/// (below `f32::MIN_POSITIVE`, normal once widened to f64) rejected.
pub const fn positive_f32(name: &'static str, x: f32) -> Result<f32, ConfigError> {
    tri!(positive(name, x as f64));
    if x >= f32::MIN_POSITIVE {
        Ok(x)
    } else {
        Err(ConfigError::NotPositive(name))
    }
}

/// `x` if it is finite and not negative as an f32 (an f32 subnormal is rejected).
pub const fn non_negative_f32(name: &'static str, x: f32) -> Result<f32, ConfigError> {
    tri!(non_negative(name, x as f64));
    if x == 0.0 || x >= f32::MIN_POSITIVE {
        Ok(x)
    } else {
        Err(ConfigError::OutOfRange(name))
    }
}

/// `x` if it is finite.
pub const fn finite(name: &'static str, x: f64) -> Result<f64, ConfigError> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(ConfigError::NonFinite(name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn validators_name_the_parameter() {
        assert_eq!(
            positive("mass", f64::NAN),
            Err(ConfigError::NonFinite("mass"))
        );
        assert_eq!(
            positive("mass", f64::INFINITY),
            Err(ConfigError::NonFinite("mass"))
        );
        assert_eq!(positive("mass", 0.0), Err(ConfigError::NotPositive("mass")));
        assert_eq!(
            positive("mass", -1.0),
            Err(ConfigError::NotPositive("mass"))
        );
        assert_eq!(
            positive("mass", 1e-310),
            Err(ConfigError::NotPositive("mass"))
        );
        assert_eq!(positive("mass", 2.0), Ok(2.0));
        assert_eq!(non_negative("c", 0.0), Ok(0.0));
        assert_eq!(non_negative("c", -0.5), Err(ConfigError::Negative("c")));
        assert_eq!(non_negative("c", 1e-310), Err(ConfigError::OutOfRange("c")));
        assert_eq!(ConfigError::Negative("c").parameter(), "c");
        assert_eq!(positive_f32("f", 1e-40), Err(ConfigError::NotPositive("f")));
        assert_eq!(
            non_negative_f32("f", 1e-40),
            Err(ConfigError::OutOfRange("f"))
        );
        assert_eq!(non_negative_f32("f", 0.0), Ok(0.0));
        assert_eq!(
            positive_f32("f", f32::NAN),
            Err(ConfigError::NonFinite("f"))
        );
    }
}
