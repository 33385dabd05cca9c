#![doc = include_str!("indenter.md")]

use glam::DVec3;

use super::lammps::{fix, num, LammpsTerm, Translation};
use super::{Kind, Law, OneBody, ParamSpec};
use crate::units::Dim;

const X: usize = 0;
const Y: usize = 1;
const Z: usize = 2;
const R: usize = 3;
const K: usize = 4;

static PARAMS: [ParamSpec; 5] = [
    ParamSpec::new("x", Dim::Length, "x of the sphere's centre").default(0.0),
    ParamSpec::new("y", Dim::Length, "y of the sphere's centre").default(0.0),
    ParamSpec::new("z", Dim::Length, "z of the sphere's centre").default(0.0),
    ParamSpec::new("r", Dim::Length, "radius R of the sphere").positive(),
    ParamSpec::new("k", Dim::Pressure, "indenter stiffness K (force per length²: F = K·δ²)").non_negative(),
];

fn eval(p: &[f64], x: DVec3) -> OneBody {
    let d = x - DVec3::new(p[X], p[Y], p[Z]);
    let r = d.length();
    let depth = p[R] - r;
    if depth <= 0.0 {
        return OneBody { energy: 0.0, force: DVec3::ZERO };
    }
    let energy = p[K] / 3.0 * depth * depth * depth;
    // At the centre every direction is equivalent: no force (E is at its maximum).
    let force = if r > 0.0 { p[K] * depth * depth / r * d } else { DVec3::ZERO };
    OneBody { energy, force }
}

/// LAMMPS `fix indent … sphere`: identical (K, centre, R). LAMMPS' force is
/// −K(r − R)² outward inside the sphere, its energy K(R − r)³/3.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    fix(term, format!("indent {} sphere {} {} {} {} units box", num(p[K]), num(p[X]), num(p[Y]), num(p[Z]), num(p[R])))
}

interaction!(
    Indenter,
    "indenter",
    Kind::External,
    "Rigid spherical indenter (LAMMPS fix indent sphere): E = (K/3)(R − r)³ inside the sphere",
    Law::OneBody(eval),
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        let p = params_of(&Indenter, &[("x", 0.5), ("y", -0.2), ("z", 3.0), ("r", 2.0), ("k", 40.0)]);
        for x in [DVec3::new(0.1, 0.2, 1.5), DVec3::new(1.0, -1.0, 2.2), DVec3::new(0.6, 0.1, 4.4)] {
            assert_all_checks(&Indenter, &p, &[x], 1e-6, 1.0);
        }
        assert_zero_force_at_rest(&Indenter, &p, &[DVec3::new(0.5, -0.2, 0.9)], 40.0);
        assert_zero_force_at_rest(&Indenter, &p, &[DVec3::new(3.0, 0.0, 0.0)], 40.0);
    }

    /// LAMMPS' form: F(r) = K(R − r)² pushing outward, E = K(R − r)³/3.
    #[test]
    fn force_is_k_depth_squared_along_the_radius() {
        let p = params_of(&Indenter, &[("z", 5.0), ("r", 2.0), ("k", 10.0)]);
        let out = eval(&p, DVec3::new(0.0, 0.0, 3.5));
        assert!((out.force - DVec3::new(0.0, 0.0, -10.0 * 0.25)).length() < 1e-12);
        assert!((out.energy - 10.0 / 3.0 * 0.125).abs() < 1e-12);
        assert_eq!(eval(&p, DVec3::new(0.0, 0.0, 5.0)), OneBody { energy: 80.0 / 3.0, force: DVec3::ZERO });
    }
}
