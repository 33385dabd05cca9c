#![doc = include_str!("surface_shear.md")]

use faer::Mat;
use glam::DVec3;

use super::{Kind, Law, ParamSpec, SurfaceGpu, SurfaceHessian, SurfaceMesh};
use crate::hessian::LocalHessian;
use crate::mesh::{triangle_area_gradient, triangle_area_hessian};
use crate::units::Dim;

const K: usize = 0;

static PARAMS: [ParamSpec; 1] =
    [ParamSpec::new("k", Dim::Energy, "shear energy scale per face: E = k·Σ_t (q_t − 1), q_t = Σ_e ℓ_e²/(4√3·A_t)").positive()];

/// 1/(4√3): q = S/(4√3·A) is 1 for an equilateral triangle.
const SHAPE: f64 = 0.144_337_567_297_406_43;

/// S = Σ_e ℓ_e² of a face and its gradient ∂S/∂x_a = 2(2x_a − x_b − x_c).
fn squared_edges([a, b, c]: [DVec3; 3]) -> (f64, [DVec3; 3]) {
    let s = (b - a).length_squared() + (c - b).length_squared() + (a - c).length_squared();
    (s, [2.0 * (2.0 * a - b - c), 2.0 * (2.0 * b - c - a), 2.0 * (2.0 * c - a - b)])
}

fn eval(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64 {
    let scale = p[K] * SHAPE;
    let mut energy = 0.0;
    for (t, face) in mesh.triangles().iter().enumerate() {
        let corners = mesh.corners(t, x);
        let (s, grad_s) = squared_edges(corners);
        let (a, grad_a) = triangle_area_gradient(corners);
        energy += p[K] * (SHAPE * s / a - 1.0);
        for k in 0..3 {
            forces[face[k] as usize] -= scale * (grad_s[k] - (s / a) * grad_a[k]) / a;
        }
    }
    energy
}

/// The exact Hessian of c·S/A per face (c = k/(4√3)):
/// c·[∇²S/A − (∇S∇Aᵀ + ∇A∇Sᵀ)/A² + S·(2∇A∇Aᵀ/A³ − ∇²A/A²)], ∇²S = 2·L⊗I with
/// L the triangle's graph Laplacian (2 on the diagonal, −1 off it).
fn hessian(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], out: &mut SurfaceHessian) {
    let c = p[K] * SHAPE;
    for (t, face) in mesh.triangles().iter().enumerate() {
        let corners = mesh.corners(t, x);
        let (s, gs) = squared_edges(corners);
        let (a, ga) = triangle_area_gradient(corners);
        let second_a = triangle_area_hessian(corners);
        let matrix = Mat::from_fn(9, 9, |r, col| {
            let (k, l, i, j) = (r / 3, col / 3, r % 3, col % 3);
            let laplacian = match (i == j, k == l) {
                (false, _) => 0.0,
                (true, true) => 4.0,
                (true, false) => -2.0,
            };
            c * (laplacian / a - (gs[k][i] * ga[l][j] + ga[k][i] * gs[l][j]) / (a * a)
                + s * (2.0 * ga[k][i] * ga[l][j] / (a * a * a) - second_a[k][l].col(j)[i] / (a * a)))
        });
        out.stencils.push(LocalHessian { nodes: face.to_vec(), matrix });
    }
}

interaction!(
    SurfaceShear,
    "surface_shear",
    Kind::Body,
    "In-plane shear (shape) elasticity of a closed body's faces, E = k·Σ_t (Σℓ²/(4√3·A_t) − 1): no tension, no bending",
    Law::Surface { eval, hessian, gpu: SurfaceGpu::PerFace }
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        for (_, mesh, x) in deformed_icospheres(&[0, 1, 2]) {
            let p = params_of(&SurfaceShear, &[("k", 0.7)]);
            assert_surface_checks(&SurfaceShear, &p, &mesh, &x, 1e-6, 1e-3);
        }
    }

    /// A regular icosahedron's faces are equilateral: E = 0 and no force.
    #[test]
    fn equilateral_faces_are_at_rest() {
        let (x, faces) = crate::mesh::icosphere(0, 2.0);
        let mesh = SurfaceMesh::new(x.len(), faces).unwrap();
        let p = params_of(&SurfaceShear, &[("k", 3.0)]);
        let (e, _) = evaluate_surface(SurfaceShear.law(), &p, &mesh, &x);
        assert!(e.abs() < 1e-13, "E = {e:e}");
        assert_surface_zero_force_at_rest(&SurfaceShear, &p, &mesh, &x, 3.0);
    }

    /// The oracle: an affine map J of an equilateral face has
    /// q = (λ1² + λ2²)/(2λ1λ2) in its principal stretches λ (Evans' shear
    /// invariant), computed here from the face's metric G = JᵀJ in the rest
    /// triangle's own frame: λ1² + λ2² = tr G, λ1λ2 = √det G. Uniform scaling
    /// leaves E unchanged (no tension): Σ x·F = 0 by Euler's theorem.
    #[test]
    fn energy_is_evans_shear_invariant_of_each_face_and_free_of_tension() {
        let (x, faces) = crate::mesh::icosphere(0, 1.0);
        let mesh = SurfaceMesh::new(x.len(), faces.clone()).unwrap();
        let stretch = glam::DMat3::from_cols(DVec3::new(1.4, 0.2, 0.0), DVec3::new(0.1, 0.9, -0.3), DVec3::new(0.0, 0.25, 0.7));
        let moved: Vec<DVec3> = x.iter().map(|p| stretch * *p).collect();
        let p = params_of(&SurfaceShear, &[("k", 2.5)]);
        let (e, f) = evaluate_surface(SurfaceShear.law(), &p, &mesh, &moved);
        let mut expected = 0.0;
        for t in &faces {
            let [a, b, c] = t.map(|k| x[k as usize]);
            // Orthonormal frame of the rest face; J maps its 2D coordinates to 3D.
            let e1 = (b - a).normalize();
            let e2 = (b - a).cross(c - a).cross(b - a).normalize();
            let (j1, j2) = (stretch * e1, stretch * e2);
            let (g11, g22, g12) = (j1.dot(j1), j2.dot(j2), j1.dot(j2));
            expected += 2.5 * ((g11 + g22) / (2.0 * (g11 * g22 - g12 * g12).sqrt()) - 1.0);
        }
        assert!((e - expected).abs() < 1e-12 * expected, "E = {e} vs {expected}");
        let virial: f64 = moved.iter().zip(&f).map(|(x, f)| x.dot(*f)).sum();
        let size: f64 = moved.iter().zip(&f).map(|(x, f)| x.length() * f.length()).sum();
        assert!(virial.abs() < 1e-12 * size, "Σ x·F = {virial:e}");
        let scaled: Vec<DVec3> = moved.iter().map(|p| 3.1 * *p).collect();
        let (e2, _) = evaluate_surface(SurfaceShear.law(), &p, &mesh, &scaled);
        assert!((e2 - e).abs() < 1e-12 * e);
    }

    #[test]
    fn stiffness_is_the_exact_hessian_per_face_projected() {
        for (_, mesh, x) in deformed_icospheres(&[0, 1]) {
            let p = params_of(&SurfaceShear, &[("k", 0.7)]);
            assert_surface_hessian(&SurfaceShear, &p, &mesh, &x, |_| 0.0, 1e-4, 1e-5);
        }
    }
}
