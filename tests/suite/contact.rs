//! Contact between cells (`contact_barrier`, issue #7): two pressurised
//! icosphere cells pressed together never interpenetrate.
//!
//! - At every step the smallest node–face distance between the cells,
//!   computed here by brute force over all node × face pairs, stays > 0,
//!   and the engine's `mindist` equals it whenever it is below d̂.
//! - The cells flatten against each other (a contact patch of many nodes).
//! - The step clamp acts (and keeps the distance positive) when the time step
//!   is too large for the barrier, with noise too.
//! - The implicit integrator (step clamp, the barrier's and the cells' stiffness blocks)
//!   and FIRE (step clamp) squeeze meshed cells together between plates
//!   without interpenetration, and settle.
//! - Runs are bit-identical on 1 and 2 threads; the GPU backend takes
//!   `contact_barrier` (tests/suite/gpu.rs compares it with the CPU).
//! - `topologies/cell_contact.top` is two `cellmd build icosphere` cells merged.

use crate::common::{merge_topologies, position_bits, squeezed_cells, two_cells, Case};
use cellmd::build::{icosphere_cell, IcosphereCell};
use cellmd::deck::validate_file;
use cellmd::integrate::fire::FireSettings;
use cellmd::mesh::point_triangle;
use cellmd::run::{RunOptions, Simulation};
use glam::DVec3;

const SHELLS: &str = "body cell turgor k 1000 dp0 100 v0 32.4\nbody cell surface_tension gamma 100\n";
const BARRIER: &str = "contact cell cell contact_barrier dhat 0.1 kappa 200\n";

/// Two 162-node cells (R = 2 µm, 0.1 µm apart) with force-field lines `ff`
/// (after `particle node drag 1`), pushed together by `push` pN per node.
fn case_with(ff: &str, push: f64, settings: &str) -> Case {
    case_on(&two_cells(2, 2.0, 0.1), ff, push, settings)
}

/// As [`case_with`] on topology `top`.
fn case_on(top: &str, ff: &str, push: f64, settings: &str) -> Case {
    let deck = format!(
        "units cell\ntopology cells.top\nforcefield cells.ff\nbox x -10 10 f y -10 10 f z -10 10 f\n\
         group left id 1:162\ngroup right id 163:324\n\
         external push_left left constant_force fx {push}\nexternal push_right right constant_force fx -{push}\n{settings}"
    );
    Case::new(&[("cells.top", top), ("cells.ff", &format!("particle node drag 1\n{ff}")), ("deck.in", &deck)])
}

/// Pressurised, tense cells with the barrier between them.
fn pressed_case(push: f64, settings: &str) -> Case {
    case_with(&format!("{SHELLS}{BARRIER}"), push, settings)
}

/// The smallest distance from a node of one body to a face of the other, over
/// all pairs, negative when a node is inside the other cell (on the inner side
/// of its closest face: the cells stay convex enough for that to decide).
fn brute_force_min_distance(sim: &Simulation) -> f64 {
    let x = &sim.state.positions;
    let mut min = f64::INFINITY;
    for (a, b) in [(0, 1), (1, 0)] {
        let (nodes, faces) = (&sim.model.bodies[a], &sim.model.bodies[b]);
        for &p in &nodes.nodes {
            let (mut closest, mut side) = (f64::INFINITY, 1.0);
            for t in faces.mesh.triangles() {
                let corners = t.map(|k| x[faces.nodes[k as usize] as usize]);
                let pt = point_triangle(x[p as usize], corners);
                if pt.distance < closest {
                    let outward = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
                    (closest, side) = (pt.distance, pt.normal.dot(outward).signum());
                }
            }
            min = min.min(side * closest);
        }
    }
    min
}

/// Runs `steps` single steps, checking the distance after each; returns the
/// smallest distance seen.
fn run_checking_every_step(sim: &mut Simulation, steps: u64, dhat: f64) -> f64 {
    let mut smallest = f64::INFINITY;
    for _ in 0..steps {
        sim.run(1).unwrap();
        let exact = brute_force_min_distance(sim);
        assert!(exact > 0.0, "step {}: the cells interpenetrate (min distance {exact:e})", sim.state.step);
        if exact < dhat {
            // Equal up to rounding (the engine measures around each face's first corner).
            let reported = sim.min_contact_distance();
            assert!((reported - exact).abs() <= 1e-12 * exact, "step {}: mindist {reported:e}, brute force {exact:e}", sim.state.step);
        }
        smallest = smallest.min(exact);
    }
    smallest
}

fn width_along_x(sim: &Simulation, body: usize) -> f64 {
    let xs = sim.model.bodies[body].nodes.iter().map(|&p| sim.state.positions[p as usize].x);
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
    hi - lo
}

#[test]
fn pressed_cells_flatten_against_each_other_without_touching() {
    let case = pressed_case(2.0, "temperature 0\ntimestep 1e-3\nrun 0\n");
    let plan = case.plan();
    let mut sim =
        Simulation::before_first_run(&plan, RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() }).unwrap();
    let width0 = width_along_x(&sim, 0);
    let smallest = run_checking_every_step(&mut sim, 1500, 0.1);
    // A flat patch: many nodes of each cell within d̂ of the other cell.
    let x = &sim.state.positions;
    let near = |a: usize, b: usize| {
        let faces = &sim.model.bodies[b];
        sim.model.bodies[a]
            .nodes
            .iter()
            .filter(|&&p| {
                faces
                    .mesh
                    .triangles()
                    .iter()
                    .any(|t| point_triangle(x[p as usize], t.map(|k| x[faces.nodes[k as usize] as usize])).distance < 0.1)
            })
            .count()
    };
    let (patch, width) = (near(0, 1).min(near(1, 0)), width_along_x(&sim, 0));
    println!("smallest distance {smallest:.4e} µm, final {:.4e} µm, contact patch {patch} nodes, width {width0:.4} → {width:.4} µm, {} clamped steps", sim.min_contact_distance(), sim.reports.contact_clamps);
    assert!(patch >= 7, "no flat contact patch: {patch} nodes within d̂");
    assert!(width < width0 - 0.05, "the cell did not flatten: width {width0} → {width}");
    assert!(sim.backend.forces.energy_by_interaction.iter().sum::<f64>().is_finite());
}

#[test]
fn the_step_clamp_keeps_a_too_large_step_from_jumping_through() {
    // Without the clamp a node would move 0.5 µm a step: five times d̂.
    let case = pressed_case(50.0, "temperature 0.0041\nseed 7\ntimestep 1e-2\nrun 0\n");
    let plan = case.plan();
    let mut sim =
        Simulation::before_first_run(&plan, RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() }).unwrap();
    let smallest = run_checking_every_step(&mut sim, 200, 0.1);
    println!("smallest distance {smallest:.4e} µm, {} of 200 steps clamped, time {:.4e} s", sim.reports.contact_clamps, sim.state.time);
    assert!(sim.reports.contact_clamps > 0, "the clamp never acted");
    assert!(sim.state.time < 200.0 * 1e-2, "clamped steps advance time by less than dt");
}

/// Steps the clamp shortens advance bond ages and stamp kinetic events by
/// their actual length: a tethered pair beside the pressed cells carries
/// bonds that never break (their age must equal the run's time, the sum of
/// the actual step lengths) and bonds that break fast (each event's time must
/// be the thermo time of its step).
#[test]
fn clamped_steps_age_bonds_and_stamp_events_by_their_actual_length() {
    let tether = "[ particles ]\n1001 anchor 8 8 8\n1002 anchor 8 8 9\n[ bonds ]\n";
    let bonds = "slow 1001 1002\n".repeat(20) + &"fast 1001 1002\n".repeat(200);
    let top = merge_topologies(&[&two_cells(2, 2.0, 0.1), &format!("{tether}{bonds}")]);
    let ff = format!(
        "{SHELLS}{BARRIER}particle anchor fixed\nbond slow harmonic k 1 r0 1 kinetics slip k0 1e-9 x_beta 1e-3\n\
         bond fast harmonic k 1 r0 1 kinetics slip k0 20 x_beta 1e-3\n"
    );
    let settings = "temperature 0.0041\nseed 7\ntimestep 1e-2\nevents events.csv\nthermo 1 step time\nthermo_file thermo.csv\nrun 200\n";
    let case = case_on(&top, &ff, 50.0, settings);
    let sim = case.run();
    assert!(sim.reports.contact_clamps > 0, "the clamp never acted");
    assert!(sim.state.time < 200.0 * 1e-2, "clamped steps advance time by less than dt");
    let bonds = sim.state.bonds.as_ref().unwrap();
    let is_slow = |b: usize| sim.model.bond_types[sim.model.bond_type[b] as usize].label.text == "slow";
    let slow: Vec<usize> = (0..sim.model.bonds.len()).filter(|&b| is_slow(b)).collect();
    assert_eq!(slow.len(), 20);
    for b in slow {
        assert!(bonds.bound[b]);
        assert_eq!(bonds.age[b], sim.state.time, "bond {b}: age {} after {} s of partly clamped steps", bonds.age[b], sim.state.time);
    }
    let thermo: std::collections::HashMap<u64, f64> = std::fs::read_to_string(case.path("thermo.csv"))
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (f[0].parse().unwrap(), f[1].parse().unwrap())
        })
        .collect();
    let mut events = 0;
    for row in std::fs::read_to_string(case.path("events.csv")).unwrap().lines().skip(1) {
        let f: Vec<&str> = row.split(',').collect();
        let (step, time): (u64, f64) = (f[0].parse().unwrap(), f[1].parse().unwrap());
        assert_eq!(time, thermo[&step], "event at step {step}: time {time}, thermo time {}", thermo[&step]);
        events += 1;
    }
    println!("{} of 200 steps clamped, {events} events", sim.reports.contact_clamps);
    assert!(events > 50, "too few events to test: {events}");
}

#[test]
fn contact_runs_are_bit_identical_on_one_and_two_threads() {
    let case = pressed_case(5.0, "temperature 0.0041\nseed 3\ntimestep 1e-3\nthermo 100 step pe mindist nclamp\nrun 300\n");
    let (one, two) = (case.run_with_threads(1), case.run_with_threads(2));
    assert_eq!(position_bits(&one), position_bits(&two));
    assert_eq!(one.backend.forces.total_energy().to_bits(), two.backend.forces.total_energy().to_bits());
    assert_eq!(one.backend.forces.virial.map(f64::to_bits), two.backend.forces.virial.map(f64::to_bits));
    assert!(one.min_contact_distance() < 0.1, "the cells never came into contact");
}

/// A simulation of `case` before its first run, writing into its output directory.
fn simulation(case: &Case) -> Simulation {
    Simulation::before_first_run(&case.plan(), RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() }).unwrap()
}

/// Squeezes the cells with `integrator implicit` at time step `dt` for 2.4 s,
/// checking after every step that they stay apart; returns the smallest
/// distance, the clamped steps and the final max |F| (pN).
fn implicit_squeeze(dt: f64) -> (f64, u64, f64) {
    let mut sim = simulation(&squeezed_cells(&format!("integrator implicit\ntemperature 0\ntimestep {dt}\nrun 0\n")));
    let smallest = run_checking_every_step(&mut sim, (2.4 / dt).round() as u64, 0.1);
    assert!(sim.min_contact_distance() < 0.1, "dt = {dt}: the barrier never acted");
    (smallest, sim.reports.contact_clamps, sim.backend.forces.forces.iter().map(|f| f.length()).fold(0.0, f64::max))
}

#[test]
fn implicit_steps_keep_squeezed_cells_apart_and_settle() {
    // Without stiffness blocks for the cells' turgor and tension the implicit step settled
    // (max |F| < 0.05 pN after 2.4 s) up to dt = 4e-3 and chattered against the barrier at
    // 5e-3 (max |F| ≈ 10 pN, nearly every step clamped). With them it settles up to 3e-2;
    // asserted at 3× the old limit (measured: final max |F| 2.2e-2 pN, 10 clamped steps).
    let (smallest, clamps, residual) = implicit_squeeze(1.2e-2);
    println!("implicit, dt = 1.2e-2: smallest distance {smallest:.4e} µm, {clamps} clamped steps, final max |F| {residual:.3e} pN");
    assert!(residual < 0.05, "the implicit run did not settle: max |F| = {residual} pN");
}

/// The table behind the test above (`cargo test --release --test suite contact:: -- --ignored --nocapture`).
#[test]
#[ignore]
fn implicit_squeeze_time_step_table() {
    println!("| dt (s) | steps | smallest distance (µm) | clamped steps | max |F| after 2.4 s (pN) |\n|---|---|---|---|---|");
    for dt in [3e-3, 4e-3, 5e-3, 8e-3, 1.2e-2, 2e-2, 3e-2, 4e-2, 6e-2, 1e-1] {
        let (smallest, clamps, residual) = implicit_squeeze(dt);
        println!("| {dt:.1e} | {} | {smallest:.3e} | {clamps} | {residual:.2e} |", (2.4 / dt).round());
    }
}

#[test]
fn fire_relaxes_squeezed_cells_without_interpenetration() {
    let mut sim = simulation(&squeezed_cells("temperature 0\ntimestep 1e-3\nrun 0\n"));
    sim.minimize(&FireSettings { ftol: 1e-2, max_iterations: 30_000, dmax: 0.05, ..Default::default() }).unwrap();
    let report = sim.reports.last_minimize.clone().unwrap();
    let exact = brute_force_min_distance(&sim);
    println!("FIRE: {report:?}, min distance {exact:.4e} µm");
    assert!(report.converged, "{report:?}");
    assert!(report.clamped > 0, "the clamp never acted: {report:?}");
    assert!(exact > 0.0 && exact < 0.1, "FIRE: min distance {exact:e}");
}

#[test]
fn the_gpu_takes_the_barrier() {
    // Bodies with contact terms only (no `body` lines), so contact is the only feature that could be refused.
    let case = case_with(BARRIER, 1.0, "temperature 0\ntimestep 1e-3\nrun 0\n");
    let sim = Simulation::before_first_run(&case.plan(), RunOptions::default()).unwrap();
    assert_eq!(sim.cpu_only_feature(), None);
}

/// `topologies/cell_contact.top` is two `cellmd build icosphere` cells merged
/// (regenerate with `CELLMD_WRITE_TOPOLOGY=1 cargo test --test suite contact::the_cell_contact_topology`).
#[test]
fn the_cell_contact_topology_is_two_icosphere_builds() {
    let left = IcosphereCell { level: 3, radius: 3.0, centre: DVec3::new(-3.06, 0.0, 0.0), ..Default::default() };
    let right = IcosphereCell { centre: DVec3::new(3.06, 0.0, 0.0), body_id: 2, first_id: 643, ..left.clone() };
    let text = merge_topologies(&[&icosphere_cell(&left).text, &icosphere_cell(&right).text]);
    let path = "topologies/cell_contact.top";
    if std::env::var_os("CELLMD_WRITE_TOPOLOGY").is_some() {
        std::fs::write(path, &text).unwrap();
    }
    assert!(std::fs::read_to_string(path).unwrap() == text, "{path} is not the two builds; regenerate with CELLMD_WRITE_TOPOLOGY=1");
    let plan = validate_file(std::path::Path::new("inputs/cell_contact.in"), &[]).unwrap();
    assert_eq!(plan.model.bodies.len(), 2);
    assert_eq!(plan.model.bodies[1].nodes.len(), 642);
}
