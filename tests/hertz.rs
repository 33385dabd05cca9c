//! Hertz contact of a meshed elastic ball (issue #20): `inputs/hertz_ball.in`
//! squeezes a neo-Hookean ball of radius R (`cellmd build ball`, linear
//! tetrahedra) between two rigid frictionless plates that each advance by δ
//! towards its centre, relaxing each stage with the implicit integrator;
//! `inputs/hertz_octant.in` solves the same problem on one octant of the
//! same mesh (`--octant`, symmetry planes held by `freeze`), which reaches
//! twice the lattice cells for the same node count.
//!
//! Oracles: by symmetry the centre stays put, so each plate is one contact
//! of a sphere on a rigid flat. Hertz (Johnson, *Contact Mechanics*, §4.2)
//! gives F = (4/3)·E*·√R·δ^{3/2}, E* = E/(1 − ν²), for a half-space: δ is
//! the approach of points far from the contact. In a ball the opposite
//! contact is only 2R away, and its load F pushes this one back by the
//! Boussinesq displacement of a half-space at depth 2R (radius a off the
//! axis), the idea of Tatara's finite-sphere law (Y. Tatara, J. Eng. Mater. Technol.
//! 111, 163, 1989; its large-strain sequel ibid. 113, 285, 1991)
//! δ = a²/R − F(1 + ν)/(2πE)·[2(1 − ν)/√(4R² + a²) + 4R²/(4R² + a²)^{3/2}],
//! with Hertz's a³ = 3(1 − ν²)FR/(4E) (written here from the Boussinesq
//! solution; the papers' text was not at hand to check it). The correction grows as a/R: at
//! δ/R = 0.02 it raises the load by 8 % over Hertz, at 0.1 by 21 %, so no
//! ball can meet the "Hertz within 5 %" at δ/R = 0.1 — the finite
//! sphere is not a half-space. The tests compare with both laws.
//!
//! A plate is a stiff wall (10⁵ pN/µm): the nodes sink into it by F/k per
//! node, ≤ 0.1 % of δ here. On the octant a node on a symmetry plane carries
//! the elements of one side only, so it sinks by half the whole ball's
//! (a quarter on the plate's axis): the octant's load ×4 is the ball's to
//! that 0.1 % level. Measured: at `--cells 16` the whole ball and the octant
//! agree within 0.2 % at every stage; at `--cells 8` they differ by 2–7 %
//! at δ/R = 0.06–0.08, the whole ball's stages barely converged (likely
//! tilted states of its faceted surface, which its frictionless plates
//! allow; not checked).
//!
//! The refinement study prints the tables (README, *Solid bodies*):
//! `cargo test --test hertz -- --ignored --nocapture`.

use std::path::Path;

use cellmd::build::{ball, BallArgs};
use cellmd::deck::{validate_file, Action, ThermoColumn};
use cellmd::run::thermo::column_label;
use cellmd::run::{RunOptions, Simulation};

/// The decks' ball and plates: R (µm), E (Pa), ν, stages up to δ = 0.1·R.
const RADIUS: f64 = 5.0;
const YOUNG: f64 = 1000.0;
const POISSON: f64 = 0.3;
const STAGES: usize = 5;

/// One relaxed stage: the plate's approach δ, its load (the whole ball's),
/// the sum of the loads on the two plates (the whole ball; 0 for the
/// octant, which has one), and the relative change of the load over the
/// stage's last step.
#[derive(Debug)]
struct Stage {
    delta: f64,
    load: f64,
    imbalance: f64,
    drift: f64,
}

/// Hertz's half-space load at approach δ.
fn hertz(delta: f64) -> f64 {
    4.0 / 3.0 * YOUNG / (1.0 - POISSON * POISSON) * RADIUS.sqrt() * delta.powf(1.5)
}

/// The approach of each plate on a ball under load F by Tatara's
/// finite-sphere law (module docs).
fn tatara_approach(load: f64) -> f64 {
    let (r, e, nu) = (RADIUS, YOUNG, POISSON);
    let a = (3.0 * (1.0 - nu * nu) * load * r / (4.0 * e)).cbrt();
    let d2 = 4.0 * r * r + a * a;
    a * a / r - load * (1.0 + nu) / (2.0 * std::f64::consts::PI * e) * (2.0 * (1.0 - nu) / d2.sqrt() + 4.0 * r * r / d2.powf(1.5))
}

/// Tatara's load at approach δ: the root of `tatara_approach`, which grows
/// with F over the loads here, by bisection between 0 and twice Hertz's.
fn tatara(delta: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, 2.0 * hertz(delta));
    assert!(tatara_approach(hi) > delta, "bracket");
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if tatara_approach(mid) < delta {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Runs the whole-ball deck (`octant` false) or the octant deck on a ball of
/// `cells` lattice cells across.
fn sweep(cells: u32, octant: bool) -> Vec<Stage> {
    let dir = tempfile::tempdir().unwrap();
    let topology = dir.path().join("ball.top");
    let args = BallArgs {
        radius: RADIUS,
        cells,
        centre: vec![0.0; 3],
        particle_type: "node".into(),
        octant,
        tetra_type: "solid".into(),
        output: topology.clone(),
    };
    std::fs::write(&topology, ball(&args).unwrap().text).unwrap();
    let vars = vec![("topology".to_string(), topology.display().to_string())];
    let deck = if octant { "inputs/hertz_octant.in" } else { "inputs/hertz_ball.in" };
    let plan = validate_file(Path::new(deck), &vars).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::new(&plan, RunOptions { output_dir: dir.path().to_path_buf(), ..Default::default() });
    let columns: Vec<ThermoColumn> =
        plan.actions.iter().rev().find_map(|a| if let Action::Thermo { columns, .. } = a { Some(columns.clone()) } else { None }).unwrap();
    let column = |name: &str| columns.iter().find(|c| column_label(c, &plan.model) == name).cloned();
    let (bottom, top) = (column("fz/bottom"), column("fz/top").expect("fz/top"));
    // The whole ball's load: the lower plate's, or four octants' share of the upper one's.
    let load = |sim: &mut Simulation| match &bottom {
        Some(b) => sim.thermo_value(b).unwrap(),
        None => -4.0 * sim.thermo_value(&top).unwrap(),
    };
    let mut stages = Vec::new();
    for action in &plan.actions {
        match action {
            Action::Run(n) if *n >= 2 => {
                sim.apply(&Action::Run(n - 1)).unwrap_or_else(|e| panic!("{e}"));
                let before = load(&mut sim);
                sim.apply(&Action::Run(1)).unwrap_or_else(|e| panic!("{e}"));
                let after = load(&mut sim);
                let imbalance = bottom.as_ref().map_or(0.0, |b| sim.thermo_value(b).unwrap() + sim.thermo_value(&top).unwrap());
                stages.push(Stage {
                    delta: 0.1 * RADIUS * (stages.len() + 1) as f64 / STAGES as f64,
                    load: after,
                    imbalance,
                    drift: ((after - before) / after).abs(),
                });
            }
            _ => sim.apply(action).unwrap_or_else(|e| panic!("{e}")),
        }
    }
    assert_eq!(stages.len(), STAGES, "one relaxed run per stage");
    stages
}

/// The fitted exponent p of F ∝ δ^p over the stages and the largest
/// |F/Hertz − 1| and |F/Tatara − 1|, printing the table.
fn report(label: &str, cells: u32, stages: &[Stage]) -> (f64, f64, f64) {
    let spacing = std::f64::consts::FRAC_PI_2 * RADIUS / cells as f64;
    println!("{label} --cells {cells} (surface spacing {spacing:.3} µm): δ/R, F (pN), F/Hertz − 1, F/Tatara − 1, a/spacing, drift");
    let (mut hertz_worst, mut tatara_worst): (f64, f64) = (0.0, 0.0);
    for s in stages {
        let (h, t) = (s.load / hertz(s.delta) - 1.0, s.load / tatara(s.delta) - 1.0);
        println!(
            "  {:.2}  {:10.3}  {h:+.4}  {t:+.4}  {:.2}  {:.1e}",
            s.delta / RADIUS,
            s.load,
            (RADIUS * s.delta).sqrt() / spacing,
            s.drift
        );
        hertz_worst = hertz_worst.max(h.abs());
        tatara_worst = tatara_worst.max(t.abs());
    }
    let points: Vec<(f64, f64)> = stages.iter().map(|s| (s.delta.ln(), s.load.ln())).collect();
    let n = points.len() as f64;
    let (mx, my) = (points.iter().map(|p| p.0).sum::<f64>() / n, points.iter().map(|p| p.1).sum::<f64>() / n);
    let slope = points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>();
    println!("  fitted exponent {slope:.4} (Hertz: 1.5); largest |F/Hertz − 1| {hertz_worst:.4}, |F/Tatara − 1| {tatara_worst:.4}");
    (slope, hertz_worst, tatara_worst)
}

fn assert_relaxed(stages: &[Stage]) {
    for s in stages {
        assert!(s.drift < 1e-3, "stage δ = {}: not relaxed (load drift {:.1e})", s.delta, s.drift);
        assert!(s.imbalance.abs() < 1e-6 * s.load, "the plates' loads differ by {}", s.imbalance);
    }
}

/// Tatara's law lies above Hertz's by the finite sphere's correction, which
/// grows with a/R (module docs): 8 % at δ/R = 0.02, 21 % at 0.1.
#[test]
fn tatara_exceeds_hertz_by_the_finite_sphere_correction() {
    let excess = |ratio: f64| tatara(ratio * RADIUS) / hertz(ratio * RADIUS) - 1.0;
    assert!((excess(0.02) - 0.08).abs() < 0.01 && (excess(0.1) - 0.21).abs() < 0.01, "{} {}", excess(0.02), excess(0.1));
    assert!(excess(1e-6) < 1e-3, "Tatara tends to Hertz for small loads: {}", excess(1e-6));
}

/// What the CI-sized ball (`--cells 8`) shows: each stage relaxed, the two
/// plates' loads equal and opposite, and the load growing as δ^{3/2}
/// (fitted exponent within ±0.1 of Hertz's 1.5). Its amplitude is not
/// compared: at this size the whole ball lies 2–7 % off the octant's
/// mirror-symmetric state at δ/R = 0.06–0.08 (module docs); from
/// `--cells 16` on they agree (README).
#[test]
fn a_meshed_ball_loads_as_hertz_delta_to_the_three_halves() {
    let stages = sweep(8, false);
    assert_relaxed(&stages);
    let (exponent, _, _) = report("ball", 8, &stages);
    assert!((exponent - 1.5).abs() < 0.1, "F ∝ δ^{exponent:.3}, expected Hertz's δ^1.5");
}

/// The CI-sized octant (`--cells 16`, 729 nodes): every stage solved to
/// machine precision (its held planes leave no soft mode), and where the
/// contact spans at least two surface spacings (δ/R ≥ 0.04) the load within
/// 5 % of Tatara's finite sphere (measured ≤ 3.3 %) and more than 10 % above
/// Hertz's half-space (the finite sphere's correction, 12–21 % there).
/// Below two spacings a node-on-wall contact cannot resolve the pressure
/// (+10 % at δ/R = 0.02 here); the refinement study shows that stage too
/// converging.
#[test]
fn the_octant_loads_as_the_finite_sphere_within_five_percent() {
    let stages = sweep(16, true);
    assert_relaxed(&stages);
    assert!(stages.iter().all(|s| s.drift < 1e-9), "{stages:?}");
    let (exponent, _, _) = report("octant", 16, &stages);
    assert!((exponent - 1.5).abs() < 0.1, "F ∝ δ^{exponent:.3}, expected δ^1.5");
    let spacing = std::f64::consts::FRAC_PI_2 * RADIUS / 16.0;
    for s in stages.iter().filter(|s| (RADIUS * s.delta).sqrt() >= 2.0 * spacing) {
        let (t, h) = (s.load / tatara(s.delta) - 1.0, s.load / hertz(s.delta) - 1.0);
        assert!(t.abs() < 0.05, "δ/R = {}: F/Tatara − 1 = {t:+.4}", s.delta / RADIUS);
        assert!(h > 0.10, "δ/R = {}: F/Hertz − 1 = {h:+.4}, expected the finite sphere's excess", s.delta / RADIUS);
    }
}

#[test]
#[ignore = "refinement study, about an hour on 2 loaded cores: cargo test --test hertz -- --ignored --nocapture"]
fn hertz_refinement_study() {
    for cells in [8, 16, 24, 32] {
        report("octant", cells, &sweep(cells, true));
    }
    for cells in [8, 12, 16] {
        report("ball", cells, &sweep(cells, false));
    }
}

/// Volume elements are no CPU-only feature (GPU parity: `tests/gpu.rs`,
/// `a_squeezed_ball_runs_on_the_gpu_like_on_the_cpu`); the hertz decks stay
/// on the CPU for their implicit integrator.
#[test]
fn volume_elements_may_run_on_the_gpu() {
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
    assert_eq!(sim.cpu_only_feature(), None);
}
