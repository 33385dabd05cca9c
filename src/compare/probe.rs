//! Snapshots of a system at the start and end of a deck, from cellmd or
//! from the probe files of an exported LAMMPS run.

use std::collections::BTreeMap;
use std::path::Path;

use glam::DVec3;

use crate::deck::{Action, Plan};
use crate::export::lammps::PROBE_FILE;
use crate::interactions::REGISTRY;
use crate::run::{RunOptions, Simulation};

/// Energies, virial, positions and forces at one step, particles sorted by id.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Snapshot {
    pub step: u64,
    /// Energy by key: one interaction name, or several joined by `+` where
    /// LAMMPS computes them in one style (e.g. `cosine_angle+wlc_bending`).
    pub energies: BTreeMap<String, f64>,
    /// W = Σ r_ij ⊗ f_ij (xx yy zz xy xz yz) of pair and bonded terms.
    pub virial: [f64; 6],
    pub ids: Vec<u64>,
    /// Unwrapped positions.
    pub positions: Vec<DVec3>,
    pub forces: Vec<DVec3>,
    /// The bound bonds, sorted, for decks whose bonds break or form
    /// (kinetics); `None` when the bond list is fixed.
    pub bonds: Option<Vec<BondRecord>>,
}

/// A bound bond: its type name and its particles' ids (smaller first).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct BondRecord {
    pub bond_type: String,
    pub ids: [u64; 2],
}

impl BondRecord {
    pub fn new(bond_type: &str, a: u64, b: u64) -> Self {
        Self { bond_type: bond_type.to_string(), ids: [a.min(b), a.max(b)] }
    }
}

impl Snapshot {
    pub fn total_energy(&self) -> f64 {
        self.energies.values().sum()
    }
}

/// The system before the first `run` and after the last one.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Probes {
    pub init: Snapshot,
    pub last: Option<Snapshot>,
}

fn snapshot(sim: &mut Simulation) -> Result<Snapshot, String> {
    sim.current_forces().map_err(|e| e.to_string())?;
    let mut order: Vec<usize> = (0..sim.model.len()).collect();
    order.sort_by_key(|&i| sim.model.ids[i]);
    let f = &sim.backend.forces;
    let energies = REGISTRY
        .iter()
        .enumerate()
        .filter(|(k, _)| sim.model.interactions_in_use().contains(k))
        .map(|(k, i)| (i.name().to_string(), f.energy_by_interaction[k]))
        .collect();
    Ok(Snapshot {
        step: sim.state.step,
        energies,
        virial: f.virial,
        ids: order.iter().map(|&i| sim.model.ids[i]).collect(),
        positions: order.iter().map(|&i| sim.sim_box.unwrap(sim.state.positions[i], sim.state.images[i])).collect(),
        forces: order.iter().map(|&i| f.forces[i]).collect(),
        bonds: sim.model.has_kinetics().then(|| bound_bonds(sim)),
    })
}

/// The bonds bound now, sorted.
fn bound_bonds(sim: &Simulation) -> Vec<BondRecord> {
    let m = &sim.model;
    let bound = sim.state.bonds.as_ref().map(|b| &b.bound);
    let mut bonds: Vec<BondRecord> = (0..m.bonds.len())
        .filter(|&b| bound.is_none_or(|bound| bound[b]))
        .map(|b| {
            let [i, j] = m.bonds[b];
            BondRecord::new(&m.bond_types[m.bond_type[b] as usize].label.text, m.ids[i as usize], m.ids[j as usize])
        })
        .collect();
    bonds.sort();
    bonds
}

/// Runs a deck in cellmd (without writing any output) and probes it before
/// the first `run` and after the last.
pub fn cellmd_probes(plan: &Plan) -> Result<Probes, String> {
    let mut sim = Simulation::new(plan, RunOptions::default());
    let first_run = plan.actions.iter().position(|a| matches!(a, Action::Run(_)));
    let mut init = None;
    for (k, action) in plan.actions.iter().enumerate() {
        if Some(k) == first_run {
            init = Some(snapshot(&mut sim)?);
        }
        if !action.is_output() {
            sim.apply(action).map_err(|e| e.to_string())?;
        }
    }
    let last = match init {
        Some(_) => Some(snapshot(&mut sim)?),
        None => {
            init = Some(snapshot(&mut sim)?);
            None
        }
    };
    Ok(Probes { init: init.expect("probed"), last })
}

fn numbers(line: &str, what: &str) -> Result<Vec<f64>, String> {
    line.split_whitespace().map(|w| w.parse::<f64>().map_err(|_| format!("{what}: `{w}` is not a number"))).collect()
}

/// Reads a LAMMPS `write_dump ... id xu yu zu fx fy fz` file.
fn read_dump(path: &Path, snapshot: &mut Snapshot) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let body = text.split("ITEM: ATOMS id xu yu zu fx fy fz\n").nth(1).ok_or_else(|| format!("{}: no ATOMS section", path.display()))?;
    for line in body.lines() {
        let v = numbers(line, &path.display().to_string())?;
        if v.len() != 7 {
            return Err(format!("{}: expected 7 columns, found `{line}`", path.display()));
        }
        snapshot.ids.push(v[0] as u64);
        snapshot.positions.push(DVec3::new(v[1], v[2], v[3]));
        snapshot.forces.push(DVec3::new(v[4], v[5], v[6]));
    }
    Ok(())
}

/// Reads a LAMMPS `write_dump ... local ... index btype batom1 batom2` file;
/// `names` are the bond type names by LAMMPS type number − 1.
fn read_bonds(path: &Path, names: &[String]) -> Result<Vec<BondRecord>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let (_, body) = text.split_once("ITEM: ENTRIES").ok_or_else(|| format!("{}: no ENTRIES section", path.display()))?;
    let mut bonds = Vec::new();
    for line in body.lines().skip(1) {
        let bad = || format!("{}: expected `index type atom1 atom2`, found `{line}`", path.display());
        let v: Vec<u64> = line.split_whitespace().map(|w| w.parse::<u64>()).collect::<Result<_, _>>().map_err(|_| bad())?;
        let [_, t, a, b] = v[..] else { return Err(bad()) };
        let name = names.get((t as usize).wrapping_sub(1)).ok_or_else(bad)?;
        bonds.push(BondRecord::new(name, a, b));
    }
    bonds.sort();
    Ok(bonds)
}

/// Reads the probe files a LAMMPS run of an exported deck wrote into `dir`;
/// `bond_types` names LAMMPS' bond types 1, 2, … (for the bond lists that
/// decks with kinetics probe).
pub fn lammps_probes(dir: &Path, bond_types: &[String]) -> Result<Probes, String> {
    let path = dir.join(PROBE_FILE);
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut snapshots: Vec<(String, Snapshot)> = Vec::new();
    for line in text.lines() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["step", step, tag] => {
                let step = step.parse().map_err(|_| format!("{}: bad step `{step}`", path.display()))?;
                snapshots.push((tag.to_string(), Snapshot { step, ..Default::default() }));
            }
            ["energy", key, value] => {
                let s = &mut snapshots.last_mut().ok_or("energy before step")?.1;
                let v: f64 = value.parse().map_err(|_| format!("{}: bad energy `{value}`", path.display()))?;
                *s.energies.entry(key.to_string()).or_default() += v;
            }
            ["virial", ..] => {
                let v = numbers(&words[1..].join(" "), &path.display().to_string())?;
                let s = &mut snapshots.last_mut().ok_or("virial before step")?.1;
                s.virial.copy_from_slice(&v[..6]);
            }
            _ => return Err(format!("{}: unexpected line `{line}`", path.display())),
        }
    }
    let mut init = None;
    let mut last = None;
    for (tag, mut s) in snapshots {
        read_dump(&dir.join(format!("cellmd_probe_{tag}.dump")), &mut s)?;
        let bonds = dir.join(format!("cellmd_probe_{tag}.bonds"));
        if bonds.exists() {
            s.bonds = Some(read_bonds(&bonds, bond_types)?);
        }
        match tag.as_str() {
            "init" => init = Some(s),
            _ => last = Some(s),
        }
    }
    Ok(Probes { init: init.ok_or_else(|| format!("{}: no initial probe", path.display()))?, last })
}
