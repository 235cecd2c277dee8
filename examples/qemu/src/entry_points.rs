//! The core's per-edge entry points as firmware calls them, each out of line under a name of
//! its own, so that `panic-free.sh` finds them in the release image, checks that nothing they
//! reach can panic, and sizes the code they and the configuration reach. [`run`] feeds the bench stream through them and checks that they
//! report the windows the inlined calls of `monitor_bench` do.

use drive_monitor::alarm::AlarmConfig;
use drive_monitor::encoder::EncoderConfig;
use drive_monitor::irregularity::WindowConfig;
use drive_monitor::learn::ToothLearner;
use drive_monitor::monitor::{DeltaMonitor, MonitorConfig, WindowOutcome};
use drive_monitor::pitch::Corrected;
use drive_monitor::speed::Direction;
use drive_monitor::ConfigError;

/// Configuration in place, validated at run time (not a per-edge path: `panic-free.sh` leaves
/// it out of its check and counts it in the monitor's code size with run-time configuration).
#[inline(never)]
pub fn configure_monitor(
    m: &mut DeltaMonitor<1024>,
    encoder: EncoderConfig,
    window: WindowConfig,
    alarm: Option<AlarmConfig>,
) -> Result<(), ConfigError> {
    m.configure_from(encoder, window, alarm)
}

/// A configuration the compiler validated, installed in place (what firmware with a fixed
/// configuration links instead of [`configure_monitor`]; left out of the panic-free check
/// like it, and counted in the monitor's code size).
#[inline(never)]
pub fn apply_config(m: &mut DeltaMonitor<1024>, config: &MonitorConfig) -> Result<(), ConfigError> {
    m.apply(config)
}

/// An edge from a capture interrupt.
#[inline(never)]
pub fn on_edge(m: &mut DeltaMonitor<1024>, t: u32, d: Option<Direction>) -> Option<WindowOutcome> {
    m.on_edge(t, d)
}

/// An edge with the per-tooth learner watching.
#[inline(never)]
pub fn on_edge_learning(
    m: &mut DeltaMonitor<1024>,
    learner: &mut ToothLearner<1024>,
    t: u32,
    d: Option<Direction>,
) -> Option<WindowOutcome> {
    m.on_edge_observed(t, d, learner)
}

/// An edge on a disc with corrected pitches.
#[inline(never)]
pub fn on_edge_corrected(
    m: &mut DeltaMonitor<1024, Corrected<1024>>,
    t: u32,
    d: Option<Direction>,
) -> Option<WindowOutcome> {
    m.on_edge(t, d)
}

/// A DMA half-buffer of captures; the last window it ended, if any, and how many.
#[inline(never)]
pub fn on_captures(m: &mut DeltaMonitor<1024>, caps: &[u32]) -> (Option<WindowOutcome>, u32) {
    let mut last = None;
    let mut n = 0u32;
    m.on_captures(caps, |o| {
        last = Some(o);
        n = n.wrapping_add(1);
    });
    (last, n)
}

/// An index pulse.
#[inline(never)]
pub fn on_index(m: &mut DeltaMonitor<1024>, t: u32) {
    m.on_index(t)
}

/// The standstill check from a timer tick.
#[inline(never)]
pub fn poll(m: &mut DeltaMonitor<1024>, now: u32) -> Option<WindowOutcome> {
    m.poll(now)
}
