//! The matrix A = γ/dt·I + θ·K̃ of the linearly implicit step: diagonal,
//! sparse and low rank.
//!
//! K̃ ([`Stiffness`]) is a list of 3×3 blocks and of Gauss–Newton rank-one
//! terms w·g gᵀ: a body's volume (turgor) or total area (global area
//! elasticity) couples all of its nodes, and as a dense block a 642-node
//! cell would add 4·10⁵ blocks per term. So A = S + U·Uᵀ with S = D + C,
//! D the drag diagonal, C sparse (the blocks; none for a system of free
//! fibres, whose blocks live in the fibre solver) and U one column √w·g
//! per rank-one term. With blocks, S is one sparse matrix (D merged into
//! C's diagonal blocks, so each product row adds in one fixed order: the
//! settled angle of the adhesive doublet at 10× the explicit step moved by
//! 1.4° when D·v was added apart, tests/suite/doublet.rs); without, D alone:
//!
//! - **Products** A·v = D·v + C·v + Σ_k w_k·g_k (g_k·v) (conjugate gradients
//!   and the projected CG of constrained bonds), and the Jacobi diagonal
//!   S_ii + Σ_k w_k·g_k,i².
//! - **Direct solve** by the Sherman–Morrison–Woodbury identity with the
//!   sparse Cholesky factor of S: A⁻¹b = y − Z(I + UᵀZ)⁻¹Uᵀy, y = S⁻¹b,
//!   Z = S⁻¹U (one extra right-hand side per rank-one term, then an m×m
//!   dense solve).
//!
//! A `fixed` particle (infinite drag) has the identity row and no couplings,
//! in the blocks and in the rank-one vectors alike; so has each held
//! coordinate (`freeze`, `move`: `held`, per degree of freedom), alone.

use faer::dyn_stack::{MemStack, StackReq};
use faer::linalg::solvers::Solve;
use faer::matrix_free::LinOp;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Col, Mat, MatMut, MatRef, Par, Side};
use glam::{DMat3, DVec3};

use crate::backend::Stiffness;

/// A = D + C + Σ_k w_k·g_k g_kᵀ over 3n degrees of freedom: D the diagonal
/// γ/dt (1 on pinned coordinates), C the sparse couplings θ·K̃ (none when
/// K̃ has no blocks: a system of free fibres and loose particles).
#[derive(Debug)]
pub struct SystemMatrix {
    /// D.
    drag: Vec<f64>,
    /// S = D + C when K̃ has blocks (`None`: S = D).
    sparse: Option<SparseColMat<usize, f64>>,
    /// Per rank-one term: w and the entries (particle, g) on mobile particles.
    rank_one: Vec<(f64, Vec<(usize, DVec3)>)>,
}

impl SystemMatrix {
    /// Assembles γ_i/dt·I + θ·K̃ (`drag[i]` infinite for a fixed particle;
    /// `held[3i + a]` true for a held coordinate, or `held` empty).
    pub fn new(drag: &[f64], held: &[bool], dt: f64, theta: f64, stiffness: &Stiffness) -> Result<Self, String> {
        let n = drag.len();
        let dim = 3 * n;
        let fixed = |i: usize| drag[i].is_infinite();
        let pinned = |k: usize| fixed(k / 3) || held.get(k).copied().unwrap_or(false);
        let diagonal: Vec<f64> = (0..dim).map(|k| if pinned(k) { 1.0 } else { drag[k / 3] / dt }).collect();
        let couplings = stiffness
            .blocks
            .iter()
            .filter(|b| !fixed(b.i as usize) && !fixed(b.j as usize))
            .map(|b| (b.i as usize, b.j as usize, theta * b.block));
        // With couplings, S = D + C as one sparse matrix: the drag blocks,
        // then the blocks between mobile particles, merged per (i, j) in
        // column order (a stable sort: duplicates add in term order, the drag
        // first) so the triplets arrive sorted, 9 per distinct block.
        let mut blocks: Vec<(usize, usize, DMat3)> = couplings.collect();
        let sparse = if blocks.is_empty() {
            None
        } else {
            let drag_blocks = (0..n).map(|i| (i, i, DMat3::from_diagonal(DVec3::from_array(std::array::from_fn(|a| diagonal[3 * i + a])))));
            blocks.splice(0..0, drag_blocks);
            blocks.sort_by_key(|&(i, j, _)| (j, i));
            let mut triplets = Vec::with_capacity(9 * blocks.len());
            let mut k = 0;
            while k < blocks.len() {
                let (i, j, mut block) = blocks[k];
                k += 1;
                while k < blocks.len() && (blocks[k].0, blocks[k].1) == (i, j) {
                    block += blocks[k].2;
                    k += 1;
                }
                for col in 0..3 {
                    for row in 0..3 {
                        let (r, c) = (3 * i + row, 3 * j + col);
                        if !pinned(r) && !pinned(c) {
                            triplets.push(Triplet::new(r, c, block.col(col)[row]));
                        } else if r == c {
                            triplets.push(Triplet::new(r, c, 1.0));
                        }
                    }
                }
            }
            Some(SparseColMat::<usize, f64>::try_new_from_triplets(dim, dim, &triplets).map_err(|e| format!("{e:?}"))?)
        };
        let rank_one = stiffness
            .rank_one
            .iter()
            .map(|r| {
                let entries = r.particles.iter().zip(&r.gradient).filter(|(&p, _)| !fixed(p as usize)).map(|(&p, &g)| {
                    let p = p as usize;
                    (p, DVec3::from_array(std::array::from_fn(|a| if pinned(3 * p + a) { 0.0 } else { g[a] })))
                });
                (theta * r.weight, entries.collect())
            })
            .collect();
        Ok(Self { drag: diagonal, sparse, rank_one })
    }

    pub fn dim(&self) -> usize {
        self.drag.len()
    }

    /// The diagonal entries A_kk.
    pub fn diagonal(&self) -> Col<f64> {
        let mut d = Col::from_fn(self.dim(), |k| self.sparse.as_ref().map_or(self.drag[k], |s| s.get(k, k).copied().unwrap_or(0.0)));
        for (w, entries) in &self.rank_one {
            for &(p, g) in entries {
                for a in 0..3 {
                    d[3 * p + a] += w * g[a] * g[a];
                }
            }
        }
        d
    }

    /// A·v.
    pub fn times(&self, v: &Col<f64>) -> Col<f64> {
        let mut out = Col::zeros(self.dim());
        self.apply_to(out.as_mat_mut(), v.as_mat());
        out
    }

    /// out = A·v on slices of length 3n.
    pub fn times_slice(&self, v: &[f64], out: &mut [f64]) {
        let rhs = faer::ColRef::from_slice(v);
        let mut dst = faer::ColMut::from_slice_mut(out);
        self.apply_to(dst.as_mut().as_mat_mut(), rhs.as_mat());
    }

    /// out = A·rhs, column by column.
    fn apply_to(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>) {
        match &self.sparse {
            Some(s) => {
                faer::sparse::linalg::matmul::sparse_dense_matmul(out.as_mut(), faer::Accum::Replace, s.as_ref(), rhs, 1.0, Par::Seq)
            }
            None => {
                for column in 0..rhs.ncols() {
                    for k in 0..self.dim() {
                        out[(k, column)] = self.drag[k] * rhs[(k, column)];
                    }
                }
            }
        }
        self.add_rank_one(out, rhs);
    }

    /// out += Σ_k w_k·g_k (g_k·v) for each column v of `rhs`.
    fn add_rank_one(&self, mut out: MatMut<'_, f64>, rhs: MatRef<'_, f64>) {
        for column in 0..rhs.ncols() {
            for (w, entries) in &self.rank_one {
                let dot: f64 = entries.iter().map(|&(p, g)| (0..3).map(|a| g[a] * rhs[(3 * p + a, column)]).sum::<f64>()).sum();
                for &(p, g) in entries {
                    for a in 0..3 {
                        out[(3 * p + a, column)] += w * dot * g[a];
                    }
                }
            }
        }
    }

    /// A⁻¹·b by sparse Cholesky of S = D + C and Sherman–Morrison–Woodbury.
    pub fn solve_direct(&self, b: &Col<f64>) -> Result<Mat<f64>, String> {
        let dim = self.dim();
        let diagonal;
        let sparse = match &self.sparse {
            Some(s) => s,
            None => {
                let triplets: Vec<Triplet<usize, usize, f64>> = (0..dim).map(|k| Triplet::new(k, k, self.drag[k])).collect();
                diagonal = SparseColMat::<usize, f64>::try_new_from_triplets(dim, dim, &triplets).map_err(|e| format!("{e:?}"))?;
                &diagonal
            }
        };
        let llt = sparse.sp_cholesky(Side::Lower).map_err(|e| format!("sparse Cholesky: {e:?}"))?;
        let y = llt.solve(b.as_mat());
        let m = self.rank_one.len();
        if m == 0 {
            return Ok(y);
        }
        let mut u = Mat::<f64>::zeros(dim, m);
        for (k, (w, entries)) in self.rank_one.iter().enumerate() {
            for &(p, g) in entries {
                for a in 0..3 {
                    u[(3 * p + a, k)] = w.sqrt() * g[a];
                }
            }
        }
        let z = llt.solve(&u);
        let capacitance = Mat::<f64>::identity(m, m) + u.transpose() * &z;
        let correction = capacitance.partial_piv_lu().solve(u.transpose() * &y);
        Ok(y - z * correction)
    }
}

impl LinOp<f64> for SystemMatrix {
    fn apply_scratch(&self, _rhs_ncols: usize, _par: Par) -> StackReq {
        StackReq::EMPTY
    }

    fn nrows(&self) -> usize {
        self.dim()
    }

    fn ncols(&self) -> usize {
        self.dim()
    }

    fn apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, _par: Par, _stack: &mut MemStack) {
        self.apply_to(out, rhs);
    }

    fn conj_apply(&self, out: MatMut<'_, f64>, rhs: MatRef<'_, f64>, par: Par, stack: &mut MemStack) {
        self.apply(out, rhs, par, stack);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::{RankOneTerm, StiffnessBlock};

    /// Products and the Woodbury solve agree with the dense matrix, without
    /// and with held coordinates (particle 0's y and particle 3's x).
    #[test]
    fn low_rank_products_and_solves_match_the_dense_matrix() {
        let mut held = [false; 12];
        (held[1], held[9]) = (true, true);
        for held in [&[][..], &held[..]] {
            products_and_solves_match(held);
        }
    }

    fn products_and_solves_match(held: &[bool]) {
        let drag = [2.0, 1.0, f64::INFINITY, 0.5];
        let block = DMat3::from_cols(DVec3::new(3.0, 1.0, 0.0), DVec3::new(1.0, 2.0, 0.5), DVec3::new(0.0, 0.5, 1.0));
        let stiffness = Stiffness {
            blocks: vec![
                StiffnessBlock { i: 0, j: 0, block },
                StiffnessBlock { i: 1, j: 1, block },
                StiffnessBlock { i: 0, j: 1, block: -block },
                StiffnessBlock { i: 1, j: 0, block: -block },
                StiffnessBlock { i: 2, j: 3, block },
            ],
            rank_one: vec![
                RankOneTerm { weight: 4.0, particles: vec![0, 2, 3], gradient: vec![DVec3::new(1.0, -2.0, 0.5); 3] },
                RankOneTerm { weight: 0.7, particles: vec![1, 3], gradient: vec![DVec3::new(0.3, 0.1, -1.0), DVec3::X] },
            ],
        };
        let dt = 0.1;
        let a = SystemMatrix::new(&drag, held, dt, 1.0, &stiffness).unwrap();
        // The dense A: fixed particle 2 keeps the identity row and loses its couplings.
        let mut dense = Mat::<f64>::zeros(12, 12);
        for (i, gamma) in drag.iter().enumerate() {
            for k in 0..3 {
                dense[(3 * i + k, 3 * i + k)] = if gamma.is_infinite() { 1.0 } else { gamma / dt };
            }
        }
        for b in stiffness.blocks.iter().filter(|b| b.i != 2 && b.j != 2) {
            for (r, c) in (0..9).map(|n| (n / 3, n % 3)) {
                dense[(3 * b.i as usize + r, 3 * b.j as usize + c)] += b.block.col(c)[r];
            }
        }
        for term in &stiffness.rank_one {
            let mut g = Col::<f64>::zeros(12);
            for (&p, v) in term.particles.iter().zip(&term.gradient).filter(|(&p, _)| p != 2) {
                (0..3).for_each(|k| g[3 * p as usize + k] = v[k]);
            }
            dense += term.weight * &g * g.transpose();
        }
        // A held coordinate likewise: the identity row and column.
        for k in (0..12).filter(|&k| held.get(k).copied().unwrap_or(false)) {
            for m in 0..12 {
                dense[(k, m)] = 0.0;
                dense[(m, k)] = 0.0;
            }
            dense[(k, k)] = 1.0;
        }
        let v = Col::from_fn(12, |k| (k as f64 * 0.7).sin());
        assert!((a.times(&v) - &dense * &v).norm_l2() < 1e-12 * v.norm_l2());
        let (slice, mut out) = ((0..12).map(|k| v[k]).collect::<Vec<_>>(), vec![0.0; 12]);
        a.times_slice(&slice, &mut out);
        assert!((0..12).all(|k| (out[k] - a.times(&v)[k]).abs() < 1e-14));
        assert!((a.diagonal() - dense.diagonal().column_vector().to_owned()).norm_l2() < 1e-12);
        let x = a.solve_direct(&v).unwrap();
        assert!((&dense * &x - v.as_mat()).norm_l2() < 1e-10 * v.norm_l2());
    }
}
