//! CPU reference backend: f64, plain loops, deterministic on any thread count.
//!
//! - **Pairs**: a full neighbour list (each pair appears in both particles'
//!   lists, sorted by index); each particle gathers its own force, so there
//!   are no write conflicts and the summation order is fixed.
//! - **Bonded terms** (bonds, angles): pass 1 evaluates every term in parallel
//!   into its own slots of a scratch buffer; pass 2 lets each particle gather
//!   its slots in term order. Each term is evaluated once and no float atomics
//!   or order-dependent reductions are used.
//! - **Externals**: per member particle, on the unwrapped position.
//! - Energies and the virial are reduced with [`ordered_sum`].
//!
//! The virial tensor is W = Σ_terms Σ_k r_k ⊗ f_k over image-consistent term
//! positions (for a pair, r_ij ⊗ f_ij); the pressure tensor reported in thermo
//! is P = (N·kT/V)·I + W/V (ideal Brownian osmotic part + configurational part).

use glam::DVec3;
use rayon::prelude::*;

use crate::interactions::{Law, Radial, REGISTRY};
use crate::neighbor::{Exclusions, NeighborList};
use crate::system::{registry_index, Model, SimBox, State};

use super::sum::ordered_sum;

/// Result of a force evaluation.
#[derive(Clone, Debug, Default)]
pub struct Forces {
    pub forces: Vec<DVec3>,
    /// Potential energy per registry entry (index as in [`REGISTRY`]).
    pub energy_by_interaction: Vec<f64>,
    /// Virial tensor W (xx, yy, zz, xy, xz, yz), energy units.
    pub virial: [f64; 6],
}

impl Forces {
    pub fn total_energy(&self) -> f64 {
        self.energy_by_interaction.iter().sum()
    }

    /// Largest |F| over particles and the particle that carries it.
    pub fn max_force(&self) -> (f64, usize) {
        self.forces.iter().enumerate().map(|(i, f)| (f.length(), i)).fold((0.0, 0), |a, b| if b.0 > a.0 { b } else { a })
    }
}

/// Contribution of one force-field entry to the force on one particle
/// (for blow-up reports).
#[derive(Clone, Debug)]
pub struct ForceBreakdown {
    pub kind: &'static str,
    pub label: String,
    pub interaction: &'static str,
    pub force: DVec3,
}

/// Bonded-term layout: slot `s` of the scratch buffer holds the force of one
/// term on one of its particles; `gather` lists each particle's slots.
#[derive(Clone, Debug, Default)]
struct BondedLayout {
    gather_offsets: Vec<u32>,
    gather_slots: Vec<u32>,
    angle_slot_base: usize,
    n_slots: usize,
}

impl BondedLayout {
    fn new(model: &Model) -> Self {
        let n = model.len();
        let angle_slot_base = 2 * model.bonds.len();
        let n_slots = angle_slot_base + 3 * model.angles.len();
        let mut owner: Vec<u32> = Vec::with_capacity(n_slots);
        owner.extend(model.bonds.iter().flatten());
        owner.extend(model.angles.iter().flatten());
        let mut counts = vec![0u32; n + 1];
        for &p in &owner {
            counts[p as usize + 1] += 1;
        }
        for i in 0..n {
            counts[i + 1] += counts[i];
        }
        let mut fill = counts.clone();
        let mut slots = vec![0u32; n_slots];
        for (slot, &p) in owner.iter().enumerate() {
            slots[fill[p as usize] as usize] = slot as u32;
            fill[p as usize] += 1;
        }
        Self { gather_offsets: counts, gather_slots: slots, angle_slot_base, n_slots }
    }
}

/// The CPU force engine with its neighbour list and scratch buffers.
pub struct CpuBackend {
    neighbors: NeighborList,
    exclusions: Exclusions,
    layout: BondedLayout,
    slot_forces: Vec<DVec3>,
    term_energy: Vec<f64>,
    term_virial: Vec<[f64; 6]>,
    /// Per bond: tension dE/dr (0 when unbound) and length, for kinetics.
    bond_tension: Vec<f64>,
    bond_length: Vec<f64>,
    /// Per particle: half the pair energy, per pair interaction in use.
    pair_energy: Vec<f64>,
    /// Per particle: its pair force and half its pair virial.
    pair_force: Vec<DVec3>,
    pair_virial: Vec<[f64; 6]>,
    /// Registry indices of the pair interactions in use (columns of `pair_energy`).
    pair_interactions: Vec<usize>,
    /// For each pair rule, its column in `pair_energy`.
    pair_rule_column: Vec<usize>,
}

#[inline]
fn outer(a: DVec3, b: DVec3) -> [f64; 6] {
    [a.x * b.x, a.y * b.y, a.z * b.z, a.x * b.y, a.x * b.z, a.y * b.z]
}

#[inline]
fn add6(a: &mut [f64; 6], b: [f64; 6]) {
    for k in 0..6 {
        a[k] += b[k];
    }
}

impl CpuBackend {
    /// Prepares buffers and builds the first neighbour list.
    pub fn new(model: &Model, state: &State, sim_box: &SimBox, skin: f64) -> Result<Self, String> {
        let mut pair_interactions: Vec<usize> = model.pair_rules.iter().map(registry_index).collect();
        pair_interactions.sort_unstable();
        pair_interactions.dedup();
        let pair_rule_column = model.pair_rules.iter().map(|r| pair_interactions.binary_search(&registry_index(r)).unwrap()).collect();
        let layout = BondedLayout::new(model);
        let n_terms = model.bonds.len() + model.angles.len();
        let mut backend = Self {
            neighbors: NeighborList::new(model.max_pair_cutoff(), skin),
            exclusions: Exclusions::from_pairs(model.len(), &model.excluded_pairs(state.bonds.as_ref().map(|b| b.bound.as_slice()))),
            slot_forces: vec![DVec3::ZERO; layout.n_slots],
            layout,
            term_energy: vec![0.0; n_terms],
            term_virial: vec![[0.0; 6]; n_terms],
            bond_tension: vec![0.0; model.bonds.len()],
            bond_length: vec![0.0; model.bonds.len()],
            pair_energy: vec![0.0; model.len() * pair_interactions.len()],
            pair_force: vec![DVec3::ZERO; model.len()],
            pair_virial: vec![[0.0; 6]; model.len()],
            pair_interactions,
            pair_rule_column,
        };
        backend.rebuild_neighbors(state, sim_box)?;
        Ok(backend)
    }

    /// Bonds broke or bound: pair exclusions follow the bound bonds, so they
    /// and the neighbour list are rebuilt (nothing to do without pair terms).
    pub fn bonds_changed(&mut self, model: &Model, state: &State, sim_box: &SimBox) -> Result<(), String> {
        if self.pair_interactions.is_empty() {
            return Ok(());
        }
        let bound = state.bonds.as_ref().map(|b| b.bound.as_slice());
        self.exclusions = Exclusions::from_pairs(model.len(), &model.excluded_pairs(bound));
        self.rebuild_neighbors(state, sim_box)
    }

    /// Rebuilds the neighbour list now.
    pub fn rebuild_neighbors(&mut self, state: &State, sim_box: &SimBox) -> Result<(), String> {
        if self.pair_interactions.is_empty() {
            return Ok(());
        }
        self.neighbors.build(&state.positions, sim_box, &self.exclusions)
    }

    /// Rebuilds the neighbour list if some particle moved more than skin/2
    /// (or unconditionally when `check` is false). Returns whether it rebuilt.
    pub fn update_neighbors(&mut self, state: &State, sim_box: &SimBox, check: bool) -> Result<bool, String> {
        if self.pair_interactions.is_empty() || (check && !self.neighbors.needs_rebuild(&state.positions, sim_box)) {
            return Ok(false);
        }
        self.rebuild_neighbors(state, sim_box)?;
        Ok(true)
    }

    /// Tension (dE/dr, positive when stretched; 0 when unbound) and length of
    /// every bond at the last [`compute`](Self::compute).
    pub fn bond_tension_and_length(&self) -> (&[f64], &[f64]) {
        (&self.bond_tension, &self.bond_length)
    }

    /// Number of neighbour-list builds so far.
    pub fn neighbor_builds(&self) -> u64 {
        self.neighbors.builds()
    }

    /// Evaluates forces, energies and the virial at `state` into `out`.
    pub fn compute(&mut self, model: &Model, state: &State, sim_box: &SimBox, out: &mut Forces) {
        let n = model.len();
        out.forces.clear();
        out.forces.resize(n, DVec3::ZERO);
        out.energy_by_interaction.clear();
        out.energy_by_interaction.resize(REGISTRY.len(), 0.0);
        out.virial = [0.0; 6];
        self.bonded_pass(model, state, sim_box);
        self.pair_pass(model, state, sim_box);
        self.gather(out);
        self.reduce(model, out);
        apply_externals(model, state, sim_box, out);
    }

    fn bonded_pass(&mut self, model: &Model, state: &State, sim_box: &SimBox) {
        let x = &state.positions;
        let (bond_slots, angle_slots) = self.slot_forces.split_at_mut(self.layout.angle_slot_base);
        let (bond_energy, angle_energy) = self.term_energy.split_at_mut(model.bonds.len());
        let (bond_virial, angle_virial) = self.term_virial.split_at_mut(model.bonds.len());
        let bond_state = state.bonds.as_ref();
        bond_slots
            .par_chunks_mut(2)
            .zip(bond_energy.par_iter_mut())
            .zip(bond_virial.par_iter_mut())
            .zip(self.bond_tension.par_iter_mut().zip(self.bond_length.par_iter_mut()))
            .enumerate()
            .for_each(|(b, (((slots, energy), virial), (tension, length)))| {
                let [i, j] = model.bonds[b];
                let t = model.bond_type[b] as usize;
                let term = &model.bond_types[t];
                let d = sim_box.minimum_image(x[j as usize] - x[i as usize]);
                let r = d.length();
                *length = r;
                let radial = match bond_state {
                    Some(s) if !s.bound[b] => Radial::ZERO,
                    Some(s) => {
                        stateful_bond(term.interaction.law(), &term.params, model.bond_kinetics[t].rest_index, s.rest[b], s.scale[b], r)
                    }
                    None => stateful_bond(term.interaction.law(), &term.params, None, None, 1.0, r),
                };
                let f_j = -radial.de_dr * d / r;
                slots[0] = -f_j;
                slots[1] = f_j;
                *energy = radial.energy;
                *virial = outer(d, f_j);
                *tension = radial.de_dr;
            });
        angle_slots.par_chunks_mut(3).zip(angle_energy.par_iter_mut()).zip(angle_virial.par_iter_mut()).enumerate().for_each(
            |(a, ((slots, energy), virial))| {
                let [i, j, k] = model.angles[a];
                let term = &model.angle_types[model.angle_type[a] as usize];
                let Law::ThreeBody(eval) = term.interaction.law() else { unreachable!("angle law is three-body") };
                let xj = x[j as usize];
                let xi = xj + sim_box.minimum_image(x[i as usize] - xj);
                let xk = xj + sim_box.minimum_image(x[k as usize] - xj);
                let out = eval(&term.params, [xi, xj, xk]);
                slots.copy_from_slice(&out.forces);
                *energy = out.energy;
                let mut w = outer(xi - xj, out.forces[0]);
                add6(&mut w, outer(xk - xj, out.forces[2]));
                *virial = w;
            },
        );
    }

    fn pair_pass(&mut self, model: &Model, state: &State, sim_box: &SimBox) {
        let columns = self.pair_interactions.len();
        if columns == 0 {
            return;
        }
        let x = &state.positions;
        let neighbors = &self.neighbors;
        let rule_column = &self.pair_rule_column;
        self.pair_energy
            .par_chunks_mut(columns)
            .zip(self.pair_force.par_iter_mut())
            .zip(self.pair_virial.par_iter_mut())
            .enumerate()
            .for_each(|(i, ((energy, force), virial))| {
                energy.fill(0.0);
                *force = DVec3::ZERO;
                *virial = [0.0; 6];
                let ti = model.types[i];
                for &j in neighbors.neighbors(i) {
                    let rules = model.pair_rules_between(ti, model.types[j as usize]);
                    if rules.is_empty() {
                        continue;
                    }
                    let d = sim_box.minimum_image(x[j as usize] - x[i]);
                    let r = d.length();
                    for &rule in rules {
                        let term = &model.pair_rules[rule as usize];
                        let Law::Radial { eval, range } = term.interaction.law() else { unreachable!("pair law is radial") };
                        if r >= range(&term.params) {
                            continue;
                        }
                        let radial = eval(&term.params, r);
                        let f_i = radial.de_dr * d / r;
                        *force += f_i;
                        energy[rule_column[rule as usize]] += 0.5 * radial.energy;
                        // r_ij ⊗ f_ij with r_ij = −d, counted half from each side.
                        add6(virial, outer(-0.5 * d, f_i));
                    }
                }
            });
    }

    fn gather(&self, out: &mut Forces) {
        let layout = &self.layout;
        let slots = &self.slot_forces;
        let pair_force = &self.pair_force;
        let has_pairs = !self.pair_interactions.is_empty();
        out.forces.par_iter_mut().enumerate().for_each(|(i, f)| {
            let mut sum = if has_pairs { pair_force[i] } else { DVec3::ZERO };
            for &s in &layout.gather_slots[layout.gather_offsets[i] as usize..layout.gather_offsets[i + 1] as usize] {
                sum += slots[s as usize];
            }
            *f = sum;
        });
    }

    fn reduce(&self, model: &Model, out: &mut Forces) {
        // Bonded energies and virial: sequential in term order.
        let bond_registry: Vec<usize> = model.bond_types.iter().map(registry_index).collect();
        let angle_registry: Vec<usize> = model.angle_types.iter().map(registry_index).collect();
        for (b, e) in self.term_energy.iter().enumerate() {
            let registry = if b < model.bonds.len() {
                bond_registry[model.bond_type[b] as usize]
            } else {
                angle_registry[model.angle_type[b - model.bonds.len()] as usize]
            };
            out.energy_by_interaction[registry] += e;
            add6(&mut out.virial, self.term_virial[b]);
        }
        let columns = self.pair_interactions.len();
        for (c, &reg) in self.pair_interactions.iter().enumerate() {
            let column: Vec<f64> = self.pair_energy.iter().skip(c).step_by(columns).copied().collect();
            out.energy_by_interaction[reg] += ordered_sum(&column);
        }
        if columns > 0 {
            for k in 0..6 {
                let component: Vec<f64> = self.pair_virial.iter().map(|w| w[k]).collect();
                out.virial[k] += ordered_sum(&component);
            }
        }
    }

    /// Per-entry forces on particle `i` (slow; for diagnostics only).
    pub fn breakdown(&self, model: &Model, state: &State, sim_box: &SimBox, i: usize) -> Vec<ForceBreakdown> {
        let mut parts = Vec::new();
        let layout = &self.layout;
        for &s in &layout.gather_slots[layout.gather_offsets[i] as usize..layout.gather_offsets[i + 1] as usize] {
            let s = s as usize;
            let (kind, term) = if s < layout.angle_slot_base {
                ("bond", &model.bond_types[model.bond_type[s / 2] as usize])
            } else {
                ("angle", &model.angle_types[model.angle_type[(s - layout.angle_slot_base) / 3] as usize])
            };
            parts.push(ForceBreakdown {
                kind,
                label: term.label.text.clone(),
                interaction: term.interaction.name(),
                force: self.slot_forces[s],
            });
        }
        if !self.pair_interactions.is_empty() {
            let x = &state.positions;
            for &j in self.neighbors.neighbors(i) {
                let d = sim_box.minimum_image(x[j as usize] - x[i]);
                let r = d.length();
                for &rule in model.pair_rules_between(model.types[i], model.types[j as usize]) {
                    let term = &model.pair_rules[rule as usize];
                    let Law::Radial { eval, range } = term.interaction.law() else { continue };
                    if r < range(&term.params) {
                        let radial = eval(&term.params, r);
                        let label = format!("{} {}-{}", term.label.text, model.ids[i], model.ids[j as usize]);
                        parts.push(ForceBreakdown {
                            kind: "pair",
                            label,
                            interaction: term.interaction.name(),
                            force: radial.de_dr * d / r,
                        });
                    }
                }
            }
        }
        for external in &model.externals {
            if external.members.binary_search(&(i as u32)).is_ok() {
                let Law::OneBody(eval) = external.term.interaction.law() else { continue };
                let out = eval(&external.term.params, sim_box.unwrap(state.positions[i], state.images[i]));
                parts.push(ForceBreakdown {
                    kind: "external",
                    label: external.term.label.text.clone(),
                    interaction: external.term.interaction.name(),
                    force: out.force,
                });
            }
        }
        parts
    }
}

/// A bond law evaluated with its own rest length (`None`: the type's) and
/// stiffness scale.
fn stateful_bond(law: Law, params: &[f64], rest_index: Option<usize>, rest: Option<f64>, scale: f64, r: f64) -> Radial {
    let Law::Radial { eval, .. } = law else { unreachable!("bond law is radial") };
    let mut radial = match (rest_index, rest) {
        (Some(k), Some(rest)) => {
            let mut own = [0.0; MAX_BOND_PARAMS];
            own[..params.len()].copy_from_slice(params);
            own[k] = rest;
            eval(&own[..params.len()], r)
        }
        _ => eval(params, r),
    };
    if scale != 1.0 {
        radial.energy *= scale;
        radial.de_dr *= scale;
        radial.d2e_dr2 *= scale;
    }
    radial
}

/// Largest parameter count of a bond law (checked by a test).
const MAX_BOND_PARAMS: usize = 8;

/// External fields: evaluated on unwrapped positions, members in ascending order.
fn apply_externals(model: &Model, state: &State, sim_box: &SimBox, out: &mut Forces) {
    for external in &model.externals {
        let Law::OneBody(eval) = external.term.interaction.law() else { unreachable!("external law is one-body") };
        let reg = registry_index(&external.term);
        let mut energy = 0.0;
        for &m in &external.members {
            let m = m as usize;
            let field = eval(&external.term.params, sim_box.unwrap(state.positions[m], state.images[m]));
            out.forces[m] += field.force;
            energy += field.energy;
        }
        out.energy_by_interaction[reg] += energy;
    }
}

#[cfg(test)]
mod tests {
    use super::MAX_BOND_PARAMS;
    use crate::interactions::{Kind, REGISTRY};

    #[test]
    fn bond_laws_fit_the_stateful_parameter_buffer() {
        for i in REGISTRY.iter().filter(|i| i.kind() == Kind::Bond) {
            assert!(i.params().len() <= MAX_BOND_PARAMS, "{} has too many parameters", i.name());
        }
    }
}
