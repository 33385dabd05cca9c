//! Simulation state: the box and the per-particle arrays (f64, structure of arrays).

mod bond_state;
mod clock;
mod model;
mod selftest;
mod sim_box;
mod state;

pub use self::bond_state::{BondState, FormedBond};
pub use self::clock::StepClock;
pub use self::model::{position_or_time, registry_index, Body, External, Model, SpecialBonds};
pub use self::selftest::{check_custom_terms, custom_warnings};
pub use self::sim_box::{Images, SimBox};
pub use self::state::State;
