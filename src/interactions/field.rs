#![doc = include_str!("field.md")]

use glam::DVec3;

use super::lammps::{LammpsStyle, LammpsTerm, Translation};
use super::{Kind, Law, OneBody, ParamSpec};
use crate::units::Dim;

const FX: usize = 0;
const FY: usize = 1;
const FZ: usize = 2;
const E: usize = 3;

static PARAMS: [ParamSpec; 4] = [
    ParamSpec::new("fx", Dim::Force, "x component of the force on each particle (an expression of x, y, z, t allowed)").default(0.0),
    ParamSpec::new("fy", Dim::Force, "y component of the force on each particle (an expression of x, y, z, t allowed)").default(0.0),
    ParamSpec::new("fz", Dim::Force, "z component of the force on each particle (an expression of x, y, z, t allowed)").default(0.0),
    ParamSpec::new("e", Dim::Energy, "energy of each particle in the field, for thermo and minimisation (an expression allowed)")
        .default(0.0),
];

fn eval(p: &[f64], _x: DVec3) -> OneBody {
    OneBody { energy: p[E], force: DVec3::new(p[FX], p[FY], p[FZ]) }
}

/// LAMMPS `fix addforce v_fx v_fy v_fz energy v_e`: one atom-style variable per parameter.
fn lammps(_term: &LammpsTerm) -> Translation {
    Some(Ok(LammpsStyle::ParameterVariables))
}

interaction!(
    Field,
    "field",
    Kind::External,
    "Force field F(x, y, z, t) given by expressions, with an optional energy e(x, y, z, t)",
    Law::OneBody(eval),
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        // With constant parameters the field is conservative only when F = 0
        // (a constant e is a level potential): the generic checks then hold.
        // Position-dependent fields: `a_field_given_by_expressions_is_minus_the_gradient_of_its_energy`.
        let p = params_of(&Field, &[("e", 2.5)]);
        for x in [DVec3::ZERO, DVec3::new(1.0, -2.0, 3.0)] {
            assert_all_checks(&Field, &p, &[x], 1e-4, 1.0);
        }
        assert_zero_force_at_rest(&Field, &p, &[DVec3::new(1.0, 2.0, 3.0)], 1.0);
    }

    /// The analytic reference (reference/NO_REFERENCE.md): the parameters
    /// given as expressions of a 3-D harmonic trap, F = −k·(x − c), E =
    /// ½k·|x − c|² with k = 3 and c = (1, −2, 0.5): F = −∇E by central
    /// differences and the closed form, at points inside and outside the trap.
    #[test]
    fn a_field_given_by_expressions_is_minus_the_gradient_of_its_energy() {
        use crate::expr::{parse, Ref};
        let texts = ["-3*(x - 1)", "-3*(y + 2)", "-3*(z - 0.5)", "1.5*((x - 1)^2 + (y + 2)^2 + (z - 0.5)^2)"];
        let exprs: Vec<_> = texts.iter().map(|t| parse(t).unwrap()).collect();
        let at = |x: DVec3| {
            let names = |r: Ref| match r {
                Ref::Name("x") => Ok(x.x),
                Ref::Name("y") => Ok(x.y),
                Ref::Name("z") => Ok(x.z),
                other => Err(format!("{other:?}")),
            };
            let p: Vec<f64> = exprs.iter().map(|e| e.eval(&mut names.clone()).unwrap()).collect();
            eval(&p, x)
        };
        let h = 1e-5;
        for x in [DVec3::new(1.0, -2.0, 0.5), DVec3::new(0.3, 0.4, -1.2), DVec3::new(-5.0, 2.0, 3.0)] {
            let out = at(x);
            let c = DVec3::new(1.0, -2.0, 0.5);
            assert!((out.force - (-3.0 * (x - c))).length() < 1e-12);
            assert!((out.energy - 1.5 * (x - c).length_squared()).abs() < 1e-12);
            for axis in 0..3 {
                let mut step = DVec3::ZERO;
                step[axis] = h;
                let gradient = (at(x + step).energy - at(x - step).energy) / (2.0 * h);
                assert!((out.force[axis] + gradient).abs() < 1e-7, "axis {axis} at {x}: F = {} vs −∇E = {}", out.force[axis], -gradient);
            }
        }
    }

    #[test]
    fn parameters_are_the_force_and_the_energy() {
        let p = params_of(&Field, &[("fx", 5.0), ("fy", 1.0), ("fz", -2.0), ("e", 0.5)]);
        let out = eval(&p, DVec3::new(7.0, 8.0, 9.0));
        assert_eq!(out, OneBody { energy: 0.5, force: DVec3::new(5.0, 1.0, -2.0) });
    }
}
