//! Collagen clustering (seed 002, Ouyang et al. 2022; issue #19): the study
//! deck `inputs/collagen_two_cells.in` on its two-cell network with shorter
//! stages (see docs/src/validation/collagen.md), and the thermo column
//! `clustering/BONDTYPE/GROUP_A/GROUP_B` on a configuration whose profile is
//! known exactly.
//!
//! `cargo test --test suite collagen:: -- --nocapture` prints the measured ratios.

use std::path::Path;
use std::process::Command;

use cellmd::deck::validate_file;
use cellmd::run::{RunOptions, Simulation};

/// The network of the CI test: the study's two-cell topology
/// (`topologies/collagen_two_cells.top`: cells of radius 100 µm, 600 µm
/// apart, 83 ring nodes, fibres 200 µm long at 0.1 µm⁻¹, node spacing 10 µm,
/// in 1000 × 600 µm), built anew by the builder.
const NETWORK: [&str; 17] = [
    "--layout",
    "pair",
    "--separation",
    "600",
    "--cell-radius",
    "100",
    "--size",
    "1000",
    "600",
    "--density",
    "0.1",
    "--fibre-length",
    "200",
    "--node-spacing",
    "10",
    "--seed",
    "1",
];

/// Stages and steps per stage of the CI runs (the study: 10 × 1000; the paper: 50 000 steps per stage).
const STAGES: u32 = 8;
const STEPS: u32 = 500;

/// Builds the network into `dir` and returns the topology's path; it is the committed one.
fn network(dir: &Path) -> std::path::PathBuf {
    let top = dir.join("collagen.top");
    let out = Command::new(env!("CARGO_BIN_EXE_cellmd")).arg("build").arg("collagen").args(NETWORK).arg("-o").arg(&top).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let committed = std::fs::read_to_string("topologies/collagen_two_cells.top").unwrap();
    assert_eq!(std::fs::read_to_string(&top).unwrap(), committed, "topologies/collagen_two_cells.top is not what the builder writes");
    top
}

/// Runs the study deck with fibre compression stiffness `kc` and returns the
/// clustering ratio at the end of each stage (stage 0: as built).
fn ratios(top: &Path, kc: f64) -> Vec<f64> {
    let dir = tempfile::tempdir().unwrap();
    let vars: Vec<(String, String)> =
        [("kc", kc.to_string()), ("stages", STAGES.to_string()), ("steps", STEPS.to_string()), ("top", top.display().to_string())]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
    let plan = validate_file(Path::new("inputs/collagen_two_cells.in"), &vars).unwrap_or_else(|e| panic!("{e}"));
    Simulation::execute(plan, RunOptions { output_dir: dir.path().to_path_buf(), ..Default::default() }).unwrap_or_else(|e| panic!("{e}"));
    let thermo = std::fs::read_to_string(dir.path().join("collagen_two_cells.thermo.csv")).unwrap();
    let header: Vec<&str> = thermo.lines().next().unwrap().split(',').collect();
    let k = header.iter().position(|h| h.starts_with("clustering/fibre/cell1/cell2[")).unwrap();
    // Each run writes a row at its start and its end: keep one per step.
    let mut rows: Vec<(u64, f64)> = Vec::new();
    for line in thermo.lines().skip(1) {
        let f: Vec<&str> = line.split(',').collect();
        let (step, value) = (f[0].parse().unwrap(), f[k].parse().unwrap());
        match rows.last_mut() {
            Some(last) if last.0 == step => last.1 = value,
            _ => rows.push((step, value)),
        }
    }
    let steps: Vec<u64> = rows.iter().map(|r| r.0).collect();
    assert_eq!(steps, (0..=STAGES as u64).map(|s| s * STEPS as u64).collect::<Vec<_>>());
    rows.into_iter().map(|r| r.1).collect()
}

#[test]
fn fibres_cluster_between_contracting_cells_whether_or_not_they_are_asymmetric() {
    let dir = tempfile::tempdir().unwrap();
    let top = network(dir.path());
    let asymmetric = ratios(&top, 1.0);
    let symmetric = ratios(&top, 100.0);
    println!("stage  S_max/S_min asymmetric (k_t = 100 k_c)  symmetric (k_t = k_c)");
    for (s, (a, b)) in asymmetric.iter().zip(&symmetric).enumerate() {
        println!("{s:>5}  {a:.4}  {b:.4}");
    }
    // The same network as built: the same ratio, near 1 (a random network's noise).
    assert_eq!(asymmetric[0], symmetric[0]);
    assert!((asymmetric[0] - 1.0).abs() < 0.1, "{asymmetric:?}");
    // Fibres gather between the contracting cells: the ratio exceeds 1 and
    // grows with every stage (on this network; on two of five others the
    // paper column falls).
    for r in [&asymmetric, &symmetric] {
        assert!(r.windows(2).all(|w| w[1] > w[0]), "not growing at every stage: {r:?}");
        assert!(r[STAGES as usize] > r[0] + 0.2, "grew by less than 0.2: {r:?}");
    }
    // The paper's claim that the asymmetry drives it is NOT what this model
    // gives: with compression as stiff as tension the ratio grows as much
    // (within 5 % of the asymmetric growth). Over five realisations (docs/src/validation/collagen.md,
    // *Asymmetric against symmetric fibres*) the difference is +0.03 ± 0.03
    // against a spread of 0.38 between networks; longer stages do not change
    // it, 10× stiffer bending gives +0.08 ± 0.05 and one bond per segment
    // +0.07 ± 0.04 (15 networks): a fifth of the spread, not assertable here.
    let grown = |r: &[f64]| r[STAGES as usize] - r[0];
    assert!(
        (grown(&symmetric) - grown(&asymmetric)).abs() < 0.05 * grown(&asymmetric),
        "asymmetric {asymmetric:?}, symmetric {symmetric:?}"
    );
}

/// Two square "cells" of radius 1 at (±5, 0), rotated by `angle` about the
/// origin with the fibres, and four fibres: three across the whole band (at
/// 0.05 and ±1.45 from the axis) and one of 6 along the axis, plus one
/// crossing the band at right angles.
fn measured_ratio(angle: f64) -> f64 {
    let dir = tempfile::tempdir().unwrap();
    let (s, c) = angle.sin_cos();
    let at = |x: f64, y: f64| format!("{} {} 0", c * x - s * y, s * x + c * y);
    let mut top = String::from("[ particles ]\n");
    let points = [
        (-6.0, 0.0),
        (-5.0, 1.0),
        (-4.0, 0.0),
        (-5.0, -1.0),
        (4.0, 0.0),
        (5.0, 1.0),
        (6.0, 0.0),
        (5.0, -1.0),
        (-6.0, 0.05),
        (6.0, 0.05),
        (-6.0, 1.45),
        (6.0, 1.45),
        (-6.0, -1.45),
        (6.0, -1.45),
        (-3.0, 0.06),
        (3.0, 0.06),
        (0.0, -2.0),
        (0.0, 2.0),
    ];
    for (k, &(x, y)) in points.iter().enumerate() {
        top += &format!("{} bead {}\n", k + 1, at(x, y));
    }
    top += "[ bonds ]\n";
    for k in (9..18).step_by(2) {
        top += &format!("fibre {k} {}\n", k + 1);
    }
    std::fs::write(dir.path().join("two.top"), top).unwrap();
    std::fs::write(dir.path().join("two.ff"), "particle bead drag 1\nbond fibre harmonic k 1 r0 1\n").unwrap();
    let deck = "units cell\ntopology two.top\nforcefield two.ff\nbox x -20 20 f y -20 20 f z -5 5 f\ngroup a id 1:4\ngroup b id 5:8\n\
                timestep 0.001\nthermo 0 step clustering/fibre/a/b\nthermo_file two.csv\nrun 0\n";
    std::fs::write(dir.path().join("two.in"), deck).unwrap();
    let plan = validate_file(&dir.path().join("two.in"), &[]).unwrap_or_else(|e| panic!("{e}"));
    Simulation::execute(plan, RunOptions { output_dir: dir.path().to_path_buf(), ..Default::default() }).unwrap();
    let csv = std::fs::read_to_string(dir.path().join("two.csv")).unwrap();
    assert!(csv.starts_with("step[-],clustering/fibre/a/b[-]\n"), "{csv}");
    csv.lines().last().unwrap().split(',').nth(1).unwrap().parse().unwrap()
}

#[test]
fn the_clustering_column_is_the_profile_ratio_across_the_band() {
    // The ROI: x from −4 to 4 (the gap), |y| ≤ 1.5 (1.5 × (r_A + r_B) wide)
    // in 21 strips of 1/7. Strip 10 holds 8 + 6 along the axis, strips 0 and
    // 20 hold 8 each, and the crossing fibre puts 1/7 in every strip. S_max:
    // strips 7–13, (14 + 7/7)/7; S_min: strips 0–2 and 18–20, 2(8 + 3/7)/6.
    let expected = (15.0 / 7.0) / (2.0 * (8.0 + 3.0 / 7.0) / 6.0);
    for angle in [0.0, 0.5, 2.0] {
        let r = measured_ratio(angle);
        assert!((r - expected).abs() < 1e-9, "angle {angle}: {r} against {expected}");
    }
}
