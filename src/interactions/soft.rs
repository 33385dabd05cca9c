#![doc = include_str!("soft.md")]

use std::f64::consts::PI;

use super::lammps::{num, pair, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, Radial};
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
        let (s, c) = (w * r).sin_cos();
        Radial { energy: a * (1.0 + c), de_dr: -a * w * s, d2e_dr2: -a * w * w * c }
    } else {
        Radial::ZERO
    }
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
    Law::Radial { eval, force: radial_force!(eval), range: |p| p[RC] },
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
