//! Engine start flares on missing-tooth crank wheels: clean streams, and streams with one
//! lost tooth, against a generator of their own (as `crank_sweep.rs`: nothing from the
//! crate's `testutil` or from host-sim, the core used only through its public API).
//!
//! The generator: ω(φ) = ω̄(φ)(1 + a·sin(zφ + phase)), the mean ω̄ cranking at 25 rad/s for
//! `FLARE_AT` revolutions (and a fraction `off` of one), then rising to ω₁ over `revs`
//! revolutions and steady at ω₁ after; each edge's time the integral of 1/ω over the pitch
//! before it (16-point Gauss-Legendre, split where the flare starts and ends), ticks of 1 µs,
//! no jitter. The mean rises in one of three shapes over the flare's angle u ∈ [0, 1]:
//!
//! - `exp`: ln ω̄ linear in u (the same ratio from tooth to tooth);
//! - `accel`: ω̄² linear in u, a constant angular acceleration in time (the steepest rise at
//!   its start: from 25 to 150 rad/s over two revolutions the mean rises 1.57 times over the
//!   first pitch of a 12-1 wheel);
//! - `smooth`: ω̄ linear in smoothstep(u) = 3u² − 2u³ (no step in the acceleration).
//!
//! The census (`cargo test --release --test start_flare -- --ignored --nocapture`) runs the
//! grid: 8-1, 12-1, 24-1, 36-1, 36-2 and 60-2 wheels; ripples a of 0.2, 0.3 and 0.4 with
//! z = 1, 2 and 3 strokes; 8 phases; the three shapes; ω₁ of 80 and 150 rad/s; flares of 2, 3
//! and 5 revolutions starting at 0, a third and two thirds of a revolution after the frame;
//! estimators of K = 1 and 4 edges, windows of one revolution. For each wheel it prints how
//! many clean streams get any fault (by kind), and how many streams with one tooth lost at
//! the first, second or third tooth after the gap (tooth 0, 1, 2 of the revolution the
//! flare starts in, or of the cranking revolution before it; only where the clean stream
//! counts no fault) count other than exactly one fault. README gives the counts (in release
//! about 20 s here); `FLARE_WHEEL=12-1` runs one wheel, `FLARE_VERBOSE=1` prints each stream
//! counted, with the `FLARE_CASE` that replays it. `FLARE_CASE='12 1 0.4 2 3 8 accel 150 2 0.333 1 none'` (n m a z ph nphase shape
//! ω₁ revs off K, then `none` or `lost REV POS`) replays one stream and lists its faults
//! with the tooth they were found at.

mod crank_common;

use crank_common::{integrate, run_wheel, Rec, HZ};
use drive_monitor::monitor::WindowOutcome;
use drive_monitor::speed::Fault;
use std::f64::consts::TAU;

const OMEGA0: f64 = 25.0;
const REVS: u32 = 14;
/// Whole revolutions of cranking before the flare.
const FLARE_AT: u32 = 5;
const T0_TICKS: f64 = 12_345.0;

const WHEELS: [(u32, u32); 6] = [(8, 1), (12, 1), (24, 1), (36, 1), (36, 2), (60, 2)];
const AMPS: [f64; 3] = [0.2, 0.3, 0.4];
const ZS: [f64; 3] = [1.0, 2.0, 3.0];
const NPHASE: u32 = 8;
const SHAPES: [Shape; 3] = [Shape::Exp, Shape::Accel, Shape::Smooth];
const TOPS: [f64; 2] = [80.0, 150.0];
const FLARE_REVS: [f64; 3] = [2.0, 3.0, 5.0];
const OFFS: [f64; 3] = [0.0, 1.0 / 3.0, 2.0 / 3.0];
const KS: [u16; 2] = [1, 4];

#[derive(Clone, Copy, Debug, PartialEq)]
enum Shape {
    Exp,
    Accel,
    Smooth,
}

impl Shape {
    fn name(self) -> &'static str {
        match self {
            Shape::Exp => "exp",
            Shape::Accel => "accel",
            Shape::Smooth => "smooth",
        }
    }
    fn parse(s: &str) -> Shape {
        match s {
            "exp" => Shape::Exp,
            "accel" => Shape::Accel,
            "smooth" => Shape::Smooth,
            _ => panic!("shape: exp, accel or smooth"),
        }
    }
}

#[derive(Clone, Copy, Debug)]
struct Params {
    n: u32,
    m: u32,
    a: f64,
    z: f64,
    /// Phase index of `nphase` (the phase is 2π·ph/nphase).
    ph: u32,
    nphase: u32,
    shape: Shape,
    /// The mean speed after the flare, rad/s.
    top: f64,
    /// The flare's length, revolutions.
    revs: f64,
    /// Where it starts: `FLARE_AT` revolutions and this fraction of one after the frame.
    off: f64,
}

impl Params {
    fn case_args(&self) -> String {
        let p = self;
        format!(
            "{} {} {} {} {} {} {} {} {} {:.3}",
            p.n,
            p.m,
            p.a,
            p.z,
            p.ph,
            p.nphase,
            p.shape.name(),
            p.top,
            p.revs,
            p.off
        )
    }

    /// The flare's start and end angles.
    fn span(&self) -> (f64, f64) {
        let s = TAU * (f64::from(FLARE_AT) + self.off);
        (s, s + TAU * self.revs)
    }

    /// The mean speed at angle φ.
    fn mean(&self, phi: f64) -> f64 {
        let (s, e) = self.span();
        let u = ((phi - s) / (e - s)).clamp(0.0, 1.0);
        let (w0, w1) = (OMEGA0, self.top);
        match self.shape {
            Shape::Exp => w0 * (w1 / w0).powf(u),
            Shape::Accel => (w0 * w0 + (w1 * w1 - w0 * w0) * u).sqrt(),
            Shape::Smooth => w0 + (w1 - w0) * u * u * (3.0 - 2.0 * u),
        }
    }
}

/// The stream: every present tooth's edge (ticks, grid position, revolution), in time order.
fn generate(p: &Params) -> Vec<(u32, u32, u32)> {
    let teeth = p.n - p.m;
    let pitch = TAU / f64::from(p.n);
    let phase = TAU * f64::from(p.ph) / f64::from(p.nphase);
    let f = |phi: f64| 1.0 / (p.mean(phi) * (1.0 + p.a * (p.z * phi + phase).sin()));
    let (s, e) = p.span();
    let mut out = Vec::new();
    let mut phi = -0.5 * pitch;
    let mut t = 0.0;
    for rev in 0..REVS {
        for pos in 0..p.n {
            let to = TAU * f64::from(rev) + f64::from(pos) * pitch;
            // Split where the mean's derivative jumps: the rule is exact only on smooth pieces.
            let mut from = phi;
            for cut in [s, e] {
                if from < cut && cut < to {
                    t += integrate(&f, from, cut);
                    from = cut;
                }
            }
            t += integrate(&f, from, to);
            phi = to;
            if pos < teeth {
                let ticks = (T0_TICKS + t * HZ).floor() as u64 as u32;
                out.push((ticks, pos, rev));
            }
        }
    }
    out
}

fn run(p: &Params, k: u16, ticks: &[u32]) -> (Vec<WindowOutcome>, Rec) {
    run_wheel(p.n, p.m, k, 1, ticks)
}

/// The stream with the tooth at grid position `pos` of revolution `rev` lost.
fn lose(edges: &[(u32, u32, u32)], rev: u32, pos: u32) -> Vec<u32> {
    edges
        .iter()
        .filter(|e| (e.2, e.1) != (rev, pos))
        .map(|e| e.0)
        .collect()
}

/// Each fault of `rec` as `kind@rev.pos` (the true edge at or after its time).
fn describe(edges: &[(u32, u32, u32)], rec: &Rec) -> String {
    rec.faults
        .iter()
        .map(|&(f, t)| {
            let at = edges
                .iter()
                .find(|e| e.0 >= t)
                .map_or("end".into(), |e| format!("{}.{}", e.2, e.1));
            format!("{}@{at}", f.name())
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Counts over the grid.
#[derive(Default, Clone)]
struct Census {
    clean: u64,
    clean_faulted: u64,
    clean_by_kind: [u64; 7],
    lost_runs: u64,
    /// Lost-tooth streams whose clean stream has no fault, counting not exactly one fault.
    lost_counted: [u64; 3],
    lost_not_one: [u64; 3],
    lost_none: [u64; 3],
    lost_unexplained: [u64; 3],
}

fn kind_index(f: Fault) -> usize {
    match f {
        Fault::Glitch => 0,
        Fault::MissingEdge => 1,
        Fault::ExtraEdge => 2,
        Fault::MissingFrame => 3,
        Fault::Reversal => 4,
        Fault::Timeout => 5,
        Fault::Unexplained => 6,
    }
}

const KIND_NAMES: [&str; 7] = [
    "glitch",
    "missing",
    "extra",
    "missing-frame",
    "reversal",
    "timeout",
    "unexplained",
];

/// One case at one K: the clean stream, then a tooth lost at the first three teeth after
/// the gap in the revolution the flare starts in and in the one before. Prints a line for a
/// clean stream with a fault and for a lost tooth not counted as exactly one fault when
/// `verbose`.
fn case(p: &Params, k: u16, c: &mut Census, verbose: bool) {
    let edges = generate(p);
    let ticks: Vec<u32> = edges.iter().map(|e| e.0).collect();
    let (_, rec) = run(p, k, &ticks);
    c.clean += 1;
    if !rec.faults.is_empty() {
        c.clean_faulted += 1;
        for &(f, _) in &rec.faults {
            c.clean_by_kind[kind_index(f)] += 1;
        }
        if verbose {
            println!(
                "CLEAN-FAULT {} | FLARE_CASE='{} {k} none'",
                describe(&edges, &rec),
                p.case_args()
            );
        }
        return;
    }
    for rev in [FLARE_AT - 1, FLARE_AT] {
        for pos in 0..3u32 {
            let (_, r) = run(p, k, &lose(&edges, rev, pos));
            c.lost_runs += 1;
            c.lost_counted[pos as usize] += 1;
            let n = r.faults.len();
            if n == 1 {
                continue;
            }
            if n == 0 {
                c.lost_none[pos as usize] += 1;
            } else {
                c.lost_not_one[pos as usize] += 1;
            }
            if r.faults.iter().any(|f| f.0 == Fault::Unexplained) {
                c.lost_unexplained[pos as usize] += 1;
            }
            if verbose {
                println!(
                    "LOST-FAULTS {n} {} | FLARE_CASE='{} {k} lost {rev} {pos}'",
                    describe(&edges, &r),
                    p.case_args()
                );
            }
        }
    }
}

fn report(label: &str, c: &Census) {
    let kinds: Vec<String> = KIND_NAMES
        .iter()
        .zip(c.clean_by_kind)
        .filter(|(_, n)| *n > 0)
        .map(|(k, n)| format!("{k} {n}"))
        .collect();
    eprintln!(
        "{label}: clean streams {} with a fault {} ({}) | lost-tooth streams {}: not one fault \
         at tooth 0/1/2 after the gap {}/{}/{} (none {}/{}/{}, with an unexplained edge \
         {}/{}/{}) of {}/{}/{}",
        c.clean,
        c.clean_faulted,
        kinds.join(", "),
        c.lost_runs,
        c.lost_not_one[0],
        c.lost_not_one[1],
        c.lost_not_one[2],
        c.lost_none[0],
        c.lost_none[1],
        c.lost_none[2],
        c.lost_unexplained[0],
        c.lost_unexplained[1],
        c.lost_unexplained[2],
        c.lost_counted[0],
        c.lost_counted[1],
        c.lost_counted[2],
    );
}

fn grid(keep: &dyn Fn(&Params) -> bool, verbose: bool) -> Census {
    let mut all = Census::default();
    for (n, m) in WHEELS {
        let mut c = Census::default();
        for a in AMPS {
            for z in ZS {
                for ph in 0..NPHASE {
                    for shape in SHAPES {
                        for top in TOPS {
                            for revs in FLARE_REVS {
                                for off in OFFS {
                                    let p = Params {
                                        n,
                                        m,
                                        a,
                                        z,
                                        ph,
                                        nphase: NPHASE,
                                        shape,
                                        top,
                                        revs,
                                        off,
                                    };
                                    if !keep(&p) {
                                        continue;
                                    }
                                    for k in KS {
                                        case(&p, k, &mut c, verbose);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
        if c.clean > 0 {
            report(&format!("{n}-{m}"), &c);
        }
        add(&mut all, &c);
    }
    report("all", &all);
    all
}

fn add(to: &mut Census, c: &Census) {
    to.clean += c.clean;
    to.clean_faulted += c.clean_faulted;
    to.lost_runs += c.lost_runs;
    for i in 0..7 {
        to.clean_by_kind[i] += c.clean_by_kind[i];
    }
    for i in 0..3 {
        to.lost_counted[i] += c.lost_counted[i];
        to.lost_not_one[i] += c.lost_not_one[i];
        to.lost_none[i] += c.lost_none[i];
        to.lost_unexplained[i] += c.lost_unexplained[i];
    }
}

/// Replays one case: every fault with the true tooth it was found at, the teeth accepted
/// around the first fault, and the windows.
fn replay(case: &str) {
    let a: Vec<&str> = case.split_whitespace().collect();
    assert!(
        a.len() >= 12,
        "FLARE_CASE: n m a z ph nphase shape top revs off K none|lost REV POS"
    );
    let f = |i: usize| -> f64 { a[i].parse().unwrap() };
    let p = Params {
        n: a[0].parse().unwrap(),
        m: a[1].parse().unwrap(),
        a: f(2),
        z: f(3),
        ph: a[4].parse().unwrap(),
        nphase: a[5].parse().unwrap(),
        shape: Shape::parse(a[6]),
        top: f(7),
        revs: f(8),
        off: f(9),
    };
    let k: u16 = a[10].parse().unwrap();
    let edges = generate(&p);
    let ticks = match a[11] {
        "lost" => lose(&edges, a[12].parse().unwrap(), a[13].parse().unwrap()),
        _ => edges.iter().map(|e| e.0).collect(),
    };
    let (out, rec) = run(&p, k, &ticks);
    println!("faults: {}", describe(&edges, &rec));
    let centre = rec.faults.first().map_or(0, |f| f.1);
    let mut prev: Option<u32> = None;
    for (i, e) in edges.iter().enumerate() {
        let dt = prev.map_or(0, |q| e.0.wrapping_sub(q));
        prev = Some(e.0);
        if i < 2 || e.0.abs_diff(centre) > 40 * dt.max(1) {
            continue;
        }
        let took = rec
            .teeth
            .iter()
            .find(|x| x.0 == e.0)
            .map_or("not accepted".into(), |x| {
                format!("tooth {} synced {}", x.1, x.2)
            });
        let was = if ticks.contains(&e.0) { "" } else { " LOST" };
        println!("edge {} rev {} pos {}: dt {dt}{was}: {took}", e.0, e.2, e.1);
    }
    for o in &out {
        let r = &o.report;
        println!(
            "window {}..{} {:?}",
            r.start_ticks,
            r.end_ticks,
            r.result.map(|m| m.delta)
        );
    }
}

/// The census over the grid (see the module's documentation), or one case (`FLARE_CASE`).
/// `FLARE_WHEEL=12-1` runs one wheel. Prints the counts; asserts nothing but that it ran.
#[test]
#[ignore]
fn start_flare_census() {
    if let Ok(case) = std::env::var("FLARE_CASE") {
        replay(&case);
        return;
    }
    let wheel: Option<(u32, u32)> = std::env::var("FLARE_WHEEL").ok().map(|s| {
        let (n, m) = s.split_once('-').expect("FLARE_WHEEL: e.g. 12-1");
        (n.parse().unwrap(), m.parse().unwrap())
    });
    let verbose = std::env::var("FLARE_VERBOSE").is_ok();
    let c = grid(
        &|p| wheel.is_none_or(|(n, m)| (p.n, p.m) == (n, m)),
        verbose,
    );
    assert!(c.clean > 0);
}

/// A single tooth lost at the second tooth after the gap (tooth 1) of a cranking wheel, with
/// no flare: 8-1 to 60-2 wheels, steady at 25 rad/s and with ripples of ±20 and ±40 % at one
/// to three strokes, 8 phases, in sync (the clean stream counts no fault). The loss is one
/// fault in its revolution, a missing edge. The interval after the frame tooth then spans two
/// pitches, and the swings into and out of it each cost the frame tooth's judgement the margin
/// shrunk at the gap: the frame tooth, which fits, was unexplained as well, on every one of
/// these streams (328 of 328).
///
/// What is left: at ±40 % with two or three strokes a revolution, on an 8-1 and a 12-1 wheel
/// at one phase each, the next revolution's frame tooth is unexplained: the interval across
/// the loss recorded no swing, so the judgement weighs the tooth after the frame against the
/// frame's interval with no swing, which costs the tooth the margin shrunk at the gap, and a
/// glitch (the two merged) explains the edges better by a quarter of it.
#[test]
fn a_tooth_lost_just_after_the_frame_tooth_is_one_fault() {
    let (mut checked, mut wrong, mut later) = (0, Vec::new(), Vec::new());
    for (n, m) in WHEELS {
        for (a, z) in [(0.0, 1.0)]
            .into_iter()
            .chain([0.2, 0.4].into_iter().flat_map(|a| ZS.map(|z| (a, z))))
        {
            for ph in 0..NPHASE {
                let p = Params {
                    n,
                    m,
                    a,
                    z,
                    ph,
                    nphase: NPHASE,
                    shape: Shape::Exp,
                    top: OMEGA0,
                    revs: 2.0,
                    off: 0.0,
                };
                let edges = generate(&p);
                let ticks: Vec<u32> = edges.iter().map(|e| e.0).collect();
                let teeth = (n - m) as usize;
                let (_, clean) = run(&p, 1, &ticks);
                // A small wheel at deep ripple may not sync by the loss: nothing to check.
                let synced = clean.teeth.iter().any(|t| t.2 && t.0 < ticks[4 * teeth]);
                if !clean.faults.is_empty() || !synced {
                    continue;
                }
                let (_, r) = run(&p, 1, &lose(&edges, 4, 1));
                checked += 1;
                let next_frame = ticks[5 * teeth];
                let (this, after): (Vec<&(Fault, u32)>, Vec<_>) =
                    r.faults.iter().partition(|f| f.1 < next_frame);
                if this.iter().map(|f| f.0).ne([Fault::MissingEdge]) {
                    wrong.push(format!("{}: {}", p.case_args(), describe(&edges, &r)));
                } else if !after.is_empty() {
                    later.push(format!("{}: {}", p.case_args(), describe(&edges, &r)));
                }
            }
        }
    }
    assert!(checked >= 300, "{checked} streams checked");
    assert!(wrong.is_empty(), "{} of {checked}: {wrong:#?}", wrong.len());
    assert!(later.len() <= 2, "{} of {checked}: {later:#?}", later.len());
}

/// The onset of a steep start flare at the frame tooth: the mean speed rising from 25 to
/// 150 rad/s at a constant angular acceleration from the frame tooth of the sixth revolution
/// on, over two revolutions on a 12-1 wheel, three on 12-1 and 8-1 wheels (the speed rising
/// by 57 and 40 % over the 12-1 wheel's first pitch), with ripples of ±20 to ±40 % at one to three
/// strokes, 8 phases, clean: no fault in that revolution. The frame tooth, which fits, is
/// judged with the two intervals after it, each a fifth to a third shorter against the one
/// before than a revolution earlier: their squared log swings passed the margin shrunk at the
/// gap, and the frame tooth was unexplained on 72, 23 and 64 of these 72 streams each. The
/// swings the three intervals share (the middle one of the three, where the speed's trend
/// has changed since the recorded revolution) are now taken out where a tooth is called
/// unexplained at a gap for costing more than that margin.
///
/// What is left (`start_flare_census`): the frame tooth of the revolution after the onset is
/// still unexplained on some of these streams (19 of 72 on the 12-1 wheel over two
/// revolutions), the swings recorded during the onset unlike those after it; on an 8-1 wheel
/// over two revolutions the onset revolution has faults on 64 of 72 streams; and a frame
/// tooth whose own swing changed with a flare by more than a quarter of that margin is
/// unexplained as a frame edge displaced (every stream of a 12-1 wheel where the flare to
/// 150 rad/s starts two thirds into a revolution).
#[test]
fn the_onset_of_a_start_flare_at_the_frame_is_no_fault() {
    let (mut checked, mut wrong) = (0, Vec::new());
    for (n, revs) in [(12, 2.0), (12, 3.0), (8, 3.0)] {
        for a in AMPS {
            for z in ZS {
                for ph in 0..NPHASE {
                    let p = Params {
                        n,
                        m: 1,
                        a,
                        z,
                        ph,
                        nphase: NPHASE,
                        shape: Shape::Accel,
                        top: 150.0,
                        revs,
                        off: 0.0,
                    };
                    let edges = generate(&p);
                    let ticks: Vec<u32> = edges.iter().map(|e| e.0).collect();
                    let (_, r) = run(&p, 1, &ticks);
                    checked += 1;
                    let end = ticks[(FLARE_AT as usize + 1) * (n - 1) as usize];
                    if r.faults.iter().any(|f| f.1 < end) {
                        wrong.push(format!("{}: {}", p.case_args(), describe(&edges, &r)));
                    }
                }
            }
        }
    }
    assert_eq!(checked, 3 * 72);
    assert!(wrong.is_empty(), "{} of {checked}: {wrong:#?}", wrong.len());
}
