//! Measurements read from a configuration and its force terms: per-particle
//! stress, plane and cortical tension, filament statistics, sheet fracture,
//! fibre clustering.
//!
//! They are computed by the CPU reference backend at output steps only (on
//! GPU runs after the positions come back), from the decomposition of every
//! force term into segments ([`Term`](crate::backend::Term)), so that each
//! quantity is consistent with the virial and the forces of the same step.
//!
//! | quantity | where | module |
//! |---|---|---|
//! | per-particle virial W_i, stress S_i = −W_i, von Mises | LAMMPS dump columns `wxx`…`wyz`, `sxx`…`syz`, `vonmises` | [`stress`] |
//! | per-bond tension and length | `dump NAME every N bonds FILE.csv` | `output::bond_csv` |
//! | force across a plane | thermo `planetension/AXIS/POS` | [`planes`] |
//! | cortical tension γ (method of planes) | thermo `gamma/BODYTYPE` | [`planes`] |
//! | end-to-end distance, tangent correlation | thermo `e2e/BONDTYPE`, `tcorr/BONDTYPE/LAG` | [`filaments`] |
//! | fibre clustering between two cells, S_max/S_min | thermo `clustering/BONDTYPE/GROUP_A/GROUP_B` | [`clustering`] |
//! | sheet fracture: broken junctions, rearrangements, crack, pieces, ductile/brittle | thermo `fracture/BONDTYPE/QUANTITY` | [`fracture`] |

pub mod clustering;
pub mod filaments;
pub mod fracture;
pub mod planes;
pub mod stress;

pub use self::planes::{cortical_tension, plane_tension};
pub use self::stress::{per_particle_virial, von_mises};
