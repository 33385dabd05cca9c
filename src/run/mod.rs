//! Executes a validated deck ([`crate::deck::Plan`]).

mod blowup;
mod protocol;
mod simulation;
pub mod thermo;

pub use self::blowup::RunError;
pub use self::simulation::{RunOptions, Simulation};
