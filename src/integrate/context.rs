//! The step context: what every step of a run reads, made by the run for
//! each step from the deck's settings in force and the state's clock.
//!
//! Integrators (explicit and implicit), constraints, FIRE, the GPU host path,
//! thermo and outputs read dt, kT, the seed, the noise kind, the step index
//! and the simulated time from one [`StepContext`] instead of loose
//! arguments, and simulated time advances in one place,
//! [`StepContext::advance`], by the length the step actually took (dt, or
//! less where the contact clamp shortened it). The [`StepClock`] it returns
//! is what the consumers after the step (bond kinetics, lifetimes) read.

use crate::rng::Noise;
use crate::system::{State, StepClock};

/// The settings and clock of the step about to be taken.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepContext {
    /// The deck's timestep (time units).
    pub dt: f64,
    /// Thermal energy kT (energy units; 0: deterministic).
    pub kt: f64,
    /// Seed of the counter-based random streams.
    pub seed: u64,
    /// Distribution of the Brownian noise.
    pub noise: Noise,
    /// Largest displacement of one particle in one step before the run is
    /// stopped as blown up (length units).
    pub max_displacement: f64,
    /// Index of the step (the state's step counter before it).
    pub step: u64,
    /// Simulated time at its start.
    pub time: f64,
}

impl Default for StepContext {
    fn default() -> Self {
        Self { dt: 0.0, kt: 0.0, seed: 1, noise: Noise::Uniform, max_displacement: 1.0, step: 0, time: 0.0 }
    }
}

impl StepContext {
    /// Ends the step in `state` after the integrator took `fraction` of dt:
    /// the step counter and the simulated time advance (the only place they
    /// do). Returns the step's clock.
    pub fn advance(&self, state: &mut State, fraction: f64) -> StepClock {
        let clock = StepClock { step: self.step, start: self.time, length: fraction * self.dt, kt: self.kt, seed: self.seed };
        state.step = self.step + 1;
        state.time = self.time + clock.length;
        clock
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn a_step_advances_the_clock_by_the_length_it_took() {
        let mut state = State::new(vec![DVec3::ZERO]);
        state.step = 41;
        state.time = 2.0;
        let ctx = StepContext { dt: 0.5, kt: 3.0, seed: 9, step: state.step, time: state.time, ..Default::default() };
        let clock = ctx.advance(&mut state, 0.25);
        assert_eq!(clock, StepClock { step: 41, start: 2.0, length: 0.125, kt: 3.0, seed: 9 });
        assert_eq!((state.step, state.time), (42, 2.125));
    }
}
