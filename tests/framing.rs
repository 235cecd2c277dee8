//! Clean signals the framing must not misjudge (host-sim's `tests/analyze.rs` checks the same
//! on simulated captures).

use drive_monitor::encoder::{Encoder, EncoderConfig};
use drive_monitor::irregularity::{WindowConfig, WindowLength};
use drive_monitor::monitor::DeltaMonitor;
use drive_monitor::speed::{EdgeSink, Fault, Tooth};
use host_sim::engine::cranking::{Ripple, SpeedProfile};
use host_sim::engine::encoder::EncoderConfig as SimEncoder;
use host_sim::engine::ode::Integrator;
use host_sim::engine::system::{ShaftModel, Simulation, System};

/// What an observer is told: every fault with its time, and the largest tooth-to-tooth ratio
/// of the per-pitch intervals of the accepted teeth (the signal's cleanliness).
#[derive(Default)]
struct Seen {
    faults: Vec<(Fault, u32)>,
}

impl EdgeSink for Seen {
    fn tooth(&mut self, _t: &Tooth) {}
    fn fault(&mut self, f: Fault, time: u32) {
        self.faults.push((f, time));
    }
}

/// A cranking 36-2 wheel — ±40 % compression ripple, two strokes per revolution, 25 rad/s
/// mean — that stalls: the mean speed falls linearly to 0 over 0.6 s after 1.6 s. Every tooth
/// is there and the per-pitch intervals change by at most 1.4× from tooth to tooth (checked
/// below): no fault, no sync loss, every revolution after sync counted.
///
/// Each interval is judged against the swing the same teeth had one revolution earlier; the
/// interval of the tooth just accepted is written to that history only once the next tooth has
/// been judged, so the reference is always the earlier revolution's (judging against this
/// revolution's own interval mistook the stall's halving mean speed for missing and extra
/// edges).
#[test]
fn a_stalling_crank_is_not_a_fault() {
    let profile = SpeedProfile {
        mean: vec![(0.0, 25.0), (1.6, 25.0), (2.2, 0.0)],
        ripple: Some(Ripple {
            amplitude: 0.4,
            strokes: 2.0,
            phase: 0.0,
        }),
    };
    let system = System::new(ShaftModel::Profile(profile), Vec::new()).unwrap();
    let integ = Integrator::Dopri5 {
        rtol: 1e-9,
        atol: 1e-9,
        max_step: Some(0.01),
    };
    let mut sim_enc = SimEncoder::ideal(36, 1e6);
    // The core's 36-2: positions 0..=33 carry teeth, 34 and 35 are the gap.
    sim_enc.teeth = Some((0..34).collect());
    let mut sim = Simulation::new(system, integ, sim_enc).unwrap();
    let mut c = EncoderConfig::missing_teeth(36, 2, 1e6);
    c.min_speed = 1.0;
    let w = WindowConfig {
        length: WindowLength::Revolutions(1),
        steady_tolerance: 0.05,
    };
    let mut m = DeltaMonitor::<64>::new(Encoder::new(c).unwrap(), w, None).unwrap();
    let mut seen = Seen::default();
    let mut times = Vec::new();
    sim.run(2.2, |e| {
        times.push((e.true_time, e.tooth));
        m.on_edge_observed(e.ticks, None, &mut seen);
    })
    .unwrap();
    // The signal is clean: per-pitch tooth-to-tooth ratios within 0.45–2.2 (1.4 at most).
    let per_pitch: Vec<f64> = times
        .windows(2)
        .map(|w| {
            let pitches = (w[1].1 + 36 - w[0].1) % 36;
            (w[1].0 - w[0].0) / f64::from(pitches)
        })
        .collect();
    let worst = per_pitch
        .windows(2)
        .map(|r| (r[1] / r[0]).max(r[0] / r[1]))
        .fold(1.0, f64::max);
    assert!(worst < 2.2, "{worst}");
    assert_eq!(seen.faults, Vec::new());
    let d = m.diagnostics().edges;
    assert_eq!((d.syncs, d.sync_losses), (1, 0), "{d:?}");
    // 237 edges, about 7 revolutions: synced within two, the rest counted.
    assert!(
        d.revolutions >= 4 && d.accepted + 1 >= times.len() as u32,
        "{d:?}"
    );
}
