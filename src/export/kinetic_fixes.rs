//! The LAMMPS fixes that stand for a deck's bond kinetics: `fix bond/break`
//! for a strain-only `threshold`, `fix bond/create` for a `bind` rule whose
//! binding is certain in one step (see the module docs of `lammps.rs`).

use super::bond_types::LammpsBondTypes;
use crate::deck::{Action, Plan};
use crate::kinetics::{deterministic_strain, Effect};
use crate::system::Model;

/// The LAMMPS fixes that stand for a deck's bond kinetics.
#[derive(Clone, Debug, Default)]
pub(super) struct KineticFixes {
    /// LAMMPS bond types (from 0) broken by `fix bond/break`.
    pub(super) breaks: Vec<usize>,
    /// Bind rules done by `fix bond/create`.
    pub(super) creates: Vec<usize>,
}

impl KineticFixes {
    /// The largest capture radius of the exported bind rules (0: none).
    pub(super) fn capture(&self, model: &Model) -> f64 {
        self.creates.iter().map(|&k| model.bind_rules[k].capture).fold(0.0, f64::max)
    }
}

/// The `fix bond/break` length Rmax = r0·(1 + S) of LAMMPS bond type `l`
/// (at its own r0), whose cellmd type's only rule is a deterministic strain
/// threshold; any other kinetics is refused.
pub(super) fn bond_break_length(model: &Model, bond_types: &LammpsBondTypes, l: usize) -> Result<f64, String> {
    let t = bond_types.cellmd_type(l);
    let kinetics = &model.bond_kinetics[t];
    let label = &model.bond_types[t].label.text;
    let names: Vec<&str> = kinetics.rules.iter().map(|r| r.rule.name()).collect();
    match kinetics.rules.as_slice() {
        [r] if matches!(r.rule.effect(), Effect::Threshold(_)) => {
            let strain = deterministic_strain(&r.params).ok_or_else(|| {
                format!("bond type `{label}`: only a `threshold` with a `strain` alone (no `force`, `spread` or `rate`) maps to LAMMPS `fix bond/break`; export the deck without it")
            })?;
            let r0 = kinetics.rest_index.map(|k| bond_types.term(model, l).params[k]).ok_or_else(|| {
                format!("bond type `{label}`: its law `{}` has no `r0`, so its strain threshold has no LAMMPS length", model.bond_types[t].interaction.name())
            })?;
            Ok(r0 * (1.0 + strain))
        }
        _ => Err(format!(
            "bond type `{label}` has kinetic rules ({}): LAMMPS has no force-dependent bond kinetics; it expresses only a strain `threshold` (fix bond/break) and certain `bind ... partner nearest` (fix bond/create); export the deck without them",
            names.join(", ")
        )),
    }
}

/// The fixes for a deck's kinetics, or why LAMMPS cannot express them.
pub(super) fn kinetic_fixes(plan: &Plan, bond_types: &LammpsBondTypes) -> Result<KineticFixes, String> {
    let m = &plan.model;
    let mut fixes = KineticFixes::default();
    for l in 0..bond_types.count() {
        if !m.bond_kinetics[bond_types.cellmd_type(l)].rules.is_empty() {
            bond_break_length(m, bond_types, l)?;
            fixes.breaks.push(l);
        }
    }
    let steps: Vec<f64> = plan.actions.iter().filter_map(|a| if let Action::Timestep(dt) = a { Some(*dt) } else { None }).collect();
    for (k, r) in m.bind_rules.iter().enumerate() {
        let bond = &m.bond_types[r.bond_type as usize].label.text;
        let name = format!("`bind {} {} {bond}`", m.type_names[r.type_a as usize], m.type_names[r.type_b as usize]);
        if !r.nearest {
            return Err(format!(
                "{name} has `partner random`: LAMMPS `fix bond/create` binds mutual-nearest partners only (`partner nearest`)"
            ));
        }
        if r.between_bodies {
            return Err(format!(
                "{name} has `between bodies`: LAMMPS `fix bond/create` cannot restrict binding to particles of different bodies"
            ));
        }
        if let Some(dt) = steps.iter().find(|&&dt| -(-r.k_on * dt).exp_m1() < 1.0) {
            return Err(format!(
                "{name}: binding is not certain within a step (k_on·dt = {:e}); LAMMPS `fix bond/create` binds every eligible pair at once: export it with k_on·dt ≥ 40",
                r.k_on * dt
            ));
        }
        if !m.bond_kinetics[r.bond_type as usize].rules.is_empty() {
            return Err(format!(
                "{name}: bond type `{bond}` also has kinetic rules; LAMMPS `fix bond/create` does not count bonds that other fixes break"
            ));
        }
        if m.bind_rules.iter().filter(|o| o.bond_type == r.bond_type).count() > 1 {
            return Err(format!(
                "{name}: several `bind` lines form `{bond}`; each LAMMPS `fix bond/create` counts only the bonds it made itself"
            ));
        }
        let sb = m.special_bonds;
        if sb.weights[1] == 0.0 || sb.weights[2] == 0.0 {
            return Err(format!(
                "{name}: `special_bonds` excludes 1-3 or 1-4 neighbours, which LAMMPS leaves out of `fix bond/create`'s neighbour list while cellmd binds them"
            ));
        }
        fixes.creates.push(k);
    }
    Ok(fixes)
}

/// `read_data` room for the bonds `fix bond/create` adds: per atom, the
/// new bonds, and the special list of 1-2, 1-3 and 1-4 neighbours they can
/// make (m + m(m − 1) + m(m − 1)² for m bonds per atom).
pub(super) fn extra_per_atom(model: &Model, fixes: &KineticFixes) -> (usize, usize) {
    let new: usize = fixes.creates.iter().map(|&k| model.bind_rules[k].max_bonds as usize).sum();
    let mut count = vec![0usize; model.len()];
    for &[i, j] in &model.bonds {
        count[i as usize] += 1;
        count[j as usize] += 1;
    }
    let m = count.iter().copied().max().unwrap_or(0) + new;
    let fan = m.saturating_sub(1);
    (new, m + m * fan + m * fan * fan)
}
