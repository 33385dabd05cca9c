//! The stiffness matrix K̃ of the implicit step as data: 3×3 blocks and
//! Gauss–Newton rank-one terms. The contact, adhesion and surface terms
//! write their blocks here; `stiffness.rs` assembles them all from the CPU
//! backend's last force evaluation.

use faer::Mat;
use glam::{DMat3, DVec3};

use crate::hessian::block;

/// A Gauss–Newton term w·g gᵀ of K̃ (w ≥ 0): `g[k]` on particle `particles[k]`.
#[derive(Clone, Debug, PartialEq)]
pub struct RankOneTerm {
    pub weight: f64,
    pub particles: Vec<u32>,
    pub gradient: Vec<DVec3>,
}

/// K̃ = Σ blocks + Σ rank-one terms.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stiffness {
    pub blocks: Vec<StiffnessBlock>,
    pub rank_one: Vec<RankOneTerm>,
}

/// One 3×3 block K̃_ij of the stiffness matrix (particle indices i, j).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StiffnessBlock {
    pub i: u32,
    pub j: u32,
    pub block: DMat3,
}

/// Appends the blocks of the 3k×3k matrix `h` over `particles`.
pub(super) fn push_blocks(particles: &[u32], h: &Mat<f64>, blocks: &mut Vec<StiffnessBlock>) {
    for (a, &i) in particles.iter().enumerate() {
        for (b, &j) in particles.iter().enumerate() {
            blocks.push(StiffnessBlock { i, j, block: block(h, a, b) });
        }
    }
}
