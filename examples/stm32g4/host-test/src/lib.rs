//! The firmware's hardware-free modules, compiled for the host so they can be tested:
//! `ring` (which DMA ring slots to feed, when an index is due) and `config` (the monitor the
//! firmware builds). The tests in `tests/` drive them with a simulated DMA and the real core.

#[path = "../../src/config.rs"]
pub mod config;
#[path = "../../src/ring.rs"]
pub mod ring;
