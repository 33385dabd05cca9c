#![doc = include_str!("linear_elastic.md")]

use glam::{DMat3, DVec3};

use super::{elastic_tetra, lame, FourBody, Kind, Law, TetraRest, ELASTIC_PARAMS as PARAMS};

/// W = μ·E:E + λ/2·(tr E)² of the Green strain E = ½(FᵀF − I), and P = F·(2μE + λ tr E·I).
pub fn density(p: &[f64], f: DMat3) -> (f64, DMat3) {
    let (mu, lambda) = lame(p);
    let green = 0.5 * (f.transpose() * f - DMat3::IDENTITY);
    let trace = green.x_axis.x + green.y_axis.y + green.z_axis.z;
    let ee = green.x_axis.length_squared() + green.y_axis.length_squared() + green.z_axis.length_squared();
    let w = mu * ee + 0.5 * lambda * trace * trace;
    (w, f * (2.0 * mu * green + lambda * trace * DMat3::IDENTITY))
}

fn eval(p: &[f64], rest: &TetraRest, x: [DVec3; 4]) -> FourBody {
    elastic_tetra(rest, x, |f, _| density(p, f))
}

interaction!(
    LinearElastic,
    "linear_elastic",
    Kind::Tetra,
    "Linear elastic solid (St Venant–Kirchhoff: Hooke's law in the Green strain, rotation invariant) on linear tetrahedra, from E and ν",
    Law::Tetra(eval)
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        assert_volume_law_checks(&LinearElastic);
    }

    #[test]
    fn finite_uniaxial_stretch_follows_the_closed_form() {
        // F = diag(s, t, t) of the unit right tetrahedron: E = diag(s² − 1, t² − 1, t² − 1)/2,
        // f_1 = −V_0·P₁₁ x̂ with P₁₁ = s·(2μE₁₁ + λ tr E).
        let p = params_of(&LinearElastic, &[("e", 900.0), ("nu", 0.4)]);
        let (mu, lambda) = lame(&p);
        for (s, t) in [(1.3, 0.9), (0.8, 1.05), (2.0, 0.7)] {
            let out = eval(&p, &unit_tetra_rest(), stretched_unit_tetra(s, t));
            let (e11, e22) = (0.5 * (s * s - 1.0), 0.5 * (t * t - 1.0));
            let trace = e11 + 2.0 * e22;
            let p11 = s * (2.0 * mu * e11 + lambda * trace);
            let w = mu * (e11 * e11 + 2.0 * e22 * e22) + 0.5 * lambda * trace * trace;
            let v0 = 1.0 / 6.0;
            assert!((out.forces[1].x + v0 * p11).abs() < 1e-12 * p11.abs().max(1.0), "s = {s}: {} vs {}", out.forces[1].x, -v0 * p11);
            assert!((out.energy - v0 * w).abs() < 1e-12 * w.abs().max(1.0));
        }
    }

    #[test]
    fn a_rotated_element_stores_no_energy() {
        // Rotation invariance is what plain small-strain elasticity lacks.
        let p = params_of(&LinearElastic, &[("e", 900.0), ("nu", 0.4)]);
        let r = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 1.1);
        let rest = unit_tetra_rest();
        let out = eval(&p, &rest, stretched_unit_tetra(1.0, 1.0).map(|x| r * x));
        assert!(out.energy.abs() < 1e-12 && out.forces.iter().all(|f| f.length() < 1e-10), "{out:?}");
    }
}
