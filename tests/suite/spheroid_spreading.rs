//! Spheroid spreading on a ligand-coated substrate (seed 000, checkpoint 2):
//! `inputs/spheroid_spreading.in` on a two-cell spheroid (`cellmd build cells
//! --layout spheroid --count 2 --substrate flat`, R = √(A0/π) = 11.8 µm)
//! for at most 6000 steps, with clutch bonds to the ligand sites and
//! without, stopping at rest (the deck's `rest`: A changed by less than
//! STATIONARY over a window of 2000 steps).
//!
//! What is robust and asserted: with clutches the cells flatten onto the
//! dish (height below FLATTEN of the start) and the top-down silhouette
//! (`hullarea/cells`, the convex hull of the nodes projected on xy) grows,
//! A/A0 > SPREAD, held by more than MIN_CLUTCHES bound clutches; without
//! them the spheroid only settles: A/A0 within CONTROL of 1, its height
//! above 0.95 of the start, and its footprint at rest: the deck stops it
//! after the second window (the first has no earlier A to compare with).
//! The spread run does not come to rest in 6000 steps (it runs them all),
//! so its equilibrium is the study's (studies/spheroid_spreading/), as is
//! the A/A0(R) law.
//!
//! `cargo test --test suite spheroid_spreading:: -- --nocapture` prints the runs.

use std::path::Path;

use cellmd::build::{cells, CellsArgs, Common, Layout, SubstrateOptions};
use cellmd::deck::validate_file;
use cellmd::run::{RunOptions, Simulation};

const DECK: &str = "inputs/spheroid_spreading.in";
const SPREAD: f64 = 1.1;
const MIN_CLUTCHES: f64 = 100.0;
const FLATTEN: f64 = 0.85;
const CONTROL: f64 = 0.03;
const STATIONARY: f64 = 0.01;

/// The thermo rows of one run, one per step: (step, silhouette area µm², bound clutches, height µm).
fn spread(adhesion: u32) -> Vec<(f64, f64, f64, f64)> {
    let dir = tempfile::tempdir().unwrap();
    let args = |z: f64| CellsArgs {
        count: Some(2),
        radius: 8.0,
        level: 1,
        layout: Layout::Spheroid,
        gap: 0.2,
        spheroid_radius: Some(200.0),
        centre: vec![0.0, 0.0, z],
        box_size: vec![40.0],
        substrate: SubstrateOptions {
            substrate: Some("flat".into()),
            substrate_spacing: 2.0,
            substrate_gap: 0.5,
            substrate_extent: Some(30.0),
            ..SubstrateOptions::default()
        },
        common: Common { seed: 1, output: "spheroid.top".into(), rest_from_geometry: false },
        ..CellsArgs::default()
    };
    // Built around z = 0, then lowered so that the substrate lies at z = 0, the deck's dish.
    let first = cells(&args(0.0)).unwrap_or_else(|e| panic!("{e}"));
    let floor: f64 = first.text.split("touching z = ").nth(1).unwrap().split_whitespace().next().unwrap().parse().unwrap();
    let built = cells(&args(-floor)).unwrap();
    let top = dir.path().join("spheroid.top");
    std::fs::write(&top, &built.text).unwrap();
    let vars = [
        ("topology", top.display().to_string()),
        ("adhesion", adhesion.to_string()),
        ("steps", "6000".into()),
        ("interval", "1000".into()),
        ("window", "2000".into()),
        ("rest", STATIONARY.to_string()),
    ]
    .map(|(k, v)| (k.to_string(), v));
    let plan = validate_file(Path::new(DECK), &vars).unwrap_or_else(|e| panic!("{e}"));
    Simulation::execute(plan, RunOptions { output_dir: dir.path().to_path_buf(), ..Default::default() }).unwrap_or_else(|e| panic!("{e}"));
    let text = std::fs::read_to_string(dir.path().join("spheroid_spreading.thermo.csv")).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').map(|h| h.split('[').next().unwrap()).collect();
    let column = |name: &str| header.iter().position(|h| *h == name).unwrap_or_else(|| panic!("no column {name} in {header:?}"));
    let (step, area, bound, height) = (column("step"), column("hullarea/cells"), column("nbound/clutch"), column("zspan/cells"));
    let mut rows: Vec<(f64, f64, f64, f64)> = Vec::new();
    for l in lines {
        let row: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
        // A run's first row repeats the step of the run before: keep one.
        if rows.last().is_some_and(|r| r.0 == row[step]) {
            rows.pop();
        }
        rows.push((row[step], row[area], row[bound], row[height]));
    }
    rows
}

#[test]
fn a_spheroid_spreads_on_clutch_bonds_and_only_settles_without() {
    for (adhesion, label) in [(1, "clutch bonds"), (0, "no clutch bonds")] {
        let rows = spread(adhesion);
        let steps: Vec<f64> = rows.iter().map(|r| r.0).collect();
        let (first, last, window_before) = (rows[0], rows[rows.len() - 1], rows[rows.len() - 3]);
        let ratio = last.1 / first.1;
        let change = (last.1 / window_before.1 - 1.0).abs();
        let height = last.3 / first.3;
        println!(
            "{label}: {} steps, A0 = {:.1} µm² (R = {:.2} µm), A/A0 = {ratio:.3}, last window ΔA/A = {change:.1e}, height {height:.3} of the start, {} clutches",
            last.0,
            first.1,
            (first.1 / std::f64::consts::PI).sqrt(),
            last.2
        );
        if adhesion == 1 {
            assert_eq!(steps, (0..=6).map(|k| 1000.0 * k as f64).collect::<Vec<_>>(), "{label}: expected 6000 steps, a row every 1000");
            assert!(change >= STATIONARY, "with clutch bonds the deck stopped at rest, ΔA/A = {change}");
            assert!(ratio > SPREAD, "with clutch bonds A/A0 = {ratio}, expected > {SPREAD}");
            assert!(last.2 > MIN_CLUTCHES, "{} clutches bound, expected > {MIN_CLUTCHES}", last.1);
            assert!(height < FLATTEN, "with clutch bonds the height is {height} of the start, expected < {FLATTEN}");
        } else {
            assert!((ratio - 1.0).abs() < CONTROL, "without clutch bonds A/A0 = {ratio}, expected 1 ± {CONTROL}");
            assert_eq!(steps, (0..=4).map(|k| 1000.0 * k as f64).collect::<Vec<_>>(), "{label}: expected a stop at rest after 4000 steps");
            assert_eq!(last.2, 0.0);
            assert!(height > 0.95, "without clutch bonds the height is {height} of the start");
            assert!(change < STATIONARY, "without clutch bonds the last window changed A by {change}");
        }
    }
}
