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
//! - **Angles and externals**: the block Hessian of the term alone by central
//!   differences of its own analytic forces (step 1e-6 of its size),
//!   symmetrised, then projected onto the positive semi-definite cone
//!   (negative eigenvalues set to 0, faer's self-adjoint eigensolver).
//!
//! - **Surface terms of bodies** (turgor, tension, bending) contribute no
//!   block yet: they enter the implicit step through F only, so their own
//!   explicit stability limit still applies to them.
//! - **Contact pairs between bodies** (node p, face corners x_k, distance d
//!   to the closest point q = Σ w_k x_k): the Gauss–Newton block
//!   max(b″, 0)·g gᵀ with g = ∂d/∂(p, x_0, x_1, x_2) = (n̂, −w_0 n̂, −w_1 n̂,
//!   −w_2 n̂) (the weights' own derivatives drop out at a closest point).
//!   The dropped part b′·∂²d is negative semi-definite for a repulsive
//!   barrier (b′ < 0): the projection would remove it anyway. The implicit
//!   step also applies the contact step clamp.
//!
//! Blocks come in term order (bonds, angles, pairs by particle and ascending
//! neighbour, externals), so the assembled matrix is the same on any thread
//! count.

use faer::{Mat, Side};
use glam::{DMat3, DVec3};

use super::bonded::eval_angle;
use super::cpu::CpuBackend;
use crate::interactions::{Law, Radial};
use crate::system::{Images, Model, SimBox, State};

/// One 3×3 block K̃_ij of the stiffness matrix (particle indices i, j).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StiffnessBlock {
    pub i: u32,
    pub j: u32,
    pub block: DMat3,
}

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

/// The Hessian of a term with `k` particles from its forces by central
/// differences, symmetrised and projected onto the PSD cone; blocks appended
/// for every pair of its particles.
fn projected_term_blocks<const K: usize>(
    particles: [u32; K],
    at: [DVec3; K],
    forces: impl Fn([DVec3; K]) -> [DVec3; K],
    blocks: &mut Vec<StiffnessBlock>,
) {
    let size = at.iter().map(|x| (*x - at[0]).length()).fold(0.0, f64::max).max(at[0].length()).max(1e-3);
    let h = 1e-6 * size;
    let dim = 3 * K;
    let mut hessian = Mat::<f64>::zeros(dim, dim);
    for b in 0..K {
        for axis in 0..3 {
            let mut plus = at;
            let mut minus = at;
            plus[b][axis] += h;
            minus[b][axis] -= h;
            let (fp, fm) = (forces(plus), forces(minus));
            for a in 0..K {
                for row in 0..3 {
                    hessian[(3 * a + row, 3 * b + axis)] = -(fp[a][row] - fm[a][row]) / (2.0 * h);
                }
            }
        }
    }
    let symmetric = Mat::<f64>::from_fn(dim, dim, |r, c| 0.5 * (hessian[(r, c)] + hessian[(c, r)]));
    let Ok(eigen) = symmetric.self_adjoint_eigen(Side::Lower) else { return };
    let (u, s) = (eigen.U(), eigen.S().column_vector());
    let projected = Mat::<f64>::from_fn(dim, dim, |r, c| (0..dim).map(|e| s[e].max(0.0) * u[(r, e)] * u[(c, e)]).sum());
    for a in 0..K {
        for b in 0..K {
            let column = |col: usize| DVec3::from_array([0, 1, 2].map(|row| projected[(3 * a + row, 3 * b + col)]));
            let block = DMat3::from_cols(column(0), column(1), column(2));
            blocks.push(StiffnessBlock { i: particles[a], j: particles[b], block });
        }
    }
}

impl CpuBackend {
    /// The blocks of K̃ at `state` (neighbour list as last built).
    pub fn stiffness(&self, model: &Model, state: &State, sim_box: &SimBox) -> Vec<StiffnessBlock> {
        let x = &state.positions;
        let images: Images = sim_box.images();
        let bond_state = state.bonds.as_ref();
        let mut blocks = Vec::new();
        for (b, &[i, j]) in model.bonds.iter().enumerate() {
            let d = images.minimum_image(x[j as usize] - x[i as usize]);
            let r = d.length();
            if let Some(radial) = self.bonded().bond_radial(b, model.bond_type[b] as usize, r, model, bond_state) {
                push_pair(&mut blocks, i, j, radial_block(&radial, d, r));
            }
        }
        for a in 0..model.angles.len() {
            let (at, _) = eval_angle(model, a, x, &images);
            let term = &model.angle_types[model.angle_type[a] as usize];
            let Law::ThreeBody(eval) = term.interaction.law() else { unreachable!("angle law is three-body") };
            projected_term_blocks(model.angles[a], at, |p| eval(&term.params, p).forces, &mut blocks);
        }
        if let Some(list) = self.neighbor_list() {
            for i in 0..model.len() {
                for &j in list.neighbors(i) {
                    let d = images.minimum_image(x[j as usize] - x[i]);
                    let r = d.length();
                    for &rule in model.pair_rules_between(model.types[i], model.types[j as usize]) {
                        let term = &model.pair_rules[rule as usize];
                        let Law::Radial { eval, range, .. } = term.interaction.law() else { unreachable!("pair law is radial") };
                        if r < range(&term.params) {
                            push_pair(&mut blocks, i as u32, j, radial_block(&eval(&term.params, r), d, r));
                        }
                    }
                }
            }
        }
        self.contacts().stiffness(model, &mut blocks);
        for external in &model.externals {
            let Law::OneBody(eval) = external.term.interaction.law() else { unreachable!("external law is one-body") };
            for &m in &external.members {
                let at = sim_box.unwrap(x[m as usize], state.images[m as usize]);
                projected_term_blocks([m], [at], |p| [eval(&external.term.params, p[0]).force], &mut blocks);
            }
        }
        blocks
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

    /// Projection keeps a PSD Hessian and removes negative curvature.
    #[test]
    fn projected_blocks_are_positive_semidefinite() {
        // A compressed spring between two particles: exact Hessian indefinite.
        let (k, r0) = (2.0, 2.0);
        let forces = |p: [DVec3; 2]| {
            let d = p[1] - p[0];
            let f = k * (d.length() - r0) * d / d.length();
            [f, -f]
        };
        let mut blocks = Vec::new();
        projected_term_blocks([0, 1], [DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0)], forces, &mut blocks);
        // v = transverse relative motion: exact vᵀHv = 2·k(r − r0)/r < 0; projected ≥ 0.
        let v = [DVec3::new(0.0, 1.0, 0.0), DVec3::new(0.0, -1.0, 0.0)];
        let quadratic: f64 = blocks.iter().map(|b| v[b.i as usize].dot(b.block * v[b.j as usize])).sum();
        assert!(quadratic.abs() < 1e-6, "transverse curvature {quadratic} should be projected to 0");
        let axial = [DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0)];
        let stiff: f64 = blocks.iter().map(|b| axial[b.i as usize].dot(b.block * axial[b.j as usize])).sum();
        assert!((stiff - 4.0 * k).abs() < 1e-5, "axial curvature {stiff}, expected 4k");
    }
}
