#![doc = include_str!("../README.md")]
#![cfg_attr(not(test), no_std)]
#![forbid(unsafe_code)]
#![warn(missing_docs)]
#![cfg_attr(
    not(test),
    warn(clippy::unwrap_used, clippy::expect_used, clippy::panic)
)]

pub mod alarm;
pub mod balancer;
pub mod drive;
pub mod encoder;
pub mod error;
pub mod irregularity;
pub mod learn;
pub mod math;
pub mod monitor;
pub mod pitch;
pub mod speed;
pub mod supports;
// Lets `testutil` name the crate the same way from unit tests and from `tests/hard_cases.rs`.
#[cfg(test)]
extern crate self as drive_monitor;
#[cfg(test)]
pub(crate) mod testutil;

pub use error::ConfigError;
pub use math::{Libm, Math, Micromath};
