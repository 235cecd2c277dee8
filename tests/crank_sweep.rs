//! Fault-injection sweep of the δ monitor on missing-tooth crank wheels, against a generator
//! and a δ replica of its own: nothing here comes from the crate's `testutil` or from host-sim,
//! and the core is used only through its public API.
//!
//! The generator: ω(φ) = ω̄(1 + a·sin(zφ + phase)) with ω̄ = 25 rad/s, each edge's time the
//! integral of 1/ω over the pitch before it (16-point Gauss-Legendre per pitch), Gaussian jitter
//! of σ times the mean pitch time (an RNG of its own), ticks of 1 µs = the floor of the time;
//! ten revolutions of a wheel's present teeth, and one fault in the sixth: a lost edge or an
//! inserted noise pulse, at and around the frame tooth and at a random tooth. Every valid
//! window of a faulted stream (and of the clean one) is checked:
//!
//! - (A) its δ equals that of the clean stream's window with the same start tick, if the clean
//!   stream has one;
//! - (B) it starts at a true tooth 0 and ends W revolutions later at a true tooth 0, and its δ
//!   equals a replica formed from the true edges (true tooth angles, the stream's ticks, K-edge
//!   samples, exact cross products, the monitor's f32 formula).
//!
//! A window failing either is printed as a `WRONG` line with the case and the `CRANK_CASE`
//! value that replays it. Where the clean stream already has a wrong valid window its faulted
//! streams are not run (counted once, as a clean run with a wrong valid window). After each
//! wheel a line gives the running counts: runs, valid and invalid windows, WRONG; the clean
//! runs' invalid windows, faults and runs without a valid window; and the largest
//! |δ − δ_ideal| at σ = 0 (δ_ideal from K-edge samples of the unjittered times).
//!
//! The grid: 8-1, 12-1, 24-1, 36-1, 36-2 and 60-2 wheels; ripple a of 0, 0.2, 0.3 and 0.4 with
//! z = 1, 2 and 3 strokes (a = 0 once); 8 phases; σ of 0, 1 % and 2 % of a pitch; estimators of
//! K = 1, 2, 4 and 8 edges; windows of 1 and 2 revolutions. README's figures (no valid window
//! of 1 038 091 wrong; 430 668 and 430 070 in the finer sweeps near the frame, seed offsets 1
//! and 2) are printed by
//!
//! ```text
//! cargo test --release --test crank_sweep -- --ignored --nocapture
//! CRANK_SWEEP=near1 cargo test --release --test crank_sweep -- --ignored --nocapture
//! CRANK_SWEEP=near2 cargo test --release --test crank_sweep -- --ignored --nocapture
//! ```
//!
//! (in release the full sweep took 39 s here, 25 s of it on the CPU on a shared machine, and
//! each finer one 13 to 19 s). `CRANK_WHEEL=8-1` runs
//! one wheel's cases of the same sweep, and `CRANK_CASE='36 2 0.3 1 2 8 0.02 36298 1 1 pulse
//! 171 0.05'` (wheel positions and missing teeth, a, z, phase index, phases, σ, seed, K, W, then
//! `none`, `lost EDGE` or `pulse EDGE FRACTION`) replays one case edge by edge instead. The
//! test that is not ignored runs a part of the grid (4 s here in a debug build).

mod crank_common;

use crank_common::{integrate, run_wheel, Rec, HZ};
use drive_monitor::monitor::WindowOutcome;
use std::f64::consts::TAU;

const OMEGA: f64 = 25.0;
const REVS: u32 = 10;
const T0_TICKS: f64 = 12_345.0;

const WHEELS: [(u32, u32); 6] = [(8, 1), (12, 1), (24, 1), (36, 1), (36, 2), (60, 2)];
const AMPS: [f64; 4] = [0.0, 0.2, 0.3, 0.4];
const ZS: [f64; 3] = [1.0, 2.0, 3.0];
const NPHASE: u32 = 8;
const SIGMAS: [f64; 3] = [0.0, 0.01, 0.02];
const KS: [u16; 4] = [1, 2, 4, 8];
const WS: [u16; 2] = [1, 2];

#[derive(Clone, Copy, Debug)]
struct Edge {
    t_true: f64,
    ticks: u32,
    /// Position on the grid (0..n) and revolution.
    pos: u32,
    rev: u32,
}

/// SplitMix64.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn unif(&mut self) -> f64 {
        (self.next() >> 11) as f64 / (1u64 << 53) as f64
    }
    fn gauss(&mut self) -> f64 {
        let u1 = self.unif().max(1e-300);
        let u2 = self.unif();
        (-2.0 * u1.ln()).sqrt() * (TAU * u2).cos()
    }
}

/// The rule is exact for polynomials of degree up to 31: ∫₀¹ xᵏ dx = 1/(k + 1) (one weight
/// off in its 8th digit, as once, fails it).
#[test]
fn the_quadrature_is_exact_for_polynomials() {
    for k in 0..=31 {
        let got = integrate(&|x: f64| x.powi(k), 0.0, 1.0);
        let want = 1.0 / f64::from(k + 1);
        assert!((got - want).abs() <= 1e-15 * 8.0, "x^{k}: {got} for {want}");
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
    sigma: f64,
    seed: u64,
}

impl Params {
    /// The case's first eight `CRANK_CASE` arguments: n m a z ph nphase σ seed.
    fn case_args(&self) -> String {
        let p = self;
        format!(
            "{} {} {} {} {} {} {} {}",
            p.n, p.m, p.a, p.z, p.ph, p.nphase, p.sigma, p.seed
        )
    }

    fn phase(&self) -> f64 {
        TAU * f64::from(self.ph) / f64::from(self.nphase)
    }
}

/// The stream: every present tooth's edge, in time order, over REVS revolutions.
fn generate(p: &Params) -> Vec<Edge> {
    let teeth = p.n - p.m;
    let pitch = TAU / f64::from(p.n);
    let mut rng = Rng(p.seed.wrapping_mul(0x123_4567).wrapping_add(99));
    let sigma_ticks = p.sigma * pitch / OMEGA * HZ;
    let phase = p.phase();
    let f = |phi: f64| 1.0 / (OMEGA * (1.0 + p.a * (p.z * phi + phase).sin()));
    let mut out = Vec::new();
    let mut phi = -0.5 * pitch;
    let mut t = 0.0;
    for rev in 0..REVS {
        for pos in 0..p.n {
            let to = TAU * f64::from(rev) + f64::from(pos) * pitch;
            t += integrate(&f, phi, to);
            phi = to;
            if pos < teeth {
                let j = rng.gauss() * sigma_ticks;
                let ticks = (T0_TICKS + t * HZ + j).floor() as u64 as u32;
                out.push(Edge {
                    t_true: t,
                    ticks,
                    pos,
                    rev,
                });
            }
        }
    }
    out
}

fn run(p: &Params, k: u16, w: u16, ticks: &[u32]) -> (Vec<WindowOutcome>, Rec) {
    run_wheel(p.n, p.m, k, w, ticks)
}

/// δ as the monitor forms it, from samples (span units, ticks): the fastest and the slowest
/// sample by exact cross products, then 2(p1 − p2)/(p1 + p2) in f32.
fn delta_of(samples: &[(u64, u64)]) -> f32 {
    let Some(&(a0, t0)) = samples.first() else {
        return 0.0;
    };
    let (mut a1, mut t1) = (a0, t0); // fastest
    let (mut a2, mut t2) = (a0, t0); // slowest
    for &(a, t) in &samples[1..] {
        if a * t1 > a1 * t {
            (a1, t1) = (a, t);
        }
        if a * t2 < a2 * t {
            (a2, t2) = (a, t);
        }
    }
    let p1 = a1 * t2;
    let p2 = a2 * t1;
    let num = p1.saturating_sub(p2);
    let den = p1 + p2;
    let c = |x: u64| -> f32 {
        match u32::try_from(x) {
            Ok(x) => x as f32,
            Err(_) => ((x >> 32) as u32) as f32 * 4_294_967_296.0 + (x as u32) as f32,
        }
    };
    if den > 0 {
        2.0 * (c(num) / c(den))
    } else {
        0.0
    }
}

fn delta_f64(samples: &[f64]) -> f64 {
    let mx = samples.iter().copied().fold(f64::MIN, f64::max);
    let mn = samples.iter().copied().fold(f64::MAX, f64::min);
    2.0 * (mx - mn) / (mx + mn)
}

/// The K-edge samples over the true edges `is + 1..=ie`: (span units, ticks) for the replica
/// and the ideal speeds (unjittered times).
fn true_samples(
    p: &Params,
    truth: &[Edge],
    k: usize,
    is: usize,
    ie: usize,
) -> (Vec<(u64, u64)>, Vec<f64>) {
    let n = u64::from(p.n);
    let ang = |e: &Edge| u64::from(e.rev) * n + u64::from(e.pos);
    let mut smp = Vec::new();
    let mut ideal = Vec::new();
    for j in is + 1..=ie {
        let (a, b) = (&truth[j - k], &truth[j]);
        smp.push((
            (ang(b) - ang(a)) * 65536,
            u64::from(b.ticks.wrapping_sub(a.ticks)),
        ));
        ideal.push((ang(b) - ang(a)) as f64 / (b.t_true - a.t_true));
    }
    (smp, ideal)
}

/// For a misframed window: the true edges nearest its start and end ticks, and the replica
/// and ideal δ over them.
fn expected_span(p: &Params, truth: &[Edge], k: usize, start: u32, end: u32, got: f32) -> String {
    let near = |t: u32| {
        (0..truth.len())
            .min_by_key(|&i| (i64::from(truth[i].ticks) - i64::from(t)).abs())
            .unwrap()
    };
    let (is, ie) = (near(start), near(end));
    if is < k || ie <= is {
        return "-".into();
    }
    let (smp, ideal) = true_samples(p, truth, k, is, ie);
    let want = delta_of(&smp);
    format!(
        "{} true span edge#{is} (pos {} rev {}, tick {}) .. edge#{ie} (pos {} rev {}, tick {}): \
         replica δ {want:.5}, ideal δ {:.5}",
        if (want - got).abs() <= 1e-6 {
            "DELTA-SAME"
        } else {
            "DELTA-WRONG"
        },
        truth[is].pos,
        truth[is].rev,
        truth[is].ticks,
        truth[ie].pos,
        truth[ie].rev,
        truth[ie].ticks,
        delta_f64(&ideal)
    )
}

enum Check {
    Ok { d_ideal: f64 },
    Misframed(String),
    Mismatch { want: f32 },
}

/// Check (B) of a valid window against the true edges `truth` (the clean stream).
fn replica(p: &Params, truth: &[Edge], k: usize, w: u32, o: &WindowOutcome) -> Check {
    let r = &o.report;
    let Some(is) = truth.iter().position(|e| e.ticks == r.start_ticks) else {
        return Check::Misframed(format!("start tick {} is no true edge", r.start_ticks));
    };
    let Some(ie) = truth.iter().position(|e| e.ticks == r.end_ticks) else {
        return Check::Misframed(format!("end tick {} is no true edge", r.end_ticks));
    };
    let (s, e) = (truth[is], truth[ie]);
    if s.pos != 0 || e.pos != 0 || e.rev != s.rev + w {
        return Check::Misframed(format!(
            "start pos {} rev {}, end pos {} rev {}",
            s.pos, s.rev, e.pos, e.rev
        ));
    }
    if is < k {
        return Check::Misframed("window too early for K samples".into());
    }
    let (smp, ideal) = true_samples(p, truth, k, is, ie);
    let want = delta_of(&smp);
    let got = r.measurement().unwrap().delta;
    if (got - want).abs() > 1e-6 * want.abs().max(1e-3) {
        Check::Mismatch { want }
    } else {
        Check::Ok {
            d_ideal: delta_f64(&ideal),
        }
    }
}

#[derive(Clone, Copy, Debug)]
enum FaultKind {
    None,
    /// Lose the edge at index i of the stream.
    Lost(usize),
    /// Insert a noise edge at fraction f of the interval ending at edge i.
    Pulse(usize, f64),
}

impl FaultKind {
    /// As `CRANK_CASE` takes it (`{}` prints the shortest form that parses back exactly).
    fn arg(self) -> String {
        match self {
            FaultKind::None => "none".into(),
            FaultKind::Lost(i) => format!("lost {i}"),
            FaultKind::Pulse(i, f) => format!("pulse {i} {f}"),
        }
    }
    fn describe(self, truth: &[Edge]) -> String {
        match self {
            FaultKind::None => "none".into(),
            FaultKind::Lost(i) => {
                format!("lost edge #{i} (pos {} rev {})", truth[i].pos, truth[i].rev)
            }
            FaultKind::Pulse(i, f) => format!(
                "pulse at {f:.3} of interval ending at edge #{i} (pos {} rev {})",
                truth[i].pos, truth[i].rev
            ),
        }
    }
}

fn apply(truth: &[Edge], f: FaultKind) -> Vec<u32> {
    let mut v: Vec<u32> = truth.iter().map(|e| e.ticks).collect();
    match f {
        FaultKind::None => {}
        FaultKind::Lost(i) => {
            v.remove(i);
        }
        FaultKind::Pulse(i, frac) => {
            let (a, b) = (v[i - 1], v[i]);
            let t = a.wrapping_add((f64::from(b.wrapping_sub(a)) * frac).round() as u32);
            if t != a && t != b {
                v.insert(i, t);
            }
        }
    }
    v
}

#[derive(Default)]
struct Stats {
    runs: u64,
    valid: u64,
    invalid: u64,
    wrong: u64,
    clean_runs: u64,
    clean_invalid: u64,
    clean_faults: u64,
    clean_wrong: u64,
    clean_no_valid: u64,
    clean_bad_configs: u64,
    max_ideal_dev: f64,
}

/// Checks (A) and (B) of the windows `out` of one run (`clean` those of its clean stream),
/// counting them in `st`; returns a `WRONG` line for each wrong valid window.
#[allow(clippy::too_many_arguments)]
fn check_run(
    p: &Params,
    truth: &[Edge],
    k: u16,
    w: u16,
    f: FaultKind,
    clean: &[WindowOutcome],
    out: &[WindowOutcome],
    st: &mut Stats,
) -> Vec<String> {
    let mut lines = Vec::new();
    for o in out {
        if !o.report.valid() {
            st.invalid += 1;
            continue;
        }
        st.valid += 1;
        let got = o.report.measurement().unwrap().delta;
        let chk = replica(p, truth, k.into(), w.into(), o);
        let mut bad = Vec::new();
        if !matches!(f, FaultKind::None) {
            let want_a = clean
                .iter()
                .find(|c| c.report.start_ticks == o.report.start_ticks)
                .and_then(|c| c.report.measurement())
                .map(|c| c.delta);
            // A window the clean run lacks is no error.
            if let Some(d) = want_a.filter(|&d| d != got) {
                bad.push(format!("A: clean δ {d:.5}"));
            }
        }
        match &chk {
            Check::Ok { d_ideal } => {
                if p.sigma == 0.0 {
                    st.max_ideal_dev = st.max_ideal_dev.max((f64::from(got) - d_ideal).abs());
                }
            }
            Check::Misframed(s) => bad.push(format!("B: misframed: {s}")),
            Check::Mismatch { want } => bad.push(format!("B: replica δ {want:.5}")),
        }
        if bad.is_empty() {
            continue;
        }
        if matches!(f, FaultKind::None) {
            st.clean_wrong += 1;
        }
        st.wrong += 1;
        let r = &o.report;
        let expected = match chk {
            Check::Ok { d_ideal } => format!("{d_ideal:.5}"),
            _ => expected_span(p, truth, k.into(), r.start_ticks, r.end_ticks, got),
        };
        lines.push(format!(
            "WRONG wheel {}-{} a={} z={} phase={}/{}·2π σ={} seed={} K={k} W={w} fault: {} | \
             window start {} end {} edges {}..{} δ={got:.5} | {} | expected: {expected} | \
             CRANK_CASE='{} {k} {w} {}'",
            p.n,
            p.m,
            p.a,
            p.z,
            p.ph,
            p.nphase,
            p.sigma,
            p.seed,
            f.describe(truth),
            r.start_ticks,
            r.end_ticks,
            r.start_edge,
            r.end_edge,
            bad.join("; "),
            p.case_args(),
            f.arg(),
        ));
    }
    lines
}

/// Runs the grid's cases that `keep` (given the case and K, W) selects, printing each `WRONG`
/// line and the counts after each wheel. `near` replaces the faults with finer ones around
/// the frame tooth; `seedoff` shifts every seed. The faults' random draws are made for every
/// case, kept or not, so that a kept case is the same as in the whole sweep.
fn sweep(near: bool, seedoff: u64, keep: &dyn Fn(&Params, u16, u16) -> bool) -> Stats {
    let mut st = Stats::default();
    let mut rng = Rng(4242);
    for (n, m) in WHEELS {
        let mut any = false;
        let teeth = (n - m) as usize;
        for a in AMPS {
            for z in ZS {
                if a == 0.0 && z != 1.0 {
                    continue;
                }
                for ph in 0..NPHASE {
                    for (si, sigma) in SIGMAS.into_iter().enumerate() {
                        let seed = u64::from(n * 1000 + m * 100)
                            + (a * 10.0) as u64 * 17
                            + z as u64 * 31
                            + u64::from(ph) * 7
                            + si as u64
                            + seedoff * 1_000_003;
                        let p = Params {
                            n,
                            m,
                            a,
                            z,
                            ph,
                            nphase: NPHASE,
                            sigma,
                            seed,
                        };
                        let faults = faults(teeth, near, &mut rng);
                        let kws: Vec<(u16, u16)> = KS
                            .into_iter()
                            .filter(|&k| usize::from(k) <= teeth)
                            .flat_map(|k| WS.map(|w| (k, w)))
                            .filter(|&(k, w)| keep(&p, k, w))
                            .collect();
                        if kws.is_empty() {
                            continue;
                        }
                        any = true;
                        let truth = generate(&p);
                        for (k, w) in kws {
                            run_case(&p, &truth, k, w, &faults, &mut st);
                        }
                    }
                }
            }
        }
        if any {
            eprintln!(
                "after {n}-{m}: runs {} valid {} invalid {} WRONG {} | clean runs {} clean invalid \
                 windows {} clean faults {} clean-wrong {} clean runs without a valid window {} \
                 clean runs with a wrong valid window {} | max |δ-δ_ideal| at σ=0: {:.4}",
                st.runs,
                st.valid,
                st.invalid,
                st.wrong,
                st.clean_runs,
                st.clean_invalid,
                st.clean_faults,
                st.clean_wrong,
                st.clean_no_valid,
                st.clean_bad_configs,
                st.max_ideal_dev
            );
        }
    }
    st
}

/// The faults of a case: none; the frame tooth's edge (in the sixth revolution) and the two
/// after it lost, the two before it, one at random; noise pulses at seven places in the
/// intervals ending at the frame tooth, the two after it and the one before it, and one at
/// random. `near` keeps the draws and replaces the faults with finer ones around the frame.
fn faults(teeth: usize, near: bool, rng: &mut Rng) -> Vec<FaultKind> {
    let base = 5 * teeth;
    let mut faults = vec![FaultKind::None];
    for off in [0usize, 1, 2] {
        faults.push(FaultKind::Lost(base + off));
    }
    for off in [1usize, 2] {
        faults.push(FaultKind::Lost(base - off));
    }
    faults.push(FaultKind::Lost(
        base + 3 + rng.next() as usize % (teeth - 3).max(1),
    ));
    for i in [base, base + 1, base + 2, base - 1] {
        for frac in [0.05, 0.2, 1.0 / 3.0, 0.5, 2.0 / 3.0, 0.8, 0.95] {
            faults.push(FaultKind::Pulse(i, frac));
        }
    }
    let ri = base + rng.next() as usize % teeth;
    faults.push(FaultKind::Pulse(ri, 0.05 + 0.9 * rng.unif()));
    if near {
        faults = vec![
            FaultKind::None,
            FaultKind::Lost(base),
            FaultKind::Lost(base + 1),
            FaultKind::Lost(base - 1),
        ];
        for frac in [0.01, 0.02, 0.05, 0.08, 0.12, 0.16] {
            faults.push(FaultKind::Pulse(base + 1, frac));
        }
        for frac in [0.84, 0.88, 0.92, 0.95, 0.98, 0.99] {
            faults.push(FaultKind::Pulse(base, frac));
        }
    }
    faults
}

/// One case at one K and W: the clean stream, then each fault (none if the clean stream
/// already has a wrong valid window).
fn run_case(p: &Params, truth: &[Edge], k: u16, w: u16, faults: &[FaultKind], st: &mut Stats) {
    let (clean, crec) = run(p, k, w, &apply(truth, FaultKind::None));
    st.clean_runs += 1;
    st.clean_invalid += clean.iter().filter(|o| !o.report.valid()).count() as u64;
    st.clean_faults += crec.faults.len() as u64;
    if clean.iter().all(|o| !o.report.valid()) {
        st.clean_no_valid += 1;
    }
    let clean_bad = clean.iter().any(|o| {
        o.report.valid() && !matches!(replica(p, truth, k.into(), w.into(), o), Check::Ok { .. })
    });
    if clean_bad {
        st.clean_bad_configs += 1;
    }
    for &f in faults {
        if clean_bad && !matches!(f, FaultKind::None) {
            continue;
        }
        st.runs += 1;
        let lines = if matches!(f, FaultKind::None) {
            check_run(p, truth, k, w, f, &clean, &clean, st)
        } else {
            let (out, _) = run(p, k, w, &apply(truth, f));
            check_run(p, truth, k, w, f, &clean, &out, st)
        };
        for l in lines {
            println!("{l}");
        }
    }
}

/// Replays one case (`CRANK_CASE`, see the module's documentation) edge by edge: the edges
/// around the fault, as generated and as the monitor took them, the faults it counted, the
/// windows of the faulted and of the clean stream, and any `WRONG` line. Returns the number
/// of wrong valid windows.
fn replay(case: &str) -> u64 {
    let a: Vec<&str> = case.split_whitespace().collect();
    assert!(
        a.len() >= 11,
        "CRANK_CASE: n m a z ph nphase σ seed K W none|lost i|pulse i frac"
    );
    let f = |i: usize| -> f64 { a[i].parse().unwrap() };
    let p = Params {
        n: a[0].parse().unwrap(),
        m: a[1].parse().unwrap(),
        a: f(2),
        z: f(3),
        ph: a[4].parse().unwrap(),
        nphase: a[5].parse().unwrap(),
        sigma: f(6),
        seed: a[7].parse().unwrap(),
    };
    let (k, w): (u16, u16) = (a[8].parse().unwrap(), a[9].parse().unwrap());
    let fault = match a[10] {
        "lost" => FaultKind::Lost(a[11].parse().unwrap()),
        "pulse" => FaultKind::Pulse(a[11].parse().unwrap(), f(12)),
        _ => FaultKind::None,
    };
    let truth = generate(&p);
    let ticks = apply(&truth, fault);
    let (out, rec) = run(&p, k, w, &ticks);
    let (clean, _) = run(&p, k, w, &apply(&truth, FaultKind::None));
    let centre = match fault {
        FaultKind::Lost(i) | FaultKind::Pulse(i, _) => i,
        FaultKind::None => 30.min(truth.len() - 1),
    };
    let lo = truth[centre.saturating_sub(4)].ticks;
    let hi = truth[(centre + 4).min(truth.len() - 1)].ticks;
    for &t in ticks.iter().filter(|&&t| (lo..=hi).contains(&t)) {
        let what = truth
            .iter()
            .find(|e| e.ticks == t)
            .map_or("NOISE".into(), |e| {
                format!("true pos {} rev {}", e.pos, e.rev)
            });
        let took = rec
            .teeth
            .iter()
            .find(|x| x.0 == t)
            .map_or("not accepted".into(), |x| {
                format!("accepted as tooth {} synced {} frame {}", x.1, x.2, x.3)
            });
        println!("edge {t}: {what}: {took}");
    }
    for (fl, t) in &rec.faults {
        println!("fault {fl:?} at {t}");
    }
    for (name, outs) in [("window", &out), ("clean window", &clean)] {
        for o in outs {
            let r = &o.report;
            println!(
                "{name} {}..{} edges {}..{} {:?}",
                r.start_ticks,
                r.end_ticks,
                r.start_edge,
                r.end_edge,
                r.result.map(|m| m.delta)
            );
        }
    }
    let mut st = Stats::default();
    for l in check_run(&p, &truth, k, w, fault, &clean, &out, &mut st) {
        println!("{l}");
    }
    st.wrong
}

/// The whole sweep (`CRANK_SWEEP` unset or `full`), the finer one near the frame
/// (`CRANK_SWEEP=near1`, `near2`: seed offsets 1 and 2), one wheel of either
/// (`CRANK_WHEEL=36-2`), or one case replayed (`CRANK_CASE`). Asserts that no valid window
/// is wrong, on the faulted streams and on the clean ones.
#[test]
#[ignore]
fn crank_sweep_finds_no_wrong_window() {
    if let Ok(case) = std::env::var("CRANK_CASE") {
        assert_eq!(replay(&case), 0, "a wrong valid window");
        return;
    }
    let which = std::env::var("CRANK_SWEEP").unwrap_or_else(|_| "full".into());
    // `full` or `near`, then an optional seed offset.
    let (near, off) = match which.strip_prefix("near") {
        Some(off) => (true, off),
        None => (
            false,
            which
                .strip_prefix("full")
                .expect("CRANK_SWEEP: full or near1"),
        ),
    };
    let seedoff: u64 = if off.is_empty() {
        0
    } else {
        off.parse().expect("CRANK_SWEEP: a seed offset")
    };
    let wheel: Option<(u32, u32)> = std::env::var("CRANK_WHEEL").ok().map(|s| {
        let (n, m) = s.split_once('-').expect("CRANK_WHEEL: e.g. 36-2");
        (n.parse().unwrap(), m.parse().unwrap())
    });
    let st = sweep(near, seedoff, &|p, _, _| {
        wheel.is_none_or(|(n, m)| (p.n, p.m) == (n, m))
    });
    assert!(st.valid > 0);
    assert_eq!(st.clean_wrong, 0, "wrong valid windows on clean streams");
    assert_eq!(st.wrong, 0, "wrong valid windows");
}

/// A part of the sweep, both fault sets: an 8-1, a 12-1, a 36-2 and a 60-2 wheel at ripples of
/// 0 and ±40 % with three strokes, two phases, σ of 0 and 2 %, K of 1 and 2, windows of one
/// revolution — the cases as in the whole sweep.
#[test]
fn a_part_of_the_crank_sweep_finds_no_wrong_window() {
    let keep = |p: &Params, k: u16, w: u16| {
        matches!((p.n, p.m), (8, 1) | (12, 1) | (36, 2) | (60, 2))
            && (p.a == 0.0 || (p.a == 0.4 && p.z == 3.0))
            && (p.ph == 2 || p.ph == 4)
            && p.sigma != 0.01
            && k <= 2
            && w == 1
    };
    for near in [false, true] {
        let st = sweep(near, 0, &keep);
        assert!(st.valid > 100, "{} valid windows", st.valid);
        assert_eq!(st.wrong, 0, "wrong valid windows (near {near})");
    }
}
