//! The model flattened into the GPU's buffers (layout: shaders/common/layout.wgsl).
//!
//! - `topo` (u32): particle types, then sections for each term's registry
//!   index (a custom term's: past the registry, [`super::custom::gpu_kinds`]), the pair rules per type pair (CSR), each particle's bond ends
//!   `(other, term)`, its angle slots `(i, j, k, term, role)`, its external
//!   terms, and its excluded partners (all CSR by particle, in the same order
//!   as the CPU backend).
//! - `fparams` (f32): eight parameter slots per term, the squared reach of
//!   each type pair, and per particle type the mobility dt/γ and the noise
//!   amplitude √(2kT·dt/γ) (computed in f64; both 0 for a `fixed` type).
//! - `topo` also holds the surface sections of [`super::surface::SurfacePack`]
//!   (faces, bodies' faces and terms, each particle's slots, edges and body
//!   nodes), at `surface_offsets`.
//!
//! - `topo` also holds each particle's partners of fractional
//!   `special_bonds` weight (`special.rs`), at `special_offsets`.
//! - `topo` and `fparams` also hold the volume elements' sections of
//!   [`super::tetra::TetraPack`] (elements, each particle's corner slots;
//!   rest shapes), at `tetra_offsets`.
//!
//! Terms are numbered bond types, then angle types, then pair rules, then
//! externals, then surface (body) terms, then volume-element (`tetra`) types, then — with bond state — one term per bound bond of a type
//! with kinetic rules or with a rest length of its own (the topology's
//! per-bond r0), holding that bond's own rest length. Each term also has
//! a force scale (`fparams`, at `topo_offsets[11]`): a kinetic bond's
//! maturation scale, 1 for every other term. Unbound bonds are left out of the
//! bond ends, and `exclusions` must be those of the bound bonds. Bond kinetics
//! are decided on the host; [`pack`] is rerun after every step that changes
//! bond state and the result uploaded as one batch.

use bytemuck::{Pod, Zeroable};

use crate::forcefield::Typed;
use crate::neighbor::Exclusions;
use crate::system::BondState;
use crate::system::{Model, SimBox};

pub use super::prelude::pack::PARAM_SLOTS;

/// The uniform block (must match `Params` in layout.wgsl, which names the
/// words of each group below one by one, in the same order: the
/// `params_match_the_wgsl_layout` test checks the sizes and offsets).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct Params {
    pub frame: BoxFrame,
    pub sizes: Sizes,
    pub step: StepWords,
    /// Offsets of the `topo` sections, in layout.wgsl's order (the last: of
    /// the term scales in `fparams`).
    pub topo_offsets: [u32; 12],
    /// Offsets of the `fparams` sections: params, skip2, mobility, amplitude.
    pub fparam_offsets: [u32; 4],
    /// Offsets of the surface sections of `topo`
    /// ([`super::surface::SurfacePack::sections`]), then the numbers of
    /// faces, bodies, edges and body nodes.
    pub surface_offsets: [u32; 16],
    /// Node–face contact: layout.wgsl's `off_cfaces` … (src/gpu/contact.rs).
    pub contact: [u32; 16],
    pub kinetics: KineticsWords,
    /// Volume elements (tetra.wgsl): `topo` elements, `fparams` rest shapes,
    /// `topo` slot CSR (offsets, slots), first `surf` slot, count, 2 × padding.
    pub tetra_offsets: [u32; 8],
    /// Simulated time at the call's first step (f32 high part, remainder), dt, padding.
    pub clock: [f32; 4],
    /// Fractional `special_bonds` partners (special.wgsl): `topo` offsets, entries, 2 × padding.
    pub special_offsets: [u32; 4],
    /// Area-weighted contact (adhesion.wgsl): layout.wgsl's `off_arule_start` … (src/gpu/adhesion.rs).
    pub adhesion: [u32; 8],
    /// Protocols (protocol.wgsl): held words present, ramped slots, the ramp table's first step, `protocol` offsets, 2 × padding.
    pub protocol: [u32; 8],
}

/// The box and the cell grid of [`Params`]: edge lengths and lower corner
/// in the 64-bit fixed point ([`FixedPoint`]: integer and fraction words),
/// periodic axes, cells along x, y, z (w: in all), cells per unit length,
/// and the edge lengths in f32 (w: the fixed-point unit q).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct BoxFrame {
    pub box_len_h: [u32; 4],
    pub box_len_f: [u32; 4],
    pub box_lo_h: [u32; 4],
    pub box_lo_f: [u32; 4],
    pub periodic: [u32; 4],
    pub grid: [u32; 4],
    pub cell_inv_width: [f32; 4],
    pub box_len: [f32; 4],
}

/// The sizes of [`Params`]: particles, neighbour-list capacity per particle,
/// particle types, and the steps this call takes.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct Sizes {
    pub n: u32,
    pub nlist_cap: u32,
    pub n_types: u32,
    pub steps_wanted: u32,
}

/// The step's words of [`Params`]: (cutoff + skin)², (skin/2)², max
/// displacement², the neighbour list's `every`, the seed and the first
/// step (low and high words), the list's `check`, scan blocks over cells,
/// the dispatch width (workgroups along x) and 1 for `noise gaussian`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct StepWords {
    pub range2: f32,
    pub half_skin2: f32,
    pub max_disp2: f32,
    pub neighbor_every: u32,
    pub seed_lo: u32,
    pub seed_hi: u32,
    pub step_lo: u32,
    pub step_hi: u32,
    pub neighbor_check: u32,
    pub scan_blocks: u32,
    pub groups_x: u32,
    pub gaussian: u32,
}

/// Bond kinetics on the device of [`Params`] (src/gpu/kinetics.rs): its
/// bonds, their first term, the event capacity and the bond types.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct KineticsWords {
    pub kin_bonds: u32,
    pub kin_first_term: u32,
    pub kin_capacity: u32,
    pub kin_types: u32,
}

/// The GPU's 64-bit fixed point (layout.wgsl): a length x is the integer
/// X = round(x/q·2³²), stored as its high i32 and low u32 words, with q a
/// power of two such that the longest box edge is at most 2²⁰·q.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FixedPoint {
    pub q: f64,
}

impl FixedPoint {
    pub fn for_box(sim_box: &SimBox) -> Self {
        let longest = sim_box.lengths().max_element().max(f64::MIN_POSITIVE);
        Self { q: 2f64.powi(longest.log2().ceil() as i32 - 20) }
    }

    /// (high word, low word) of x.
    pub fn encode(&self, x: f64) -> (u32, u32) {
        let scaled = (x / self.q * 4_294_967_296.0).round() as i64;
        ((scaled >> 32) as i32 as u32, scaled as u32)
    }

    pub fn decode(&self, high: u32, low: u32) -> f64 {
        let whole = ((high as i32 as i64) << 32) | low as i64;
        whole as f64 / 4_294_967_296.0 * self.q
    }
}

/// The static buffers and the parts of [`Params`] they determine.
pub struct Packed {
    pub topo: Vec<u32>,
    pub fparams: Vec<f32>,
    pub topo_offsets: [u32; 12],
    pub fparam_offsets: [u32; 4],
    pub surface_offsets: [u32; 16],
    pub tetra_offsets: [u32; 8],
    pub special_offsets: [u32; 4],
    /// Entries of the `surf` buffer.
    pub surf_entries: u64,
    /// The user id of each packed body (in packing order).
    pub body_ids: Vec<u64>,
    /// The bond of each bond term of its own (after the shared terms, from `first_own_term`).
    pub own_bonds: Vec<u32>,
    pub first_own_term: u32,
}

/// Appends a CSR section (`offsets` for n + 1 entries, then rows flattened).
pub(super) fn push_csr<T: Copy>(rows: &[Vec<T>], offsets: &mut Vec<u32>, flat: &mut Vec<T>) {
    offsets.push(flat.len() as u32);
    for row in rows {
        flat.extend_from_slice(row);
        offsets.push(flat.len() as u32);
    }
}

/// Packs the model for `dt` and `kt` (mobilities and noise amplitudes depend
/// on them) and the bond state `bonds`, if bonds have state
/// ([`Model::has_bond_state`]).
pub fn pack(model: &Model, exclusions: &Exclusions, dt: f64, kt: f64, bonds: Option<&BondState>) -> Result<Packed, String> {
    let n = model.len();
    let nt = model.type_names.len();
    let terms: Vec<_> = model
        .bond_types
        .iter()
        .map(Typed::term)
        .chain(model.angle_types.iter().map(Typed::term))
        .chain(model.pair_rules.iter().map(Typed::term))
        .chain(model.externals.iter().map(|e| e.term.term()))
        .chain(model.body_rules.iter().map(Typed::term))
        .chain(model.tetra_types.iter().map(Typed::term))
        .collect();
    let angle_base = model.bond_types.len();
    let pair_base = angle_base + model.angle_types.len();
    let external_base = pair_base + model.pair_rules.len();
    let body_base = external_base + model.externals.len();
    let tetra_base = body_base + model.body_rules.len();
    // Bonds with their own parameters (bound, and of a type with kinetic
    // rules, or that `bind` forms — the device's formation counts them,
    // src/gpu/bind.rs — or with a rest length of their own): (bond, own term).
    let has_state = |b: usize| {
        let t = model.bond_type[b];
        !model.bond_kinetics[t as usize].rules.is_empty() || model.bind_rules.iter().any(|r| r.bond_type == t)
    };
    let kinetic: Vec<usize> = match bonds {
        Some(state) => (0..model.bonds.len()).filter(|&b| state.bound[b] && (state.rest[b].is_some() || has_state(b))).collect(),
        None => Vec::new(),
    };
    let mut own_term = vec![u32::MAX; model.bonds.len()];
    for (k, &b) in kinetic.iter().enumerate() {
        own_term[b] = (terms.len() + k) as u32;
    }

    let mut fparams = Vec::with_capacity((terms.len() + kinetic.len()) * PARAM_SLOTS);
    let mut push_params = |label: &str, params: &[f64]| {
        if params.len() > PARAM_SLOTS {
            return Err(format!("`{label}` has {} parameters; the GPU backend holds {PARAM_SLOTS}", params.len()));
        }
        let start = fparams.len();
        fparams.extend(params.iter().map(|&p| p as f32));
        fparams.resize(start + PARAM_SLOTS, 0.0);
        Ok(())
    };
    for term in &terms {
        push_params(&term.label.text, super::custom::gpu_params(term))?;
    }
    let mut scales = vec![1.0f32; terms.len()];
    if let Some(state) = bonds {
        for &b in &kinetic {
            let t = model.bond_type[b] as usize;
            let mut params = super::custom::gpu_params(&model.bond_types[t]).to_vec();
            if let Some(k) = model.bond_kinetics[t].rest_index {
                params[k] = model.rest_length(b, Some(state));
            }
            push_params(&model.bond_types[t].label.text, &params)?;
            scales.push(state.scale[b] as f32);
        }
    }
    let scale_offset = fparams.len();
    fparams.extend(&scales);
    let skip2_offset = fparams.len();
    for a in 0..nt as u32 {
        for b in 0..nt as u32 {
            let reach = model.pair_rules_between(a, b).iter().map(|&r| pair_range(model, r as usize)).fold(0.0f64, f64::max);
            // Slightly above reach² so that f32 rounding of r² never drops a pair the CPU keeps.
            fparams.push((reach * reach * (1.0 + 1e-6)) as f32);
        }
    }
    let mobility_offset = fparams.len();
    let finite = |g: f64| g.is_finite();
    fparams.extend(model.type_drag.iter().map(|&g| if finite(g) { (dt / g) as f32 } else { 0.0 }));
    let amplitude_offset = fparams.len();
    fparams.extend(model.type_drag.iter().map(|&g| if finite(g) && kt > 0.0 { (2.0 * kt * dt / g).sqrt() as f32 } else { 0.0 }));

    let mut topo: Vec<u32> = model.types.clone();
    let mut offsets = [0u32; 12];
    offsets[0] = topo.len() as u32;
    let mut kinds = super::custom::gpu_kinds(model);
    kinds.extend(model.body_rules.iter().map(|t| crate::system::registry_index(t) as u32));
    kinds.extend(model.tetra_types.iter().map(|t| crate::system::registry_index(t) as u32));
    topo.extend(&kinds);
    topo.extend(kinetic.iter().map(|&b| kinds[model.bond_type[b] as usize]));
    // Pair rules per type pair.
    offsets[1] = topo.len() as u32;
    let pair_rows: Vec<Vec<u32>> =
        (0..nt * nt).map(|ab| model.pair_table[ab].iter().map(|&r| (pair_base + r as usize) as u32).collect()).collect();
    let (mut starts, mut rules) = (Vec::new(), Vec::new());
    push_csr(&pair_rows, &mut starts, &mut rules);
    topo.extend(&starts);
    offsets[2] = topo.len() as u32;
    topo.extend(&rules);
    // Bond ends, angle slots and externals by particle, in term order.
    let mut bond_rows = vec![Vec::new(); n];
    for (b, &[i, j]) in model.bonds.iter().enumerate() {
        if bonds.is_some_and(|state| !state.bound[b]) {
            continue;
        }
        let term = if own_term[b] != u32::MAX { own_term[b] } else { model.bond_type[b] };
        bond_rows[i as usize].push([j, term]);
        bond_rows[j as usize].push([i, term]);
    }
    let mut angle_rows = vec![Vec::new(); n];
    for (a, &[i, j, k]) in model.angles.iter().enumerate() {
        let term = (angle_base + model.angle_type[a] as usize) as u32;
        for (role, p) in [i, j, k].into_iter().enumerate() {
            angle_rows[p as usize].push([i, j, k, term, role as u32]);
        }
    }
    let mut external_rows = vec![Vec::new(); n];
    for (e, external) in model.externals.iter().enumerate() {
        for &m in &external.members {
            external_rows[m as usize].push((external_base + e) as u32);
        }
    }
    let exclusion_rows: Vec<Vec<u32>> = (0..n as u32).map(|i| exclusions.partners(i).to_vec()).collect();
    let flatten = |rows: Vec<Vec<[u32; 2]>>| rows.into_iter().map(|r| r.concat()).collect::<Vec<Vec<u32>>>();
    let angle_flat: Vec<Vec<u32>> = angle_rows.into_iter().map(|r| r.concat()).collect();
    for (slot, rows, width) in [(3, flatten(bond_rows), 2), (5, angle_flat, 5), (7, external_rows, 1), (9, exclusion_rows, 1)] {
        let (mut row_offsets, mut flat) = (Vec::new(), Vec::new());
        push_csr(&rows, &mut row_offsets, &mut flat);
        // Offsets count entries of `width` words.
        row_offsets.iter_mut().for_each(|o| *o /= width);
        offsets[slot] = topo.len() as u32;
        topo.extend(&row_offsets);
        offsets[slot + 1] = topo.len() as u32;
        topo.extend(&flat);
    }
    offsets[11] = scale_offset as u32;
    let surfaces = super::surface::pack_surfaces(model, body_base);
    let mut surface_offsets = [0u32; 16];
    for (k, section) in surfaces.sections().into_iter().enumerate() {
        surface_offsets[k] = topo.len() as u32;
        topo.extend(section);
    }
    surface_offsets[12..].copy_from_slice(&surfaces.counts());
    let tetras = super::tetra::pack_tetras(model, tetra_base, surfaces.surf_entries());
    let mut tetra_offsets = [0u32; 8];
    tetra_offsets[0] = topo.len() as u32;
    topo.extend(&tetras.elements);
    tetra_offsets[1] = fparams.len() as u32;
    fparams.extend(&tetras.rest);
    tetra_offsets[2] = topo.len() as u32;
    topo.extend(&tetras.slot_offsets);
    tetra_offsets[3] = topo.len() as u32;
    topo.extend(&tetras.slots);
    tetra_offsets[4] = surfaces.surf_entries() as u32;
    tetra_offsets[5] = tetras.elements();
    let (special_rows, special) = super::special::pack_special(model, bonds.map(|b| b.bound.as_slice()));
    let special_offsets = [topo.len() as u32, (topo.len() + special_rows.len()) as u32, 0, 0];
    topo.extend(&special_rows);
    topo.extend(&special);
    if topo.len() > u32::MAX as usize / 2 {
        return Err(format!("the model needs {} words of GPU topology, more than the u32 index range", topo.len()));
    }
    Ok(Packed {
        topo,
        fparams,
        topo_offsets: offsets,
        fparam_offsets: [0, skip2_offset as u32, mobility_offset as u32, amplitude_offset as u32],
        surface_offsets,
        tetra_offsets,
        special_offsets,
        surf_entries: surfaces.surf_entries() + tetras.surf_entries(),
        body_ids: surfaces.body_ids,
        own_bonds: kinetic.iter().map(|&b| b as u32).collect(),
        first_own_term: terms.len() as u32,
    })
}

fn pair_range(model: &Model, rule: usize) -> f64 {
    let term = &model.pair_rules[rule];
    (term.law.range)(&term.params)
}

/// The cell grid for a neighbour range: cells at least `range` wide, at most
/// about 8 per particle (halving the finest axis until it fits).
pub fn cell_grid(sim_box: &SimBox, range: f64, n: usize) -> ([u32; 3], [f32; 3]) {
    let lengths = sim_box.lengths();
    let mut counts = [1u32; 3];
    if range > 0.0 {
        for a in 0..3 {
            // A hair wider than `range`, so f32 rounding of 1/width never makes a cell narrower.
            counts[a] = ((lengths[a] / (range * (1.0 + 1e-6))).floor() as u64).clamp(1, 1 << 20) as u32;
        }
    }
    let limit = (8 * n as u64).max(64);
    while counts.iter().map(|&c| c as u64).product::<u64>() > limit {
        let a = (0..3).max_by_key(|&a| counts[a]).expect("three axes");
        counts[a] = (counts[a] / 2).max(1);
    }
    let inv = [0, 1, 2].map(|a| if lengths[a] > 0.0 { (counts[a] as f64 / lengths[a]) as f32 } else { 0.0 });
    (counts, inv)
}

#[cfg(test)]
mod tests {
    use std::mem::{offset_of, size_of};

    use super::*;

    /// `Params` here and in layout.wgsl are the same bytes: the same size,
    /// and each word of the Rust groups at the offset of the WGSL member of
    /// its name (an array at the offset of the WGSL member that starts it).
    #[test]
    fn params_match_the_wgsl_layout() {
        let module = naga::front::wgsl::parse_str(&super::super::shader::compose()).expect("the composed program parses");
        let params = module.types.iter().find(|(_, t)| t.name.as_deref() == Some("Params")).expect("layout.wgsl declares Params");
        let naga::TypeInner::Struct { members, span } = &params.1.inner else { panic!("Params is a struct") };
        assert_eq!(*span as usize, size_of::<Params>(), "the sizes of Params in layout.wgsl and in Rust");
        let (frame, sizes, step, kinetics) =
            (offset_of!(Params, frame), offset_of!(Params, sizes), offset_of!(Params, step), offset_of!(Params, kinetics));
        let words = [
            ("box_len_h", frame + offset_of!(BoxFrame, box_len_h)),
            ("box_len_f", frame + offset_of!(BoxFrame, box_len_f)),
            ("box_lo_h", frame + offset_of!(BoxFrame, box_lo_h)),
            ("box_lo_f", frame + offset_of!(BoxFrame, box_lo_f)),
            ("periodic", frame + offset_of!(BoxFrame, periodic)),
            ("grid", frame + offset_of!(BoxFrame, grid)),
            ("cell_inv_width", frame + offset_of!(BoxFrame, cell_inv_width)),
            ("box_len", frame + offset_of!(BoxFrame, box_len)),
            ("n", sizes + offset_of!(Sizes, n)),
            ("nlist_cap", sizes + offset_of!(Sizes, nlist_cap)),
            ("n_types", sizes + offset_of!(Sizes, n_types)),
            ("steps_wanted", sizes + offset_of!(Sizes, steps_wanted)),
            ("range2", step + offset_of!(StepWords, range2)),
            ("half_skin2", step + offset_of!(StepWords, half_skin2)),
            ("max_disp2", step + offset_of!(StepWords, max_disp2)),
            ("neighbor_every", step + offset_of!(StepWords, neighbor_every)),
            ("seed_lo", step + offset_of!(StepWords, seed_lo)),
            ("seed_hi", step + offset_of!(StepWords, seed_hi)),
            ("step_lo", step + offset_of!(StepWords, step_lo)),
            ("step_hi", step + offset_of!(StepWords, step_hi)),
            ("neighbor_check", step + offset_of!(StepWords, neighbor_check)),
            ("scan_blocks", step + offset_of!(StepWords, scan_blocks)),
            ("groups_x", step + offset_of!(StepWords, groups_x)),
            ("gaussian", step + offset_of!(StepWords, gaussian)),
            ("off_term_kind", offset_of!(Params, topo_offsets)),
            ("off_params", offset_of!(Params, fparam_offsets)),
            ("off_faces", offset_of!(Params, surface_offsets)),
            ("off_cfaces", offset_of!(Params, contact)),
            ("kin_bonds", kinetics + offset_of!(KineticsWords, kin_bonds)),
            ("kin_first_term", kinetics + offset_of!(KineticsWords, kin_first_term)),
            ("kin_capacity", kinetics + offset_of!(KineticsWords, kin_capacity)),
            ("kin_types", kinetics + offset_of!(KineticsWords, kin_types)),
            ("off_tetras", offset_of!(Params, tetra_offsets)),
            ("time_hi", offset_of!(Params, clock)),
            ("off_special_offsets", offset_of!(Params, special_offsets)),
            ("off_arule_start", offset_of!(Params, adhesion)),
            ("protocol_held", offset_of!(Params, protocol)),
        ];
        for (name, offset) in words {
            let member = members.iter().find(|m| m.name.as_deref() == Some(name)).unwrap_or_else(|| panic!("layout.wgsl has no `{name}`"));
            assert_eq!(member.offset as usize, offset, "the offset of `{name}` in layout.wgsl and in Rust");
        }
    }
}
