//! `contact_adhesion` through the engine (issue #7): its energy depends on
//! whole bodies (each node's area share and nearest face of another body),
//! so the shared physics checks run on the CPU backend's total energy and
//! forces.
//!
//! - F = −∇E by central differences, Σf = 0, Σ r×f = 0 and rigid-motion
//!   invariance, for two jittered cells with nodes in full contact, in the
//!   switch zone and free, alone and with the barrier;
//! - the energy against an independent brute-force sum −w·Σ_t A_t·s_a·s_b·s_c;
//! - the implicit step's stiffness blocks against the Gauss–Newton model
//!   Σ_k max(∂²E/∂d_k², 0)·g_k g_kᵀ built here from brute-force closest points
//!   and a finite-difference ∂²E/∂d_k² of that sum; K̃ ⪰ 0 with rigid
//!   translations and rotations in its null space;
//! - runs are bit-identical on 1 and 2 threads; the GPU refuses the term.

use crate::common::{cpu_energy_and_forces, jitter, position_bits, two_cells, Case};
use cellmd::backend::{CpuBackend, Forces};
use cellmd::deck::Plan;
use cellmd::interactions::testing::assert_checks_of;
use cellmd::interactions::REGISTRY;
use cellmd::mesh::{point_triangle, triangle_area, PointTriangle};
use cellmd::system::State;
use faer::{Mat, Side};
use glam::DVec3;

/// Two level-2 cells of radius 1 µm 0.1 µm apart, force-field lines `ff`
/// (after `particle node drag 1`) and deck lines `commands`.
fn cells_case(ff: &str, commands: &str) -> Case {
    let deck = format!("units cell\ntopology cells.top\nforcefield cells.ff\nbox x -10 10 f y -10 10 f z -10 10 f\n{commands}");
    Case::new(&[("cells.top", &two_cells(2, 1.0, 0.1)), ("cells.ff", &format!("particle node drag 1\n{ff}")), ("deck.in", &deck)])
}

const ADHESION: &str = "contact cell cell contact_adhesion w 3 d_on 0.14 d_off 0.45\n";
const BARRIER: &str = "contact cell cell contact_barrier dhat 0.1 kappa 5\n";

/// The topology's positions, each node moved by a deterministic offset of up
/// to 0.03 µm (a generic configuration: no symmetric ties).
fn jittered(plan: &Plan) -> Vec<DVec3> {
    plan.positions.iter().enumerate().map(|(k, p)| *p + 0.02 * jitter(k)).collect()
}

/// Nodes of body `a` by their distance to body `b`: (in full contact, in the switch zone).
fn zones(plan: &Plan, x: &[DVec3], a: usize, b: usize, on: f64, off: f64) -> (usize, usize) {
    let d = nearest(plan, x, a, b);
    (d.iter().filter(|d| **d <= on).count(), d.iter().filter(|d| **d > on && **d < off).count())
}

/// Each node's distance to the nearest face of body `b`, by brute force.
fn nearest(plan: &Plan, x: &[DVec3], a: usize, b: usize) -> Vec<f64> {
    let body = &plan.model.bodies[b];
    plan.model.bodies[a]
        .nodes
        .iter()
        .map(|&p| {
            body.mesh
                .triangles()
                .iter()
                .map(|t| point_triangle(x[p as usize], t.map(|k| x[body.nodes[k as usize] as usize])).distance)
                .fold(f64::INFINITY, f64::min)
        })
        .collect()
}

#[test]
fn adhesion_forces_are_minus_the_gradient_of_the_engine_energy() {
    for ff in [ADHESION.to_string(), format!("{BARRIER}{ADHESION}")] {
        let case = cells_case(&ff, "timestep 1e-3\nrun 0\n");
        let plan = case.plan();
        let x = jittered(&plan);
        // Generic: nodes in full contact, in the switch zone and beyond it.
        let (full, switching) = zones(&plan, &x, 0, 1, 0.14, 0.45);
        assert!(full >= 1 && switching >= 10, "{full} nodes in contact, {switching} in the switch zone");
        let eval = cpu_energy_and_forces(&plan);
        let (energy, forces) = eval(&x);
        assert!(energy < 0.0 && forces.iter().any(|f| f.length() > 0.1), "E = {energy}");
        assert_checks_of("contact_adhesion (engine)", &eval, &x, 1e-6, 0.0);
    }
}

/// The energy against −w·Σ_t A_t·s_a·s_b·s_c computed here from the
/// definition: face areas, the quintic switch, brute-force distances.
#[test]
fn adhesion_energy_is_minus_w_times_the_area_in_contact() {
    let (w, on, off) = (3.0, 0.14, 0.45);
    let case = cells_case(ADHESION, "timestep 1e-3\nrun 0\n");
    let plan = case.plan();
    let x = jittered(&plan);
    let (energy, _) = cpu_energy_and_forces(&plan)(&x);
    let switch = quintic(on, off);
    let mut expected = 0.0;
    for (a, b) in [(0, 1), (1, 0)] {
        let body = &plan.model.bodies[a];
        let s: Vec<f64> = nearest(&plan, &x, a, b).into_iter().map(&switch).collect();
        for t in body.mesh.triangles() {
            let area = triangle_area(t.map(|k| x[body.nodes[k as usize] as usize]));
            expected -= w * area * t.iter().map(|&k| s[k as usize]).product::<f64>();
        }
    }
    assert!(expected < -0.1, "no contact: {expected}");
    assert!((energy - expected).abs() < 1e-12 * expected.abs(), "engine {energy}, definition {expected}");
}

/// The quintic switch of `contact_adhesion` from its definition (d_on `on`, d_off `off`).
fn quintic(on: f64, off: f64) -> impl Fn(f64) -> f64 {
    move |d: f64| {
        let t = ((d - on) / (off - on)).clamp(0.0, 1.0);
        1.0 - t * t * t * (10.0 - 15.0 * t + 6.0 * t * t)
    }
}

/// Each node of body `a`'s closest point on body `b` (the first face in order on a tie), by brute force.
fn closest_points(plan: &Plan, x: &[DVec3], a: usize, b: usize) -> Vec<(PointTriangle, [u32; 3])> {
    let body = &plan.model.bodies[b];
    plan.model.bodies[a]
        .nodes
        .iter()
        .map(|&p| {
            let mut best: Option<(PointTriangle, [u32; 3])> = None;
            for t in body.mesh.triangles() {
                let corners = t.map(|k| body.nodes[k as usize]);
                let pt = point_triangle(x[p as usize], corners.map(|q| x[q as usize]));
                if best.as_ref().is_none_or(|(b, _)| pt.distance < b.distance) {
                    best = Some((pt, corners));
                }
            }
            best.unwrap()
        })
        .collect()
}

/// The engine's K̃ at `x` as a dense 3N×3N matrix.
fn engine_stiffness(plan: &Plan, x: &[DVec3]) -> Mat<f64> {
    let state = State::new(x.to_vec());
    let mut backend = CpuBackend::new(&plan.model, &state, &plan.sim_box, 0.0).unwrap();
    backend.update_contacts(&plan.model, &state, &plan.sim_box).unwrap();
    backend.compute(&plan.model, &state, &plan.sim_box, &mut Forces::default());
    let stiffness = backend.stiffness(&plan.model, &state, &plan.sim_box);
    assert!(stiffness.rank_one.is_empty());
    let mut k = Mat::<f64>::zeros(3 * x.len(), 3 * x.len());
    for b in &stiffness.blocks {
        for (r, c) in (0..3).flat_map(|r| (0..3).map(move |c| (r, c))) {
            k[(3 * b.i as usize + r, 3 * b.j as usize + c)] += b.block.col(c)[r];
        }
    }
    k
}

/// K̃ of adhesion alone is Σ_k max(∂²E/∂d_k², 0)·g_k g_kᵀ, g_k = (n̂, −w_j n̂)
/// on (node, corners of its nearest face), with ∂²E/∂d_k² here the central
/// second difference of E = −w·Σ_t A_t·s_a·s_b·s_c (brute-force distances)
/// in node k's distance alone; it is PSD and rigid motions cost nothing.
#[test]
fn adhesion_stiffness_is_the_clamped_gauss_newton_model_of_its_energy() {
    let (w, on, off) = (3.0, 0.14, 0.45);
    let case = cells_case(ADHESION, "timestep 1e-3\nrun 0\n");
    let plan = case.plan();
    let x = jittered(&plan);
    let k = engine_stiffness(&plan, &x);
    let switch = quintic(on, off);
    let dim = 3 * x.len();
    let mut expected = Mat::<f64>::zeros(dim, dim);
    let (mut stiff, mut clamped) = (0, 0);
    for (a, b) in [(0, 1), (1, 0)] {
        let body = &plan.model.bodies[a];
        let points = closest_points(&plan, &x, a, b);
        let areas: Vec<f64> = body.mesh.triangles().iter().map(|t| triangle_area(t.map(|q| x[body.nodes[q as usize] as usize]))).collect();
        // E as a function of node `node`'s distance shifted by δ.
        let energy = |node: usize, delta: f64| -> f64 {
            let s = |c: u32| switch(points[c as usize].0.distance + if c as usize == node { delta } else { 0.0 });
            -w * body.mesh.triangles().iter().zip(&areas).map(|(t, area)| area * t.iter().map(|&c| s(c)).product::<f64>()).sum::<f64>()
        };
        for (node, (pt, corners)) in points.iter().enumerate() {
            let h = 1e-5;
            let curvature = (energy(node, h) - 2.0 * energy(node, 0.0) + energy(node, -h)) / (h * h);
            if curvature.abs() < 1e-3 {
                continue;
            }
            if curvature < 0.0 {
                clamped += 1;
                continue;
            }
            stiff += 1;
            let particles = [body.nodes[node], corners[0], corners[1], corners[2]];
            let g = [1.0, -pt.weights[0], -pt.weights[1], -pt.weights[2]];
            for (i, j) in (0..4).flat_map(|i| (0..4).map(move |j| (i, j))) {
                for (r, c) in (0..3).flat_map(|r| (0..3).map(move |c| (r, c))) {
                    expected[(3 * particles[i] as usize + r, 3 * particles[j] as usize + c)] +=
                        curvature * g[i] * g[j] * pt.normal[r] * pt.normal[c];
                }
            }
        }
    }
    // Nodes on both sides of the switch's inflection: kept and clamped curvatures.
    assert!(stiff >= 5 && clamped >= 5, "{stiff} nodes with positive curvature, {clamped} clamped");
    let scale = expected.norm_max();
    let error = (&k - &expected).norm_max();
    println!(
        "K̃ vs the Gauss–Newton model: max |difference| {error:.3e} of max |entry| {scale:.3e} ({stiff} nodes kept, {clamped} clamped)"
    );
    assert!(error < 1e-6 * scale, "max |K̃ − model| = {error:e}, max |model| = {scale:e}");
    // PSD, and rigid translations and rotations (about the origin) in its null space.
    // (On the rows K̃ touches: faer's eigensolver does not converge with the zero rows of the free nodes.)
    let touched: Vec<usize> = (0..dim).filter(|&r| (0..dim).any(|c| k[(r, c)] != 0.0)).collect();
    let sub = Mat::from_fn(touched.len(), touched.len(), |r, c| k[(touched[r], touched[c])]);
    let lowest = sub.self_adjoint_eigenvalues(Side::Lower).unwrap().into_iter().fold(f64::INFINITY, f64::min);
    assert!(lowest > -1e-10 * scale, "smallest eigenvalue {lowest:e}");
    for axis in 0..3 {
        let mut e = DVec3::ZERO;
        e[axis] = 1.0;
        for (motion, v) in [("translation", x.iter().map(|_| e).collect::<Vec<_>>()), ("rotation", x.iter().map(|p| e.cross(*p)).collect())]
        {
            let v = Mat::from_fn(dim, 1, |r, _| v[r / 3][r % 3]);
            let resisted = (&k * &v).norm_max();
            assert!(resisted < 1e-10 * scale * v.norm_max(), "{motion} about axis {axis}: |K̃·v| = {resisted:e}");
        }
    }
}

#[test]
fn adhesion_runs_are_bit_identical_on_one_and_two_threads() {
    let shells = "body cell turgor k 100 dp0 8 v0 4.0\nbody cell surface_tension gamma 4\n";
    let case = cells_case(
        &format!("{shells}{BARRIER}{ADHESION}"),
        "temperature 0.0041\nseed 5\ntimestep 2e-3\nthermo 50 step pe pe/contact_adhesion mindist\nrun 200\n",
    );
    let (one, two) = (case.run_with_threads(1), case.run_with_threads(2));
    assert_eq!(position_bits(&one), position_bits(&two));
    assert_eq!(one.backend.forces.total_energy().to_bits(), two.backend.forces.total_energy().to_bits());
    assert_eq!(one.backend.forces.virial.map(f64::to_bits), two.backend.forces.virial.map(f64::to_bits));
    let index = REGISTRY.iter().position(|i| i.name() == "contact_adhesion").unwrap();
    assert!(one.backend.forces.energy_by_interaction[index] < 0.0, "the cells never adhered");
}
