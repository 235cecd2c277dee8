//! Drive effects: torques on the shaft from the motor and the working load (seed 000).
//!
//! Each type is one [`Effect`] with no states of its own; a scene lists the ones it needs.
//! The motor and the load are the core's [`drive_monitor::drive::Motor`] and
//! [`drive_monitor::drive::Load`] (validated by their constructors): the model lives in one
//! place, and the simulator integrates the same torques the prediction uses. The effects
//! without a core counterpart here have plain fields (deserializable from TOML, though no
//! scene-file table maps onto them); call `validate` once before use.

pub mod load;
pub mod motor;

pub use load::ViscousFriction;

use serde::Deserialize;

use drive_monitor::error::{finite, ConfigError};

use crate::engine::model::{Effect, Shaft};

/// A constant torque on the shaft (a test drive, or a constant external moment).
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConstantTorque {
    /// Torque, N·m (positive drives the shaft forward).
    pub torque: f64,
}

impl ConstantTorque {
    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), ConfigError> {
        finite("torque", self.torque).map(|_| ())
    }
}

impl Effect for ConstantTorque {
    fn name(&self) -> &'static str {
        "constant_torque"
    }
    fn eval(&self, _t: f64, _shaft: Shaft, _y: &[f64], _dy: &mut [f64]) -> f64 {
        self.torque
    }
}
