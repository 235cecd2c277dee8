//! Property test: the monitor is total. Arbitrary edge streams (wraps, duplicates, zero and
//! huge intervals, reversals, bursts, stray index pulses, polls at any time) never panic, and
//! every window it reports is either valid with finite numbers or carries its fault.

use drive_monitor::alarm::AlarmConfig;
use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator};
use drive_monitor::irregularity::{WindowConfig, WindowLength};
use drive_monitor::monitor::DeltaMonitor;
use drive_monitor::speed::Direction;
use proptest::prelude::*;

#[derive(Debug, Clone)]
enum Op {
    /// Edge after `dt` ticks (may wrap the counter), with an optional direction.
    Edge(u32, Option<bool>),
    /// A burst of `n` edges `dt` ticks apart.
    Burst(u8, u32),
    Index(u32),
    Poll(u32),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        6 => (prop_oneof![0u32..3, 3000u32..5000, any::<u32>()], proptest::option::of(any::<bool>()))
            .prop_map(|(d, dir)| Op::Edge(d, dir)),
        1 => (1u8..40, 0u32..10_000).prop_map(|(n, d)| Op::Burst(n, d)),
        1 => any::<u32>().prop_map(Op::Index),
        1 => any::<u32>().prop_map(Op::Poll),
    ]
}

/// The wheel: 0 unframed, 1 indexed, 2 a missing-tooth wheel with 1–3 missing.
fn framing() -> impl Strategy<Value = (u8, u8)> {
    (0u8..3, 1u8..=3)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_edge_streams_never_panic(
        ops in proptest::collection::vec(op(), 0..400),
        framing in framing(),
        bits in prop_oneof![Just(16u8), Just(24u8), Just(32u8)],
        k in 1u16..8,
        positions in 12u16..64,
        revs in 1u16..4,
    ) {
        let mut c = match framing.0 {
            0 => EncoderConfig::unframed(positions, 1e6),
            1 => EncoderConfig::indexed(positions, 1e6),
            _ => EncoderConfig::missing_teeth(positions as u8, framing.1, 1e6),
        };
        c.counter_bits = bits;
        c.estimator = Estimator::Edges(k);
        c.min_speed = 100.0;
        let enc = Encoder::new(c).unwrap();
        let w = WindowConfig { length: WindowLength::Revolutions(revs), steady_tolerance: 0.05 };
        let mut m = DeltaMonitor::<64>::new(enc, w, Some(AlarmConfig::new(0.05))).unwrap();
        let mut t = 0u32;
        let mut reports = Vec::new();
        for o in ops {
            match o {
                Op::Edge(dt, dir) => {
                    t = t.wrapping_add(dt);
                    let dir = dir.map(|f| if f { Direction::Forward } else { Direction::Reverse });
                    reports.extend(m.on_edge(t, dir));
                }
                Op::Burst(n, dt) => {
                    for _ in 0..n {
                        t = t.wrapping_add(dt);
                        reports.extend(m.on_edge(t, None));
                    }
                }
                Op::Index(dt) => m.on_index(t.wrapping_add(dt % 10_000)),
                Op::Poll(dt) => reports.extend(m.poll(t.wrapping_add(dt))),
            }
            prop_assert!(m.speed().is_finite() && m.speed() >= 0.0);
        }
        // At the end of the stream: a second window ended by the last call waits for the
        // next one, and a window may be held for the edge after its frame.
        while let Some(o) = m.release_held() {
            reports.push(o);
        }
        let d = m.diagnostics();
        prop_assert_eq!(d.valid_windows + d.invalid_windows, reports.len() as u32);
        for r in reports {
            let r = r.report;
            if let Some(m) = r.measurement() {
                prop_assert!(m.delta.is_finite() && m.delta >= 0.0 && m.delta < 2.0, "{:?}", r);
                prop_assert!(m.omega_max >= m.omega_min);
                prop_assert!(m.noise_floor.is_finite());
                prop_assert_eq!(r.revolutions, revs);
            }
        }
    }
}
