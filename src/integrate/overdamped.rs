//! Overdamped Langevin (Brownian) dynamics, Euler–Maruyama:
//!
//! x(t + dt) = x(t) + dt·F/γ + √(2·kT·dt/γ)·ξ
//!
//! with γ the drag of the particle's type and ξ a vector of three independent
//! zero-mean, unit-variance numbers from the counter-based Philox stream keyed
//! by (seed, step, particle index) — see [`crate::rng`]. The default noise is
//! uniform on [−√3, √3) (exact mean and variance, no transcendentals, the same
//! bits on CPU and GPU; the Euler–Maruyama step only needs the first two
//! moments); `noise gaussian` uses Box–Muller normals instead. kT = 0 is
//! deterministic.
//!
//! A step is computed into a scratch buffer and committed only if every
//! displacement is finite and no longer than `max_displacement`, so a blow-up
//! leaves the last good configuration in place.
//!
//! # Step clamp (contact between bodies)
//!
//! With per-particle limits L_i (the contact step clamp: no node or face
//! corner may move more than 0.4 × the distance of its closest contact), the
//! step is shortened to s·dt with the largest s ∈ (0, 1] such that every
//! limited particle's displacement s·a_i + √s·b_i (drift a_i = dt·F_i/γ,
//! noise b_i = √(2kT·dt/γ)·ξ_i) satisfies s|a_i| + √s|b_i| ≤ L_i: the
//! Euler–Maruyama step of length s·dt with the same draw ξ (drift scales with
//! the time, noise with its square root), and time advances by s·dt. All
//! particles take the shortened step, so the dynamics stay consistent; since
//! s is chosen after ξ is drawn, clamped steps slightly bias the noise
//! (large draws near a contact are shortened), so with kT > 0 clamping should
//! be rare — frequent clamps mean dt is too large for the contact stiffness.

use glam::DVec3;
use rayon::prelude::*;

use super::context::StepContext;
use super::fibre::FibreStep;
use crate::rng::{noise3, noise3_x4, Noise};
use crate::system::{Model, SimBox, State};

/// Options of `integrator overdamped`, which `integrator implicit` shares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OverdampedSettings {
    pub noise: Noise,
    /// Largest displacement allowed in one step (length units) before the run
    /// is stopped as blown up.
    pub max_displacement: f64,
    /// Weight θ of the stiffness in the implicit parts of a step (the
    /// implicit step's K̃, an inextensible fibre's own terms on the explicit
    /// one): 1 backward Euler, ½ the trapezoidal rule (`integrate::fibre`).
    pub theta: f64,
}

impl Default for OverdampedSettings {
    fn default() -> Self {
        Self { noise: Noise::Uniform, max_displacement: 1.0, theta: 1.0 }
    }
}

/// Why a step was refused.
#[derive(Clone, Debug, PartialEq)]
pub struct Blowup {
    pub particle: usize,
    pub displacement: f64,
}

/// The largest s ∈ (0, 1] with s·|a| + √s·|b| ≤ `limit` (1 when the full step fits).
fn step_fraction(a: f64, b: f64, limit: f64) -> f64 {
    if a + b <= limit {
        return 1.0;
    }
    // u = √s solves |a|u² + |b|u − L = 0 (the stable root).
    let u = 2.0 * limit / (b + (b * b + 4.0 * a * limit).sqrt());
    u * u
}

/// The largest s ∈ (0, 1] with s·|Δxᵢ| ≤ Lᵢ for every particle (1 when
/// `limits` is empty): the clamp of a step with no noise part (FIRE moves,
/// implicit steps), the b = 0 case of `step_fraction`.
pub fn clamp_fraction(moves: &[DVec3], limits: &[f64]) -> f64 {
    limits.iter().zip(moves).map(|(limit, dx)| if dx.length() > *limit { limit / dx.length() } else { 1.0 }).fold(1.0, f64::min)
}

/// Moves `state` by one step of the context's dt and kT, shortened to s·dt
/// when a particle would move farther than its entry of `limits` (see the
/// module docs). With `fibres`, the points of inextensible fibres take the
/// fibre solver's semi-implicit step instead (`integrate::fibre`). Returns s (1 for a full step); the caller ends the step
/// ([`StepContext::advance`]).
///
/// `scratch` (the displacements) is reused between calls. On a blow-up
/// `state` is unchanged. Two passes over the particles: the displacements
/// with the refusal check, then the commit; with `limits`, one more before
/// them for s, which draws the noise again rather than storing it (the
/// stream is counter-based, so the draw is the same).
#[allow(clippy::too_many_arguments)]
pub fn overdamped_step(
    model: &Model,
    state: &mut State,
    forces: &[DVec3],
    sim_box: &SimBox,
    ctx: &StepContext,
    limits: Option<&[f64]>,
    scratch: &mut Vec<DVec3>,
    fibres: Option<FibreStep>,
) -> Result<f64, Blowup> {
    let StepContext { dt, kt, seed, noise, step, .. } = *ctx;
    let refused = |d: &DVec3| !d.is_finite() || d.length() > ctx.max_displacement;
    // Drift a = dt·F/γ and noise b = √(2kT·dt/γ)·ξ of particle i, with ξ
    // its draw; a `fixed` particle never moves (and its draw is unused).
    let drift_and_noise = |i: usize, xi: [f64; 3]| {
        let gamma = model.type_drag[model.types[i] as usize];
        if gamma.is_infinite() {
            return (DVec3::ZERO, DVec3::ZERO);
        }
        let noise = if kt > 0.0 { (2.0 * kt * dt / gamma).sqrt() * DVec3::from_array(xi) } else { DVec3::ZERO };
        (forces[i] * (dt / gamma), noise)
    };
    // The minimum is exact, so s does not depend on the thread count.
    let fraction = limits.map_or(1.0, |limits| {
        (0..state.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|i| {
                let xi = if kt > 0.0 { noise3(seed, step, i as u32, noise) } else { [0.0; 3] };
                let (a, b) = drift_and_noise(i, xi);
                step_fraction(a.length(), b.length(), limits[i])
            })
            .reduce(|| 1.0, f64::min)
    });
    let root = fraction.sqrt();
    // A fibre point's displacement is the fibre solve's (below), which
    // draws its own noise: its Euler–Maruyama step is not computed.
    let on_fibre = |i: usize| fibres.as_ref().is_some_and(|f| f.fibres.holds(i));
    scratch.resize(state.len(), DVec3::ZERO);
    // Four particles at a time: their noise is drawn in one call (noise3_x4,
    // the same bits as four).
    let any_refused = scratch
        .par_chunks_mut(4)
        .enumerate()
        .with_min_len(256)
        .fold(
            || false,
            |mut bad, (c, four)| {
                let xi = if kt > 0.0 { noise3_x4(seed, step, 4 * c as u32, noise) } else { [[0.0; 3]; 4] };
                for (l, d) in four.iter_mut().enumerate() {
                    let i = 4 * c + l;
                    if on_fibre(i) {
                        continue;
                    }
                    let (a, b) = drift_and_noise(i, xi[l]);
                    *d = if fraction == 1.0 { a + b } else { fraction * a + root * b };
                    bad |= refused(d);
                }
                bad
            },
        )
        .reduce(|| false, |a, b| a | b);
    let mut any_refused = any_refused;
    if let Some(mut fibres) = fibres {
        let images = sim_box.images();
        if let Err(singular) = fibres.displace(model, &state.positions, &images, forces, ctx, fraction * dt, scratch) {
            return Err(Blowup { particle: singular.particle as usize, displacement: f64::NAN });
        }
        any_refused = scratch.iter().any(refused);
    }
    let scratch = &*scratch;
    if any_refused {
        let particle = scratch.iter().position(refused).expect("a refused displacement");
        return Err(Blowup { particle, displacement: scratch[particle].length() });
    }
    state.positions.par_iter_mut().zip(state.images.par_iter_mut()).zip(scratch.par_iter()).with_min_len(1024).for_each(
        |((x, image), d)| {
            *x += *d;
            sim_box.wrap(x, image);
        },
    );
    Ok(fraction)
}

#[cfg(test)]
mod tests {
    use super::{clamp_fraction, step_fraction};
    use glam::DVec3;

    #[test]
    fn the_step_fraction_keeps_drift_plus_noise_within_the_limit() {
        assert_eq!(step_fraction(0.1, 0.2, 0.5), 1.0);
        for (a, b, limit) in [(1.0, 0.0, 0.25), (0.0, 1.0, 0.25), (2.0, 0.5, 0.3), (1e-3, 4.0, 1e-2)] {
            let s = step_fraction(a, b, limit);
            assert!(s > 0.0 && s < 1.0);
            assert!((s * a + s.sqrt() * b - limit).abs() < 1e-12 * limit, "({a}, {b}, {limit}): s = {s}");
        }
        assert_eq!(step_fraction(1.0, 0.0, 0.25), 0.25);
        assert_eq!(step_fraction(0.0, 1.0, 0.25), 0.0625);
    }

    #[test]
    fn clamp_fraction_is_the_largest_safe_scale() {
        let moves = [DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 0.5, 0.0)];
        assert_eq!(clamp_fraction(&moves, &[]), 1.0);
        assert_eq!(clamp_fraction(&moves, &[2.0, f64::INFINITY]), 1.0);
        assert_eq!(clamp_fraction(&moves, &[0.25, 0.5]), 0.25);
        assert_eq!(clamp_fraction(&moves, &[1.0, 0.1]), 0.2);
    }
}
