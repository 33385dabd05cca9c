//! Composition: several `topology` lines make one system with offset particle
//! and body ids and shared type names.

use crate::common::Case;

const DIMER: &str = "[ particles ]\n1 p 0 0 0\n2 p 1.5 0 0\n[ bonds ]\ns 1 2\n";
const BEAD: &str = "[ particles ]\n1 q 0 3 0\n";
const FF: &str = "particle p drag 2\nparticle q drag 1\nbond s harmonic k 3 r0 1\n";

fn deck(topologies: &str, body: &str) -> Case {
    let header = format!("units lj\n{topologies}forcefield f.ff\nbox x -20 20 f y -20 20 f z -20 20 f\ntimestep 0.001\n");
    Case::new(&[("d.top", DIMER), ("b.top", BEAD), ("f.ff", FF), ("deck.in", &format!("{header}{body}"))])
}

#[test]
fn later_topologies_follow_the_earlier_ids_and_share_type_names() {
    let case = deck("topology d.top\ntopology b.top\ntopology d.top\n", "group second id 4:5\nrun 0\n");
    let plan = case.plan();
    let m = &plan.model;
    assert_eq!(m.ids, vec![1, 2, 3, 4, 5]);
    assert_eq!(m.type_names, vec!["p".to_string(), "q".to_string()]);
    assert_eq!(m.types, vec![0, 0, 1, 0, 0]);
    assert_eq!(m.bonds, vec![[0, 1], [3, 4]]);
    assert_eq!(m.bond_type, vec![0, 0]);
    // Both dimers relax to r0 = 1 independently.
    let sim = deck("topology d.top\ntopology b.top\ntopology d.top\n", "run 20000\n").run();
    let r = |i: usize, j: usize| (sim.state.positions[j] - sim.state.positions[i]).length();
    assert!((r(0, 1) - 1.0).abs() < 1e-12 && (r(3, 4) - 1.0).abs() < 1e-12);
}

#[test]
fn an_explicit_offset_places_the_ids() {
    let plan = deck("topology d.top offset 100\ntopology d.top offset 10\n", "run 0\n").plan();
    assert_eq!(plan.model.ids, vec![101, 102, 11, 12]);
}

#[test]
fn bodies_of_several_topologies_get_distinct_ids() {
    let cell = std::fs::read_to_string("tests/decks/bad/body_tetrahedron.top").unwrap();
    let header = "units lj\ntopology c.top\ntopology c.top\nforcefield f.ff\nbox x -5 5 f y -5 5 f z -5 5 f\ntimestep 0.001\n";
    let case = Case::new(&[
        ("c.top", &cell),
        ("f.ff", "particle bead drag 1\nbody cell turgor k 100 v0 0.2\n"),
        ("deck.in", &format!("{header}run 0\n")),
    ]);
    let m = case.plan().model;
    assert_eq!(m.bodies.iter().map(|b| b.id).collect::<Vec<_>>(), vec![1, 2]);
    assert_eq!(m.bodies[1].nodes, vec![4, 5, 6, 7]);
    assert_eq!(m.triangle_body[4..], [2, 2, 2, 2]);
}
