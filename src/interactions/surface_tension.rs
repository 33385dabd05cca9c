#![doc = include_str!("surface_tension.md")]

use glam::DVec3;

use super::{Kind, Law, ParamSpec, SurfaceGpu, SurfaceHessian, SurfaceMesh};
use crate::mesh::triangle_area_gradient;
use crate::units::Dim;

const GAMMA: usize = 0;

static PARAMS: [ParamSpec; 1] = [ParamSpec::new("gamma", Dim::Tension, "surface tension γ (energy per area)").non_negative()];

fn eval(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64 {
    let gamma = p[GAMMA];
    let mut area = 0.0;
    for (t, face) in mesh.triangles().iter().enumerate() {
        let (a, grad) = triangle_area_gradient(mesh.corners(t, x));
        area += a;
        for (node, g) in face.iter().zip(grad) {
            forces[*node as usize] -= gamma * g;
        }
    }
    gamma * area
}

/// The exact Hessian γ·Σ_t ∇²A_t, one stencil per face.
fn hessian(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], out: &mut SurfaceHessian) {
    for (t, face) in mesh.triangles().iter().enumerate() {
        out.push_face(*face, mesh.corners(t, x), p[GAMMA], 0.0);
    }
}

interaction!(
    SurfaceTension,
    "surface_tension",
    Kind::Body,
    "Surface tension of a closed body, E = γ·A",
    Law::Surface { eval, hessian, gpu: SurfaceGpu::PerFace }
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        for (_, mesh, x) in deformed_icospheres(&[0, 1, 2]) {
            let p = params_of(&SurfaceTension, &[("gamma", 665.0)]);
            assert_surface_checks(&SurfaceTension, &p, &mesh, &x, 1e-6, 1e-3);
        }
    }

    #[test]
    fn energy_is_tension_times_area_and_scales_as_the_square_of_size() {
        let (mesh, x) = deformed_icosphere(2, 1.0, 0.02);
        let p = params_of(&SurfaceTension, &[("gamma", 3.0)]);
        let (e1, f1) = evaluate_surface(SurfaceTension.law(), &p, &mesh, &x);
        assert!((e1 - 3.0 * mesh.area(&x)).abs() < 1e-13 * e1);
        // Uniform scaling by s: E → s²E, and by Euler's theorem Σ x·F = −2E.
        let virial: f64 = x.iter().zip(&f1).map(|(x, f)| x.dot(*f)).sum();
        assert!((virial + 2.0 * e1).abs() < 1e-12 * e1);
        let scaled: Vec<DVec3> = x.iter().map(|p| 1.7 * *p).collect();
        let (e2, _) = evaluate_surface(SurfaceTension.law(), &p, &mesh, &scaled);
        assert!((e2 - 1.7f64.powi(2) * e1).abs() < 1e-12 * e2);
    }

    #[test]
    fn stiffness_is_the_exact_hessian_per_face_projected() {
        for (level, mesh, x) in deformed_icospheres(&[0, 1]) {
            let p = params_of(&SurfaceTension, &[("gamma", 300.0)]);
            let lowest = assert_surface_hessian(&SurfaceTension, &p, &mesh, &x, |_| 0.0, 1e-4, 1e-5);
            // Area is concave in some directions: the projection has work to do.
            assert!(lowest < -1e-3, "level {level}: lowest relative eigenvalue {lowest:e}");
        }
    }
}
