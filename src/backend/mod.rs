//! Force backends. [`cpu`] is the reference (f64, deterministic, rayon); the
//! GPU backend must match it within each interaction's declared epsilon.

pub mod cpu;
mod sum;

pub use self::cpu::{CpuBackend, ForceBreakdown, Forces};
pub use self::sum::ordered_sum;
