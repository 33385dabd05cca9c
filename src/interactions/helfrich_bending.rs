#![doc = include_str!("helfrich_bending.md")]

use glam::DVec3;

use super::{Kind, Law, ParamSpec, SurfaceMesh};
use crate::mesh::{bending_angle, triangle_area_gradient};
use crate::units::Dim;

const KAPPA: usize = 0;
const C0: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("kappa", Dim::Energy, "bending rigidity κ (lipid bilayers ≈ 20 kT ≈ 0.08 pN·µm)").non_negative(),
    ParamSpec::new(
        "c0",
        Dim::Curvature,
        "spontaneous curvature C0 (the sum of principal curvatures at rest; 2/R for a sphere of radius R)",
    )
    .default(0.0),
];

fn eval(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64 {
    let kappa = p[KAPPA];
    let c = 0.5 * p[C0];
    let n = mesh.nodes();
    let mut m = vec![0.0; n];
    let mut a = vec![0.0; n];
    // Edge geometry: length, unit vector, bending angle and its gradient.
    let edges: Vec<(f64, DVec3, f64, [DVec3; 4])> = mesh
        .edges()
        .iter()
        .map(|e| {
            let [i, j] = e.ends.map(|p| p as usize);
            let [wa, wb] = e.wings.map(|p| p as usize);
            let d = x[j] - x[i];
            let l = d.length();
            let (theta, grad) = bending_angle(x[i], x[j], x[wa], x[wb]);
            m[i] += 0.25 * l * theta;
            m[j] += 0.25 * l * theta;
            (l, d / l, theta, grad)
        })
        .collect();
    let faces: Vec<(f64, [DVec3; 3])> = (0..mesh.triangles().len()).map(|t| triangle_area_gradient(mesh.corners(t, x))).collect();
    for (face, (area, _)) in mesh.triangles().iter().zip(&faces) {
        for p in face {
            a[*p as usize] += area / 3.0;
        }
    }
    // E = Σ_i 2κ u_i²/A_i with u_i = M_i − c·A_i.
    let mut energy = 0.0;
    let mut de_dm = vec![0.0; n];
    let mut de_da = vec![0.0; n];
    for i in 0..n {
        let u = m[i] - c * a[i];
        energy += 2.0 * kappa * u * u / a[i];
        de_dm[i] = 4.0 * kappa * u / a[i];
        de_da[i] = -2.0 * kappa * u * (2.0 * c * a[i] + u) / (a[i] * a[i]);
    }
    for (e, &(l, unit, theta, grad)) in mesh.edges().iter().zip(&edges) {
        let [i, j] = e.ends.map(|p| p as usize);
        let [wa, wb] = e.wings.map(|p| p as usize);
        // d(ℓθ) = θ·dℓ + ℓ·dθ, each end's M_i holding a quarter.
        let coef = 0.25 * (de_dm[i] + de_dm[j]);
        forces[i] -= coef * (-theta * unit + l * grad[0]);
        forces[j] -= coef * (theta * unit + l * grad[1]);
        forces[wa] -= coef * l * grad[2];
        forces[wb] -= coef * l * grad[3];
    }
    for (face, (_, grad)) in mesh.triangles().iter().zip(&faces) {
        let coef = face.iter().map(|&p| de_da[p as usize]).sum::<f64>() / 3.0;
        for (p, g) in face.iter().zip(grad) {
            forces[*p as usize] -= coef * *g;
        }
    }
    energy
}

interaction!(
    HelfrichBending,
    "helfrich_bending",
    Kind::Body,
    "Helfrich bending (κ/2)∮(2H − C0)² dA, Jülicher's discretisation: Σ_i 2κ(M_i − C0·A_i/2)²/A_i",
    Law::Surface(eval)
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use std::f64::consts::PI;

    #[test]
    fn shared_checks() {
        for level in [0, 1, 2] {
            let (mesh, x) = deformed_icosphere(level, 1.5, 0.05);
            for (kappa, c0) in [(0.08, 0.0), (0.08, 1.2), (1.0, -0.7)] {
                let p = params_of(&HelfrichBending, &[("kappa", kappa), ("c0", c0)]);
                assert_surface_checks(&HelfrichBending, &p, &mesh, &x, 1e-6, 1e-3);
            }
        }
    }

    #[test]
    fn a_sphere_at_its_spontaneous_curvature_is_nearly_at_rest_and_its_energy_is_scale_free() {
        // E of a sphere is 8πκ(1 − C0·R/2)²: zero at C0 = 2/R, and for C0 = 0 independent of R.
        let (x, faces) = crate::mesh::icosphere(4, 1.0);
        let mesh = SurfaceMesh::new(x.len(), faces).unwrap();
        let free = params_of(&HelfrichBending, &[("kappa", 1.0)]);
        let (e1, _) = evaluate_surface(HelfrichBending.law(), &free, &mesh, &x);
        let big: Vec<DVec3> = x.iter().map(|p| 3.0 * *p).collect();
        let (e3, _) = evaluate_surface(HelfrichBending.law(), &free, &mesh, &big);
        assert!((e1 - e3).abs() < 1e-12 * e1, "{e1} vs {e3}");
        assert!((e1 / (8.0 * PI) - 1.0).abs() < 0.01, "E = {e1}, 8πκ = {}", 8.0 * PI);
        let at_rest = params_of(&HelfrichBending, &[("kappa", 1.0), ("c0", 2.0)]);
        let (e, _) = evaluate_surface(HelfrichBending.law(), &at_rest, &mesh, &x);
        assert!(e < 1e-3 * e1, "E = {e} at C0 = 2/R");
    }
}
