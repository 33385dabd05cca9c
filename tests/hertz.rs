//! Hertz contact of a meshed elastic ball (issue #20): `inputs/hertz_ball.in`
//! squeezes a neo-Hookean ball of radius R (`cellmd build ball`, linear
//! tetrahedra) between two rigid frictionless plates that each advance by δ
//! towards its centre, relaxing each stage with the implicit integrator.
//!
//! Oracle: by symmetry the centre stays put, so each plate is one contact of
//! a sphere on a rigid flat, and Hertz (Johnson, *Contact Mechanics*, §4.2)
//! gives the load F = (4/3)·E*·√R·δ^{3/2} with E* = E/(1 − ν²) (the plate
//! is rigid). Hertz assumes a half-space and a contact radius a = √(Rδ) ≪ R;
//! at δ/R = 0.1, a/R = 0.32. A plate is a stiff wall (10⁵ pN/µm): the nodes
//! sink into it by F/k per node, ≤ 0.1 % of δ here.
//!
//! Measured (README, *Solid bodies*): the load follows δ^{3/2} but lies
//! 14–27 % above Hertz at n = 8, 12 and 16 alike (`--cells n`), so
//! resolution explains little of the excess; the suspect is the oracle: a
//! ball between plates is no half-space (its centre, pinned by symmetry,
//! lies only R below each contact). The 5 % is not met, and this test does not claim it:
//! it checks the exponent. The refinement study prints the whole table:
//! `cargo test --release --test hertz -- --ignored --nocapture`.

use std::path::Path;

use cellmd::build::{ball, BallArgs};
use cellmd::deck::{validate_file, Action, ThermoColumn};
use cellmd::run::thermo::column_label;
use cellmd::run::{RunOptions, Simulation};

const DECK: &str = "inputs/hertz_ball.in";
/// The deck's ball and plates: R (µm), E (Pa), ν, stages up to δ = 0.1·R.
const RADIUS: f64 = 5.0;
const YOUNG: f64 = 1000.0;
const POISSON: f64 = 0.3;
const STAGES: usize = 5;

/// One relaxed stage: each plate's approach δ, the load on the lower plate
/// and on the upper one, and the relative change of the load over the
/// stage's last step.
#[derive(Debug)]
struct Stage {
    delta: f64,
    bottom: f64,
    top: f64,
    drift: f64,
}

fn hertz(delta: f64) -> f64 {
    4.0 / 3.0 * YOUNG / (1.0 - POISSON * POISSON) * RADIUS.sqrt() * delta.powf(1.5)
}

/// Runs the deck on a ball of `cells` lattice cells across.
fn sweep(cells: u32) -> Vec<Stage> {
    let dir = tempfile::tempdir().unwrap();
    let topology = dir.path().join("ball.top");
    let args = BallArgs {
        radius: RADIUS,
        cells,
        centre: vec![0.0; 3],
        particle_type: "node".into(),
        tetra_type: "solid".into(),
        output: topology.clone(),
    };
    std::fs::write(&topology, ball(&args).unwrap().text).unwrap();
    let vars = vec![("topology".to_string(), topology.display().to_string())];
    let plan = validate_file(Path::new(DECK), &vars).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::new(&plan, RunOptions { output_dir: dir.path().to_path_buf(), ..Default::default() });
    let columns: Vec<ThermoColumn> =
        plan.actions.iter().rev().find_map(|a| if let Action::Thermo { columns, .. } = a { Some(columns.clone()) } else { None }).unwrap();
    let column = |name: &str| columns.iter().find(|c| column_label(c, &plan.model) == name).unwrap_or_else(|| panic!("{name}")).clone();
    let [bottom, top] = ["fz/bottom", "fz/top"].map(column);
    let mut stages = Vec::new();
    for action in &plan.actions {
        match action {
            Action::Run(n) if *n >= 2 => {
                sim.apply(&Action::Run(n - 1)).unwrap_or_else(|e| panic!("{e}"));
                let before = sim.thermo_value(&bottom).unwrap();
                sim.apply(&Action::Run(1)).unwrap_or_else(|e| panic!("{e}"));
                let load = sim.thermo_value(&bottom).unwrap();
                stages.push(Stage {
                    delta: 0.1 * RADIUS * (stages.len() + 1) as f64 / STAGES as f64,
                    bottom: load,
                    top: sim.thermo_value(&top).unwrap(),
                    drift: ((load - before) / load).abs(),
                });
            }
            _ => sim.apply(action).unwrap_or_else(|e| panic!("{e}")),
        }
    }
    assert_eq!(stages.len(), STAGES, "one relaxed run per stage");
    stages
}

/// Prints the table of a sweep; returns the exponent of the least-squares
/// fit F ∝ δ^p over its stages and the largest |F/Hertz − 1|.
fn report(cells: u32, stages: &[Stage]) -> (f64, f64) {
    let spacing = std::f64::consts::FRAC_PI_2 * RADIUS / cells as f64;
    println!("cells {cells} (surface spacing {spacing:.3} µm): δ/R, F (pN), Hertz (pN), F/Hertz − 1, a/spacing, drift");
    let mut worst: f64 = 0.0;
    for s in stages {
        let (f, h) = (s.bottom, hertz(s.delta));
        println!(
            "  {:.2}  {f:10.3}  {h:10.3}  {:+.4}  {:.2}  {:.1e}",
            s.delta / RADIUS,
            f / h - 1.0,
            (RADIUS * s.delta).sqrt() / spacing,
            s.drift
        );
        worst = worst.max((f / h - 1.0).abs());
    }
    let points: Vec<(f64, f64)> = stages.iter().map(|s| (s.delta.ln(), s.bottom.ln())).collect();
    let n = points.len() as f64;
    let (mx, my) = (points.iter().map(|p| p.0).sum::<f64>() / n, points.iter().map(|p| p.1).sum::<f64>() / n);
    let slope = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    println!("  fitted exponent {slope:.4} (Hertz: 1.5); largest |F/Hertz − 1| {worst:.4}");
    (slope, worst)
}

/// What the CI-sized ball (`--cells 8`) shows: each stage relaxed, the two
/// plates' loads equal and opposite, and the load growing as δ^{3/2}
/// (fitted exponent within ±0.1 of Hertz's 1.5: the node rings entering the
/// contact one by one scatter single stages by up to ~10 %). Its amplitude
/// is not within 5 % of the half-space law (see the module docs).
#[test]
fn a_meshed_ball_loads_as_hertz_delta_to_the_three_halves() {
    let stages = sweep(8);
    for s in &stages {
        assert!(s.drift < 1e-3, "stage δ = {}: not relaxed (load drift {:.1e})", s.delta, s.drift);
        assert!((s.bottom + s.top).abs() < 1e-6 * s.bottom, "the plates' loads differ: {} vs {}", s.bottom, -s.top);
    }
    let (exponent, _) = report(8, &stages);
    assert!((exponent - 1.5).abs() < 0.1, "F ∝ δ^{exponent:.3}, expected Hertz's δ^1.5");
}

#[test]
#[ignore = "refinement study, minutes: cargo test --release --test hertz -- --ignored --nocapture"]
fn hertz_refinement_study() {
    for cells in [8, 12, 16] {
        report(cells, &sweep(cells));
    }
}

#[test]
fn the_gpu_refuses_volume_elements() {
    let dir = tempfile::tempdir().unwrap();
    let files = [
        ("t.top", "[ particles ]\n1 p 0 0 0\n2 p 1 0 0\n3 p 0 1 0\n4 p 0 0 1\n[ tetrahedra ]\nsolid 1 2 3 4\n"),
        ("f.ff", "particle p drag 1\ntetra solid neo_hookean e 10 nu 0.3\n"),
        ("deck.in", "units cell\ntopology t.top\nforcefield f.ff\nbox x -5 5 f y -5 5 f z -5 5 f\ntimestep 1e-3\nrun 1\n"),
    ];
    for (name, text) in files {
        std::fs::write(dir.path().join(name), text).unwrap();
    }
    let plan = validate_file(&dir.path().join("deck.in"), &[]).unwrap_or_else(|e| panic!("{e}"));
    let sim = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
    assert_eq!(sim.cpu_only_feature(), Some("volume elements (`[ tetrahedra ]`, `tetra` lines) run on the CPU backend only"));
}
