//! Overdamped Langevin (Brownian) dynamics, Euler–Maruyama:
//!
//! x(t + dt) = x(t) + dt·F/γ + √(2·kT·dt/γ)·ξ
//!
//! with γ the drag of the particle's type and ξ a vector of three independent
//! zero-mean, unit-variance numbers from the counter-based Philox stream keyed
//! by (seed, step, particle index) — see [`super::rng`]. The default noise is
//! uniform on [−√3, √3) (exact mean and variance, no transcendentals, the same
//! bits on CPU and GPU; the Euler–Maruyama step only needs the first two
//! moments); `noise gaussian` uses Box–Muller normals instead. kT = 0 is
//! deterministic.
//!
//! A step is computed into a scratch buffer and committed only if every
//! displacement is finite and no longer than `max_displacement`, so a blow-up
//! leaves the last good configuration in place.

use glam::DVec3;
use rayon::prelude::*;

use super::rng::{noise3, Noise};
use crate::system::{Model, SimBox, State};

/// Options of `integrator overdamped`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverdampedSettings {
    pub noise: Noise,
    /// Largest displacement allowed in one step (length units) before the run
    /// is stopped as blown up.
    pub max_displacement: f64,
    /// `integrator implicit`: the linearly implicit step and its solver
    /// ([`super::implicit`]); `None` for the explicit step.
    pub implicit: Option<super::implicit::ImplicitSettings>,
}

impl Default for OverdampedSettings {
    fn default() -> Self {
        Self { noise: Noise::Uniform, max_displacement: 1.0, implicit: None }
    }
}

/// Why a step was refused.
#[derive(Clone, Debug, PartialEq)]
pub struct Blowup {
    pub particle: usize,
    pub displacement: f64,
}

/// Advances `state` by one step of length `dt` at temperature `kt`.
///
/// `scratch` is reused between calls. On a blow-up `state` is unchanged.
#[allow(clippy::too_many_arguments)]
pub fn overdamped_step(
    model: &Model,
    state: &mut State,
    forces: &[DVec3],
    sim_box: &SimBox,
    dt: f64,
    kt: f64,
    seed: u64,
    settings: &OverdampedSettings,
    scratch: &mut Vec<DVec3>,
) -> Result<(), Blowup> {
    let step = state.step;
    let refused = |d: &DVec3| !d.is_finite() || d.length() > settings.max_displacement;
    scratch.resize(state.len(), DVec3::ZERO);
    let any_refused = scratch.par_iter_mut().enumerate().with_min_len(1024).fold(
        || false,
        |bad, (i, dx)| {
            let gamma = model.type_drag[model.types[i] as usize];
            if gamma.is_infinite() {
                // A `fixed` particle never moves (and draws no noise).
                *dx = DVec3::ZERO;
                return bad;
            }
            let mut d = forces[i] * (dt / gamma);
            if kt > 0.0 {
                let amplitude = (2.0 * kt * dt / gamma).sqrt();
                let xi = noise3(seed, step, i as u32, settings.noise);
                d += amplitude * DVec3::from_array(xi);
            }
            *dx = d;
            bad | refused(&d)
        },
    );
    if any_refused.reduce(|| false, |a, b| a | b) {
        let particle = scratch.iter().position(refused).expect("a refused displacement");
        return Err(Blowup { particle, displacement: scratch[particle].length() });
    }
    state.positions.par_iter_mut().zip(state.images.par_iter_mut()).zip(scratch.par_iter()).with_min_len(1024).for_each(
        |((x, image), d)| {
            *x += *d;
            sim_box.wrap(x, image);
        },
    );
    state.step += 1;
    state.time += dt;
    Ok(())
}
