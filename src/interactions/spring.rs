#![doc = include_str!("spring.md")]

use super::lammps::{lepton_bond, num, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const K: usize = 0;
const R0: usize = 1;
const TAU: usize = 2;

static PARAMS: [ParamSpec; 3] = [
    ParamSpec::new("k", Dim::Force, "axial stiffness EA: force per unit strain").non_negative(),
    ParamSpec::new("r0", Dim::Length, "reference (unstrained) length").positive(),
    ParamSpec::new("tau", Dim::Dimensionless, "pre-strain added to the strain (tau > 0: pre-tensioned)").default(0.0),
];

fn eval(p: &[f64], r: f64) -> Radial {
    let (k, r0) = (p[K], p[R0]);
    let strain = (r - r0) / r0 + p[TAU];
    Radial { energy: 0.5 * k * r0 * strain * strain, de_dr: k * strain, d2e_dr2: k / r0 }
}

/// LAMMPS `bond_style lepton`: the exact expression in Δr = r − r0.
fn lammps(term: &LammpsTerm) -> Translation {
    let (k, r0, tau) = (term.params[K], term.params[R0], term.params[TAU]);
    lepton_bond(format!("0.5*{}*{}*(r/{}+({}))^2", num(k), num(r0), num(r0), num(tau)), r0)
}

interaction!(
    Spring,
    "spring",
    Kind::Bond,
    "Strain spring with pre-strain, F = k·((r − r0)/r0 + τ) in tension and compression",
    Law::Radial { eval, force: radial_force!(eval), range: |_| f64::INFINITY },
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use glam::DVec3;

    fn pair(r: f64) -> [DVec3; 2] {
        let a = DVec3::new(0.5, 0.4, -0.3);
        [a, a + DVec3::new(-2.0, 1.0, 2.0) / 3.0 * r]
    }

    #[test]
    fn shared_checks() {
        let p = params_of(&Spring, &[("k", 50.0), ("r0", 1.0), ("tau", -0.2)]);
        for r in [0.4, 1.0, 1.2 + 1e-3, 1.7] {
            assert_all_checks(&Spring, &p, &pair(r), 1e-6, 1.0);
        }
        // Rest at r0(1 − tau) = 1.2.
        assert_zero_force_at_rest(&Spring, &p, &pair(1.2), 50.0);
    }

    #[test]
    fn pushes_in_compression_and_pulls_in_tension() {
        let p = params_of(&Spring, &[("k", 50.0), ("r0", 2.0), ("tau", 0.05)]);
        // 10 % compression with 5 % pre-strain: strain = −0.1 + 0.05 = −0.05, pushes with 2.5 pN.
        let c = eval(&p, 1.8);
        assert!((c.de_dr + 2.5).abs() < 1e-12);
        assert!((c.energy - 0.5 * 50.0 * 2.0 * 0.0025).abs() < 1e-14);
        // Tension side matches the cable exactly.
        let t = eval(&p, 2.2);
        assert!((t.de_dr - 7.5).abs() < 1e-12 && (t.d2e_dr2 - 25.0).abs() < 1e-12);
        // Without pre-strain it is a Hookean spring of constant k/r0.
        let h = params_of(&Spring, &[("k", 50.0), ("r0", 2.0)]);
        assert!((eval(&h, 2.3).energy - 0.5 * 25.0 * 0.09).abs() < 1e-12);
    }
}
