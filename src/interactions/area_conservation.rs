#![doc = include_str!("area_conservation.md")]

use glam::DVec3;

use super::{Kind, Law, ParamSpec, SurfaceGpu, SurfaceHessian, SurfaceMesh};
use crate::hessian::RankOne;
use crate::mesh::{triangle_area, triangle_area_gradient};
use crate::units::Dim;

const KA: usize = 0;
const KL: usize = 1;
const A0: usize = 2;

static PARAMS: [ParamSpec; 3] = [
    ParamSpec::new("ka", Dim::Tension, "global area modulus k_a: E = ½k_a(A − A0)²/A0").non_negative().default(0.0),
    ParamSpec::new("kl", Dim::Tension, "local (per face) area modulus k_l: E = ½k_l Σ(A_t − a0)²/a0, a0 = A0/N_faces")
        .non_negative()
        .default(0.0),
    ParamSpec::new("a0", Dim::Area, "rest area A0 of the whole body").positive(),
];

fn validate(p: &[f64]) -> Result<(), String> {
    if p[KA] > 0.0 || p[KL] > 0.0 {
        Ok(())
    } else {
        Err("`ka` > 0 or `kl` > 0 (with both zero the term does nothing)".into())
    }
}

/// dE/dA_t = k_a(A − A0)/A0 + k_l(A_t − a0)/a0 of a face of area `face`
/// on a body of area `area` with `faces` faces.
fn face_tension(p: &[f64], area: f64, face: f64, faces: usize) -> f64 {
    let a0_face = p[A0] / faces as f64;
    p[KA] * (area - p[A0]) / p[A0] + p[KL] * (face - a0_face) / a0_face
}

fn eval(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64 {
    let (ka, kl, a0) = (p[KA], p[KL], p[A0]);
    let faces = mesh.triangles().len();
    let a0_face = a0 / faces as f64;
    let mut areas = Vec::with_capacity(faces);
    let mut area = 0.0;
    let mut local_energy = 0.0;
    for t in 0..faces {
        let (a, grad) = triangle_area_gradient(mesh.corners(t, x));
        area += a;
        local_energy += 0.5 * kl * (a - a0_face).powi(2) / a0_face;
        areas.push((a, grad));
    }
    for (face, (a, grad)) in mesh.triangles().iter().zip(&areas) {
        let de_da = face_tension(p, area, *a, faces);
        for (node, g) in face.iter().zip(grad) {
            forces[*node as usize] -= de_da * *g;
        }
    }
    0.5 * ka * (area - a0).powi(2) / a0 + local_energy
}

/// The exact Hessian: per face c·∇A_t∇A_tᵀ + τ_t·∇²A_t with τ_t = dE/dA_t
/// and c = k_l/a0, plus the global term's rank-one (k_a/A0)·∇A∇Aᵀ.
fn hessian(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], out: &mut SurfaceHessian) {
    let faces = mesh.triangles().len();
    let areas: Vec<f64> = (0..faces).map(|t| triangle_area(mesh.corners(t, x))).collect();
    let area: f64 = areas.iter().sum();
    let mut gradient = vec![DVec3::ZERO; x.len()];
    for (t, face) in mesh.triangles().iter().enumerate() {
        let corners = mesh.corners(t, x);
        out.push_face(*face, corners, face_tension(p, area, areas[t], faces), p[KL] * faces as f64 / p[A0]);
        for (node, g) in face.iter().zip(triangle_area_gradient(corners).1) {
            gradient[*node as usize] += g;
        }
    }
    if p[KA] > 0.0 {
        out.rank_one.push(RankOne { weight: p[KA] / p[A0], gradient });
    }
}

interaction!(
    AreaConservation,
    "area_conservation",
    Kind::Body,
    "Area elasticity of a closed body, global ½k_a(A − A0)²/A0 and per face ½k_l Σ(A_t − A0/N)²/(A0/N)",
    Law::Surface { eval, hessian, gpu: SurfaceGpu::PerFace },
    validate = validate
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        for (_, mesh, x) in deformed_icospheres(&[0, 1, 2]) {
            let area = mesh.area(&x);
            for (ka, kl, a0) in [(100.0, 0.0, 0.9 * area), (0.0, 50.0, 1.1 * area), (80.0, 30.0, area)] {
                let p = params_of(&AreaConservation, &[("ka", ka), ("kl", kl), ("a0", a0)]);
                assert_surface_checks(&AreaConservation, &p, &mesh, &x, 1e-6, 1e-3);
            }
            // The global term is at rest at A = A0 whatever the face areas.
            let p = params_of(&AreaConservation, &[("ka", 100.0), ("a0", area)]);
            assert_surface_zero_force_at_rest(&AreaConservation, &p, &mesh, &x, 100.0);
        }
        assert!(AreaConservation.validate(&[0.0, 0.0, 1.0]).is_err());
    }

    #[test]
    fn local_term_is_at_rest_only_when_all_faces_have_the_mean_area() {
        // A regular icosahedron: every face has the mean area.
        let (x, faces) = crate::mesh::icosphere(0, 1.0);
        let mesh = SurfaceMesh::new(x.len(), faces).unwrap();
        let area = mesh.area(&x);
        let p = params_of(&AreaConservation, &[("kl", 40.0), ("a0", area)]);
        assert_surface_zero_force_at_rest(&AreaConservation, &p, &mesh, &x, 40.0);
        // A level-1 icosphere has faces of two sizes: the local term pushes, the global does not.
        let (x, faces) = crate::mesh::icosphere(1, 1.0);
        let mesh = SurfaceMesh::new(x.len(), faces).unwrap();
        let area = mesh.area(&x);
        let local = params_of(&AreaConservation, &[("kl", 40.0), ("a0", area)]);
        let (e, f) = evaluate_surface(AreaConservation.law(), &local, &mesh, &x);
        assert!(e > 0.0 && f.iter().any(|f| f.length() > 1e-3));
    }

    #[test]
    fn stiffness_is_the_exact_hessian_per_face_projected_plus_the_global_rank_one() {
        let (mesh, x) = deformed_icosphere(1, 1.5, 0.05);
        let area = mesh.area(&x);
        for (ka, kl, a0) in [(100.0, 0.0, 0.9 * area), (0.0, 50.0, 1.1 * area), (80.0, 30.0, area)] {
            let p = params_of(&AreaConservation, &[("ka", ka), ("kl", kl), ("a0", a0)]);
            assert_surface_hessian(&AreaConservation, &p, &mesh, &x, |_| 0.0, 1e-4, 1e-5);
        }
    }
}
