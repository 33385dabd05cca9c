#![doc = include_str!("soft.md")]

use std::f64::consts::{FRAC_PI_2, FRAC_PI_4, PI};

use super::lammps::{num, pair, LammpsTerm, Translation};
use super::{over_r, Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const A: usize = 0;
const RC: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("A", Dim::Energy, "energy at full overlap is 2A").non_negative(),
    ParamSpec::new("rc", Dim::Length, "cutoff").positive(),
];

fn eval(p: &[f64], r: f64) -> Radial {
    let (a, rc) = (p[A], p[RC]);
    if r < rc {
        let w = PI / rc;
        let (s, c) = (sin_to_pi(w * r), (w * r).cos());
        Radial { energy: a * (1.0 + c), de_dr: -a * w * s, d2e_dr2: -a * w * w * c }
    } else {
        Radial::ZERO
    }
}

/// (dE/dr)/r from r², for the pair loop: the `de_dr` of [`eval`], bit for
/// bit, without the cosine that only the energy needs.
fn force(p: &[f64], r2: f64) -> f64 {
    let (a, rc) = (p[A], p[RC]);
    let r = r2.sqrt();
    if r < rc {
        let w = PI / rc;
        over_r(-a * w * sin_to_pi(w * r), r)
    } else {
        0.0
    }
}

/// sin t for 0 ≤ t ≤ 5π/4 (used for t = πr/rc, r < rc), within 1.1 ulp of
/// the exact value: the largest error found against a 200-bit reference
/// (mpmath) at 3·10⁵ points of [0, π] is 0.77 ulp; against glibc's `sin` it
/// is within 1 ulp, with the same bits at 97 % of t (tested below).
///
/// The force needs sin(πr/rc) at every pair in range, and libm's `sin`,
/// which reduces any argument and guards the rounding mode, was 17 % of the
/// benchmark network's instructions. Here t ∈ [0, π] (rounding can push
/// πr/rc a few ulp past π, where the result is a tiny negative number), so
/// one subtraction reduces it to |u| ≤ π/4, exactly (Sterbenz's lemma:
/// t − π/2 is exact for t ≥ π/4, π − t for t ≥ π/2), and the tail of π
/// (`FRAC_PI_2_LO`, `PI_LO`) enters as a first-order correction; then sin u
/// or cos u is a Taylor polynomial.
///
/// The bound, from a first-order rounding-error analysis: the Taylor
/// remainders at |u| ≤ π/4, |u|¹⁹/19! and |u|¹⁸/18!, are below 1.1·10⁻¹⁹ and
/// 3·10⁻¹⁸ of the result; the polynomial's tail is at most u²/6 ≈ 0.103 of
/// the result for sin (z²/24 ≈ 0.016 for cos) and carries about five
/// roundings of its own size, ≤ 0.58 ulp of the result; for cos the rounding
/// of 1 − z/2 is recovered exactly (as in fdlibm's `__kernel_cos`, Sun
/// Microsystems 1993) and that of z costs ≤ 0.31 ulp, ≤ 0.38 ulp in all;
/// the final addition adds 0.5 ulp.
#[inline(always)]
fn sin_to_pi(t: f64) -> f64 {
    /// π/2 − `FRAC_PI_2` and π − `PI`, rounded.
    const FRAC_PI_2_LO: f64 = 6.123233995736766e-17;
    const PI_LO: f64 = 1.2246467991473532e-16;
    if t <= FRAC_PI_4 {
        sin_near_zero(t, 0.0)
    } else if t < 3.0 * FRAC_PI_4 {
        // sin t = cos(t − π/2), and t − π/2 = (t − FRAC_PI_2) − FRAC_PI_2_LO.
        cos_near_zero(t - FRAC_PI_2, -FRAC_PI_2_LO)
    } else {
        // sin t = sin(π − t), and π − t = (PI − t) + PI_LO.
        sin_near_zero(PI - t, PI_LO)
    }
}

/// sin(u + lo) for |u| ≤ π/4 and |lo| ≤ 2⁻⁵²: u − u³/3! + … + u¹⁷/17!
/// (1/n! rounded), plus lo·cos u to first order.
#[inline(always)]
fn sin_near_zero(u: f64, lo: f64) -> f64 {
    const S: [f64; 8] = [
        -0.16666666666666666,
        0.008333333333333333,
        -0.0001984126984126984,
        2.7557319223985893e-06,
        -2.505210838544172e-08,
        1.6059043836821613e-10,
        -7.647163731819816e-13,
        2.8114572543455206e-15,
    ];
    let z = u * u;
    u + (u * z * horner(&S, z) + lo * (1.0 - 0.5 * z))
}

/// cos(v + lo) for |v| ≤ π/4 and |lo| ≤ 2⁻⁵²: 1 − v²/2 + v⁴/4! − … + v¹⁶/16! (1/n! rounded),
/// minus lo·sin v to first order; 1 − v²/2 is rounded once and its rounding
/// error added back to the tail.
#[inline(always)]
fn cos_near_zero(v: f64, lo: f64) -> f64 {
    const K: [f64; 7] = [
        0.041666666666666664,
        -0.001388888888888889,
        2.48015873015873e-05,
        -2.755731922398589e-07,
        2.08767569878681e-09,
        -1.1470745597729725e-11,
        4.779477332387385e-14,
    ];
    let z = v * v;
    let half = 0.5 * z;
    let w = 1.0 - half;
    w + (((1.0 - w) - half) + (z * z * horner(&K, z) - v * lo))
}

/// c₀ + z·(c₁ + z·(… + z·c_last)).
#[inline(always)]
fn horner(c: &[f64], z: f64) -> f64 {
    c.iter().rev().skip(1).fold(c[c.len() - 1], |p, &ck| p * z + ck)
}

/// LAMMPS `pair_style soft`: identical.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    pair("soft", format!("{} {}", num(p[A]), num(p[RC])))
}

interaction!(
    Soft,
    "soft",
    Kind::Pair,
    "Cosine soft repulsion E = A[1 + cos(πr/rc)] (LAMMPS pair_style soft)",
    Law::Radial { eval, force, range: |p| p[RC] },
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use glam::DVec3;

    fn pair(r: f64) -> [DVec3; 2] {
        let a = DVec3::new(0.2, 0.2, 0.2);
        [a, a + DVec3::new(2.0, -2.0, 1.0) / 3.0 * r]
    }

    #[test]
    fn shared_checks() {
        let p = params_of(&Soft, &[("A", 10.0), ("rc", 1.0)]);
        // Avoid r = rc/2, where d²E/dr² = 0, and the cutoff.
        for r in [0.1, 0.3, 0.7, 0.95, 1.5] {
            assert_all_checks(&Soft, &p, &pair(r), 1e-6, 1.0);
        }
        assert_zero_force_at_rest(&Soft, &p, &pair(1.0), 40.0);
        assert_zero_force_at_rest(&Soft, &p, &pair(2.0), 40.0);
    }

    /// The polynomial sine against glibc's `sin` over everything it is used
    /// for, [0, π] and a few ulp past π, with the branch edges ulp by ulp:
    /// within 1 ulp everywhere and the same bits almost everywhere (a wrong
    /// coefficient, a lost correction term or an inexact reduction fails).
    #[test]
    fn sine_is_within_one_ulp_of_libm_from_zero_to_pi() {
        let ulp = |x: f64| if x == 0.0 { f64::from_bits(1) } else { f64::from_bits(x.abs().to_bits() + 1) - x.abs() };
        let next = |t: f64, k: i64| f64::from_bits((t.to_bits() as i64 + k) as u64);
        let n = 1_000_000;
        let grid = (0..=n).map(|i| PI * (1.0 + 2e-16) * i as f64 / n as f64);
        let edges = [FRAC_PI_4, 3.0 * FRAC_PI_4, FRAC_PI_2, PI].into_iter().flat_map(|t| (-64..=64).map(move |k| next(t, k)));
        let tiny = [f64::from_bits(1), 1e-300, 1e-160, 1e-20, 1e-8];
        let (mut same, mut total) = (0, 0);
        for t in grid.chain(edges).chain(tiny) {
            let (got, libm) = (sin_to_pi(t), t.sin());
            assert!((got - libm).abs() <= ulp(libm), "sin({t:e}): {got:e}, libm {libm:e}");
            same += usize::from(got.to_bits() == libm.to_bits());
            total += 1;
        }
        assert!(same as f64 > 0.95 * total as f64, "the same bits as libm at only {same} of {total} points");
    }

    /// The pair loop's force is eval's dE/dr over r, bit for bit, in range and beyond.
    #[test]
    fn force_is_the_bits_of_eval() {
        let p = params_of(&Soft, &[("A", 3.0), ("rc", 1.5)]);
        for k in 0..=2000 {
            let r2 = (1.6 * k as f64 / 2000.0).powi(2);
            let r = r2.sqrt();
            assert_eq!(force(&p, r2).to_bits(), over_r(eval(&p, r).de_dr, r).to_bits(), "r = {r}");
        }
    }

    #[test]
    fn matches_lammps_pair_soft() {
        let p = params_of(&Soft, &[("A", 10.0), ("rc", 2.0)]);
        assert!((eval(&p, 1e-9).energy - 20.0).abs() < 1e-9); // 2A at full overlap
        assert!((eval(&p, 1.0).energy - 10.0).abs() < 1e-12); // A at rc/2
                                                              // LAMMPS: fpair = A·π/rc·sin(πr/rc)/r (F/r, repulsive).
        let r = 0.6;
        let fpair = 10.0 * PI / 2.0 * (PI * r / 2.0).sin() / r;
        assert!((eval(&p, r).de_dr + fpair * r).abs() < 1e-12);
        // Continuous energy and force at the cutoff.
        let edge = eval(&p, 2.0 * (1.0 - 1e-9));
        assert!(edge.energy.abs() < 1e-15 && edge.de_dr.abs() < 1e-7);
        assert_eq!(eval(&p, 2.0), Radial::ZERO);
    }
}
