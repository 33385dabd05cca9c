//! The bond-kinetics engine: after every force pass it applies the kinetic
//! rules of each bond type (the registry in [`crate::kinetics`]) to the bond
//! state ([`crate::system::BondState`]), and forms new bonds from `bind`
//! rules.

mod engine;
mod events;
mod formation;

pub use self::engine::{initial_bond_state, Kinetics, KineticsReport, COARSE_RATE_DT, STREAM_KINETICS, STREAM_QUENCHED};
pub use self::events::{Event, EventKind};
pub use self::formation::{Binding, Formation, FORMATION_SALT};
