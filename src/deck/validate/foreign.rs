//! Pointers from LAMMPS and GROMACS commands to their cellmd equivalents,
//! for the "unknown command" error: a user who writes `read_data` or
//! `nsteps = 1000` out of habit learns where that setting lives here.
//!
//! LAMMPS input scripts are whole decks of their own; `cellmd import-lammps
//! DATA INPUT -o DIR` translates a data file and its script. GROMACS `.mdp`
//! lines (`key = value`) and topology directives (`[ atoms ]`) name the
//! settings below.

/// (command word, where it lives in cellmd). `fix` is answered by style.
const HINTS: &[(&str, &str)] = &[
    // LAMMPS: the system.
    ("read_data", "the system comes from `topology FILE` (a LAMMPS data file and script translate with `cellmd import-lammps DATA INPUT -o DIR`)"),
    ("read_restart", "a cellmd restart is `read_state FILE`; a LAMMPS system translates with `cellmd import-lammps DATA INPUT -o DIR`"),
    ("create_atoms", "particles are listed in the topology file (`topology FILE`), or generated with `cellmd build`"),
    ("create_box", "the box is `box x LO HI p|f y LO HI p|f z LO HI p|f` (or `[ box ]` in the topology)"),
    ("region", "the box is `box x LO HI p|f …`; particles are listed in the topology file"),
    ("lattice", "particles are listed in the topology file, or generated with `cellmd build`"),
    ("boundary", "periodicity is the p|f after each axis of `box x LO HI p|f y LO HI p|f z LO HI p|f`"),
    ("atom_style", "the topology file's `[ particles ]`, `[ bonds ]` and `[ angles ]` sections hold what the atom style would"),
    ("mass", "overdamped dynamics has no mass: a particle type's drag is `particle NAME drag G` in the force-field file"),
    // LAMMPS: the force field.
    ("pair_style", "pair laws are `pair A B LAW PARAM VALUE …` lines in the force-field file (`forcefield FILE`; `cellmd list` names the laws)"),
    ("pair_coeff", "pair laws and their coefficients are `pair A B LAW PARAM VALUE …` lines in the force-field file (`forcefield FILE`)"),
    ("pair_modify", "each pair law states its own cutoff and shift in the force-field file (`lj` is unshifted, `wca` shifted)"),
    ("bond_style", "bond laws are `bond NAME LAW PARAM VALUE …` lines in the force-field file (`forcefield FILE`)"),
    ("bond_coeff", "bond laws and their coefficients are `bond NAME LAW PARAM VALUE …` lines in the force-field file (`forcefield FILE`)"),
    ("angle_style", "angle laws are `angle NAME LAW PARAM VALUE …` lines in the force-field file (`forcefield FILE`)"),
    ("angle_coeff", "angle laws and their coefficients are `angle NAME LAW PARAM VALUE …` lines in the force-field file (`forcefield FILE`)"),
    ("neigh_modify", "the neighbour list is set by `neighbor skin S [every N] [check yes|no]`"),
    // LAMMPS: running and output.
    ("velocity", "overdamped dynamics has no velocities: `temperature T` sets the noise"),
    ("unfix", "remove an external with `unexternal NAME`, a move with `unmove GROUP`, a freeze with `unfreeze GROUP`"),
    ("thermo_style", "thermo columns follow the interval: `thermo N [column ...]`"),
    ("thermo_modify", "thermo columns follow the interval: `thermo N [column ...]`; `thermo_file FILE.csv` writes them to a file"),
    ("dump_modify", "a dump's columns are part of it: `dump NAME every N lammps FILE columns COLUMN...`"),
    ("write_dump", "a trajectory is `dump NAME every N mcap|xyz|lammps|bonds|dcd FILE`"),
    ("write_restart", "a restart file is `write_state FILE [every N [keep K]]`"),
    ("write_data", "a restart file is `write_state FILE`; `cellmd export-lammps DECK OUTDIR` writes a LAMMPS data file"),
    ("compute", "thermo columns (`thermo N [column ...]`) and dump columns (forces, per-particle stress) hold what cellmd computes"),
    ("min_style", "the minimiser is chosen by `minimize [style fire|newton]`"),
    ("reset_timestep", "each `run` continues the step count; `read_state FILE` restores it"),
    // GROMACS .mdp keys and topology directives.
    ("nsteps", "the run length is `run N`"),
    ("dt", "the time step is `timestep DT`"),
    ("ref_t", "the temperature is `temperature T` (kT in pN·µm in cell units)"),
    ("ref-t", "the temperature is `temperature T` (kT in pN·µm in cell units)"),
    ("bd_fric", "Brownian dynamics is `integrator overdamped`; the friction is each type's `particle NAME drag G` in the force-field file"),
    ("bd-fric", "Brownian dynamics is `integrator overdamped`; the friction is each type's `particle NAME drag G` in the force-field file"),
    ("ld_seed", "the random seed is `seed N`"),
    ("ld-seed", "the random seed is `seed N`"),
    ("pbc", "periodicity is the p|f after each axis of `box x LO HI p|f …`"),
    ("nstlist", "the neighbour list is set by `neighbor skin S [every N]`"),
    ("rlist", "the neighbour list's buffer is `neighbor skin S`; each pair law states its cutoff in the force-field file"),
    ("rvdw", "each pair law states its cutoff in the force-field file (`pair A B lj … rc RC`)"),
    ("nstxout", "a trajectory is `dump NAME every N mcap|xyz|lammps|bonds|dcd FILE`"),
    ("nstxout-compressed", "a trajectory is `dump NAME every N mcap|xyz|lammps|bonds|dcd FILE`"),
    ("nstenergy", "energies are printed by `thermo N` (and written by `thermo_file FILE.csv`)"),
    ("nstlog", "energies are printed by `thermo N`"),
    ("[", "GROMACS topology directives have no place in a deck: particles, bonds and angles live in the topology file (`topology FILE`), laws in the force-field file (`forcefield FILE`)"),
];

/// Where LAMMPS `fix STYLE` lives in cellmd, by style.
fn fix_hint(style: &str) -> &'static str {
    match style {
        "brownian" | "langevin" | "nve" | "nvt" | "bd/baoab" | "brownian/sphere" => {
            "dynamics is overdamped: `integrator overdamped` with `temperature T`, each type's drag `particle NAME drag G` in the force-field file"
        }
        "wall/harmonic" | "wall/lj93" | "wall/lj126" | "wall/region" | "wall/reflect" => "a wall is `external NAME GROUP wall …`",
        "addforce" | "gravity" => "a constant or scripted force is `external NAME GROUP constant_force …` (or `custom`)",
        "setforce" | "freeze" => "pinning is `freeze GROUP x|y|z ...` (or a `fixed` particle type)",
        "move" => "prescribed motion is `move GROUP linear VX VY VZ`",
        "indent" => "an indenter is `indent NAME velocity VX VY VZ`",
        "bond/break" | "bond/create" => "bond kinetics are `kinetics …` on a bond type and `bind …` lines in the force-field file",
        "shake" | "rattle" => "rigid bonds are `constrain BONDTYPE`",
        _ => "cellmd has no fixes: the integrator is `integrator …`, forces on groups are `external …`, motion is `move`/`freeze`",
    }
}

/// A pointer to the cellmd equivalent of a LAMMPS or GROMACS command, if
/// `words[0]` is one (`words` are the line's words).
pub(super) fn hint(words: &[&str]) -> Option<String> {
    let command = *words.first()?;
    let (program, text) = if command == "fix" {
        ("LAMMPS", fix_hint(words.get(3).copied().unwrap_or("")))
    } else {
        let &(_, text) = HINTS.iter().find(|(name, _)| *name == command)?;
        let gromacs = words.get(1) == Some(&"=") || command == "[" || matches!(command, "nsteps" | "dt" | "ref_t" | "ref-t");
        (if gromacs { "GROMACS" } else { "LAMMPS" }, text)
    };
    Some(format!("`{command}` is a {program} command; in cellmd, {text}"))
}

/// The words [`hint`] answers (besides `fix`).
#[cfg(test)]
pub(super) fn words() -> impl Iterator<Item = &'static str> {
    HINTS.iter().map(|(name, _)| *name)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lammps_and_gromacs_words_point_to_their_cellmd_settings() {
        assert!(hint(&["read_data", "x.data"]).unwrap().contains("`topology FILE`"));
        assert!(hint(&["read_data"]).unwrap().contains("cellmd import-lammps"));
        assert!(hint(&["fix", "1", "all", "brownian", "1.0", "42"]).unwrap().contains("`integrator overdamped`"));
        assert!(hint(&["fix", "w", "all", "wall/harmonic"]).unwrap().contains("external NAME GROUP wall"));
        assert!(hint(&["pair_style", "lj/cut", "2.5"]).unwrap().contains("force-field file"));
        assert!(hint(&["nsteps", "=", "1000"]).unwrap().starts_with("`nsteps` is a GROMACS command; in cellmd, the run length is `run N`"));
        assert!(hint(&["runn", "10"]).is_none());
        let mut seen = std::collections::HashSet::new();
        assert!(HINTS.iter().all(|(name, _)| seen.insert(*name)), "a word listed twice");
    }
}
