//! The firmware's hardware-free modules, compiled for the host so they can be tested:
//! `ring` (which DMA ring slots to feed, when an index is due, and how a block and the index
//! pulses among them go to the core) and `config` (the monitor the firmware configures). The tests in `tests/` drive them with a simulated DMA and the real core.

#[path = "../../src/config.rs"]
pub mod config;
#[path = "../../src/ring.rs"]
pub mod ring;
