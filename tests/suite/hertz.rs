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
//! The half-space check (the law's own setting): a rigid sphere of radius R
//! (the `indenter`) pressed by δ into a large elastic body whose far side
//! is held: `inputs/hertz_block.in` (a quarter block, `cellmd build block
//! --quarter`, spacings graded from the contact along each axis) and
//! `inputs/hertz_halfspace.in` (a quarter half-ball, `cellmd build ball
//! --octant --spacing`, shells graded from the contact). Oracles: Hertz,
//! and Sneddon's exact small-strain load of a sphere (Int. J. Eng. Sci. 3,
//! 47, 1965), 0.2–1 % below Hertz for δ/R = 0.02–0.1.
//!
//! Volumetric locking (issue #46): at ν = 0.49 plain linear tetrahedra
//! load the CI block 75–92 % above Hertz, the average-nodal-pressure ones
//! (`neo_hookean_anp`) follow Hertz's ν-dependence
//! (`average_nodal_pressure_elements_do_not_lock_at_nu_0_49`; the
//! refinement study at ν = 0.3 … 0.499: studies/hertz_locking/).
//!
//! The refinement studies print the tables (docs/src/user-guide/solids.md):
//! `cargo test --test suite hertz:: -- --ignored --nocapture`.

use std::path::Path;

use cellmd::build::{ball, block, BallArgs, BlockArgs};
use cellmd::deck::{validate_file, Action, ThermoColumn};
use cellmd::run::thermo::column_label;
use cellmd::run::{RunOptions, Simulation};

/// The decks' ball and plates: R (µm), E (Pa), ν, stages up to δ = 0.1·R.
const RADIUS: f64 = 5.0;
const YOUNG: f64 = 1000.0;
const POISSON: f64 = 0.3;
const STAGES: usize = 5;

/// One relaxed stage: the approach δ, the whole body's load, the sum of
/// the loads on the two plates (the whole ball; 0 where there is one tool),
/// the relative change of the load over the stage's last step, and the
/// thermo columns read at its end.
#[derive(Debug)]
struct Stage {
    delta: f64,
    load: f64,
    imbalance: f64,
    drift: f64,
    values: Vec<f64>,
}

/// Hertz's half-space load at approach δ.
fn hertz(delta: f64) -> f64 {
    hertz_at(delta, POISSON)
}

/// Hertz's load at approach δ on a half-space of Poisson's ratio ν.
fn hertz_at(delta: f64, nu: f64) -> f64 {
    4.0 / 3.0 * YOUNG / (1.0 - nu * nu) * RADIUS.sqrt() * delta.powf(1.5)
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
    let args = BallArgs { radius: RADIUS, cells, octant, ..Default::default() };
    let text = ball(&args).unwrap().text;
    if octant {
        // The whole ball's load: four octants' share of the upper plate's.
        relax("inputs/hertz_octant.in", &text, &[], &["fz/top"], |v| (-4.0 * v[0], 0.0))
    } else {
        relax("inputs/hertz_ball.in", &text, &[], &["fz/bottom", "fz/top"], |v| (v[0], v[0] + v[1]))
    }
}

/// Runs `deck` on the topology `text` (with the deck variables `vars`),
/// reading the thermo `columns` at the end of each stage's relaxation and
/// one step before; `load` maps their values to the whole body's load and
/// the plates' imbalance.
fn relax(deck: &str, text: &str, vars: &[(&str, String)], columns: &[&str], load: impl Fn(&[f64]) -> (f64, f64)) -> Vec<Stage> {
    let dir = tempfile::tempdir().unwrap();
    let topology = dir.path().join("solid.top");
    std::fs::write(&topology, text).unwrap();
    let mut vars: Vec<(String, String)> = vars.iter().map(|(k, v)| (k.to_string(), v.clone())).collect();
    vars.push(("topology".into(), topology.display().to_string()));
    let plan = validate_file(Path::new(deck), &vars).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::new(&plan, RunOptions { output_dir: dir.path().to_path_buf(), ..Default::default() });
    let thermo: Vec<ThermoColumn> =
        plan.actions.iter().rev().find_map(|a| if let Action::Thermo { columns, .. } = a { Some(columns.clone()) } else { None }).unwrap();
    let wanted: Vec<ThermoColumn> = columns
        .iter()
        .map(|name| {
            thermo.iter().find(|c| column_label(c, &plan.model) == *name).cloned().unwrap_or_else(|| panic!("no thermo column {name}"))
        })
        .collect();
    let read = |sim: &mut Simulation| -> Vec<f64> { wanted.iter().map(|c| sim.thermo_value(c).unwrap()).collect() };
    let mut stages = Vec::new();
    for action in &plan.actions {
        match action {
            Action::Run(n) if *n >= 2 => {
                sim.apply(&Action::Run(n - 1)).unwrap_or_else(|e| panic!("{e}"));
                let (before, _) = load(&read(&mut sim));
                sim.apply(&Action::Run(1)).unwrap_or_else(|e| panic!("{e}"));
                let values = read(&mut sim);
                let (after, imbalance) = load(&values);
                stages.push(Stage {
                    delta: 0.1 * RADIUS * (stages.len() + 1) as f64 / STAGES as f64,
                    load: after,
                    imbalance,
                    drift: ((after - before) / after).abs(),
                    values,
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
    let slope = fitted_exponent(stages);
    println!("  fitted exponent {slope:.4} (Hertz: 1.5); largest |F/Hertz − 1| {hertz_worst:.4}, |F/Tatara − 1| {tatara_worst:.4}");
    (slope, hertz_worst, tatara_worst)
}

/// The least-squares slope p of ln F against ln δ over the stages.
fn fitted_exponent(stages: &[Stage]) -> f64 {
    let points: Vec<(f64, f64)> = stages.iter().map(|s| (s.delta.ln(), s.load.ln())).collect();
    let n = points.len() as f64;
    let (mx, my) = (points.iter().map(|p| p.0).sum::<f64>() / n, points.iter().map(|p| p.1).sum::<f64>() / n);
    points.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum::<f64>() / points.iter().map(|p| (p.0 - mx).powi(2)).sum::<f64>()
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
/// `--cells 16` on they agree (docs/src/user-guide/solids.md).
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
#[ignore = "refinement study, about an hour on 2 loaded cores: cargo test --test suite hertz:: -- --ignored --nocapture"]
fn hertz_refinement_study() {
    for cells in [8, 16, 24, 32] {
        report("octant", cells, &sweep(cells, true));
    }
    for cells in [8, 12, 16] {
        report("ball", cells, &sweep(cells, false));
    }
}

/// Sneddon's exact small-strain load of a rigid sphere of radius R pressed
/// by δ into an elastic half-space (Sneddon 1965, the sphere): with contact
/// radius a, δ = (a/2)·ln((R + a)/(R − a)) and
/// F = E*/2·[(a² + R²)·ln((R + a)/(R − a)) − 2aR]; Hertz's law is its
/// leading order in a/R. a by bisection in (0, R).
fn sneddon(delta: f64) -> f64 {
    let log = |a: f64| ((RADIUS + a) / (RADIUS - a)).ln();
    let (mut lo, mut hi) = (0.0, RADIUS * (1.0 - 1e-12));
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if 0.5 * mid * log(mid) < delta {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let a = 0.5 * (lo + hi);
    0.5 * YOUNG / (1.0 - POISSON * POISSON) * ((a * a + RADIUS * RADIUS) * log(a) - 2.0 * a * RADIUS)
}

/// A graded mesh of the half-space under the indenter: the quarter block of
/// `inputs/hertz_block.in` (half-width and depth L) or the quarter half-ball
/// of `inputs/hertz_halfspace.in` (radius L); `cells` spacings from the
/// contact outwards, the first `core` of them `spacing`.
#[derive(Clone, Copy, Debug)]
struct Block {
    ball: bool,
    half_width: f64,
    cells: u32,
    spacing: f64,
    core: u32,
}

/// The deck's block (`topologies/hertz_block.top`): the CI size.
const CI_BLOCK: Block = Block { ball: false, half_width: 50.0, cells: 10, spacing: 0.35, core: 4 };

/// The quarter block `b`'s arguments of `cellmd build block`.
fn block_args(b: Block) -> BlockArgs {
    BlockArgs {
        half_width: b.half_width,
        depth: None,
        cells: b.cells,
        spacing: Some(b.spacing),
        core_cells: b.core,
        centre: vec![0.0; 3],
        particle_type: "node".into(),
        quarter: true,
        tetra_type: "solid".into(),
        output: "block.top".into(),
    }
}

/// Runs `inputs/hertz_block.in` on the block `b` (or
/// `inputs/hertz_halfspace.in` on the half-ball).
fn block_sweep(b: Block) -> Vec<Stage> {
    block_sweep_with(b, &[])
}

/// `block_sweep` with the deck variables `extra` besides the block's extent.
fn block_sweep_with(b: Block, extra: &[(&str, String)]) -> Vec<Stage> {
    let mut vars = vec![("extent", b.half_width.to_string())];
    vars.extend(extra.iter().cloned());
    // The whole body's load: four quarters' share of the indenter's (down onto the block, up into the half-ball).
    if b.ball {
        let args = BallArgs {
            radius: b.half_width,
            cells: 2 * b.cells,
            octant: true,
            spacing: Some(b.spacing),
            core_cells: b.core,
            surface_type: Some("node_far".into()),
            ..Default::default()
        };
        let text = ball(&args).unwrap_or_else(|e| panic!("{e}")).text;
        relax("inputs/hertz_halfspace.in", &text, &vars, &["fz/tip", "depth/tip"], |v| (4.0 * v[0], 0.0))
    } else {
        let text = block(&block_args(b)).unwrap_or_else(|e| panic!("{e}")).text;
        relax("inputs/hertz_block.in", &text, &vars, &["fz/tip", "depth/tip"], |v| (-4.0 * v[0], 0.0))
    }
}

/// Prints a block's table and returns the fitted exponent and each stage's
/// F/Hertz − 1.
fn report_block(b: Block, stages: &[Stage]) -> (f64, Vec<f64>) {
    println!(
        "{} L = {} µm ({} R), --cells {} --spacing {} --core-cells {} ({} nodes): δ/R, F (pN), F/Hertz − 1, F/Sneddon − 1, a/spacing, deepest node in the indenter / δ, drift",
        if b.ball { "half-ball" } else { "block" },
        b.half_width,
        b.half_width / RADIUS,
        b.cells,
        b.spacing,
        b.core,
        (b.cells + 1).pow(3)
    );
    let mut excess = Vec::new();
    for s in stages {
        let (h, n) = (s.load / hertz(s.delta) - 1.0, s.load / sneddon(s.delta) - 1.0);
        println!(
            "  {:.2}  {:10.3}  {h:+.4}  {n:+.4}  {:.2}  {:.1e}  {:.1e}",
            s.delta / RADIUS,
            s.load,
            (RADIUS * s.delta).sqrt() / b.spacing,
            s.values[1] / s.delta,
            s.drift
        );
        excess.push(h);
    }
    let slope = fitted_exponent(stages);
    println!("  fitted exponent {slope:.4} (Hertz: 1.5)");
    (slope, excess)
}

/// Sneddon's exact sphere lies below Hertz's paraboloid by a/R-order terms:
/// 1 % at δ/R = 0.1, 0.2 % at 0.02, and meets it for small loads.
#[test]
fn sneddon_lies_a_percent_below_hertz_at_a_tenth_of_the_radius() {
    let gap = |ratio: f64| sneddon(ratio * RADIUS) / hertz(ratio * RADIUS) - 1.0;
    assert!((gap(0.1) + 0.010).abs() < 5e-4 && (gap(0.02) + 0.002).abs() < 2e-4, "{} {}", gap(0.1), gap(0.02));
    assert!(gap(1e-6).abs() < 1e-6, "Sneddon tends to Hertz: {}", gap(1e-6));
}

/// The committed topology of `inputs/hertz_block.in` is the CI block as
/// the builder writes it.
#[test]
fn the_committed_block_is_what_the_builder_writes() {
    let text = std::fs::read_to_string("topologies/hertz_block.top").unwrap();
    assert_eq!(block(&block_args(CI_BLOCK)).unwrap().text, text);
}

/// The CI-sized block (the deck's, 1331 nodes, 25 implicit steps a stage):
/// every stage solved to machine precision with the nodes at most 0.5 % of
/// δ inside the indenter, the load growing as δ^{3/2} (fitted exponent
/// within ±0.1), and above Hertz (a displacement-based mesh is stiffer than
/// the solid it approximates; Sneddon's exact sphere is 0.2–1 % below
/// Hertz) by less than 30 % (measured: 13–24 %). Hertz within 5 % needs a
/// finer mesh than CI affords: the study's table (docs/src/user-guide/solids.md).
#[test]
fn a_rigid_sphere_on_a_graded_block_loads_as_hertz_from_above() {
    let stages = block_sweep(CI_BLOCK);
    let (exponent, excess) = report_block(CI_BLOCK, &stages);
    for s in &stages {
        assert!(s.drift < 1e-9, "stage δ = {} µm: not relaxed (load drift {:.1e})", s.delta, s.drift);
        assert!(s.values[1] < 5e-3 * s.delta, "stage δ = {}: a node {} inside the indenter", s.delta, s.values[1]);
    }
    assert!((exponent - 1.5).abs() < 0.1, "F ∝ δ^{exponent:.3}, expected Hertz's δ^1.5");
    assert!(excess.iter().all(|&e| e > 0.0 && e < 0.3), "F/Hertz − 1 = {excess:?}");
}

/// The meshes of the study (docs/src/user-guide/solids.md): the block at 20·R and
/// 10·R with the same spacings, the block at 20·R graded more gently, and
/// the half-ball at the block's spacings.
const STUDY: [Block; 4] = [
    Block { ball: false, half_width: 100.0, cells: 10, spacing: 0.35, core: 4 },
    Block { ball: false, half_width: 50.0, cells: 10, spacing: 0.35, core: 4 },
    Block { ball: false, half_width: 100.0, cells: 14, spacing: 0.35, core: 4 },
    Block { ball: true, half_width: 50.0, cells: 10, spacing: 0.35, core: 4 },
];

#[test]
#[ignore = "half-space study, about 15 min on 2 loaded cores: cargo test --test suite hertz::hertz_block_study -- --ignored --nocapture (HERTZ_BLOCK=L,cells,spacing,core,ball runs one mesh, ball 1 for the half-ball)"]
fn hertz_block_study() {
    let one: Option<Vec<f64>> = std::env::var("HERTZ_BLOCK").ok().map(|v| v.split(',').map(|x| x.parse().unwrap()).collect());
    let blocks = match one {
        Some(v) => vec![Block { ball: v[4] != 0.0, half_width: v[0], cells: v[1] as u32, spacing: v[2], core: v[3] as u32 }],
        None => STUDY.to_vec(),
    };
    for b in blocks {
        report_block(b, &block_sweep(b));
    }
}

/// The CI block's solid as the volume law `law` at Poisson's ratio `nu`:
/// each stage's F/Hertz_ν − 1 (Hertz at that ν).
fn block_excess(law: &str, nu: f64) -> Vec<f64> {
    let dir = tempfile::tempdir().unwrap();
    let ff = dir.path().join("block.ff");
    let text = std::fs::read_to_string("forcefields/hertz_block.ff").unwrap();
    let solid = "tetra solid neo_hookean e 1000 nu 0.3";
    assert!(text.contains(solid), "the CI force field's solid changed");
    std::fs::write(&ff, text.replace(solid, &format!("tetra solid {law} e {YOUNG} nu {nu}"))).unwrap();
    let stages = block_sweep_with(CI_BLOCK, &[("forcefield", ff.display().to_string())]);
    for s in &stages {
        assert!(s.drift < 1e-9, "{law} ν = {nu}, stage δ = {} µm: not relaxed (load drift {:.1e})", s.delta, s.drift);
    }
    let excess: Vec<f64> = stages.iter().map(|s| s.load / hertz_at(s.delta, nu) - 1.0).collect();
    println!("{law} ν = {nu} on the CI block: F/Hertz − 1 = {excess:+.4?}");
    excess
}

/// Volumetric locking (issue #46) on the CI block (1331 nodes): Hertz's
/// load grows with ν as 1/(1 − ν²), and the average-nodal-pressure elements
/// (`neo_hookean_anp`) follow it, so at ν = 0.49 each stage's F/Hertz is
/// within 5 % of its value at ν = 0.3 on the same mesh (measured 1.3–3.4 %
/// below it: F/Hertz − 1 = +4.0 % to +13.8 % at ν = 0.49, +5.4 % to
/// +17.8 % at ν = 0.3, the mesh's own excess over Hertz). Plain
/// `neo_hookean` elements lock: on this mesh they give +74.7 % to +92.0 %
/// at ν = 0.49 against +12.6 % to +23.7 % at ν = 0.3, a ratio of
/// 1.49–1.55, which this test would fail by ten times its tolerance. Absolute Hertz within 5 % needs a finer mesh than CI
/// affords at any ν (docs/src/user-guide/solids.md, *Near-incompressible solids*).
#[test]
fn average_nodal_pressure_elements_do_not_lock_at_nu_0_49() {
    // The two sweeps side by side (each implicit step's factorisation is mostly serial).
    let (compressible, nearly) = std::thread::scope(|s| {
        let nearly = s.spawn(|| block_excess("neo_hookean_anp", 0.49));
        (block_excess("neo_hookean_anp", 0.3), nearly.join().unwrap())
    });
    for (k, (a, b)) in compressible.iter().zip(&nearly).enumerate() {
        let ratio = (1.0 + b) / (1.0 + a);
        assert!((ratio - 1.0).abs() < 0.05, "stage {}: F/Hertz at ν = 0.49 is {ratio:.4} of that at ν = 0.3", k + 1);
    }
}

/// Volume elements are no CPU-only feature (GPU parity: `tests/suite/gpu.rs`,
/// `a_squeezed_ball_runs_on_the_gpu_like_on_the_cpu`; their implicit blocks:
/// `tests/suite/gpu_implicit.rs`).
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
