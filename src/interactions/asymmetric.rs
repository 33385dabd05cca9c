#![doc = include_str!("asymmetric.md")]

use super::lammps::{lepton_bond, num, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const K_TENSION: usize = 0;
const K_COMPRESSION: usize = 1;
const R0: usize = 2;

static PARAMS: [ParamSpec; 3] = [
    ParamSpec::new("k_tension", Dim::Stiffness, "spring constant when stretched (r > r0)").non_negative(),
    ParamSpec::new("k_compression", Dim::Stiffness, "spring constant when compressed (r <= r0)").non_negative(),
    ParamSpec::new("r0", Dim::Length, "rest length").non_negative(),
];

fn eval(p: &[f64], r: f64) -> Radial {
    let stretch = r - p[R0];
    let k = if stretch > 0.0 { p[K_TENSION] } else { p[K_COMPRESSION] };
    Radial { energy: 0.5 * k * stretch * stretch, de_dr: k * stretch, d2e_dr2: k }
}

/// LAMMPS `bond_style lepton`: the exact expression in Δr = r − r0.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    lepton_bond(format!("0.5*({}*step(r)+{}*(1-step(r)))*r^2", num(p[K_TENSION]), num(p[K_COMPRESSION])), p[R0])
}

interaction!(
    Asymmetric,
    "asymmetric",
    Kind::Bond,
    "Bilinear bond, stiffer in tension than compression: E = ½k_t(r − r0)² or ½k_c(r − r0)²",
    Law::Radial { eval, force: radial_force!(eval), range: |_| f64::INFINITY },
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use glam::DVec3;

    fn pair(r: f64) -> [DVec3; 2] {
        let a = DVec3::new(0.1, 0.2, 0.3);
        [a, a + DVec3::new(2.0, 2.0, -1.0) / 3.0 * r]
    }

    fn collagen() -> Vec<f64> {
        params_of(&Asymmetric, &[("k_tension", 1000.0), ("k_compression", 10.0), ("r0", 0.5)])
    }

    #[test]
    fn shared_checks() {
        let p = collagen();
        for r in [0.2, 0.5 - 1e-3, 0.5 + 1e-3, 0.9] {
            assert_all_checks(&Asymmetric, &p, &pair(r), 1e-6, 1.0);
        }
        assert_zero_force_at_rest(&Asymmetric, &p, &pair(0.5), 1000.0);
    }

    #[test]
    fn stiffer_in_tension_than_compression() {
        let p = collagen();
        let t = eval(&p, 0.6);
        let c = eval(&p, 0.4);
        assert!((t.de_dr - 100.0).abs() < 1e-9 && (c.de_dr + 1.0).abs() < 1e-12);
        assert!((t.energy / c.energy - 100.0).abs() < 1e-9);
        // Kink at r0: the branch r <= r0 gives the one-sided (compression) curvature.
        assert_eq!(eval(&p, 0.5).d2e_dr2, 10.0);
        assert_eq!(eval(&p, 0.5).energy, 0.0);
    }
}
