//! `bind` formation on the device (kernels: shaders/common/bind.wgsl; the
//! rule and its CPU decision: src/kinetics_engine/formation.rs).
//!
//! Each step, after the device's breaks and rebinds, every particle lists
//! its candidate partners j > i from the GPU neighbour list (the list's
//! range covers the capture radius): a rule's types, two different bodies
//! where the rule says `between bodies`, closer than the capture radius,
//! both ends under `max_bonds` bound bonds of the rule's type and the pair
//! not bound by one, and the CPU's Philox number for (seed, step, i, j) under
//! 1 − exp(−k_on·Δt) (f32: the CPU's decision differs only where the
//! uniform falls within ~1e-7·p of p, or a distance within f32 rounding of
//! the capture radius). The candidates are compacted in ascending (i, j)
//! order (per-block counts, a one-workgroup scan, per-particle sorted
//! writes) and one invocation accepts them in that order, as the CPU does:
//! a pair that has an unbound bond of the type rebinds it (`rebind`), any
//! other gets a new bond (`form`) whose model index is the next one, as
//! the CPU appends. So the same seed gives the same bonds, indices and
//! events as the CPU.
//!
//! New bonds take a record from a pool preallocated after the kinetic
//! bonds (their law is the bond type's own term) and a slot at each end;
//! the force pass gathers each particle's slots. A step whose candidates
//! might overflow the candidate list, the pool or an end's slots binds
//! nothing on the device: it halts the run after the step
//! (`GpuHalt::Formation`); the host decides that step's formation
//! on the CPU and builds the backend anew, with the formed bonds in the bond
//! rows and an empty pool.
//!
//! Which models: [`refusal`] names the `bind` rules the device does not
//! take (more than four rules; `partner nearest`; pair terms, whose exclusions the formed bonds
//! would change; particles a rule could pair that other bonds already join).
//!
//! # Sections of the `kin` buffer (after those of src/gpu/kinetics.rs)
//! Header words 16–31 as the `KIN_*` constants of bind.wgsl. Per particle
//! its slot base (or none); the slots (`width` per taking particle: a pool
//! record, or none once free); per rule its record (type a, type b, bond
//! type, max_bonds, between bodies, capture, k_on, rest length as f32
//! bits); per particle its body (or none); the candidates (i, j, rule); per
//! particle its candidate count; per block of 256 particles its count, then
//! its base.

use super::prelude::bind::*;
use crate::system::Model;

/// No slot, record or body (the kinetics' `KIN_NONE`).
const NONE: u32 = u32::MAX;

/// Why the model's `bind` rules cannot be decided on the device (None: they can, or it has none).
pub fn refusal(model: &Model) -> Option<String> {
    if model.bind_rules.is_empty() {
        return None;
    }
    if model.bind_rules.len() > BIND_RULES {
        return Some(format!("more than {BIND_RULES} `bind` rules"));
    }
    if model.bind_rules.iter().any(|r| r.nearest) {
        return Some("`bind … partner nearest`".into());
    }
    if !model.pair_rules.is_empty() {
        return Some("`bind` with pair terms (formed bonds would change the pair exclusions)".into());
    }
    let body = model.body_of_particles();
    for (b, &[i, j]) in model.bonds.iter().enumerate() {
        let t = model.bond_type[b];
        let (ti, tj) = (model.types[i as usize], model.types[j as usize]);
        let pairs = model
            .bind_rules
            .iter()
            .any(|r| r.bond_type != t && r.joins_types(ti, tj) && r.joins_bodies(body[i as usize], body[j as usize]));
        if pairs {
            let label = &model.bond_types[t as usize].label.text;
            return Some(format!("`bind` between particles that a bond of type `{label}` already joins"));
        }
    }
    None
}

/// The sizes of the device's formation sections for `model`.
pub(super) struct BindSizes {
    /// Pool records (0 without `bind` rules).
    pub pool: usize,
    /// Slots per taking particle.
    pub width: usize,
    /// Candidates one step may list.
    pub candidates: usize,
}

impl BindSizes {
    pub(super) fn of(model: &Model) -> Self {
        if model.bind_rules.is_empty() {
            return Self { pool: 0, width: 0, candidates: 0 };
        }
        let takers = (0..model.len()).filter(|&i| takes_part(model, i)).count();
        let gain = max_gain(model) as usize;
        // Twice the bonds the takers can hold at once; each end's slots hold
        // twice its gain in a step, so a step defers only after many partners.
        Self { pool: (takers * gain).max(1024), width: 2 * gain + 2, candidates: (2 * model.len()).max(4096) }
    }
}

/// Σ max_bonds over the rules: the most bonds a particle gains in one step.
fn max_gain(model: &Model) -> u32 {
    model.bind_rules.iter().map(|r| r.max_bonds).sum()
}

fn takes_part(model: &Model, i: usize) -> bool {
    let t = model.types[i];
    model.bind_rules.iter().any(|r| r.type_a == t || r.type_b == t)
}

/// Appends the formation sections to `words` and fills header words 16–31
/// (`next_bond`: the model's bond count; `pool_end`: the kinetic records).
pub(super) fn append(model: &Model, sizes: &BindSizes, pool_end: usize, words: &mut Vec<u32>, header: &mut [u32]) {
    if sizes.pool == 0 {
        return;
    }
    let n = model.len();
    header[KIN_SLOT_OF] = words.len() as u32;
    let mut takers = 0u32;
    for i in 0..n {
        words.push(if takes_part(model, i) {
            takers += 1;
            (takers - 1) * sizes.width as u32
        } else {
            NONE
        });
    }
    header[KIN_SLOTS] = words.len() as u32;
    words.resize(words.len() + takers as usize * sizes.width, NONE);
    header[KIN_SLOT_WIDTH] = sizes.width as u32;
    header[KIN_RULES] = words.len() as u32;
    header[KIN_RULE_COUNT] = model.bind_rules.len() as u32;
    for r in &model.bind_rules {
        let t = r.bond_type as usize;
        let rest = model.bond_kinetics[t].rest_index.map_or(f64::NAN, |k| model.bond_types[t].params[k]);
        let record: [u32; KIN_RULE_WORDS] = [
            r.type_a,
            r.type_b,
            r.bond_type,
            r.max_bonds,
            r.between_bodies as u32,
            (r.capture as f32).to_bits(),
            (r.k_on as f32).to_bits(),
            (rest as f32).to_bits(),
        ];
        words.extend(record);
    }
    header[KIN_BODY] = words.len() as u32;
    words.extend(model.body_of_particles());
    header[KIN_POOL_NEXT] = (pool_end - sizes.pool) as u32;
    header[KIN_POOL_END] = pool_end as u32;
    header[KIN_NEXT_BOND] = model.bonds.len() as u32;
    header[KIN_CAND] = words.len() as u32;
    words.resize(words.len() + 3 * sizes.candidates, 0);
    header[KIN_CAND_CAP] = sizes.candidates as u32;
    header[KIN_CAND_N] = words.len() as u32;
    words.resize(words.len() + n, 0);
    header[KIN_CAND_BLOCK] = words.len() as u32;
    words.resize(words.len() + 2 * n.div_ceil(super::context::WORKGROUP as usize), 0);
    header[KIN_MAX_GAIN] = max_gain(model);
}

/// The largest capture radius of the model's `bind` rules (0: none).
pub fn capture(model: &Model) -> f64 {
    model.bind_rules.iter().map(|r| r.capture).fold(0.0, f64::max)
}
