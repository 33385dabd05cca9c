//! Tissue fracture (seed 001, issue #19): the study deck
//! `inputs/tissue_fracture.in` on a small sheet of the reduced model, at two
//! corners of the phase diagram. Strong re-bonding (fast binding, fast
//! maturation) under a low force gradient flows by neighbour exchange
//! (ductile); weak re-bonding (slow binding, slow maturation) under a high
//! gradient tears (brittle). The labels come from the `fracture/junction/…`
//! thermo columns, whose numbers are asserted too.
//!
//! `cargo test --test suite tissue_fracture:: -- --nocapture` prints them.

use std::path::Path;
use std::process::Command;

use cellmd::deck::validate_file;
use cellmd::run::{RunOptions, Simulation};

/// The final `fracture/junction/…` values of a run.
#[derive(Debug)]
struct Outcome {
    broken: f64,
    rearranged: f64,
    ratio: f64,
    crack: f64,
    pieces: f64,
    label: f64,
}

/// Runs the study deck on a 6 × 10 sheet with the force field's
/// `threshold strain`, binding rate `k_on` and maturation time `tau` (and
/// capture D·(1 + 0.75·strain), as studies/tissue_fracture/sweep.py sets it).
fn run_point(g: f64, strain: f64, k_on: f64, tau: f64, steps: u64) -> Outcome {
    let dir = tempfile::tempdir().unwrap();
    let top = dir.path().join("sheet.top");
    let status = Command::new(env!("CARGO_BIN_EXE_cellmd"))
        .args([
            "build",
            "sheet",
            "--rows",
            "6",
            "--columns",
            "10",
            "--cell-size",
            "3",
            "--nodes-per-edge",
            "0",
            "--centre-type",
            "cell",
            "-o",
        ])
        .arg(&top)
        .output()
        .unwrap();
    assert!(status.status.success(), "{}", String::from_utf8_lossy(&status.stderr));
    let ff = std::fs::read_to_string("forcefields/tissue_fracture.ff")
        .unwrap()
        .replace("threshold strain 0.8 ", &format!("threshold strain {strain} "))
        .replace("k_on 20 ", &format!("k_on {k_on} "))
        .replace("maturation tau 0.5", &format!("maturation tau {tau}"))
        .replace("capture 4.8 ", &format!("capture {} ", 3.0 * (1.0 + 0.75 * strain)));
    for changed in
        [format!("strain {strain} "), format!("k_on {k_on} "), format!("tau {tau}"), format!("capture {}", 3.0 * (1.0 + 0.75 * strain))]
    {
        assert!(ff.contains(&changed), "the force field no longer has the values this test replaces ({changed})");
    }
    std::fs::write(dir.path().join("point.ff"), ff).unwrap();
    let vars: Vec<(String, String)> = [
        ("g", g.to_string()),
        ("tau", tau.to_string()),
        ("steps", steps.to_string()),
        ("top", top.display().to_string()),
        ("ff", dir.path().join("point.ff").display().to_string()),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v))
    .collect();
    let plan = validate_file(Path::new("inputs/tissue_fracture.in"), &vars).unwrap_or_else(|e| panic!("{e}"));
    Simulation::execute(plan, RunOptions { output_dir: dir.path().to_path_buf(), ..Default::default() }).unwrap_or_else(|e| panic!("{e}"));
    let thermo = std::fs::read_to_string(dir.path().join("tissue_fracture.thermo.csv")).unwrap();
    let header: Vec<&str> = thermo.lines().find(|l| l.starts_with("step")).unwrap().split(',').collect();
    let last: Vec<f64> = thermo.lines().last().unwrap().split(',').map(|v| v.parse().unwrap()).collect();
    let value = |name: &str| {
        let k = header.iter().position(|h| h.starts_with(&format!("fracture/junction/{name}["))).unwrap();
        last[k]
    };
    Outcome {
        broken: value("broken"),
        rearranged: value("rearranged"),
        ratio: value("ratio"),
        crack: value("crack"),
        pieces: value("pieces"),
        label: value("label"),
    }
}

#[test]
fn strong_rebinding_at_a_low_gradient_is_ductile() {
    let o = run_point(1.0, 0.8, 20.0, 0.5, 3000);
    println!("ductile corner: {o:?}");
    assert_eq!(o.label, 1.0, "{o:?}");
    assert_eq!(o.pieces, 1.0);
    assert!(o.broken >= 5.0, "too few junctions broke to call it flow: {o:?}");
    assert!(o.ratio >= 0.5 && o.rearranged >= 0.5 * o.broken);
}

#[test]
fn weak_rebinding_at_a_high_gradient_is_brittle() {
    let o = run_point(2.0, 0.1, 0.05, 10.0, 3000);
    println!("brittle corner: {o:?}");
    assert_eq!(o.label, 2.0, "{o:?}");
    assert!(o.pieces >= 2.0, "the sheet did not separate: {o:?}");
    assert!(o.ratio < 0.5);
    assert!(o.crack >= 10.0, "no crack across the sheet: {o:?}");
}
