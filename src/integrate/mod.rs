//! Integrators and their random numbers.

pub mod constraints;
pub mod context;
pub mod fire;
pub mod implicit;
pub mod overdamped;
pub mod rng;
pub mod system_matrix;
