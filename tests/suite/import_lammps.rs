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
        // The export's thermo output settings have no cellmd counterpart; nothing else is left out.
        let physics: Vec<&String> =
            imported.notes.iter().filter(|n| !n.contains("`thermo_style") && !n.contains("`thermo_modify")).collect();
        assert!(physics.is_empty(), "{reference}: {physics:?}");
        assert!(imported.deck.contains("temperature 0.0"), "{reference}: the export's `rng none` means no noise");
    }
}

#[test]
fn what_is_not_translated_is_listed() {
    let data = "title\n\n2 atoms\n1 atom types\n\n0 1 xlo xhi\n0 1 ylo yhi\n0 1 zlo zhi\n\nMasses\n\n1 2.5\n\nAtoms # atomic\n\n1 1 0.1 0.2 0.3\n2 1 0.5 0.5 0.5\n\nVelocities\n\n1 0 0 0\n2 0 0 0\n";
    let script = "units real\nboundary p f p\npair_style morse 2.0\npair_coeff 1 1 1.0 2.0 1.0\nfix 1 all nve\ncompute c all pe\nthermo_style custom step pe\n";
    let imported = cellmd::export::import_lammps::import("d.data", data, Some(("in", script))).unwrap();
    let notes = imported.notes.join("\n");
    for expected in [
        "in:1: `units real`: only `units lj`",
        "in:4: `pair_coeff 1 1 1.0 2.0 1.0`: pair style `morse` is not translated",
        "in:5: `fix … nve` without `fix … langevin` (inertial dynamics) is not translated",
        "in:6: `compute c all pe`: not translated",
        "in:7: `thermo_style custom step pe`: not translated",
        "d.data:19: section `Velocities` is not translated",
        "type 1 (`t1`): no fix brownian or langevin moves it, so it is `fixed`",
    ] {
        assert!(notes.contains(expected), "notes lack {expected:?}:\n{notes}");
    }
    assert!(imported.topology.contains("y 0.0 1.0 f"), "{}", imported.topology);
    assert!(imported.forcefield.contains("particle t1 fixed"));
    assert!(imported.deck.contains("#   in:4: `pair_coeff 1 1 1.0 2.0 1.0`"));
    // A style it does not know is an error, not a guess.
    let bad = data.replace("Atoms # atomic", "Atoms # ellipsoid");
    assert!(cellmd::export::import_lammps::import("d.data", &bad, None).unwrap_err().contains("atom style `ellipsoid`"));
}

/// Each `tests/lammps/bad/*.in` (reading `tests/lammps/bad/two.data`)
/// starts with `# expect: MESSAGE`, the exact import error, at its
/// `file:line:col`; the CLI exits 2 with it and writes nothing.
#[test]
fn bad_lammps_input_is_an_error_at_its_place() {
    let mut checked = 0;
    for entry in std::fs::read_dir("tests/lammps/bad").unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_none_or(|e| e != "in") {
            continue;
        }
        let text = std::fs::read_to_string(&path).unwrap();
        let expected = text
            .lines()
            .next()
            .and_then(|l| l.strip_prefix("# expect: "))
            .unwrap_or_else(|| panic!("{} lacks `# expect:`", path.display()));
        let out = tempfile::tempdir().unwrap();
        let result = std::process::Command::new(env!("CARGO_BIN_EXE_cellmd"))
            .args(["import-lammps", path.to_str().unwrap(), "-o", out.path().join("imp").to_str().unwrap()])
            .output()
            .unwrap();
        assert_eq!(result.status.code(), Some(2), "{}", path.display());
        let stderr = String::from_utf8_lossy(&result.stderr);
        assert_eq!(stderr.trim(), format!("error: {expected}"), "{}", path.display());
        assert!(!out.path().join("imp").exists(), "{}: wrote output", path.display());
        checked += 1;
    }
    assert!(checked >= 5, "only {checked} bad inputs");
}

/// The LAMMPS decks written for the import (`tests/lammps/NAME/in.lammps`
/// and its data file; `tests/lammps/make_data.py` wrote the data): each
/// exercises idioms of real decks (see their comments).
const DECKS: &[&str] = &["molecular", "full_lepton", "small_box"];

/// The probe commands put before a deck's first `run`: LAMMPS' step-0
/// energy, virial, positions and forces in the files `cellmd compare` reads.
const PROBE: &str = "compute cellmd_virial all pressure NULL virial\n\
    thermo_style custom step pe c_cellmd_virial[1] c_cellmd_virial[2] c_cellmd_virial[3] c_cellmd_virial[4] c_cellmd_virial[5] c_cellmd_virial[6] vol\n\
    thermo_modify norm no\n\
    run 0 post no\n\
    print \"step $(step) init\" file cellmd_probe.txt screen no\n\
    print \"energy total $(pe:%.17g)\" append cellmd_probe.txt screen no\n\
    print \"virial $(c_cellmd_virial[1]*vol:%.17g) $(c_cellmd_virial[2]*vol:%.17g) $(c_cellmd_virial[3]*vol:%.17g) $(c_cellmd_virial[4]*vol:%.17g) $(c_cellmd_virial[5]*vol:%.17g) $(c_cellmd_virial[6]*vol:%.17g)\" append cellmd_probe.txt screen no\n\
    write_dump all custom cellmd_probe_init.dump id xu yu zu fx fy fz modify format float %.17g sort id\n\
    quit\n";

/// LAMMPS' step-0 probes of a deck, run by `$CELLMD_LMP` (None when unset).
fn lammps_step0(dir: &Path) -> Option<cellmd::compare::Probes> {
    let lmp = cellmd::compare::Lmp::at(std::env::var_os("CELLMD_LMP")?.into());
    let work = tempfile::tempdir().unwrap();
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        std::fs::copy(&path, work.path().join(path.file_name().unwrap())).unwrap();
    }
    let text = std::fs::read_to_string(dir.join("in.lammps")).unwrap();
    let first_run = text.lines().position(|l| l.split_whitespace().next() == Some("run")).expect("a run");
    // Forces at step 0 are the force field's: fix langevin would add its drag and noise at setup.
    let unfix: String = text
        .lines()
        .filter_map(|l| match l.split_whitespace().collect::<Vec<_>>()[..] {
            ["fix", id, _, "langevin", ..] => Some(format!("unfix {id}\n")),
            _ => None,
        })
        .collect();
    let probe = unfix + PROBE;
    let mut lines: Vec<&str> = text.lines().collect();
    lines.insert(first_run, &probe);
    std::fs::write(work.path().join("in.lammps"), lines.join("\n")).unwrap();
    let version = lmp.run(work.path()).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
    println!("{}: {version}", dir.display());
    Some(cellmd::compare::lammps_probes(work.path(), &[]).unwrap())
}

/// A snapshot's energies as one total (LAMMPS' `pe`; cellmd's `custom`
/// laws span bonds, angles and pairs, so per-style keys would not line up).
fn total_only(mut s: cellmd::compare::Snapshot) -> cellmd::compare::Snapshot {
    let total = s.total_energy();
    s.energies = [("total".to_string(), total)].into();
    s
}

/// Every LAMMPS deck of tests/lammps/ imports (its `in.lammps` alone, which
/// names its data file) and runs in cellmd to its end with no hand edit, and
/// at step 0 its energy, forces and virial agree with LAMMPS' within 1e-12:
/// with `$CELLMD_LMP` set (the cross-check stage of `scripts/test-all`)
/// LAMMPS runs the deck now, and its answers must also match the committed
/// `lammps.yaml` (`CELLMD_LAMMPS_GOLDEN=write` rewrites it); without
/// LAMMPS, cellmd is checked against that file.
#[test]
fn lammps_decks_import_run_to_their_end_and_match_lammps_at_step_zero() {
    let tol = cellmd::compare::Tolerance { single_point: 1e-12, run: 1e-12 };
    for name in DECKS {
        let dir = Path::new("tests/lammps").join(name);
        let out = tempfile::tempdir().unwrap();
        let imported = import_files(&dir.join("in.lammps"), None, out.path()).unwrap_or_else(|e| panic!("{name}: {e}"));
        let plan = validate_file(&out.path().join("system.in"), &[]).unwrap_or_else(|e| panic!("{name}: {e}\n{}", imported.deck));
        // The whole deck runs: its last probe is at the sum of its runs.
        let steps: u64 = plan.actions.iter().filter_map(|a| if let cellmd::deck::Action::Run(n) = a { Some(*n) } else { None }).sum();
        let whole = cellmd::compare::cellmd_probes(&plan).unwrap_or_else(|e| panic!("{name}: the imported deck stopped: {e}"));
        assert!(
            steps > 0 && whole.last.as_ref().map(|l| l.step) == Some(steps),
            "{name}: ran to {:?} of {steps}",
            whole.last.map(|l| l.step)
        );
        let ours = cellmd::compare::cellmd_probes(&cellmd::compare::up_to_first_run(&plan)).unwrap();
        let ours = cellmd::compare::Probes { init: total_only(ours.init), last: None };
        let golden_path = dir.join("lammps.yaml");
        let live = lammps_step0(&dir).map(|p| cellmd::compare::Probes { init: total_only(p.init), last: None });
        if let (Some(live), Ok("write")) = (&live, std::env::var("CELLMD_LAMMPS_GOLDEN").as_deref()) {
            let header = [
                ("generator", "LAMMPS (22 Jul 2025 - Update 4), the deck as written plus step-0 probes".to_string()),
                ("epsilon", "1e-12".into()),
            ];
            std::fs::write(&golden_path, cellmd::compare::golden::write(&[cellmd::compare::golden::document_of(&header, live)])).unwrap();
        }
        let text = std::fs::read_to_string(&golden_path)
            .unwrap_or_else(|e| panic!("{}: {e} (write it with CELLMD_LAMMPS_GOLDEN=write)", golden_path.display()));
        let golden = cellmd::compare::golden::probes_of(&cellmd::compare::golden::parse(&text).unwrap()[0]).unwrap();
        let mut references = vec![("golden", golden.clone())];
        if let Some(live) = live {
            let drift = cellmd::compare::Agreement::new(&live, &golden).unwrap();
            assert!(drift.agrees(tol), "{name}: LAMMPS drifted from {}:\n{}", golden_path.display(), drift.table("golden", tol));
            references.push(("LAMMPS", live));
        }
        for (who, reference) in references {
            let agreement = cellmd::compare::Agreement::new(&ours, &reference).unwrap();
            println!("{name}: worst relative error against {who} {:.1e} at step 0", agreement.init.worst());
            assert!(agreement.agrees(tol), "{name}: cellmd disagrees with {who}:\n{}", agreement.table(who, tol));
            assert!(agreement.init.force_scale > 0.0 && agreement.init.virial_scale > 0.0);
        }
    }
}
