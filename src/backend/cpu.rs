//! CPU reference backend: f64, plain loops, deterministic on any thread count.
//!
//! Two parallel passes over fixed blocks of particles compute each
//! particle's force as a sum in an order fixed by the data, with no write
//! conflicts, float atomics or order-dependent reductions:
//!
//! - **Pairs**: a half neighbour list (each pair once, rows sorted by
//!   index), the pair rules resolved per type pair
//!   (`PairTable`, `pair_table.rs`), each pair's force added to both
//!   particles by Newton's third law in the ordered scatter/gather of
//!   `newton` (first pass, and the start of the second).
//! - **Bonds, angles and volume elements**: each once, in the row of its lowest-index
//!   particle, in the same scatter as the pairs (see `bonded`).
//! - The second pass gathers, per particle, the spills of the scatter, then
//!   the slots of surface and contact terms.
//! - **Externals**: per member particle, on the unwrapped position.
//! - **Surface terms** of closed bodies (turgor, tension, bending): each body
//!   once, in parallel over bodies, into per-node slots that each particle
//!   gathers in a fixed order (see `src/backend/surface.rs`).
//! - **Contact terms** between bodies (`contact` lines): node–face candidate
//!   pairs, each evaluated into its own slot, gathered per particle in pair
//!   order (see `src/backend/contact.rs`); [`CpuBackend::update_contacts`]
//!   keeps the candidate list current and [`CpuBackend::contact_step_limits`]
//!   gives the explicit step its clamp.
//!
//! Energies and the virial are needed only on thermo steps:
//! [`CpuBackend::compute_forces`] skips them, [`CpuBackend::compute`]
//! adds them (bonded terms in term order; pair terms in the pair pass, per
//! block, reduced in block order) without changing a bit of the forces.
//!
//! The virial tensor is W = Σ_terms Σ_k r_k ⊗ f_k over image-consistent term
//! positions (for a pair, r_ij ⊗ f_ij); the pressure tensor reported in thermo
//! is P = (N·kT/V)·I + W/V (ideal Brownian osmotic part + configurational part).

use glam::DVec3;
use rayon::prelude::*;

use super::bonded::Bonded;
use super::candidates::Near;
use super::contact::Contacts;
use super::newton::{Newton, Scatter, BLOCK};
use super::pair_table::{PairGeometry, PairTable};
use super::special::SpecialPairs;
use super::surface::Surfaces;
use super::virial::add6;
use crate::interactions::{Kind, RadialLaw, REGISTRY};
use crate::neighbor::{Exclusions, NeighborList};
use crate::system::{registry_index, External, Model, SimBox, State};

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

/// The CPU force engine with its neighbour list and scratch buffers.
pub struct CpuBackend {
    neighbors: NeighborList,
    exclusions: Exclusions,
    bonded: Bonded,
    surfaces: Surfaces,
    contacts: Contacts,
    pairs: PairTable,
    /// Spill buckets of the Newton's-third-law pair scatter.
    newton: Newton,
    /// Registry indices of the pair interactions in use (the energy columns).
    pair_interactions: Vec<usize>,
    /// For each pair rule, its energy column.
    pair_rule_column: Vec<usize>,
    /// Per bond: tension dE/dr (0 when unbound) and length at the last
    /// evaluation (filled only when bonds have kinetics).
    /// Bonded neighbour pairs of fractional `special_bonds` weight.
    special: SpecialPairs,
    bond_tension: Vec<f64>,
    bond_length: Vec<f64>,
}

impl CpuBackend {
    /// Prepares buffers and builds the first neighbour list.
    pub fn new(model: &Model, state: &State, sim_box: &SimBox, skin: f64) -> Result<Self, String> {
        let mut pair_interactions: Vec<usize> = model.pair_rules.iter().map(|t| registry_index(t)).collect();
        pair_interactions.sort_unstable();
        pair_interactions.dedup();
        let pair_rule_column = model.pair_rules.iter().map(|r| pair_interactions.binary_search(&registry_index(r)).unwrap()).collect();
        let mut backend = Self {
            neighbors: NeighborList::half(model.max_pair_cutoff(), skin).with_periodic_images(),
            exclusions: pair_exclusions(model, state.bonds.as_ref().map(|b| b.bound.as_slice())),
            special: SpecialPairs::new(model, state.bonds.as_ref().map(|b| b.bound.as_slice())),
            bonded: Bonded::new(model),
            surfaces: Surfaces::new(model),
            contacts: Contacts::new(model),
            pairs: PairTable::default(),
            newton: Newton::default(),
            pair_interactions,
            pair_rule_column,
            bond_tension: Vec::new(),
            bond_length: Vec::new(),
        };
        backend.rebuild_neighbors(state, sim_box)?;
        backend.update_contacts(model, state, sim_box)?;
        Ok(backend)
    }

    /// Rebuilds the contact candidate list if a contact node moved more than
    /// d̂/2 since it was built. Call before every force evaluation at moved
    /// positions: a stale list could miss a pair (nothing to do without
    /// `contact` lines).
    pub fn update_contacts(&mut self, model: &Model, state: &State, sim_box: &SimBox) -> Result<(), String> {
        self.contacts.update(model, &state.positions, sim_box)
    }

    /// The smallest node–face distance between different bodies at the last
    /// evaluation: exact below the largest contact d̂, ∞ when no pair is
    /// within the search range 2·d̂ (and when there are no `contact` lines).
    pub fn min_contact_distance(&self) -> f64 {
        self.contacts.min_distance()
    }

    /// Contact candidate-list builds so far.
    pub fn contact_builds(&self) -> u64 {
        self.contacts.builds()
    }

    /// Fills `limits` with each particle's largest safe displacement for the
    /// next explicit step (see `src/backend/contact.rs`); false (and `limits`
    /// untouched) when the model has no contact terms.
    pub fn contact_step_limits(&self, n: usize, limits: &mut Vec<f64>) -> bool {
        if self.contacts.is_empty() {
            return false;
        }
        self.contacts.fill_step_limits(n, limits);
        true
    }

    /// Bonds broke or bound: pair exclusions follow the bound bonds, so they
    /// and the neighbour list are rebuilt (nothing to do without pair terms).
    pub fn bonds_changed(&mut self, model: &Model, state: &State, sim_box: &SimBox) -> Result<(), String> {
        if self.pair_interactions.is_empty() {
            return Ok(());
        }
        let bound = state.bonds.as_ref().map(|b| b.bound.as_slice());
        self.exclusions = pair_exclusions(model, bound);
        self.special = SpecialPairs::new(model, bound);
        self.rebuild_neighbors(state, sim_box)
    }

    /// Tension (dE/dr, positive when stretched; 0 when unbound) and length of
    /// every bond at the last evaluation; empty when bonds have no kinetics.
    /// Measures the tension and length of every bond at `state` without a
    /// force pass (bond kinetics between GPU steps), for
    /// [`Self::bond_tension_and_length`].
    pub fn measure_bonds(&mut self, model: &Model, state: &State, sim_box: &SimBox) {
        self.bonded.resolve_laws(model);
        self.bonded.tensions(
            model,
            &state.positions,
            &sim_box.images(),
            state.bonds.as_ref(),
            &mut self.bond_tension,
            &mut self.bond_length,
        );
    }

    pub fn bond_tension_and_length(&self) -> (&[f64], &[f64]) {
        (&self.bond_tension, &self.bond_length)
    }

    /// Tension (dE/dr, positive when stretched; 0 when unbound) and length of
    /// every bond at `state`, computed now (for outputs). Needs a force
    /// evaluation since the model's parameters last changed.
    pub fn bond_tensions_at(&self, model: &Model, state: &State, sim_box: &SimBox) -> (Vec<f64>, Vec<f64>) {
        let (mut tension, mut length) = (Vec::new(), Vec::new());
        self.bonded.tensions(model, &state.positions, &sim_box.images(), state.bonds.as_ref(), &mut tension, &mut length);
        (tension, length)
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

    pub(super) fn bonded(&self) -> &Bonded {
        &self.bonded
    }

    pub(super) fn pair_table(&self) -> &PairTable {
        &self.pairs
    }

    pub(super) fn surfaces(&self) -> &Surfaces {
        &self.surfaces
    }

    pub(super) fn contacts(&self) -> &Contacts {
        &self.contacts
    }

    pub(super) fn special_pairs(&self) -> &SpecialPairs {
        &self.special
    }

    /// The half neighbour list, or None when the model has no pair terms.
    pub(super) fn neighbor_list(&self) -> Option<&NeighborList> {
        (!self.pair_interactions.is_empty()).then_some(&self.neighbors)
    }

    /// Number of neighbour-list builds so far.
    pub fn neighbor_builds(&self) -> u64 {
        self.neighbors.builds()
    }

    /// Evaluates forces, energies and the virial at `state` into `out`.
    pub fn compute(&mut self, model: &Model, state: &State, sim_box: &SimBox, out: &mut Forces) {
        self.evaluate(model, state, sim_box, out, true);
    }

    /// Evaluates the forces only (the step loop between thermo steps);
    /// `out.energy_by_interaction` and `out.virial` are left as they were.
    pub fn compute_forces(&mut self, model: &Model, state: &State, sim_box: &SimBox, out: &mut Forces) {
        self.evaluate(model, state, sim_box, out, false);
    }

    fn evaluate(&mut self, model: &Model, state: &State, sim_box: &SimBox, out: &mut Forces, energies: bool) {
        let n = model.len();
        let x = &state.positions;
        let images = sim_box.images();
        let has_pairs = !self.pair_interactions.is_empty();
        if has_pairs {
            self.pairs.update(model, &self.pair_rule_column);
        }
        self.bonded.resolve_laws(model);
        self.bonded.gather_state(state.bonds.as_ref());
        self.bonded.prepare_tetras(model, x, &images);
        self.surfaces.prepare(model, x, &images);
        self.contacts.prepare(model, x, &images);
        let bond_state = state.bonds.as_ref();
        if model.has_kinetics() {
            self.bonded.tensions(model, x, &images, bond_state, &mut self.bond_tension, &mut self.bond_length);
        }
        let (pairs, bonded, surfaces, contacts) = (&self.pairs, &self.bonded, &self.surfaces, &self.contacts);
        let (has_surfaces, has_contacts) = (!surfaces.is_empty(), !contacts.is_empty());
        let geometry = PairGeometry { x, types: &model.types, list: &self.neighbors, images };
        out.forces.resize(n, DVec3::ZERO);
        let scattered = has_pairs || !model.bonds.is_empty() || !model.angles.is_empty() || !model.tetras.is_empty();
        let terms = ScatterTerms { pairs: has_pairs.then_some(pairs), geometry: &geometry, bonded, model };
        let columns = self.pair_interactions.len();
        let pair_energy = match (scattered, energies) {
            (false, _) => None,
            (true, false) => terms.scatter::<false>(&mut self.newton, &mut out.forces, columns),
            (true, true) => terms.scatter::<true>(&mut self.newton, &mut out.forces, columns),
        };
        let newton = &self.newton;
        out.forces.par_chunks_mut(BLOCK).enumerate().for_each(|(t, block)| {
            if scattered {
                newton.gather(t, block);
            } else {
                block.fill(DVec3::ZERO);
            }
            if has_surfaces || has_contacts {
                for (k, f) in block.iter_mut().enumerate() {
                    let i = t * BLOCK + k;
                    if has_surfaces {
                        *f += surfaces.force_on(i);
                    }
                    if has_contacts {
                        *f += contacts.force_on(i);
                    }
                }
            }
        });
        if energies {
            out.energy_by_interaction.clear();
            out.energy_by_interaction.resize(REGISTRY.len(), 0.0);
            out.virial = [0.0; 6];
            self.special.add(model, x, &images, &mut out.forces, Some((&mut out.energy_by_interaction, &mut out.virial)));
            bonded.energy(model, x, &images, bond_state, &mut out.energy_by_interaction, &mut out.virial);
            surfaces.energy(model, &mut out.energy_by_interaction, &mut out.virial);
            contacts.energy(model, x, &images, &mut out.energy_by_interaction, &mut out.virial);
            if let Some((energy, virial)) = pair_energy {
                for (c, &reg) in self.pair_interactions.iter().enumerate() {
                    out.energy_by_interaction[reg] += energy[c];
                }
                add6(&mut out.virial, virial);
            }
        } else {
            self.special.add(model, x, &images, &mut out.forces, None);
        }
        apply_externals(model, state, sim_box, out, energies);
    }

    /// Per-entry forces on particle `i` (slow; for diagnostics only).
    pub fn breakdown(&self, model: &Model, state: &State, sim_box: &SimBox, i: usize) -> Vec<ForceBreakdown> {
        let images = sim_box.images();
        let mut parts: Vec<ForceBreakdown> = (self.bonded.terms_on(i, model, &state.positions, &images, state.bonds.as_ref()).into_iter())
            .map(|(kind, t, force)| {
                let (term, label) = match kind {
                    Kind::Bond => (model.bond_types[t].term(), model.bond_types[t].label.text.clone()),
                    Kind::Angle => (model.angle_types[t].term(), model.angle_types[t].label.text.clone()),
                    _ => {
                        let term = model.tetra_types[model.tetra_type[t] as usize].term();
                        let ids = model.tetras[t].map(|p| model.ids[p as usize].to_string()).join("–");
                        // A NaN force is the mark of an element turned inside out (J ≤ 0).
                        let inverted = if force.is_finite() { "" } else { ", turned inside out (det F ≤ 0)" };
                        (term, format!("{} element {} of particles {ids}{inverted}", term.label.text, t + 1))
                    }
                };
                ForceBreakdown { kind: kind.keyword(), label, interaction: term.interaction.name(), force }
            })
            .collect();
        for (rule, force) in self.surfaces.terms_on(i) {
            let term = &model.body_rules[rule];
            parts.push(ForceBreakdown { kind: "body", label: term.label.text.clone(), interaction: term.interaction.name(), force });
        }
        if let Some(term) = model.contact_rules.first().filter(|_| !self.contacts.is_empty()) {
            let force = self.contacts.force_on(i);
            if force != DVec3::ZERO {
                parts.push(ForceBreakdown {
                    kind: "contact",
                    label: "node–face contacts".into(),
                    interaction: term.interaction.name(),
                    force,
                });
            }
        }
        if !self.pair_interactions.is_empty() {
            let x = &state.positions;
            for j in self.neighbors.partners(i) {
                let d = images.minimum_image(x[j as usize] - x[i]);
                let r = d.length();
                for &rule in model.pair_rules_between(model.types[i], model.types[j as usize]) {
                    let term = &model.pair_rules[rule as usize];
                    let RadialLaw { eval, range, .. } = term.law;
                    if r < range(&term.params) {
                        let radial = eval(&term.params, r);
                        let label = format!("{} {}-{}", term.label.text, model.ids[i], model.ids[j as usize]);
                        parts.push(ForceBreakdown {
                            kind: "pair",
                            label,
                            interaction: term.interaction.name(),
                            force: radial.force_along(d, r),
                        });
                    }
                }
            }
        }
        self.special.for_each(model, &state.positions, &images, |a, b, d, r, radial, rule| {
            if a as usize == i || b as usize == i {
                let term = &model.pair_rules[rule];
                let f = radial.force_along(d, r);
                let (label, force) = (
                    format!("{} {}-{} (special_bonds)", term.label.text, model.ids[a as usize], model.ids[b as usize]),
                    if a as usize == i { f } else { -f },
                );
                parts.push(ForceBreakdown { kind: "pair", label, interaction: term.interaction.name(), force });
            }
        });
        for external in &model.externals {
            if external.members.binary_search(&(i as u32)).is_ok() {
                let out = external.at(sim_box.unwrap(state.positions[i], state.images[i]), state.time);
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

/// The terms of the first pass: pairs (when the model has any), bonds and
/// angles and volume elements, row by row.
struct ScatterTerms<'a> {
    pairs: Option<&'a PairTable>,
    geometry: &'a PairGeometry<'a>,
    bonded: &'a Bonded,
    model: &'a Model,
}

impl ScatterTerms<'_> {
    /// The scatter (first pass): in each row, its pairs, bonds, angles and volume elements,
    /// each force on all of the term's particles; with `ENERGY` also the energy per pair column
    /// and the pair virial, each block's in row order and the blocks' in block
    /// order (`None` without `ENERGY`: nothing is allocated then).
    fn scatter<const ENERGY: bool>(&self, newton: &mut Newton, forces: &mut [DVec3], columns: usize) -> Option<(Vec<f64>, [f64; 6])> {
        let PairGeometry { x, images, .. } = self.geometry;
        let rows = |range: std::ops::Range<usize>, scatter: &mut Scatter, energy: &mut [f64], virial: &mut [f64; 6]| {
            let mut near = Near::new();
            for i in range {
                if let Some(pairs) = self.pairs {
                    // The row's own force stays in a register (Scatter::own).
                    let mut fi = scatter.own(i);
                    pairs.row_forces::<ENERGY>(i, self.geometry, &mut near, energy, virial, |j, f| {
                        fi += f;
                        scatter.partner(j, f);
                    });
                    scatter.set_own(i, fi);
                }
                self.bonded.row_bonds(i, self.model, x, images, |j, f| scatter.pair(i, j, f));
                self.bonded.row_angles(i, self.model, x, images, |p, f| scatter.add(p, f));
                self.bonded.row_tetras(i, self.model, x, images, |p, f| scatter.add(p, f));
            }
        };
        if !ENERGY {
            newton.scatter(forces, |range, scatter| rows(range, scatter, &mut [], &mut [0.0; 6]));
            return None;
        }
        let blocks = newton.scatter(forces, |range, scatter| {
            let (mut energy, mut virial) = (vec![0.0; columns], [0.0; 6]);
            rows(range, scatter, &mut energy, &mut virial);
            (energy, virial)
        });
        let (mut energy, mut virial) = (vec![0.0; columns], [0.0; 6]);
        for (e, w) in blocks {
            energy.iter_mut().zip(&e).for_each(|(a, b)| *a += b);
            add6(&mut virial, w);
        }
        Some((energy, virial))
    }
}

/// What the pair list leaves out: the `special_bonds` pairs along the
/// bound bonds (`bound` = None: all), and every pair of particle types that
/// no pair rule acts between.
fn pair_exclusions(model: &Model, bound: Option<&[bool]>) -> Exclusions {
    let pairs = Exclusions::from_pairs(model.len(), &model.excluded_pairs(bound));
    pairs.with_type_pairs(&model.types, model.type_names.len(), |a, b| model.pair_rules_between(a, b).is_empty())
}

/// One external's field on each of its members (index, energy and force),
/// evaluated on unwrapped positions, members in ascending order.
pub fn external_field<'a>(
    external: &'a External,
    state: &'a State,
    sim_box: &'a SimBox,
) -> impl Iterator<Item = (usize, crate::interactions::OneBody)> + 'a {
    external.members.iter().map(move |&m| {
        let m = m as usize;
        (m, external.at(sim_box.unwrap(state.positions[m], state.images[m]), state.time))
    })
}

fn apply_externals(model: &Model, state: &State, sim_box: &SimBox, out: &mut Forces, energies: bool) {
    for external in &model.externals {
        let reg = registry_index(&external.term);
        let mut energy = 0.0;
        for (m, field) in external_field(external, state, sim_box) {
            out.forces[m] += field.force;
            energy += field.energy;
        }
        if energies {
            out.energy_by_interaction[reg] += energy;
        }
    }
}
