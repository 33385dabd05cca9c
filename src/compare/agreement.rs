//! Agreement figures between two [`Probes`] and the verdict against tolerances.
//!
//! Every figure is a relative error with a stated scale, so one tolerance
//! fits systems of any size and units (after a run, each scale is the largest
//! of the start and the end: a relaxed end state has tiny forces, but the
//! round-off grew with the forces met on the way):
//! - energy of each key: |ΔE| / max(|E_ref|, largest |E_ref| of any key);
//! - forces: max_i |ΔF_i| / max_i |F_ref,i| (and the RMS of |ΔF_i|, absolute);
//! - virial: max_k |ΔW_k| / max_k |W_ref,k|;
//! - after the run: max_i |Δx_i| / max_i |x_ref,i(end) − x_ref,i(start)|, the
//!   position error relative to the largest displacement of the run (and the
//!   positions RMSD, absolute);
//! - bonds (decks with kinetics): the bound bond sets must be identical; the
//!   figure is the number of bonds bound in one engine and not the other.

use std::fmt::Write;

use glam::DVec3;

use super::probe::{BondRecord, Probes, Snapshot};

/// Tolerances of a comparison.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Tolerance {
    /// Energies, forces and virial at one configuration.
    pub single_point: f64,
    /// Positions, forces and energies after the run.
    pub run: f64,
}

impl Default for Tolerance {
    fn default() -> Self {
        Self { single_point: 1e-10, run: 1e-9 }
    }
}

/// One row of the energy table.
#[derive(Clone, Debug)]
pub struct EnergyRow {
    pub key: String,
    pub cellmd: f64,
    pub reference: Option<f64>,
    /// The largest |E| of any key in the reference snapshot: a term that is
    /// nearly zero (bonds at rest) is measured against the system's energy scale.
    pub scale: f64,
}

impl EnergyRow {
    pub fn relative_error(&self) -> f64 {
        match self.reference {
            Some(r) => ratio((self.cellmd - r).abs(), r.abs().max(self.scale)),
            None => f64::INFINITY,
        }
    }
}

/// Agreement at one configuration.
#[derive(Clone, Debug)]
pub struct PointAgreement {
    pub step: u64,
    pub energies: Vec<EnergyRow>,
    pub force_max_diff: f64,
    pub force_rms_diff: f64,
    pub force_scale: f64,
    pub virial_max_diff: f64,
    pub virial_scale: f64,
    /// Position error relative to the run's largest displacement (after a run).
    pub position_max_diff: f64,
    pub position_rmsd: f64,
    pub displacement_scale: f64,
    /// Bound bonds (decks with kinetics).
    pub bonds: Option<BondAgreement>,
}

/// The bound bonds of both engines at one configuration.
#[derive(Clone, Debug, Default)]
pub struct BondAgreement {
    pub cellmd: usize,
    pub reference: usize,
    /// Bound in cellmd only.
    pub only_cellmd: Vec<BondRecord>,
    /// Bound in the reference only.
    pub only_reference: Vec<BondRecord>,
}

impl BondAgreement {
    /// Compares two bond lists as multisets (a bond listed twice counts twice).
    fn new(cellmd: &[BondRecord], reference: &[BondRecord]) -> Self {
        let mut count: std::collections::BTreeMap<&BondRecord, i64> = std::collections::BTreeMap::new();
        for r in cellmd {
            *count.entry(r).or_default() += 1;
        }
        for r in reference {
            *count.entry(r).or_default() -= 1;
        }
        let mut out = Self { cellmd: cellmd.len(), reference: reference.len(), ..Default::default() };
        for (r, n) in count {
            let list = if n > 0 { &mut out.only_cellmd } else { &mut out.only_reference };
            list.extend(std::iter::repeat_n(r.clone(), n.unsigned_abs() as usize));
        }
        out
    }

    /// Bonds bound in one engine and not the other.
    pub fn mismatches(&self) -> usize {
        self.only_cellmd.len() + self.only_reference.len()
    }
}

fn ratio(a: f64, scale: f64) -> f64 {
    if a == 0.0 {
        0.0
    } else {
        a / scale.max(f64::MIN_POSITIVE)
    }
}

impl PointAgreement {
    pub fn force_error(&self) -> f64 {
        ratio(self.force_max_diff, self.force_scale)
    }
    pub fn virial_error(&self) -> f64 {
        ratio(self.virial_max_diff, self.virial_scale)
    }
    pub fn position_error(&self) -> f64 {
        ratio(self.position_max_diff, self.displacement_scale)
    }
    pub fn energy_error(&self) -> f64 {
        self.energies.iter().map(EnergyRow::relative_error).fold(0.0, f64::max)
    }
    /// The largest of all relative errors.
    pub fn worst(&self) -> f64 {
        self.force_error().max(self.virial_error()).max(self.position_error()).max(self.energy_error())
    }
    /// Whether both engines have the same bound bonds (or neither lists them).
    pub fn same_bonds(&self) -> bool {
        self.bonds.as_ref().is_none_or(|b| b.mismatches() == 0)
    }
}

/// Agreement at the start and (if the deck runs) after the last run.
#[derive(Clone, Debug)]
pub struct Agreement {
    pub init: PointAgreement,
    pub last: Option<PointAgreement>,
}

fn max_norm(v: impl Iterator<Item = DVec3>) -> f64 {
    v.map(|x| x.length()).fold(0.0, f64::max)
}

fn point(cellmd: &Snapshot, reference: &Snapshot, start: Option<&Snapshot>) -> Result<PointAgreement, String> {
    if cellmd.ids != reference.ids {
        return Err(format!(
            "step {}: the particle ids differ ({} in cellmd, {} in the reference)",
            reference.step,
            cellmd.ids.len(),
            reference.ids.len()
        ));
    }
    if cellmd.step != reference.step {
        return Err(format!("probed at step {} in cellmd but {} in the reference", cellmd.step, reference.step));
    }
    // After a run, scales are those of the whole run (start and end): a relaxed
    // end state has tiny forces, but round-off grew with the forces met on the way.
    let runs = std::iter::once(reference).chain(start);
    let scale = runs.clone().flat_map(|s| s.energies.values()).map(|e| e.abs()).fold(0.0, f64::max);
    let force_scale = runs.clone().map(|s| max_norm(s.forces.iter().copied())).fold(0.0, f64::max);
    let virial_scale = runs.flat_map(|s| s.virial).map(f64::abs).fold(0.0, f64::max);
    let mut energies: Vec<EnergyRow> = reference
        .energies
        .iter()
        .map(|(key, &r)| {
            // A reference group `a+b` (one LAMMPS style for several cellmd
            // types) is the sum of cellmd's a and b — unless the other side is
            // itself a reference document with the same group.
            let ours = cellmd
                .energies
                .get(key)
                .copied()
                .unwrap_or_else(|| key.split('+').map(|k| cellmd.energies.get(k).copied().unwrap_or(0.0)).sum());
            EnergyRow { key: key.clone(), cellmd: ours, reference: Some(r), scale }
        })
        .collect();
    for (key, &e) in &cellmd.energies {
        if !reference.energies.keys().any(|k| k == key || k.split('+').any(|p| p == key)) {
            energies.push(EnergyRow { key: key.clone(), cellmd: e, reference: None, scale });
        }
    }
    let df: Vec<f64> = cellmd.forces.iter().zip(&reference.forces).map(|(a, b)| (*a - *b).length()).collect();
    let dx: Vec<f64> = cellmd.positions.iter().zip(&reference.positions).map(|(a, b)| (*a - *b).length()).collect();
    let n = df.len().max(1) as f64;
    let displacement_scale = start.map_or(0.0, |s| max_norm(reference.positions.iter().zip(&s.positions).map(|(a, b)| *a - *b)));
    let bonds = match (&cellmd.bonds, &reference.bonds) {
        (Some(a), Some(b)) => Some(BondAgreement::new(a, b)),
        (None, None) => None,
        (Some(_), None) => {
            return Err(format!("step {}: the reference has no bond list (re-record it: the deck has kinetics)", reference.step))
        }
        (None, Some(_)) => return Err(format!("step {}: the reference lists bonds but the deck has no kinetics", reference.step)),
    };
    Ok(PointAgreement {
        step: reference.step,
        energies,
        force_max_diff: df.iter().copied().fold(0.0, f64::max),
        force_rms_diff: (df.iter().map(|d| d * d).sum::<f64>() / n).sqrt(),
        force_scale,
        virial_max_diff: (0..6).map(|k| (cellmd.virial[k] - reference.virial[k]).abs()).fold(0.0, f64::max),
        virial_scale,
        position_max_diff: if start.is_some() { dx.iter().copied().fold(0.0, f64::max) } else { 0.0 },
        position_rmsd: (dx.iter().map(|d| d * d).sum::<f64>() / n).sqrt(),
        displacement_scale,
        bonds,
    })
}

impl Agreement {
    /// Compares cellmd's probes with a reference's.
    pub fn new(cellmd: &Probes, reference: &Probes) -> Result<Self, String> {
        let init = point(&cellmd.init, &reference.init, None)?;
        let last = match (&cellmd.last, &reference.last) {
            (Some(c), Some(r)) => Some(point(c, r, Some(&reference.init))?),
            (None, None) => None,
            _ => return Err("one side ran and the other did not".into()),
        };
        Ok(Self { init, last })
    }

    /// Whether every figure is within tolerance and the bond sets are identical.
    pub fn agrees(&self, tol: Tolerance) -> bool {
        self.init.worst() <= tol.single_point
            && self.init.same_bonds()
            && self.last.as_ref().is_none_or(|l| l.worst() <= tol.run && l.same_bonds())
    }

    /// The table `cellmd compare` prints, ending in the verdict.
    pub fn table(&self, reference: &str, tol: Tolerance) -> String {
        let mut s = String::new();
        let _ = writeln!(s, "energy at step {:<10} {:>24} {:>24} {:>10}", self.init.step, "cellmd", reference, "rel. diff");
        for row in &self.init.energies {
            let r = row.reference.map_or("—".to_string(), |r| format!("{r:.16e}"));
            let _ = writeln!(s, "  {:<23} {:>24.16e} {:>24} {:>10.1e}", row.key, row.cellmd, r, row.relative_error());
        }
        for (name, p) in std::iter::once(("start", &self.init)).chain(self.last.iter().map(|l| ("end", l))) {
            let _ = writeln!(
                s,
                "{name} (step {}): forces max |ΔF| = {:.2e}, RMS |ΔF| = {:.2e} (max |F| = {:.3e}: rel. {:.1e}); virial rel. {:.1e}",
                p.step,
                p.force_max_diff,
                p.force_rms_diff,
                p.force_scale,
                p.force_error(),
                p.virial_error()
            );
        }
        if let Some(l) = &self.last {
            let _ = writeln!(
                s,
                "after the run (step {}): positions RMSD = {:.2e}, max |Δx| = {:.2e} (largest displacement {:.3e}: rel. {:.1e}); energy rel. {:.1e}",
                l.step,
                l.position_rmsd,
                l.position_max_diff,
                l.displacement_scale,
                l.position_error(),
                l.energy_error()
            );
        }
        for (name, p) in std::iter::once(("start", &self.init)).chain(self.last.iter().map(|l| ("end", l))) {
            let Some(b) = &p.bonds else { continue };
            let _ = writeln!(
                s,
                "bonds at the {name} (step {}): {} bound in cellmd, {} in {reference}; {} bound in only one",
                p.step,
                b.cellmd,
                b.reference,
                b.mismatches()
            );
            for (who, list) in [("cellmd", &b.only_cellmd), (reference, &b.only_reference)] {
                for r in list.iter().take(10) {
                    let _ = writeln!(s, "  only in {who}: {} {} {}", r.bond_type, r.ids[0], r.ids[1]);
                }
            }
        }
        let verdict = if self.agrees(tol) { "AGREE" } else { "DISAGREE" };
        let _ = writeln!(s, "verdict: {verdict} (tolerance {:.0e} at one configuration, {:.0e} after the run)", tol.single_point, tol.run);
        s
    }
}
