//! Integrators and their random numbers.

pub mod rng;
