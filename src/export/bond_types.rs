//! LAMMPS bond types for cellmd bonds with their own rest lengths.
//!
//! LAMMPS gives every bond of a type the same coefficients, so one r0 per
//! bond type; cellmd bonds may have their own (the topology's `type i j r0`).
//! The export makes one LAMMPS bond type per distinct (cellmd type, r0):
//!
//! - LAMMPS type t + 1 is cellmd bond type t with its own `r0` (so a deck
//!   without per-bond rest lengths keeps cellmd's numbering, and `fix
//!   bond/create` makes bonds of the type as the force field gives it);
//! - each further (type, r0) pair, in the order its first bond appears in the
//!   topology, is a new LAMMPS type after those, with the cellmd type's other
//!   coefficients and that r0. A per-bond r0 equal (bit for bit) to its type's
//!   r0 uses the type's LAMMPS type.
//!
//! `coeff bond TYPE …` then rewrites every LAMMPS type of that cellmd type
//! (the deck refuses `coeff … r0` on a type with per-bond rest lengths), and a
//! strain `threshold` becomes one `fix bond/break` per LAMMPS type at its own
//! r0·(1 + S).

use std::collections::BTreeMap;

use crate::forcefield::TermType;
use crate::system::Model;

/// The LAMMPS bond types of a model and the LAMMPS type of each bond.
#[derive(Clone, Debug)]
pub struct LammpsBondTypes {
    /// LAMMPS type l + 1 is cellmd bond type `types[l].0` with rest length
    /// `types[l].1` (`None`: the cellmd type's `r0`).
    types: Vec<(usize, Option<f64>)>,
    /// The LAMMPS type (from 0) of each topology bond.
    of_bond: Vec<usize>,
}

impl LammpsBondTypes {
    pub fn new(model: &Model) -> Self {
        let mut types: Vec<(usize, Option<f64>)> = (0..model.bond_types.len()).map(|t| (t, None)).collect();
        let mut extra: BTreeMap<(usize, u64), usize> = BTreeMap::new();
        let of_bond = (0..model.topology_bonds)
            .map(|b| {
                let t = model.bond_type[b] as usize;
                let own_r0 = model.bond_types[t].params.get(model.bond_kinetics[t].rest_index.unwrap_or(usize::MAX)).copied();
                match model.bond_rest[b] {
                    Some(r0) if Some(r0.to_bits()) != own_r0.map(f64::to_bits) => *extra.entry((t, r0.to_bits())).or_insert_with(|| {
                        types.push((t, Some(r0)));
                        types.len() - 1
                    }),
                    _ => t,
                }
            })
            .collect();
        Self { types, of_bond }
    }

    /// Number of LAMMPS bond types.
    pub fn count(&self) -> usize {
        self.types.len()
    }

    /// The LAMMPS type (from 0) of topology bond `b`.
    pub fn of_bond(&self, b: usize) -> usize {
        self.of_bond[b]
    }

    /// The cellmd bond type of LAMMPS type `l` (from 0).
    pub fn cellmd_type(&self, l: usize) -> usize {
        self.types[l].0
    }

    /// The LAMMPS types (from 0) of cellmd bond type `t`.
    pub fn of_cellmd_type(&self, t: usize) -> impl Iterator<Item = usize> + '_ {
        (0..self.types.len()).filter(move |&l| self.types[l].0 == t)
    }

    /// LAMMPS type `l`'s law: its cellmd type's current parameters, with its own r0.
    pub fn term(&self, model: &Model, l: usize) -> TermType {
        let (t, r0) = self.types[l];
        let mut term = model.bond_types[t].term().clone();
        if let (Some(r0), Some(k)) = (r0, model.bond_kinetics[t].rest_index) {
            term.params[k] = r0;
        }
        term
    }

    /// The cellmd type name of each LAMMPS type (what `compare` reads LAMMPS' bond lists with).
    pub fn labels(&self, model: &Model) -> Vec<String> {
        self.types.iter().map(|&(t, _)| model.bond_types[t].label.text.clone()).collect()
    }
}
