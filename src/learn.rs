//! Learning the disc's true tooth angles from steady running (time-synchronous averaging).
//!
//! Without a correction δ measures the disc, not the shaft: a 0.1° pitch error on a 6° tooth is
//! 1.7 % of speed, and run-out e at radius r adds a false once-per-turn ripple of about 2e/r.
//! Over a revolution at speed ω, tooth k takes dt_k = θ_k/ω and the turn takes T = 2π/ω, so
//! θ_k = 2π·dt_k/T. Speed ripple that is not synchronous with the revolution (a load of order
//! 1/8, say) averages out over many revolutions; ripple synchronous with the revolution cannot
//! be told from pitch error, so learn at light, steady load.
//!
//! Per-edge work is O(1): the intervals of a revolution are staged, and each is folded into
//! its tooth's running mean when the same tooth comes round again in the next revolution,
//! which by then is known to have been counted correctly and steady.

use crate::encoder::Encoder;
use crate::error::ConfigError;
use crate::speed::EdgeEvent;

/// Per-tooth running means of the revolution fraction. Memory: 10·N bytes.
#[derive(Debug, Clone)]
pub struct ToothLearner<const N: usize> {
    staged: [u32; N],
    mean: [f32; N],
    count: [u16; N],
    /// Interval sum of the revolution being staged.
    rev_ticks: u64,
    edges_in_rev: u16,
    /// 1/T of the last staged revolution, if it may be folded.
    fold: Option<f32>,
    prev_rev_ticks: u64,
    steady_tolerance: f32,
    started: bool,
}

impl<const N: usize> ToothLearner<N> {
    /// A learner that accepts revolutions whose period is within `steady_tolerance` (fraction)
    /// of the previous one's.
    pub fn new(steady_tolerance: f32) -> Self {
        ToothLearner {
            staged: [0; N],
            mean: [0.0; N],
            count: [0; N],
            rev_ticks: 0,
            edges_in_rev: 0,
            fold: None,
            prev_rev_ticks: 0,
            steady_tolerance,
            started: false,
        }
    }

    /// Forgets everything learned.
    pub fn reset(&mut self) {
        *self = Self::new(self.steady_tolerance);
    }

    /// Takes one edge event. O(1).
    pub fn on_event(&mut self, edges: u16, ev: &EdgeEvent) {
        if ev.fault.is_some() {
            self.started = false;
            self.fold = None;
            self.prev_rev_ticks = 0;
            return;
        }
        let Some((dt, tooth)) = ev.interval else {
            return;
        };
        if !self.started {
            if ev.frame {
                self.started = true;
                self.rev_ticks = 0;
                self.edges_in_rev = 0;
            }
            return;
        }
        let k = tooth as usize;
        if let (Some(inv_t), Some(&staged), Some(mean), Some(count)) = (
            self.fold,
            self.staged.get(k),
            self.mean.get_mut(k),
            self.count.get_mut(k),
        ) {
            let n = count.saturating_add(1);
            *count = n;
            // Running mean: no growing sum to lose digits over long learning runs.
            *mean += (staged as f32 * inv_t - *mean) / n as f32;
        }
        if let Some(s) = self.staged.get_mut(k) {
            *s = dt;
        }
        self.rev_ticks = self.rev_ticks.saturating_add(dt as u64);
        self.edges_in_rev = self.edges_in_rev.saturating_add(1);
        if ev.frame {
            let t = self.rev_ticks;
            let steady = self.prev_rev_ticks > 0
                && (t as f32 - self.prev_rev_ticks as f32).abs() < self.steady_tolerance * t as f32;
            self.fold = if steady && self.edges_in_rev == edges && t > 0 {
                Some(1.0 / t as f32)
            } else {
                None
            };
            self.prev_rev_ticks = t;
            self.rev_ticks = 0;
            self.edges_in_rev = 0;
        }
    }

    /// Revolutions folded into the least-learned tooth.
    pub fn revolutions(&self, edges: u16) -> u16 {
        self.count
            .iter()
            .take(edges as usize)
            .copied()
            .min()
            .unwrap_or(0)
    }

    /// The learned pitch table (rad, summing to 2π) once every tooth has at least
    /// `min_revolutions` revolutions, written into `out` (`edges` entries); apply it with
    /// [`Encoder::with_pitches`] and store it to survive a reboot.
    pub fn pitches<'a>(
        &self,
        encoder: &Encoder<N>,
        min_revolutions: u16,
        out: &'a mut [f32; N],
    ) -> Result<&'a [f32], ConfigError> {
        let edges = encoder.edges() as usize;
        if self.revolutions(encoder.edges()) < min_revolutions.max(1) {
            return Err(ConfigError::Inconsistent("learned revolutions"));
        }
        let sum: f64 = self.mean.iter().take(edges).map(|&m| m as f64).sum();
        if sum.is_nan() || sum <= 0.0 {
            return Err(ConfigError::Inconsistent("learned revolutions"));
        }
        for (o, &m) in out.iter_mut().zip(self.mean.iter()).take(edges) {
            *o = (core::f64::consts::TAU * m as f64 / sum) as f32;
        }
        Ok(out.get(..edges).unwrap_or(&[]))
    }
}
