//! The simulation engine: integrators with dense output ([`ode`]), the system assembled from the
//! effects a scene calls for ([`model`], [`system`], [`effects`], [`vibration`],
//! [`rotor_loads`]) and the encoder edges a capture timer would see ([`encoder`]).

pub mod cranking;
pub mod effects;
pub mod encoder;
pub mod model;
pub mod ode;
pub mod rotor_loads;
pub mod system;
pub mod vibration;
