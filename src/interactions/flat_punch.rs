#![doc = include_str!("flat_punch.md")]

use glam::DVec3;

use super::{Kind, Law, OneBody, ParamSpec};
use crate::units::Dim;

const X: usize = 0;
const Y: usize = 1;
const Z: usize = 2;
const NX: usize = 3;
const NY: usize = 4;
const NZ: usize = 5;
const A: usize = 6;
const K: usize = 7;

static PARAMS: [ParamSpec; 8] = [
    ParamSpec::new("x", Dim::Length, "x of the centre of the punch's face").default(0.0),
    ParamSpec::new("y", Dim::Length, "y of the centre of the punch's face").default(0.0),
    ParamSpec::new("z", Dim::Length, "z of the centre of the punch's face").default(0.0),
    ParamSpec::new("nx", Dim::Dimensionless, "x component of the direction the punch pushes (normalised internally)").default(0.0),
    ParamSpec::new("ny", Dim::Dimensionless, "y component of the direction the punch pushes (normalised internally)").default(0.0),
    ParamSpec::new("nz", Dim::Dimensionless, "z component of the direction the punch pushes (normalised internally)").default(0.0),
    ParamSpec::new("a", Dim::Length, "radius a of the punch's flat circular face").positive(),
    ParamSpec::new("k", Dim::Pressure, "punch stiffness K (force per length²: F = K·δ²)").non_negative(),
];

/// The unit push direction, or `None` for a zero (or non-finite) one.
fn unit_normal(p: &[f64]) -> Option<DVec3> {
    let n = DVec3::new(p[NX], p[NY], p[NZ]);
    let scale = n.abs().max_element();
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    Some((n / scale).normalize())
}

fn eval(p: &[f64], x: DVec3) -> OneBody {
    let Some(n) = unit_normal(p) else {
        return OneBody { energy: 0.0, force: DVec3::ZERO };
    };
    let d = x - DVec3::new(p[X], p[Y], p[Z]);
    let depth = -n.dot(d);
    let lateral = d + depth * n;
    if depth <= 0.0 || lateral.length_squared() >= p[A] * p[A] {
        return OneBody { energy: 0.0, force: DVec3::ZERO };
    }
    OneBody { energy: p[K] / 3.0 * depth * depth * depth, force: p[K] * depth * depth * n }
}

interaction!(
    FlatPunch,
    "flat_punch",
    Kind::External,
    "Rigid flat cylindrical punch of radius a: E = (K/3)δ³ for particles under its face",
    Law::OneBody(eval),
    validate = validate
);

fn validate(p: &[f64]) -> Result<(), String> {
    match unit_normal(p) {
        Some(_) => Ok(()),
        None => Err(format!("a nonzero push direction (nx, ny, nz), e.g. `nz -1` to press down, found ({}, {}, {})", p[NX], p[NY], p[NZ])),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks_away_from_the_rim() {
        let p = params_of(&FlatPunch, &[("x", 0.5), ("y", -0.2), ("z", 3.0), ("nx", 0.3), ("nz", -1.0), ("a", 2.0), ("k", 40.0)]);
        for x in [DVec3::new(0.1, 0.2, 3.5), DVec3::new(1.0, -1.0, 3.2), DVec3::new(-0.6, 0.1, 4.4)] {
            assert!(eval(&p, x).energy > 0.0, "{x} is under the face");
            assert_all_checks(&FlatPunch, &p, &[x], 1e-6, 1.0);
        }
        // Below the face, and beside the punch (beyond its radius): no force.
        assert_zero_force_at_rest(&FlatPunch, &p, &[DVec3::new(0.5, -0.2, 2.5)], 40.0);
        assert_zero_force_at_rest(&FlatPunch, &p, &[DVec3::new(3.5, -0.2, 3.5)], 40.0);
    }

    #[test]
    fn pushes_along_its_axis_by_k_depth_squared_within_its_radius() {
        let p = params_of(&FlatPunch, &[("z", 2.0), ("nz", -2.0), ("a", 1.0), ("k", 10.0)]);
        let under = eval(&p, DVec3::new(0.6, 0.7, 2.5));
        assert!((under.force - DVec3::new(0.0, 0.0, -2.5)).length() < 1e-12);
        assert!((under.energy - 10.0 / 3.0 * 0.125).abs() < 1e-12);
        // √(0.6² + 0.9²) > a: beside the punch.
        assert_eq!(eval(&p, DVec3::new(0.6, 0.9, 2.5)).force, DVec3::ZERO);
    }

    #[test]
    fn zero_direction_is_rejected_with_what_is_expected() {
        let err = FlatPunch.validate(&[0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 10.0]).unwrap_err();
        assert!(err.contains("nonzero push direction"), "{err}");
    }
}
