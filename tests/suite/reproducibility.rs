//! Bit-reproducibility: thread count and restarts (issue: engine core).

use crate::common::{position_bits, Case};

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
    assert_eq!(one.backend.forces.total_energy().to_bits(), two.backend.forces.total_energy().to_bits());
    assert_eq!(one.backend.forces.virial.map(f64::to_bits), two.backend.forces.virial.map(f64::to_bits));
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

/// A periodic cubic network of 20 × 20 × 27 = 10 800 beads (three blocks of
/// the backend's Newton scatter, so pair and bond forces cross blocks and
/// the periodic faces), numbered in a shuffled order so that most terms
/// join particles of different blocks.
fn network_case(extra: &str) -> Case {
    let (nx, ny, nz) = (20usize, 20usize, 27usize);
    let n = nx * ny * nz;
    // A fixed permutation of the lattice sites: id = 1 + (site·7919 mod n).
    let id = |x: usize, y: usize, z: usize| 1 + ((x + nx * (y + ny * z)) * 7919) % n;
    // Particles listed by id, so the internal order is the shuffled one.
    let mut particles = vec![String::new(); n];
    let mut bonds = String::from("[ bonds ]\n");
    for z in 0..nz {
        for y in 0..ny {
            for x in 0..nx {
                let jitter = |k: usize| 0.1 * (((x * 31 + y * 17 + z * 13 + k * 7) % 11) as f64 / 5.0 - 1.0);
                let (i, p) = (id(x, y, z), [x as f64 + jitter(0), y as f64 + jitter(1), z as f64 + jitter(2)]);
                particles[i - 1] = format!("{i} b {} {} {}\n", p[0], p[1], p[2]);
                bonds += &format!("s {} {}\n", id(x, y, z), id((x + 1) % nx, y, z));
                bonds += &format!("s {} {}\n", id(x, y, z), id(x, (y + 1) % ny, z));
                bonds += &format!("s {} {}\n", id(x, y, z), id(x, y, (z + 1) % nz));
            }
        }
    }
    let ff = "particle b drag 1\nbond s harmonic k 10 r0 1\npair b b soft A 1 rc 1.5\n";
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 {nx} p y 0 {ny} p z 0 {nz} p\nneighbor skin 0.5\n\
         temperature 0.1\ntimestep 0.005\nseed 7\n{extra}"
    );
    let top = String::from("[ particles ]\n") + &particles.concat() + &bonds;
    Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

#[test]
fn many_blocks_give_identical_bits_on_one_and_two_threads_and_across_a_restart() {
    let whole = network_case("run 40\nrun 40\n");
    let one = whole.run_with_threads(1);
    let two = whole.run_with_threads(2);
    assert!(one.model.len() > 2 * 4096);
    assert_eq!(position_bits(&one), position_bits(&two));
    assert_eq!(one.backend.forces.total_energy().to_bits(), two.backend.forces.total_energy().to_bits());
    assert_eq!(one.backend.forces.virial.map(f64::to_bits), two.backend.forces.virial.map(f64::to_bits));
    let first = network_case("run 40\nwrite_state half.state\n");
    first.run_with_threads(2);
    let second = network_case("read_state half.state\nrun 40\n");
    std::fs::copy(first.path("half.state"), second.path("half.state")).unwrap();
    let resumed = second.run_with_threads(1);
    assert_eq!(position_bits(&one), position_bits(&resumed));
    assert_ne!(position_bits(&one), position_bits(&network_case("").run_with_threads(1)), "the beads moved");
}
