//! What the monitor is told about the machine: the disc, the capture timer, the δ window and
//! the alarm. Validated by the compiler ([`CONFIG`] is a `const`: a rejected value stops the
//! build with the parameter's name), so the image holds no checking code and no software
//! floating point; at start-up the firmware checks that TIM2 really counts at [`TIMER_HZ`] and
//! installs [`CONFIG`] in the monitor's `static`.

use drive_monitor::alarm::AlarmConfig;
use drive_monitor::encoder::{EncoderConfig, Estimator};
use drive_monitor::irregularity::{WindowConfig, WindowLength};
use drive_monitor::monitor::{DeltaMonitor, MonitorConfig};

/// Lines on the encoder disc: channel A's rising edges per revolution.
pub const LINES: u16 = 1024;

/// Whether the disc's index (Z) pulse frames the revolution: it is captured on TIM2_CH2.
/// Without Z wired, set `false`: the disc is then unframed (revolutions are counted in edges
/// from the first), and the index channel is left off.
pub const USE_INDEX: bool = true;

/// Width of TIM2's counter on the STM32G4 (RM0440, general-purpose timers TIM2/TIM5:
/// 32-bit); the timestamps wrap modulo 2^32, as the core is told.
pub const COUNTER_BITS: u8 = 32;

/// Encoder edges per capture: the timer input prescaler ICxPSC takes one capture every 1, 2,
/// 4 or 8 edges, and the core is told the same (`EncoderConfig::prescaler`), so that one
/// capture spans that many lines. [`LINES`] must be a multiple of it.
pub const EDGES_PER_CAPTURE: u8 = 1;

/// Captures per revolution: the monitor's capacity.
pub const CAPACITY: usize = LINES as usize / EDGES_PER_CAPTURE as usize;

/// The monitor this firmware runs: no per-tooth table (a uniform disc at its nominal pitches).
pub type Monitor = DeltaMonitor<CAPACITY>;

/// Edges per speed sample: the speed at each edge is the angle over the time of the last 16
/// captures, which divides the timer's quantization error by 16 (the configuration
/// `docs/accuracy.md` recommends for a 1024-line disc on a 170 MHz timer).
pub const SAMPLE_EDGES: u16 = 16;

/// Slowest speed still counted as running, rad/s.
pub const MIN_SPEED: f64 = 1.0;

/// The load's fundamental order: one load cycle per 8 revolutions (the seed's kneader, whose
/// load has this one order), so a δ window spans 8 revolutions. For a load of several orders
/// this is the largest order each of them is a whole multiple of (1/6 for orders 1/3 and 1/2,
/// which repeat every 6 revolutions), not the lowest: a window of the lowest order's cycle
/// alone reads δ low (`drive_monitor::drive::period_revolutions` gives the period).
pub const LOAD_ORDER: f64 = 0.125;

/// Permissible δ.
pub const DELTA_LIMIT: f32 = 0.06;

/// TIM2's counter clock, Hz: the 170 MHz `board::clocks` sets up, with the timer's prescaler
/// at 1. The firmware compares it with the clock read back from the RCC before it runs.
pub const TIMER_HZ: u32 = 170_000_000;

/// The encoder and capture timer, for a timer counting at `timer_hz`.
pub const fn encoder(timer_hz: f64) -> EncoderConfig {
    let mut encoder = if USE_INDEX {
        EncoderConfig::indexed(LINES, timer_hz)
    } else {
        EncoderConfig::unframed(LINES, timer_hz)
    };
    encoder.counter_bits = COUNTER_BITS;
    encoder.prescaler = EDGES_PER_CAPTURE;
    encoder.estimator = Estimator::Edges(SAMPLE_EDGES);
    encoder.min_speed = MIN_SPEED;
    encoder
}

/// The δ window: one load cycle.
pub const fn window() -> WindowConfig {
    WindowConfig {
        length: WindowLength::LoadOrder(LOAD_ORDER),
        steady_tolerance: 0.02,
    }
}

/// The δ alarm: over [`DELTA_LIMIT`] in 3 of the last 5 windows.
pub const fn alarm() -> AlarmConfig {
    AlarmConfig::new(DELTA_LIMIT)
}

/// The monitor's configuration, validated by the compiler.
pub const CONFIG: MonitorConfig =
    match MonitorConfig::new(encoder(TIMER_HZ as f64), window(), Some(alarm())) {
        Ok(c) => c,
        Err(e) => panic!("{}", e.parameter()),
    };
