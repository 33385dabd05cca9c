//! The stiffness matrix K̃ ≈ ∂²E/∂x∂x of the current configuration, as 3×3
//! blocks, for the linearly implicit integrator.
//!
//! K̃ is the Hessian of the potential energy made positive semi-definite term
//! by term (a projected Newton matrix), so that γ/dt·I + K̃ is symmetric
//! positive definite for every dt and conjugate gradients or a Cholesky
//! factorisation always apply:
//!
//! - **Radial terms** (bonds and pairs, d = x_j − x_i, û = d/r): the analytic
//!   block h = max(E″, 0)·ûûᵀ + max(E′/r, 0)·(I − ûûᵀ), added to (i, i) and
//!   (j, j) and subtracted from (i, j) and (j, i). The exact Hessian has E″
//!   and E′/r without the clamps; they drop only the destabilising parts
//!   (a compressed spring's negative transverse stiffness, the concave side
//!   of a potential), which an implicit step must not amplify.
//! - **Angles, volume elements and externals**: the block Hessian of the term alone by central
//!   differences of its own analytic forces, projected onto the positive
//!   semi-definite cone ([`crate::hessian`]: symmetrised, negative
//!   eigenvalues set to 0).
//! - **Surface terms of bodies** ([`crate::hessian::SurfaceHessian`], each
//!   term's `hessian` in its interaction file): local stencils projected like
//!   the angles, and Gauss–Newton rank-one terms w·g gᵀ kept as vectors
//!   ([`RankOneTerm`](super::RankOneTerm); the implicit step applies them matrix-free):
//!   - `surface_tension`: γ·∇²A_t per face (analytic, exact before
//!     projection); `area_conservation`: per face
//!     (k_l/a0)·∇A_t∇A_tᵀ + τ_t·∇²A_t with τ_t = dE/dA_t, and the global
//!     term's (k_a/A0)·∇A∇Aᵀ — together the exact Hessian;
//!   - `turgor` and `turgor_log`: E″(V)·∇V∇Vᵀ (K/V0, resp. K/V). The
//!     pressure part −ΔP·∇²V is left out: V is linear in each node, so ∇²V
//!     has zero diagonal blocks and every local piece of it is traceless
//!     and indefinite — its projection would add stiffness of order |ΔP|·ℓ
//!     that no mode has, while the part itself is O(ℓ/R) of the tension's at a
//!     Young–Laplace balance ΔP = 2γ/R;
//!   - `helfrich_bending`: node i's energy f(u_i, A_i) = 2κu_i²/A_i
//!     (u_i = M_i − C0·A_i/2) is convex in (u, A) with Hessian
//!     (4κ/A)·v vᵀ, v = (1, −u/A); linearising u_i and A_i gives the
//!     generalised Gauss–Newton term (4κ/A_i)·g gᵀ, g = ∇u_i − (u_i/A_i)·∇A_i
//!     on node i's one-ring (analytic, PSD as it stands). Left out:
//!     ∂E/∂M_i·∇²M_i + ∂E/∂A_i·∇²A_i, O(ℓ/R) of what is kept.

//! - **Contact pairs between bodies** (node p, face corners x_k, distance d
//!   to the closest point q = Σ w_k x_k): the Gauss–Newton block
//!   max(b″, 0)·g gᵀ with g = ∂d/∂(p, x_0, x_1, x_2) = (n̂, −w_0 n̂, −w_1 n̂,
//!   −w_2 n̂) (the weights' own derivatives drop out at a closest point).
//!   The dropped part b′·∂²d is negative semi-definite for a repulsive
//!   barrier (b′ < 0): the projection would remove it anyway. The implicit
//!   step also applies the contact step clamp.
//! - **Adhesion** (`contact_adhesion`, E = ε·Σ_t A_t·s_a s_b s_c with
//!   ε = −w): per node k and rule, the Gauss–Newton block of its distance,
//!   max(∂²E/∂d_k², 0)·g_k g_kᵀ, ∂²E/∂d_k² = ε·s″(d_k)·B_k,
//!   B_k = Σ_{t ∋ k} A_t·Π_{c ≠ k} s_c, g_k as for a contact pair at node
//!   k's nearest pair. It is stiff (−w·s″ > 0) on the near half of the
//!   switch zone, where s is concave, and clamped to 0 on the far half.
//!   Left out: the area part ε·P_t·∇²A_t of each face (P_t = s_a s_b s_c),
//!   a negative tension −w·P_t that lowers the stiffness γ·∇²A_t the face's
//!   `surface_tension` blocks carry; alone it is indefinite like ∇²A_t, and
//!   its projection would keep exactly the pieces that are the opposite of
//!   what it does, so a contact face keeps its full tension's stiffness
//!   (γ/(γ − w) of the exact one: stiffer, still ⪰ 0). Also left out: the
//!   cross terms ε·s′_k s′_l·(…)·∇d_k∇d_lᵀ between corners of a face and the
//!   area–distance terms ε·s′_k·(…)·∇A_t∇d_kᵀ (indefinite), and the pull
//!   ε·s′_k·B_k·∇²d_k.
//!
//! Blocks come in term order (bonds, angles, volume elements, pairs by particle and ascending
//! neighbour, contact pairs, adhesion by node and rule, externals, then
//! bodies by body, term and stencil), so the assembled matrix is the same on
//! any thread count.

use glam::{DMat3, DVec3};

use super::bonded::{eval_angle, eval_tetra};
use super::cpu::CpuBackend;
use super::nodal_pressure::nodal_stiffness;
use super::stiffness_blocks::{push_blocks, Stiffness, StiffnessBlock};
use crate::hessian::{finite_difference_hessian, project_psd};
use crate::interactions::{AngleLaw, Radial, RadialLaw, TetraLaw};
use crate::system::{Images, Model, SimBox, State};

/// The projected block of a radial term along `d` (length r).
fn radial_block(radial: &Radial, d: DVec3, r: f64) -> DMat3 {
    if r == 0.0 {
        return DMat3::ZERO;
    }
    let u = d / r;
    let uu = DMat3::from_cols(u * u.x, u * u.y, u * u.z);
    radial.d2e_dr2.max(0.0) * uu + (radial.de_dr / r).max(0.0) * (DMat3::IDENTITY - uu)
}

fn push_pair(blocks: &mut Vec<StiffnessBlock>, i: u32, j: u32, h: DMat3) {
    blocks.push(StiffnessBlock { i, j: i, block: h });
    blocks.push(StiffnessBlock { i: j, j, block: h });
    blocks.push(StiffnessBlock { i, j, block: -h });
    blocks.push(StiffnessBlock { i: j, j: i, block: -h });
}

/// The PSD projection of a term's finite-difference Hessian, as blocks.
fn projected_term_blocks(particles: &[u32], at: &[DVec3], forces: impl Fn(&[DVec3]) -> Vec<DVec3>, blocks: &mut Vec<StiffnessBlock>) {
    push_blocks(particles, &project_psd(&finite_difference_hessian(at, forces)), blocks);
}

impl CpuBackend {
    /// K̃ at `state` (neighbour list, contact candidates and surface positions
    /// as at the last force evaluation).
    pub fn stiffness(&self, model: &Model, state: &State, sim_box: &SimBox) -> Stiffness {
        self.stiffness_except(model, state, sim_box, &[], &[])
    }

    /// K̃ without the bonds and angles marked in `owned_bonds` and
    /// `owned_angles` (those whose stiffness a fibre's banded block carries,
    /// `integrate::fibre`; an empty slice owns none).
    pub fn stiffness_except(
        &self,
        model: &Model,
        state: &State,
        sim_box: &SimBox,
        owned_bonds: &[bool],
        owned_angles: &[bool],
    ) -> Stiffness {
        let x = &state.positions;
        let images: Images = sim_box.images();
        let mut blocks = Vec::new();
        for (b, &[i, j]) in model.bonds.iter().enumerate() {
            if owned_bonds.get(b).copied().unwrap_or(false) {
                continue;
            }
            if let Some(block) = self.bond_block(b, model, state, &images) {
                push_pair(&mut blocks, i, j, block);
            }
        }
        for a in (0..model.angles.len()).filter(|&a| !owned_angles.get(a).copied().unwrap_or(false)) {
            let (at, _) = eval_angle(model, a, x, &images);
            let term = &model.angle_types[model.angle_type[a] as usize];
            let AngleLaw(eval) = term.law;
            projected_term_blocks(&model.angles[a], &at, |p| eval(&term.params, [p[0], p[1], p[2]]).forces.to_vec(), &mut blocks);
        }
        let nodal = &self.bonded().nodal;
        for e in 0..model.tetras.len() {
            let (at, _) = eval_tetra(model, e, x, &images, nodal);
            let term = &model.tetra_types[model.tetra_type[e] as usize];
            let TetraLaw { eval, .. } = term.law;
            let rest = &model.tetra_rest[e];
            // At fixed p̄_e for a nodal-pressure element (its nodal part follows).
            projected_term_blocks(
                &model.tetras[e],
                &at,
                |p| {
                    let p = [p[0], p[1], p[2], p[3]];
                    nodal.complete(model, e, p, eval(&term.params, rest, p)).forces.to_vec()
                },
                &mut blocks,
            );
        }
        nodal_stiffness(model, x, &images, &mut blocks);
        if let Some(list) = self.neighbor_list() {
            for i in 0..model.len() {
                // Every image of each partner (a small periodic box has several); a
                // particle's own images are at a fixed distance: no stiffness.
                list.for_each_separation(i, x, &images, |j, d| {
                    if j as usize == i {
                        return;
                    }
                    let r = d.length();
                    for &rule in model.pair_rules_between(model.types[i], model.types[j as usize]) {
                        let term = &model.pair_rules[rule as usize];
                        let RadialLaw { eval, range, .. } = term.law;
                        if r < range(&term.params) {
                            push_pair(&mut blocks, i as u32, j, radial_block(&eval(&term.params, r), d, r));
                        }
                    }
                });
            }
        }
        self.special_pairs().for_each(model, x, &images, |i, j, d, r, radial, _| push_pair(&mut blocks, i, j, radial_block(&radial, d, r)));
        self.contacts().stiffness(model, &mut blocks);
        for external in &model.externals {
            for &m in &external.members {
                let at = sim_box.unwrap(x[m as usize], state.images[m as usize]);
                projected_term_blocks(&[m], &[at], |p| vec![external.at(p[0], state.time).force], &mut blocks);
            }
        }
        let rank_one = self.surfaces().stiffness(model, &mut blocks);
        Stiffness { blocks, rank_one }
    }
}

impl CpuBackend {
    /// The projected radial block of bond `b` at `state` (`None` for an unbound bond).
    pub fn bond_block(&self, b: usize, model: &Model, state: &State, images: &Images) -> Option<DMat3> {
        let [i, j] = model.bonds[b];
        let d = images.minimum_image(state.positions[j as usize] - state.positions[i as usize]);
        let r = d.length();
        self.bonded().bond_radial(b, model.bond_type[b] as usize, r, model, state.bonds.as_ref()).map(|radial| radial_block(&radial, d, r))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A stretched harmonic bond's block is the exact Hessian (no clamp active).
    #[test]
    fn radial_block_is_the_exact_hessian_for_a_stretched_spring() {
        let (k, r0) = (3.0, 1.0);
        let d = DVec3::new(1.2, 0.5, -0.3);
        let r = d.length();
        let radial = Radial { energy: 0.0, de_dr: k * (r - r0), d2e_dr2: k };
        let h = radial_block(&radial, d, r);
        // Finite differences of the force on j, F_j = −k(r − r0)·d/r.
        let force = |d: DVec3| -k * (d.length() - r0) * d / d.length();
        for axis in 0..3 {
            let mut e = DVec3::ZERO;
            e[axis] = 1e-6;
            let column = -(force(d + e) - force(d - e)) / 2e-6;
            assert!((column - h.col(axis)).length() < 1e-8, "axis {axis}: {column} vs {}", h.col(axis));
        }
    }
}
