//! The irregularity monitor: encoder edges in, δ windows, shaft state, alarm and diagnostics out.
//!
//! [`DeltaMonitor`] ties together the validated configuration ([`Encoder`], [`Window`],
//! [`DeltaAlarm`]) and the per-edge state ([`SpeedTracker`], [`WindowState`],
//! [`ToothLearner`]). Call [`DeltaMonitor::on_edge`] from the capture interrupt with the raw
//! timestamp, [`DeltaMonitor::on_index`] for an index pulse, and [`DeltaMonitor::poll`]
//! periodically (at least once per counter period) so a stopped shaft is seen as standstill.
//! Every call is O(1), allocation-free and panic-free for any input.

use crate::alarm::{AlarmConfig, AlarmEvent, DeltaAlarm, Verdict};
use crate::encoder::Encoder;
use crate::error::ConfigError;
use crate::irregularity::{Window, WindowConfig, WindowReport, WindowState};
use crate::learn::ToothLearner;
use crate::speed::{Direction, EdgeCounters, Fault, ShaftState, SpeedSample, SpeedTracker};

/// Everything the monitor counted.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct Diagnostics {
    /// Edge-level counters.
    pub edges: EdgeCounters,
    /// Valid windows reported.
    pub valid_windows: u32,
    /// Invalid windows reported.
    pub invalid_windows: u32,
    /// Alarms raised.
    pub alarms_raised: u32,
}

/// A finished window with the alarm's view of it.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "defmt", derive(defmt::Format))]
pub struct WindowOutcome {
    /// The window.
    pub report: WindowReport,
    /// How the alarm judged it (`None` without an alarm configured).
    pub verdict: Option<Verdict>,
    /// The alarm transition it caused.
    pub event: Option<AlarmEvent>,
}

/// Monitor of running irregularity for a disc of up to `N` edges per revolution.
#[derive(Debug, Clone)]
pub struct DeltaMonitor<const N: usize> {
    encoder: Encoder<N>,
    window: Window,
    tracker: SpeedTracker,
    state: WindowState,
    alarm: Option<DeltaAlarm>,
    learner: Option<ToothLearner<N>>,
    /// The latest speed sample as angle (rad) over ticks (0 ticks: none); converted to rad/s
    /// only when asked for, so the per-edge path does not divide.
    last_angle: f32,
    last_ticks: u32,
    diag: Diagnostics,
}

impl<const N: usize> DeltaMonitor<N> {
    /// Builds a monitor from validated pieces.
    pub fn new(
        encoder: Encoder<N>,
        window: WindowConfig,
        alarm: Option<AlarmConfig>,
    ) -> Result<Self, ConfigError> {
        let window = window.validate()?;
        let alarm = match alarm {
            Some(a) => Some(a.validate()?),
            None => None,
        };
        Ok(DeltaMonitor {
            encoder,
            window,
            tracker: SpeedTracker::new(),
            state: WindowState::new(),
            alarm,
            learner: None,
            last_angle: 0.0,
            last_ticks: 0,
            diag: Diagnostics::default(),
        })
    }

    /// The encoder in use.
    pub fn encoder(&self) -> &Encoder<N> {
        &self.encoder
    }

    /// Revolutions per δ window.
    pub fn window_revolutions(&self) -> u16 {
        self.window.revolutions()
    }

    /// Replaces the pitch table (a learned or stored correction); restarts framing.
    pub fn set_pitches(&mut self, pitches: &[f32]) -> Result<(), ConfigError> {
        self.encoder = self.encoder.clone().with_pitches(pitches)?;
        self.tracker = SpeedTracker::new();
        self.state = WindowState::new();
        Ok(())
    }

    /// Starts learning per-tooth corrections on revolutions whose period is within
    /// `steady_tolerance` of the previous one's.
    pub fn start_learning(&mut self, steady_tolerance: f32) {
        self.learner = Some(ToothLearner::new(steady_tolerance));
    }

    /// The learner, while learning.
    pub fn learner(&self) -> Option<&ToothLearner<N>> {
        self.learner.as_ref()
    }

    /// Stops learning and, with at least `min_revolutions` per tooth, applies what was learned
    /// (also written into `out`, to store it).
    pub fn finish_learning<'a>(
        &mut self,
        min_revolutions: u16,
        out: &'a mut [f32; N],
    ) -> Result<&'a [f32], ConfigError> {
        let learner = self
            .learner
            .take()
            .ok_or(ConfigError::Inconsistent("learned revolutions"))?;
        let table = learner.pitches(&self.encoder, min_revolutions, out)?;
        self.set_pitches(table)?;
        Ok(table)
    }

    /// The shaft state.
    pub fn shaft_state(&self) -> ShaftState {
        self.tracker.state()
    }

    /// The latest speed sample, rad/s (0 unless running).
    pub fn speed(&self) -> f32 {
        if self.tracker.state() == ShaftState::Running && self.last_ticks > 0 {
            SpeedSample {
                angle: self.last_angle,
                ticks: self.last_ticks,
                tooth: 0,
            }
            .omega(self.encoder.timer_hz())
        } else {
            0.0
        }
    }

    /// Whether the δ alarm is on.
    pub fn alarm_active(&self) -> bool {
        self.alarm.is_some_and(|a| a.active())
    }

    /// The counters.
    pub fn diagnostics(&self) -> Diagnostics {
        Diagnostics {
            edges: self.tracker.counters(),
            ..self.diag
        }
    }

    /// An index pulse was captured; call before the edge that follows it.
    pub fn on_index(&mut self) {
        self.tracker.on_index();
    }

    /// One encoder edge captured at `ticks` (raw counter value), with the direction if known.
    /// Returns a window when one ends.
    pub fn on_edge(&mut self, ticks: u32, direction: Option<Direction>) -> Option<WindowOutcome> {
        let ev = self.tracker.on_edge(&self.encoder, ticks, direction);
        if let Some(s) = &ev.sample {
            self.last_angle = s.angle;
            self.last_ticks = s.ticks;
        }
        if let Some(l) = self.learner.as_mut() {
            l.on_event(self.encoder.edges(), &ev);
        }
        let report = self
            .state
            .on_event(&self.window, self.encoder.timer_hz(), &ev)?;
        Some(self.finish(report))
    }

    /// Checks for standstill at time `now` (ticks); returns the window cut short, if any.
    pub fn poll(&mut self, now: u32) -> Option<WindowOutcome> {
        let fault = self.tracker.poll(&self.encoder, now)?;
        self.last_ticks = 0;
        if let Some(l) = self.learner.as_mut() {
            l.on_event(
                self.encoder.edges(),
                &crate::speed::EdgeEvent {
                    fault: Some(fault),
                    ..Default::default()
                },
            );
        }
        let report = self
            .state
            .abort(&self.window, self.encoder.timer_hz(), fault)?;
        Some(self.finish(report))
    }

    /// Counts a finished window and runs the alarm on it: once per window, kept out of line so
    /// the per-edge path stays small.
    #[cold]
    #[inline(never)]
    fn finish(&mut self, report: WindowReport) -> WindowOutcome {
        if report.valid() {
            self.diag.valid_windows = self.diag.valid_windows.wrapping_add(1);
        } else {
            self.diag.invalid_windows = self.diag.invalid_windows.wrapping_add(1);
        }
        let (verdict, event) = match self.alarm.as_mut() {
            Some(a) => {
                let (v, e) = a.update(&report);
                (Some(v), e)
            }
            None => (None, None),
        };
        if event == Some(AlarmEvent::Raised) {
            self.diag.alarms_raised = self.diag.alarms_raised.wrapping_add(1);
        }
        WindowOutcome {
            report,
            verdict,
            event,
        }
    }
}

/// Why a window was invalid, as a short name for logs and reports.
pub fn fault_name(f: Fault) -> &'static str {
    match f {
        Fault::Glitch => "glitch",
        Fault::MissingEdge => "missing-edge",
        Fault::ExtraEdge => "extra-edge",
        Fault::MissingFrame => "missing-frame",
        Fault::Reversal => "reversal",
        Fault::Timeout => "timeout",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::encoder::{EncoderConfig, Estimator, Framing};
    use crate::irregularity::WindowLength;
    use std::vec::Vec;

    /// Capture timestamps of a disc whose edge k sits at `angle(k)`, for a shaft whose speed is
    /// `omega(φ)`: t(θ) = ∫dφ/ω by Simpson's rule per pitch (error far below one tick).
    struct Gen {
        t: f64,
        phi: f64,
    }

    impl Gen {
        fn advance(&mut self, to: f64, omega: &dyn Fn(f64) -> f64) -> f64 {
            let n = 8;
            let h = (to - self.phi) / n as f64;
            let mut s = 1.0 / omega(self.phi) + 1.0 / omega(to);
            for i in 1..n {
                let w = if i % 2 == 1 { 4.0 } else { 2.0 };
                s += w / omega(self.phi + i as f64 * h);
            }
            self.t += s * h / 3.0;
            self.phi = to;
            self.t
        }
    }

    #[derive(Clone, Copy, PartialEq, Debug)]
    enum Ev {
        Edge(u32),
        Index,
    }

    /// Edge stream for `revs` revolutions of a disc with `positions` lines, `missing` positions
    /// absent at the start of each turn, index pulse before tooth 0 if `index`, per-position
    /// angle error `err(k)`.
    #[allow(clippy::too_many_arguments)]
    fn stream(
        positions: u32,
        missing: u32,
        index: bool,
        revs: u32,
        timer_hz: f64,
        mask: u32,
        omega: &dyn Fn(f64) -> f64,
        err: &dyn Fn(u32) -> f64,
    ) -> Vec<Ev> {
        let mut g = Gen { t: 0.0, phi: 0.0 };
        let mut out = Vec::new();
        let p = core::f64::consts::TAU / positions as f64;
        for r in 0..revs {
            for k in missing..positions {
                let to = core::f64::consts::TAU * r as f64 + p * k as f64 + err(k) + p * 0.5;
                let t = g.advance(to, omega);
                if index && k == missing {
                    out.push(Ev::Index);
                }
                out.push(Ev::Edge(((t * timer_hz) as u64 as u32) & mask));
            }
        }
        out
    }

    fn monitor(
        positions: u16,
        framing: Framing,
        k: u16,
        bits: u8,
        timer_hz: f64,
        revs: u16,
    ) -> DeltaMonitor<1024> {
        let mut c = EncoderConfig::new(positions, timer_hz);
        c.framing = framing;
        c.estimator = Estimator::Edges(k);
        c.counter_bits = bits;
        c.min_speed = 20.0;
        let enc = Encoder::new(c).unwrap();
        let w = WindowConfig {
            length: WindowLength::Revolutions(revs),
            steady_tolerance: 0.02,
        };
        DeltaMonitor::new(enc, w, Some(AlarmConfig::new(0.06))).unwrap()
    }

    fn run(m: &mut DeltaMonitor<1024>, evs: &[Ev]) -> Vec<WindowOutcome> {
        let mut out = Vec::new();
        for e in evs {
            match *e {
                Ev::Index => m.on_index(),
                Ev::Edge(t) => out.extend(m.on_edge(t, Some(Direction::Forward))),
            }
        }
        out
    }

    /// ω(φ) = ω̄(1 + ε sin(φ/8)): δ = 2ε exactly (2(ωmax − ωmin)/(ωmax + ωmin)).
    fn kneader(eps: f64) -> impl Fn(f64) -> f64 {
        move |phi: f64| 134.0 * (1.0 + eps * (phi / 8.0).sin())
    }

    #[test]
    fn measures_delta_of_a_known_speed_ripple() {
        let w = kneader(0.015);
        for (bits, k) in [(32u8, 16u16), (16, 16), (32, 1)] {
            let mut m = monitor(1024, Framing::Index, k, bits, 84e6, 8);
            let mask = if bits == 32 {
                u32::MAX
            } else {
                (1 << bits) - 1
            };
            let evs = stream(1024, 0, true, 8 * 5 + 2, 84e6, mask, &w, &|_| 0.0);
            let out = run(&mut m, &evs);
            let valid: Vec<_> = out.iter().filter(|o| o.report.valid()).collect();
            assert_eq!(valid.len(), 5, "bits {bits} k {k}: {out:?}");
            for o in &valid {
                let r = o.report;
                // Quantization bounds the error by the reported floor.
                assert!(
                    (r.delta as f64 - 0.03).abs() <= r.noise_floor as f64 + 1e-5,
                    "{r:?}"
                );
                // Angle over time of ω̄(1 + ε sin): ω̄·√(1 − ε²).
                assert!(
                    (r.omega_mean as f64 / (134.0 * (1.0 - 0.015f64.powi(2)).sqrt()) - 1.0).abs()
                        < 2e-6
                );
            }
            if k == 16 {
                // Averaging 16 edges puts the floor at 2/(16·3800) ≈ 3e-5: δ within 0.3 %.
                let r = valid[4].report;
                assert!(r.noise_floor < 4e-5, "{r:?}");
                assert!((r.delta as f64 / 0.03 - 1.0).abs() < 3e-3, "{r:?}");
                assert!(r.steady);
            }
            assert_eq!(m.diagnostics().edges.glitches, 0);
            assert_eq!(m.diagnostics().invalid_windows, 0);
            assert_eq!(m.shaft_state(), ShaftState::Running);
        }
    }

    #[test]
    fn missing_tooth_disc_frames_revolutions() {
        let w = kneader(0.01);
        let mut m = monitor(60, Framing::MissingTooth { missing: 2 }, 4, 32, 10e6, 8);
        let evs = stream(60, 2, false, 8 * 4 + 2, 10e6, u32::MAX, &w, &|_| 0.0);
        let out = run(&mut m, &evs);
        let valid: Vec<_> = out.iter().filter(|o| o.report.valid()).collect();
        assert!(valid.len() >= 3, "{out:?}");
        for o in valid {
            assert!((o.report.delta - 0.02).abs() < 2e-3, "{:?}", o.report);
        }
        assert_eq!(m.diagnostics().edges.missing, 0);
    }

    #[test]
    fn faults_invalidate_windows_with_their_reason() {
        let w = kneader(0.01);
        let base = stream(256, 0, true, 40, 84e6, u32::MAX, &w, &|_| 0.0);
        let edges: Vec<usize> = (0..base.len())
            .filter(|&i| matches!(base[i], Ev::Edge(_)))
            .collect();
        // A glitch between two edges in the third window.
        let mut g = base.clone();
        let i = edges[256 * 20 + 10];
        if let (Ev::Edge(a), Ev::Edge(b)) = (g[i], g[i + 1]) {
            g.insert(i + 1, Ev::Edge(a + (b - a) / 5));
        }
        let mut m = monitor(256, Framing::Index, 4, 32, 84e6, 8);
        let out = run(&mut m, &g);
        assert!(out.iter().any(|o| o.report.fault == Some(Fault::Glitch)));
        assert_eq!(m.diagnostics().edges.glitches, 1);
        // A dropped edge.
        let mut d = base.clone();
        d.remove(edges[256 * 20 + 10]);
        let mut m = monitor(256, Framing::Index, 4, 32, 84e6, 8);
        let out = run(&mut m, &d);
        assert!(
            out.iter()
                .any(|o| o.report.fault == Some(Fault::MissingEdge)),
            "{out:?}"
        );
        assert!(m.diagnostics().invalid_windows >= 1);
        // A lost index pulse.
        let mut x = base.clone();
        let idx: Vec<usize> = (0..x.len()).filter(|&i| x[i] == Ev::Index).collect();
        x.remove(idx[20]);
        let mut m = monitor(256, Framing::Index, 4, 32, 84e6, 8);
        let out = run(&mut m, &x);
        assert!(
            out.iter()
                .any(|o| o.report.fault == Some(Fault::MissingFrame)),
            "{out:?}"
        );
        // Valid windows resume after each fault.
        assert!(out.last().unwrap().report.valid());
    }

    #[test]
    fn reversal_and_standstill_are_states() {
        let w = kneader(0.0);
        let evs = stream(256, 0, true, 20, 84e6, u32::MAX, &w, &|_| 0.0);
        let mut m = monitor(256, Framing::Index, 1, 32, 84e6, 1);
        assert_eq!(m.shaft_state(), ShaftState::NoSignal);
        run(&mut m, &evs[..evs.len() / 2]);
        assert_eq!(m.shaft_state(), ShaftState::Running);
        assert!((m.speed() - 134.0).abs() < 0.1);
        let half = evs.len() / 2 + usize::from(evs[evs.len() / 2] == Ev::Index);
        let Ev::Edge(t) = evs[half] else {
            unreachable!()
        };
        let o = m.on_edge(t, Some(Direction::Reverse)).unwrap();
        assert_eq!(o.report.fault, Some(Fault::Reversal));
        assert_eq!(m.shaft_state(), ShaftState::Reversed);
        assert_eq!(m.speed(), 0.0);
        // Forward again, then stop: the poll after the timeout reports standstill.
        let rest: Vec<Ev> = evs[half + 1..].to_vec();
        run(&mut m, &rest);
        assert_eq!(m.shaft_state(), ShaftState::Running);
        let Some(Ev::Edge(last)) = rest.last().copied() else {
            unreachable!()
        };
        assert!(m.poll(last + 1000).is_none());
        let o = m.poll(last + m.encoder().timeout_ticks() + 1).unwrap();
        assert_eq!(o.report.fault, Some(Fault::Timeout));
        assert_eq!(m.shaft_state(), ShaftState::Standstill);
        assert_eq!(m.speed(), 0.0);
        assert_eq!(m.diagnostics().edges.timeouts, 1);
        assert_eq!(m.diagnostics().edges.reversals, 1);
    }

    #[test]
    fn learned_pitches_remove_disc_errors() {
        // Run-out of e/r = 2e-3 (a false once-per-turn speed ripple of ±0.2 %) and a pitch
        // error of up to ±1e-4 rad per line (0.8 % of a 0.0123 rad pitch).
        let err = |k: u32| {
            let hash = ((k.wrapping_mul(2_654_435_761) >> 16) % 2001) as f64 / 1000.0 - 1.0;
            2e-3 * (core::f64::consts::TAU * k as f64 / 512.0).sin() + 1e-4 * hash
        };
        let steady = kneader(0.0);
        let ripple = kneader(0.005);
        let mut m = monitor(512, Framing::Index, 8, 32, 84e6, 8);
        let out = run(
            &mut m,
            &stream(512, 0, true, 41, 84e6, u32::MAX, &ripple, &err),
        );
        let before = out.last().unwrap().report;
        // Uncorrected, the disc's error dominates: δ far from 0.01.
        assert!(before.delta > 0.013, "{before:?}");
        m.start_learning(0.01);
        run(
            &mut m,
            &stream(512, 0, true, 30, 84e6, u32::MAX, &steady, &err),
        );
        let mut table = [0.0f32; 1024];
        let learned = m.finish_learning(20, &mut table).unwrap();
        assert_eq!(learned.len(), 512);
        // Re-run the ripple: now δ is the shaft's.
        let out = run(
            &mut m,
            &stream(512, 0, true, 41, 84e6, u32::MAX, &ripple, &err),
        );
        let after = out.last().unwrap().report;
        assert!(after.valid());
        assert!((after.delta - 0.01).abs() < 5e-4, "{after:?}");
    }
}
