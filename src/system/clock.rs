//! The clock of the step a run has just integrated.
//!
//! Simulated time advances by the length each step actually took: `dt`, or
//! less where the contact clamp shortened the step (see
//! `integrate::overdamped`), and a deck may change `timestep` between runs.
//! Everything that stamps or ages with time — kinetic event times, bond ages,
//! the rates' per-step probabilities 1 − exp(−k·Δt), the lifetime
//! correction — reads it from one [`StepClock`], which the run's step
//! context (`integrate::context`) returns as it advances the state's time by
//! the fraction of dt the integrator took, so event times always equal
//! thermo times.

/// The step just integrated: its index, when it started and how long it took.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepClock {
    /// Index of the step (the state's step counter before it).
    pub step: u64,
    /// Simulated time at the start of the step (the thermo time of `step`).
    pub start: f64,
    /// The step's actual length Δt: the fraction of dt the integrator took × dt.
    pub length: f64,
    /// The thermal energy kT the step ran at (the rates of kinetic rules read it).
    pub kt: f64,
    /// Seed of the step's random streams.
    pub seed: u64,
}
