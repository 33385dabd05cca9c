#![doc = include_str!("helfrich_bending.md")]

use glam::DVec3;

use super::{Kind, Law, ParamSpec, SurfaceGpu, SurfaceHessian, SurfaceMesh};
use crate::hessian::LocalRankOne;
use crate::mesh::{bending_angle, triangle_area_gradient, MeshEdge};
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

/// A node's energy 2κu²/A (u = m − c·a, c = C0/2) from its integrated mean
/// curvature m and area a, with ∂E/∂m and ∂E/∂a.
fn node_energy(kappa: f64, c: f64, m: f64, a: f64) -> (f64, f64, f64) {
    let u = m - c * a;
    (2.0 * kappa * u * u / a, 4.0 * kappa * u / a, -2.0 * kappa * u * (2.0 * c * a + u) / (a * a))
}

/// ∂(ℓθ)/∂(x_i, x_j, x_a, x_b) of an edge of length `l` along `unit` with
/// bending angle `theta` and its gradient `grad`: d(ℓθ) = θ·dℓ + ℓ·dθ.
fn edge_gradient(l: f64, unit: DVec3, theta: f64, grad: [DVec3; 4]) -> [DVec3; 4] {
    [-theta * unit + l * grad[0], theta * unit + l * grad[1], l * grad[2], l * grad[3]]
}

fn eval(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64 {
    let kappa = p[KAPPA];
    let c = 0.5 * p[C0];
    let n = mesh.nodes();
    let mut m = vec![0.0; n];
    let mut a = vec![0.0; n];
    // Edge geometry: ∂(ℓθ) of each edge.
    let edges: Vec<[DVec3; 4]> = mesh
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
            edge_gradient(l, d / l, theta, grad)
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
        let e;
        (e, de_dm[i], de_da[i]) = node_energy(kappa, c, m[i], a[i]);
        energy += e;
    }
    for (e, grad) in mesh.edges().iter().zip(&edges) {
        let [i, j] = e.ends.map(|p| p as usize);
        // Each end's M_i holds a quarter of ℓθ.
        let coef = 0.25 * (de_dm[i] + de_dm[j]);
        for (p, g) in [e.ends[0], e.ends[1], e.wings[0], e.wings[1]].iter().zip(grad) {
            forces[*p as usize] -= coef * *g;
        }
    }
    for (face, (_, grad)) in mesh.triangles().iter().zip(&faces) {
        let coef = face.iter().map(|&p| de_da[p as usize]).sum::<f64>() / 3.0;
        for (p, g) in face.iter().zip(grad) {
            forces[*p as usize] -= coef * *g;
        }
    }
    energy
}

/// Node i's integrated mean curvature M_i and area A_i with their gradients
/// over its one-ring (local 0 the node itself, then its neighbours in order
/// of first appearance): (ring nodes, M, A, ∂M, ∂A).
fn ring_curvature(i: u32, edges: &[MeshEdge], faces: &[[u32; 3]], x: &[DVec3]) -> (Vec<u32>, f64, f64, Vec<DVec3>, Vec<DVec3>) {
    let mut nodes = vec![i];
    let mut local = |p: u32| {
        nodes.iter().position(|&q| q == p).unwrap_or_else(|| {
            nodes.push(p);
            nodes.len() - 1
        })
    };
    let edges: Vec<[usize; 4]> = edges.iter().map(|e| [e.ends[0], e.ends[1], e.wings[0], e.wings[1]].map(&mut local)).collect();
    let faces: Vec<[usize; 3]> = faces.iter().map(|f| f.map(&mut local)).collect();
    let y: Vec<DVec3> = nodes.iter().map(|&p| x[p as usize]).collect();
    let (mut m, mut a) = (0.0, 0.0);
    let (mut grad_m, mut grad_a) = (vec![DVec3::ZERO; y.len()], vec![DVec3::ZERO; y.len()]);
    for edge in edges {
        let [i, j, wa, wb] = edge;
        let d = y[j] - y[i];
        let l = d.length();
        let (theta, grad) = bending_angle(y[i], y[j], y[wa], y[wb]);
        m += 0.25 * l * theta;
        for (k, g) in edge.iter().zip(edge_gradient(l, d / l, theta, grad)) {
            grad_m[*k] += 0.25 * g;
        }
    }
    for face in faces {
        let (area, grad) = triangle_area_gradient(face.map(|k| y[k]));
        a += area / 3.0;
        for (k, g) in face.iter().zip(grad) {
            grad_a[*k] += g / 3.0;
        }
    }
    (nodes, m, a, grad_m, grad_a)
}

/// The generalised Gauss–Newton model, one rank-one term per node: E_i =
/// f(u_i, A_i) = 2κu_i²/A_i is convex in (u, A) (a perspective of u²) with
/// the rank-one Hessian (4κ/A)·v vᵀ, v = (1, −u/A); linearising u_i and A_i
/// in x gives (4κ/A_i)·g_i g_iᵀ with g_i = ∇u_i − (u_i/A_i)·∇A_i over node i's
/// one-ring. Left out: ∂E/∂M_i·∇²M_i + ∂E/∂A_i·∇²A_i.
fn hessian(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], out: &mut SurfaceHessian) {
    let (kappa, c) = (p[KAPPA], 0.5 * p[C0]);
    let n = mesh.nodes();
    let mut edges_at = vec![Vec::new(); n];
    for e in mesh.edges() {
        for end in e.ends {
            edges_at[end as usize].push(*e);
        }
    }
    let mut faces_at = vec![Vec::new(); n];
    for face in mesh.triangles() {
        for corner in face {
            faces_at[*corner as usize].push(*face);
        }
    }
    for i in 0..n {
        let (nodes, m, a, grad_m, grad_a) = ring_curvature(i as u32, &edges_at[i], &faces_at[i], x);
        let u = m - c * a;
        let gradient = grad_m.iter().zip(&grad_a).map(|(gm, ga)| *gm - (c + u / a) * *ga).collect();
        out.gauss_newton.push(LocalRankOne { weight: 4.0 * kappa / a, nodes, gradient });
    }
}

interaction!(
    HelfrichBending,
    "helfrich_bending",
    Kind::Body,
    "Helfrich bending (κ/2)∮(2H − C0)² dA, Jülicher's discretisation: Σ_i 2κ(M_i − C0·A_i/2)²/A_i",
    Law::Surface { eval, hessian, gpu: SurfaceGpu::NodeCurvature }
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use std::f64::consts::PI;

    #[test]
    fn shared_checks() {
        for (_, mesh, x) in deformed_icospheres(&[0, 1, 2]) {
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

    #[test]
    fn stiffness_is_the_gauss_newton_model_of_each_node() {
        for (level, mesh, x) in deformed_icospheres(&[0, 1]) {
            let rings = |y: &[DVec3]| -> Vec<(f64, f64)> {
                (0..mesh.nodes() as u32)
                    .map(|i| {
                        let edges: Vec<MeshEdge> = mesh.edges().iter().filter(|e| e.ends.contains(&i)).copied().collect();
                        let faces: Vec<[u32; 3]> = mesh.triangles().iter().filter(|f| f.contains(&i)).copied().collect();
                        let (_, m, a, _, _) = ring_curvature(i, &edges, &faces, y);
                        (m, a)
                    })
                    .collect()
            };
            for (kappa, c0) in [(0.08, 0.0), (1.0, -0.7)] {
                let p = params_of(&HelfrichBending, &[("kappa", kappa), ("c0", c0)]);
                // The part left out, frozen at x: Σ_i ∂E/∂M_i·M_i + ∂E/∂A_i·A_i.
                let slopes: Vec<(f64, f64)> =
                    rings(&x).iter().map(|&(m, a)| (node_energy(kappa, 0.5 * c0, m, a).1, node_energy(kappa, 0.5 * c0, m, a).2)).collect();
                let dropped = |y: &[DVec3]| rings(y).iter().zip(&slopes).map(|((m, a), (dm, da))| dm * m + da * a).sum::<f64>();
                let lowest = assert_surface_hessian(&HelfrichBending, &p, &mesh, &x, dropped, 1e-4, 1e-5);
                // PSD by construction: no projection needed.
                assert!(lowest > -1e-9, "level {level}, κ {kappa}, C0 {c0}: lowest relative eigenvalue {lowest:e}");
            }
        }
    }
}
