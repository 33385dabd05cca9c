//! # cellmd — overdamped molecular dynamics whose force fields are cell mechanics
//!
//! Architecture map (data flows top to bottom):
//!
//! | module | role |
//! |---|---|
//! | [`input`] | shared nom lexer for decks, topologies and force fields; `file:line:col` diagnostics |
//! | `deck` | deck commands → validated plan |
//! | `topology` | particles, bonds, angles, triangles, bodies |
//! | `forcefield` | particle/bond/angle/pair types checked against each interaction's schema |
//! | [`interactions`] | the registry: one file per interaction type (its evaluator + docs) |
//! | [`system`] | box and f64 state |
//! | [`neighbor`] | cell list + Verlet list with skin |
//! | [`integrate`] | Philox RNG, overdamped Euler–Maruyama, FIRE |
//! | `backend` | the CPU reference force engine (f64, rayon, deterministic) |
//! | [`output`] | thermo, MCAP, extended XYZ, LAMMPS dump, restart |

pub mod integrate;
pub mod interactions;
pub mod neighbor;
pub mod output;
pub mod system;
pub mod units;
