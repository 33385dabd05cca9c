//! FIRE energy minimisation (Bitzek et al., Phys. Rev. Lett. 97, 170201 (2006)).
//!
//! Fictitious inertial dynamics with mass mᵢ = γᵢ·Δt (Δt the deck timestep),
//! so the first FIRE move equals one overdamped step and the step is stable
//! whenever the overdamped one is. Each iteration, with P = Σ F·v:
//! - P > 0: v ← (1 − α)v + α|v|F̂; after `N_min` = 5 such steps, Δt ← min(1.1Δt, 10Δt₀), α ← 0.99α;
//! - P ≤ 0: v ← 0, Δt ← Δt/2, α ← α₀ = 0.1;
//!
//! then v ← v + Δt·F/m and x ← x + Δt·v, each particle's move capped at `dmax`
//! (as LAMMPS `min_modify dmax`). Converged when max |Fᵢ| < `ftol`.
//!
//! **Step clamp** (contact between bodies): when the evaluation also gives
//! per-particle limits Lᵢ (the contact clamp of `src/backend/contact.rs`:
//! no node or face corner may move more than 0.4 × the distance of its
//! closest contact), the whole move is scaled by s = min(1, minᵢ Lᵢ/|Δxᵢ|),
//! a line search that keeps every body outside every other; the velocities
//! are kept, so FIRE's own Δt adaptation is unchanged.
//!
//! A particle of infinite mass (a `fixed` type, γ = ∞) never moves: its force
//! is the reaction of its anchor, not a residual, so it is left out of P, of
//! the mixing and of the convergence test (LAMMPS zeroes such forces with
//! `fix setforce 0 0 0` before minimising). Without this, the mixing step
//! v ← …α|v|F̂ would move an anchor that carries load, and a loaded anchor
//! would keep max |F| above `ftol` for ever.

use glam::DVec3;

use super::context::StepContext;
use super::overdamped::clamp_fraction;
use crate::system::{SimBox, State};

/// FIRE's parameters (Bitzek et al. 2006), shared with the device's FIRE
/// (src/gpu/fire.rs, shaders/common/fire.wgsl): positive steps before Δt
/// grows, Δt's growth and cut factors, α's start and decay, and Δt's cap in
/// units of Δt₀.
pub const N_MIN: u32 = 5;
pub const F_INC: f64 = 1.1;
pub const F_DEC: f64 = 0.5;
pub const ALPHA0: f64 = 0.1;
pub const F_ALPHA: f64 = 0.99;
pub const DT_MAX_FACTOR: f64 = 10.0;

/// The residual FIRE converges on: the largest |F| over the particles of
/// finite mass (a fixed particle's force is its anchor's reaction).
pub fn max_residual_force(forces: &[DVec3], mass: &[f64]) -> f64 {
    forces.iter().zip(mass).filter(|(_, m)| m.is_finite()).map(|(f, _)| f.length()).fold(0.0, f64::max)
}

/// Zeroes the forces of the particles of infinite mass (`fixed`): reactions,
/// which no minimiser may follow.
pub fn zero_fixed_forces(forces: &mut [DVec3], mass: &[f64]) {
    forces.iter_mut().zip(mass).filter(|(_, m)| m.is_infinite()).for_each(|(f, _)| *f = DVec3::ZERO);
}

/// The minimiser of the deck `minimize` command (`style`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum MinimizeStyle {
    /// FIRE (this module), on the CPU or the device.
    #[default]
    Fire,
    /// Damped Newton steps with sparse Cholesky (src/integrate/newton.rs), on the CPU.
    Newton,
}

/// Options of the deck `minimize` command.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FireSettings {
    /// Force tolerance: converged when every |Fᵢ| is below it (force units).
    pub ftol: f64,
    pub max_iterations: u64,
    /// Largest move of a particle in one iteration (length units).
    pub dmax: f64,
    pub style: MinimizeStyle,
}

impl Default for FireSettings {
    fn default() -> Self {
        Self { ftol: 1e-6, max_iterations: 10_000, dmax: 0.1, style: MinimizeStyle::Fire }
    }
}

/// Outcome of a minimisation.
#[derive(Clone, Debug, PartialEq)]
pub struct FireReport {
    pub converged: bool,
    pub iterations: u64,
    pub energy: f64,
    pub max_force: f64,
    /// Iterations whose move the contact step clamp shortened.
    pub clamped: u64,
}

/// Minimises with FIRE. `evaluate(state, f, limits, energy)` fills the
/// forces at a state, and the per-particle step limits if the model has any
/// (else leaves them empty), and returns the energy when `energy` is true
/// (anything otherwise). FIRE's moves need only forces, so the energy is
/// asked for once, at the state returned (its forces evaluated again: the
/// same bits, an evaluation with energies giving the forces one without
/// gives).
pub fn fire_minimize<E>(
    state: &mut State,
    sim_box: &SimBox,
    mass: &[f64],
    ctx: &StepContext,
    settings: &FireSettings,
    mut evaluate: impl FnMut(&State, &mut Vec<DVec3>, &mut Vec<f64>, bool) -> Result<f64, E>,
) -> Result<FireReport, E> {
    let n = state.len();
    let mut v = vec![DVec3::ZERO; n];
    let mut f = Vec::with_capacity(n);
    let (mut limits, mut moves) = (Vec::new(), vec![DVec3::ZERO; n]);
    let dt0 = ctx.dt;
    let (mut dt, dt_max, mut alpha, mut positive_steps) = (dt0, DT_MAX_FACTOR * dt0, ALPHA0, 0u32);
    let (mut iterations, mut clamped) = (0, 0);
    loop {
        limits.clear();
        evaluate(state, &mut f, &mut limits, false)?;
        zero_fixed_forces(&mut f, mass);
        let max_force = max_residual_force(&f, mass);
        if max_force < settings.ftol || iterations >= settings.max_iterations {
            let energy = evaluate(state, &mut f, &mut limits, true)?;
            return Ok(FireReport { converged: max_force < settings.ftol, iterations, energy, max_force, clamped });
        }
        iterations += 1;
        let power: f64 = f.iter().zip(&v).map(|(f, v)| f.dot(*v)).sum();
        if power > 0.0 {
            let v_norm = v.iter().map(|x| x.length_squared()).sum::<f64>().sqrt();
            let f_norm = f.iter().map(|x| x.length_squared()).sum::<f64>().sqrt();
            for (v, f) in v.iter_mut().zip(&f) {
                *v = (1.0 - alpha) * *v + alpha * v_norm * *f / f_norm;
            }
            if positive_steps > N_MIN {
                dt = (dt * F_INC).min(dt_max);
                alpha *= F_ALPHA;
            }
            positive_steps += 1;
        } else {
            v.iter_mut().for_each(|x| *x = DVec3::ZERO);
            dt *= F_DEC;
            alpha = ALPHA0;
            positive_steps = 0;
        }
        for i in 0..n {
            v[i] += dt * f[i] / mass[i];
            let dx = dt * v[i];
            let len = dx.length();
            moves[i] = if len > settings.dmax { dx * (settings.dmax / len) } else { dx };
        }
        let s = clamp_fraction(&moves, &limits);
        clamped += u64::from(s < 1.0);
        for ((x, image), dx) in state.positions.iter_mut().zip(state.images.iter_mut()).zip(&moves) {
            *x += s * *dx;
            sim_box.wrap(x, image);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timestep(dt: f64) -> StepContext {
        StepContext { dt, ..Default::default() }
    }

    #[test]
    fn converges_a_stiff_anisotropic_quadratic() {
        let sim_box = SimBox::new(DVec3::splat(-10.0), DVec3::splat(10.0), [false; 3]);
        let mut state = State::new(vec![DVec3::new(1.0, -2.0, 0.5), DVec3::new(-0.3, 0.2, 0.9)]);
        let k = DVec3::new(1.0, 50.0, 400.0);
        let report = fire_minimize::<()>(
            &mut state,
            &sim_box,
            &[1e-3, 1e-3],
            &timestep(1e-3),
            &FireSettings { ftol: 1e-8, ..Default::default() },
            |s, f, _, _| {
                f.clear();
                f.extend(s.positions.iter().map(|x| -k * *x));
                Ok(s.positions.iter().map(|x| 0.5 * (k * *x).dot(*x)).sum())
            },
        )
        .unwrap();
        assert!(report.converged, "{report:?}");
        assert!(state.positions.iter().all(|x| x.length() < 1e-8 / 1.0));
    }

    /// With limits L = 0.4·(x − 1) (a contact at x = 1), FIRE sliding down
    /// a slope towards x = 0 approaches x = 1 but never reaches it.
    #[test]
    fn the_step_clamp_keeps_particles_short_of_their_contact() {
        let sim_box = SimBox::new(DVec3::splat(-10.0), DVec3::splat(10.0), [false; 3]);
        let mut state = State::new(vec![DVec3::new(3.0, 0.0, 0.0)]);
        let mut lowest = f64::INFINITY;
        let settings = FireSettings { ftol: 1e-12, max_iterations: 60, dmax: 0.5, ..Default::default() };
        let report = fire_minimize::<()>(&mut state, &sim_box, &[1.0], &timestep(0.1), &settings, |s, f, limits, _| {
            lowest = lowest.min(s.positions[0].x);
            f.clear();
            f.push(DVec3::new(-1.0, 0.0, 0.0));
            limits.push(0.4 * (s.positions[0].x - 1.0));
            Ok(s.positions[0].x)
        })
        .unwrap();
        assert!(report.clamped > 10, "{report:?}");
        assert!(lowest > 1.0 && lowest < 1.0 + 1e-3, "closest approach {lowest}");
    }

    /// A spring of stiffness k and rest length 1 from a fixed anchor at the
    /// origin to a bead, the bead also pulled by 2 along x: the bead settles at
    /// x = 1 + 2/k, the anchor never moves although it carries the load.
    #[test]
    fn a_loaded_anchor_of_infinite_mass_stays_put_and_does_not_block_convergence() {
        let sim_box = SimBox::new(DVec3::splat(-10.0), DVec3::splat(10.0), [false; 3]);
        let mut state = State::new(vec![DVec3::ZERO, DVec3::new(1.5, 0.2, 0.0)]);
        let (k, pull) = (4.0, DVec3::new(2.0, 0.0, 0.0));
        let settings = FireSettings { ftol: 1e-10, ..Default::default() };
        let report = fire_minimize::<()>(&mut state, &sim_box, &[f64::INFINITY, 1e-2], &timestep(1e-2), &settings, |s, f, _, _| {
            let d = s.positions[1] - s.positions[0];
            let spring = -k * (d.length() - 1.0) * d.normalize();
            f.clear();
            f.extend([-spring, spring + pull]);
            Ok(0.5 * k * (d.length() - 1.0).powi(2) - pull.dot(s.positions[1]))
        })
        .unwrap();
        assert!(report.converged, "{report:?}");
        assert_eq!(state.positions[0], DVec3::ZERO);
        assert!((state.positions[1] - DVec3::new(1.0 + 2.0 / k, 0.0, 0.0)).length() < 1e-9, "{:?}", state.positions[1]);
    }
}
