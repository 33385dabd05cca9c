//! Export of a cellmd deck to other engines.
//!
//! [`lammps::export`] turns a validated [`crate::deck::Plan`] into a LAMMPS data
//! file and input script that compute the same energies and forces and run the
//! same overdamped dynamics (`cellmd export-lammps DECK OUTDIR`). Each
//! interaction type's LAMMPS form is its own `Interaction::lammps` (in its
//! file under `src/interactions/`), which [`styles`] plugs into the script;
//! an interaction LAMMPS cannot express is an error that names it. Bonds with their own
//! rest lengths get one LAMMPS bond type per distinct (type, r0)
//! ([`bond_types`]). [`import_lammps`] reads a LAMMPS data file (and script)
//! back as a topology, force field and deck (`cellmd import-lammps`).

pub mod bond_types;
mod data_file;
pub mod formula;
mod hybrid;
pub mod import_lammps;
mod kinetic_fixes;
pub mod lammps;
pub mod styles;

pub use self::lammps::{export, ExportOptions, LammpsDeck};
