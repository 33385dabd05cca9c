//! `constrain BONDTYPE`: inextensible bonds by overdamped SHAKE, with both
//! integrators.

use crate::common;

use crate::common::Case;
use cellmd::run::{RunOptions, Simulation};

/// A chain of `n` segments of 0.1 along x, its first `anchors` beads fixed
/// (1: pinned, 2: clamped), its tip pulled by `load` (pN) along (lx, ly, 0);
/// segments constrained.
fn chain(n: usize, anchors: usize, integrator: &str, dt: f64, steps: u64, load: (f64, f64)) -> Case {
    let (top, ff) = common::chain_of_rods(n, anchors);
    let deck = format!(
        "topology t.top\nforcefield f.ff\nbox x -2 2 f y -2 2 f z -2 2 f\ngroup tip id {}\n\
         external load tip constant_force fx {} fy {}\nconstrain rod tolerance 1e-10\n{integrator}\ntimestep {dt}\n\
         thermo 0 step pe ctension/rod\nrun {steps}\n",
        n + 1,
        load.0,
        load.1
    );
    Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)])
}

fn run(case: &Case) -> Simulation {
    Simulation::execute(case.plan(), RunOptions { output_dir: case.output_dir().to_path_buf(), ..Default::default() }).unwrap()
}

fn worst_length_error(sim: &Simulation) -> f64 {
    sim.model
        .bonds
        .iter()
        .map(|&[i, j]| ((sim.state.positions[j as usize] - sim.state.positions[i as usize]).length() / 0.1 - 1.0).abs())
        .fold(0.0, f64::max)
}

/// A bending cantilever with inextensible segments (soft bonds, k = 10, that
/// alone would stretch by 4 %): lengths hold to 1e-8 relative under both
/// integrators, and both reach the same equilibrium.
#[test]
fn constrained_lengths_hold_under_both_integrators() {
    let limit = 0.01 * 1e-3 / (8.0 * 0.01);
    let explicit = run(&chain(10, 2, "integrator overdamped", 0.4 * limit, 200_000, (0.0, 0.02)));
    let implicit = run(&chain(10, 2, "integrator implicit", 100.0 * limit, 1_000, (0.0, 0.02)));
    for (name, sim) in [("explicit", &explicit), ("implicit", &implicit)] {
        let error = worst_length_error(sim);
        println!("{name}: worst |r − r0|/r0 = {error:e}, tip at {}", sim.state.positions[10]);
        assert!(error < 1e-8, "{name}: segment length off by {error:e}");
    }
    let apart = explicit.state.positions.iter().zip(&implicit.state.positions).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
    assert!(apart < 1e-6, "explicit and implicit equilibria differ by {apart:e}");
    assert!(implicit.state.positions[10].y > 0.1, "the load barely bent the filament");
}

/// A chain pulled straight along its axis carries the load in every
/// segment: each constraint tension equals the pull (and the bonds' own
/// harmonic force is zero at r0).
#[test]
fn constraint_tension_carries_the_axial_load() {
    let load = 0.5;
    for (integrator, dt) in [("integrator overdamped", 1e-5), ("integrator implicit", 1e-2)] {
        let sim = run(&chain(10, 1, integrator, dt, 50, (load, 0.0)));
        let c = &sim.constraints;
        assert_eq!(c.tension.len(), 10);
        for (k, t) in c.tension.iter().enumerate() {
            assert!((t / load - 1.0).abs() < 1e-6, "{integrator}: segment {k}: tension {t}, pull {load}");
        }
        assert!(worst_length_error(&sim) < 1e-9);
    }
}

/// Two inextensible fibres (10 unit segments each, free joints) joined end
/// to end by a constrained crosslink of length 1.5, a third constrained
/// link from the joint to a free bead: the constraint graph is no chain
/// (three constraints meet at the first fibre's end), so the fibres are
/// solved as fibres and the links as couplings of one projection
/// (src/integrate/fibre/coupled.rs). The first fibre's root is fixed and
/// the second's tip pulled along the axis: every segment and the
/// crosslink carry the pull, the dangling link nothing, on both
/// integrators at a step of 0.025 (10 ms for actin's segments). Without
/// the coupled projection the run stopped at step 1 (`constraint … not met
/// after 1000 sweeps`); a projection that moved only the crosslink's ends
/// would leave the fibres' segments off their lengths.
#[test]
fn a_constrained_crosslink_between_fibres_carries_the_pull() {
    let load = 0.5;
    let mut top = String::from("[ particles ]\n1 anchor 0 0 0\n");
    for s in 1..=10 {
        top += &format!("{} bead {s} 0 0\n", s + 1);
    }
    for s in 0..=10 {
        top += &format!("{} bead {} 0 0\n", s + 12, 11.5 + s as f64);
    }
    top += "23 bead 10 1.5 0\n[ bonds ]\n";
    for s in 1..=10 {
        top += &format!("rod {s} {}\nrod {} {}\n", s + 1, s + 11, s + 12);
    }
    top += "link 11 12\nlink 11 23\n";
    let ff = "particle bead drag 1\nparticle anchor fixed\nbond rod harmonic k 10 r0 1\nbond link harmonic k 10 r0 1.5\n";
    for integrator in ["integrator overdamped", "integrator implicit"] {
        let deck = format!(
            "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 30 f y -5 5 f z -5 5 f\ngroup tip id 22\n\
             external load tip constant_force fx {load}\nconstrain rod tolerance 1e-10\nconstrain link tolerance 1e-10\n\
             {integrator}\ntimestep 0.025\nrun 40\n"
        );
        let sim = run(&Case::new(&[("t.top", &top), ("f.ff", ff), ("deck.in", &deck)]));
        let c = &sim.constraints;
        for (k, constraint) in c.list.iter().enumerate() {
            let [i, j] = sim.model.bonds[constraint.bond];
            let r = (sim.state.positions[j as usize] - sim.state.positions[i as usize]).length();
            assert!((r / constraint.length - 1.0).abs() < 1e-9, "{integrator}: bond {i}-{j} is {r}, held at {}", constraint.length);
            let expected = if [i, j] == [10, 22] { 0.0 } else { load };
            println!("{integrator}: bond {i}-{j}: tension {:.9}", c.tension[k]);
            assert!(
                (c.tension[k] - expected).abs() < 1e-6 * load,
                "{integrator}: bond {i}-{j}: tension {}, expected {expected}",
                c.tension[k]
            );
        }
    }
}
