//! cellmd against the golden reference files in `reference/` (LAMMPS' answers
//! recorded by `reference/regenerate`), with no Python or LAMMPS needed.
//!
//! Each `reference/NAME.yaml` holds one document per case (`small`: 1–3
//! particles; `random`: ≥ 100 particles, periodic where the type allows).
//! Energies, forces and virial at step 0 must agree within the file's
//! `epsilon`, positions, forces and energies after the run within its
//! `run_epsilon` (figures defined in `cellmd::compare::Agreement`).
//!
//! The golden files of bond kinetics (`threshold.yaml`: LAMMPS `fix
//! bond/break`; `bind.yaml`: `fix bond/create`) also record the bound bonds
//! at the start and after the run, and cellmd must end with the same set.
//!
//! `per_bond_r0.yaml` checks a feature rather than one type: bonds with their
//! own rest lengths (`type i j r0`), exported as one LAMMPS bond type per
//! distinct (type, r0).
//!
//! The surface (`body`) types have no LAMMPS style: their golden files come
//! from OpenMM custom forces (`reference/openmm_surfaces.py`; the generator
//! header says which engine produced a file); so do the volume-element
//! (`tetra`) types (`reference/openmm_solids.py`).

use std::path::{Path, PathBuf};

use cellmd::compare::{cellmd_probes, golden, Agreement, Probes};
use cellmd::deck::validate_file;
use cellmd::interactions::REGISTRY;

fn documents(path: &Path) -> Vec<golden::Document> {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    golden::parse(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Whether a golden file checks bond kinetics (named after a kinetic rule,
/// or `bind` for formation) rather than an interaction.
fn is_kinetics(path: &Path) -> bool {
    let name = path.file_stem().unwrap().to_str().unwrap();
    name == "bind" || cellmd::kinetics::lookup_rule(name).is_some()
}

/// Whether a golden document was produced by OpenMM (the surface types)
/// rather than by LAMMPS through `cellmd export-lammps`.
fn is_openmm(doc: &golden::Document) -> bool {
    doc.get("generator").is_some_and(|g| g.starts_with("OpenMM "))
}

fn golden_files() -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> =
        std::fs::read_dir("reference").unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e == "yaml")).collect();
    files.sort();
    files
}

/// Checks one document; returns the worst relative errors (start, end).
fn check(path: &Path, doc: &golden::Document) -> (f64, f64) {
    let deck = Path::new("reference").join(doc.get("deck").expect("deck"));
    let tol = golden::tolerance_of(doc).unwrap();
    let reference = golden::probes_of(doc).unwrap();
    let plan = validate_file(&deck, &[]).unwrap_or_else(|e| panic!("{e}"));
    let ours = cellmd_probes(&plan).unwrap();
    let agreement = Agreement::new(&ours, &reference).unwrap_or_else(|e| panic!("{}: {e}", deck.display()));
    assert!(
        agreement.agrees(tol),
        "{} ({}): cellmd disagrees with {}\n{}",
        path.display(),
        deck.display(),
        doc.get("generator").unwrap(),
        agreement.table("golden", tol)
    );
    (agreement.init.worst(), agreement.last.map_or(0.0, |l| l.worst()))
}

#[test]
fn cellmd_matches_every_golden_file() {
    let files = golden_files();
    assert!(!files.is_empty(), "no golden files under reference/");
    for path in files {
        let docs = documents(&path);
        let cases: Vec<&str> = docs.iter().map(|d| d.get("case").unwrap()).collect();
        assert_eq!(cases, ["random", "small"], "{}: expected the cases random and small", path.display());
        for doc in &docs {
            for key in ["generator", "date", "epsilon_reason", "run_epsilon_reason"] {
                assert!(doc.get(key).is_some_and(|v| !v.is_empty()), "{}: header lacks `{key}`", path.display());
            }
            let (start, end) = check(&path, doc);
            println!(
                "{} {}: worst relative error {start:.1e} at step 0, {end:.1e} after the run",
                path.display(),
                doc.get("case").unwrap()
            );
        }
    }
}

#[test]
fn random_cases_are_not_toys() {
    for path in golden_files() {
        for doc in documents(&path).iter().filter(|d| d.get("case") == Some("random")) {
            let probes = golden::probes_of(doc).unwrap();
            assert!(probes.init.ids.len() >= 100, "{}: only {} particles", path.display(), probes.init.ids.len());
            let deck = Path::new("reference").join(doc.get("deck").unwrap());
            let plan = validate_file(&deck, &[]).unwrap();
            let name = path.file_stem().unwrap().to_str().unwrap();
            // Periodic wherever the type allows it (walls need a fixed axis).
            let periodic = plan.sim_box.periodic.iter().filter(|&&p| p).count();
            assert!(periodic >= if name == "wall" { 1 } else { 3 }, "{}: periodic axes {:?}", path.display(), plan.sim_box.periodic);
            let last = probes.last.as_ref().expect("a run");
            if is_kinetics(&path) {
                // Kinetics act: many bonds break or form, and many do not.
                let (before, after) = (probes.init.bonds.as_ref().unwrap(), last.bonds.as_ref().unwrap());
                let changed = before.iter().filter(|b| !after.contains(b)).count() + after.iter().filter(|b| !before.contains(b)).count();
                let kept = before.iter().filter(|b| after.contains(b)).count();
                println!(
                    "{}: {} bonds at the start, {} after the run: {changed} changed, {kept} kept",
                    path.display(),
                    before.len(),
                    after.len()
                );
                assert!(changed >= 50 && kept >= 20, "{}: {changed} bonds changed and {kept} kept: not a test of kinetics", path.display());
                continue;
            }
            // The interaction (or, for a feature's file, every term) acts, and the run moves the particles.
            let acts = |k: &str| k.split('+').any(|p| p == name) || cellmd::interactions::lookup(name).is_none();
            let energy: f64 = probes.init.energies.iter().filter(|(k, _)| acts(k)).map(|(_, e)| e.abs()).sum();
            assert!(energy > 0.0, "{}: `{name}` has no energy", path.display());
            assert!(
                last.positions.iter().zip(&probes.init.positions).any(|(a, b)| (*a - *b).length() > 1e-3),
                "{}: nothing moved",
                path.display()
            );
        }
    }
}

/// `per_bond_r0.yaml` can fail: the same decks with every bond at its
/// type's r0 (the per-bond values dropped) disagree with LAMMPS.
#[test]
fn per_bond_r0_golden_file_tells_the_type_r0_apart() {
    let path = Path::new("reference/per_bond_r0.yaml");
    for doc in documents(path) {
        let deck = Path::new("reference").join(doc.get("deck").unwrap());
        let mut plan = validate_file(&deck, &[]).unwrap();
        let own = plan.model.bond_rest.iter().filter(|r| r.is_some()).count();
        assert!(own >= 2, "{}: only {own} bonds with their own r0", deck.display());
        plan.model.bond_rest.iter_mut().for_each(|r| *r = None);
        let reference = golden::probes_of(&doc).unwrap();
        let agreement = Agreement::new(&cellmd_probes(&plan).unwrap(), &reference).unwrap();
        println!("{}: without the per-bond r0, worst relative error {:.2e} at step 0", deck.display(), agreement.init.worst());
        assert!(!agreement.agrees(golden::tolerance_of(&doc).unwrap()), "{}: dropping the per-bond r0 changed nothing", deck.display());
    }
}

/// The kinetics golden files can fail: cellmd with a strain threshold 5 %
/// lower, or with `partner random` instead of mutual-nearest partners, ends
/// with other bonds than LAMMPS.
#[test]
fn kinetics_golden_files_tell_a_different_rule_apart() {
    let mut checked = 0;
    for path in golden_files().into_iter().filter(|p| is_kinetics(p)) {
        for doc in documents(&path).iter().filter(|d| d.get("case") == Some("random")) {
            let deck = Path::new("reference").join(doc.get("deck").unwrap());
            let reference = golden::probes_of(doc).unwrap();
            let mut plan = validate_file(&deck, &[]).unwrap();
            for k in &mut plan.model.bond_kinetics {
                for r in k.rules.iter_mut().filter(|r| r.rule.name() == "threshold") {
                    r.params[0] *= 0.95;
                }
            }
            for r in &mut plan.model.bind_rules {
                r.nearest = false;
            }
            let ours = cellmd_probes(&plan).unwrap();
            let agreement = Agreement::new(&ours, &reference).unwrap();
            let mismatches = agreement.last.as_ref().unwrap().bonds.as_ref().unwrap().mismatches();
            println!("{}: the altered rule leaves {mismatches} bonds bound in only one engine", path.display());
            assert!(mismatches > 0, "{}: an altered rule still matches LAMMPS ({mismatches} mismatches)", path.display());
            assert!(!agreement.agrees(golden::tolerance_of(doc).unwrap()));
            checked += 1;
        }
    }
    assert_eq!(checked, 2, "expected the threshold and bind golden files");
}

/// The OpenMM golden files can fail: every surface and volume case disagrees
/// with cellmd once one parameter of each body or tetra term is off by one
/// part in 10⁶.
#[test]
fn surface_golden_files_tell_a_perturbed_term_apart() {
    let mut checked = 0;
    for path in golden_files() {
        for doc in documents(&path).iter().filter(|d| is_openmm(d)) {
            let deck = Path::new("reference").join(doc.get("deck").unwrap());
            let mut plan = validate_file(&deck, &[]).unwrap();
            let bodies = plan.model.body_rules.iter_mut().map(|t| t.params_mut());
            for params in bodies.chain(plan.model.tetra_types.iter_mut().map(|t| t.params_mut())) {
                let k = params.iter().position(|p| *p != 0.0).unwrap();
                params[k] *= 1.0 + 1e-6;
            }
            let agreement = Agreement::new(&cellmd_probes(&plan).unwrap(), &golden::probes_of(doc).unwrap()).unwrap();
            println!("{}: worst relative error {:.1e} with a parameter off by 1e-6", deck.display(), agreement.init.worst());
            assert!(!agreement.agrees(golden::tolerance_of(doc).unwrap()), "{}: a perturbed term still agrees", deck.display());
            checked += 1;
        }
    }
    assert_eq!(checked, 16);
}

/// The LAMMPS inputs committed beside each case are what `cellmd
/// export-lammps` writes for its deck today (`reference/regenerate` copies
/// them there): the golden data came from these decks. OpenMM cases have
/// none: their system is built from the deck's own files by
/// `reference/openmm_surfaces.py` (`openmm_solids.py` for the volume
/// elements), and LAMMPS export refuses body terms and volume elements.
#[test]
fn committed_lammps_inputs_are_current_exports() {
    let mut openmm = 0;
    for path in golden_files() {
        for doc in documents(&path) {
            if is_openmm(&doc) {
                let deck = Path::new("reference").join(doc.get("deck").unwrap());
                let plan = validate_file(&deck, &[]).unwrap();
                let openmm_only = plan.model.has_surface_terms() || !plan.model.tetras.is_empty();
                assert!(openmm_only, "{}: an OpenMM case without surface terms or volume elements", deck.display());
                let refusal = cellmd::export::export(&plan, cellmd::export::ExportOptions { probes: true }).err().unwrap_or_default();
                assert!(refusal.contains("which LAMMPS cannot express"), "{}: {refusal}", deck.display());
                assert!(!deck.parent().unwrap().join("lammps").exists());
                openmm += 1;
                continue;
            }
            let deck = Path::new("reference").join(doc.get("deck").unwrap());
            let plan = validate_file(&deck, &[]).unwrap();
            let exported = cellmd::export::export(&plan, cellmd::export::ExportOptions { probes: true }).unwrap();
            let dir = deck.parent().unwrap().join("lammps").join(doc.get("case").unwrap());
            for (file, text) in [("in.lammps", &exported.input), ("data.lammps", &exported.data)] {
                let committed = std::fs::read_to_string(dir.join(file)).unwrap_or_else(|e| panic!("{}: {e}", dir.join(file).display()));
                assert!(
                    &committed == text,
                    "{}/{file} is not the current export of {}: rerun reference/regenerate",
                    dir.display(),
                    deck.display()
                );
            }
        }
    }
    assert_eq!(openmm, 16, "expected two OpenMM cases for each of the six surface types and the two volume types");
}

/// Each name has `reference/NAME.yaml` or a row `| `NAME` | reason | `test` |`
/// in reference/NO_REFERENCE.md naming a test found in `sources`.
fn golden_file_or_stated_reason(names: &[&str], sources: &str) {
    let listed = std::fs::read_to_string("reference/NO_REFERENCE.md").unwrap();
    for name in names {
        if Path::new(&format!("reference/{name}.yaml")).exists() {
            assert!(!listed.contains(&format!("| `{name}` |")), "{name} has a golden file and is listed as lacking one");
            continue;
        }
        let row = listed
            .lines()
            .find(|l| l.starts_with(&format!("| `{name}` |")))
            .unwrap_or_else(|| panic!("{name} has no reference/{name}.yaml and no row in reference/NO_REFERENCE.md"));
        let cells: Vec<&str> = row.split('|').map(str::trim).collect();
        // | `name` | reason | `test_name` |
        assert!(cells.len() >= 4 && !cells[2].is_empty(), "{name}: no reason given");
        let test = cells[3].trim_matches('`');
        assert!(sources.contains(&format!("fn {test}(")), "{name}: the covering test `{test}` does not exist");
    }
}

fn read_sources(dirs: &[&str]) -> String {
    dirs.iter()
        .flat_map(|d| std::fs::read_dir(d).unwrap())
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "rs"))
        .map(|p| std::fs::read_to_string(p).unwrap())
        .collect()
}

/// Every registered type has a golden file, or is listed in
/// reference/NO_REFERENCE.md with the reason and the test that covers it.
#[test]
fn every_interaction_has_a_golden_file_or_a_stated_reason() {
    let names: Vec<&str> = REGISTRY.iter().map(|i| i.name()).collect();
    golden_file_or_stated_reason(&names, &read_sources(&["src/interactions"]));
}

/// Likewise every kinetic rule, and bond formation (`bind`): LAMMPS can
/// express only a few, the others name their test against exact results.
#[test]
fn every_kinetic_rule_has_a_golden_file_or_a_stated_reason() {
    let mut names: Vec<&str> = cellmd::kinetics::RULES.iter().map(|r| r.name()).collect();
    names.push("bind");
    golden_file_or_stated_reason(&names, &read_sources(&["src/kinetics", "tests/suite"]));
}

/// `reference/regenerate --check` sets CELLMD_GOLDEN_NEW=require: every
/// freshly regenerated NAME.yaml.new must match the committed NAME.yaml.
#[test]
fn regenerated_data_matches_the_committed_golden_files() {
    let Some(mode) = std::env::var_os("CELLMD_GOLDEN_NEW") else { return };
    assert_eq!(mode, "require");
    for path in golden_files() {
        let new = path.with_extension("yaml.new");
        assert!(new.exists(), "{} was not regenerated", new.display());
        let (old_docs, new_docs) = (documents(&path), documents(&new));
        assert_eq!(old_docs.len(), new_docs.len(), "{}: the number of cases changed", new.display());
        for (old, new_doc) in old_docs.iter().zip(&new_docs) {
            let tol = golden::tolerance_of(old).unwrap();
            let (a, b): (Probes, Probes) = (golden::probes_of(new_doc).unwrap(), golden::probes_of(old).unwrap());
            let agreement = Agreement::new(&a, &b).unwrap();
            assert!(agreement.agrees(tol), "{} drifted from {}:\n{}", new.display(), path.display(), agreement.table("committed", tol));
        }
    }
}

/// The golden cases are defined in one data file keyed by interaction name
/// (`reference/cases.json`, read by the reference scripts): every key is a
/// registered interaction of the kind the entry says, with a golden file.
#[test]
fn case_definitions_are_keyed_by_registered_interactions() {
    let text = std::fs::read_to_string("reference/cases.json").unwrap();
    let cases: serde_json::Map<String, serde_json::Value> = serde_json::from_str(&text).unwrap();
    assert!(cases.len() >= 20, "{} cases", cases.len());
    for (name, case) in &cases {
        let interaction = cellmd::interactions::lookup(name).unwrap_or_else(|| panic!("reference/cases.json: `{name}` is not registered"));
        assert_eq!(case["kind"].as_str(), Some(interaction.kind().keyword()), "reference/cases.json: `{name}`");
        assert!(Path::new("reference").join(format!("{name}.yaml")).exists(), "reference/cases.json: `{name}` has no golden file");
    }
}
