//! Average nodal pressure (Bonet and Burton 1998) for the volume elements of
//! a [`Law::NodalTetra`](crate::interactions::Law::NodalTetra) type.
//!
//! Each node a of elements of such a type t gets the rest and current
//! volumes V_a = Σ_{e ∋ a} V_0,e/4 and v_a = Σ_{e ∋ a} v_e/4 (v_e = J_e·V_0,e,
//! elements of type t only) and the dilatation J_a = v_a/V_a. The energy
//! E = Σ_e V_0,e·W(F_e) + Σ_a V_a·U(J_a) has, since ∂v_a/∂x = Σ_{e ∋ a}
//! ∂v_e/∂x/4, the forces of the elements' deviatoric parts plus −p̄_e·∂v_e/∂x
//! per element with p̄_e = Σ_{a ∈ e} U′(J_a)/4, the mean of its corners'
//! pressures ([`pressured_tetra`]). So each force pass first sums the nodal
//! volumes ([`NodalPressure::prepare`], a pass over the elements in element
//! order), then every element is evaluated alone with its p̄_e and its share
//! Σ_{a ∈ e} V_0,e·U(J_a)/4 of the nodal energy (the shares add up to
//! Σ_a V_a·U(J_a)). Each element's forces still sum to zero and exert no
//! torque; the virial is the elements' own.
//!
//! The implicit step's Hessian ([`nodal_stiffness`]) is exact before
//! projection: per element the projected finite-difference Hessian of its
//! forces at fixed p̄_e (the deviatoric part and p̄_e·∇²v_e), plus per node
//! the Gauss–Newton term U″(J_a)/V_a·∇v_a∇v_aᵀ on its one-ring, PSD as it
//! stands (U″ > 0), written as dense blocks.
//!
//! Reference: J. Bonet and A. J. Burton, *A simple average nodal pressure
//! tetrahedral element for incompressible and nearly incompressible dynamic
//! explicit applications*, Commun. Numer. Meth. Eng. 14, 437 (1998).

use glam::{DMat3, DVec3};

use super::stiffness_blocks::StiffnessBlock;
use crate::interactions::{pressured_tetra, FourBody, Volumetric};
use crate::system::{Images, Model};

/// Per element of a nodal-pressure type: p̄_e and its share of the nodal
/// energy, from the last [`NodalPressure::prepare`] (empty without such types).
#[derive(Default)]
pub(super) struct NodalPressure {
    element: Vec<[f64; 2]>,
}

/// The image-consistent corners of element `e` (1–3 at their minimum image around 0).
pub(super) fn tetra_positions(model: &Model, e: usize, x: &[DVec3], images: &Images) -> [DVec3; 4] {
    let corners = model.tetras[e];
    let x0 = x[corners[0] as usize];
    corners.map(|p| x0 + images.minimum_image(x[p as usize] - x0))
}

/// The nodal dilatations: for each element of a nodal-pressure type, the
/// volumetric law's U, U′, U″ at its four corners' J_a, and each corner's V_a.
fn corner_dilatations(model: &Model, x: &[DVec3], images: &Images) -> Vec<Option<[(Volumetric, f64); 4]>> {
    let n = model.len();
    // Per nodal type (in type order) and node: [V_a, v_a].
    let slot: Vec<Option<usize>> = {
        let mut next = 0;
        model
            .tetra_types
            .iter()
            .map(|t| {
                t.law.volumetric.map(|_| {
                    next += 1;
                    next - 1
                })
            })
            .collect()
    };
    let types = slot.iter().flatten().count();
    let mut volumes = vec![[0.0f64; 2]; types * n];
    for e in 0..model.tetras.len() {
        let Some(s) = slot[model.tetra_type[e] as usize] else { continue };
        let rest = &model.tetra_rest[e];
        let j = rest.deformation_gradient(tetra_positions(model, e, x, images)).determinant();
        for &a in &model.tetras[e] {
            let v = &mut volumes[s * n + a as usize];
            v[0] += 0.25 * rest.volume;
            v[1] += 0.25 * j * rest.volume;
        }
    }
    (0..model.tetras.len())
        .map(|e| {
            let t = model.tetra_type[e] as usize;
            let (s, u) = (slot[t]?, model.tetra_types[t].law.volumetric?);
            let params = &model.tetra_types[t].params;
            Some(model.tetras[e].map(|a| {
                let [rest, now] = volumes[s * n + a as usize];
                (u(params, now / rest), rest)
            }))
        })
        .collect()
}

impl NodalPressure {
    /// Sums the nodal volumes at `x` and each element's p̄_e and energy share.
    pub(super) fn prepare(&mut self, model: &Model, x: &[DVec3], images: &Images) {
        self.element.clear();
        if !model.has_nodal_pressure_tetras() {
            return;
        }
        let corners = corner_dilatations(model, x, images);
        self.element.extend(corners.iter().enumerate().map(|(e, c)| match c {
            Some(c) => {
                [c.iter().map(|(u, _)| 0.25 * u.pressure).sum(), c.iter().map(|(u, _)| 0.25 * model.tetra_rest[e].volume * u.energy).sum()]
            }
            None => [0.0; 2],
        }));
    }

    /// Element `e`'s energy and forces at `at` from its deviatoric part
    /// `out`: unchanged for a type without nodal pressure.
    pub(super) fn complete(&self, model: &Model, e: usize, at: [DVec3; 4], out: FourBody) -> FourBody {
        if model.tetra_types[model.tetra_type[e] as usize].law.volumetric.is_none() {
            return out;
        }
        let [pressure, energy] = self.element[e];
        let done = pressured_tetra(&model.tetra_rest[e], at, out, pressure);
        FourBody { energy: done.energy + energy, ..done }
    }
}

/// A node's Gauss–Newton weight U″(J_a)/V_a and the entries (particle,
/// ∂v_a/∂x) of its gradient, one per element corner (merged before use).
type Patch = (f64, Vec<(u32, DVec3)>);

/// The nodal Gauss–Newton blocks U″(J_a)/V_a·∇v_a∇v_aᵀ of every node a of
/// a nodal-pressure type at `x` (module docs), node by node in particle order.
pub(super) fn nodal_stiffness(model: &Model, x: &[DVec3], images: &Images, blocks: &mut Vec<StiffnessBlock>) {
    if !model.has_nodal_pressure_tetras() {
        return;
    }
    let corners = corner_dilatations(model, x, images);
    // Per (node, nodal type): its weight and the gradient ∇v_a, entry by entry.
    let mut patches: std::collections::BTreeMap<(u32, u32), Patch> = Default::default();
    for (e, c) in corners.iter().enumerate() {
        let Some(c) = c else { continue };
        let rest = &model.tetra_rest[e];
        let f = rest.deformation_gradient(tetra_positions(model, e, x, images));
        // ∂v_e/∂x_k = −(the forces of the Piola stress cof F = J·F⁻ᵀ).
        let gradient = rest.forces(f.determinant() * f.inverse().transpose()).map(|g| -0.25 * g);
        for (k, &a) in model.tetras[e].iter().enumerate() {
            let (u, volume) = c[k];
            let patch = patches.entry((a, model.tetra_type[e])).or_insert((u.stiffness / volume, Vec::new()));
            patch.1.extend(model.tetras[e].iter().copied().zip(gradient));
        }
    }
    for (weight, mut entries) in patches.into_values() {
        entries.sort_by_key(|&(p, _)| p);
        let mut merged: Vec<(u32, DVec3)> = Vec::with_capacity(entries.len());
        for (p, g) in entries {
            match merged.last_mut() {
                Some(last) if last.0 == p => last.1 += g,
                _ => merged.push((p, g)),
            }
        }
        for &(i, gi) in &merged {
            for &(j, gj) in &merged {
                blocks.push(StiffnessBlock { i, j, block: weight * DMat3::from_cols(gi * gj.x, gi * gj.y, gi * gj.z) });
            }
        }
    }
}
