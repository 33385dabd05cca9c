//! # cellmd — overdamped molecular dynamics whose force fields are cell mechanics
//!
//! Architecture map (data flows top to bottom). The modules are layered: a
//! module imports only modules of the layers before its own, in this order:
//! leaves (`units`, `expr`, `input`, `rng`, `mesh`), then `hessian`,
//! `interactions`, `kinetics`, `forcefield`, `topology`, `system`,
//! `neighbor`, `backend`, `integrate`, `kinetics_engine`, `measure`,
//! `output`, `gpu`, `deck`, `run`, `export`, `compare`, `build`, `manual`, `cli`.
//! `tests/suite/architecture.rs` fails on any cycle among them.
//!
//! | module | role |
//! |---|---|
//! | [`expr`] | expression trees (parse with spans → evaluate): deck variables, loop bounds, `if` conditions |
//! | [`input`] | shared nom lexer for decks, topologies and force fields; `file:line:col` diagnostics; inputs recorded for restarts |
//! | [`deck`] | deck commands → validated [`deck::Plan`] |
//! | [`topology`] | particles, bonds, angles, triangles, bodies (checked: closed, oriented, sphere topology) |
//! | [`mesh`] | closed triangulated surfaces: edges and wings, volume, area, bending angles, the icosphere |
//! | [`hessian`] | local Hessians (finite differences, PSD projection) and surface terms' second-order models for the implicit step |
//! | [`forcefield`] | particle/bond/angle/pair types checked against each interaction's schema; `bind` lines |
//! | [`interactions`] | the registry: one file per interaction type (its evaluator + docs) |
//! | [`system`] | box, f64 state (with the bond state) and the resolved [`system::Model`] |
//! | [`neighbor`] | cell list + Verlet list with skin, exclusions |
//! | [`rng`] | counter-based Philox4x32-10 streams and noise (a leaf: imports nothing of the crate) |
//! | [`integrate`] | the integrator choice: overdamped Euler–Maruyama, the linearly implicit step, constraints, FIRE |
//! | [`kinetics`] | the kinetic-rule registry (one file per rule, like interactions): force-dependent unbinding, rebinding, motors, ratchets, plasticity, maturation |
//! | [`kinetics_engine`] | applies the rules to the bond state every step, forms bonds from `bind` lines, bond events |
//! | [`backend`] | the CPU reference force engine (f64, rayon, deterministic) |
//! | [`measure`] | per-particle stress, plane and cortical tension, filament statistics (thermo columns, dump fields) |
//! | [`output`] | MCAP, extended XYZ, LAMMPS dump (selectable columns), per-bond tension CSV, bond events and lifetimes, restart (carrying the deck's inputs), run log |
//! | [`export`] | a deck as LAMMPS data + input (`cellmd export-lammps`) |
//! | [`compare`] | cellmd vs LAMMPS probes, agreement table, golden reference files (`cellmd compare`) |
//! | [`build`] | topology generators (`cellmd build`: icosphere, filament, network, aster, cortex, branched, filopodium, cells, sheet, tensegrity) |
//! | [`run`] | executes a plan: run loop, thermo, blow-up diagnosis, minimise; clean stop on signals, `--continue` from a restart |
//! | [`manual`] | the user manual's pages generated from the registries, the command table and `inputs/` (`cellmd docs`) |
//! | [`cli`] | the `cellmd` command line (the binary and the Python package's console script call [`cli::main`]) |

pub mod backend;
pub mod build;
pub mod cli;
pub mod compare;
pub mod deck;
pub mod export;
pub mod expr;
pub mod forcefield;
pub mod gpu;
pub mod hessian;
pub mod input;
pub mod integrate;
pub mod interactions;
pub mod kinetics;
pub mod kinetics_engine;
pub mod manual;
pub mod measure;
pub mod mesh;
pub mod neighbor;
pub mod output;
pub mod rng;
pub mod run;
pub mod system;
pub mod topology;
pub mod units;
