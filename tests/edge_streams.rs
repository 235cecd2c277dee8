//! Property test: the monitor is total. Arbitrary edge streams (wraps, duplicates, zero and
//! huge intervals, reversals, bursts, stray index pulses, polls at any time) never panic, and
//! every window it reports is either valid with finite numbers or carries its fault.

use drive_monitor::alarm::AlarmConfig;
use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator, Framing};
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
    Index,
    Poll(u32),
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        6 => (prop_oneof![0u32..3, 3000u32..5000, any::<u32>()], proptest::option::of(any::<bool>()))
            .prop_map(|(d, dir)| Op::Edge(d, dir)),
        1 => (1u8..40, 0u32..10_000).prop_map(|(n, d)| Op::Burst(n, d)),
        1 => Just(Op::Index),
        1 => any::<u32>().prop_map(Op::Poll),
    ]
}

fn framing() -> impl Strategy<Value = Framing> {
    prop_oneof![
        Just(Framing::None),
        Just(Framing::Index),
        (1u8..=3).prop_map(|missing| Framing::MissingTooth { missing }),
    ]
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
        let mut c = EncoderConfig::new(positions, 1e6);
        c.framing = framing;
        c.counter_bits = bits;
        c.estimator = Estimator::Edges(k);
        c.min_speed = 100.0;
        let enc = Encoder::<64>::new(c).unwrap();
        let w = WindowConfig { length: WindowLength::Revolutions(revs), steady_tolerance: 0.05 };
        let mut m = DeltaMonitor::new(enc, w, Some(AlarmConfig::new(0.05))).unwrap();
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
                Op::Index => m.on_index(),
                Op::Poll(dt) => reports.extend(m.poll(t.wrapping_add(dt))),
            }
            prop_assert!(m.speed().is_finite() && m.speed() >= 0.0);
        }
        let d = m.diagnostics();
        prop_assert_eq!(d.valid_windows + d.invalid_windows, reports.len() as u32);
        for r in reports {
            let r = r.report;
            if r.valid() {
                prop_assert!(r.delta.is_finite() && r.delta >= 0.0 && r.delta < 2.0, "{:?}", r);
                prop_assert!(r.omega_max >= r.omega_min);
                prop_assert!(r.noise_floor.is_finite());
                prop_assert_eq!(r.revolutions, revs);
            }
        }
    }
}
