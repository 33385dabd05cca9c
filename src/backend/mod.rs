//! Force backends. [`cpu`] is the reference (f64, deterministic, rayon); the
//! GPU backend must match it within each interaction's declared epsilon.

mod adhesion;
mod bonded;
mod candidates;
mod contact;
mod contact_mesh;
pub mod cpu;
mod newton;
mod nodal_pressure;
mod pair_table;
mod special;
pub mod stiffness;
mod stiffness_blocks;
mod surface;
mod terms;
mod virial;

pub use self::contact::STEP_FRACTION as CONTACT_STEP_FRACTION;
pub use self::cpu::{external_field, CpuBackend, ForceBreakdown, Forces};
pub use self::stiffness_blocks::{RankOneTerm, Stiffness, StiffnessBlock};
pub use self::terms::{Segment, Term, TermKind};
