//! `integrator implicit`: the linearly implicit step against the explicit one
//! and exact results.

use crate::common;

use crate::common::Case;
use cellmd::run::{RunError, RunOptions, Simulation};
use glam::DVec3;

/// A clamped cantilever: `n` beads ℓ apart along x, the first two fixed,
/// bending modulus κ, stiff bonds, a transverse force on the tip.
fn cantilever(integrator: &str, dt: f64, steps: u64) -> Case {
    let n = 11;
    let l = 0.1;
    let mut top = String::from("[ particles ]\n");
    for k in 0..n {
        let kind = if k < 2 { "clamp" } else { "bead" };
        top += &format!("{} {kind} {} 0 0\n", k + 1, k as f64 * l);
    }
    top += "[ bonds ]\n";
    for k in 1..n {
        top += &format!("rod {k} {}\n", k + 1);
    }
    top += "[ angles ]\n";
    for k in 1..n - 1 {
        top += &format!("bend {k} {} {}\n", k + 1, k + 2);
    }
    let ff = "particle clamp fixed\nparticle bead drag 0.01\nparticle tip drag 0.01\n\
              bond rod harmonic k 100 r0 0.1\nangle bend wlc_bending kappa 0.01 l0 0.1\n";
    let deck = format!(
        "topology t.top\nforcefield f.ff\nbox x -1 2 f y -1 1 f z -1 1 f\ngroup tip id {n}\nexternal load tip constant_force fy 0.02\n\
         {integrator}\ntimestep {dt}\nthermo 0 step pe solver_iterations solver_residual\nrun {steps}\n"
    );
    Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

fn run(case: &Case) -> Result<Simulation, RunError> {
    Simulation::execute(case.plan(), RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() })
}

/// The explicit stability limit of the bending stencil, γℓ³/(8κ).
const BENDING_LIMIT: f64 = 0.01 * 1e-3 / (8.0 * 0.01);

/// The same equilibrium (to 1e-6 µm) from the explicit step at dt below its
/// stability limit and from the implicit step at 100× that limit, where the
/// explicit step blows up.
#[test]
fn implicit_and_explicit_reach_the_same_cantilever_equilibrium() {
    let explicit = run(&cantilever("integrator overdamped", 0.4 * BENDING_LIMIT, 250_000)).unwrap();
    let dt = 100.0 * BENDING_LIMIT;
    let implicit = run(&cantilever("integrator implicit", dt, 1_000)).unwrap();
    let cholesky = run(&cantilever("integrator implicit solver cholesky", dt, 1_000)).unwrap();
    // The two solvers also agree step by step.
    let cg_3 = run(&cantilever("integrator implicit tolerance 1e-14", dt, 3)).unwrap();
    let cholesky_3 = run(&cantilever("integrator implicit solver cholesky", dt, 3)).unwrap();
    let tip = |s: &Simulation| s.state.positions[10];
    let deflection = tip(&explicit).y;
    let worst = |a: &Simulation, b: &Simulation| {
        a.state.positions.iter().zip(&b.state.positions).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max)
    };
    println!(
        "tip deflection {deflection:.8} µm; implicit − explicit {:.2e} µm, cholesky − cg {:.2e} µm; last CG solve {:?}",
        worst(&implicit, &explicit),
        worst(&cholesky, &implicit),
        implicit.reports.last_solve
    );
    assert!(deflection > 0.01, "the load bent the filament by only {deflection} µm");
    assert!(worst(&implicit, &explicit) < 1e-6, "implicit and explicit equilibria differ by {:e} µm", worst(&implicit, &explicit));
    assert!(worst(&cholesky, &implicit) < 1e-9);
    assert!(worst(&cg_3, &cholesky_3) < 1e-12, "after 3 steps CG and Cholesky differ by {:e}", worst(&cg_3, &cholesky_3));
    // The explicit step at the implicit's dt is unstable.
    match run(&cantilever("integrator overdamped", dt, 1_000)) {
        Err(RunError::Blowup { .. }) => {}
        other => panic!("the explicit step at 100× its limit should blow up, got {:?}", other.map(|s| s.state.step)),
    }
}

/// Quasi-static Newton steps (γ/dt = 1e-8 pN/µm, as the `solver cholesky`
/// decks take them): conjugate gradients reach the Cholesky step. Started
/// from the explicit step b·dt/γ (2·10⁶ µm here) CG cannot: the relative
/// residual it stops at is measured against |b|, not against that start.
#[test]
fn conjugate_gradients_take_newton_steps_like_cholesky() {
    let cg = run(&cantilever("integrator implicit tolerance 1e-12", 1e6, 4)).unwrap();
    let cholesky = run(&cantilever("integrator implicit solver cholesky", 1e6, 4)).unwrap();
    let worst = cg.state.positions.iter().zip(&cholesky.state.positions).map(|(x, y)| (*x - *y).length()).fold(0.0, f64::max);
    let deflection = cholesky.state.positions[10].y;
    println!("tip deflection {deflection:.6} µm; cg − cholesky {worst:.2e} µm; last CG solve {:?}", cg.reports.last_solve);
    assert!(deflection > 0.01, "the load bent the filament by only {deflection} µm");
    assert!(worst < 1e-9, "CG and Cholesky Newton steps differ by {worst:e} µm");
}

/// A particle on a spring to a fixed anchor: backward Euler contracts the
/// displacement from rest by exactly 1/(1 + k·dt/γ) per step, also at
/// k·dt/γ = 100 (the explicit factor would be −99).
#[test]
fn a_linear_spring_relaxes_by_the_backward_euler_factor() {
    for ratio in [0.1f64, 1.0, 100.0] {
        let (k, gamma) = (4.0, 2.0);
        let dt = ratio * gamma / k;
        let top = "[ particles ]\n1 anchor 0 0 0\n2 bead 1.5 0 0\n[ bonds ]\ns 1 2\n";
        let ff = "particle anchor fixed\nparticle bead drag 2\nbond s harmonic k 4 r0 1\n";
        let deck = format!("units lj\ntopology t.top\nforcefield f.ff\nbox x -3 3 f y -3 3 f z -3 3 f\nintegrator implicit tolerance 1e-14\ntimestep {dt}\nrun 5\n");
        let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", &deck)]);
        let sim = run(&case).unwrap();
        let expected = 1.0 + 0.5 * (1.0 / (1.0 + ratio)).powi(5);
        let got = sim.state.positions[1];
        assert!((got - DVec3::new(expected, 0.0, 0.0)).length() < 1e-12, "k·dt/γ = {ratio}: x = {got}, expected {expected}");
    }
}

/// Without stiffness (free particles) the implicit step is the explicit one,
/// noise included.
#[test]
fn without_stiffness_the_implicit_step_is_the_explicit_step() {
    let positions = |integrator: &str| {
        let deck = format!("units lj\ntopology t.top\nforcefield f.ff\nbox x -5 9 f y -5 9 f z -5 9 f\ntemperature 0.7\nseed 3\n{integrator}\ntimestep 0.01\nrun 20\n");
        let case = Case::new(&[("t.top", &common::grid_topology(4, 1.0)), ("f.ff", "particle p drag 1.5\n"), ("deck.in", &deck)]);
        run(&case).unwrap().state.positions
    };
    let (explicit, implicit) = (positions("integrator overdamped"), positions("integrator implicit"));
    let worst = explicit.iter().zip(&implicit).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
    assert!(worst < 1e-14, "implicit − explicit {worst:e} for free particles");
    assert!(explicit.iter().zip(common::grid_positions(4, 1.0)).any(|(x, x0)| (*x - x0).length() > 0.05), "nothing diffused");
}

/// Accuracy against step size: the tip position at t = 0.25 s (mid-transient)
/// from the implicit step at dt = 1, 10, 100 and 1000 × the explicit limit,
/// against the explicit step at 0.1 × the limit. Backward Euler is first
/// order, so the error must fall about tenfold per tenfold smaller dt.
#[test]
fn implicit_error_is_first_order_in_dt() {
    let t = 0.25;
    let reference_dt = 0.1 * BENDING_LIMIT;
    let reference = run(&cantilever("integrator overdamped", reference_dt, (t / reference_dt).round() as u64)).unwrap();
    let tip_ref = reference.state.positions[10];
    let mut errors = Vec::new();
    println!("| dt / explicit limit | steps | tip error (µm) | CG iterations (last step) |");
    for factor in [1.0, 10.0, 100.0, 1000.0] {
        let dt = factor * BENDING_LIMIT;
        let steps = (t / dt).round() as u64;
        let sim = run(&cantilever("integrator implicit tolerance 1e-12", dt, steps)).unwrap();
        let error = (sim.state.positions[10] - tip_ref).length();
        println!("| {factor} | {steps} | {error:.3e} | {} |", sim.reports.last_solve.iterations);
        errors.push(error);
    }
    for w in errors.windows(2) {
        let ratio = w[1] / w[0];
        assert!((4.0..25.0).contains(&ratio), "error ratio {ratio} per tenfold dt (errors {errors:?}): not first order");
    }
}

/// A pressurised, tense, bending-stiff cell (level-1 icosphere of R = 2 µm,
/// 42 nodes, stretched to axes 2.6, 2, 1.6 µm, drag 1 pN·s/µm per node)
/// with every body term: `turgor`, `surface_tension`, `area_conservation`
/// (per face and global) and `helfrich_bending`, at kT = 0, relaxed by
/// `integrator` at `dt`, before its first step.
fn deformed_cell(integrator: &str, dt: f64) -> Simulation {
    let cell =
        cellmd::build::icosphere_cell(&cellmd::build::IcosphereCell { level: 1, radius: 2.0, bond_type: None, ..Default::default() });
    let top = common::stretch_particles(&cell.text, DVec3::new(1.3, 1.0, 0.8));
    let ff = "particle node drag 1\nbody cell turgor k 1000 dp0 100 v0 33.5\nbody cell surface_tension gamma 100\n\
              body cell area_conservation ka 20 kl 50 a0 50\nbody cell helfrich_bending kappa 0.1\n";
    let deck = format!("units cell\ntopology c.top\nforcefield c.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntemperature 0\n{integrator}\ntimestep {dt}\nrun 0\n");
    let case = Case::new(&[("c.top", &top), ("c.ff", ff), ("deck.in", &deck)]);
    Simulation::before_first_run(&case.plan(), RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() }).unwrap()
}

/// Runs `sim` until max |F| < 1e-9 pN (checked every 50 steps).
fn relax(mut sim: Simulation) -> Simulation {
    loop {
        sim.run(50).unwrap();
        if sim.backend.forces.forces.iter().map(|f| f.length()).fold(0.0, f64::max) < 1e-9 {
            return sim;
        }
        assert!(sim.state.step < 200_000, "not relaxed after {} steps", sim.state.step);
    }
}

/// The shape of a body up to rigid motion: each node's distance from the
/// centroid, then each edge's length (the implicit step may turn the cell:
/// K̃ need not annihilate rotations away from equilibrium).
fn shape(sim: &Simulation) -> Vec<f64> {
    let x = &sim.state.positions;
    let centre = x.iter().sum::<DVec3>() / x.len() as f64;
    let edges = sim.model.bodies[0].mesh.edges().iter().map(|e| (x[e.ends[1] as usize] - x[e.ends[0] as usize]).length());
    x.iter().map(|p| (*p - centre).length()).chain(edges).collect()
}

/// A time step the explicit step is stable at for the cell below (it blows up at 0.05, asserted).
const EXPLICIT_DT: f64 = 5e-4;

/// A deformed pressurised cell relaxes to the same shape under the explicit
/// step below its stability limit and under the implicit step far above it
/// (CG and Cholesky, the latter through the Woodbury solve of the turgor and
/// area rank-one terms).
#[test]
fn a_deformed_pressurised_cell_relaxes_to_the_same_shape_under_both_integrators() {
    let explicit = relax(deformed_cell("integrator overdamped", EXPLICIT_DT));
    let start = shape(&deformed_cell("integrator overdamped", EXPLICIT_DT));
    let reference = shape(&explicit);
    let moved = start.iter().zip(&reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(moved > 0.2, "the cell hardly changed shape: {moved} µm");
    for (integrator, dt) in [("integrator implicit", 0.05), ("integrator implicit solver cholesky", 0.05), ("integrator implicit", 0.5)] {
        let sim = relax(deformed_cell(integrator, dt));
        let error = shape(&sim).iter().zip(&reference).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
        println!("{integrator} at dt = {dt}: {} steps (explicit: {} at {EXPLICIT_DT}), shape − explicit {error:.2e} µm (the shape moved {moved:.3} µm)", sim.state.step, explicit.state.step);
        // Both stop at max |F| < 1e-9 pN; the softest shape mode is ~1 pN/µm, so they may differ by ~1e-9 µm
        // (measured: 1.0e-11 at dt = 0.05, 3.4e-11 at dt = 0.5).
        assert!(error < 1e-9, "{integrator} at dt = {dt}: equilibrium shape differs by {error:e} µm");
    }
    // The explicit step at the implicit's dt blows up.
    let mut unstable = deformed_cell("integrator overdamped", 0.05);
    assert!(matches!(unstable.run(50), Err(RunError::Blowup { .. })), "the explicit step at dt = 0.05 should blow up");
}
