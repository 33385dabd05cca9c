//! Time-dependent protocols end to end: parameter ramps over a run (bond,
//! body and external parameters), groups moved at constant velocity with
//! their reaction force, per-axis freezes at kT > 0 and in `minimize`, and
//! rest lengths reset to the current geometry. Every expectation is exact
//! arithmetic of the overdamped update, not a recorded output.

use crate::common::Case;
use cellmd::deck::{Group, GroupQuantity, ThermoColumn};

const TOP: &str = "[ particles ]\n1 p 0 0 0\n2 p 1.5 0 0\n3 q 5 5 5\n4 q 6 5 5\n[ bonds ]\ns 1 2\n";
const FF: &str = "particle p drag 2\nparticle q radius 0.5 viscosity 0.1\nbond s harmonic k 3 r0 1\n";
const DT: f64 = 0.001;

fn deck(body: &str) -> Case {
    let header = "units lj\ntopology t.top\nforcefield f.ff\nbox x -20 20 f y -20 20 f z -20 20 f\ntimestep 0.001\n";
    Case::new(&[("t.top", TOP), ("f.ff", FF), ("deck.in", &format!("{header}{body}"))])
}

fn gamma_q() -> f64 {
    6.0 * std::f64::consts::PI * 0.1 * 0.5
}

#[test]
fn a_ramped_force_grows_linearly_over_the_run_and_keeps_its_end_value() {
    let case =
        deck("group one id 3\nexternal pull one constant_force fx 0\nramp external pull fx 0 2\nrun 1000\nwrite_state a.state\nrun 1000\n");
    let sim = case.run();
    let mid = cellmd::output::restart::read_state(&case.path("a.state")).unwrap().to_state();
    // Step s of N uses F = 2·s/N: x = x0 + dt/γ · Σ 2s/N = x0 + dt/γ · (N − 1).
    let expected = 5.0 + DT / gamma_q() * 999.0;
    assert!((mid.positions[2].x - expected).abs() < 1e-12, "{} vs {expected}", mid.positions[2].x);
    // The next run keeps the end value, F = 2, for all its 1000 steps.
    let after = expected + DT / gamma_q() * 2.0 * 1000.0;
    assert!((sim.state.positions[2].x - after).abs() < 1e-12, "{} vs {after}", sim.state.positions[2].x);
    assert_eq!(sim.model.externals[0].term.params[0], 2.0);
    // Nothing else moved.
    assert_eq!(sim.state.positions[3], glam::DVec3::new(6.0, 5.0, 5.0));
}

#[test]
fn a_ramped_bond_stiffness_ends_at_its_end_value_and_the_plan_keeps_the_start() {
    let case = deck("ramp bond s k 3 30\nrun 10\n");
    let sim = case.run();
    assert_eq!(sim.model.bond_types[0].params[0], 30.0);
    assert_eq!(case.plan().model.bond_types[0].params[0], 3.0);
    // The first step used k = 3 (the force before any ramping): particle 1
    // moved by dt·k(r − r0)/γ = 0.001·3·0.5/2 in it; the rest is stiffer, so
    // the dimer relaxed further than it would at k = 3 throughout.
    let soft = deck("run 10\n").run();
    let r = |s: &cellmd::run::Simulation| (s.state.positions[1] - s.state.positions[0]).length();
    assert!(r(&sim) < r(&soft), "{} vs {}", r(&sim), r(&soft));
    let one = deck("ramp bond s k 3 30\nrun 1\n").run();
    assert!((one.state.positions[0].x - DT * 3.0 * 0.5 / 2.0).abs() < 1e-15);
}

#[test]
fn body_parameters_change_with_coeff_and_ramp() {
    let top = std::fs::read_to_string("tests/decks/bad/body_tetrahedron.top").unwrap();
    let ff = "particle bead drag 1\nbody cell turgor k 100 v0 0.2\n";
    let header = "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 5 f y -5 5 f z -5 5 f\ntimestep 0.0001\n";
    let body = "coeff body cell turgor v0 0.25\nrun 10\nramp body cell turgor k 100 50\nrun 10\n";
    let case = Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &format!("{header}{body}"))]);
    let sim = case.run();
    // turgor's parameters: k, dp0, v0.
    assert_eq!(sim.model.body_rules[0].params, vec![50.0, 0.0, 0.25]);
    assert_eq!(case.plan().model.body_rules[0].params, vec![100.0, 0.0, 0.2]);
    // Over the ramp the cell relaxed towards the new V0 with a softer K:
    // its volume moved from 0.1667 (the tetrahedron) towards 0.25.
    let mut sim = sim;
    let volume = sim.thermo_value(&ThermoColumn::BodyVolume(0)).unwrap();
    assert!(volume > 1.0 / 6.0, "volume {volume}");
}

#[test]
fn a_moved_group_moves_at_its_velocity_and_reports_the_drag_it_pulls() {
    // Particle 2 is dragged at v = 0.3 along x; particle 1 follows through
    // the bond, whose tension at steady state balances its drag γv.
    let case = deck("group drv id 2\nmove drv linear 0.3 0 0\nrun 20000\n");
    let mut sim = case.run();
    let x2 = 1.5 + 0.3 * DT * 20000.0;
    assert!((sim.state.positions[1].x - x2).abs() < 1e-9, "{}", sim.state.positions[1].x);
    assert_eq!(sim.state.positions[1].y, 0.0);
    let r = sim.state.positions[1].x - sim.state.positions[0].x;
    assert!((r - (1.0 + 2.0 * 0.3 / 3.0)).abs() < 1e-9, "stretch {r}");
    let reaction = sim
        .thermo_value(&ThermoColumn::Group { group: Group { name: "drv".into(), members: vec![1] }, quantity: GroupQuantity::Force(0) })
        .unwrap();
    assert!((reaction + 2.0 * 0.3).abs() < 1e-9, "reaction {reaction}");
}

#[test]
fn a_velocity_field_moves_each_particle_by_explicit_euler_steps_of_its_own_velocity() {
    // Particles 3 and 4 turn about the z axis (v = ω ẑ × x) while drifting up
    // at a speed that grows with time; each step is x += dt·v(x, t), t the
    // step's start, which this recursion repeats exactly.
    let body = "variable w equal 2\ngroup qs type q\nmove qs velocity \"-w*y\" \"w*x\" \"0.5*t\"\nrun 300\n";
    let sim = deck(body).run();
    for (k, start) in [(2, [5.0, 5.0, 5.0]), (3, [6.0, 5.0, 5.0])] {
        let mut x = glam::DVec3::from_array(start);
        for n in 0..300 {
            let t = n as f64 * DT;
            x += DT * glam::DVec3::new(-2.0 * x.y, 2.0 * x.x, 0.5 * t);
        }
        assert!((sim.state.positions[k] - x).length() < 1e-12, "particle {k}: {} vs {x}", sim.state.positions[k]);
    }
    // Turning by explicit Euler grows the radius by √(1 + (ω·dt)²) per step.
    let radius = sim.state.positions[2].truncate().length();
    let expected = 50f64.sqrt() * (1.0 + (2.0 * DT) * (2.0 * DT)).powf(150.0);
    assert!((radius - expected).abs() < 1e-9, "{radius} vs {expected}");
}

#[test]
fn group_extent_force_magnitudes_and_footprint_columns() {
    let mut sim = deck("group ends id 1 2 3\nrun 0\n").run();
    let mut column = |name: &str, quantity| {
        let members = vec![0, 1, 2];
        sim.thermo_value(&ThermoColumn::Group { group: Group { name: name.into(), members }, quantity }).unwrap()
    };
    // Particles at (0,0,0), (1.5,0,0), (5,5,5): x spans 5, z spans 5.
    assert_eq!(column("ends", GroupQuantity::Span(0)), 5.0);
    assert_eq!(column("ends", GroupQuantity::Span(2)), 5.0);
    // The xy footprint is the triangle (0,0), (1.5,0), (5,5): area 3.75.
    assert!((column("ends", GroupQuantity::HullArea) - 3.75).abs() < 1e-12);
    // The bond pulls 1 and 2 together with k(r − r0) = 1.5 each: Σ|f| = 3
    // while the summed vector force fx is 0.
    assert!((column("ends", GroupQuantity::ForceMagnitudes) - 3.0).abs() < 1e-12);
    assert!(column("ends", GroupQuantity::Force(0)).abs() < 1e-12);
}

#[test]
fn unmove_stops_the_motion() {
    let sim = deck("group one id 3\nmove one linear 1 -2 0.5\nrun 1000\nunmove one\nrun 1000\n").run();
    let expected = glam::DVec3::new(6.0, 3.0, 5.5);
    assert!((sim.state.positions[2] - expected).length() < 1e-12, "{}", sim.state.positions[2]);
}

#[test]
fn frozen_axes_stay_put_at_finite_temperature() {
    let sim = deck("temperature 1\nseed 7\nfreeze all z\ngroup pair id 1:2\nfreeze pair x\nrun 500\n").run();
    for (i, x) in sim.state.positions.iter().enumerate() {
        assert_eq!(x.z, [0.0, 0.0, 5.0, 5.0][i], "particle {i} left its plane");
    }
    // The pair is frozen in x too; the q particles move freely in x and y.
    assert_eq!((sim.state.positions[0].x, sim.state.positions[1].x), (0.0, 1.5));
    assert_ne!(sim.state.positions[0].y, 0.0);
    assert_ne!(sim.state.positions[2].x, 5.0);
    let free = deck("temperature 1\nseed 7\nfreeze all z\ngroup pair id 1:2\nfreeze pair x\nunfreeze pair\nrun 500\n").run();
    assert_ne!(free.state.positions[0].x, 0.0);
}

#[test]
fn minimize_respects_frozen_axes() {
    // The stretched dimer cannot relax along its only direction, x.
    let sim = deck("freeze all x\nminimize ftol 1e-8\n").run();
    assert_eq!(sim.state.positions[1].x, 1.5);
    let relaxed = deck("minimize ftol 1e-8\n").run();
    assert!(((relaxed.state.positions[1] - relaxed.state.positions[0]).length() - 1.0).abs() < 1e-6);
}

#[test]
fn reset_rest_makes_the_current_geometry_the_rest_state() {
    for which in ["s", "all"] {
        let mut sim = deck(&format!("reset_rest {which}\nrun 100\n")).run();
        // No force anywhere: nothing moved at kT = 0 and the energy is zero.
        assert_eq!(sim.state.positions[1].x, 1.5);
        assert_eq!(sim.thermo_value(&ThermoColumn::Pe).unwrap(), 0.0);
        assert_eq!(sim.state.bonds.as_ref().unwrap().rest[0], Some(1.5));
    }
    // A reset after relaxing to r0 = 1 and pulling to 1.8 keeps 1.8.
    let sim =
        deck("run 20000\ndisplace_atoms all move 0 0 0\ngroup two id 2\ndisplace_atoms two move 0.8 0 0\nreset_rest s\nrun 1000\n").run();
    let r = (sim.state.positions[1] - sim.state.positions[0]).length();
    assert!((r - 1.8).abs() < 1e-9, "{r}");
}

#[test]
fn an_indenter_driven_to_a_load_stops_there_and_reports_load_and_depth() {
    // A fixed particle at the origin; a sphere (R = 1, K = 10) above it at
    // z = 1.5 comes down at 1 µm/s until it carries 0.9: depth √(0.9/10) = 0.3,
    // i.e. the centre at z = 0.7 after 800 steps of 1 ms, where it holds.
    let top = "[ particles ]\n1 anchor 0 0 0\n2 p 5 5 5\n";
    let ff = "particle anchor fixed\nparticle p drag 1\n";
    let header = "units lj\ntopology t.top\nforcefield f.ff\nbox x -20 20 f y -20 20 f z -20 20 f\ntimestep 0.001\n";
    let body = "group a id 1\nexternal tip a indenter z 1.5 r 1 k 10\nindent tip velocity 0 0 -1 until 0.9\nrun 1000\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", &format!("{header}{body}"))]);
    let mut sim = case.run();
    let centre = sim.model.externals[0].term.params[2];
    assert!((centre - 0.7).abs() < 1.5e-3, "centre {centre}");
    let load = sim.thermo_value(&ThermoColumn::IndenterLoad("tip".into())).unwrap();
    let depth = sim.thermo_value(&ThermoColumn::IndenterDepth("tip".into())).unwrap();
    assert!((depth - (1.0 - centre)).abs() < 1e-12, "depth {depth} for centre {centre}");
    assert!((load - 10.0 * depth * depth).abs() < 1e-12, "load {load} at depth {depth}");
    assert!((0.9..=10.0 * 0.301 * 0.301 + 1e-9).contains(&load), "load {load}: reached within one step");
    // The anchor's reaction is the load.
    let reaction = sim
        .thermo_value(&ThermoColumn::Group { group: Group { name: "a".into(), members: vec![0] }, quantity: GroupQuantity::Force(2) })
        .unwrap();
    assert!((reaction + load).abs() < 1e-12, "reaction {reaction}");
    // Without `until` it keeps going; `indent tip stop` holds it.
    let body = "group a id 1\nexternal tip a indenter z 1.5 r 1 k 10\nindent tip velocity 0 0 -1\nrun 300\nindent tip stop\nrun 300\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", &format!("{header}{body}"))]);
    let sim = case.run();
    assert!((sim.model.externals[0].term.params[2] - 1.2).abs() < 1e-12);
}

#[test]
fn coeff_and_ramp_reach_externals_and_pair_rules() {
    // `coeff external` changes an active external between runs.
    let sim = deck("group one id 3\nexternal pull one constant_force fx 1\nrun 100\ncoeff external pull fx 3\nrun 100\n").run();
    let expected = 5.0 + DT / gamma_q() * (100.0 * 1.0 + 100.0 * 3.0);
    assert!((sim.state.positions[2].x - expected).abs() < 1e-12, "{}", sim.state.positions[2].x);
    // A pair parameter that leaves the cutoff alone ramps like any other.
    let ff = format!("{FF}pair q q soft_repulsion k 10 sigma 2\n");
    let header = "units lj\ntopology t.top\nforcefield f.ff\nbox x -20 20 f y -20 20 f z -20 20 f\ntimestep 0.001\n";
    let case = Case::new(&[("t.top", TOP), ("f.ff", &ff), ("deck.in", &format!("{header}ramp pair q q k 10 40\nrun 1\n"))]);
    let one = case.run();
    assert_eq!(one.model.pair_rules[0].params[0], 40.0);
    // Its only step used k = 10: the q pair 1 apart overlaps by 1 and pushes with 10.
    let expected = 5.0 - DT * 10.0 / gamma_q();
    assert!((one.state.positions[2].x - expected).abs() < 1e-14, "{} vs {expected}", one.state.positions[2].x);
}

#[test]
fn a_flat_punch_driven_to_a_load_stops_at_its_depth() {
    // The punch's face (radius 1, pushing along −z) starts 0.5 above a fixed
    // particle and comes down at 1 µm/s until it carries 0.9 = K·δ²: δ = 0.3.
    let top = "[ particles ]\n1 anchor 0 0 0\n2 p 5 5 5\n";
    let ff = "particle anchor fixed\nparticle p drag 1\n";
    let header = "units lj\ntopology t.top\nforcefield f.ff\nbox x -20 20 f y -20 20 f z -20 20 f\ntimestep 0.001\n";
    let body = "group a id 1\nexternal punch a flat_punch x 0.3 z 0.5 nz -1 a 1 k 10\nindent punch velocity 0 0 -1 until 0.9\nrun 1000\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", &format!("{header}{body}"))]);
    let mut sim = case.run();
    let face = sim.model.externals[0].term.params[2];
    let depth = sim.thermo_value(&ThermoColumn::IndenterDepth("punch".into())).unwrap();
    let load = sim.thermo_value(&ThermoColumn::IndenterLoad("punch".into())).unwrap();
    assert!((depth + face).abs() < 1e-12, "depth {depth} for the face at {face}");
    assert!((load - 10.0 * depth * depth).abs() < 1e-12 && (0.9..=10.0 * 0.301 * 0.301 + 1e-9).contains(&load), "load {load}");
}
