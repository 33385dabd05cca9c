//! Custom expressions in the engine: restating built-in laws as `custom`
//! lines gives the built-ins' forces and energies on the same system (to
//! 1e-14 of the largest force), and the same trajectory with the explicit
//! and the implicit step (which uses the symbolic d²E/dr²); `check
//! --selftest` runs the shared checks on a deck's custom terms.

use crate::common;

use std::process::Command;

use crate::common::{position_bits, Case};
use cellmd::run::{RunOptions, Simulation};
use glam::DVec3;

/// 300 particles in a periodic box with bonds, angles, two pair rules and
/// an external push; `ff_laws` gives the bond, angle and pair lines and
/// `external` the push.
fn case(ff_laws: &str, external: &str, run: &str) -> Case {
    let mut next = common::uniform(0x2545F4914F6CDD1D);
    let (n, l) = (300, 6.0);
    let mut top = String::from("[ particles ]\n");
    for id in 1..=n {
        let ty = if id % 3 == 0 { "b" } else { "a" };
        top += &format!("{id} {ty} {} {} {}\n", next() * l, next() * l, next() * l);
    }
    top += &common::pairs_and_triples(n);
    let ff = format!("particle a drag 1\nparticle b drag 2\n{ff_laws}");
    let deck = format!(
        "units lj\ntopology t.top\nforcefield f.ff\nbox x 0 {l} p y 0 {l} p z 0 {l} p\nneighbor skin 0.3\ntimestep 1e-3\n{external}\n{run}"
    );
    Case::new(&[("t.top", &top), ("f.ff", &ff), ("deck.in", &deck)])
}

const BUILT_IN: &str = "bond s harmonic k 20 r0 0.5\nangle t cosine_angle K 0.3\npair a a soft A 2 rc 0.8\npair a b soft A 1 rc 0.7\n";
const CUSTOM: &str = "bond s custom \"0.5*k*(r-r0)^2\" k 20 r0 0.5\nangle t custom \"K*(1+cos(theta))\" K 0.3\n\
                      pair a a custom \"A*(1+cos(pi*r/rc))\" cutoff 0.8 A 2 rc 0.8\npair a b custom \"A*(1+cos(pi*r/rc))\" cutoff 0.7 A 1 rc 0.7\n";
const PUSH: &str = "external push all constant_force fx 0.4";
const CUSTOM_PUSH: &str = "external push all custom \"-f*x\" f 0.4";

fn forces(case: &Case) -> (Vec<DVec3>, f64) {
    let mut sim = Simulation::before_first_run(&case.plan(), RunOptions::default()).unwrap();
    let f = sim.current_forces().unwrap();
    (f.forces.clone(), f.total_energy())
}

#[test]
fn custom_restatements_of_built_in_laws_give_their_forces() {
    let (fb, eb) = forces(&case(BUILT_IN, PUSH, "run 0\n"));
    let (fc, ec) = forces(&case(CUSTOM, CUSTOM_PUSH, "run 0\n"));
    let scale = fb.iter().map(|f| f.length()).fold(0.0, f64::max);
    assert!(scale > 1.0, "the system exerts forces");
    for (k, (a, b)) in fc.iter().zip(&fb).enumerate() {
        assert!((*a - *b).length() <= 1e-14 * scale, "particle {k}: custom {a} vs built-in {b}");
    }
    // The external's energy −f·x differs from constant_force's by its zero; the rest agrees.
    let (fb0, eb0) = forces(&case(BUILT_IN, "", "run 0\n"));
    let (_, ec0) = forces(&case(CUSTOM, "", "run 0\n"));
    assert!((ec0 - eb0).abs() <= 1e-14 * eb0.abs(), "energy: custom {ec0} vs built-in {eb0}");
    assert!(fb0.len() == fb.len() && (ec - ec0 - (eb - eb0)).is_finite());
}

#[test]
fn trajectories_agree_with_the_explicit_and_the_implicit_step() {
    for integrator in ["integrator overdamped", "integrator implicit"] {
        let run = format!("{integrator}\nrun 20\n");
        let built_in = case(BUILT_IN, PUSH, &run).run();
        let custom = case(CUSTOM, CUSTOM_PUSH, &run).run();
        let worst = built_in.state.positions.iter().zip(&custom.state.positions).map(|(a, b)| (*a - *b).length()).fold(0.0, f64::max);
        assert!(worst < 1e-12, "{integrator}: positions differ by {worst}");
        // Bit-identical across thread counts, as every law.
        let c = case(CUSTOM, CUSTOM_PUSH, &run);
        assert_eq!(position_bits(&c.run_with_threads(1)), position_bits(&c.run_with_threads(2)), "{integrator}");
    }
}

/// Custom bonds, angles, pairs and externals run on the GPU (generated
/// WGSL), an external that reads `t` too, like every external with an
/// expression parameter. (GPU parity: `tests/suite/gpu.rs`.)
#[test]
fn custom_terms_are_not_cpu_only_even_where_an_external_reads_time() {
    let sim = Simulation::before_first_run(&case(CUSTOM, CUSTOM_PUSH, "run 0\n").plan(), RunOptions::default()).unwrap();
    assert_eq!(sim.cpu_only_feature(), None);
    let timed = case(CUSTOM, "external push all custom \"-f*x*t\" f 0.4", "run 0\n");
    let sim = Simulation::before_first_run(&timed.plan(), RunOptions::default()).unwrap();
    assert!(!sim.model.externals[0].expressions.is_empty(), "reading t makes an expression parameter");
    assert_eq!(sim.cpu_only_feature(), None);
}

#[test]
fn check_selftest_runs_the_shared_checks_on_every_custom_term() {
    let c = case(
        &format!("{CUSTOM}bond u custom \"k*(r>r0)*(r-r0)^3\" k 5 r0 0.4\npair b b custom \"A*(1-r)\" cutoff 0.5 A 1\n"),
        CUSTOM_PUSH,
        "run 0\n",
    );
    let out = Command::new(env!("CARGO_BIN_EXE_cellmd")).arg("check").arg("--selftest").arg(c.path("deck.in")).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    for line in [
        "selftest: pair a a custom: ok at 4 geometries; E and F continuous at the cutoff",
        "selftest: bond s custom: ok",
        "selftest: angle t custom: ok",
        "selftest: pair a b custom: ok",
        "selftest: external push custom: ok",
        "selftest: pair b b custom: ok at 4 geometries; warning: truncated at the cutoff with E = 5.000000000005e-1, dE/dr = -1e0 just inside",
        "selftest: 7 custom term(s) pass",
    ] {
        assert!(stdout.contains(line), "stdout lacks `{line}`:\n{stdout}");
    }
}

/// Every `check` (and `run`) warns, at the law's label, of a custom law that
/// is not finite where the deck starts or at its declared rest value, and of
/// a pair law truncated at its cutoff; a law that is fine says nothing.
#[test]
fn custom_laws_not_finite_where_the_deck_starts_or_truncated_at_the_cutoff_warn() {
    let laws = "bond s custom \"k*ln(r-r0)\" k 1 r0 0.5\nangle t custom \"K*ln(1-cos(theta-theta0))\" K 1 theta0 90deg\n\
                pair a a custom \"A*(1+cos(pi*r/rc))\" cutoff 0.8 A 2 rc 0.8\npair b b custom \"A*(1-r)\" cutoff 0.5 A 1\n";
    let c = case(laws, "external sink all custom \"f*sqrt(x-3)\" f 1", "run 0\n");
    let out = Command::new(env!("CARGO_BIN_EXE_cellmd")).arg("check").arg(c.path("deck.in")).output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    for warning in [
        "f.ff:3:6: warning: bond `s` (custom): E = -inf, dE/dr = inf at its rest length r0 (r = 5e-1)",
        "f.ff:4:7: warning: angle `t` (custom): not finite at its rest angle theta0 = 90.000000°",
        "warning: external `sink` (custom): not finite at the initial position of particle",
        "f.ff:6:6: warning: pair b b (custom): truncated at the cutoff with E = 5.000000000005e-1, dE/dr = -1e0 just inside; \
         the dynamics feel the jump",
    ] {
        assert!(stderr.contains(warning), "stderr lacks `{warning}`:\n{stderr}");
    }
    assert_eq!(stderr.matches("warning").count(), 4, "{stderr}");
}
