//! Simple shear of an athermal crosslinked Mikado network (issue #6): the
//! differential modulus K = dσ/dγ is constant at small strain and stiffens
//! with the shear stress σ; the exponent m of K ∝ σ^m is fitted where the
//! network stiffens while bending still holds most of its elastic energy.
//!
//! The test runs `inputs/network_shear.in` as written (its topology is
//! `cellmd build network … --pin-crosslinks --slab y --seed 1`) and again on
//! the network of seed 2, stage by stage, reading the deck's own thermo
//! columns after each stage's relaxation: γ = Δ`xu/plate`/(`yu/plate` −
//! `yu/base`), σ = −`fx/plate`/L_x (pN/µm, the sheet's 2D shear stress) and
//! the bending share `pe/wlc_bending`/`pe`. K_k = (σ_k − σ_{k−1})/(γ_k −
//! γ_{k−1}) belongs to the interval's mean stress (σ_{k−1} + σ_k)/2.
//!
//! Expected: athermal bending-dominated networks stiffen as bending gives
//! way to stretching, with K ∝ σ (m = 1) in the stiffening regime (Licup et
//! al., PNAS 112, 7480 (2015); Broedersz & MacKintosh, Rev. Mod. Phys. 86,
//! 995 (2014)), not the entropic m = 3/2 of thermal semiflexible networks
//! (Storm et al., Nature 435, 191 (2005)); once stretching dominates, K
//! grows more slowly. The band around m = 1 is twice the larger of each
//! seed's fit error and the two seeds' difference (measured: ±0.17), and
//! must stay below ±0.25 to tell 1 from 3/2. Measured: docs/src/user-guide/dynamics.md, *Network shear*.
//!
//! `cargo test --release --test suite shear:: -- --nocapture` prints the tables.

use std::path::Path;

use cellmd::build::{network, Chain, Common, NetworkArgs, SlabAxis};
use cellmd::deck::{validate_file, Action, ThermoColumn};
use cellmd::run::thermo::column_label;
use cellmd::run::{RunOptions, Simulation};

const DECK: &str = "inputs/network_shear.in";

/// The topology of the deck's header for another seed.
fn network_of(seed: u64) -> String {
    let args = NetworkArgs {
        filaments: 60,
        chain: Chain { length: 1.6, segments: Some(8), ..Chain::default() },
        box_lengths: vec![4.0, 4.0, 1.0],
        planar: true,
        capture: 0.08,
        pin_crosslinks: true,
        slab: Some(SlabAxis::Y),
        common: Common { seed, output: "network_shear.top".into(), rest_from_geometry: false },
        ..NetworkArgs::default()
    };
    network(&args).unwrap().text
}

/// One relaxed stage.
#[derive(Clone, Copy, Debug)]
struct Stage {
    gamma: f64,
    sigma: f64,
    /// |change of σ over the stage's last step| / σ.
    drift: f64,
    /// Bending share of the elastic energy.
    bending: f64,
}

/// Runs the deck on `topology` (None: its own), recording each stage at
/// the end of its relaxation: its last run, split to see the last step.
fn sweep(topology: Option<&Path>) -> Vec<Stage> {
    let vars: Vec<(String, String)> = topology.map(|t| ("topology".to_string(), t.display().to_string())).into_iter().collect();
    let plan = validate_file(Path::new(DECK), &vars).unwrap_or_else(|e| panic!("{e}"));
    let out = tempfile::tempdir().unwrap();
    let mut sim = Simulation::new(&plan, RunOptions { output_dir: out.path().to_path_buf(), ..Default::default() });
    let columns: Vec<ThermoColumn> =
        plan.actions.iter().rev().find_map(|a| if let Action::Thermo { columns, .. } = a { Some(columns.clone()) } else { None }).unwrap();
    let column = |name: &str| columns.iter().find(|c| column_label(c, &plan.model) == name).unwrap_or_else(|| panic!("{name}")).clone();
    let [xu, yu, yb, fx, pe, bend] = ["xu/plate", "yu/plate", "yu/base", "fx/plate", "pe", "pe/wlc_bending"].map(column);
    let lx = plan.sim_box.lengths().x;
    let (mut stages, mut reference) = (Vec::new(), None);
    for (k, action) in plan.actions.iter().enumerate() {
        let next = plan.actions[k + 1..].iter().find(|a| matches!(a, Action::Run(_) | Action::Displace { .. }));
        let ends_stage = reference.is_some() && next.is_none_or(|a| matches!(a, Action::Displace { .. }));
        match action {
            Action::Run(n) if *n >= 2 && ends_stage => {
                sim.apply(&Action::Run(n - 1)).unwrap_or_else(|e| panic!("{e}"));
                let before = -sim.thermo_value(&fx).unwrap() / lx;
                sim.apply(&Action::Run(1)).unwrap_or_else(|e| panic!("{e}"));
                let mut value = |c: &ThermoColumn| sim.thermo_value(c).unwrap();
                let sigma = -value(&fx) / lx;
                stages.push(Stage {
                    gamma: (value(&xu) - reference.unwrap()) / (value(&yu) - value(&yb)),
                    sigma,
                    drift: ((sigma - before) / sigma).abs(),
                    bending: value(&bend) / value(&pe),
                });
            }
            Action::Run(0) if reference.is_none() => {
                sim.apply(action).unwrap_or_else(|e| panic!("{e}"));
                reference = Some(sim.thermo_value(&xu).unwrap());
            }
            _ => sim.apply(action).unwrap_or_else(|e| panic!("{e}")),
        }
    }
    stages
}

/// K over one interval between consecutive stages (the first from the
/// unstrained reference).
#[derive(Clone, Copy, Debug)]
struct Point {
    /// Mean stress of the interval (pN/µm).
    sigma: f64,
    /// K = Δσ/Δγ (pN/µm).
    k: f64,
    /// Bending share of the energy at the interval's start.
    bending: f64,
}

fn points(stages: &[Stage]) -> Vec<Point> {
    let start = Stage { gamma: 0.0, sigma: 0.0, drift: 0.0, bending: 1.0 };
    std::iter::once(&start)
        .chain(stages)
        .zip(stages)
        .map(|(a, b)| Point { sigma: 0.5 * (a.sigma + b.sigma), k: (b.sigma - a.sigma) / (b.gamma - a.gamma), bending: a.bending })
        .collect()
}

/// Least-squares slope of ln K against ln σ and its standard error.
fn fit(window: &[Point]) -> (f64, f64) {
    let n = window.len() as f64;
    let (x, y): (Vec<f64>, Vec<f64>) = window.iter().map(|p| (p.sigma.ln(), p.k.ln())).unzip();
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxx: f64 = x.iter().map(|x| (x - mx).powi(2)).sum();
    let m = x.iter().zip(&y).map(|(x, y)| (x - mx) * (y - my)).sum::<f64>() / sxx;
    let residual: f64 = x.iter().zip(&y).map(|(x, y)| (y - my - m * (x - mx)).powi(2)).sum();
    (m, (residual / (n - 2.0) / sxx).sqrt())
}

/// What one seed's sweep shows.
struct Analysis {
    /// Linear modulus: mean K of the first three intervals (γ ≤ 2.2e-4).
    k0: f64,
    /// Their (max − min)/K0.
    spread: f64,
    /// Largest K / K0.
    stiffening: f64,
    /// The stiffening regime: intervals with K ≥ 2·K0 that start with
    /// bending holding at least half the energy.
    window: Vec<Point>,
    /// Fitted m and its standard error there.
    m: f64,
    se: f64,
    /// m where stretching dominates (bending share < 5 % at the start).
    m_stretching: f64,
}

fn analyse(stages: &[Stage]) -> Analysis {
    let p = points(stages);
    let linear: Vec<f64> = p[..3].iter().map(|p| p.k).collect();
    let k0 = linear.iter().sum::<f64>() / 3.0;
    let spread = (linear.iter().copied().fold(f64::MIN, f64::max) - linear.iter().copied().fold(f64::MAX, f64::min)) / k0;
    let window: Vec<Point> = p.iter().copied().filter(|p| p.k >= 2.0 * k0 && p.bending >= 0.5).collect();
    let stretching: Vec<Point> = p.iter().copied().filter(|p| p.bending < 0.05).collect();
    let (m, se) = fit(&window);
    Analysis { k0, spread, stiffening: p.iter().map(|p| p.k).fold(0.0, f64::max) / k0, m, se, m_stretching: fit(&stretching).0, window }
}

#[test]
fn sheared_network_is_linear_then_stiffens_with_k_proportional_to_stress() {
    assert_eq!(
        std::fs::read_to_string("topologies/network_shear.top").unwrap(),
        network_of(1),
        "the deck's topology is not what its header's command writes"
    );
    let dir = tempfile::tempdir().unwrap();
    let second = dir.path().join("seed2.top");
    std::fs::write(&second, network_of(2)).unwrap();
    let sweeps = std::thread::scope(|s| {
        let first = s.spawn(|| sweep(None));
        let other = s.spawn(|| sweep(Some(&second)));
        [first.join().unwrap(), other.join().unwrap()]
    });
    let analyses: Vec<Analysis> = sweeps.iter().map(|s| analyse(s)).collect();
    for (seed, (stages, a)) in sweeps.iter().zip(&analyses).enumerate() {
        println!("seed {}: K0 = {:.4} pN/µm (spread {:.1e}), K_max/K0 = {:.0}", seed + 1, a.k0, a.spread, a.stiffening);
        println!("m = {:.3} ± {:.3} over {} points; m (stretching-dominated) = {:.2}", a.m, a.se, a.window.len(), a.m_stretching);
        println!("| γ | σ (pN/µm) | K (pN/µm) over the interval ending here | bending share | fit window |");
        println!("|---|---|---|---|---|");
        for (s, p) in stages.iter().zip(points(stages)) {
            let fitted = a.window.iter().any(|w| w.sigma == p.sigma);
            println!("| {:.3e} | {:.3e} | {:.3e} | {:.3} | {} |", s.gamma, s.sigma, p.k, s.bending, if fitted { "yes" } else { "" });
        }
        let worst = stages.iter().map(|s| s.drift).fold(0.0, f64::max);
        println!("largest relative change of σ over a stage's last step: {worst:.1e}");
        assert!(worst < 1e-2, "seed {}: a stage is not relaxed (σ still moves by {worst:e} per step)", seed + 1);
        assert!(a.k0 > 0.0 && a.spread < 0.02, "seed {}: no linear regime: K0 = {}, spread {}", seed + 1, a.k0, a.spread);
        assert!(a.stiffening >= 10.0, "seed {}: K rises only {}-fold", seed + 1, a.stiffening);
        assert!(a.window.len() >= 3, "seed {}: {} points in the stiffening regime", seed + 1, a.window.len());
        assert!(a.m_stretching < a.m, "seed {}: K grows faster once stretching dominates ({} > {})", seed + 1, a.m_stretching, a.m);
    }
    let tolerance = 2.0 * analyses[0].se.max(analyses[1].se).max((analyses[0].m - analyses[1].m).abs());
    println!("band: m = 1 ± {tolerance:.3}");
    assert!(tolerance < 0.25, "the two seeds scatter too much to tell m = 1 from 3/2: ±{tolerance}");
    for (seed, a) in analyses.iter().enumerate() {
        assert!((a.m - 1.0).abs() <= tolerance, "seed {}: m = {} ± {} outside 1 ± {tolerance}", seed + 1, a.m, a.se);
    }
}
