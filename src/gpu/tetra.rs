//! Volume elements (`[ tetrahedra ]`, the `neo_hookean` and
//! `linear_elastic` laws) on the GPU, without float atomics (kernel in
//! shaders/common/tetra.wgsl; evaluators `NAME_tetra` in
//! shaders/interactions/). Each force evaluation runs, after the surface
//! passes and before the `forces` kernel:
//!
//! 1. `tetra_forces`, one invocation per element: F = D_s·D_m⁻¹ (corners
//!    1–3 at their minimum images from corner 0, as on the CPU), J = det F,
//!    F⁻ᵀ from cross products of F's columns, the law's W and P, and the
//!    corner forces −V_0·P·D_m⁻ᵀ into the element's four corner slots
//!    (a quarter of V_0·W with each).
//! 2. The `forces` kernel gathers each particle's corner slots through a
//!    node → (element, corner) CSR built here, in ascending element order,
//!    so the sum is the same bits on every run.
//!
//! The elements' terms are packed after the surface (body) terms; their rest
//! shapes (D_m⁻¹, V_0, computed in f64 on the host) are rounded once to f32.
//! The corner slots are the last region of the `surf` buffer, after the
//! surface regions of [`super::surface`].

use super::pack::push_csr;
use super::prelude::tetra::*;
use crate::system::Model;

/// The volume elements' sections of the GPU buffers.
#[derive(Default)]
pub struct TetraPack {
    /// Per element: its four corners (particles) and its term.
    pub elements: Vec<u32>,
    /// Per element: D_m⁻¹ by columns, then V_0 (TETRA_REST_FLOATS).
    pub rest: Vec<f32>,
    /// CSR by particle (n + 1 offsets) of its corner slots' `surf` indices.
    pub slot_offsets: Vec<u32>,
    pub slots: Vec<u32>,
}

impl TetraPack {
    pub fn elements(&self) -> u32 {
        (self.elements.len() / TETRA_WORDS) as u32
    }

    /// Entries of the `surf` buffer the corner slots take.
    pub fn surf_entries(&self) -> u64 {
        4 * self.elements() as u64
    }
}

/// Packs the model's volume elements: element e of type t is term
/// `term_base + t`, and its corner k's slot is `surf[surf_base + 4e + k]`.
pub fn pack_tetras(model: &Model, term_base: usize, surf_base: u64) -> TetraPack {
    let mut out = TetraPack::default();
    let mut rows: Vec<Vec<u32>> = vec![Vec::new(); model.len()];
    for (e, corners) in model.tetras.iter().enumerate() {
        for (k, &p) in corners.iter().enumerate() {
            rows[p as usize].push((surf_base + 4 * e as u64 + k as u64) as u32);
        }
        out.elements.extend(corners);
        out.elements.push((term_base + model.tetra_type[e] as usize) as u32);
        let rest = &model.tetra_rest[e];
        out.rest.extend(rest.dm_inv.to_cols_array().map(|v| v as f32));
        out.rest.push(rest.volume as f32);
    }
    push_csr(&rows, &mut out.slot_offsets, &mut out.slots);
    out
}
