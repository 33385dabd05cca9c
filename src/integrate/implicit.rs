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
//! conjugate gradients with a Jacobi preconditioner D⁻¹ (`solver cg`, the
//! default; relative residual `tolerance`, at most `max_iterations`), or by a
//! sparse Cholesky factorisation (`solver cholesky`). CG starts from the
//! Jacobi step Δx₀ = D⁻¹b: the explicit step b·dt/γ where K̃ is small
//! against γ/dt, and well scaled at any dt. (The explicit step itself is not:
//! at the quasi-static γ/dt = 1e-6 of the Hertz decks it starts 10¹³ µm from
//! the answer, and CG's relative residual cannot recover the 10¹⁻² µm step
//! under that cancellation; measured on `inputs/hertz_block.in`: a node moved
//! 10.2 µm where the Cholesky step moves it < 1 µm.) A `fixed` particle
//! (infinite drag) has Δx = 0: its row is the identity and its couplings are
//! dropped; so has a held coordinate (`freeze`, `move`: the protocols put it
//! back after the step), so the solve moves the free coordinates as the
//! held ones will be, and its fixed point is the held equilibrium. Both
//! solvers run sequentially, so the step is the same on any thread count.
//!
//! With constrained bonds (`constrain`), the step solves the constrained
//! linear system instead — (γ/dt·I + K̃)·Δx = b + Jᵀλ with JΔx = 0 — by
//! projected conjugate gradients (whatever `solver` says), so its fixed point
//! is the constrained equilibrium; SHAKE then removes the second-order drift
//! of the lengths. Projecting an unconstrained implicit step instead would
//! stop short of equilibrium wherever K̃ couples the constrained directions to
//! the free ones (measured: 1.1e-3 µm off on a bent 1 µm filament).
//!
//! **Step clamp** (contact between bodies): with per-particle limits Lᵢ
//! (no node or face corner may move more than 0.4 × the distance of its
//! closest contact, `src/backend/contact.rs`), the solved step is scaled by
//! s = min(1, minᵢ Lᵢ/|Δxᵢ|) — a line search along the backward-Euler
//! direction that keeps every body outside every other — and time advances
//! by s·dt. The contact barrier's Gauss–Newton blocks are in K̃, so the
//! solve already slows the approach; the clamp is the guarantee.

use faer::matrix_free::conjugate_gradient::{conjugate_gradient, conjugate_gradient_scratch, CgParams};
use faer::matrix_free::InitialGuessStatus;
use faer::{dyn_stack::MemBuffer, dyn_stack::MemStack, Col, Mat, Par};
use glam::DVec3;

use super::context::StepContext;
use super::fibre::Fibres;
use super::overdamped::{clamp_fraction, Blowup};
use super::projected_cg::projected_cg;
use super::system_matrix::SystemMatrix;
use crate::backend::Stiffness;
use crate::rng::noise3;
use crate::system::{Model, SimBox, State};

/// The linear solver of `integrator implicit`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LinearSolver {
    /// Conjugate gradients with a Jacobi preconditioner.
    Cg,
    /// Sparse Cholesky factorisation.
    Cholesky,
}

/// How the GPU backend spreads its conjugate gradients (src/gpu/implicit.rs):
/// `gpu_workgroups one|all|auto`. The CPU ignores it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GpuWorkgroups {
    /// One workgroup runs the whole solve (nothing read back per step).
    One,
    /// Every workgroup: one dispatch per phase (the split solve).
    All,
    /// `all` from 8 192 particles on (`SPLIT_SOLVE_FROM` in src/gpu/implicit.rs) without `constrain`, else `one`.
    Auto,
}

/// Options of `integrator implicit`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImplicitSettings {
    pub solver: LinearSolver,
    /// Relative residual |AΔx − b|/|b| at which CG stops.
    pub tolerance: f64,
    pub max_iterations: usize,
    pub gpu_workgroups: GpuWorkgroups,
}

impl Default for ImplicitSettings {
    fn default() -> Self {
        Self { solver: LinearSolver::Cg, tolerance: 1e-10, max_iterations: 1000, gpu_workgroups: GpuWorkgroups::Auto }
    }
}

/// What one implicit step's solve took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SolveReport {
    pub iterations: usize,
    pub relative_residual: f64,
    /// The step clamp's s (1: the step was not shortened).
    pub step_fraction: f64,
}

/// Why an implicit step was refused.
#[derive(Clone, Debug, PartialEq)]
pub enum ImplicitError {
    Blowup(Blowup),
    /// The linear solve failed (no convergence within max_iterations, or a
    /// factorisation error).
    Solve(String),
}

/// Moves `state` by one implicit step of the context's dt and kT; the
/// caller ends the step ([`StepContext::advance`]). On an error `state` is
/// unchanged. `fibres`, assembled at `state` for this step, carry their
/// own terms (which `stiffness` then leaves out) and precondition the solve;
/// θ weighs the stiffness (`theta`).
#[allow(clippy::too_many_arguments)]
pub fn implicit_step(
    model: &Model,
    state: &mut State,
    forces: &[DVec3],
    stiffness: &Stiffness,
    sim_box: &SimBox,
    ctx: &StepContext,
    implicit: &ImplicitSettings,
    theta: f64,
    constrained: &mut ConstrainedBonds,
    fibres: Option<&mut Fibres>,
    limits: Option<&[f64]>,
    held: &[bool],
) -> Result<SolveReport, ImplicitError> {
    let StepContext { dt, kt, seed, noise, step, .. } = *ctx;
    let n = state.len();
    let dim = 3 * n;
    let gamma = |i: usize| model.type_drag[model.types[i] as usize];
    let fixed = |i: usize| gamma(i).is_infinite();
    let on_fibre = |i: usize| fibres.as_ref().is_some_and(|f| f.holds(i));
    // A fibre's points carry their drag in the fibre's own block.
    let drag: Vec<f64> = (0..n).map(|i| if on_fibre(i) && !fixed(i) { 0.0 } else { gamma(i) }).collect();
    let matrix = SystemMatrix::new(&drag, held, dt, theta, stiffness).map_err(ImplicitError::Solve)?;
    let mut rhs = Col::<f64>::zeros(dim);
    for i in (0..n).filter(|&i| !fixed(i)) {
        let mut b = forces[i];
        if kt > 0.0 {
            b += (2.0 * kt * gamma(i) / dt).sqrt() * DVec3::from_array(noise3(seed, step, i as u32, noise));
        }
        for a in (0..3).filter(|&a| !held.get(3 * i + a).copied().unwrap_or(false)) {
            rhs[3 * i + a] = b[a];
        }
    }
    let (solution, report) = match implicit.solver {
        _ if !constrained.pairs.is_empty() || fibres.is_some() => {
            let mobile: Vec<bool> = (0..n).map(|i| !fixed(i)).collect();
            let b: Vec<f64> = (0..dim).map(|k| rhs[k]).collect();
            let solve = projected_cg(&matrix, &b, &mobile, held, constrained, fibres, &state.positions, sim_box, implicit)?;
            constrained.tension.clear();
            constrained.tension.extend(solve.lambda.iter().map(|l| -l));
            (Mat::from_fn(dim, 1, |k, _| solve.x[k]), solve.report)
        }
        LinearSolver::Cholesky => {
            let x = matrix.solve_direct(&rhs).map_err(ImplicitError::Solve)?;
            let report = SolveReport { iterations: 1, relative_residual: relative_residual(&matrix, &x, &rhs), step_fraction: 1.0 };
            (x, report)
        }
        LinearSolver::Cg => {
            let diagonal = matrix.diagonal();
            let mut x = Mat::<f64>::from_fn(dim, 1, |k, _| rhs[k] / diagonal[k]); // the Jacobi step D⁻¹b
            let inverse: Col<f64> = diagonal.iter().map(|d| 1.0 / d).collect();
            let precond = inverse.as_diagonal();
            let params = CgParams {
                initial_guess: InitialGuessStatus::MaybeNonZero,
                abs_tolerance: 0.0,
                rel_tolerance: implicit.tolerance,
                max_iters: implicit.max_iterations,
                ..Default::default()
            };
            let mut memory = MemBuffer::new(conjugate_gradient_scratch(precond, &matrix, 1, Par::Seq));
            let info = conjugate_gradient(x.as_mut(), precond, &matrix, rhs.as_mat(), params, |_| {}, Par::Seq, MemStack::new(&mut memory))
                .map_err(|e| ImplicitError::Solve(format!("conjugate gradients: {e:?}")))?;
            (x, SolveReport { iterations: info.iter_count, relative_residual: info.rel_residual, step_fraction: 1.0 })
        }
    };
    let mut step: Vec<DVec3> =
        (0..n).map(|i| DVec3::new(solution[(3 * i, 0)], solution[(3 * i + 1, 0)], solution[(3 * i + 2, 0)])).collect();
    if let Some(particle) = step.iter().position(|d| !d.is_finite() || d.length() > ctx.max_displacement) {
        return Err(ImplicitError::Blowup(Blowup { particle, displacement: step[particle].length() }));
    }
    let fraction = limits.map_or(1.0, |limits| clamp_fraction(&step, limits));
    if fraction < 1.0 {
        step.iter_mut().for_each(|d| *d *= fraction);
    }
    for ((x, image), d) in state.positions.iter_mut().zip(state.images.iter_mut()).zip(&step) {
        *x += *d;
        sim_box.wrap(x, image);
    }
    Ok(SolveReport { step_fraction: fraction, ..report })
}

/// Constrained bonds for the implicit step: the particle pairs whose
/// distances the step must keep (to first order), and on return the
/// constraint tension each needed (force units, positive pulling together).
#[derive(Clone, Debug, Default)]
pub struct ConstrainedBonds {
    pub pairs: Vec<[u32; 2]>,
    pub tension: Vec<f64>,
}

fn relative_residual(matrix: &SystemMatrix, x: &Mat<f64>, rhs: &Col<f64>) -> f64 {
    let residual = matrix.times(&x.col(0).to_owned()) - rhs;
    let norm = rhs.norm_l2();
    if norm == 0.0 {
        residual.norm_l2()
    } else {
        residual.norm_l2() / norm
    }
}
