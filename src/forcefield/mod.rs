//! Force-field files (`*.ff`): particle types and the interaction types that act
//! between them, each line naming a registered interaction and its parameters.
//!
//! ```text
//! include common.ff                          # path relative to this file
//! particle actin  drag 0.05                  # γ in pN·s/µm, optional radius (µm)
//! particle bead   radius 0.05 viscosity 1e-3 # Stokes drag γ = 6πηa (η in Pa·s)
//! particle point  viscosity 1 fibre 5 points 51  # a fibre's drag shared by its points (Cytosim's)
//! particle anchor fixed                      # never moves (a substrate site)
//! bond  actin_segment  harmonic  k 400 r0 0.1
//! angle actin_bend     wlc_bending kappa 0.07 l0 0.1
//! tetra nucleus        neo_hookean e 1000 nu 0.3   # volume elements ([ tetrahedra ])
//! pair  actin actin    soft_repulsion k 100 sigma 0.05
//! body  cell           turgor k 7e5 dp0 40 v0 4189
//! contact cell cell    contact_barrier dhat 0.1 kappa 100
//! contact cell cell    contact_adhesion w 50 d_on 0.1 d_off 0.4
//! ```
//!
//! Parameters are `name value` pairs in any order, checked against the
//! interaction's schema (`cellmd list NAME`): unknown or repeated names,
//! missing required values, non-finite or out-of-range values and an
//! interaction of the wrong kind are errors at their `file:line:col`.
//! Several `pair` lines for one type pair add up (like LAMMPS `hybrid/overlay`),
//! and so do several `body` lines for one body type (the `type` of a body in
//! the topology's `[ bodies ]`): each line is one many-body term evaluated on
//! every body of that type. A `contact` line names two body types (possibly
//! the same) and a contact term between different bodies of those types: a
//! node–face term (`contact_barrier`) acts between every node of one body and
//! every face of the other, an area-weighted one (`contact_adhesion`) on each
//! face by its corners' distances to the other body. Several `contact` lines
//! for one pair add up (a barrier and an adhesion).
//!
//! A `bond` line may end with kinetic rules (see [`crate::kinetics`]):
//! `bond clutch harmonic k 5 r0 0.02 kinetics catch_slip kc0 10 xc 0.002 ks0 0.05 xs 0.001`.
//! A `bind` line ([`parse_bind`]) lets two particle types form bonds of a
//! bond type during a run.

mod bind;
mod custom;
mod params;
mod parse;

pub use self::bind::{parse_bind, BindLine, BindRule, NO_BODY};
pub use self::custom::{parse_custom, parse_custom_external};
pub use self::params::{
    check_param, param_position, param_value, parse_kinetics, parse_params, parse_values, BondTypeKinetics, TermType, Typed,
};
pub use self::parse::{check_pair_types, load_forcefield, typed, BodyRule, ContactRule, ForceField, PairRule, ParticleType};
