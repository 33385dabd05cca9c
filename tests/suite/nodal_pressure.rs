//! `neo_hookean_anp` through the engine (issue #46): its volumetric energy
//! lives on the nodes (average nodal pressure, Bonet & Burton 1998), so an
//! element's forces depend on its neighbours' volumes and the shared checks
//! run on the CPU backend's total energy and forces of a meshed ball
//! (`cellmd build ball --cells 2`: 27 nodes, 48 elements, every node shared):
//!
//! - F = −∇E by central differences, Σf = 0, Σ r×f = 0 and rigid-motion
//!   invariance at a jittered, compressed configuration;
//! - the energy against the definition summed here from the positions:
//!   Σ_e V_0,e·μ/2(J_e^{−2/3}I₁ − 3) + Σ_a V_a·U(J_a), J_a = v_a/V_a;
//! - the implicit step's stiffness K̃ at rest against the finite-difference
//!   Hessian of the engine's forces (exact there: no pressure, nothing projected);
//! - the GPU refuses the law (CPU only).
//!
//! Hertz indentation, where the formulation removes locking: tests/suite/hertz.rs.

use crate::common::{cpu_energy_and_forces, jitter, Case};
use cellmd::backend::{CpuBackend, Forces};
use cellmd::build::{ball, BallArgs};
use cellmd::deck::Plan;
use cellmd::hessian::finite_difference_hessian;
use cellmd::interactions::testing::assert_checks_of;
use cellmd::mesh::tetra_edges;
use cellmd::run::{RunOptions, Simulation};
use cellmd::system::State;
use glam::{DMat3, DVec3};

const YOUNG: f64 = 800.0;
const POISSON: f64 = 0.45;

fn ball_case() -> Case {
    let top = ball(&BallArgs { radius: 1.0, cells: 2, ..Default::default() }).unwrap().text;
    let ff = format!("particle node drag 1\ntetra solid neo_hookean_anp e {YOUNG} nu {POISSON}\n");
    let deck = "units cell\ntopology ball.top\nforcefield ball.ff\nbox x -5 5 f y -5 5 f z -5 5 f\ntimestep 1e-3\nrun 0\n";
    Case::new(&[("ball.top", &top), ("ball.ff", &ff), ("deck.in", deck)])
}

/// The rest positions squeezed by 10 % along z and moved by a deterministic
/// jitter of up to 0.05 µm (a generic configuration: no symmetric ties).
fn deformed(plan: &Plan) -> Vec<DVec3> {
    plan.positions.iter().enumerate().map(|(k, p)| DVec3::new(p.x, p.y, 0.9 * p.z) + 0.05 * jitter(k)).collect()
}

#[test]
fn nodal_pressure_forces_are_minus_the_gradient_of_the_engine_energy() {
    let plan = ball_case().plan();
    let x = deformed(&plan);
    let eval = cpu_energy_and_forces(&plan);
    let (energy, forces) = eval(&x);
    assert!(energy > 0.0 && forces.iter().any(|f| f.length() > 1.0), "E = {energy}");
    assert_checks_of("neo_hookean_anp (engine)", &eval, &x, 1e-6, 0.0);
}

#[test]
fn nodal_pressure_energy_is_its_definition() {
    let plan = ball_case().plan();
    let x = deformed(&plan);
    let (mu, kappa) = (YOUNG / (2.0 * (1.0 + POISSON)), YOUNG / (3.0 * (1.0 - 2.0 * POISSON)));
    let (mut expected, mut rest, mut now) = (0.0, vec![0.0; x.len()], vec![0.0; x.len()]);
    for corners in &plan.model.tetras {
        let at = |p: &[DVec3]| tetra_edges(corners.map(|c| p[c as usize]));
        let (dm, ds) = (at(&plan.positions), at(&x));
        let f: DMat3 = ds * dm.inverse();
        let (j, v0) = (f.determinant(), dm.determinant().abs() / 6.0);
        let i1 = f.x_axis.length_squared() + f.y_axis.length_squared() + f.z_axis.length_squared();
        expected += v0 * 0.5 * mu * (j.powf(-2.0 / 3.0) * i1 - 3.0);
        for &c in corners {
            rest[c as usize] += v0 / 4.0;
            now[c as usize] += j * v0 / 4.0;
        }
    }
    for (v, w) in rest.iter().zip(&now) {
        let j = w / v;
        expected += v * 0.25 * kappa * (j * j - 1.0 - 2.0 * j.ln());
    }
    let (energy, _) = cpu_energy_and_forces(&plan)(&x);
    assert!((energy - expected).abs() < 1e-12 * expected, "engine {energy}, definition {expected}");
}

#[test]
fn nodal_pressure_stiffness_at_rest_is_the_hessian() {
    let plan = ball_case().plan();
    let state = State::new(plan.positions.clone());
    let mut backend = CpuBackend::new(&plan.model, &state, &plan.sim_box, 0.0).unwrap();
    let mut out = Forces::default();
    backend.compute(&plan.model, &state, &plan.sim_box, &mut out);
    let stiffness = backend.stiffness(&plan.model, &state, &plan.sim_box);
    assert!(stiffness.rank_one.is_empty());
    let n = plan.positions.len();
    let mut k = faer::Mat::<f64>::zeros(3 * n, 3 * n);
    for b in &stiffness.blocks {
        for (c, col) in [b.block.x_axis, b.block.y_axis, b.block.z_axis].into_iter().enumerate() {
            for r in 0..3 {
                k[(3 * b.i as usize + r, 3 * b.j as usize + c)] += col[r];
            }
        }
    }
    let eval = cpu_energy_and_forces(&plan);
    let h = finite_difference_hessian(&plan.positions, |p| eval(p).1);
    let scale = (0..3 * n).map(|d| h[(d, d)].abs()).fold(0.0, f64::max);
    let worst = (0..3 * n).flat_map(|r| (0..3 * n).map(move |c| (r, c))).map(|(r, c)| (k[(r, c)] - h[(r, c)]).abs()).fold(0.0, f64::max);
    assert!(worst < 1e-6 * scale, "K̃ − H: {worst:e} of a diagonal up to {scale:e}");
}

#[test]
fn nodal_pressure_elements_stay_on_the_cpu() {
    let plan = ball_case().plan();
    let sim = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
    assert!(sim.cpu_only_feature().is_some_and(|why| why.contains("neo_hookean_anp")), "{:?}", sim.cpu_only_feature());
}
