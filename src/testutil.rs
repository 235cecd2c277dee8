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

use drive_monitor::balancer::{Coupling, MachineConfig, Platform};
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
