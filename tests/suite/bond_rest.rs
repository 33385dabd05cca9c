//! Bonds with their own rest lengths (`type i j r0` in the topology, and
//! `cellmd build … --rest-from-geometry`).
//!
//! The oracle for the engine is the same system written with one bond type
//! per bond (each type's `r0` = that bond's own): forces, energies and whole
//! runs (explicit, implicit, FIRE, constrained) must be bit-identical.

use crate::common;

use std::path::Path;
use std::process::Command;

use crate::common::Case;
use cellmd::deck::{validate_file, Plan};
use cellmd::run::{RunOptions, Simulation};

/// Largest |F| on any particle at the deck's start (pN).
fn max_force(plan: &Plan) -> f64 {
    let mut sim = Simulation::before_first_run(plan, RunOptions::default()).unwrap();
    sim.current_forces().unwrap().forces.iter().map(|f| f.length()).fold(0.0, f64::max)
}

/// `cellmd build ARGS -o out.top` in `dir`.
fn build(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_cellmd")).current_dir(dir).arg("build").args(args).args(["-o", "out.top"]).output().unwrap();
    assert!(out.status.success(), "cellmd build {args:?}: {}", String::from_utf8_lossy(&out.stderr));
}

/// The plan of `out.top` in `dir` under force field `ff`.
fn plan_in(dir: &Path, ff: &str) -> Plan {
    std::fs::write(dir.join("ff.ff"), ff).unwrap();
    std::fs::write(dir.join("deck.in"), "units cell\ntopology out.top\nforcefield ff.ff\ntimestep 1e-4\nrun 0\n").unwrap();
    validate_file(&dir.join("deck.in"), &[]).unwrap_or_else(|e| panic!("{e}"))
}

const SHEET_ARGS: [&str; 15] = [
    "sheet",
    "--rows",
    "4",
    "--columns",
    "6",
    "--cell-size",
    "3",
    "--nodes-per-edge",
    "2",
    "--jitter",
    "0.1",
    "--seed",
    "2",
    "--box",
    "20",
];

/// A jittered sheet: with each bond's length as its r0 it starts force-free;
/// with one r0 per type (the mean of that type's lengths, the best single
/// value) it does not.
#[test]
fn a_jittered_sheet_with_rest_lengths_from_geometry_starts_force_free() {
    let dir = tempfile::tempdir().unwrap();
    build(dir.path(), &[&SHEET_ARGS[..], &["--rest-from-geometry"]].concat());
    let ff = |edge: f64, spoke: f64, junction: f64| {
        format!(
            "particle node drag 1\nparticle cell_centre drag 1\nbond edge harmonic k 50 r0 {edge}\nbond spoke harmonic k 10 r0 {spoke}\n\
             bond junction harmonic k 20 r0 {junction}\n"
        )
    };
    let plan = plan_in(dir.path(), &ff(1.0, 1.0, 1.0));
    let m = &plan.model;
    assert!(m.bond_rest.iter().all(Option::is_some), "every bond has its own r0");
    let mean = |name: &str| {
        let t = m.bond_types.iter().position(|t| t.label.text == name).unwrap() as u32;
        let of: Vec<f64> = (0..m.bonds.len()).filter(|&b| m.bond_type[b] == t).map(|b| m.bond_rest[b].unwrap()).collect();
        let (lo, hi) = of.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| (lo.min(r), hi.max(r)));
        println!("{name}: {} bonds, length {lo:.4} to {hi:.4} µm", of.len());
        of.iter().sum::<f64>() / of.len() as f64
    };
    let (edge, spoke, junction) = (mean("edge"), mean("spoke"), mean("junction"));
    let own = max_force(&plan);
    build(dir.path(), &SHEET_ARGS);
    let typed = max_force(&plan_in(dir.path(), &ff(edge, spoke, junction)));
    println!("jittered sheet at step 0: max |F| = {own:.3e} pN with each bond's own r0, {typed:.3e} pN with the mean r0 per type");
    assert!(own <= 1e-9, "max |F| = {own:e} pN with rest lengths from geometry");
    assert!(typed > 1.0, "max |F| = {typed:e} pN with one r0 per type: the comparison would be vacuous");
}

/// Every builder whose bonds differ in length, with `--rest-from-geometry`:
/// each bond carries its own r0 and nothing pulls at the start (bonded terms
/// only: angles and bodies at zero stiffness). The network's crosslinks cross
/// the periodic box, so lengths are minimum-image ones.
#[test]
fn builders_with_rest_lengths_from_geometry_start_force_free() {
    let bonds = |names: &[&str]| names.iter().map(|n| format!("bond {n} harmonic k 100 r0 1\n")).collect::<String>();
    let shells = "particle node drag 1\nparticle nucleus_node drag 1\nbody cell turgor k 0 v0 1\nbody nucleus turgor k 0 v0 1\n";
    let cases: Vec<(Vec<&str>, String)> = vec![
        (
            vec![
                "tensegrity",
                "--radius",
                "5",
                "--level",
                "2",
                "--nucleus",
                "2.5",
                "--microtubules",
                "162",
                "--focal-adhesions",
                "12",
                "--fibre-segments",
                "3",
                "--seed",
                "4",
                "--box",
                "10",
            ],
            "particle node drag 1\nparticle nucleus_node drag 1\nparticle fibre_bead drag 1\nparticle focal_adhesion fixed\n\
             bond edge cable k 100 r0 1 tau 0\nbond nucleus_edge spring k 200 r0 1\nbond microtubule spring k 300 r0 1\n\
             bond actin cable k 20 r0 1\nbond stress_fibre cable k 50 r0 1\n"
                .to_string(),
        ),
        (
            vec![
                "cells",
                "--layout",
                "spheroid",
                "--count",
                "7",
                "--radius",
                "1",
                "--level",
                "2",
                "--gap",
                "0.1",
                "--spheroid-radius",
                "4",
                "--nucleus",
                "0.5",
                "--box",
                "8",
            ],
            format!("{shells}{}", bonds(&["edge", "nucleus_edge"])),
        ),
        (
            vec!["icosphere", "--level", "3", "--radius", "5", "--nucleus", "2", "--box", "8"],
            format!("{shells}{}", bonds(&["edge", "nucleus_edge"])),
        ),
        (
            vec![
                "network",
                "--filaments",
                "30",
                "--length",
                "2",
                "--segment-length",
                "0.1",
                "--box",
                "4",
                "4",
                "4",
                "--capture",
                "0.15",
                "--seed",
                "3",
            ],
            format!("particle bead drag 1\nangle bend cosine_angle K 0\n{}", bonds(&["segment", "crosslink"])),
        ),
    ];
    for (args, ff) in cases {
        let dir = tempfile::tempdir().unwrap();
        build(dir.path(), &[&args[..], &["--rest-from-geometry"]].concat());
        let plan = plan_in(dir.path(), &ff);
        let lengths: Vec<f64> = plan.model.bond_rest.iter().map(|r| r.expect("every bond has its own r0")).collect();
        let (lo, hi) = lengths.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &r| (lo.min(r), hi.max(r)));
        let f = max_force(&plan);
        println!("{}: {} bonds of lengths {lo:.4} to {hi:.4} µm; max |F| = {f:.3e} pN at step 0", args[0], lengths.len());
        assert!(hi > 1.05 * lo, "{}: the bonds are all alike, the test would be vacuous", args[0]);
        assert!(f <= 1e-9, "{}: max |F| = {f:e} pN", args[0]);
    }
}

/// A random system in a periodic box: 150 beads in chains, bonds of four
/// laws, most at their own r0 (`per_type`: written instead as one bond type
/// per such bond), a pair repulsion and bending angles; `constrain h` in
/// `deck_body` constrains every `h` bond. Returns the case.
fn chains(per_type: bool, deck_body: &str) -> Case {
    let mut next = common::uniform(0x2545F4914F6CDD1D);
    let laws = [
        ("h", "harmonic k 50 r0 1.0"),
        ("c", "cable k 40 r0 1.0 tau 0.05"),
        ("s", "spring k 30 r0 0.9 tau -0.05"),
        ("a", "asymmetric k_tension 60 k_compression 15 r0 1.0"),
    ];
    let mut ff = String::from("particle p drag 1\npair p p soft_repulsion k 5 sigma 0.6\nangle bend cosine_angle K 1\n");
    ff += &laws.iter().map(|(n, law)| format!("bond {n} {law}\n")).collect::<String>();
    let (mut top, mut bond_lines, mut angles) =
        (String::from("[ particles ]\n"), String::from("[ bonds ]\n"), String::from("[ angles ]\n"));
    let (chains, beads, l) = (15, 10, 7.0);
    for c in 0..chains {
        let mut x = [next() * l, next() * l, next() * l];
        for k in 0..beads {
            let id = c * beads + k + 1;
            top += &format!("{id} p {:?} {:?} {:?}\n", x[0], x[1], x[2]);
            if k > 0 {
                let (name, law) = laws[(c + k) % 4];
                let r0 = 0.7 + 0.6 * next();
                match (k % 3, per_type) {
                    (0, _) => bond_lines += &format!("{name} {} {id}\n", id - 1),
                    (_, false) => bond_lines += &format!("{name} {} {id} {r0:?}\n", id - 1),
                    (_, true) => {
                        let own = format!("{name}_{id}");
                        let law = law.split(" r0 ").collect::<Vec<_>>();
                        let rest = law[1].split_once(' ').map_or(String::new(), |(_, tail)| format!(" {tail}"));
                        ff += &format!("bond {own} {} r0 {r0:?}{rest}\n", law[0]);
                        bond_lines += &format!("{own} {} {id}\n", id - 1);
                    }
                }
            }
            if k > 1 {
                angles += &format!("bend {} {} {id}\n", id - 2, id - 1);
            }
            // The next bead 0.7–1.3 away in a random direction.
            let d = [next() - 0.5, next() - 0.5, next() - 0.5];
            let norm = d.iter().map(|v| v * v).sum::<f64>().sqrt().max(1e-3);
            let step = (0.7 + 0.6 * next()) / norm;
            x = [0, 1, 2].map(|a| x[a] + step * d[a]);
        }
    }
    // `constrain h` stands for every type of the `h` bonds; the chains are
    // built 0.7–1.3 long whatever their r0, so the constraints first move the
    // particles onto their lengths (`reshape yes`).
    let h_types: String = ff
        .lines()
        .filter_map(|line| line.split(' ').nth(1))
        .filter(|t| *t == "h" || t.starts_with("h_"))
        .map(|t| format!("constrain {t} reshape yes\n"))
        .collect();
    let deck_body = deck_body.replace("constrain h\n", &h_types);
    let deck = format!("units lj\ntopology t.top\nforcefield f.ff\nbox x 0 {l} p y 0 {l} p z 0 {l} p\n{deck_body}");
    Case::new(&[("t.top", &(top + &bond_lines + &angles)), ("f.ff", &ff), ("deck.in", &deck)])
}

fn bits(sim: &Simulation) -> Vec<[u64; 3]> {
    sim.state.positions.iter().map(|x| x.to_array().map(f64::to_bits)).collect()
}

/// Per-bond r0 is the same as one bond type per bond: forces, energies and
/// virial at the start, and whole runs under every integrator, bit for bit;
/// and different from every bond at its type's r0.
#[test]
fn per_bond_rest_lengths_equal_one_bond_type_per_bond() {
    let start = |case: &Case| {
        let mut sim = Simulation::before_first_run(&case.plan(), RunOptions::default()).unwrap();
        let f = sim.current_forces().unwrap();
        (
            f.forces.iter().map(|x| x.to_array().map(f64::to_bits)).collect::<Vec<_>>(),
            f.total_energy().to_bits(),
            f.virial.map(f64::to_bits),
        )
    };
    let (own, typed) = (chains(false, "timestep 1e-3\nrun 0\n"), chains(true, "timestep 1e-3\nrun 0\n"));
    assert!(own.plan().model.bond_rest.iter().filter(|r| r.is_some()).count() >= 80);
    assert_eq!(start(&own), start(&typed), "forces, energy and virial at step 0");
    let mut ignored = own.plan();
    ignored.model.bond_rest.iter_mut().for_each(|r| *r = None);
    let mut sim = Simulation::before_first_run(&ignored, RunOptions::default()).unwrap();
    let energy = sim.current_forces().unwrap().total_energy();
    let mut sim = Simulation::before_first_run(&own.plan(), RunOptions::default()).unwrap();
    let own_energy = sim.current_forces().unwrap().total_energy();
    println!("energy at step 0: {own_energy:.6e} with the per-bond r0, {energy:.6e} with the types' r0");
    assert!((energy - own_energy).abs() > 1e-3 * own_energy.abs());
    let start_x = own.plan().positions;
    for body in [
        "temperature 0.1\ntimestep 1e-3\nrun 300\n",
        "integrator implicit\ntimestep 2e-2\nrun 50\n",
        "timestep 1e-3\nminimize ftol 1e-6 maxiter 2000\n",
        "constrain h\ntimestep 1e-3\nrun 100\n",
    ] {
        let (b, a) = (chains(true, body).run(), chains(false, body).run());
        let moved = (0..a.state.len())
            .map(|i| (a.sim_box.unwrap(a.state.positions[i], a.state.images[i]) - start_x[i]).length())
            .fold(0.0, f64::max);
        println!("{}: moved up to {moved:.3e}, identical: {}", body.lines().last().unwrap(), bits(&a) == bits(&b));
        assert!(moved > 1e-3, "{body}: nothing moved");
        assert_eq!(bits(&a), bits(&b), "{body}");
    }
}

/// `constrain` holds each bond at its own rest length.
#[test]
fn constraints_hold_bonds_at_their_own_rest_length() {
    let sim = chains(false, "constrain h tolerance 1e-10 reshape yes\ntimestep 1e-3\nrun 200\n").run();
    let m = &sim.model;
    let mut checked = 0;
    for (b, &[i, j]) in m.bonds.iter().enumerate() {
        let (true, Some(r0)) = (m.bond_types[m.bond_type[b] as usize].label.text == "h", m.bond_rest[b]) else { continue };
        let r = sim.sim_box.minimum_image(sim.state.positions[j as usize] - sim.state.positions[i as usize]).length();
        assert!((r / r0 - 1.0).abs() < 1e-9, "bond {b}: length {r}, its r0 {r0}");
        checked += 1;
    }
    assert!(checked >= 20, "only {checked} constrained bonds with their own r0");
}

/// A restart keeps every bond's own r0 (also after a plastic reset moved
/// one), and continuing from it is bit-identical to the uninterrupted run.
#[test]
fn restarts_keep_per_bond_rest_lengths() {
    let plastic = "bond p harmonic k 2 r0 1 kinetics plastic threshold 0.1\n";
    let top = "[ particles ]\n1 a 0 0 0\n2 b 0 0 0.5\n3 a 3 0 0\n4 b 3 0 0.8\n[ bonds ]\np 1 2 0.5\ns 3 4 0.6\n";
    let ff = format!("particle a fixed\nparticle b drag 1\nbond s harmonic k 3 r0 1\n{plastic}");
    let head = "units lj\ntopology t.top\nforcefield f.ff\nbox x -5 10 f y -5 5 f z -5 50 f\ntimestep 1e-3\ngroup pulled id 2\n\
                external pull pulled constant_force fz 0.3\n";
    let case = Case::new(&[
        ("t.top", top),
        ("f.ff", &ff),
        ("deck.in", &format!("{head}run 1000\nwrite_state a.state\nrun 1000\n")),
        ("again.in", &format!("{head}read_state a.state\nrun 1000\n")),
    ]);
    let whole = case.run();
    let saved = cellmd::output::restart::read_state(&case.path("a.state")).unwrap();
    let rest = saved.bonds.as_ref().unwrap().rest.clone();
    println!("rest lengths in the restart: {rest:?}; after the run: {:?}", whole.state.bonds.as_ref().unwrap().rest);
    assert_eq!(rest[1], Some(0.6), "the unchanging bond keeps its own r0");
    assert!(rest[0].unwrap() > 0.5 * 1.1, "the plastic bond reset from its own r0 0.5: {:?}", rest[0]);
    let plan = validate_file(&case.path("again.in"), &[]).unwrap();
    let again = Simulation::execute(plan, RunOptions { output_dir: case.path(""), ..Default::default() }).unwrap();
    assert_eq!(bits(&again), bits(&whole));
    assert_eq!(again.state.bonds, whole.state.bonds);
}
