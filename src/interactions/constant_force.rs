#![doc = include_str!("constant_force.md")]

use glam::DVec3;

use super::lammps::{fix, num, LammpsTerm, Translation};
use super::{Kind, Law, OneBody, ParamSpec};
use crate::units::Dim;

const FX: usize = 0;
const FY: usize = 1;
const FZ: usize = 2;

static PARAMS: [ParamSpec; 3] = [
    ParamSpec::new("fx", Dim::Force, "x component of the force on each particle").default(0.0),
    ParamSpec::new("fy", Dim::Force, "y component of the force on each particle").default(0.0),
    ParamSpec::new("fz", Dim::Force, "z component of the force on each particle").default(0.0),
];

fn eval(p: &[f64], x: DVec3) -> OneBody {
    let f = DVec3::new(p[FX], p[FY], p[FZ]);
    OneBody { energy: -f.dot(x), force: f }
}

/// LAMMPS `fix addforce`: identical; its scalar is −F·x on unwrapped x.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    fix(term, format!("addforce {} {} {}", num(p[FX]), num(p[FY]), num(p[FZ])))
}

interaction!(
    ConstantForce,
    "constant_force",
    Kind::External,
    "Constant pulling force F on each particle of a group, E = −F·x",
    Law::OneBody(eval),
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        let p = params_of(&ConstantForce, &[("fx", 5.0), ("fz", -2.0)]);
        for x in [DVec3::ZERO, DVec3::new(1.0, -2.0, 3.0), DVec3::new(-30.0, 12.0, 0.5)] {
            assert_all_checks(&ConstantForce, &p, &[x], 1e-4, 1.0);
        }
        // With the defaults (F = 0) every position is at rest.
        let none = params_of(&ConstantForce, &[]);
        assert_zero_force_at_rest(&ConstantForce, &none, &[DVec3::new(1.0, 2.0, 3.0)], 1.0);
    }

    #[test]
    fn force_is_constant_and_energy_is_its_work() {
        let p = params_of(&ConstantForce, &[("fx", 5.0), ("fy", 1.0), ("fz", -2.0)]);
        let a = eval(&p, DVec3::new(1.0, 0.0, 0.0));
        let b = eval(&p, DVec3::new(3.0, 1.0, 1.0));
        assert_eq!(a.force, DVec3::new(5.0, 1.0, -2.0));
        assert_eq!(a.force, b.force);
        // Moving by Δx lowers the energy by the work F·Δx = 10 + 1 − 2 = 9 pN·µm.
        assert!((a.energy - b.energy - 9.0).abs() < 1e-12);
    }
}
