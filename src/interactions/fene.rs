#![doc = include_str!("fene.md")]

use super::lammps::{bonded, num, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const K: usize = 0;
const R0: usize = 1;
const EPSILON: usize = 2;
const SIGMA: usize = 3;

static PARAMS: [ParamSpec; 4] = [
    ParamSpec::new("K", Dim::Stiffness, "stiffness of the attractive log term").non_negative(),
    ParamSpec::new("R0", Dim::Length, "maximum bond extension (E diverges as r → R0)").positive(),
    ParamSpec::new("epsilon", Dim::Energy, "depth of the WCA core (0 switches it off)").non_negative(),
    ParamSpec::new("sigma", Dim::Length, "size of the WCA core; it acts for r < 2^(1/6)·sigma").positive(),
];

/// 2^(1/3): the WCA core acts for r² < 2^(1/3)·σ² (LAMMPS `MY_CUBEROOT2`).
const CUBEROOT2: f64 = 1.259_921_049_894_873_2;

fn eval(p: &[f64], r: f64) -> Radial {
    let (k, r0) = (p[K], p[R0]);
    let x2 = (r / r0) * (r / r0);
    if x2 >= 1.0 || x2.is_nan() {
        // Bond stretched to or past its maximum extension: report a blow-up.
        return Radial { energy: f64::INFINITY, de_dr: f64::INFINITY, d2e_dr2: f64::INFINITY };
    }
    let logarg = 1.0 - x2;
    let mut out = Radial { energy: -0.5 * k * r0 * r0 * logarg.ln(), de_dr: k * r / logarg, d2e_dr2: k * (1.0 + x2) / (logarg * logarg) };
    let (eps, sigma) = (p[EPSILON], p[SIGMA]);
    if r * r < CUBEROOT2 * sigma * sigma {
        let s2 = sigma * sigma / (r * r);
        let s6 = s2 * s2 * s2;
        let s12 = s6 * s6;
        out.energy += 4.0 * eps * (s12 - s6) + eps;
        out.de_dr += 4.0 * eps * (-12.0 * s12 + 6.0 * s6) / r;
        out.d2e_dr2 += 4.0 * eps * (156.0 * s12 - 42.0 * s6) / (r * r);
    }
    out
}

/// LAMMPS `bond_style fene`: identical (K, R0, ε, σ).
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    bonded("fene", format!("{} {} {} {}", num(p[K]), num(p[R0]), num(p[EPSILON]), num(p[SIGMA])))
}

interaction!(
    Fene,
    "fene",
    Kind::Bond,
    "FENE bond with WCA core, E = −½K·R0²·ln(1 − (r/R0)²) + WCA (LAMMPS bond_style fene)",
    Law::Radial { eval, force: radial_force!(eval), range: |_| f64::INFINITY },
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use glam::DVec3;

    fn kremer_grest() -> Vec<f64> {
        params_of(&Fene, &[("K", 30.0), ("R0", 1.5), ("epsilon", 1.0), ("sigma", 1.0)])
    }

    fn pair(r: f64) -> [DVec3; 2] {
        let a = DVec3::new(0.3, -0.1, 0.7);
        [a, a + DVec3::new(2.0, -1.0, 2.0) / 3.0 * r]
    }

    #[test]
    fn shared_checks() {
        let p = kremer_grest();
        // Inside the WCA core, outside it, and close to R0 (avoid the core edge 2^(1/6)).
        for r in [0.85, 0.97, 1.05, 1.3, 1.45] {
            assert_all_checks(&Fene, &p, &pair(r), 1e-6, 1.0);
        }
        // Rest: dE/dr = 0 where the log attraction balances the WCA core (Kremer–Grest ≈ 0.9609).
        let mut lo = 0.9;
        let mut hi = 1.0;
        for _ in 0..200 {
            let mid = 0.5 * (lo + hi);
            if eval(&p, mid).de_dr < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let r_rest = 0.5 * (lo + hi);
        assert!((r_rest - 0.9609).abs() < 1e-3, "Kremer–Grest bond length {r_rest}");
        assert_zero_force_at_rest(&Fene, &p, &pair(r_rest), 100.0);
    }

    /// The LAMMPS `bond_fene.cpp` kernel, transcribed (valid where LAMMPS does not warn).
    fn lammps(k: f64, r0: f64, epsilon: f64, sigma: f64, rsq: f64) -> (f64, f64) {
        let r0sq = r0 * r0;
        let rlogarg = 1.0 - rsq / r0sq;
        assert!(rlogarg >= 0.1);
        let mut fbond = -k / rlogarg;
        let mut ebond = -0.5 * k * r0sq * rlogarg.ln();
        if rsq < CUBEROOT2 * sigma * sigma {
            let sr2 = sigma * sigma / rsq;
            let sr6 = sr2 * sr2 * sr2;
            fbond += 48.0 * epsilon * sr6 * (sr6 - 0.5) / rsq;
            ebond += 4.0 * epsilon * sr6 * (sr6 - 1.0) + epsilon;
        }
        (ebond, fbond)
    }

    #[test]
    fn matches_lammps_bond_fene() {
        let p = kremer_grest();
        for r in [0.8, 0.97, 1.1, 1.4] {
            let (e, fbond) = lammps(30.0, 1.5, 1.0, 1.0, r * r);
            let out = eval(&p, r);
            assert!((out.energy - e).abs() < 1e-12 * e.abs().max(1.0), "E({r}) {} vs LAMMPS {e}", out.energy);
            // LAMMPS fbond is F/r with F > 0 repulsive, so dE/dr = −fbond·r.
            assert!((out.de_dr + fbond * r).abs() < 1e-12 * (fbond * r).abs().max(1.0));
        }
        // A known number: K=30, R0=1.5, r=1: −½·30·2.25·ln(1 − 1/2.25) + 4(1 − 1) + 1.
        let e = eval(&p, 1.0).energy;
        assert!((e - (-33.75 * (1.25f64 / 2.25).ln() + 1.0)).abs() < 1e-12);
    }

    #[test]
    fn overstretched_bond_is_infinite_and_wca_is_off_beyond_its_cutoff() {
        let p = kremer_grest();
        for r in [1.5, 1.6, 10.0] {
            let out = eval(&p, r);
            assert!(out.energy == f64::INFINITY && out.de_dr == f64::INFINITY, "r = {r}: {out:?}");
        }
        let rc = 2f64.powf(1.0 / 6.0);
        let below = eval(&p, rc * (1.0 - 1e-9)).energy;
        let above = eval(&p, rc * (1.0 + 1e-9)).energy;
        assert!((below - above).abs() < 1e-6, "WCA core is not continuous at its cutoff");
        let no_core = params_of(&Fene, &[("K", 30.0), ("R0", 1.5), ("epsilon", 0.0), ("sigma", 1.0)]);
        assert_eq!(eval(&no_core, 1.2).energy, eval(&p, 1.2).energy);
    }
}
