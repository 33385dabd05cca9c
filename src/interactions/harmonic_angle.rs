#![doc = include_str!("harmonic_angle.md")]

use glam::DVec3;

use super::lammps::{bonded, num, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, ThreeBody};
use crate::units::Dim;

const K: usize = 0;
const THETA0: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("k", Dim::AngularStiffness, "angular spring constant (E = ½k(θ − θ0)²)").non_negative(),
    ParamSpec::new("theta0", Dim::Degrees, "rest angle at the vertex j, in degrees").non_negative().at_most(180.0),
];

/// Floor on sin θ: keeps forces finite (not NaN) for exactly collinear input.
const SIN_FLOOR: f64 = 1e-12;

fn eval(p: &[f64], [ri, rj, rk]: [DVec3; 3]) -> ThreeBody {
    let u = ri - rj;
    let v = rk - rj;
    let (lu, lv) = (u.length(), v.length());
    let (uh, vh) = (u / lu, v / lv);
    let c = uh.dot(vh).clamp(-1.0, 1.0);
    // atan2 is accurate near 0 and π, where acos(c) loses half its digits.
    let theta = uh.cross(vh).length().atan2(c);
    let dtheta = theta - p[THETA0].to_radians();
    // dθ/dr_i = −e_i/|u| with e_i the unit vector ⟂ u in the plane, towards v:
    // e_i = (v̂ − c·û)/sin θ, and the same with i ↔ k.
    let pi = vh - c * uh;
    let pk = uh - c * vh;
    let ei = pi / pi.length().max(SIN_FLOOR);
    let ek = pk / pk.length().max(SIN_FLOOR);
    let torque = p[K] * dtheta; // −dE/dθ with the sign folded into the directions
    let fi = torque / lu * ei;
    let fk = torque / lv * ek;
    ThreeBody { energy: 0.5 * p[K] * dtheta * dtheta, forces: [fi, -fi - fk, fk] }
}

/// LAMMPS `angle_style harmonic` K(θ − θ0)²: K = k/2.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    bonded("harmonic", format!("{} {}", num(0.5 * p[K]), num(p[THETA0])))
}

interaction!(
    HarmonicAngle,
    "harmonic_angle",
    Kind::Angle,
    "Harmonic angle E = ½k(θ − θ0)², θ0 in degrees",
    Law::ThreeBody(eval),
    lammps = lammps
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    fn branch() -> Vec<f64> {
        params_of(&HarmonicAngle, &[("k", 2.0), ("theta0", 70.0)])
    }

    /// i at distance a along x, k at distance b at angle `deg` from x, around j.
    fn at_angle(deg: f64, a: f64, b: f64) -> [DVec3; 3] {
        let j = DVec3::new(0.4, -0.3, 0.2);
        let t = deg.to_radians();
        [j + a * DVec3::X, j, j + b * DVec3::new(t.cos(), t.sin(), 0.0)]
    }

    #[test]
    fn shared_checks() {
        let p = branch();
        for deg in [5.0, 45.0, 70.5, 120.0, 175.0] {
            assert_all_checks(&HarmonicAngle, &p, &at_angle(deg, 0.2, 0.35), 1e-7, 1e-2);
        }
        let j = DVec3::new(0.1, 0.2, 0.3);
        let skew = [j + DVec3::new(0.1, 0.2, -0.1), j, j + DVec3::new(-0.2, 0.1, 0.15)];
        assert_all_checks(&HarmonicAngle, &p, &skew, 1e-7, 1e-2);
        assert_zero_force_at_rest(&HarmonicAngle, &p, &at_angle(70.0, 0.2, 0.35), 10.0);
        let straight = params_of(&HarmonicAngle, &[("k", 2.0), ("theta0", 180.0)]);
        assert_all_checks(&HarmonicAngle, &straight, &at_angle(150.0, 0.2, 0.35), 1e-7, 1e-2);
        assert_zero_force_at_rest(&HarmonicAngle, &straight, &at_angle(180.0, 0.2, 0.35), 10.0);
    }

    #[test]
    fn energy_and_torque_at_a_known_angle() {
        let p = branch();
        let x = at_angle(90.0, 0.2, 0.35);
        let out = eval(&p, x);
        let d = 20f64.to_radians();
        assert!((out.energy - 0.5 * 2.0 * d * d).abs() < 1e-14);
        // Torque k·Δθ closes the angle: F_i = k·Δθ/|u| towards k (+y), F_k towards i (+x).
        assert!((out.forces[0] - DVec3::new(0.0, 2.0 * d / 0.2, 0.0)).length() < 1e-12);
        assert!((out.forces[2] - DVec3::new(2.0 * d / 0.35, 0.0, 0.0)).length() < 1e-12);
    }

    #[test]
    fn collinear_input_gives_finite_forces() {
        let p = branch();
        let j = DVec3::new(0.1, 0.2, 0.3);
        let dir = DVec3::new(1.0, 2.0, -2.0) / 3.0;
        for x in [[j - 0.2 * dir, j, j + 0.3 * dir], [j + 0.2 * dir, j, j + 0.3 * dir], [j + 0.2 * dir, j, j + 0.2 * dir]] {
            let out = eval(&p, x);
            assert!(out.energy.is_finite(), "{out:?}");
            assert!(out.forces.iter().all(|f| f.is_finite()), "{out:?}");
        }
    }
}
