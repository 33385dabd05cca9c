#![doc = include_str!("lj.md")]

use super::lammps::{num, pair, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const EPSILON: usize = 0;
const SIGMA: usize = 1;
const RC: usize = 2;

static PARAMS: [ParamSpec; 3] = [
    ParamSpec::new("epsilon", Dim::Energy, "well depth").non_negative(),
    ParamSpec::new("sigma", Dim::Length, "distance at which E = 0").positive(),
    ParamSpec::new("rc", Dim::Length, "cutoff (E = 0 beyond; not shifted)").positive(),
];

/// (dE/dr)/r = 4ε[6(σ/r)⁶ − 12(σ/r)¹²]/r² of the Lennard-Jones energy,
/// from r² alone (no square root; shared with `wca`).
#[inline(always)]
pub(crate) fn lennard_jones_over_r(epsilon: f64, sigma: f64, r2: f64) -> f64 {
    let s2 = sigma * sigma / r2;
    let s6 = s2 * s2 * s2;
    let s12 = s6 * s6;
    4.0 * epsilon * (6.0 * s6 - 12.0 * s12) / r2
}

/// 4ε[(σ/r)¹² − (σ/r)⁶] and its first two derivatives (shared with `wca`).
pub(crate) fn lennard_jones(epsilon: f64, sigma: f64, r: f64) -> Radial {
    let s2 = sigma * sigma / (r * r);
    let s6 = s2 * s2 * s2;
    let s12 = s6 * s6;
    Radial {
        energy: 4.0 * epsilon * (s12 - s6),
        de_dr: lennard_jones_over_r(epsilon, sigma, r * r) * r,
        d2e_dr2: 4.0 * epsilon * (156.0 * s12 - 42.0 * s6) / (r * r),
    }
}

fn eval(p: &[f64], r: f64) -> Radial {
    if r < p[RC] {
        lennard_jones(p[EPSILON], p[SIGMA], r)
    } else {
        Radial::ZERO
    }
}

fn force(p: &[f64], r2: f64) -> f64 {
    if r2 < p[RC] * p[RC] {
        lennard_jones_over_r(p[EPSILON], p[SIGMA], r2)
    } else {
        0.0
    }
}

/// LAMMPS `pair_style lj/cut`: identical, not shifted.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    pair("lj/cut", format!("{} {} {}", num(p[EPSILON]), num(p[SIGMA]), num(p[RC])))
}

interaction!(
    Lj,
    "lj",
    Kind::Pair,
    "Lennard-Jones 12-6, cut at rc and not shifted (LAMMPS lj/cut)",
    Law::Radial { eval, force, range: |p| p[RC] },
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use glam::DVec3;

    fn pair(r: f64) -> [DVec3; 2] {
        let a = DVec3::new(-1.0, 0.5, 2.0);
        [a, a + DVec3::new(1.0, 2.0, 2.0) / 3.0 * r]
    }

    fn argon_like() -> Vec<f64> {
        params_of(&Lj, &[("epsilon", 1.0), ("sigma", 1.0), ("rc", 2.5)])
    }

    #[test]
    fn shared_checks() {
        let p = argon_like();
        // Avoid the inflection point (≈ 1.244σ, where d²E/dr² = 0) and the cutoff.
        for r in [0.9, 1.0, 1.15, 1.5, 2.2, 2.6] {
            assert_all_checks(&Lj, &p, &pair(r), 1e-6, 1.0);
        }
        let rmin = 2f64.powf(1.0 / 6.0);
        assert_zero_force_at_rest(&Lj, &p, &pair(rmin), 24.0);
    }

    #[test]
    fn minimum_is_minus_epsilon_at_two_to_the_sixth_sigma() {
        let p = params_of(&Lj, &[("epsilon", 0.5), ("sigma", 0.8), ("rc", 2.0)]);
        let rmin = 2f64.powf(1.0 / 6.0) * 0.8;
        let out = eval(&p, rmin);
        assert!((out.energy + 0.5).abs() < 1e-14, "{out:?}");
        assert!(out.de_dr.abs() < 1e-12);
        // Curvature at the minimum: 72ε/(2^(1/3)σ²) ≈ 57.15 ε/σ².
        assert!((out.d2e_dr2 - 72.0 * 0.5 / (2f64.powf(1.0 / 3.0) * 0.64)).abs() < 1e-10);
        assert_eq!(eval(&p, 0.8).energy, 0.0);
        // Unshifted: a jump of E(rc) at the cutoff (LAMMPS lj/cut without pair_modify shift).
        let e_rc = 4.0 * 0.5 * ((0.4f64).powi(12) - (0.4f64).powi(6));
        assert!((eval(&p, 2.0 - 1e-12).energy - e_rc).abs() < 1e-12);
        assert_eq!(eval(&p, 2.0), Radial::ZERO);
    }
}
