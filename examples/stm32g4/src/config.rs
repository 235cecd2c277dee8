//! What the monitor is told about the machine: the disc, the capture timer, the δ window and
//! the alarm. Validated once at start-up; a rejected value stops the firmware with the
//! [`ConfigError`] naming it.

use drive_monitor::alarm::AlarmConfig;
use drive_monitor::encoder::{Encoder, EncoderConfig, Framing};
use drive_monitor::irregularity::{WindowConfig, WindowLength};
use drive_monitor::monitor::DeltaMonitor;
use drive_monitor::ConfigError;

/// Lines on the encoder disc: channel A's rising edges per revolution.
pub const LINES: u16 = 1024;

/// The monitor's capacity in edges per revolution (at least [`LINES`]).
pub const CAPACITY: usize = LINES as usize;

/// The monitor this firmware runs.
pub type Monitor = DeltaMonitor<CAPACITY>;

/// How revolutions are framed. `Framing::Index` needs the Z pulse on TIM2_CH2; without it
/// wired, set `Framing::None` (revolutions are then counted in edges, and the index channel
/// is left off).
pub const FRAMING: Framing = Framing::Index;

/// Whether the index channel (TIM2_CH2) is captured.
pub const USE_INDEX: bool = matches!(FRAMING, Framing::Index);

/// Width of TIM2's counter on the STM32G4 (RM0440, general-purpose timers TIM2/TIM5:
/// 32-bit); the timestamps wrap modulo 2^32, as the core is told.
pub const COUNTER_BITS: u8 = 32;

/// Encoder edges per capture: the timer input prescaler ICxPSC takes one capture every 1, 2,
/// 4 or 8 edges. Today's `DeltaMonitor::on_edge` takes one capture per edge, so this stays 1
/// until the batch entry point that accepts prescaled captures is used in `feed::Feeder::feed`.
pub const EDGES_PER_CAPTURE: u8 = 1;
const _: () = assert!(
    EDGES_PER_CAPTURE == 1,
    "on_edge needs one capture per edge; prescaled captures need the batch entry point"
);

/// Slowest speed still counted as running, rad/s.
pub const MIN_SPEED: f64 = 1.0;

/// The load's lowest order: one load cycle per 8 revolutions (the seed's kneader), so a δ
/// window spans 8 revolutions.
pub const LOAD_ORDER: f64 = 0.125;

/// Permissible δ.
pub const DELTA_LIMIT: f32 = 0.06;

/// Builds the monitor for a capture timer counting at `timer_hz` (the real TIM2 counter clock
/// after the RCC setup).
pub fn monitor(timer_hz: f64) -> Result<Monitor, ConfigError> {
    let mut encoder = EncoderConfig::new(LINES, timer_hz);
    encoder.framing = FRAMING;
    encoder.counter_bits = COUNTER_BITS;
    encoder.min_speed = MIN_SPEED;
    let window = WindowConfig {
        length: WindowLength::LoadOrder(LOAD_ORDER),
        steady_tolerance: 0.02,
    };
    DeltaMonitor::new(
        Encoder::new(encoder)?,
        window,
        Some(AlarmConfig::new(DELTA_LIMIT)),
    )
}
