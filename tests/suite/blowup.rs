//! A run that blows up stops with the step, the particle and the interaction
//! responsible, writes the last good frame, and leaves complete output files.

use crate::common::Case;
use cellmd::deck::validate_file;
use cellmd::run::{RunError, RunOptions, Simulation};

fn run_to_error(case: &Case) -> RunError {
    let plan = validate_file(&case.path("deck.in"), &[]).unwrap();
    match Simulation::execute(plan, RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() }) {
        Ok(_) => panic!("the run should blow up"),
        Err(e) => e,
    }
}

/// Frames (steps) in an MCAP file, read back through the summary-independent stream.
fn mcap_frame_steps(path: &std::path::Path) -> Vec<u64> {
    let bytes = std::fs::read(path).unwrap();
    // A file without its footer (truncated) fails to read in mcap::read::Summary.
    assert!(mcap::Summary::read(&bytes).unwrap().is_some(), "no summary: the MCAP was not finished");
    mcap::MessageStream::new(&bytes)
        .unwrap()
        .map(|m| m.unwrap())
        .filter(|m| m.channel.topic == "/cellmd/frame")
        .map(|m| cellmd::output::mcap_messages::message_json(&m).unwrap()["step"].as_u64().unwrap())
        .collect()
}

#[test]
fn runaway_displacement_is_diagnosed() {
    // Two LJ particles placed far inside the core: the first step launches them.
    let top = "[ particles ]\n1 p 0 0 0\n2 p 0.55 0 0\n3 p 5 5 5\n";
    let ff = "particle p drag 1\npair p p lj epsilon 1 sigma 1 rc 2.5\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntimestep 0.01\n\
                integrator overdamped max_displacement 0.5\ndump traj every 1 mcap traj.mcap\ndump x every 1 xyz traj.xyz\nrun 100\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", deck)]);
    let error = run_to_error(&case);
    let RunError::Blowup { step, particle_id, culprit, last_good, .. } = &error else { panic!("{error}") };
    assert_eq!(*step, 0, "{error}");
    assert_eq!(*particle_id, 1);
    let culprit = culprit.as_ref().unwrap();
    assert_eq!((culprit.kind, culprit.interaction), ("pair", "lj"));
    let message = error.to_string();
    assert!(message.contains("step 0") && message.contains("particle 1") && message.contains("(lj)"), "{message}");
    assert!(last_good.iter().any(|p| p.ends_with("deck.lastgood.restart")), "{message}");
    // The last good frame is the unchanged initial configuration.
    let restart = cellmd::output::restart::read_state(&case.path("deck.lastgood.restart")).unwrap();
    assert_eq!(restart.to_state().positions[1].x, 0.55);
    assert_eq!(mcap_frame_steps(&case.path("traj.mcap")), vec![0]);
    assert_eq!(std::fs::read_to_string(case.path("traj.xyz")).unwrap().lines().count(), 5);
}

#[test]
fn non_finite_force_names_the_bond() {
    // A FENE bond pulled past its maximum extent R0 by a constant force in one
    // step (the displacement bound is raised so the bond, not the bound, trips).
    let top = "[ particles ]\n1 p 0 0 0\n2 p 1 0 0\n[ bonds ]\nchain 1 2\n";
    let ff = "particle p drag 1\nbond chain fene K 30 R0 1.5 epsilon 1 sigma 1\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntimestep 0.01\n\
                integrator overdamped max_displacement 100\ngroup end id 2\nexternal pull end constant_force fx 500\n\
                dump traj every 5 mcap traj.mcap\nrun 1000\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", deck)]);
    let error = run_to_error(&case);
    let RunError::Blowup { step, culprit, what, .. } = &error else { panic!("{error}") };
    assert_eq!(*step, 1, "{error}");
    assert!(what.contains("non-finite force"), "{error}");
    assert_eq!(culprit.as_ref().unwrap().interaction, "fene", "{error}");
    // Dumped at step 0, then the frame at which the force became non-finite.
    assert_eq!(mcap_frame_steps(&case.path("traj.mcap")), vec![0, 1]);
}

/// Two particles that meet on a slack cable (bonded, so no pair repulsion)
/// feel no force from it: r = 0 with dE/dr = 0 is not a blow-up. The same
/// pair on a harmonic bond with r0 > 0 has no defined direction: refused at
/// `check`, naming the particles (issue 21; it stopped at step 0 before).
#[test]
fn coincident_particles_on_a_slack_bond_are_not_a_blowup() {
    let top = "[ particles ]\n1 a 1 1 1\n2 a 1 1 1\n[ bonds ]\ns 1 2\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 5 f y 0 5 f z 0 5 f\ntimestep 0.01\nrun 5\n";
    let slack = Case::new(&[("t.top", top), ("f.ff", "particle a drag 1\nbond s cable k 10 r0 1\n"), ("deck.in", deck)]);
    let sim = slack.run();
    assert!(sim.state.positions.iter().all(|x| *x == glam::DVec3::ONE), "{:?}", sim.state.positions);
    let stretched = Case::new(&[("t.top", top), ("f.ff", "particle a drag 1\nbond s harmonic k 10 r0 1\n"), ("deck.in", deck)]);
    let error = validate_file(&stretched.path("deck.in"), &[]).expect_err("refused").to_string();
    assert!(error.ends_with("t.top:5:1: bond `s` joins particles 1 and 2 at the same position, where its law `harmonic` exerts a force of undefined direction; expected bonded particles apart"), "{error}");
}

#[test]
fn a_collapsed_cell_names_its_body_term() {
    // A tetrahedral cell under the log-law turgor, crushed through itself by
    // a strong surface tension in one step: its volume turns negative, the log
    // law has no pressure there, and the report names the body term.
    let top = "[ particles ]\n1 p 0 0 0\n2 p 1 0 0\n3 p 0 1 0\n4 p 0 0 1\n[ bodies ]\n1 cell\n[ triangles ]\n1 1 3 2\n1 1 2 4\n1 2 3 4\n1 3 1 4\n";
    let ff = "particle p drag 1\nbody cell turgor_log k 1 v0 0.1667\nbody cell surface_tension gamma 100\n";
    // The box leaves room for the crushed cell: a particle leaving a fixed
    // box would stop the run first, as lost.
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -100 100 f y -100 100 f z -100 100 f\ntimestep 0.1\n\
                integrator overdamped max_displacement 1000\nrun 10\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", deck)]);
    let error = run_to_error(&case);
    let RunError::Blowup { step, culprit, .. } = &error else { panic!("{error}") };
    assert_eq!(*step, 1, "{error}");
    let culprit = culprit.as_ref().unwrap();
    assert_eq!((culprit.kind, culprit.label.as_str(), culprit.interaction), ("body", "cell", "turgor_log"), "{error}");
    assert!(error.to_string().contains("non-finite force; largest force on it from body `cell` (turgor_log)"), "{error}");
}

#[test]
fn an_inverted_volume_element_names_its_element() {
    // A neo-Hookean tetrahedron whose apex is pushed through its base in one
    // step: det F < 0, where the law has no energy. The run stops at that
    // step naming the element and its type, and writes no NaN.
    let top = "[ particles ]\n1 p 0 0 0\n2 p 1 0 0\n3 p 0 1 0\n4 p 0 0 1\n[ tetrahedra ]\nsolid 1 2 3 4\n";
    let ff = "particle p drag 1\ntetra solid neo_hookean e 10 nu 0.3\n";
    let deck = "units lj\ntopology t.top\nforcefield f.ff\nbox x -10 10 f y -10 10 f z -10 10 f\ntimestep 0.01\n\
                integrator overdamped max_displacement 100\ngroup apex id 4\nexternal push apex constant_force fz -300\n\
                dump x every 1 xyz traj.xyz\nrun 10\n";
    let case = Case::new(&[("t.top", top), ("f.ff", ff), ("deck.in", deck)]);
    let error = run_to_error(&case);
    let RunError::Blowup { step, culprit, .. } = &error else { panic!("{error}") };
    assert_eq!(*step, 1, "{error}");
    let culprit = culprit.as_ref().unwrap();
    assert_eq!((culprit.kind, culprit.interaction), ("tetra", "neo_hookean"), "{error}");
    assert_eq!(culprit.label, "solid element 1 of particles 1–2–3–4, turned inside out (det F ≤ 0)", "{error}");
    let xyz = std::fs::read_to_string(case.path("traj.xyz")).unwrap();
    assert!(!xyz.to_lowercase().contains("nan"), "{xyz}");
}
