//! `cellmd build GENERATOR …` end to end: each generator's topology, written
//! by the binary, passes `cellmd check` with a small force field written
//! beside it; bad options exit with status 2 and say what was expected.

use std::path::Path;
use std::process::{Command, Output};

fn cellmd(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cellmd")).current_dir(dir).args(args).output().unwrap()
}

/// Builds `out.top` with `args` in `dir` and returns what the builder printed.
fn build_in(dir: &Path, args: &[&str]) -> String {
    let mut all = vec!["build"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["-o", "out.top"]);
    let built = cellmd(dir, &all);
    let said = String::from_utf8_lossy(&built.stdout).to_string();
    assert!(built.status.success(), "cellmd {all:?}: {}", String::from_utf8_lossy(&built.stderr));
    assert!(said.starts_with("wrote out.top: "), "{said}");
    said
}

/// Builds `out.top` with `args`, then checks a deck of it with the force
/// field `ff` (and the deck line `extra`, e.g. a box). Returns what the
/// builder printed.
fn build_and_check(args: &[&str], ff: &str, extra: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let said = build_in(dir.path(), args);
    std::fs::write(dir.path().join("ff.ff"), ff).unwrap();
    std::fs::write(dir.path().join("deck.in"), format!("units cell\ntopology out.top\nforcefield ff.ff\n{extra}timestep 1e-6\nrun 1\n"))
        .unwrap();
    let checked = cellmd(dir.path(), &["check", "deck.in"]);
    assert!(
        checked.status.success(),
        "cellmd check after {args:?}:\n{}{}",
        String::from_utf8_lossy(&checked.stdout),
        String::from_utf8_lossy(&checked.stderr)
    );
    said
}

const CHAIN_FF: &str = "particle bead drag 1\nbond segment harmonic k 100 r0 0.1\nangle bend wlc_bending kappa 0.07 l0 0.1\n";

#[test]
fn filament() {
    let said =
        build_and_check(&["filament", "--length", "2", "--segments", "20", "--direction", "1", "1", "0", "--box", "5"], CHAIN_FF, "");
    assert!(said.contains("21 beads, 20 bonds `segment`") && said.contains("wlc_bending kappa 6.994368e-2 l0 1.000000e-1"), "{said}");
}

#[test]
fn network() {
    let ff = format!("{CHAIN_FF}bond xl_stiff harmonic k 100 r0 0.05\nbond xl_soft harmonic k 5 r0 0.05\n");
    let said = build_and_check(
        &[
            "network",
            "--filaments",
            "40",
            "--length",
            "2",
            "--segment-length",
            "0.1",
            "--box",
            "5",
            "5",
            "5",
            "--planar",
            "--capture",
            "0.1",
            "--crosslinker-types",
            "xl_stiff:0.5,xl_soft:0.5",
            "--seed",
            "3",
        ],
        &ff,
        "",
    );
    assert!(said.contains("40 filaments × 21 beads") && said.contains("xl_stiff") && said.contains("xl_soft"), "{said}");
}

#[test]
fn aster() {
    let ff =
        format!("{CHAIN_FF}particle centrosome drag 10\nbond anchor harmonic k 100 r0 0.1\nangle clamp harmonic_angle k 10 theta0 180\n");
    let said = build_and_check(
        &["aster", "--microtubules", "12", "--length", "1", "--segments", "10", "--anchor-angle-type", "clamp", "--box", "3"],
        &ff,
        "",
    );
    assert!(said.contains("12 microtubules × 11 beads"), "{said}");
}

#[test]
fn cortex() {
    let ff = format!("{CHAIN_FF}bond crosslink harmonic k 10 r0 0.1\n");
    let said = build_and_check(
        &["cortex", "--radius", "3", "--filaments", "30", "--length", "2", "--segments", "20", "--capture", "0.15", "--seed", "2"],
        &ff,
        "box x -4 4 f y -4 4 f z -4 4 f\n",
    );
    assert!(said.contains("30 filaments × 21 beads on a sphere of radius 3.0") && said.contains("crosslinks"), "{said}");
}

#[test]
fn branched() {
    let ff = format!("{CHAIN_FF}bond branch harmonic k 100 r0 0.1\nangle branch_angle harmonic_angle k 2 theta0 70\n");
    let said = build_and_check(
        &["branched", "--mothers", "5", "--length", "1", "--segments", "10", "--branches", "2", "--branch-length", "0.5", "--box", "4"],
        &ff,
        "",
    );
    assert!(said.contains("5 mothers × 11 beads and 10 daughters × 5 beads") && said.contains("branch angles 70 ± 7 degrees"), "{said}");
}

#[test]
fn filopodium() {
    let ff = format!("{CHAIN_FF}bond fascin harmonic k 100 r0 0.02\n");
    let said = build_and_check(
        &[
            "filopodium",
            "--filaments",
            "7",
            "--length",
            "1",
            "--segments",
            "10",
            "--spacing",
            "0.02",
            "--crosslink-every",
            "2",
            "--box",
            "2",
        ],
        &ff,
        "",
    );
    assert!(said.contains("7 filaments × 11 beads on a hexagonal lattice") && said.contains("72 crosslinks (fascin 72)"), "{said}");
}

const CELL_FF: &str = "particle node drag 1\nparticle nucleus_node drag 1\nbond edge harmonic k 10 r0 0.3\nbond nucleus_edge harmonic k 10 r0 0.2\nbody cell turgor k 1000 v0 4\nbody nucleus turgor k 1000 v0 0.5\n";

#[test]
fn icosphere_with_a_nucleus() {
    let said = build_and_check(&["icosphere", "--level", "2", "--radius", "1", "--nucleus", "0.5", "--box", "2"], CELL_FF, "");
    assert!(said.contains("162 nodes") && said.contains("nucleus (body 2, radius 0.5)"), "{said}");
}

#[test]
fn cells_in_a_spheroid_and_a_layer() {
    let said = build_and_check(
        &[
            "cells",
            "--layout",
            "spheroid",
            "--count",
            "13",
            "--radius",
            "1",
            "--level",
            "1",
            "--gap",
            "0.1",
            "--spheroid-radius",
            "4",
            "--nucleus",
            "0.5",
            "--box",
            "5",
        ],
        CELL_FF,
        "",
    );
    assert!(said.contains("13 cells of radius 1.0 in a spheroid"), "{said}");
    let said =
        build_and_check(&["cells", "--layout", "layer", "--radius", "1", "--level", "1", "--gap", "0.1", "--box", "10", "10"], CELL_FF, "");
    assert!(said.contains("16 cells of radius 1.0 in a confluent layer"), "{said}");
}

#[test]
fn bad_options_exit_with_status_2_and_say_what_was_expected() {
    let dir = tempfile::tempdir().unwrap();
    for (args, expected) in [
        (&["filament", "--length", "-1", "--segments", "3"][..], "expected --length > 0, found -1"),
        (&["filament", "--length", "1", "--segments", "0"][..], "expected --segments >= 1, found 0"),
        (&["filament", "--length", "1"][..], "expected --segments N or --segment-length L"),
        (
            &["network", "--filaments", "3", "--length", "1", "--segments", "3", "--box", "5", "5", "5", "--capture", "0"][..],
            "expected --capture > 0, found 0",
        ),
        (
            &["cortex", "--radius", "1", "--filaments", "3", "--length", "1", "--segments", "3", "--capture", "-0.1"][..],
            "expected --capture > 0, found -0.1",
        ),
        (&["cells", "--layout", "spheroid", "--count", "100", "--radius", "1", "--spheroid-radius", "2"][..], "too many cells: at most"),
        (&["icosphere", "--level", "1", "--radius", "1", "--nucleus", "2"][..], "expected 0 < --nucleus RADIUS < --radius 1, found 2"),
        (&["sheet", "--rows", "2", "--columns", "2", "--cell-size", "-1"][..], "expected --cell-size > 0, found -1"),
        (&["sheet", "--rows", "2", "--columns", "2", "--cell-size", "3", "--jitter", "0.49", "--gap", "1"][..], "convex hexagon"),
    ] {
        let mut all = vec!["build"];
        all.extend_from_slice(args);
        all.extend_from_slice(&["-o", "x.top"]);
        let out = cellmd(dir.path(), &all);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{all:?}: {err}");
        assert!(err.contains(expected), "{all:?}: {err}");
        assert!(!dir.path().join("x.top").exists());
    }
}

/// The mean that the summary `said` prints after `what` ("… WHAT … mean b …").
fn printed_mean(said: &str, what: &str) -> f64 {
    let rest = said.split(what).nth(1).unwrap_or_else(|| panic!("no `{what}` in {said}"));
    rest.split(" mean ").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap()
}

/// Runs `deck` with the force field `ff` on `out.top` in `dir`; returns what it printed.
fn run_in(dir: &Path, ff: &str, deck: &str) -> String {
    std::fs::write(dir.join("ff.ff"), ff).unwrap();
    std::fs::write(dir.join("deck.in"), format!("units cell\ntopology out.top\nforcefield ff.ff\n{deck}")).unwrap();
    let out = cellmd(dir, &["run", "deck.in", "-o", ".", "--quiet"]);
    let said = String::from_utf8_lossy(&out.stdout).to_string();
    assert!(out.status.success(), "cellmd run:\n{deck}\n{said}{}", String::from_utf8_lossy(&out.stderr));
    said
}

/// The columns `names` (header `name[unit]`) of every row of a CSV file.
fn csv_columns(path: &Path, names: &[&str]) -> Vec<Vec<String>> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').map(|h| h.split('[').next().unwrap()).collect();
    let at: Vec<usize> =
        names.iter().map(|n| header.iter().position(|h| h == n).unwrap_or_else(|| panic!("no column {n} in {header:?}"))).collect();
    lines.map(|l| l.split(',').collect::<Vec<_>>()).map(|f| at.iter().map(|&k| f[k].to_string()).collect()).collect()
}

/// The junction bonds (ids) of the topology `out.top` in `dir`.
fn junctions_in(dir: &Path) -> Vec<(u64, u64)> {
    let top = std::fs::read_to_string(dir.join("out.top")).unwrap();
    let bonds = top.split("[ bonds ]").nth(1).unwrap().split("\n[").next().unwrap();
    let fields = bonds.lines().map(|l| l.split_whitespace().collect::<Vec<_>>());
    fields.filter(|f| f.first() == Some(&"junction")).map(|f| (f[1].parse().unwrap(), f[2].parse().unwrap())).collect()
}

const SHEET_FF: &str = "particle node drag 1\nparticle cell_centre drag 1\nbond edge harmonic k 50 r0 EDGE\nbond spoke harmonic k 10 r0 SPOKE\nbond junction harmonic k 20 r0 JUNCTION\n";

/// The sheet force field with the rest lengths `said` prints and the junction `kinetics`.
fn sheet_ff(said: &str, kinetics: &str) -> String {
    SHEET_FF
        .replace("EDGE", &printed_mean(said, "edge length").to_string())
        .replace("SPOKE", &printed_mean(said, "spoke length").to_string())
        .replace("JUNCTION", &format!("{}{kinetics}", printed_mean(said, "junctions `junction`: length")))
}

#[test]
fn sheet() {
    let said = build_and_check(
        &["sheet", "--rows", "3", "--columns", "4", "--cell-size", "2", "--nodes-per-edge", "0"],
        "particle cell_centre drag 1\nbond junction harmonic k 10 r0 2\n",
        "box x -9 9 f y -9 9 f z -1 1 f\n",
    );
    assert!(said.contains("12 cells (3 rows × 4 columns)") && said.contains("23 junctions `junction`"), "{said}");
    let setup =
        "box x -30 30 f y -30 30 f z -5 5 f\ntimestep 1e-3\nthermo_file thermo.csv\nthermo 100 step pe fmax breaks nbound/junction\n";

    // A jittered sheet of rings is pre-stressed as built (one rest length per
    // bond type); at kT = 0 it relaxes by gradient flow — the energy never
    // rises — towards a minimum that FIRE then reaches.
    let dir = tempfile::tempdir().unwrap();
    let said = build_in(
        dir.path(),
        &["sheet", "--rows", "4", "--columns", "6", "--cell-size", "3", "--nodes-per-edge", "2", "--jitter", "0.05", "--seed", "2"],
    );
    let printed = run_in(dir.path(), &sheet_ff(&said, ""), &format!("{setup}run 3000\nminimize ftol 1e-6 maxiter 100000\n"));
    let relax = csv_columns(&dir.path().join("thermo.csv"), &["pe", "fmax"]);
    let pe: Vec<f64> = relax.iter().map(|r| r[0].parse().unwrap()).collect();
    let fmax: Vec<f64> = relax.iter().map(|r| r[1].parse().unwrap()).collect();
    println!(
        "jittered sheet relaxing: pe {:.4e} → {:.4e} pN·µm, fmax {:.4e} → {:.4e} pN",
        pe[0],
        pe[pe.len() - 1],
        fmax[0],
        fmax[fmax.len() - 1]
    );
    assert!(pe.windows(2).all(|w| w[1] <= w[0]) && pe[pe.len() - 1] < 0.5 * pe[0], "{pe:?}");
    let fire = printed.lines().find(|l| l.starts_with("minimize (FIRE)")).unwrap_or_else(|| panic!("{printed}"));
    println!("then {fire}");
    assert!(fire.contains(": converged after"), "{fire}");

    // A regular sheet of hexagons (7 particles a cell, ids cell by cell, rows
    // from −y, each from −x) is at rest as built. Junctions break beyond a
    // force threshold F_c (seed 001). Pull the first column of cells S to
    // −x and the last to +x: only junctions join S to the rest, so at
    // equilibrium their tensions' x-components sum to the pull, and a pull
    // above n_S·F_c must break one; well below it the sheet holds.
    let (rows, columns, per_cell) = (4u64, 6u64, 7u64);
    let said = build_in(dir.path(), &["sheet", "--rows", "4", "--columns", "6", "--cell-size", "3", "--nodes-per-edge", "1"]);
    let fc = 1.0;
    let ff = sheet_ff(&said, &format!(" kinetics threshold force {fc}"));
    let junctions = junctions_in(dir.path());
    let total = junctions.len();
    assert_eq!(total, 2 * (5 * 4 + 3 * (2 * 6 - 1)));
    let column = |i: u64| (0..rows).map(move |j| (j * columns + i) * per_cell + 1).map(|first| (first, first + per_cell - 1));
    let in_first = |id: u64| column(0).any(|(a, b)| (a..=b).contains(&id));
    let n_s = junctions.iter().filter(|(i, j)| in_first(*i) != in_first(*j)).count() as f64;
    let group =
        |name: &str, i: u64| format!("group {name} id {}\n", column(i).map(|(a, b)| format!("{a}:{b}")).collect::<Vec<_>>().join(" "));
    let pulled = (rows * per_cell) as f64;
    let mut outcomes = Vec::new();
    for factor in [0.25, 0.5, 0.75, 1.0, 1.5] {
        let f = factor * n_s * fc / pulled;
        let deck = format!(
            "{setup}{}{}external pl left constant_force fx {}\nexternal pr right constant_force fx {f}\nrun 5000\n",
            group("left", 0),
            group("right", columns - 1),
            -f
        );
        run_in(dir.path(), &ff, &deck);
        let last = csv_columns(&dir.path().join("thermo.csv"), &["breaks", "nbound/junction"]).pop().unwrap();
        outcomes.push((factor, last[0].parse::<u64>().unwrap(), last[1].parse::<usize>().unwrap()));
    }
    println!("regular sheet pulled by factor × n_S·F_c (n_S = {n_s}): (factor, breaks, bound of {total}) {outcomes:?}");
    assert_eq!((outcomes[0].1, outcomes[0].2), (0, total), "{outcomes:?}");
    assert!(outcomes[4].1 > 0 && outcomes[4].2 < total, "{outcomes:?}");
}
