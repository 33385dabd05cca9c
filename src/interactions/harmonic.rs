#![doc = include_str!("harmonic.md")]

use super::lammps::{bonded, num, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const K: usize = 0;
const R0: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("k", Dim::Stiffness, "spring constant").non_negative(),
    ParamSpec::new("r0", Dim::Length, "rest length").non_negative(),
];

fn eval(p: &[f64], r: f64) -> Radial {
    let stretch = r - p[R0];
    Radial { energy: 0.5 * p[K] * stretch * stretch, de_dr: p[K] * stretch, d2e_dr2: p[K] }
}

/// LAMMPS `bond_style harmonic` K(r − r0)²: K = k/2.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    bonded("harmonic", format!("{} {}", num(0.5 * p[K]), num(p[R0])))
}

interaction!(
    Harmonic,
    "harmonic",
    Kind::Bond,
    "Hookean bond E = ½k(r − r0)²",
    Law::Radial { eval, force: radial_force!(eval), range: |_| f64::INFINITY },
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use glam::DVec3;

    #[test]
    fn shared_checks() {
        let p = params_of(&Harmonic, &[("k", 400.0), ("r0", 0.1)]);
        for r in [0.05, 0.1 + 1e-3, 0.3] {
            let x = [DVec3::new(0.1, -0.2, 0.3), DVec3::new(0.1, -0.2, 0.3) + DVec3::new(1.0, 2.0, -2.0) / 3.0 * r];
            assert_all_checks(&Harmonic, &p, &x, 1e-6, 1e-3);
        }
        assert_zero_force_at_rest(&Harmonic, &p, &[DVec3::ZERO, DVec3::new(0.0, 0.1, 0.0)], 40.0);
    }

    #[test]
    fn energy_is_half_k_stretch_squared() {
        let p = params_of(&Harmonic, &[("k", 2.0), ("r0", 1.0)]);
        let out = eval(&p, 1.5);
        assert_eq!(out.energy, 0.25);
        assert_eq!(out.de_dr, 1.0);
    }
}
