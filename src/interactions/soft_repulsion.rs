#![doc = include_str!("soft_repulsion.md")]

use super::lammps::{num, pair, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const K: usize = 0;
const SIGMA: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("k", Dim::Stiffness, "contact stiffness").non_negative(),
    ParamSpec::new("sigma", Dim::Length, "contact distance (typically the sum of the two radii); also the cutoff").positive(),
];

fn eval(p: &[f64], r: f64) -> Radial {
    let overlap = p[SIGMA] - r;
    if overlap > 0.0 {
        Radial { energy: 0.5 * p[K] * overlap * overlap, de_dr: -p[K] * overlap, d2e_dr2: p[K] }
    } else {
        Radial::ZERO
    }
}

/// LAMMPS `pair_style harmonic/cut` k(rc − r)²: k/2, rc = σ.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    pair("harmonic/cut", format!("{} {}", num(0.5 * p[K]), num(p[SIGMA])))
}

interaction!(
    SoftRepulsion,
    "soft_repulsion",
    Kind::Pair,
    "One-sided harmonic excluded volume E = ½k(σ − r)² for r < σ",
    Law::Radial { eval, force: radial_force!(eval), range: |p| p[SIGMA] },
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use crate::interactions::{KindLaw, RadialLaw};
    use glam::DVec3;

    fn pair(r: f64) -> [DVec3; 2] {
        let a = DVec3::new(1.0, 2.0, 3.0);
        [a, a + DVec3::new(2.0, 1.0, -2.0) / 3.0 * r]
    }

    #[test]
    fn shared_checks() {
        let p = params_of(&SoftRepulsion, &[("k", 100.0), ("sigma", 1.0)]);
        for r in [0.3, 0.8, 0.999, 1.2] {
            assert_all_checks(&SoftRepulsion, &p, &pair(r), 1e-6, 1.0);
        }
        for r in [1.0, 1.5, 3.0] {
            assert_zero_force_at_rest(&SoftRepulsion, &p, &pair(r), 100.0);
        }
    }

    #[test]
    fn repels_on_overlap_only_and_range_is_sigma() {
        let p = params_of(&SoftRepulsion, &[("k", 100.0), ("sigma", 1.0)]);
        let out = eval(&p, 0.9);
        assert!((out.energy - 0.5).abs() < 1e-12 && (out.de_dr + 10.0).abs() < 1e-12);
        assert_eq!(eval(&p, 1.0), Radial::ZERO);
        assert_eq!((RadialLaw::from_law(SoftRepulsion.law()).unwrap().range)(&p), 1.0);
        // At contact d²E/dr² takes the one-sided (separated) value.
        assert_eq!(eval(&p, 1.0).d2e_dr2, 0.0);
        assert_eq!(eval(&p, 1.0 - 1e-12).d2e_dr2, 100.0);
    }
}
