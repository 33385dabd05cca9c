#![doc = include_str!("neo_hookean.md")]

use glam::{DMat3, DVec3};

use super::{elastic_tetra, lame, FourBody, Kind, Law, TetraRest, ELASTIC_PARAMS as PARAMS};

/// W = μ/2·(I₁ − 3) − μ·ln J + λ/2·(ln J)² and P = μ(F − F⁻ᵀ) + λ·ln J·F⁻ᵀ.
pub fn density(p: &[f64], f: DMat3, j: f64) -> (f64, DMat3) {
    let (mu, lambda) = lame(p);
    let (ln_j, f_inv_t) = (j.ln(), f.inverse().transpose());
    let i1 = f.x_axis.length_squared() + f.y_axis.length_squared() + f.z_axis.length_squared();
    let w = 0.5 * mu * (i1 - 3.0) - mu * ln_j + 0.5 * lambda * ln_j * ln_j;
    (w, mu * (f - f_inv_t) + lambda * ln_j * f_inv_t)
}

fn eval(p: &[f64], rest: &TetraRest, x: [DVec3; 4]) -> FourBody {
    elastic_tetra(rest, x, |f, j| density(p, f, j))
}

interaction!(
    NeoHookean,
    "neo_hookean",
    Kind::Tetra,
    "Compressible neo-Hookean solid W = μ/2(I₁ − 3) − μ ln J + λ/2 (ln J)² on linear tetrahedra, from E and ν",
    Law::Tetra(eval)
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        assert_volume_law_checks(&NeoHookean);
    }

    #[test]
    fn finite_uniaxial_stretch_follows_the_closed_form() {
        // F = diag(s, t, t) of the unit right tetrahedron (D_m = I, V_0 = 1/6):
        // f_1 = −V_0·P₁₁ x̂ with P₁₁ = μ(s − 1/s) + λ ln(st²)/s.
        let p = params_of(&NeoHookean, &[("e", 900.0), ("nu", 0.4)]);
        let (mu, lambda) = lame(&p);
        for (s, t) in [(1.3, 0.9), (0.8, 1.05), (2.0, 0.7)] {
            let out = eval(&p, &unit_tetra_rest(), stretched_unit_tetra(s, t));
            let (j, v0) = (s * t * t, 1.0 / 6.0);
            let p11 = mu * (s - 1.0 / s) + lambda * j.ln() / s;
            let w = 0.5 * mu * (s * s + 2.0 * t * t - 3.0) - mu * j.ln() + 0.5 * lambda * j.ln().powi(2);
            assert!((out.forces[1].x + v0 * p11).abs() < 1e-12 * p11.abs().max(1.0), "s = {s}: {} vs {}", out.forces[1].x, -v0 * p11);
            assert!((out.energy - v0 * w).abs() < 1e-12 * w.abs().max(1.0));
        }
    }

    #[test]
    fn an_inverted_element_has_no_finite_energy() {
        let p = params_of(&NeoHookean, &[("e", 900.0), ("nu", 0.4)]);
        for s in [0.0, -0.2] {
            let out = eval(&p, &unit_tetra_rest(), stretched_unit_tetra(s, 1.0));
            assert!(out.energy.is_nan() && out.forces.iter().all(|f| f.is_nan()), "{out:?}");
        }
    }
}
