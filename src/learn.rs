//! Learning the disc's true tooth angles from steady running (time-synchronous averaging).
//!
//! Without a correction δ measures the disc, not the shaft: a 0.1° pitch error on a 6° tooth is
//! 1.7 % of speed, and run-out e at radius r adds a false once-per-turn ripple of about 2e/r.
//! Over a revolution at speed ω, tooth k takes dt_k = θ_k/ω and the turn takes T = 2π/ω, so
//! θ_k = 2π·dt_k/T. Speed ripple that is not synchronous with the revolution (a load of order
//! 1/8, say) averages out over many revolutions; ripple synchronous with the revolution cannot
//! be told from pitch error, so learn at light, steady load.
//!
//! The learner lives outside the monitor (it costs 8 bytes per tooth, only while learning) and
//! watches its edges as an [`EdgeSink`]: pass it to
//! [`crate::monitor::DeltaMonitor::on_edge_observed`]. Per-edge work is O(1): the intervals of a
//! revolution are staged, and each is folded into its tooth's running mean when the same tooth
//! comes round again in the next revolution, which by then is known to have been counted
//! correctly and steady.

use crate::encoder::Encoder;
use crate::error::{positive_f32, ConfigError};
use crate::speed::{EdgeSink, Fault, Tooth};

/// Per-tooth running means of the revolution fraction. Memory: 8·N bytes and a few words.
#[derive(Debug, Clone)]
pub struct ToothLearner<const N: usize> {
    staged: [u32; N],
    mean: [f32; N],
    /// Revolutions folded into every tooth (a revolution is folded whole).
    folded: u16,
    edges: u16,
    /// Interval sum of the revolution being staged.
    rev_ticks: u64,
    edges_in_rev: u16,
    /// The last tooth seen in the revolution being staged.
    last_tooth: u16,
    /// 1/T of the last staged revolution and 1/(folds + 1), if it may be folded.
    fold: Option<(f32, f32)>,
    prev_rev_ticks: u64,
    steady_tolerance: f32,
    started: bool,
}

impl<const N: usize> ToothLearner<N> {
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
            rev_ticks: 0,
            edges_in_rev: 0,
            last_tooth: 0,
            fold: None,
            prev_rev_ticks: 0,
            steady_tolerance: t,
            started: false,
        })
    }

    /// Forgets everything learned.
    pub fn reset(&mut self) {
        self.folded = 0;
        self.mean = [0.0; N];
        self.started = false;
        self.fold = None;
        self.prev_rev_ticks = 0;
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
}

impl<const N: usize> EdgeSink for ToothLearner<N> {
    #[inline]
    fn tooth(&mut self, ev: &Tooth) {
        if !ev.synced {
            self.started = false;
            return;
        }
        if !self.started {
            if ev.frame {
                self.started = true;
                self.rev_ticks = 0;
                self.edges_in_rev = 0;
            }
            return;
        }
        let k = usize::from(ev.tooth);
        if let (Some((inv_t, inv_n)), Some(slot), Some(mean)) =
            (self.fold, self.staged.get_mut(k), self.mean.get_mut(k))
        {
            // Running mean: no growing sum to lose digits over long learning runs.
            *mean += (*slot as f32 * inv_t - *mean) * inv_n;
            *slot = ev.dt;
        } else if let Some(slot) = self.staged.get_mut(k) {
            *slot = ev.dt;
        }
        self.rev_ticks = self.rev_ticks.wrapping_add(u64::from(ev.dt));
        self.edges_in_rev = self.edges_in_rev.wrapping_add(1);
        self.last_tooth = ev.tooth;
        if ev.frame {
            self.end_revolution();
        }
    }

    fn fault(&mut self, _fault: Fault, _time: u32) {
        self.finish_fold();
        self.started = false;
        self.prev_rev_ticks = 0;
    }
}

impl<const N: usize> ToothLearner<N> {
    /// A revolution was staged: it may be folded if it was counted whole and steady (the
    /// previous fold, if any, is complete now: every tooth came round once).
    /// A fold in progress is cut short: the teeth it has not reached still hold the staged
    /// revolution's intervals, so fold them now and every tooth keeps the same count.
    #[cold]
    fn finish_fold(&mut self) {
        let Some((inv_t, inv_n)) = self.fold.take() else {
            return;
        };
        let from = usize::from(self.last_tooth) + 1;
        let edges = usize::from(self.edges);
        for k in (from..edges).chain(core::iter::once(0)) {
            if let (Some(&slot), Some(mean)) = (self.staged.get(k), self.mean.get_mut(k)) {
                *mean += (slot as f32 * inv_t - *mean) * inv_n;
            }
        }
        self.folded = self.folded.saturating_add(1);
    }

    #[cold]
    fn end_revolution(&mut self) {
        if self.fold.is_some() {
            self.folded = self.folded.saturating_add(1);
        }
        let t = self.rev_ticks;
        let steady = self.prev_rev_ticks > 0
            && ((t as f32) - (self.prev_rev_ticks as f32)).abs() < self.steady_tolerance * t as f32;
        self.fold = if steady && self.edges_in_rev == self.edges && t > 0 {
            Some((1.0 / t as f32, 1.0 / (f32::from(self.folded) + 1.0)))
        } else {
            None
        };
        self.prev_rev_ticks = t;
        self.rev_ticks = 0;
        self.edges_in_rev = 0;
    }
}
