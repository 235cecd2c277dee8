//! Test helpers shared by the unit tests and the integration tests (`tests/hard_cases.rs`
//! includes this file with `#[path]`, so both use the same lists, builders and references).

#![allow(dead_code)]

/// Values a strictly positive f64 parameter must reject: NaN, ±∞, zero, a negative value and a
/// subnormal (not physical, and it loses its digits in the first division).
pub(crate) const BAD: [f64; 6] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -1.0,
    1e-310,
];

/// The values of [`BAD`] a non-negative f64 parameter must reject: all but zero.
pub(crate) const BAD_NON_NEGATIVE: [f64; 5] =
    [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1.0, 1e-310];

/// [`BAD`] for f32 parameters; 1e-40 is subnormal as an f32 (though normal as an f64).
pub(crate) const BAD_F32: [f32; 6] = [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, 0.0, -1.0, 1e-40];

/// The values of [`BAD_F32`] a non-negative f32 parameter must reject: all but zero.
pub(crate) const BAD_F32_NON_NEGATIVE: [f32; 5] =
    [f32::NAN, f32::INFINITY, f32::NEG_INFINITY, -1.0, 1e-40];

use drive_monitor::balancer::{Coupling, Machine, MachineConfig, Platform};
use drive_monitor::drive::{DriveModel, Harmonic, Load, Motor, Parabola, SteadyState};

/// The seed 000 kneader: ω0 = 145 rad/s, ω_m = 36 rad/s, M_m = 158 N·m, J = 0.323 kg·m²,
/// mean load M1 = 24 N·m.
pub(crate) const W0: f64 = 145.0;
/// Breakdown speed ω_m, rad/s.
pub(crate) const WM: f64 = 36.0;
/// Breakdown torque M_m, N·m.
pub(crate) const MM: f64 = 158.0;
/// Reduced inertia J, kg·m².
pub(crate) const J: f64 = 0.323;
/// Mean load M1, N·m.
pub(crate) const M1: f64 = 24.0;

/// The seed's parabolic motor.
pub(crate) fn seed_motor() -> Motor {
    Parabola::new(W0, WM, MM).unwrap().into()
}

/// A load harmonic `amplitude·sin(order·φ + phase)`.
pub(crate) fn h(order: f64, amplitude: f64, phase: f64) -> Harmonic {
    Harmonic::new(order, amplitude, phase).unwrap()
}

/// The seed's drive with mean load M1, the given harmonics and inertia, no flywheel.
pub(crate) fn drive(harmonics: &[Harmonic], inertia: f64) -> DriveModel {
    DriveModel::new(
        seed_motor(),
        Load::new(M1, harmonics).unwrap(),
        inertia,
        0.0,
    )
    .unwrap()
}

/// The steady state of a drive that has one.
pub(crate) fn steady(m: &DriveModel) -> SteadyState {
    *m.predict().steady().expect("steady state")
}

/// The reference for one harmonic of amplitude `m2` and order `n` on the seed's drive at
/// inertia `j`, in the paper's own coefficients (eq. 10–12, B's sign corrected), written
/// independently of the model's `hypot` form: `(ū, R)` with ū = D2/D1 the mean and
/// R = 2·D3/√(4·D1² + n²) the amplitude of ω².
pub(crate) fn paper_terms(m2: f64, n: f64, j: f64) -> (f64, f64) {
    let k = W0 * W0 - WM * WM;
    let d1 = MM / (j * k);
    let d2 = (MM * W0 * W0 - M1 * k) / (j * k);
    let d3 = m2 / j;
    (d2 / d1, 2.0 * d3 / (4.0 * d1 * d1 + n * n).sqrt())
}

/// A platform of a vibration machine.
pub(crate) fn platform(mass: f64, stiffness: f64, damping: f64) -> Platform {
    Platform {
        mass,
        stiffness,
        damping,
    }
}

/// A coupling between platforms `a` and `b` (1-based).
pub(crate) fn coupling(a: u8, b: u8, stiffness: f64, damping: f64) -> Coupling {
    Coupling {
        between: [a, b],
        stiffness,
        damping,
    }
}

/// `cfg` with every mass ×`ms` (the auto-balancer's loads and housing too), stiffness ×`ks`
/// and damping and load viscosity ×`cs`.
pub(crate) fn scaled_config(cfg: &MachineConfig, ms: f64, ks: f64, cs: f64) -> MachineConfig {
    let p: Vec<Platform> = cfg
        .platforms()
        .iter()
        .map(|p| platform(p.mass * ms, p.stiffness * ks, p.damping * cs))
        .collect();
    let c: Vec<Coupling> = cfg
        .couplings()
        .iter()
        .map(|c| coupling(c.between[0], c.between[1], c.stiffness * ks, c.damping * cs))
        .collect();
    let mut b = *cfg.balancer();
    b.load_mass *= ms;
    b.housing_mass *= ms;
    b.viscosity *= cs;
    MachineConfig::new(&p, &c, b).unwrap()
}

/// The symmetric matrix (0-based, zero beyond the platforms) that the supports and couplings of
/// a validated machine make of one of their properties, assembled from the public
/// configuration: `support(p)` to the ground on the diagonal, `link(c)` between the coupled
/// platforms. Stiffness gives K, damping gives C.
pub(crate) fn assemble(
    cfg: &MachineConfig,
    support: impl Fn(&Platform) -> f64,
    link: impl Fn(&Coupling) -> f64,
) -> [[f64; 3]; 3] {
    let mut x = [[0.0; 3]; 3];
    for (i, p) in cfg.platforms().iter().enumerate() {
        x[i][i] += support(p);
    }
    for c in cfg.couplings() {
        let (a, b) = (c.between[0] as usize - 1, c.between[1] as usize - 1);
        let v = link(c);
        x[a][a] += v;
        x[b][b] += v;
        x[a][b] -= v;
        x[b][a] -= v;
    }
    x
}

/// Stiffness and mass matrices of a validated machine (moving masses include the balancer).
fn km(cfg: &MachineConfig) -> ([[f64; 3]; 3], [f64; 3], usize) {
    let n = cfg.platforms().len();
    let k = assemble(cfg, |p| p.stiffness, |c| c.stiffness);
    let mut m = [0.0; 3];
    for (i, mi) in m.iter_mut().enumerate().take(n) {
        *mi = cfg.moving_mass(i);
    }
    (k, m, n)
}

/// Eigenvalues of (K, M) restricted to the indices `idx`, by bisection on Sylvester's inertia:
/// the number of negative pivots of the LDLᵀ factorisation of K − λM is the number of
/// eigenvalues below λ. A second method, independent of the closed forms and Jacobi rotations
/// the core uses; each eigenvalue is bracketed down to adjacent doubles.
#[allow(clippy::needless_range_loop)]
fn inertia_eigenvalues(k: &[[f64; 3]; 3], m: &[f64; 3], idx: &[usize]) -> Vec<f64> {
    let n = idx.len();
    let below = |lambda: f64| {
        let mut a = [[0.0; 3]; 3];
        for i in 0..n {
            for j in 0..n {
                a[i][j] = k[idx[i]][idx[j]] - if i == j { lambda * m[idx[i]] } else { 0.0 };
            }
        }
        let mut neg = 0;
        for p in 0..n {
            let d = a[p][p];
            if d < 0.0 {
                neg += 1;
            }
            let d = if d == 0.0 { f64::MIN_POSITIVE } else { d };
            for i in p + 1..n {
                let l = a[i][p] / d;
                for j in p + 1..n {
                    a[i][j] -= l * a[p][j];
                }
            }
        }
        neg
    };
    let hi0 = (0..n)
        .map(|i| (0..n).map(|j| k[idx[i]][idx[j]].abs()).sum::<f64>() / m[idx[i]])
        .fold(0.0, f64::max)
        * 2.0;
    (0..n)
        .map(|i| {
            let (mut lo, mut hi) = (0.0, hi0);
            loop {
                let mid = 0.5 * (lo + hi);
                if mid <= lo || mid >= hi {
                    break hi;
                }
                if below(mid) > i {
                    hi = mid;
                } else {
                    lo = mid;
                }
            }
        })
        .map(f64::sqrt)
        .collect()
}

/// Resonant and additional speeds of a machine by the inertia method (rad/s, ascending): the
/// reference the auto-balancer's closed forms and Jacobi rotations are checked against.
pub(crate) fn reference_speeds(cfg: &MachineConfig) -> (Vec<f64>, Vec<f64>) {
    let (k, m, n) = km(cfg);
    let all: Vec<usize> = (0..n).collect();
    let others: Vec<usize> = (0..n).filter(|&i| i != cfg.exciter_index()).collect();
    (
        inertia_eigenvalues(&k, &m, &all),
        inertia_eigenvalues(&k, &m, &others),
    )
}

/// Relative difference `|a − b|/max(|a|, |b|)` (0 when equal).
fn rel_diff(a: f64, b: f64) -> f64 {
    if a == b {
        0.0
    } else {
        (a - b).abs() / a.abs().max(b.abs())
    }
}

/// Tolerance on zone boundaries (and capture `from`) between [`Machine::new`] and the scanned
/// reference [`Machine::new_scanned`]: both bracket each boundary to `rel_tol` (≤ 1e-12) on the
/// same solve, so 1e-9 leaves three decades.
pub(crate) const SCAN_BOUNDARY_TOL: f64 = 1e-9;
/// Tolerance on a capture maximum's location `at` where both searches find it inside the zone:
/// the scan's golden section on a flat maximum stops near `√ε` of it (measured up to 1.6e-8 on
/// 4 000 random machines), the fast search refines the zero of the exact slope to 1e-9.
pub(crate) const SCAN_AT_TOL: f64 = 1e-7;

/// How the fast analysis of a machine compares with the scanned reference.
#[derive(Debug, Default, Clone, Copy)]
pub(crate) struct ScanAgreement {
    /// Capture windows whose `until` agrees.
    pub agreeing: usize,
    /// Windows where the scan missed the maximum, which lies between its last node and the
    /// zone's end, and the fast search found it (checked against a dense search).
    pub scan_missed: usize,
    /// Largest relative difference of a zone boundary.
    pub boundary: f64,
    /// Largest relative difference of `until` among the agreeing windows.
    pub until: f64,
    /// Largest relative difference of `at` where both maxima are inside the zone.
    pub at: f64,
}

/// The largest `Ω + D(Ω)` on `[lo, hi]` by a dense search: 20 000 log-spaced nodes, then a
/// golden section about the best (the reference for maxima the scan missed).
pub(crate) fn dense_capture_max(m: &Machine, lo: f64, hi: f64) -> (f64, f64) {
    let f = |w: f64| w + m.capture_lag(w);
    let n = 20_000;
    let node = |i: usize| lo * (hi / lo).powf(i as f64 / n as f64);
    let mut best = (hi, f(hi), n);
    for i in 0..n {
        let x = node(i);
        let v = f(x);
        if v > best.1 {
            best = (x, v, i);
        }
    }
    let (mut a, mut b) = (node(best.2.saturating_sub(1)), node((best.2 + 1).min(n)));
    let g = 0.5 * (5f64.sqrt() - 1.0);
    for _ in 0..200 {
        let x1 = b - g * (b - a);
        let x2 = a + g * (b - a);
        if f(x1) >= f(x2) {
            b = x2
        } else {
            a = x1
        }
    }
    let x = 0.5 * (a + b);
    if f(x) > best.1 {
        (x, f(x))
    } else {
        (best.0, best.1)
    }
}

/// Checks [`Machine::new`]'s analysis `fast` against the scanned reference `scan` of the same
/// machine and options:
/// - characteristic speeds bit-identical (the same code);
/// - the same zones (count and kinds), boundaries within [`SCAN_BOUNDARY_TOL`];
/// - the same capture windows, `from` within [`SCAN_BOUNDARY_TOL`], and `until` within 1e-9
///   relative plus twice what `Ω + D(Ω)` changes between the two `from` and over four
///   roundings of each (`until` is often the value at the zone's end, where a sharp resonance
///   makes it steep);
/// - or else `fast.until` higher: the scan missed a maximum between its last node and the
///   zone's end. Then the fast value must be attained inside the zone (at `at`, to 1e-12)
///   and no lower than a dense search finds (to 1e-10: the fast search locates the maximum
///   to 1e-9, which moves its value by the square of that times the peak's sharpness);
/// - `at` within [`SCAN_AT_TOL`] where both maxima lie inside the zone.
pub(crate) fn compare_with_scan(fast: &Machine, scan: &Machine, what: &str) -> ScanAgreement {
    let mut agree = ScanAgreement::default();
    assert_eq!(fast.resonant_speeds(), scan.resonant_speeds(), "{what}");
    assert_eq!(fast.additional_speeds(), scan.additional_speeds(), "{what}");
    let (fz, sz) = (fast.zones(), scan.zones());
    assert_eq!(fz.len(), sz.len(), "{what}: zones {fz:?} vs {sz:?}");
    for (f, s) in fz.iter().zip(sz) {
        assert_eq!(f.kind, s.kind, "{what}");
        assert_eq!(f.to.is_some(), s.to.is_some(), "{what}");
        let r = rel_diff(f.from, s.from);
        assert!(r <= SCAN_BOUNDARY_TOL, "{what}: zones {fz:?} vs {sz:?}");
        agree.boundary = agree.boundary.max(r);
    }
    let (fc, sc) = (fast.capture_windows(), scan.capture_windows());
    assert_eq!(fc.len(), sc.len(), "{what}: captures {fc:?} vs {sc:?}");
    // Ω + D(Ω); on an undamped resonance (a singular solve), the value a few roundings below.
    let phi = |w: f64| {
        let mut step = 0.0;
        loop {
            let x = w * (1.0 - step);
            let v = x + fast.capture_lag(x);
            if !v.is_nan() || step > 1e-3 {
                return v;
            }
            step = if step == 0.0 {
                4.0 * f64::EPSILON
            } else {
                4.0 * step
            };
        }
    };
    // How much `Ω + D(Ω)` moves over a few roundings of `w` (it is steep at a sharp resonance).
    let jitter =
        |w: f64| (phi(w * (1.0 + 4.0 * f64::EPSILON)) - phi(w * (1.0 - 4.0 * f64::EPSILON))).abs();
    for (f, s) in fc.iter().zip(sc) {
        let d_from = rel_diff(f.from, s.from);
        assert!(d_from <= SCAN_BOUNDARY_TOL, "{what}: {f:?} vs {s:?}");
        let allowed = 1e-9 * s.until.abs()
            + 2.0 * (phi(f.from) - phi(s.from)).abs()
            + 2.0 * jitter(f.from)
            + 2.0 * jitter(s.from);
        if (f.until - s.until).abs() <= allowed {
            agree.agreeing += 1;
            agree.until = agree.until.max(rel_diff(f.until, s.until));
            if f.at < f.from && s.at < s.from {
                let r = rel_diff(f.at, s.at);
                assert!(r <= SCAN_AT_TOL, "{what}: {f:?} vs {s:?}");
                agree.at = agree.at.max(r);
            }
            continue;
        }
        assert!(f.until > s.until, "{what}: {f:?} below the scan's {s:?}");
        let zone = fz
            .iter()
            .find(|z| z.to == Some(f.from))
            .expect("a capture window ends a zone");
        let lo = zone.from.max(f.from * 1e-3);
        assert!(
            f.at >= lo && f.at <= f.from,
            "{what}: {f:?} outside {zone:?}"
        );
        assert!(
            (f.until - phi(f.at)).abs() <= 1e-12 * f.until + 2.0 * jitter(f.at),
            "{what}: {f:?} is not attained: {}",
            phi(f.at)
        );
        let (at, dense) = dense_capture_max(fast, lo, f.from);
        assert!(
            dense <= f.until * (1.0 + 1e-10),
            "{what}: {f:?} below the dense search's {dense} at {at}"
        );
        agree.scan_missed += 1;
    }
    agree
}
