//! Executes a validated deck ([`crate::deck::Plan`]), stops it cleanly on
//! request ([`StopSignal`]) and continues it from a restart
//! ([`Simulation::resume`]).

mod blowup;
mod protocol;
mod simulation;
mod stop;
pub mod thermo;

pub use self::blowup::{RunError, OUTPUT_ERROR_STATUS};
pub use self::simulation::{ActiveRun, Backends, BondTable, KineticsState, Reports, RunOptions, Settings, Simulation};
pub use self::stop::{StopReason, StopSignal, STOPPED_STATUS};
