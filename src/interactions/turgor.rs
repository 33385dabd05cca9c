#![doc = include_str!("turgor.md")]

use glam::DVec3;

use super::{Kind, Law, ParamSpec, SurfaceGpu, SurfaceHessian, SurfaceMesh};
use crate::hessian::RankOne;
use crate::units::Dim;

const K: usize = 0;
const DP0: usize = 1;
const V0: usize = 2;

static PARAMS: [ParamSpec; 3] = [
    ParamSpec::new("k", Dim::Pressure, "bulk modulus K of the cytoplasm: the pressure rises by K per unit relative compression")
        .non_negative(),
    ParamSpec::new("dp0", Dim::Pressure, "pressure difference ΔP0 across the surface at the rest volume (inside minus outside)")
        .default(0.0),
    ParamSpec::new("v0", Dim::Volume, "rest volume V0").positive(),
];

/// The pressure ΔP(V) = ΔP0 + K·(V0 − V)/V0 and the energy E(V) whose −dE/dV it is.
pub fn pressure_and_energy(p: &[f64], volume: f64) -> (f64, f64) {
    let dv = volume - p[V0];
    (p[DP0] - p[K] * dv / p[V0], -p[DP0] * dv + 0.5 * p[K] * dv * dv / p[V0])
}

fn eval(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64 {
    let mut grad = vec![DVec3::ZERO; x.len()];
    let volume = mesh.volume_gradient(x, &mut grad);
    let (pressure, energy) = pressure_and_energy(p, volume);
    for (f, g) in forces.iter_mut().zip(&grad) {
        *f += pressure * *g;
    }
    energy
}

/// The Gauss–Newton model E″(V)·∇V∇Vᵀ = (K/V0)·∇V∇Vᵀ (see the docs: the
/// pressure part −ΔP·∇²V is left out).
fn hessian(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], out: &mut SurfaceHessian) {
    if p[K] > 0.0 {
        let mut gradient = vec![DVec3::ZERO; x.len()];
        mesh.volume_gradient(x, &mut gradient);
        out.rank_one.push(RankOne { weight: p[K] / p[V0], gradient });
    }
}

interaction!(
    Turgor,
    "turgor",
    Kind::Body,
    "Pressure of the enclosed volume, ΔP = ΔP0 + K(V0 − V)/V0, E = −ΔP0(V − V0) + K(V − V0)²/(2V0)",
    Law::Surface { eval, hessian, gpu: SurfaceGpu::PerFace }
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        for (_, mesh, x) in deformed_icospheres(&[0, 1, 2]) {
            let v = mesh.volume(&x);
            for (k, dp0, v0) in [(1000.0, 0.0, 1.1 * v), (500.0, 40.0, 0.9 * v), (0.0, 133.0, v)] {
                let p = params_of(&Turgor, &[("k", k), ("dp0", dp0), ("v0", v0)]);
                assert_surface_checks(&Turgor, &p, &mesh, &x, 1e-6, 1e-3);
            }
            // At V = V0 with ΔP0 = 0 nothing pushes.
            let p = params_of(&Turgor, &[("k", 1000.0), ("v0", v)]);
            assert_surface_zero_force_at_rest(&Turgor, &p, &mesh, &x, 1000.0);
        }
    }

    #[test]
    fn force_is_the_pressure_on_a_third_of_each_face() {
        // The rule of turgor.md: ΔP·(A_t n̂_t)/3 on each corner of each face.
        let (mesh, x) = deformed_icosphere(2, 2.0, 0.03);
        let v = mesh.volume(&x);
        let p = params_of(&Turgor, &[("k", 700.0), ("dp0", 20.0), ("v0", 1.2 * v)]);
        let (energy, forces) = evaluate_surface(Turgor.law(), &p, &mesh, &x);
        let pressure = 20.0 + 700.0 * (1.2 * v - v) / (1.2 * v);
        let mut expected = vec![DVec3::ZERO; x.len()];
        for t in 0..mesh.triangles().len() {
            let [a, b, c] = mesh.corners(t, &x);
            for node in mesh.triangles()[t] {
                expected[node as usize] += pressure * 0.5 * (b - a).cross(c - a) / 3.0;
            }
        }
        for (f, e) in forces.iter().zip(&expected) {
            assert!((*f - *e).length() < 1e-12 * pressure, "{f} vs {e}");
        }
        let dv = v - 1.2 * v;
        assert!((energy - (-20.0 * dv + 350.0 * dv * dv / (1.2 * v))).abs() < 1e-12 * energy.abs());
    }

    #[test]
    fn energy_is_minus_the_integral_of_the_pressure() {
        // E(V) − E(V0) = −∫ ΔP dV, checked by quadrature over a wide range.
        let p = [800.0, 35.0, 2.0];
        for v in [0.5, 1.7, 2.0, 3.1] {
            let n = 2000;
            let h = (v - 2.0) / n as f64;
            let integral: f64 = (0..n).map(|k| pressure_and_energy(&p, 2.0 + (k as f64 + 0.5) * h).0 * h).sum();
            let e = pressure_and_energy(&p, v).1;
            assert!((e + integral).abs() < 1e-9 * (1.0 + e.abs()), "V = {v}: E = {e}, −∫ΔP dV = {}", -integral);
        }
    }

    #[test]
    fn stiffness_is_the_gauss_newton_volume_term() {
        let (mesh, x) = deformed_icosphere(1, 1.5, 0.05);
        let v = mesh.volume(&x);
        // At V = V0 with ΔP0 = 0 there is no pressure: (K/V0)·∇V∇Vᵀ is the exact Hessian.
        let p = params_of(&Turgor, &[("k", 1000.0), ("v0", v)]);
        assert_surface_hessian(&Turgor, &p, &mesh, &x, |_| 0.0, 1e-4, 1e-5);
        // Under pressure it leaves out −ΔP·∇²V, and only that.
        let p = params_of(&Turgor, &[("k", 700.0), ("dp0", 40.0), ("v0", 1.2 * v)]);
        let (pressure, _) = pressure_and_energy(&p, v);
        assert_surface_hessian(&Turgor, &p, &mesh, &x, |y| -pressure * mesh.volume(y), 1e-4, 1e-5);
    }
}
