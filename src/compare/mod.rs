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
//! LAMMPS is found as `$CELLMD_LMP`, else `lmp` on `PATH`, else through the
//! pinned reference environment (`scripts/reference-venv --lmp`).

mod agreement;
pub mod golden;
mod probe;

use std::path::{Path, PathBuf};
use std::process::Command;

pub use self::agreement::{Agreement, BondAgreement, EnergyRow, PointAgreement, Tolerance};
pub use self::probe::{cellmd_probes, lammps_probes, BondRecord, Probes, Snapshot};
use crate::deck::Plan;
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
            let out = Command::new("bash").arg(&script).arg("--lmp").output().map_err(|e| format!("{}: {e}", script.display()))?;
            if out.status.success() {
                return Ok(Self::at(PathBuf::from(String::from_utf8_lossy(&out.stdout).trim())));
            }
            return Err(format!("{} --lmp failed: {}", script.display(), String::from_utf8_lossy(&out.stderr)));
        }
        Err("LAMMPS not found: set CELLMD_LMP to an lmp executable or put lmp on PATH".into())
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
    lammps::write(&deck, dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let version = lmp.run(dir)?;
    let bond_types = crate::export::bond_types::LammpsBondTypes::new(&plan.model).labels(&plan.model);
    Ok((lammps_probes(dir, &bond_types)?, version))
}
