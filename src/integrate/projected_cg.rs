//! The constrained implicit step's linear solve: min ½ΔxᵀAΔx − bᵀΔx
//! subject to JΔx = c, by conjugate gradients with a constraint
//! preconditioner (Gould, Hribar & Nocedal 2001; Keller, Gould & Wathen
//! 2000).
//!
//! J holds the constraint gradients û_ij at the current positions. The
//! preconditioner is, on the points of fibres, each fibre's exact banded
//! solve of its own block with its own constraints (`integrate::fibre`),
//! and elsewhere the projected Jacobi preconditioner
//! P = D⁻¹ − D⁻¹Jᵀ(JD⁻¹Jᵀ)⁻¹JD⁻¹ of the other constraints (JD⁻¹Jᵀ factorised
//! once per step by sparse Cholesky, only where there are such
//! constraints). The iterates stay in the null space of J, and the answer
//! is the step of the constrained linear system AΔx = b + Jᵀλ; λ =
//! (JD⁻¹Jᵀ)⁻¹JD⁻¹(AΔx − b) are the other constraints' forces, a fibre's
//! come from its solve of the final residual. The fibres' segments restore
//! their lengths to first order (c = ℓ − |r|, in the starting point), the
//! other constraints keep them (c = 0). The residual update of Gould,
//! Hribar & Nocedal, r ← r − Jᵀ(JD⁻¹Jᵀ)⁻¹JD⁻¹r (a change of λ only), keeps r
//! consistent with the null space, so the round-off of the projection does
//! not stall the iteration. Fixed particles and held coordinates have D⁻¹ = 0, so they never
//! move; a bond with both ends fixed is skipped. For free fibres the
//! preconditioner is A itself and the starting point is the answer.
//!
//! Sums run in a fixed order, so the solve is the same on any thread count.

use faer::linalg::solvers::Solve;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Col, Side};
use glam::DVec3;

use super::fibre::Fibres;
use super::implicit::{ConstrainedBonds, ImplicitError, ImplicitSettings, SolveReport};
use super::system_matrix::SystemMatrix;
use crate::system::SimBox;

/// The solution, the multipliers of the constraints that are not on fibres
/// (0 for those that are), and the solve's report.
pub(super) struct ProjectedSolve {
    pub(super) x: Vec<f64>,
    pub(super) lambda: Vec<f64>,
    pub(super) report: SolveReport,
}

/// The constraints off the fibres: rows of J and the factorised JD⁻¹Jᵀ.
struct GeneralConstraints {
    rows: Vec<(usize, usize, DVec3)>,
    active: Vec<bool>,
    schur: Option<faer::sparse::linalg::solvers::Llt<usize, f64>>,
}

impl GeneralConstraints {
    fn new(
        constrained: &ConstrainedBonds,
        chained: &[bool],
        on_fibre: &[bool],
        mobile: &[bool],
        dinv: &[f64],
        positions: &[DVec3],
        sim_box: &SimBox,
    ) -> Result<Self, ImplicitError> {
        let images = sim_box.images();
        let rows: Vec<(usize, usize, DVec3)> = constrained
            .pairs
            .iter()
            .map(|&[i, j]| {
                (i as usize, j as usize, images.minimum_image(positions[j as usize] - positions[i as usize]).normalize_or_zero())
            })
            .collect();
        // A constraint on a fibre's point that is not one of its segments (a
        // constrained crosslink) is left to the projection after the step,
        // which restores it with the fibres (`integrate::fibre::coupled`):
        // the fibre's solve, not D⁻¹, moves that point.
        let active: Vec<bool> = rows
            .iter()
            .enumerate()
            .map(|(k, &(i, j, _))| (mobile[i] || mobile[j]) && !chained.get(k).copied().unwrap_or(false) && !on_fibre[i] && !on_fibre[j])
            .collect();
        let m = rows.len();
        if !active.iter().any(|&a| a) {
            return Ok(Self { rows, active, schur: None });
        }
        // S = J D⁻¹ Jᵀ; rows of inactive constraints are the identity.
        let mut by_particle: std::collections::BTreeMap<usize, Vec<(usize, f64)>> = Default::default();
        for (k, &(i, j, _)) in rows.iter().enumerate().filter(|(k, _)| active[*k]) {
            by_particle.entry(i).or_default().push((k, -1.0));
            by_particle.entry(j).or_default().push((k, 1.0));
        }
        let mut triplets: Vec<Triplet<usize, usize, f64>> = (0..m).filter(|&k| !active[k]).map(|k| Triplet::new(k, k, 1.0)).collect();
        for (&p, list) in &by_particle {
            for &(k, sk) in list {
                for &(l, sl) in list {
                    let dot: f64 = (0..3).map(|a| sk * rows[k].2[a] * dinv[3 * p + a] * sl * rows[l].2[a]).sum();
                    triplets.push(Triplet::new(k, l, dot));
                }
            }
        }
        let schur =
            SparseColMat::<usize, f64>::try_new_from_triplets(m, m, &triplets).map_err(|e| ImplicitError::Solve(format!("{e:?}")))?;
        let schur = schur.sp_cholesky(Side::Lower).map_err(|e| ImplicitError::Solve(format!("constraint matrix JD⁻¹Jᵀ: {e:?}")))?;
        Ok(Self { rows, active, schur: Some(schur) })
    }

    /// (JD⁻¹Jᵀ)⁻¹ J D⁻¹ v (zeros without active constraints).
    fn multipliers(&self, dinv: &[f64], v: &[f64]) -> Col<f64> {
        let mut mu = Col::from_fn(self.rows.len(), |k| {
            let (i, j, u) = self.rows[k];
            if !self.active[k] {
                return 0.0;
            }
            (0..3).map(|a| u[a] * (dinv[3 * j + a] * v[3 * j + a] - dinv[3 * i + a] * v[3 * i + a])).sum()
        });
        if let Some(schur) = &self.schur {
            schur.solve_in_place(mu.as_mat_mut());
        }
        mu
    }

    /// r ← r − Jᵀ(JD⁻¹Jᵀ)⁻¹JD⁻¹r on the coordinates that move (D⁻¹ > 0).
    fn update(&self, dinv: &[f64], r: &mut [f64]) {
        if self.schur.is_none() {
            return;
        }
        let mu = self.multipliers(dinv, r);
        for (k, &(i, j, u)) in self.rows.iter().enumerate().filter(|(k, _)| self.active[*k]) {
            for a in 0..3 {
                if dinv[3 * i + a] > 0.0 {
                    r[3 * i + a] += u[a] * mu[k];
                }
                if dinv[3 * j + a] > 0.0 {
                    r[3 * j + a] -= u[a] * mu[k];
                }
            }
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

fn norm(a: &[f64]) -> f64 {
    dot(a, a).sqrt()
}

/// The constrained solve of A·Δx = b (see the module docs).
#[allow(clippy::too_many_arguments)]
pub(super) fn projected_cg(
    matrix: &SystemMatrix,
    rhs: &[f64],
    mobile: &[bool],
    held: &[bool],
    constrained: &ConstrainedBonds,
    mut fibres: Option<&mut Fibres>,
    positions: &[DVec3],
    sim_box: &SimBox,
    implicit: &ImplicitSettings,
) -> Result<ProjectedSolve, ImplicitError> {
    let dim = rhs.len();
    let on_fibre: Vec<bool> = (0..dim / 3).map(|p| fibres.as_ref().is_some_and(|f| f.holds(p))).collect();
    let diagonal = matrix.diagonal();
    let free = |k: usize| mobile[k / 3] && !held.get(k).copied().unwrap_or(false);
    let dinv: Vec<f64> = (0..dim).map(|k| if free(k) && !on_fibre[k / 3] { 1.0 / diagonal[k] } else { 0.0 }).collect();
    let chained = fibres.as_ref().map_or(&[][..], |f| &f.chains.chained_constraints[..]);
    let general = GeneralConstraints::new(constrained, chained, &on_fibre, mobile, &dinv, positions, sim_box)?;
    // z = M⁻¹ r: projected Jacobi off the fibres (after the residual update), each fibre's own solve on them.
    let precondition = |r: &[f64], restore: bool, fibres: &mut Option<&mut Fibres>, z: &mut [f64]| {
        z.iter_mut().zip(r).zip(&dinv).for_each(|((z, r), d)| *z = d * r);
        if let Some(f) = fibres.as_deref_mut() {
            f.precondition(r, restore, z);
        }
    };
    // The preconditioned residual of r, with r's constraint forces removed (the residual update).
    let precondition_residual = |r: &mut [f64], fibres: &mut Option<&mut Fibres>, z: &mut [f64]| {
        general.update(&dinv, r);
        precondition(r, false, fibres, z);
        if let Some(f) = fibres.as_deref() {
            f.remove_constraint_forces(r);
        }
    };
    let product = |v: &[f64], fibres: &mut Option<&mut Fibres>, out: &mut [f64]| {
        matrix.times_slice(v, out);
        if let Some(f) = fibres.as_deref_mut() {
            f.add_times(v, out);
        }
    };
    let mut x = vec![0.0; dim];
    let mut z = vec![0.0; dim];
    let mut ap = vec![0.0; dim];
    // The starting point: the fibres' own solve (restoring their lengths), zero elsewhere.
    if fibres.is_some() {
        precondition(rhs, true, &mut fibres, &mut z);
        for k in (0..dim).filter(|&k| on_fibre[k / 3]) {
            x[k] = z[k];
        }
    }
    product(&x, &mut fibres, &mut ap);
    let mut r: Vec<f64> = rhs.iter().zip(&ap).map(|(b, a)| b - a).collect();
    precondition_residual(&mut r, &mut fibres, &mut z);
    // |r|/|b|, r the residual with the constraint forces removed (the criterion of unconstrained CG).
    let reference = norm(rhs).max(f64::MIN_POSITIVE);
    let mut p = z.clone();
    let mut rz = dot(&r, &z);
    let mut iterations = 0;
    let mut residual = norm(&r) / reference;
    while residual > implicit.tolerance && iterations < implicit.max_iterations {
        product(&p, &mut fibres, &mut ap);
        let curvature = dot(&p, &ap);
        if curvature <= 0.0 {
            return Err(ImplicitError::Solve(format!("projected conjugate gradients: non-positive curvature {curvature:e}")));
        }
        let alpha = rz / curvature;
        x.iter_mut().zip(&p).for_each(|(x, p)| *x += alpha * p);
        r.iter_mut().zip(&ap).for_each(|(r, a)| *r -= alpha * a);
        precondition_residual(&mut r, &mut fibres, &mut z);
        let rz_next = dot(&r, &z);
        let beta = rz_next / rz;
        p.iter_mut().zip(&z).for_each(|(p, z)| *p = z + beta * *p);
        rz = rz_next;
        iterations += 1;
        residual = norm(&r) / reference;
    }
    if residual > implicit.tolerance {
        return Err(ImplicitError::Solve(format!(
            "projected conjugate gradients: relative residual {residual:e} after {iterations} iterations (tolerance {:e})",
            implicit.tolerance
        )));
    }
    // The defect AΔx − b = −Jᵀλ gives the multipliers: the general ones by
    // the projection, the fibres' by their solve of b − AΔx. Without an
    // iteration (free fibres: the starting point is the answer) `ap` is
    // still A·x and, without general constraints, the residual's solve
    // above was that of b − AΔx, so the fibres hold their multipliers.
    let settled = iterations == 0 && general.schur.is_none();
    if iterations > 0 {
        product(&x, &mut fibres, &mut ap);
    }
    let defect: Vec<f64> = ap.iter().zip(rhs).map(|(a, b)| a - b).collect();
    let lambda = general.multipliers(&dinv, &defect);
    if fibres.is_some() && !settled {
        let minus: Vec<f64> = defect.iter().map(|d| -d).collect();
        precondition(&minus, false, &mut fibres, &mut z);
    }
    let m = general.rows.len();
    Ok(ProjectedSolve {
        x,
        lambda: (0..m).map(|k| if general.active[k] { lambda[k] } else { 0.0 }).collect(),
        report: SolveReport { iterations, relative_residual: residual, step_fraction: 1.0 },
    })
}
