//! Bonded terms on the CPU, each evaluated once per force pass.
//!
//! - **Bonds**: in the row of the bond's lower-index end
//!   ([`Bonded::row_bonds`]), from the force-only evaluator; the force goes
//!   to both ends by Newton's third law through the ordered scatter of
//!   [`super::newton`], with the pair forces.
//! - **Angles**: in the row of the angle's lowest-index particle
//!   ([`Bonded::row_angles`]), the three forces through the same scatter.
//! - **Volume elements** (tetrahedra): likewise, in the row of their
//!   lowest-index corner ([`Bonded::row_tetras`]), the four forces.
//! - **Energies and virial** (thermo steps only): every term once, in term
//!   order, sequentially.
//!
//! A row visits its bonds, then its angles, then its elements, in ascending term index, so the
//! order of every sum is fixed by the data (see [`super::newton`]).
//!
//! With bond kinetics, each bond also has a state: an unbound bond carries no
//! force, and a bond may have its own rest length and a stiffness scale
//! ([`BondState`]).

use glam::DVec3;
use rayon::prelude::*;

use super::nodal_pressure::{tetra_positions, NodalPressure};
use super::virial::{add6, outer};
use crate::interactions::{FourBody, Kind, Radial, ThreeBody};
use crate::system::BondState;
use crate::system::{registry_index, Images, Model};

/// Groups entries by owning particle: entry `s` belongs to `owner[s]`.
/// Returns CSR offsets and, per particle, its entries in ascending order.
fn by_particle(n: usize, owner: impl Iterator<Item = u32> + Clone) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; n + 1];
    for p in owner.clone() {
        offsets[p as usize + 1] += 1;
    }
    for i in 0..n {
        offsets[i + 1] += offsets[i];
    }
    let mut fill = offsets.clone();
    let mut entries = vec![0u32; offsets[n] as usize];
    for (s, p) in owner.enumerate() {
        entries[fill[p as usize] as usize] = s as u32;
        fill[p as usize] += 1;
    }
    (offsets, entries)
}

/// A radial law's `eval` and `force` (`interactions::RadialLaw`).
type RadialEval = fn(&[f64], f64) -> Radial;
type RadialForce = fn(&[f64], f64) -> f64;
/// An angle law's evaluator (`interactions::AngleLaw`).
type ThreeBodyEval = fn(&[f64], [DVec3; 3]) -> ThreeBody;

/// The bonds and angles owned by each particle, and the resolved laws.
#[derive(Default)]
pub(super) struct Bonded {
    /// The bonds whose lower-index end is particle i are
    /// `owned_bonds[owned_offsets[i]..owned_offsets[i + 1]]`, ascending.
    owned_offsets: Vec<u32>,
    owned_bonds: Vec<u32>,
    /// Per slot of `owned_bonds` (row order): the bond's other end and its
    /// type. The bond arrays are in the topology's order, which a row visits
    /// at scattered indices (a builder writes a shell's edges face by face);
    /// read there, their cache misses cost more than the laws: FIRE on the
    /// level-5 tensegrity cell (23 803 particles, 128 091 bonds) took 26 s
    /// for 1 000 iterations with them, 20 s from the slots (one thread).
    slot_other: Vec<u32>,
    slot_type: Vec<u32>,
    /// Per slot, the bond's state, gathered before each force pass
    /// ([`Self::gather_state`]; empty when bonds have none).
    slot_state: Vec<SlotState>,
    /// The angles whose lowest-index particle is i, likewise.
    angle_offsets: Vec<u32>,
    owned_angles: Vec<u32>,
    /// Evaluator and force-only evaluator per bond type, re-resolved every evaluation.
    bond_laws: Vec<(RadialEval, RadialForce)>,
    /// Parameters per bond type, likewise, in a fixed-size array a bond with
    /// its own rest length copies whole (no call to copy a slice); a custom
    /// law with more parameters copies its own.
    bond_params: Vec<TypeParams>,
    /// Evaluator per angle type, likewise.
    angle_laws: Vec<ThreeBodyEval>,
    /// The volume elements whose lowest-index corner is i, likewise.
    tetra_offsets: Vec<u32>,
    owned_tetras: Vec<u32>,
    /// The elements' averaged nodal pressures at the last force pass
    /// ([`Self::prepare_tetras`]; empty without nodal-pressure types).
    pub(super) nodal: NodalPressure,
}

impl Bonded {
    pub(super) fn new(model: &Model) -> Self {
        let n = model.len();
        let (owned_offsets, owned_bonds) = by_particle(n, model.bonds.iter().map(|&[i, j]| i.min(j)));
        let slot_other = owned_bonds.iter().map(|&b| model.bonds[b as usize].into_iter().max().unwrap()).collect();
        let slot_type = owned_bonds.iter().map(|&b| model.bond_type[b as usize]).collect();
        let (angle_offsets, owned_angles) = by_particle(n, model.angles.iter().map(|a| a.iter().copied().min().unwrap()));
        let (tetra_offsets, owned_tetras) = by_particle(n, model.tetras.iter().map(|t| t.iter().copied().min().unwrap()));
        Self {
            owned_offsets,
            owned_bonds,
            slot_other,
            slot_type,
            slot_state: Vec::new(),
            angle_offsets,
            owned_angles,
            bond_laws: Vec::new(),
            bond_params: Vec::new(),
            angle_laws: Vec::new(),
            tetra_offsets,
            owned_tetras,
            nodal: NodalPressure::default(),
        }
    }

    /// The evaluators of each bond and angle type's law.
    pub(super) fn resolve_laws(&mut self, model: &Model) {
        self.bond_laws.clear();
        self.bond_laws.extend(model.bond_types.iter().map(|t| (t.law.eval, t.law.force)));
        self.bond_params.clear();
        self.bond_params.extend(model.bond_types.iter().zip(&model.bond_kinetics).map(|(t, kinetics)| {
            let mut values = [0.0; MAX_BOND_PARAMS];
            let fits = t.params.len() <= MAX_BOND_PARAMS;
            if fits {
                values[..t.params.len()].copy_from_slice(&t.params);
            }
            TypeParams { values: fits.then_some(values), len: t.params.len(), rest_index: kinetics.rest_index }
        }));
        self.angle_laws.clear();
        self.angle_laws.extend(model.angle_types.iter().map(|t| t.law.0));
    }

    /// `law(params)` of a bond of type `t` in state `slot` (its own rest
    /// length, if its type's law has one), and the stiffness scale to apply
    /// to the result; `None` when it is unbound.
    #[inline(always)]
    fn with_state<R>(&self, t: usize, model: &Model, slot: SlotState, law: impl FnOnce(&[f64]) -> R) -> Option<(R, f64)> {
        if !slot.bound {
            return None;
        }
        let params = &model.bond_types[t].params;
        let out = match (&self.bond_params[t], slot.rest) {
            (&TypeParams { values: Some(mut values), len, rest_index: Some(k) }, Some(rest)) => {
                values[k] = rest;
                law(&values[..len])
            }
            (&TypeParams { values: None, rest_index: Some(k), .. }, Some(rest)) => {
                // A custom law with more parameters than the array holds.
                let mut own = params.clone();
                own[k] = rest;
                law(&own)
            }
            _ => law(params),
        };
        Some((out, slot.scale))
    }

    /// Copies each bond's state into its slot (row order) for the rows'
    /// force pass: one pass whose scattered reads overlap, rather than one
    /// miss after another inside the rows. Call before [`Self::row_bonds`]
    /// whenever the state may have changed (every force pass).
    pub(super) fn gather_state(&mut self, state: Option<&BondState>) {
        let Some(s) = state else {
            self.slot_state.clear();
            return;
        };
        self.slot_state.resize(self.owned_bonds.len(), SlotState { bound: false, rest: None, scale: 0.0 });
        (self.slot_state.par_iter_mut().zip(self.owned_bonds.par_iter()).with_min_len(4096))
            .for_each(|(slot, &b)| *slot = SlotState::of(s, b as usize));
    }

    /// `law(params)` of bond `b` of type `t` with its state if it has one
    /// (its own rest length), and the stiffness scale to apply to the result;
    /// `None` when it is unbound.
    #[inline(always)]
    fn with_params<R>(
        &self,
        b: usize,
        t: usize,
        model: &Model,
        state: Option<&BondState>,
        law: impl FnOnce(&[f64]) -> R,
    ) -> Option<(R, f64)> {
        match state {
            None => Some((law(&model.bond_types[t].params), 1.0)),
            Some(s) => self.with_state(t, model, SlotState::of(s, b), law),
        }
    }

    /// Bond `b` of type `t` at length `r`, with its state if it has one
    /// (`None` when it is unbound).
    #[inline(always)]
    pub(super) fn bond_radial(&self, b: usize, t: usize, r: f64, model: &Model, state: Option<&BondState>) -> Option<Radial> {
        let (mut radial, scale) = self.with_params(b, t, model, state, |p| (self.bond_laws[t].0)(p, r))?;
        if scale != 1.0 {
            radial.energy *= scale;
            radial.de_dr *= scale;
            radial.d2e_dr2 *= scale;
        }
        Some(radial)
    }

    /// The bonds owned by particle `i` (lower-index end), ascending: calls
    /// `visit(j, f)` with the other end j and the force f on `i` (−f acts on j)
    /// of each bond that exerts one, from the force-only evaluator. With a
    /// bond state, [`Self::gather_state`] must have copied it since it last
    /// changed.
    #[inline(always)]
    pub(super) fn row_bonds(&self, i: usize, model: &Model, x: &[DVec3], images: &Images, mut visit: impl FnMut(usize, DVec3)) {
        for k in self.owned_offsets[i] as usize..self.owned_offsets[i + 1] as usize {
            let (j, t) = (self.slot_other[k] as usize, self.slot_type[k] as usize);
            let d = images.minimum_image(x[j] - x[i]);
            let r2 = d.length_squared();
            let law = |p: &[f64]| (self.bond_laws[t].1)(p, r2);
            let out = match self.slot_state.get(k) {
                None => Some((law(&model.bond_types[t].params), 1.0)),
                Some(&slot) => self.with_state(t, model, slot, law),
            };
            let f = match out {
                Some((over_r, scale)) if over_r != 0.0 => d * (over_r * scale),
                _ => continue,
            };
            if f != DVec3::ZERO {
                visit(j, f);
            }
        }
    }

    /// Bond `b` seen from its particle `i` (diagnostics): its force on `i`,
    /// as [`Self::row_bonds`] computes it.
    fn bond_force(&self, b: usize, i: usize, model: &Model, x: &[DVec3], images: &Images, state: Option<&BondState>) -> DVec3 {
        let [p, q] = model.bonds[b];
        let other = if p as usize == i { q } else { p } as usize;
        let t = model.bond_type[b] as usize;
        let d = images.minimum_image(x[other] - x[i]);
        let r2 = d.length_squared();
        match self.with_params(b, t, model, state, |p| (self.bond_laws[t].1)(p, r2)) {
            Some((over_r, scale)) if over_r != 0.0 => d * (over_r * scale),
            _ => DVec3::ZERO,
        }
    }

    /// Tension (dE/dr; 0 when unbound) and length of every bond.
    pub(super) fn tensions(
        &self,
        model: &Model,
        x: &[DVec3],
        images: &Images,
        state: Option<&BondState>,
        tension: &mut Vec<f64>,
        length: &mut Vec<f64>,
    ) {
        tension.resize(model.bonds.len(), 0.0);
        length.resize(model.bonds.len(), 0.0);
        tension.par_iter_mut().zip(length.par_iter_mut()).enumerate().with_min_len(1024).for_each(|(b, (tension, length))| {
            let [i, j] = model.bonds[b];
            let r = images.minimum_image(x[j as usize] - x[i as usize]).length();
            *length = r;
            *tension = self.bond_radial(b, model.bond_type[b] as usize, r, model, state).map_or(0.0, |radial| radial.de_dr);
        });
    }

    /// The angles owned by particle `i` (lowest-index particle), ascending:
    /// calls `visit(p, f)` with each of the angle's particles and its force.
    #[inline(always)]
    pub(super) fn row_angles(&self, i: usize, model: &Model, x: &[DVec3], images: &Images, mut visit: impl FnMut(usize, DVec3)) {
        for &a in &self.owned_angles[self.angle_offsets[i] as usize..self.angle_offsets[i + 1] as usize] {
            let a = a as usize;
            let t = model.angle_type[a] as usize;
            let out = (self.angle_laws[t])(&model.angle_types[t].params, angle_positions(model, a, x, images));
            for (&p, f) in model.angles[a].iter().zip(out.forces) {
                visit(p as usize, f);
            }
        }
    }

    /// Before a force pass at `x`: the nodal volumes of the nodal-pressure
    /// elements (src/backend/nodal_pressure.rs).
    pub(super) fn prepare_tetras(&mut self, model: &Model, x: &[DVec3], images: &Images) {
        self.nodal.prepare(model, x, images);
    }

    /// The volume elements owned by particle `i` (lowest-index corner),
    /// ascending: calls `visit(p, f)` with each corner and its force.
    #[inline(always)]
    pub(super) fn row_tetras(&self, i: usize, model: &Model, x: &[DVec3], images: &Images, mut visit: impl FnMut(usize, DVec3)) {
        for &e in &self.owned_tetras[self.tetra_offsets[i] as usize..self.tetra_offsets[i + 1] as usize] {
            let (_, out) = eval_tetra(model, e as usize, x, images, &self.nodal);
            for (&p, f) in model.tetras[e as usize].iter().zip(out.forces) {
                visit(p as usize, f);
            }
        }
    }

    /// Bonded energies (per registry entry, added to `energy`) and virial
    /// (added to `virial`), every term once in term order.
    pub(super) fn energy(
        &self,
        model: &Model,
        x: &[DVec3],
        images: &Images,
        state: Option<&BondState>,
        energy: &mut [f64],
        virial: &mut [f64; 6],
    ) {
        let bond_registry: Vec<usize> = model.bond_types.iter().map(|t| registry_index(t)).collect();
        for (b, &[i, j]) in model.bonds.iter().enumerate() {
            let t = model.bond_type[b] as usize;
            let d = images.minimum_image(x[j as usize] - x[i as usize]);
            let r = d.length();
            let Some(radial) = self.bond_radial(b, t, r, model, state) else { continue };
            energy[bond_registry[t]] += radial.energy;
            add6(virial, outer(d, -radial.force_along(d, r)));
        }
        let angle_registry: Vec<usize> = model.angle_types.iter().map(|t| registry_index(t)).collect();
        for a in 0..model.angles.len() {
            let ([xi, xj, xk], out) = eval_angle(model, a, x, images);
            energy[angle_registry[model.angle_type[a] as usize]] += out.energy;
            add6(virial, outer(xi - xj, out.forces[0]));
            add6(virial, outer(xk - xj, out.forces[2]));
        }
        let tetra_registry: Vec<usize> = model.tetra_types.iter().map(|t| registry_index(t)).collect();
        for e in 0..model.tetras.len() {
            let (at, out) = eval_tetra(model, e, x, images, &self.nodal);
            energy[tetra_registry[model.tetra_type[e] as usize]] += out.energy;
            for k in 1..4 {
                add6(virial, outer(at[k] - at[0], out.forces[k]));
            }
        }
    }

    /// The bonded terms on particle `i` with their forces (diagnostics):
    /// (kind, index, force), the index being the type of a bond or angle and
    /// the element itself for a volume element (its report names it).
    pub(super) fn terms_on(
        &self,
        i: usize,
        model: &Model,
        x: &[DVec3],
        images: &Images,
        state: Option<&BondState>,
    ) -> Vec<(Kind, usize, DVec3)> {
        let mut parts = Vec::new();
        for (b, _) in model.bonds.iter().enumerate().filter(|(_, ends)| ends.contains(&(i as u32))) {
            parts.push((Kind::Bond, model.bond_type[b] as usize, self.bond_force(b, i, model, x, images, state)));
        }
        for (a, ends) in model.angles.iter().enumerate() {
            if let Some(k) = ends.iter().position(|&p| p as usize == i) {
                parts.push((Kind::Angle, model.angle_type[a] as usize, eval_angle(model, a, x, images).1.forces[k]));
            }
        }
        for (e, corners) in model.tetras.iter().enumerate() {
            if let Some(k) = corners.iter().position(|&p| p as usize == i) {
                parts.push((Kind::Tetra, e, eval_tetra(model, e, x, images, &self.nodal).1.forces[k]));
            }
        }
        parts
    }
}

/// The positions of angle `a`, image-consistent: i and k at their minimum
/// image around the vertex j.
#[inline(always)]
fn angle_positions(model: &Model, a: usize, x: &[DVec3], images: &Images) -> [DVec3; 3] {
    let [i, j, k] = model.angles[a];
    let xj = x[j as usize];
    [xj + images.minimum_image(x[i as usize] - xj), xj, xj + images.minimum_image(x[k as usize] - xj)]
}

/// Angle `a` at image-consistent positions (see `angle_positions`).
#[inline]
pub(super) fn eval_angle(model: &Model, a: usize, x: &[DVec3], images: &Images) -> ([DVec3; 3], ThreeBody) {
    let term = &model.angle_types[model.angle_type[a] as usize];
    let at = angle_positions(model, a, x, images);
    (at, (term.law.0)(&term.params, at))
}

/// Volume element `e` at image-consistent positions (corners 1–3 at their
/// minimum image around corner 0), with its averaged nodal pressure from
/// `nodal` if its type has one.
#[inline]
pub(super) fn eval_tetra(model: &Model, e: usize, x: &[DVec3], images: &Images, nodal: &NodalPressure) -> ([DVec3; 4], FourBody) {
    let term = &model.tetra_types[model.tetra_type[e] as usize];
    let at = tetra_positions(model, e, x, images);
    (at, nodal.complete(model, e, at, (term.law.eval)(&term.params, &model.tetra_rest[e], at)))
}

/// Largest parameter count of a bond law (checked by a test).
const MAX_BOND_PARAMS: usize = 8;

/// One bond's state as a force pass reads it.
#[derive(Clone, Copy)]
struct SlotState {
    bound: bool,
    /// Its own rest length (`None`: the type's).
    rest: Option<f64>,
    scale: f64,
}

impl SlotState {
    fn of(s: &BondState, b: usize) -> Self {
        Self { bound: s.bound[b], rest: s.rest[b], scale: s.scale[b] }
    }
}

/// A bond type's parameters ([`Bonded::resolve_laws`]).
#[derive(Clone, Copy)]
struct TypeParams {
    /// The values (None when a custom law has more than the array holds).
    values: Option<[f64; MAX_BOND_PARAMS]>,
    len: usize,
    /// Which of them is the rest length a bond may have its own value of.
    rest_index: Option<usize>,
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
