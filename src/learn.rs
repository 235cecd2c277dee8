//! Learning the disc's true tooth angles from steady running (time-synchronous averaging).
//!
//! Without a correction δ measures the disc, not the shaft: a 0.1° pitch error on a 6° tooth is
//! 1.7 % of speed, and run-out e at radius r adds a false once-per-turn ripple of about 2e/r.
//! Over a revolution at speed ω, tooth k takes dt_k = θ_k/ω and the turn takes T = 2π/ω, so
//! θ_k = 2π·dt_k/T. Speed ripple that is not synchronous with the revolution (a load of order
//! 1/8, say) averages out over many revolutions; ripple synchronous with the revolution cannot
//! be told from pitch error, so learn at light, steady load.
//!
//! The learner lives outside the monitor (8 bytes per tooth, only while learning) and watches
//! its edges as an [`EdgeSink`]: pass it to
//! [`crate::monitor::DeltaMonitor::on_edge_observed`]. Per edge it stages the tooth's interval
//! (one store); at the frame that ends a revolution counted whole (from a frame, in sync, no
//! fault) and steady (its period within the tolerance of the previous one's), every tooth's
//! share of it is folded into that tooth's running mean, once per revolution and out of line.

// The per-edge path runs through this module: no integer operation here may overflow or
// divide by zero, and no index may fail, in a debug build either (`panic-free.sh dev` in
// examples/qemu checks the image).
#![cfg_attr(
    not(test),
    deny(clippy::arithmetic_side_effects, clippy::indexing_slicing)
)]

use crate::encoder::Encoder;
use crate::error::{positive_f32, ConfigError};
use crate::speed::{each_pair, EdgeSink, Fault, Tooth};
use core::num::NonZeroUsize;

/// Per-tooth running means of the revolution fraction. Memory: 8·N bytes and a few words.
#[derive(Debug, Clone)]
pub struct ToothLearner<const N: usize> {
    /// This revolution's interval of every tooth, ticks.
    staged: [u32; N],
    /// Every tooth's learned share of a revolution.
    mean: [f32; N],
    /// Revolutions folded into every tooth (a revolution is folded whole).
    folded: u16,
    edges: u16,
    /// The revolution being staged runs from a frame in sync with no fault since.
    whole: bool,
    /// Period of the previous whole revolution, ticks (0: none).
    prev_period: u64,
    steady_tolerance: f32,
    /// Time of the last frame; with a 32-bit counter and a revolution within 2^32 ticks
    /// (`timed`), a period is the difference of two frame times, not a sum of intervals.
    frame_time: u32,
    timed: bool,
}

impl<const N: usize> ToothLearner<N> {
    /// `N` as a divisor (1 for an empty learner).
    const TEETH: NonZeroUsize = match NonZeroUsize::new(N) {
        Some(n) => n,
        None => NonZeroUsize::MIN,
    };

    /// A learner for `encoder`'s wheel that accepts revolutions whose period is within
    /// `steady_tolerance` (a fraction, 0 to 0.5) of the previous one's.
    pub fn new(encoder: &Encoder, steady_tolerance: f32) -> Result<Self, ConfigError> {
        let t = positive_f32("steady_tolerance", steady_tolerance)?;
        if t > 0.5 {
            return Err(ConfigError::OutOfRange("steady_tolerance"));
        }
        if usize::from(encoder.edges()) > N {
            return Err(ConfigError::Capacity("learner teeth"));
        }
        Ok(ToothLearner {
            staged: [0; N],
            mean: [0.0; N],
            folded: 0,
            edges: encoder.edges(),
            whole: false,
            prev_period: 0,
            steady_tolerance: t,
            frame_time: 0,
            // Every interval is within the timeout, so a revolution is within edges·timeout.
            timed: encoder.mask() == u32::MAX
                && f64::from(encoder.edges()) * f64::from(encoder.timeout_ticks())
                    < f64::from(u32::MAX),
        })
    }

    /// Forgets everything learned.
    pub fn reset(&mut self) {
        self.mean = [0.0; N];
        self.folded = 0;
        self.whole = false;
        self.prev_period = 0;
    }

    /// Revolutions folded into every tooth.
    pub fn revolutions(&self) -> u16 {
        self.folded
    }

    /// The learned pitch table (rad, summing to 2π) once at least `min_revolutions`
    /// revolutions are folded, written into `out` (`edges` entries); apply it with
    /// [`crate::monitor::DeltaMonitor::set_pitches`] and store it to survive a reboot.
    pub fn pitches<'a>(
        &self,
        min_revolutions: u16,
        out: &'a mut [f32; N],
    ) -> Result<&'a [f32], ConfigError> {
        let edges = usize::from(self.edges);
        if self.folded < min_revolutions.max(1) {
            return Err(ConfigError::Inconsistent("learned revolutions"));
        }
        let sum: f64 = self.mean.iter().take(edges).map(|&m| f64::from(m)).sum();
        if sum.is_nan() || sum <= 0.0 {
            return Err(ConfigError::Inconsistent("learned revolutions"));
        }
        for (o, &m) in out.iter_mut().zip(self.mean.iter()).take(edges) {
            *o = (core::f64::consts::TAU * f64::from(m) / sum) as f32;
        }
        Ok(out.get(..edges).unwrap_or(&[]))
    }

    /// A revolution ended at a frame: if it was staged whole and steady, fold every tooth's
    /// share of it into the running means (the staged intervals of a whole revolution add up
    /// to its period). Once per revolution, out of line.
    #[cold]
    #[inline(never)]
    fn end_revolution(&mut self, time: u32) {
        let edges = usize::from(self.edges);
        let since = time.wrapping_sub(self.frame_time);
        self.frame_time = time;
        if self.whole {
            let t: u64 = if self.timed {
                u64::from(since)
            } else {
                // At most 2^16 intervals of 32 bits: the sum does not wrap.
                self.staged
                    .iter()
                    .take(edges)
                    .fold(0u64, |s, &d| s.wrapping_add(u64::from(d)))
            };
            let prev = self.prev_period;
            self.prev_period = t;
            let steady =
                prev > 0 && ((t as f32) - (prev as f32)).abs() < self.steady_tolerance * t as f32;
            if steady && t > 0 {
                // Running mean: no growing sum to lose digits over long learning runs.
                let weight = 1.0 / (f32::from(self.folded) + 1.0);
                let (keep, take) = (1.0 - weight, weight / t as f32);
                let mean = self.mean.get_mut(..edges).unwrap_or_default();
                each_pair(mean, &self.staged, |m, &d| *m = keep * *m + take * d as f32);
                self.folded = self.folded.saturating_add(1);
            }
        }
        // The revolution starting here is whole if nothing cuts it.
        self.whole = true;
    }
}

impl<const N: usize> EdgeSink for ToothLearner<N> {
    /// Stages this tooth's interval: one store on the ordinary tooth. Teeth before sync are
    /// staged too but never folded: a revolution is folded only from frame to frame, frames
    /// come in sync, and sync is lost only through a fault, which cuts the revolution.
    #[inline]
    fn tooth(&mut self, ev: &Tooth) {
        // `tooth` < edges ≤ N, so the remainder is the tooth itself; it spares a bounds
        // branch (an `and` when N is a power of two).
        if let Some(s) = self.staged.get_mut(usize::from(ev.tooth) % Self::TEETH) {
            *s = ev.dt;
        }
        if ev.frame {
            self.end_revolution(ev.time);
        }
    }

    fn fault(&mut self, _fault: Fault, _time: u32) {
        // The revolution in progress cannot be trusted, nor compared with the next.
        self.whole = false;
        self.prev_period = 0;
    }
}
