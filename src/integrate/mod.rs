//! Integrators and their random numbers.

pub mod constraints;
pub mod fire;
pub mod implicit;
pub mod overdamped;
pub mod system_matrix;
