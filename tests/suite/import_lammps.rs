//! `cellmd import-lammps`: a deck exported to LAMMPS and imported back is the
//! same system — every particle's force and the total energy agree with the
//! original deck's (CPU backend, f64) — and what cannot be translated is
//! listed, not dropped.

use std::path::Path;

use cellmd::deck::validate_file;
use cellmd::export::import_lammps::import_files;
use cellmd::export::{export, lammps, ExportOptions};
use cellmd::run::{RunOptions, Simulation};

/// Forces by particle id and the total energy of a deck's initial state.
fn forces_and_energy(deck: &Path) -> (Vec<(u64, glam::DVec3)>, f64) {
    let plan = validate_file(deck, &[]).unwrap_or_else(|e| panic!("{e}"));
    let mut sim = Simulation::before_first_run(&plan, RunOptions::default()).unwrap();
    let forces = sim.current_forces().unwrap().clone();
    let mut by_id: Vec<(u64, glam::DVec3)> = sim.model.ids.iter().copied().zip(forces.forces.iter().copied()).collect();
    by_id.sort_by_key(|p| p.0);
    (by_id, forces.total_energy())
}

fn round_trip(reference: &str) -> cellmd::export::import_lammps::Imported {
    let deck = Path::new("reference").join(reference).join("random.in");
    let dir = tempfile::tempdir().unwrap();
    let plan = validate_file(&deck, &[]).unwrap();
    lammps::write(&export(&plan, ExportOptions { probes: false }).unwrap(), &dir.path().join("lmp")).unwrap();
    let lmp = dir.path().join("lmp");
    let imported = import_files(&lmp.join("data.lammps"), Some(&lmp.join("in.lammps")), &dir.path().join("imp")).unwrap();
    let (want, e_want) = forces_and_energy(&deck);
    let (got, e_got) = forces_and_energy(&dir.path().join("imp/system.in"));
    assert_eq!(want.len(), got.len(), "{reference}: particle count");
    let scale = want.iter().map(|p| p.1.length()).fold(0.0, f64::max);
    assert!(scale > 0.0, "{reference}: no force to compare");
    for ((id, f), (id2, g)) in want.iter().zip(&got) {
        assert_eq!(id, id2);
        assert!((*f - *g).length() <= 1e-12 * scale, "{reference}: particle {id}: {f} vs {g}");
    }
    assert!((e_want - e_got).abs() <= 1e-12 * e_want.abs().max(1.0), "{reference}: energy {e_want} vs {e_got}");
    imported
}

#[test]
fn exported_decks_import_back_to_the_same_forces_and_energy() {
    for reference in ["harmonic", "fene", "lj", "wca", "soft", "soft_repulsion", "harmonic_angle", "cosine_angle"] {
        let imported = round_trip(reference);
        assert!(imported.notes.is_empty(), "{reference}: {:?}", imported.notes);
        assert!(imported.deck.contains("temperature 0.0"), "{reference}: the export's `rng none` means no noise");
    }
}

#[test]
fn what_is_not_translated_is_listed() {
    let data = "title\n\n2 atoms\n1 atom types\n\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nMasses\n\n1 2.5\n\nAtoms # atomic\n\n1 1 0.1 0.2 0.3\n2 1 0.5 0.5 0.5\n\nPair Coeffs\n\n1 1.0 1.0\n";
    let script = "units real\nboundary p f p\npair_style morse 2.0\npair_coeff 1 1 1.0 2.0 1.0\nfix 1 all nve\n";
    let imported = cellmd::export::import_lammps::import("d.data", data, Some(script)).unwrap();
    let notes = imported.notes.join("\n");
    for expected in [
        "only `units lj`",
        "pair style `morse`",
        "`fix 1 all nve`: not translated",
        "its drag is its mass 2.5",
        "section `Pair Coeffs` is not translated",
    ] {
        assert!(notes.contains(expected), "notes lack {expected:?}:\n{notes}");
    }
    assert!(imported.topology.contains("y 0.0 1.0 f"), "{}", imported.topology);
    assert!(imported.forcefield.contains("particle t1 drag 2.5"));
    assert!(imported.deck.contains("#   INPUT:4: `pair_coeff 1 1 1.0 2.0 1.0`"));
    // A style it does not know is an error, not a guess.
    let bad = data.replace("Atoms # atomic", "Atoms # ellipsoid");
    assert!(cellmd::export::import_lammps::import("d.data", &bad, None).unwrap_err().contains("atom style `ellipsoid`"));
}
