#![doc = include_str!("wca.md")]

use super::lammps::{num, LammpsStyle, LammpsTerm, Translation};
use super::lj::{lennard_jones, lennard_jones_over_r};
use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const EPSILON: usize = 0;
const SIGMA: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("epsilon", Dim::Energy, "energy scale of the repulsion").non_negative(),
    ParamSpec::new("sigma", Dim::Length, "particle diameter; the cutoff is 2^(1/6)·sigma").positive(),
];

/// 2^(1/6): the LJ minimum in units of σ.
const TWO_SIXTH: f64 = 1.122_462_048_309_373;

fn cutoff(p: &[f64]) -> f64 {
    TWO_SIXTH * p[SIGMA]
}

fn eval(p: &[f64], r: f64) -> Radial {
    if r < cutoff(p) {
        let mut out = lennard_jones(p[EPSILON], p[SIGMA], r);
        out.energy += p[EPSILON];
        out
    } else {
        Radial::ZERO
    }
}

fn force(p: &[f64], r2: f64) -> f64 {
    let rc = cutoff(p);
    if r2 < rc * rc {
        lennard_jones_over_r(p[EPSILON], p[SIGMA], r2)
    } else {
        0.0
    }
}

/// LAMMPS `pair_style lj/cut` at 2^(1/6)σ with `pair_modify shift yes`.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    let coeffs = format!("{} {} {}", num(p[EPSILON]), num(p[SIGMA]), num(cutoff(p)));
    Some(Ok(LammpsStyle::Pair { style: "lj/cut", coeffs, shift: true }))
}

interaction!(
    Wca,
    "wca",
    Kind::Pair,
    "Weeks–Chandler–Andersen repulsion: LJ cut at 2^(1/6)σ and shifted up by ε",
    Law::Radial { eval, force, range: cutoff },
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use glam::DVec3;

    fn pair(r: f64) -> [DVec3; 2] {
        let a = DVec3::new(0.0, 0.5, -2.0);
        [a, a + DVec3::new(-1.0, 2.0, 2.0) / 3.0 * r]
    }

    #[test]
    fn shared_checks() {
        let p = params_of(&Wca, &[("epsilon", 1.0), ("sigma", 1.0)]);
        for r in [0.85, 0.95, 1.05, 1.3] {
            assert_all_checks(&Wca, &p, &pair(r), 1e-6, 1.0);
        }
        for r in [TWO_SIXTH, 1.2, 5.0] {
            assert_zero_force_at_rest(&Wca, &p, &pair(r), 24.0);
        }
    }

    #[test]
    fn vanishes_continuously_at_the_cutoff() {
        let p = params_of(&Wca, &[("epsilon", 0.004), ("sigma", 0.05)]);
        let rc = TWO_SIXTH * 0.05;
        assert!((cutoff(&p) - rc).abs() < 1e-18);
        // E(rc⁻) → 0 and F(rc⁻) → 0: continuous energy and force.
        let just_inside = eval(&p, rc * (1.0 - 1e-10));
        assert!(just_inside.energy.abs() < 1e-14 && just_inside.de_dr.abs() < 1e-6, "{just_inside:?}");
        assert!((lennard_jones(0.004, 0.05, rc).energy + 0.004).abs() < 1e-15);
        assert_eq!(eval(&p, rc), Radial::ZERO);
        // E(σ) = ε.
        assert!((eval(&p, 0.05).energy - 0.004).abs() < 1e-15);
    }
}
