//! Newton energy minimisation (`minimize … style newton`): damped Newton
//! steps on the stiffness matrix of the implicit step (Levenberg–Marquardt;
//! Nocedal & Wright, *Numerical Optimization*, 2nd ed., §3.4 and §10.3),
//!
//! (K̃ + μ·I)·Δx = F,   x ← x + s·Δx,
//!
//! with F the forces, K̃ the energy Hessian made positive semi-definite term
//! by term ([`crate::backend::stiffness`], as for `integrator implicit`) and
//! the system solved by sparse Cholesky ([`SystemMatrix::solve_direct`]).
//!
//! - **Damping μ.** It keeps the system positive definite where K̃ is only
//!   semi-definite (a floppy mode, a slack cable) and turns the step towards
//!   steepest descent while the quadratic model is poor. A step that lowers
//!   the energy is taken and μ ← max(μ/3, μ_min); one that does not is
//!   halved up to three times (a force evaluation each: a kink of the
//!   energy, a cable going slack or taut, makes the full step overshoot),
//!   and a halved step that lowers it is taken with μ kept; failing that
//!   the step is solved again with μ ← 4μ. μ starts at 10⁻³ and is floored at 10⁻⁹ of
//!   the largest diagonal entry of K̃, so near the minimum the steps are
//!   Newton steps: quadratic convergence where K̃ is the Hessian, linear
//!   where the projection dropped a negative part (a compressed strut's
//!   transverse stiffness). Each solve counts as one iteration.
//! - **Step length** s = min(1, dmax/maxᵢ|Δxᵢ|, the contact step clamp):
//!   no particle moves more than `dmax` in one iteration (LAMMPS `min_modify
//!   dmax`), nor past the clamp that keeps bodies apart.
//! - **What is minimised.** As for FIRE ([`super::fire`]): `fixed`
//!   particles and the coordinates held by `freeze` or `move` do not move,
//!   and their forces (reactions) are left out of the convergence test,
//!   max |Fᵢ| < `ftol`.
//! - **Round-off.** Near the minimum an energy difference drowns in the
//!   rounding of the energy; there a step is also taken when the energies
//!   agree to 10⁻¹² and the largest residual force falls.
//!
//! Each iteration costs a factorisation (~0.8 s for the 23 803 particles of
//! a level-5 tensegrity cell on one core) against a force evaluation for a
//! FIRE iteration, so it pays only where it needs far fewer iterations than
//! FIRE: measured (README, *Dynamics*) 2.4× faster on the level-2 tensegrity
//! protocol, 3.5× slower on the level-5 cell's first stage and 8× on the
//! pressurised single cell, where K̃ drops much of the Hessian.

use glam::DVec3;

use super::fire::{max_residual_force, zero_fixed_forces, FireReport, FireSettings};
use super::overdamped::clamp_fraction;
use super::system_matrix::SystemMatrix;
use crate::backend::Stiffness;
use crate::system::{SimBox, State};

/// μ's start and floor, relative to the largest diagonal entry of K̃, and its
/// factors after a taken and a refused step.
const MU_START: f64 = 1e-3;
const MU_FLOOR: f64 = 1e-9;
const MU_DOWN: f64 = 3.0;
const MU_UP: f64 = 4.0;
/// Halvings of a step that does not lower the energy, before a new solve.
const BACKTRACKS: i32 = 3;

/// Minimises by damped Newton steps. `evaluate` fills the forces at a state
/// (held coordinates already masked to 0) and the per-particle step limits
/// if the model has any (else leaves them empty), and returns the energy;
/// `stiffness` gives K̃ at a state; `mass` is FIRE's (infinite for a particle
/// that never moves, [`super::fire::max_residual_force`]) and `held` (3 per
/// particle, or empty) marks the held coordinates. A failed
/// factorisation is returned through `failed`.
#[allow(clippy::too_many_arguments)]
pub fn newton_minimize<E>(
    state: &mut State,
    sim_box: &SimBox,
    mass: &[f64],
    held: &[bool],
    settings: &FireSettings,
    mut evaluate: impl FnMut(&State, &mut Vec<DVec3>, &mut Vec<f64>) -> Result<f64, E>,
    mut stiffness: impl FnMut(&State) -> Stiffness,
    failed: impl Fn(String) -> E,
) -> Result<FireReport, E> {
    let n = state.len();
    let (mut forces, mut limits) = (Vec::with_capacity(n), Vec::new());
    let (mut trial_forces, mut trial_limits) = (Vec::with_capacity(n), Vec::new());
    let mut energy = evaluate(state, &mut forces, &mut limits)?;
    zero_fixed_forces(&mut forces, mass);
    let (mut iterations, mut clamped) = (0, 0);
    let mut mu = None;
    loop {
        let max_force = max_residual_force(&forces, mass);
        if max_force < settings.ftol || iterations >= settings.max_iterations {
            return Ok(FireReport { converged: max_force < settings.ftol, iterations, energy, max_force, clamped });
        }
        let k = stiffness(state);
        let scale = k
            .blocks
            .iter()
            .filter(|b| b.i == b.j)
            .map(|b| b.block.x_axis.x.max(b.block.y_axis.y).max(b.block.z_axis.z))
            .fold(0.0, f64::max);
        let scale = if scale > 0.0 { scale } else { 1.0 };
        let floor = MU_FLOOR * scale;
        let mut damping = mu.unwrap_or(MU_START * scale);
        let rhs = faer::Col::<f64>::from_fn(3 * n, |c| forces[c / 3][c % 3]);
        // Solve, and solve again with more damping until a step lowers the energy.
        loop {
            iterations += 1;
            let drag: Vec<f64> = mass.iter().map(|m| if m.is_infinite() { f64::INFINITY } else { damping }).collect();
            let matrix = SystemMatrix::new(&drag, held, 1.0, 1.0, &k).map_err(&failed)?;
            let solution = matrix.solve_direct(&rhs).map_err(&failed)?;
            let mut step: Vec<DVec3> =
                (0..n).map(|i| DVec3::new(solution[(3 * i, 0)], solution[(3 * i + 1, 0)], solution[(3 * i + 2, 0)])).collect();
            let longest = step.iter().map(|d| d.length()).fold(0.0, f64::max);
            if !longest.is_finite() {
                return Err(failed(format!("the Newton step is not finite at iteration {iterations}")));
            }
            let mut s = if longest > settings.dmax { settings.dmax / longest } else { 1.0 };
            step.iter_mut().for_each(|d| *d *= s);
            let fraction = clamp_fraction(&step, &limits);
            if fraction < 1.0 {
                step.iter_mut().for_each(|d| *d *= fraction);
                s *= fraction;
                clamped += 1;
            }
            // Backtrack along the solved direction (a force evaluation each)
            // before paying for another factorisation with more damping.
            let mut taken = None;
            for halving in (0..=BACKTRACKS).filter(|_| s > 0.0) {
                let h = 0.5f64.powi(halving);
                let mut trial = state.clone();
                for ((x, image), d) in trial.positions.iter_mut().zip(trial.images.iter_mut()).zip(&step) {
                    *x += h * *d;
                    sim_box.wrap(x, image);
                }
                trial_limits.clear();
                let trial_energy = evaluate(&trial, &mut trial_forces, &mut trial_limits)?;
                zero_fixed_forces(&mut trial_forces, mass);
                let level = trial_energy - energy <= 1e-12 * energy.abs().max(f64::MIN_POSITIVE);
                if trial_energy < energy || (level && max_residual_force(&trial_forces, mass) < max_force) {
                    taken = Some((trial, trial_energy, halving));
                    break;
                }
            }
            if let Some((trial, trial_energy, halving)) = taken {
                *state = trial;
                energy = trial_energy;
                std::mem::swap(&mut forces, &mut trial_forces);
                std::mem::swap(&mut limits, &mut trial_limits);
                // A full step: the model is good, damp less; a shortened one: keep μ.
                mu = Some(if halving == 0 { (damping / MU_DOWN).max(floor) } else { damping });
                break;
            }
            damping *= MU_UP;
            if iterations >= settings.max_iterations {
                return Ok(FireReport { converged: false, iterations, energy, max_force, clamped });
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::backend::StiffnessBlock;
    use glam::DMat3;

    fn open_box() -> SimBox {
        SimBox::new(DVec3::splat(-10.0), DVec3::splat(10.0), [false; 3])
    }

    /// A quadratic bowl E = ½Σ kₐxₐ² with stiffnesses over three decades:
    /// damped Newton steps converge to max |F| < 1e-10 in at most 8
    /// iterations (μ, at first 0.4 against the softest k = 1, falls
    /// threefold a step; measured: 7).
    #[test]
    fn converges_a_stiff_anisotropic_quadratic_in_a_few_steps() {
        let mut state = State::new(vec![DVec3::new(1.0, -2.0, 0.5), DVec3::new(-0.3, 0.2, 0.9)]);
        let k = DVec3::new(1.0, 50.0, 400.0);
        let settings = FireSettings { ftol: 1e-10, max_iterations: 50, dmax: 10.0, ..Default::default() };
        let report = newton_minimize::<String>(
            &mut state,
            &open_box(),
            &[1.0, 1.0],
            &[],
            &settings,
            |s, f, _| {
                f.clear();
                f.extend(s.positions.iter().map(|x| -k * *x));
                Ok(s.positions.iter().map(|x| 0.5 * (k * *x).dot(*x)).sum())
            },
            |_| Stiffness {
                blocks: (0..2).map(|i| StiffnessBlock { i, j: i, block: DMat3::from_diagonal(k) }).collect(),
                rank_one: vec![],
            },
            |e| e,
        )
        .unwrap();
        assert!(report.converged && report.iterations <= 8, "{report:?}");
        assert!(state.positions.iter().all(|x| x.length() < 1e-10 / 1.0), "{:?}", state.positions);
    }

    /// A spring k (rest length 1) from a fixed anchor to a bead pulled by 2
    /// along x, its Hessian given only along the spring (a projected,
    /// semi-definite K̃), the bead's z held at 0.3: the bead settles where
    /// the spring's x component balances the pull, k(L − 1)·x/L = 2 with
    /// L = √(x² + 0.3²), at y = 0; the anchor stays put though it carries
    /// the load, and the held coordinate keeps its value.
    #[test]
    fn a_loaded_anchor_and_a_held_coordinate_stay_put() {
        let mut state = State::new(vec![DVec3::ZERO, DVec3::new(1.5, 0.2, 0.3)]);
        let (k, pull) = (4.0, DVec3::new(2.0, 0.0, 0.0));
        let held = [false, false, false, false, false, true];
        let settings = FireSettings { ftol: 1e-10, max_iterations: 100, dmax: 0.5, ..Default::default() };
        let report = newton_minimize::<String>(
            &mut state,
            &open_box(),
            &[f64::INFINITY, 1.0],
            &held,
            &settings,
            |s, f, _| {
                let d = s.positions[1] - s.positions[0];
                let spring = -k * (d.length() - 1.0) * d.normalize();
                f.clear();
                f.extend([-spring, (spring + pull) * DVec3::new(1.0, 1.0, 0.0)]);
                Ok(0.5 * k * (d.length() - 1.0).powi(2) - pull.dot(s.positions[1]))
            },
            |s| {
                let u = (s.positions[1] - s.positions[0]).normalize();
                let h = k * DMat3::from_cols(u * u.x, u * u.y, u * u.z);
                Stiffness {
                    blocks: vec![
                        StiffnessBlock { i: 0, j: 0, block: h },
                        StiffnessBlock { i: 1, j: 1, block: h },
                        StiffnessBlock { i: 0, j: 1, block: -h },
                        StiffnessBlock { i: 1, j: 0, block: -h },
                    ],
                    rank_one: vec![],
                }
            },
            |e| e,
        )
        .unwrap();
        assert!(report.converged, "{report:?}");
        assert_eq!(state.positions[0], DVec3::ZERO);
        assert_eq!(state.positions[1].z, 0.3);
        let balance = |x: f64| {
            let l = (x * x + 0.09f64).sqrt();
            k * (l - 1.0) * x / l - 2.0
        };
        let (mut lo, mut hi) = (1.0, 3.0);
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if balance(mid) > 0.0 {
                hi = mid
            } else {
                lo = mid
            }
        }
        let x = state.positions[1];
        assert!((x.x - lo).abs() < 1e-9 && x.y.abs() < 1e-9, "{x:?}, expected x = {lo} ({report:?})");
    }
}
