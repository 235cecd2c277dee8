//! Unit tests: every split against an independent force/moment balance, the seed's closed
//! forms (corrected where misprinted), ISO allocation on worked numbers, hard cases, and the
//! runtime's totality.
#![allow(
    clippy::unwrap_used,
    clippy::expect_used,
    clippy::panic,
    clippy::needless_range_loop
)]

use super::*;
use crate::error::ConfigError;
use crate::math::{Libm, Micromath};
use crate::testutil::BAD;
use core::f64::consts::PI;
use proptest::prelude::*;

/// SplitMix64: a seeded generator for the randomised rotors.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn uniform(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * ((self.next() >> 11) as f64 / (1u64 << 53) as f64)
    }
}

/// Generic n×n solve by Gaussian elimination with partial pivoting (the test's independent
/// reference for the plane splits).
fn solve<const K: usize>(mut a: [[f64; K]; K], mut b: [f64; K]) -> [f64; K] {
    for col in 0..K {
        let piv = (col..K)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, piv);
        b.swap(col, piv);
        for row in col + 1..K {
            let f = a[row][col] / a[col][col];
            for k in col..K {
                a[row][k] -= f * a[col][k];
            }
            b[row] -= f * b[col];
        }
    }
    let mut x = [0.0; K];
    for row in (0..K).rev() {
        let s: f64 = (row + 1..K).map(|k| a[row][k] * x[k]).sum();
        x[row] = (b[row] - s) / a[row][row];
    }
    x
}

fn assert_close(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol,
        "{what}: got {got:e}, want {want:e}, |diff| {:e} > tol {tol:e}",
        (got - want).abs()
    );
}

fn assert_vec_close(got: Vec2, want: Vec2, tol: f64, what: &str) {
    assert_close(got.x, want.x, tol, what);
    assert_close(got.y, want.y, tol, what);
}

const CAP: usize = 8;

/// A random rotor; `overhung` puts unbalances (and possibly the centre of mass) outside the
/// span and lets B lie left of A.
fn random_rotor(rng: &mut Rng, overhung: bool) -> Rotor<CAP> {
    let za = rng.uniform(-2.0, 2.0);
    let len = rng.uniform(0.5, 5.0);
    let zb = if overhung && rng.next() % 2 == 0 {
        za - len
    } else {
        za + len
    };
    let (lo, hi) = (za.min(zb), za.max(zb));
    let n = 1 + (rng.next() % CAP as u64) as usize;
    let mut us = [Unbalance::default(); CAP];
    for u in us.iter_mut().take(n) {
        let z = if overhung {
            if rng.next() % 2 == 0 {
                hi + rng.uniform(0.0, 3.0 * len)
            } else {
                lo - rng.uniform(0.0, 3.0 * len)
            }
        } else {
            rng.uniform(lo, hi)
        };
        *u = Unbalance::new(z, rng.uniform(0.0, 5e-3), rng.uniform(-10.0, 10.0));
    }
    let zm = if overhung {
        hi + rng.uniform(0.0, len)
    } else {
        rng.uniform(lo, hi)
    };
    Rotor::new(rng.uniform(10.0, 1000.0), zm, za, zb, &us[..n], None).unwrap()
}

/// Tolerance for a split of this rotor: `rel` times the largest term of the balance.
fn split_tol(r: &Rotor<CAP>, planes: [f64; 2], rel: f64) -> f64 {
    let scale = r.axial_scale().max(planes[0].abs()).max(planes[1].abs());
    let total: f64 = r.unbalances().iter().map(|u| u.amount).sum();
    rel * total * (1.0 + 2.0 * scale / (planes[1] - planes[0]).abs())
}

#[test]
fn support_unbalance_matches_an_independent_linear_solve() {
    let mut rng = Rng(0x5EED_0002);
    for case in 0..400 {
        let r = random_rotor(&mut rng, case % 2 == 1);
        let (za, zb) = (r.support_a(), r.support_b());
        let [da, db] = r.support_unbalance();
        let tol = split_tol(&r, [za, zb], 1e-13);
        // Per component: [1 1; z_A z_B]·[D_A; D_B] = [Σ D_i; Σ z_i·D_i].
        for (comp, (ga, gb)) in [(0, (da.x, db.x)), (1, (da.y, db.y))] {
            let c = |v: Vec2| if comp == 0 { v.x } else { v.y };
            let f: f64 = r.pairs().map(|(_, v)| c(v)).sum();
            let m: f64 = r.pairs().map(|(z, v)| z * c(v)).sum();
            let [xa, xb] = solve([[1.0, 1.0], [za, zb]], [f, m]);
            assert_close(ga, xa, tol, "D_A vs solve");
            assert_close(gb, xb, tol, "D_B vs solve");
        }
        // Reconstruct force and moment about an arbitrary point.
        let p = rng.uniform(-10.0, 10.0);
        let f = r.pairs().fold(Vec2::ZERO, |s, (_, v)| s + v);
        let m = r.pairs().fold(Vec2::ZERO, |s, (z, v)| s + v * (z - p));
        assert_vec_close(da + db, f, tol, "force");
        assert_vec_close(
            da * (za - p) + db * (zb - p),
            m,
            tol * (1.0 + p.abs()),
            "moment",
        );
    }
}

#[test]
fn static_and_moment_split_eq_5_to_7() {
    let mut rng = Rng(57);
    for case in 0..200 {
        let r = random_rotor(&mut rng, case % 2 == 1);
        let s = r.plane_split();
        let (za, zb, zm) = (r.support_a(), r.support_b(), r.centre_of_mass());
        let l = zb - za;
        let d_st = r.static_unbalance();
        let tol = split_tol(&r, [za, zb], 1e-13) * (1.0 + zm.abs());
        // eq. 5: D_stA = D_st·L_B/L, D_stB = D_st·L_A/L with L_A, L_B from the centre of mass.
        assert_vec_close(s.static_a, d_st * ((zb - zm) / l), tol, "D_stA");
        assert_vec_close(s.static_b, d_st * ((zm - za) / l), tol, "D_stB");
        // eq. 6: D_MA = −D_MB = −M_D/L.
        assert_eq!(s.moment_a, -s.moment_b);
        let m = r.moment_unbalance();
        assert_vec_close(s.moment_b, m * (1.0 / l), tol, "D_MB");
        // eq. 7: D_A = D_stA + D_MA, D_B = D_stB + D_MB.
        let [da, db] = r.support_unbalance();
        assert_vec_close(s.static_a + s.moment_a, da, tol, "eq. 7 A");
        assert_vec_close(s.static_b + s.moment_b, db, tol, "eq. 7 B");
    }
}

#[test]
fn two_unbalances_eq_30_to_33_with_cos_in_the_denominator() {
    let mut rng = Rng(33);
    for _ in 0..300 {
        let (za, zb) = (0.0, rng.uniform(1.0, 5.0));
        let (z1, z2) = (rng.uniform(-3.0, 8.0), rng.uniform(-3.0, 8.0));
        let (d1, d2) = (rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
        let (a1, a2) = (rng.uniform(-PI, PI), rng.uniform(-PI, PI));
        let us = [Unbalance::new(z1, d1, a1), Unbalance::new(z2, d2, a2)];
        let r = Rotor::<2>::new(1.0, 1.0, za, zb, &us, None).unwrap();
        let [da, db] = r.support_unbalance();
        let tol = 1e-13 * (1.0 + 8.0 / zb);
        // eq. 30: moments about A and about B vanish.
        let (v1, v2) = (us[0].vector(), us[1].vector());
        let ma = v1 * (z1 - za) + v2 * (z2 - za) - db * (zb - za);
        let mb = v1 * (z1 - zb) + v2 * (z2 - zb) - da * (za - zb);
        assert!(ma.norm() <= tol && mb.norm() <= tol, "eq. 30 moments");
        // eq. 32: magnitudes by the law of cosines.
        let mag = |p: f64, q: f64| {
            libm::sqrt(
                d1 * d1 * p * p + d2 * d2 * q * q + 2.0 * d1 * d2 * p * q * libm::cos(a1 - a2),
            ) / zb.abs()
        };
        assert_close(da.norm(), mag(z1 - zb, z2 - zb), tol, "eq. 32 |D_A|");
        assert_close(db.norm(), mag(z1 - za, z2 - za), tol, "eq. 32 |D_B|");
        // eq. 33, corrected (cos α_2 in the denominator) and resolved by quadrant: the
        // components of eq. 30 over (Z_A − Z_B), then atan2.
        let num = (d1 * libm::sin(a1) * (z1 - zb) + d2 * libm::sin(a2) * (z2 - zb)) / (za - zb);
        let den = (d1 * libm::cos(a1) * (z1 - zb) + d2 * libm::cos(a2) * (z2 - zb)) / (za - zb);
        if da.norm() > 1e-6 {
            let diff = libm::remainder(da.angle() - libm::atan2(num, den), 2.0 * PI);
            assert!(diff.abs() < 1e-10, "eq. 33 angle off by {diff}");
        }
    }
    // The printed eq. 33 (sin α_2 in the denominator) gives a different angle: D_1 = 1 at 0°
    // in z_1 = 1, D_2 = 1 at 90° in z_2 = 2 on supports 0…4: components (−3, −2)/(−4), so
    // α_A = atan2(2, 3) ≈ 33.7°; the printed denominator gives atan(2/5) ≈ 21.8°.
    let us = [
        Unbalance::new(1.0, 1.0, 0.0),
        Unbalance::new(2.0, 1.0, PI / 2.0),
    ];
    let r = Rotor::<2>::new(1.0, 1.0, 0.0, 4.0, &us, None).unwrap();
    let [da, _] = r.support_unbalance();
    assert_close(da.angle(), libm::atan2(2.0, 3.0), 1e-15, "α_A");
    let printed =
        libm::atan((1.0 * 0.0 * -3.0 + 1.0 * 1.0 * -2.0) / (1.0 * 1.0 * -3.0 + 1.0 * 1.0 * -2.0));
    assert!((printed - da.angle()).abs() > 0.2);
}

#[test]
fn transfer_between_plane_pairs_eq_34_to_38() {
    let mut rng = Rng(38);
    for _ in 0..300 {
        let (za, zb) = (0.0, rng.uniform(1.0, 5.0));
        let da = Vec2::from_polar(rng.uniform(0.0, 1.0), rng.uniform(-PI, PI));
        let db = Vec2::from_polar(rng.uniform(0.0, 1.0), rng.uniform(-PI, PI));
        let z1 = rng.uniform(-3.0, 8.0);
        let z2 = z1 + rng.uniform(0.3, 3.0) * if rng.next() % 2 == 0 { 1.0 } else { -1.0 };
        let [e1, e2] = equivalent_planes(&[(za, da), (zb, db)], [z1, z2]).unwrap();
        let tol = 1e-13 * (1.0 + 16.0 / (z2 - z1).abs());
        // eq. 35: −D_1 = (D_A(Z_A − Z_2) + D_B(Z_B − Z_2))/(Z_2 − Z_1), and for D_2 likewise.
        assert_vec_close(
            -e1,
            (da * (za - z2) + db * (zb - z2)) * (1.0 / (z2 - z1)),
            tol,
            "eq. 35 D_1",
        );
        assert_vec_close(
            -e2,
            (da * (za - z1) + db * (zb - z1)) * (1.0 / (z1 - z2)),
            tol,
            "eq. 35 D_2",
        );
        // Back to A and B: the round trip returns the originals.
        let [ra, rb] = equivalent_planes(&[(z1, e1), (z2, e2)], [za, zb]).unwrap();
        assert_vec_close(ra, da, tol * 10.0, "round trip A");
        assert_vec_close(rb, db, tol * 10.0, "round trip B");
    }
    // eq. 38, the static case: all angles equal; signed scalars along the common direction.
    let alpha = 2.5;
    let u = Vec2::from_polar(1.0, alpha);
    let (z1, z2, za, zb, d1, d2) = (0.7, 3.1, 0.0, 4.0, 0.3, 0.45);
    let r = Rotor::<2>::new(
        1.0,
        2.0,
        za,
        zb,
        &[Unbalance::new(z1, d1, alpha), Unbalance::new(z2, d2, alpha)],
        None,
    )
    .unwrap();
    let [a, b] = r.support_unbalance();
    let want_a = -(d1 * (z1 - zb) + d2 * (z2 - zb)) / (zb - za);
    let want_b = -(d1 * (z1 - za) + d2 * (z2 - za)) / (za - zb);
    assert_vec_close(a, u * want_a, 1e-15, "eq. 38 D_A");
    assert_vec_close(b, u * want_b, 1e-15, "eq. 38 D_B");
}

#[test]
fn table_1_scheme_i_inboard_and_scheme_ii_overhung() {
    let l = 4.0;
    let (v1, v2) = (Vec2::new(0.3, -0.1), Vec2::new(-0.2, 0.25));
    // Static column (signed vectors), the same balance for both schemes: unbalances v1, v2 in
    // planes l1, l2 to the supports (D_A, D_B) and back; `tol` for the way back.
    let static_column = |scheme: &str, l1: f64, l2: f64, tol: f64| {
        let [a, b] = equivalent_planes(&[(l1, v1), (l2, v2)], [0.0, l]).unwrap();
        assert_vec_close(
            a,
            (v1 * (l - l1) + v2 * (l - l2)) * (1.0 / l),
            1e-15,
            &format!("{scheme}: D_A"),
        );
        assert_vec_close(
            b,
            (v1 * l1 + v2 * l2) * (1.0 / l),
            1e-15,
            &format!("{scheme}: D_B"),
        );
        let [c1, c2] = equivalent_planes(&[(0.0, a), (l, b)], [l1, l2]).unwrap();
        // D_1 corrected (scheme I's table repeats D_2's formula), D_2 as printed.
        assert_vec_close(
            c1,
            (a * l2 + b * (l2 - l)) * (1.0 / (l2 - l1)),
            tol,
            &format!("{scheme}: D_1"),
        );
        assert_vec_close(
            c2,
            (-a * l1 + b * (l - l1)) * (1.0 / (l2 - l1)),
            tol,
            &format!("{scheme}: D_2"),
        );
        assert_vec_close(c1, v1, tol, &format!("{scheme}: back to plane 1"));
        assert_vec_close(c2, v2, tol, &format!("{scheme}: back to plane 2"));
        [a, b]
    };
    // Scheme I: both correction planes inside the span.
    let (l1, l2) = (1.0, 3.0);
    static_column("I", l1, l2, 1e-15);
    // Moment column: magnitudes d1 at 0°, d2 at 180°; D_A along 0°, D_B along 180°.
    let (d1, d2) = (0.4, 0.3);
    let [ma, mb] = equivalent_planes(
        &[(l1, Vec2::new(d1, 0.0)), (l2, Vec2::new(-d2, 0.0))],
        [0.0, l],
    )
    .unwrap();
    let (sa, sb) = (
        (d1 * (l - l1) - d2 * (l - l2)) / l,
        (-d1 * l1 + d2 * l2) / l,
    );
    assert_close(ma.x, sa, 1e-15, "I moment: D_A");
    assert_close(-mb.x, sb, 1e-15, "I moment: D_B");
    // Inverse: d1 = (D_A·l2 + D_B·(L − l2))/(l2 − l1) (printed with D_2·l2), d2 as printed.
    assert_close(
        (sa * l2 + sb * (l - l2)) / (l2 - l1),
        d1,
        1e-15,
        "I moment: D_1",
    );
    assert_close(
        (sa * l1 + sb * (l - l1)) / (l2 - l1),
        d2,
        1e-15,
        "I moment: D_2",
    );

    // Scheme II: correction planes overhung beyond B (signed l > L). Same balance.
    let [a, b] = static_column("II", 5.0, 6.5, 1e-14);
    // And the supports themselves overhung by the correction planes on both sides.
    let [c1, c2] = equivalent_planes(&[(0.0, a), (l, b)], [-2.0, 7.0]).unwrap();
    let [ra, rb] = equivalent_planes(&[(-2.0, c1), (7.0, c2)], [0.0, l]).unwrap();
    assert_vec_close(ra, a, 1e-14, "II: round trip A");
    assert_vec_close(rb, b, 1e-14, "II: round trip B");
}

#[test]
fn corrections_recompose_to_zero_force_and_moment() {
    let mut rng = Rng(0xC0);
    for case in 0..400 {
        let r = random_rotor(&mut rng, case % 2 == 1);
        let z1 = match case % 4 {
            0 | 1 => rng.uniform(-3.0, 3.0),
            2 => rng.uniform(50.0, 100.0), // far outside the span
            _ => rng.uniform(-100.0, -50.0),
        };
        let z2 = z1 + rng.uniform(0.2, 4.0);
        let [c1, c2] = r.corrections(z1, z2).unwrap();
        // Residual force and moment about plane 1, and the size of the terms summed.
        let mut f = c1 + c2;
        let mut m = c2 * (z2 - z1);
        let mut size = c1.norm() + c2.norm() * (1.0 + (z2 - z1).abs());
        for (z, v) in r.pairs() {
            f = f + v;
            m = m + v * (z - z1);
            size += v.norm() * (1.0 + (z - z1).abs());
        }
        assert!(
            f.norm() <= 1e-12 * size,
            "force residual {:e} of {size:e}",
            f.norm()
        );
        assert!(
            m.norm() <= 1e-12 * size,
            "moment residual {:e} of {size:e}",
            m.norm()
        );
    }
}

#[test]
fn iso_allocation_on_worked_numbers() {
    // U_per = G·m/ω = 6.3e-3 m/s · 350 kg / 60 rad/s = 0.03675 kg·m.
    let u = permissible_residual_unbalance(6.3, 350.0, 60.0);
    assert_close(u, 0.03675, 1e-17, "U_per");
    // Inboard, CoM at 1.9 on 0…4: L_A = 1.9, L_B = 2.1.
    let p = allocate(u, 0.0, 4.0, 1.9);
    assert_eq!(p.allocation, Allocation::Inboard);
    assert_close(p.a, 0.03675 * 2.1 / 4.0, 1e-17, "A = 0.01929375");
    assert_close(p.b, 0.03675 * 1.9 / 4.0, 1e-17, "B = 0.01745625");
    assert_close(p.a, 0.019_293_75, 1e-16, "A");
    // Supports given in the other order: the same physical allocation.
    let q = allocate(u, 4.0, 0.0, 1.9);
    assert_close(q.a, 0.017_456_25, 1e-16, "reversed A");
    assert_close(q.b, 0.019_293_75, 1e-16, "reversed B");
    // Clamp: CoM at 0.4: shares 0.9/0.1 are held at 0.7/0.3.
    let c = allocate(u, 0.0, 4.0, 0.4);
    assert_close(c.a, 0.7 * 0.03675, 1e-17, "clamped A = 0.025725");
    assert_close(c.b, 0.3 * 0.03675, 1e-17, "clamped B = 0.011025");
    // CoM on a support: still inboard, clamped.
    let s = allocate(u, 0.0, 4.0, 0.0);
    assert_eq!(s.allocation, Allocation::Inboard);
    assert_close(s.a, 0.025_725, 1e-16, "on support A");
    assert_close(s.b, 0.011_025, 1e-16, "on support A, B");
    // Overhung, CoM at 5 on 0…4: |L_B|/L = 0.25, held at the floor 0.3, and L_A/L = 1.25.
    let o = allocate(u, 0.0, 4.0, 5.0);
    assert_eq!(o.allocation, Allocation::Overhung);
    assert_close(o.a, 0.3 * 0.03675, 1e-17, "overhung A = 0.011025");
    assert_close(o.b, 1.25 * 0.03675, 1e-17, "overhung B = 0.0459375");
    // The overhung rule's defining property: U_per placed at the centre of mass sits exactly
    // on the near plane's limit and within the far one's.
    let r = Rotor::<1>::new(350.0, 5.0, 0.0, 4.0, &[Unbalance::new(5.0, u, 1.0)], None).unwrap();
    let [da, db] = r.support_unbalance();
    assert_close(da.norm(), 0.25 * 0.03675, 1e-17, "U_per at CoM → plane A");
    assert!(da.norm() < o.a);
    assert_close(db.norm(), o.b, 1e-17, "U_per at CoM → plane B");
    // Far out the floor does not bind: CoM at 6, |L_B|/L = 0.5, L_A/L = 1.5.
    let f = allocate(u, 0.0, 4.0, 6.0);
    assert_close(f.a, 0.5 * 0.03675, 1e-17, "far overhung A");
    assert_close(f.b, 1.5 * 0.03675, 1e-17, "far overhung B");
}

/// Where the centre of mass crosses a support the far plane's limit stays at 30 % of U_per
/// on both sides (it fell to U_per·|L_A|/L → 0 outside: 1 mm overhung on a 4 m span allowed
/// 9.19e-6 kg·m at B against 1.10e-2 inboard, and a well-balanced rotor read "over"), and the
/// near plane's never falls.
#[test]
fn the_far_plane_limit_is_continuous_where_the_centre_of_mass_crosses_a_support() {
    let u = permissible_residual_unbalance(6.3, 350.0, 60.0);
    for (a, b) in [(0.0, 4.0), (4.0, 0.0)] {
        for eps in [1e-3, 1e-6, 0.0] {
            // Just inside and just outside support A (at 0).
            let inside = allocate(u, a, b, eps);
            let outside = allocate(u, a, b, -eps);
            let far = |p: &Permissible| if a == 0.0 { p.b } else { p.a };
            let near = |p: &Permissible| if a == 0.0 { p.a } else { p.b };
            assert_close(far(&inside), 0.3 * u, 1e-17, "far, inside");
            assert_close(far(&outside), 0.3 * u, 1e-17, "far, outside");
            assert!(near(&outside) >= near(&inside), "{eps}");
        }
    }
}

#[test]
fn planes_nearly_coincident() {
    // Scale 2.0 (the unbalance at z = 2): the threshold is 2e-6.
    let us = [Unbalance::new(2.0, 1.0, 0.0)];
    let below = Rotor::<1>::new(1.0, 1.0, 1.0, 1.0 + 1.9e-6, &us, None);
    assert_eq!(below.unwrap_err(), ConfigError::Inconsistent("support_b"));
    assert_eq!(
        Rotor::<1>::new(1.0, 1.0, 1.0, 1.0, &us, None).unwrap_err(),
        ConfigError::Inconsistent("support_b")
    );
    // Just above: span 2^-18 ≈ 3.8e-6; the exact answers are representable.
    let span = libm::ldexp(1.0, -18);
    let r = Rotor::<1>::new(1.0, 1.0, 1.0, 1.0 + span, &us, None).unwrap();
    let [da, db] = r.support_unbalance();
    assert_eq!(da, Vec2::new(-(libm::ldexp(1.0, 18) - 1.0), 0.0));
    assert_eq!(db, Vec2::new(libm::ldexp(1.0, 18), 0.0));
    // Just above with inexact positions: against the generic solve.
    let (za, zb) = (1.0, 1.0 + 2.1e-6);
    let us = [
        Unbalance::new(1.9, 1e-3, 0.4),
        Unbalance::new(0.3, 2e-3, -2.0),
    ];
    let r = Rotor::<2>::new(1.0, 1.0, za, zb, &us, None).unwrap();
    let [da, db] = r.support_unbalance();
    let (l, f, m) = (
        zb - za,
        us[0].vector() + us[1].vector(),
        us[0].vector() * (1.9 - za) + us[1].vector() * (0.3 - za),
    );
    // Moments taken about A: [1 1; 0 L]·[D_A; D_B] = [F; M_A].
    let [xa, xb] = solve([[1.0, 1.0], [0.0, l]], [f.x, m.x]);
    assert_close(da.x / xa, 1.0, 1e-9, "near-coincident A");
    assert_close(db.x / xb, 1.0, 1e-9, "near-coincident B");
    // Correction planes too close, and coincident.
    assert_eq!(
        r.corrections(1.5, 1.5 + 1e-7).unwrap_err(),
        ConfigError::Inconsistent("correction_plane_2")
    );
    assert_eq!(
        r.corrections(3.0, 3.0).unwrap_err(),
        ConfigError::Inconsistent("correction_plane_2")
    );
    assert_eq!(
        equivalent_planes(&[(0.0, Vec2::new(1.0, 0.0))], [1.0, 1.0]).unwrap_err(),
        ConfigError::Inconsistent("correction_plane_2")
    );
    assert_eq!(
        r.corrections(f64::NAN, 2.0).unwrap_err(),
        ConfigError::NonFinite("correction_plane_1")
    );
}

#[test]
fn unbalances_that_nearly_cancel_keep_their_remainder() {
    assert_eq!(libm::cos(PI), -1.0);
    let (za, zb) = (0.0, 4.0);
    let zs = [0.37, 1.3, 2.9];
    let eps = [3.0, 5.0, 7.0].map(|k| k * libm::ldexp(1.0, -52)); // ≈ 7e-16 … 1.6e-15
    let amounts = [0.61, 0.83, 0.97];
    let mut us = [Unbalance::default(); 6];
    for k in 0..3 {
        us[2 * k] = Unbalance::new(zs[k], amounts[k], 0.0);
        us[2 * k + 1] = Unbalance::new(zs[k], amounts[k] - eps[k], PI);
        assert_eq!(amounts[k] - (amounts[k] - eps[k]), eps[k]); // exact inputs
    }
    let r = Rotor::<6>::new(1.0, 2.0, za, zb, &us, None).unwrap();
    // Rearranged reference: cancel each pair first (exact), then take the levers.
    let net: [Vec2; 3] = core::array::from_fn(|k| us[2 * k].vector() + us[2 * k + 1].vector());
    assert_eq!(net[1].x, eps[1]);
    let want_a = (0..3).fold(Vec2::ZERO, |s, k| s + net[k] * ((zb - zs[k]) / (zb - za)));
    let want_b = (0..3).fold(Vec2::ZERO, |s, k| s + net[k] * ((zs[k] - za) / (zb - za)));
    let [da, db] = r.support_unbalance();
    assert_close(da.x / want_a.x, 1.0, 1e-12, "cancelling D_A.x");
    assert_close(db.x / want_b.x, 1.0, 1e-12, "cancelling D_B.x");
    assert_close(da.y / want_a.y, 1.0, 1e-12, "cancelling D_A.y");
    let st = r.static_unbalance();
    assert_eq!(st.x, eps[0] + eps[1] + eps[2]);
    // Exact cancellation gives exactly zero along x.
    let r = Rotor::<2>::new(
        1.0,
        2.0,
        za,
        zb,
        &[Unbalance::new(1.1, 0.7, 0.0), Unbalance::new(1.1, 0.7, PI)],
        None,
    )
    .unwrap();
    let [da, db] = r.support_unbalance();
    assert_eq!((da.x, db.x, r.static_unbalance().x), (0.0, 0.0, 0.0));
}

#[test]
fn pure_couple() {
    let (a, theta) = (2e-3, 0.7);
    let us = [
        Unbalance::new(1.0, a, theta),
        Unbalance::new(3.0, a, theta + PI),
    ];
    let r = Rotor::<2>::new(350.0, 2.0, 0.0, 4.0, &us, None).unwrap();
    let u = Vec2::from_polar(1.0, theta);
    // The angle π is rounded, so "zero" is a few ulps of the amount.
    assert!(r.static_unbalance().norm() <= 1e-15 * a);
    let [da, db] = r.support_unbalance();
    assert!((da + db).norm() <= 1e-15 * a, "D_A = −D_B");
    // D_A = a·u·(z_2 − z_1)/L, the moment unbalance about the CoM is a·u·(z_1 − z_2).
    assert_vec_close(da, u * (a * 2.0 / 4.0), 1e-15 * a, "couple D_A");
    assert_vec_close(r.moment_unbalance(), u * (-2.0 * a), 1e-15 * a, "M_D");
    let s = r.plane_split();
    assert!(s.static_a.norm() <= 1e-15 * a && s.static_b.norm() <= 1e-15 * a);
}

#[test]
fn unbalance_far_outside_the_span() {
    let d = Unbalance::new(1000.0, 1e-3, 0.3);
    let r = Rotor::<1>::new(10.0, 2.0, 0.0, 4.0, &[d], None);
    // The scale is 1000, the span 4: well conditioned enough (4e-3 > 1e-6).
    let r = r.unwrap();
    let [da, db] = r.support_unbalance();
    assert_vec_close(da, d.vector() * (-996.0 / 4.0), 1e-17, "far D_A");
    assert_vec_close(db, d.vector() * (1000.0 / 4.0), 1e-17, "far D_B");
    // Correction planes far away on the other side: still recomposes.
    let [c1, c2] = r.corrections(-101.0, -100.0).unwrap();
    let f = c1 + c2 + d.vector();
    let m = c1 * (-101.0 - 1000.0) + c2 * (-100.0 - 1000.0);
    assert!(f.norm() <= 1e-15 && m.norm() <= 1e-12);
}

/// The auger's rotor: 350 kg with its centre of mass at 1.9, supports at 0 and `support_b`,
/// an unbalance of 2e-3 kg·m at `unbalance_z` and 30°, and a process load of 400 N/m on
/// 0.5…3.5 at 270°.
fn auger_rotor(support_b: f64, unbalance_z: f64) -> Rotor<4> {
    Rotor::<4>::new(
        350.0,
        1.9,
        0.0,
        support_b,
        &[Unbalance::new(unbalance_z, 2.0e-3, 30f64.to_radians())],
        Some(ProcessLoad {
            per_length: 400.0,
            from: 0.5,
            to: 3.5,
            angle: 270f64.to_radians(),
        }),
    )
    .unwrap()
}

/// The auger's limits: grade G 6.3 up to 60 rad/s, 8 000 N at each support, warning at 0.8.
fn auger_limits() -> Limits {
    Limits::new(6.3, 60.0, Some([8000.0, 8000.0]), 0.8).unwrap()
}

/// The bundled auger scene (supports at 0 and 4, the unbalance at 1.2), with or without
/// gravity, and its limits.
fn auger(gravity: bool) -> (Rotor<4>, Limits) {
    let rotor = auger_rotor(4.0, 1.2);
    let rotor = if gravity {
        rotor
    } else {
        rotor.with_gravity(0.0, 0.0).unwrap()
    };
    (rotor, auger_limits())
}

#[test]
fn bundled_auger_scene_worked_numbers() {
    let (rotor, limits) = auger(true);
    let an = SupportAnalysis::new(&rotor, &limits).unwrap();
    let rep = an.report();
    // D = 2e-3 at z = 1.2 on 0…4: D_A = 2e-3·2.8/4, D_B = 2e-3·1.2/4.
    assert_close(rep.unbalance_a, 1.4e-3, 1e-18, "unbalance_a");
    assert_close(rep.unbalance_b, 0.6e-3, 1e-18, "unbalance_b");
    assert_close(rep.permissible_a, 0.019_293_75, 1e-16, "permissible_a");
    assert_close(rep.permissible_b, 0.017_456_25, 1e-16, "permissible_b");
    // Static: weight 350·9.80665 = 3432.3275 N at 1.9 → 1801.97194 N at A, 1630.35556 N at
    // B; process load 400·3 = 1200 N at 2.0 → 600 N each; both at 270°.
    let [sa, sb] = an.static_load;
    assert_close(
        sa.norm(),
        3432.3275 * 2.1 / 4.0 + 600.0,
        1e-9,
        "S_A = 2401.97194",
    );
    assert_close(
        sb.norm(),
        3432.3275 * 1.9 / 4.0 + 600.0,
        1e-9,
        "S_B = 2230.35556",
    );
    // ω_A = √((8000 − 2401.97194)/1.4e-3) ≈ 1999.648, ω_B = √((8000 − 2230.35556)/0.6e-3) ≈ 3100.980.
    let wa = libm::sqrt((8000.0 - 2401.9719375) / 1.4e-3);
    let wb = libm::sqrt((8000.0 - 2230.3555625) / 0.6e-3);
    assert_close(wa, 1999.647, 1e-3, "ω_A");
    assert_close(wb, 3100.9795, 1e-3, "ω_B");
    assert_close(rep.max_speed.unwrap(), wa, 1e-9, "max_speed");
    let [ma, mb] = an.max_speed.unwrap();
    assert_close(mb, wb, 1e-9, "ω_B");
    assert_eq!(ma, rep.max_speed.unwrap());
    // Without gravity only the process load's 600 N remains.
    let (r0, _) = auger(false);
    let an0 = SupportAnalysis::new(&r0, &limits).unwrap();
    assert_close(an0.static_load[0].norm(), 600.0, 1e-9, "no gravity S_A");
    assert_close(
        an0.max_safe_speed().unwrap(),
        libm::sqrt(7400.0 / 1.4e-3),
        1e-9,
        "no gravity max speed",
    );
    // Without load limits there is no max speed.
    let nl = Limits::new(6.3, 60.0, None, 0.8).unwrap();
    assert_eq!(
        SupportAnalysis::new(&rotor, &nl)
            .unwrap()
            .report()
            .max_speed,
        None
    );
}

#[test]
fn overhung_auger_variant_is_sensible() {
    // Supports at 0 and 1.5, the screw overhangs B up to 4.0: CoM 1.9 and the unbalance at
    // 3.5 lie beyond B, as does most of the process load.
    let rotor = auger_rotor(1.5, 3.5);
    let limits = auger_limits();
    let an = SupportAnalysis::new(&rotor, &limits).unwrap();
    let rep = an.report();
    // Lever: D_A = D·(1.5 − 3.5)/1.5 (opposite to D), D_B = D·3.5/1.5.
    assert_close(
        rep.unbalance_a,
        2e-3 * 2.0 / 1.5,
        1e-18,
        "overhung unbalance_a",
    );
    assert_close(
        rep.unbalance_b,
        2e-3 * 3.5 / 1.5,
        1e-18,
        "overhung unbalance_b",
    );
    let [da, _] = an.unbalance;
    let dv = Vec2::from_polar(2e-3, 30f64.to_radians());
    assert!(
        da.x * dv.x + da.y * dv.y < 0.0,
        "A is pushed opposite to the unbalance"
    );
    // Permissible, overhung rule: |L_B|/L = 0.4/1.5 held at the floor 0.3, L_A/L = 1.9/1.5.
    assert_eq!(an.permissible.allocation, Allocation::Overhung);
    assert_close(
        rep.permissible_a,
        0.03675 * 0.3,
        1e-16,
        "overhung permissible_a",
    );
    assert_close(
        rep.permissible_b,
        0.03675 * 1.9 / 1.5,
        1e-16,
        "overhung permissible_b",
    );
    // Static: weight at 1.9 and 1200 N at 2.0, both beyond B, lift A and load B more.
    let w = 350.0 * STANDARD_GRAVITY;
    let sa = w * (1.5 - 1.9) / 1.5 + 1200.0 * (1.5 - 2.0) / 1.5;
    let sb = w * 1.9 / 1.5 + 1200.0 * 2.0 / 1.5;
    assert_close(an.static_load[0].norm(), sa.abs(), 1e-9, "overhung S_A");
    assert_close(an.static_load[1].norm(), sb, 1e-9, "overhung S_B");
    assert!(an.static_load[0].y > 0.0, "A is loaded upwards");
    let want = libm::sqrt((8000.0 - sb) / (2e-3 * 3.5 / 1.5));
    assert_close(rep.max_speed.unwrap(), want, 1e-9, "overhung max speed");
    std::println!("overhung: {rep:?}, S = [{}, {}]", sa.abs(), sb);
}

#[test]
fn process_load_statics_against_a_discretised_beam() {
    let mut rng = Rng(12);
    for _ in 0..50 {
        let (za, zb) = (rng.uniform(-1.0, 1.0), rng.uniform(2.0, 5.0));
        let from = rng.uniform(-3.0, 6.0);
        let to = from + rng.uniform(0.1, 4.0);
        let (q, ang) = (rng.uniform(0.0, 1000.0), rng.uniform(-PI, PI));
        let p = ProcessLoad {
            per_length: q,
            from,
            to,
            angle: ang,
        };
        let r = Rotor::<1>::new(1.0, 1.0, za, zb, &[], Some(p))
            .unwrap()
            .with_gravity(0.0, 0.0)
            .unwrap();
        // Independent: 2000 segments, each q·dz at its middle, moments about B and A.
        let n = 2000;
        let dz = (to - from) / n as f64;
        let (mut ra, mut rb) = (0.0, 0.0);
        for i in 0..n {
            let z = from + (i as f64 + 0.5) * dz;
            ra += q * dz * (zb - z) / (zb - za);
            rb += q * dz * (z - za) / (zb - za);
        }
        let u = Vec2::from_polar(1.0, ang);
        let [sa, sb] = r.static_load();
        let tol = 1e-9 * q * (to - from) * (1.0 + 12.0 / (zb - za));
        assert_vec_close(sa, u * ra, tol, "S_A");
        assert_vec_close(sb, u * rb, tol, "S_B");
    }
}

#[test]
fn peak_and_minimum_match_a_phase_sweep() {
    let (rotor, _) = auger(true);
    for &omega in &[0.0, 30.0, 600.0, 1500.0, 2500.0] {
        let ranges = rotor.loads(omega);
        for (k, range) in ranges.iter().enumerate() {
            let s = rotor.static_load()[k];
            let d = rotor.support_unbalance()[k];
            let (mut hi, mut lo) = (0.0f64, f64::INFINITY);
            for i in 0..36_000 {
                let phi = i as f64 * (2.0 * PI / 36_000.0);
                let rot = Vec2::from_polar(d.norm() * omega * omega, phi);
                let n = (s + rot).norm();
                hi = hi.max(n);
                lo = lo.min(n);
            }
            // A 0.01° grid misses the extremes by at most |S||R|(1 − cos 0.005°) / |·|.
            assert_close(range.peak, hi, 1e-8 * hi + 1e-9, "peak");
            assert_close(range.min, lo, 1e-6 * hi + 1e-9, "min");
        }
    }
}

#[test]
fn max_safe_speed_edge_cases() {
    assert_eq!(max_safe_speed(3000.0, 1e-3, 2000.0), 0.0);
    assert_eq!(max_safe_speed(3000.0, 0.0, 2000.0), 0.0);
    assert_eq!(max_safe_speed(1000.0, 0.0, 2000.0), f64::INFINITY);
    assert_eq!(max_safe_speed(1000.0, 1e-3, 2000.0), 1000.0);
    assert_eq!(max_safe_speed(2000.0, 1e-3, 2000.0), 0.0);
}

#[test]
fn runtime_speeds_near_zero_and_near_the_limit() {
    let (rotor, limits) = auger(true);
    let an = SupportAnalysis::new(&rotor, &limits).unwrap();
    let mon = an.monitor().unwrap();
    let s = [
        an.static_load[0].norm() as f32,
        an.static_load[1].norm() as f32,
    ];
    for w in [0.0f32, -0.0, 1e-30, f32::MIN_POSITIVE, 1e-3] {
        let st = mon.update(w);
        assert!(st.speed_valid);
        for k in 0..2 {
            assert_close(st.peak_load[k] as f64, s[k] as f64, 1e-3, "peak at rest");
            assert_close(st.min_load[k] as f64, s[k] as f64, 1e-3, "min at rest");
        }
        assert_eq!(st.load, [Level::Normal; 2]);
        assert_eq!(st.unbalance, [Level::Normal; 2]);
    }
    let wmax = mon.max_safe_speed().unwrap();
    assert_close(
        wmax as f64,
        an.max_safe_speed().unwrap(),
        1e-3,
        "f32 max speed",
    );
    let below = mon.update(wmax * (1.0 - 1e-4));
    assert_eq!(below.load[0], Level::Warning);
    assert!(below.peak_load[0] < 8000.0 && below.peak_load[0] > 7990.0);
    let above = mon.update(wmax * (1.0 + 1e-4));
    assert_eq!(above.load[0], Level::Over);
    // B at the same speed: 0.6e-3·2000² + 2230 ≈ 4630 N, below the 6400 N warning threshold.
    assert_eq!(above.load[1], Level::Normal);
}

#[test]
fn runtime_matches_the_f64_analysis_and_reverse_speed() {
    let (rotor, limits) = auger(true);
    let mon = SupportAnalysis::new(&rotor, &limits)
        .unwrap()
        .monitor()
        .unwrap();
    for w in [10.0f32, 100.0, 777.0, 1500.0, 2100.0, 5000.0] {
        let st = mon.update(w);
        let back = mon.update(-w);
        assert_eq!(st, back, "reverse rotation loads the supports alike");
        let f = rotor.loads(w as f64);
        for k in 0..2 {
            assert_close(st.peak_load[k] as f64 / f[k].peak, 1.0, 1e-6, "f32 peak");
            assert_close(st.min_load[k] as f64, f[k].min, 1e-6 * f[k].peak, "f32 min");
        }
    }
    // Warning band for the load at A: 0.8·8000 = 6400 N ⇒ ω = √((6400 − 2401.97)/1.4e-3) ≈ 1690.
    assert_eq!(mon.update(1680.0).load[0], Level::Normal);
    assert_eq!(mon.update(1700.0).load[0], Level::Warning);
}

#[test]
fn runtime_unbalance_flags_and_update() {
    let (rotor, limits) = auger(true);
    let mut mon = SupportAnalysis::new(&rotor, &limits)
        .unwrap()
        .monitor()
        .unwrap();
    // Permissible A = 0.01929375, warning from 0.015435.
    assert!(mon.set_unbalance::<Libm>(0.015, 0.0));
    assert_eq!(mon.update(60.0).unbalance[0], Level::Normal);
    assert!(mon.set_unbalance::<Libm>(0.016, 0.0));
    assert_eq!(mon.update(60.0).unbalance[0], Level::Warning);
    assert!(mon.set_unbalance::<Libm>(0.02, 0.02));
    assert_eq!(mon.update(60.0).unbalance, [Level::Over; 2]);
    // Max speed follows: A: √((8000 − 2401.97)/0.02) ≈ 529.05 rad/s.
    let want = libm::sqrt((8000.0 - 2401.9719375) / 0.02);
    assert_close(
        mon.max_safe_speed().unwrap() as f64,
        want,
        1e-3,
        "updated max speed",
    );
    let mut mm = mon;
    assert!(mm.set_unbalance::<Micromath>(0.02, 0.02));
    let got = mm.max_safe_speed().unwrap() as f64;
    assert!(
        (got / want - 1.0).abs() < 0.07,
        "micromath sqrt within its 6.1 %"
    );
    // Zero unbalance: unlimited speed; garbage is refused.
    assert!(mon.set_unbalance::<Libm>(0.0, 0.0));
    assert_eq!(mon.max_safe_speed(), Some(f32::INFINITY));
    assert_eq!(mon.update(f32::INFINITY).load, [Level::Normal; 2]);
    for bad in [f32::NAN, f32::INFINITY, -1.0, f32::NEG_INFINITY] {
        assert!(!mon.set_unbalance::<Libm>(bad, 0.0));
        assert!(!mon.set_unbalance::<Libm>(0.0, bad));
    }
    assert_eq!(mon.unbalance(), [0.0, 0.0]);
}

#[test]
fn static_overload_means_no_safe_speed() {
    let (rotor, _) = auger(true);
    let limits = Limits::new(6.3, 60.0, Some([2000.0, 8000.0]), 0.8).unwrap();
    let an = SupportAnalysis::new(&rotor, &limits).unwrap();
    assert_eq!(an.max_safe_speed(), Some(0.0));
    let mon = an.monitor().unwrap();
    assert_eq!(mon.update(0.0).load[0], Level::Over);
    assert_eq!(mon.max_safe_speed(), Some(0.0));
}

#[test]
fn runtime_special_speeds() {
    let (rotor, limits) = auger(true);
    let mon = SupportAnalysis::new(&rotor, &limits)
        .unwrap()
        .monitor()
        .unwrap();
    let nan = mon.update(f32::NAN);
    assert!(!nan.speed_valid);
    assert_eq!(nan.load, [Level::Unknown; 2]);
    assert!(nan.peak_load[0].is_nan());
    assert_eq!(nan.unbalance, [Level::Normal; 2]);
    let inf = mon.update(f32::NEG_INFINITY);
    assert!(inf.speed_valid);
    assert_eq!(inf.load, [Level::Over; 2]);
    let huge = mon.update(f32::MAX);
    assert_eq!(huge.load, [Level::Over; 2]);
    // No load limits: loads reported, levels unknown, no max speed.
    let nl = Limits::new(6.3, 60.0, None, 0.8).unwrap();
    let m2 = SupportAnalysis::new(&rotor, &nl)
        .unwrap()
        .monitor()
        .unwrap();
    let st = m2.update(100.0);
    assert_eq!(st.load, [Level::Unknown; 2]);
    assert_eq!(st.max_safe_speed, None);
    assert!(st.peak_load[0] > 2400.0);
}

fn rotor_with(
    mass: f64,
    zm: f64,
    za: f64,
    zb: f64,
    u: Unbalance,
    p: Option<ProcessLoad>,
) -> Result<Rotor<2>, ConfigError> {
    Rotor::<2>::new(mass, zm, za, zb, &[u], p)
}

#[test]
fn constructors_reject_bad_numbers_with_typed_errors() {
    let u = Unbalance::new(1.0, 1e-3, 0.5);
    let p = ProcessLoad {
        per_length: 100.0,
        from: 0.5,
        to: 3.5,
        angle: 1.0,
    };
    let ok = |r: Result<Rotor<2>, ConfigError>| r.map(|_| ());
    for x in BAD {
        let nonfinite = !x.is_finite();
        // Positive magnitudes: mass.
        let want = if nonfinite {
            ConfigError::NonFinite("mass")
        } else {
            ConfigError::NotPositive("mass")
        };
        assert_eq!(ok(rotor_with(x, 2.0, 0.0, 4.0, u, None)), Err(want));
        // Coordinates: any finite value is a position.
        let coord = |name: &'static str| -> Result<(), ConfigError> {
            if nonfinite {
                Err(ConfigError::NonFinite(name))
            } else {
                Ok(())
            }
        };
        assert_eq!(
            ok(rotor_with(1.0, x, 0.0, 4.0, u, None)),
            coord("centre_of_mass")
        );
        assert_eq!(
            ok(rotor_with(1.0, 2.0, x, 4.0, u, None)),
            coord("support_a")
        );
        assert_eq!(
            ok(rotor_with(1.0, 2.0, -4.0, x, u, None)),
            coord("support_b")
        );
        let uz = Unbalance::new(x, 1e-3, 0.5);
        assert_eq!(
            ok(rotor_with(1.0, 2.0, 0.0, 4.0, uz, None)),
            coord("unbalance.z")
        );
        let ua = Unbalance::new(1.0, 1e-3, x);
        assert_eq!(
            ok(rotor_with(1.0, 2.0, 0.0, 4.0, ua, None)),
            coord("unbalance.angle")
        );
        // Non-negative amounts.
        let want = if nonfinite {
            Err(ConfigError::NonFinite("unbalance.amount"))
        } else if x == 0.0 {
            Ok(())
        } else if x < 0.0 {
            Err(ConfigError::Negative("unbalance.amount"))
        } else {
            Err(ConfigError::OutOfRange("unbalance.amount"))
        };
        let um = Unbalance::new(1.0, x, 0.5);
        assert_eq!(ok(rotor_with(1.0, 2.0, 0.0, 4.0, um, None)), want);
        let pq = ProcessLoad { per_length: x, ..p };
        let want_q = want.map_err(|e| match e {
            ConfigError::NonFinite(_) => ConfigError::NonFinite("process_load.per_length"),
            ConfigError::Negative(_) => ConfigError::Negative("process_load.per_length"),
            _ => ConfigError::OutOfRange("process_load.per_length"),
        });
        assert_eq!(ok(rotor_with(1.0, 2.0, 0.0, 4.0, u, Some(pq))), want_q);
        // Process-load ends: non-finite, or an empty/reversed interval.
        let pf = ProcessLoad { from: x, ..p };
        let want_f = if nonfinite {
            Err(ConfigError::NonFinite("process_load.from"))
        } else {
            Ok(())
        };
        assert_eq!(ok(rotor_with(1.0, 2.0, 0.0, 4.0, u, Some(pf))), want_f);
        let pt = ProcessLoad { to: x, ..p };
        let want_t = if nonfinite {
            Err(ConfigError::NonFinite("process_load.to"))
        } else {
            Err(ConfigError::Inconsistent("process_load.to"))
        };
        assert_eq!(ok(rotor_with(1.0, 2.0, 0.0, 4.0, u, Some(pt))), want_t);
        let pa = ProcessLoad { angle: x, ..p };
        assert_eq!(
            ok(rotor_with(1.0, 2.0, 0.0, 4.0, u, Some(pa))),
            coord("process_load.angle")
        );
        // Gravity: non-negative, any finite direction.
        let r0 = rotor_with(1.0, 2.0, 0.0, 4.0, u, None).unwrap();
        assert_eq!(r0.with_gravity(1.0, x).map(|_| ()), coord("gravity.angle"));
        let r = rotor_with(1.0, 2.0, 0.0, 4.0, u, None).unwrap();
        let want_g = if nonfinite {
            Err(ConfigError::NonFinite("gravity"))
        } else if x == 0.0 {
            Ok(())
        } else if x < 0.0 {
            Err(ConfigError::Negative("gravity"))
        } else {
            Err(ConfigError::OutOfRange("gravity"))
        };
        assert_eq!(r.with_gravity(x, 0.0).map(|_| ()), want_g);
        // Limits: every number positive.
        let pos = |name: &'static str| {
            if nonfinite {
                ConfigError::NonFinite(name)
            } else {
                ConfigError::NotPositive(name)
            }
        };
        assert_eq!(Limits::new(x, 60.0, None, 0.8), Err(pos("grade")));
        assert_eq!(Limits::new(6.3, x, None, 0.8), Err(pos("service_speed")));
        assert_eq!(
            Limits::new(6.3, 60.0, Some([x, 1.0]), 0.8),
            Err(pos("support_load_limit.a"))
        );
        assert_eq!(
            Limits::new(6.3, 60.0, Some([1.0, x]), 0.8),
            Err(pos("support_load_limit.b"))
        );
        assert_eq!(
            Limits::new(6.3, 60.0, None, x),
            Err(pos("warning_fraction"))
        );
        // Transfer planes.
        if nonfinite {
            assert_eq!(
                equivalent_planes(&[(x, Vec2::ZERO)], [0.0, 1.0]),
                Err(ConfigError::NonFinite("unbalance.z"))
            );
            assert_eq!(
                equivalent_planes(&[(0.5, Vec2::new(x, 0.0))], [0.0, 1.0]),
                Err(ConfigError::NonFinite("unbalance"))
            );
            assert_eq!(
                r.equivalent_in(0.0, x),
                Err(ConfigError::NonFinite("correction_plane_2"))
            );
        }
    }
    assert_eq!(
        Limits::new(6.3, 60.0, None, 1.5),
        Err(ConfigError::OutOfRange("warning_fraction"))
    );
    assert!(Limits::new(6.3, 60.0, None, 1.0).is_ok());
    // Capacity.
    assert_eq!(
        Rotor::<2>::new(1.0, 2.0, 0.0, 4.0, &[u, u, u], None).map(|_| ()),
        Err(ConfigError::Capacity("unbalances"))
    );
    assert!(Rotor::<0>::new(1.0, 2.0, 0.0, 4.0, &[], None).is_ok());
    // Overflow is OutOfRange, not inf.
    assert_eq!(
        rotor_with(1e308, 2.0, 0.0, 4.0, u, None).map(|_| ()),
        Err(ConfigError::OutOfRange("mass"))
    );
    let big = Unbalance::new(3.0, 1e308, 0.0);
    assert_eq!(
        Rotor::<2>::new(1.0, 2.0, 0.0, 4.0, &[big, big], None).map(|_| ()),
        Err(ConfigError::OutOfRange("unbalances"))
    );
    // Coincident supports at zero.
    assert_eq!(
        rotor_with(1.0, 2.0, 0.0, 0.0, u, None).map(|_| ()),
        Err(ConfigError::Inconsistent("support_b"))
    );
}

fn arb_f64() -> impl Strategy<Value = f64> {
    prop_oneof![
        Just(f64::NAN),
        Just(f64::INFINITY),
        Just(-0.0),
        Just(1e-310),
        -1e3..1e3f64,
        any::<f64>(),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(512))]

    #[test]
    fn runtime_is_total_for_any_speed(
        w in any::<f32>(),
        a in any::<f32>(),
        b in any::<f32>(),
        mass in 1.0..1e4f64,
        zu in -10.0..10.0f64,
        amount in 0.0..1.0f64,
        limit in 1.0..1e6f64,
        frac in 0.01..1.0f64,
    ) {
        let rotor = Rotor::<1>::new(mass, 1.0, 0.0, 4.0, &[Unbalance::new(zu, amount, 0.3)], None)
            .unwrap();
        let limits = Limits::new(6.3, 60.0, Some([limit, limit]), frac).unwrap();
        let mut mon = SupportAnalysis::new(&rotor, &limits).unwrap().monitor().unwrap();
        let accepted = mon.set_unbalance::<Libm>(a, b);
        prop_assert_eq!(accepted, a.is_finite() && b.is_finite() && a >= 0.0 && b >= 0.0);
        let st = mon.update(w);
        prop_assert_eq!(st.speed_valid, !w.is_nan());
        if !w.is_nan() {
            for k in 0..2 {
                prop_assert!(st.peak_load[k] >= st.min_load[k]);
                prop_assert!(st.load[k] != Level::Unknown);
            }
        }
        let m = mon.max_safe_speed().unwrap();
        prop_assert!(m >= 0.0);
        let _ = mon.set_unbalance::<Micromath>(a, b);
        let _ = mon.update(w);
    }

    #[test]
    fn constructors_never_panic(
        mass in arb_f64(), zm in arb_f64(), za in arb_f64(), zb in arb_f64(),
        z in arb_f64(), amount in arb_f64(), angle in arb_f64(),
        q in arb_f64(), from in arb_f64(), to in arb_f64(),
        g in arb_f64(), z1 in arb_f64(), z2 in arb_f64(),
    ) {
        let p = ProcessLoad { per_length: q, from, to, angle };
        if let Ok(r) = Rotor::<2>::new(mass, zm, za, zb, &[Unbalance::new(z, amount, angle)], Some(p)) {
            let [da, db] = r.support_unbalance();
            prop_assert!(da.is_finite() && db.is_finite());
            prop_assert!(r.static_load()[0].is_finite());
            if let Ok(rg) = r.with_gravity(g, angle) {
                prop_assert!(rg.static_load()[1].is_finite());
            }
            if let Ok([c1, c2]) = r.corrections(z1, z2) {
                prop_assert!(c1.is_finite() && c2.is_finite());
            }
            if let Ok(l) = Limits::new(g, zm, Some([q, amount]), 0.8) {
                // An analysis is an error or always gives a monitor whose loads at a finite
                // speed are numbers, never NaN.
                if let Ok(an) = SupportAnalysis::new(&r, &l) {
                    let st = an.monitor().unwrap().update(1.0);
                    prop_assert!(st.peak_load.iter().chain(&st.min_load).all(|x| !x.is_nan()));
                    prop_assert!(an.permissible.a.is_finite() && an.permissible.b.is_finite());
                }
            }
        }
    }
}

#[test]
fn results_beyond_f32_or_f64_are_typed_errors_not_infinities() {
    // Issue 16, finding 5: a grade of 1.7e308 passed `Limits::new` and gave an infinite
    // permissible unbalance; a process load of 2e48 N/m gave static loads beyond f32, so the
    // monitor reported an infinite peak and a NaN minimum for a valid speed.
    let (rotor, _) = auger(true);
    // G·m/ω beyond f64 (infinite), and finite in f64 but beyond f32.
    for service_speed in [1e-3, 60.0] {
        let huge_grade = Limits::new(1.7e308, service_speed, Some([8000.0, 8000.0]), 0.8).unwrap();
        assert_eq!(
            SupportAnalysis::new(&rotor, &huge_grade),
            Err(ConfigError::OutOfRange("grade"))
        );
    }
    // G·m/ω below f64's range: no permissible unbalance to judge against.
    let tiny_grade = Limits::new(1e-300, 1e10, None, 0.8).unwrap();
    assert_eq!(
        SupportAnalysis::new(&rotor, &tiny_grade),
        Err(ConfigError::OutOfRange("grade"))
    );
    // Finite in f64, zero in f32.
    let f32_zero = Limits::new(1e-40, 60.0, None, 0.8).unwrap();
    assert_eq!(
        SupportAnalysis::new(&rotor, &f32_zero),
        Err(ConfigError::OutOfRange("grade"))
    );
    let heavy = |per_length: f64| {
        Rotor::<4>::new(
            350.0,
            1.9,
            0.0,
            4.0,
            &[Unbalance::new(1.2, 2.0e-3, 0.5)],
            Some(ProcessLoad {
                per_length,
                from: 0.5,
                to: 3.5,
                angle: 4.712,
            }),
        )
        .unwrap()
    };
    let limits = Limits::new(6.3, 60.0, None, 0.8).unwrap();
    assert_eq!(
        SupportAnalysis::new(&heavy(2e48), &limits),
        Err(ConfigError::OutOfRange("process_load.per_length"))
    );
    // Just inside f32: accepted, and every load at a finite speed is a number.
    let an = SupportAnalysis::new(&heavy(1e37), &limits).unwrap();
    let st = an.monitor().unwrap().update(60.0);
    assert!(st.speed_valid);
    for k in 0..2 {
        assert!(
            st.peak_load[k].is_finite() && st.min_load[k].is_finite(),
            "{st:?}"
        );
    }
    let big_unbalance = Rotor::<4>::new(
        350.0,
        1.9,
        0.0,
        4.0,
        &[Unbalance::new(1.2, 1e39, 0.0)],
        None,
    )
    .unwrap();
    assert_eq!(
        SupportAnalysis::new(&big_unbalance, &limits),
        Err(ConfigError::OutOfRange("unbalances"))
    );
    let limit_beyond_f32 = Limits::new(6.3, 60.0, Some([1e39, 8000.0]), 0.8).unwrap();
    assert_eq!(
        SupportAnalysis::new(&rotor, &limit_beyond_f32),
        Err(ConfigError::OutOfRange("support_load_limit.a"))
    );
    // The monitor checks an analysis changed after it was built (its fields are public).
    let mut an = SupportAnalysis::new(&rotor, &limits).unwrap();
    an.load_limit = Some([8000.0, f64::INFINITY]);
    assert_eq!(
        an.monitor(),
        Err(ConfigError::OutOfRange("support_load_limit.b"))
    );
}
