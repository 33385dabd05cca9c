//! `cellmd build GENERATOR …` end to end: each generator's topology, written
//! by the binary, passes `cellmd check` with a small force field written
//! beside it; bad options exit with status 2 and say what was expected.

use std::path::Path;
use std::process::{Command, Output};

fn cellmd(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_cellmd")).current_dir(dir).args(args).output().unwrap()
}

/// Builds `out.top` with `args`, then checks a deck of it with the force
/// field `ff` (and the deck line `extra`, e.g. a box). Returns what the
/// builder printed.
fn build_and_check(args: &[&str], ff: &str, extra: &str) -> String {
    let dir = tempfile::tempdir().unwrap();
    let mut all = vec!["build"];
    all.extend_from_slice(args);
    all.extend_from_slice(&["-o", "out.top"]);
    let built = cellmd(dir.path(), &all);
    let said = String::from_utf8_lossy(&built.stdout).to_string();
    assert!(built.status.success(), "cellmd {all:?}: {}", String::from_utf8_lossy(&built.stderr));
    assert!(said.starts_with("wrote out.top: "), "{said}");
    std::fs::write(dir.path().join("ff.ff"), ff).unwrap();
    std::fs::write(dir.path().join("deck.in"), format!("units cell\ntopology out.top\nforcefield ff.ff\n{extra}timestep 1e-6\nrun 1\n"))
        .unwrap();
    let checked = cellmd(dir.path(), &["check", "deck.in"]);
    assert!(
        checked.status.success(),
        "cellmd check after {all:?}:\n{}{}",
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

/// A slab for shear with pinned crosslinks: its cut ends are the `base` and
/// `plate` types, which a force field declares `fixed`.
#[test]
fn network_slab() {
    let ff = format!("{CHAIN_FF}particle base fixed\nparticle plate fixed\nbond crosslink harmonic k 100 r0 0\n");
    let args =
        ["network", "--filaments", "40", "--length", "2", "--segments", "20", "--box", "5", "5", "1", "--planar", "--capture", "0.1"];
    let said = build_and_check(&[&args[..], &["--slab", "y", "--pin-crosslinks", "--seed", "2"]].concat(), &ff, "");
    assert!(
        said.contains("planar, slab box 5 × 5 × 1") && said.contains("slab: y fixed at 0 and 5, the filaments cut there into"),
        "{said}"
    );
    assert!(said.contains("pinned: each crosslink's bead also bonded to its partner's nearer neighbour"), "{said}");
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
            &[
                "network",
                "--filaments",
                "3",
                "--length",
                "1",
                "--segments",
                "3",
                "--box",
                "5",
                "5",
                "5",
                "--capture",
                "0.1",
                "--planar",
                "--slab",
                "z",
            ][..],
            "expected --slab x or y for a --planar network",
        ),
        (
            &["cortex", "--radius", "1", "--filaments", "3", "--length", "1", "--segments", "3", "--capture", "-0.1"][..],
            "expected --capture > 0, found -0.1",
        ),
        (&["cells", "--layout", "spheroid", "--count", "100", "--radius", "1", "--spheroid-radius", "2"][..], "too many cells: at most"),
        (&["icosphere", "--level", "1", "--radius", "1", "--nucleus", "2"][..], "expected 0 < --nucleus RADIUS < --radius 1, found 2"),
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
