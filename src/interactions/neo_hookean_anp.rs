#![doc = include_str!("neo_hookean_anp.md")]

use glam::{DMat3, DVec3};

use super::{elastic_tetra, lame, FourBody, Kind, Law, TetraRest, Volumetric, ELASTIC_PARAMS as PARAMS};

/// The bulk modulus κ = λ + 2μ/3 = E/(3(1 − 2ν)).
fn bulk(p: &[f64]) -> f64 {
    let (mu, lambda) = lame(p);
    lambda + 2.0 * mu / 3.0
}

/// The isochoric part W = μ/2·(J^{−2/3}·I₁ − 3), P = μ·J^{−2/3}·(F − I₁/3·F⁻ᵀ).
fn deviatoric(p: &[f64], rest: &TetraRest, x: [DVec3; 4]) -> FourBody {
    let (mu, _) = lame(p);
    elastic_tetra(rest, x, |f: DMat3, j: f64| {
        let i1 = f.x_axis.length_squared() + f.y_axis.length_squared() + f.z_axis.length_squared();
        let scale = mu * j.powf(-2.0 / 3.0);
        (0.5 * (scale * i1 - 3.0 * mu), scale * (f - (i1 / 3.0) * f.inverse().transpose()))
    })
}

/// U(J) = κ/4·(J² − 1 − 2 ln J), U′ = κ/2·(J − 1/J), U″ = κ/2·(1 + 1/J²).
pub fn volumetric(p: &[f64], j: f64) -> Volumetric {
    let kappa = bulk(p);
    Volumetric {
        energy: 0.25 * kappa * (j * j - 1.0 - 2.0 * j.ln()),
        pressure: 0.5 * kappa * (j - 1.0 / j),
        stiffness: 0.5 * kappa * (1.0 + 1.0 / (j * j)),
    }
}

interaction!(
    NeoHookeanAnp,
    "neo_hookean_anp",
    Kind::Tetra,
    "Nearly incompressible neo-Hookean solid on average-nodal-pressure tetrahedra (Bonet & Burton 1998): locking-free as ν → 0.5",
    Law::NodalTetra { deviatoric, volumetric }
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::nodal_tetra_alone;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        assert_volume_law_checks(&NeoHookeanAnp);
    }

    #[test]
    fn an_element_alone_follows_the_closed_form_of_a_uniaxial_stretch() {
        // F = diag(s, t, t) of the unit right tetrahedron: J = st², I₁ = s² + 2t²,
        // P₁₁ = μJ^{−2/3}(s − I₁/(3s)) + U′(J)·t², f_1 = −V_0·P₁₁ x̂.
        let p = params_of(&NeoHookeanAnp, &[("e", 900.0), ("nu", 0.45)]);
        let (mu, kappa) = (lame(&p).0, bulk(&p));
        for (s, t) in [(1.3, 0.9), (0.8, 1.05), (2.0, 0.7)] {
            let out = nodal_tetra_alone(deviatoric, volumetric, &p, &unit_tetra_rest(), stretched_unit_tetra(s, t));
            let (j, i1, v0) = (s * t * t, s * s + 2.0 * t * t, 1.0 / 6.0);
            let p11 = mu * j.powf(-2.0 / 3.0) * (s - i1 / (3.0 * s)) + 0.5 * kappa * (j - 1.0 / j) * t * t;
            let w = 0.5 * mu * (j.powf(-2.0 / 3.0) * i1 - 3.0) + 0.25 * kappa * (j * j - 1.0 - 2.0 * j.ln());
            assert!((out.forces[1].x + v0 * p11).abs() < 1e-12 * p11.abs().max(1.0), "s = {s}: {} vs {}", out.forces[1].x, -v0 * p11);
            assert!((out.energy - v0 * w).abs() < 1e-12 * w.abs().max(1.0));
        }
    }

    #[test]
    fn the_volumetric_energy_is_convex_and_has_a_barrier_at_zero_volume() {
        let p = params_of(&NeoHookeanAnp, &[("e", 900.0), ("nu", 0.45)]);
        let h = 1e-6;
        for j in [0.05, 0.5, 1.0, 1.7, 4.0] {
            let u = volumetric(&p, j);
            let (up, um) = (volumetric(&p, j + h), volumetric(&p, j - h));
            assert!(((up.energy - um.energy) / (2.0 * h) - u.pressure).abs() < 1e-6 * u.pressure.abs().max(bulk(&p)));
            assert!(((up.pressure - um.pressure) / (2.0 * h) - u.stiffness).abs() < 1e-6 * u.stiffness);
            assert!(u.stiffness > 0.0 && u.energy >= 0.0);
        }
        assert_eq!((volumetric(&p, 1.0).energy, volumetric(&p, 1.0).pressure), (0.0, 0.0));
        // The barrier: U grows as −κ/2·ln J and the pressure U′ without bound as J → 0.
        let (squeezed, flat) = (volumetric(&p, 1e-3), volumetric(&p, 1e-9));
        assert!(flat.energy > squeezed.energy && squeezed.energy > 3.0 * bulk(&p) && flat.pressure < -1e8 * bulk(&p));
    }
}
