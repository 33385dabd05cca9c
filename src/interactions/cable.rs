#![doc = include_str!("cable.md")]

use super::lammps::{lepton_bond, num, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const K: usize = 0;
const R0: usize = 1;
const TAU: usize = 2;

static PARAMS: [ParamSpec; 3] = [
    ParamSpec::new("k", Dim::Force, "axial stiffness EA: tension per unit strain").non_negative(),
    ParamSpec::new("r0", Dim::Length, "reference (unstrained) length").positive(),
    ParamSpec::new("tau", Dim::Dimensionless, "pre-strain added to the strain (tau > 0: pre-tensioned)").default(0.0),
];

fn eval(p: &[f64], r: f64) -> Radial {
    let (k, r0) = (p[K], p[R0]);
    let strain = (r - r0) / r0 + p[TAU];
    if strain > 0.0 {
        Radial { energy: 0.5 * k * r0 * strain * strain, de_dr: k * strain, d2e_dr2: k / r0 }
    } else {
        // Slack: a cable carries no compression.
        Radial::ZERO
    }
}

/// LAMMPS `bond_style lepton`: the exact expression in Δr = r − r0.
fn lammps(term: &LammpsTerm) -> Translation {
    let (k, r0, tau) = (term.params[K], term.params[R0], term.params[TAU]);
    lepton_bond(format!("0.5*{}*{}*max(0,r/{}+({}))^2", num(k), num(r0), num(r0), num(tau)), r0)
}

interaction!(
    Cable,
    "cable",
    Kind::Bond,
    "Tension-only cable with pre-strain, F = k·⟨(r − r0)/r0 + τ⟩₊",
    Law::Radial { eval, force: radial_force!(eval), range: |_| f64::INFINITY },
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use glam::DVec3;

    fn pair(r: f64) -> [DVec3; 2] {
        let a = DVec3::new(-0.2, 0.4, 0.1);
        [a, a + DVec3::new(1.0, -2.0, 2.0) / 3.0 * r]
    }

    #[test]
    fn shared_checks() {
        // Slack below r0(1 − tau) = 0.9 µm; avoid the kink there.
        let p = params_of(&Cable, &[("k", 50.0), ("r0", 1.0), ("tau", 0.1)]);
        for r in [0.5, 0.95, 1.0, 1.4] {
            assert_all_checks(&Cable, &p, &pair(r), 1e-6, 1.0);
        }
        for r in [0.3, 0.9, 0.899] {
            assert_zero_force_at_rest(&Cable, &p, &pair(r), 50.0);
        }
    }

    #[test]
    fn tension_only_with_pre_strain() {
        let p = params_of(&Cable, &[("k", 50.0), ("r0", 2.0), ("tau", 0.05)]);
        // Compressed or slack: nothing.
        assert_eq!(eval(&p, 1.0), Radial::ZERO);
        assert_eq!(eval(&p, 1.9), Radial::ZERO);
        // At r0 the pre-strain alone gives tension k·tau.
        let at_r0 = eval(&p, 2.0);
        assert!((at_r0.de_dr - 2.5).abs() < 1e-12);
        assert!((at_r0.energy - 0.5 * 50.0 * 2.0 * 0.05 * 0.05).abs() < 1e-15);
        // 10 % stretch + 5 % pre-strain: F = 50·0.15 = 7.5 pN; dE/dr = F.
        let out = eval(&p, 2.2);
        assert!((out.de_dr - 7.5).abs() < 1e-12);
        assert!((out.d2e_dr2 - 25.0).abs() < 1e-12);
        // Kink: one-sided curvature, the slack side at the kink itself.
        assert_eq!(eval(&p, 1.9).d2e_dr2, 0.0);
    }
}
