//! Linearly implicit overdamped step (Nédélec & Foethke, *New J. Phys.* 9,
//! 427 (2007); Cytosim):
//!
//! (γ/dt·I + K̃)·Δx = F(x) + √(2·kT·γ/dt)·ξ,   x ← x + Δx
//!
//! with γ the drag of each particle's type, F the forces at x, K̃ the
//! stiffness matrix of [`crate::backend::stiffness`] (the energy Hessian
//! projected to be positive semi-definite, term by term) and ξ the same
//! Philox noise as the explicit step. With K̃ = 0 this is exactly the
//! explicit Euler–Maruyama step; with K̃ it is backward Euler linearised at
//! x: a linear spring k relaxes by the factor 1/(1 + k·dt/γ) per step, so the
//! linear part is stable for every dt (the explicit step needs dt < 2γ/k),
//! while the error per step stays O(dt²) as for the explicit step.
//!
//! The system is symmetric positive definite and is solved by faer's
//! conjugate gradients with a Jacobi preconditioner (`solver cg`, the
//! default; relative residual `tolerance`, at most `max_iterations`), or by a
//! sparse Cholesky factorisation (`solver cholesky`). A `fixed` particle
//! (infinite drag) has Δx = 0: its row is the identity and its couplings are
//! dropped. Both solvers run sequentially, so the step is the same on any
//! thread count.

use faer::linalg::solvers::Solve;
use faer::matrix_free::conjugate_gradient::{conjugate_gradient, conjugate_gradient_scratch, CgParams};
use faer::matrix_free::InitialGuessStatus;
use faer::sparse::{SparseColMat, Triplet};
use faer::{dyn_stack::MemBuffer, dyn_stack::MemStack, Col, Mat, Par, Side};
use glam::DVec3;

use super::overdamped::{Blowup, OverdampedSettings};
use super::rng::noise3;
use crate::backend::stiffness::StiffnessBlock;
use crate::system::{Model, SimBox, State};

/// The linear solver of `integrator implicit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinearSolver {
    /// Conjugate gradients with a Jacobi preconditioner.
    Cg,
    /// Sparse Cholesky factorisation.
    Cholesky,
}

/// Options of `integrator implicit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImplicitSettings {
    pub solver: LinearSolver,
    /// Relative residual |AΔx − b|/|b| at which CG stops.
    pub tolerance: f64,
    pub max_iterations: usize,
}

impl Default for ImplicitSettings {
    fn default() -> Self {
        Self { solver: LinearSolver::Cg, tolerance: 1e-10, max_iterations: 1000 }
    }
}

/// What one implicit step's solve took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveReport {
    pub iterations: usize,
    pub relative_residual: f64,
}

/// Why an implicit step was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum ImplicitError {
    Blowup(Blowup),
    /// The linear solve failed (no convergence within max_iterations, or a
    /// factorisation error).
    Solve(String),
}

/// Advances `state` by one implicit step. On an error `state` is unchanged.
#[allow(clippy::too_many_arguments)]
pub fn implicit_step(
    model: &Model,
    state: &mut State,
    forces: &[DVec3],
    stiffness: &[StiffnessBlock],
    sim_box: &SimBox,
    dt: f64,
    kt: f64,
    seed: u64,
    settings: &OverdampedSettings,
    implicit: &ImplicitSettings,
) -> Result<SolveReport, ImplicitError> {
    let n = state.len();
    let dim = 3 * n;
    let gamma = |i: usize| model.type_drag[model.types[i] as usize];
    let fixed = |i: usize| gamma(i).is_infinite();
    let mut triplets = Vec::with_capacity(dim + 9 * stiffness.len());
    for i in 0..n {
        let diagonal = if fixed(i) { 1.0 } else { gamma(i) / dt };
        for a in 0..3 {
            triplets.push(Triplet::new(3 * i + a, 3 * i + a, diagonal));
        }
    }
    for b in stiffness.iter().filter(|b| !fixed(b.i as usize) && !fixed(b.j as usize)) {
        for col in 0..3 {
            for row in 0..3 {
                triplets.push(Triplet::new(3 * b.i as usize + row, 3 * b.j as usize + col, b.block.col(col)[row]));
            }
        }
    }
    let matrix =
        SparseColMat::<usize, f64>::try_new_from_triplets(dim, dim, &triplets).map_err(|e| ImplicitError::Solve(format!("{e:?}")))?;
    let mut rhs = Col::<f64>::zeros(dim);
    let mut guess = Mat::<f64>::zeros(dim, 1);
    for i in (0..n).filter(|&i| !fixed(i)) {
        let mut b = forces[i];
        if kt > 0.0 {
            b += (2.0 * kt * gamma(i) / dt).sqrt() * DVec3::from_array(noise3(seed, state.step, i as u32, settings.noise));
        }
        for a in 0..3 {
            rhs[3 * i + a] = b[a];
            guess[(3 * i + a, 0)] = b[a] * dt / gamma(i); // the explicit step
        }
    }
    let report = match implicit.solver {
        LinearSolver::Cholesky => {
            let llt = matrix.sp_cholesky(Side::Lower).map_err(|e| ImplicitError::Solve(format!("sparse Cholesky: {e:?}")))?;
            guess = llt.solve(rhs.as_mat());
            SolveReport { iterations: 1, relative_residual: relative_residual(&matrix, &guess, &rhs) }
        }
        LinearSolver::Cg => {
            let diagonal: Col<f64> = Col::from_fn(dim, |k| 1.0 / matrix.get(k, k).copied().unwrap_or(1.0));
            let precond = diagonal.as_diagonal();
            let params = CgParams {
                initial_guess: InitialGuessStatus::MaybeNonZero,
                abs_tolerance: 0.0,
                rel_tolerance: implicit.tolerance,
                max_iters: implicit.max_iterations,
                ..Default::default()
            };
            let mut memory = MemBuffer::new(conjugate_gradient_scratch(precond, matrix.as_ref(), 1, Par::Seq));
            let info = conjugate_gradient(
                guess.as_mut(),
                precond,
                matrix.as_ref(),
                rhs.as_mat(),
                params,
                |_| {},
                Par::Seq,
                MemStack::new(&mut memory),
            )
            .map_err(|e| ImplicitError::Solve(format!("conjugate gradients: {e:?}")))?;
            SolveReport { iterations: info.iter_count, relative_residual: info.rel_residual }
        }
    };
    let step: Vec<DVec3> = (0..n).map(|i| DVec3::new(guess[(3 * i, 0)], guess[(3 * i + 1, 0)], guess[(3 * i + 2, 0)])).collect();
    if let Some(particle) = step.iter().position(|d| !d.is_finite() || d.length() > settings.max_displacement) {
        return Err(ImplicitError::Blowup(Blowup { particle, displacement: step[particle].length() }));
    }
    for ((x, image), d) in state.positions.iter_mut().zip(state.images.iter_mut()).zip(&step) {
        *x += *d;
        sim_box.wrap(x, image);
    }
    state.step += 1;
    state.time += dt;
    Ok(report)
}

fn relative_residual(matrix: &SparseColMat<usize, f64>, x: &Mat<f64>, rhs: &Col<f64>) -> f64 {
    let residual = matrix * x - rhs.as_mat();
    let norm = rhs.norm_l2();
    if norm == 0.0 {
        residual.norm_l2()
    } else {
        residual.norm_l2() / norm
    }
}
