//! Topology files (`*.top`): particles, bonds, angles, bodies and triangles.
//!
//! GROMACS-like sections, one record per line, `#` comments:
//!
//! ```text
//! [ box ]              # optional; the deck's `box` command overrides it
//! x  -5 5 p            # axis lo hi p|f   (periodic or fixed), length units
//! y  -5 5 p
//! z   0 10 f
//! [ particles ]
//! # id  type   x     y     z     [body]
//! 1     actin  0.0   0.0   0.5
//! 2     actin  0.1   0.0   0.5
//! [ bonds ]
//! # type           i  j  [r0]    (particle ids; r0: this bond's own rest length)
//! actin_segment    1  2
//! actin_segment    2  3  0.1047
//! [ angles ]
//! # type           i  j  k       (j is the vertex)
//! [ bodies ]
//! # id  type                     (closed surfaces: a cell, a nucleus)
//! [ triangles ]
//! # body  i  j  k                (outward-wound face of that body: counter-clockwise seen from outside)
//! [ tetrahedra ]
//! # type  i  j  k  l             (a volume element; its rest shape is where [ particles ] places it)
//! ```
//!
//! Particle ids are any distinct positive integers; types are names defined in
//! the force field. Names of particle, bond, angle and tetra types are resolved
//! against the force field when the deck is validated, so unknown names are
//! reported at their position in this file.
//!
//! A bond line may end with the bond's own rest length r0 (length units: µm
//! under `units cell`; a positive finite number). It replaces the bond type's
//! `r0` for that bond alone, everywhere a rest length is used; it is the
//! bond's initial rest length in its state (`system::BondState::rest`), so kinetic
//! rules that move the rest length (plastic reset, motor, ratchet) start from
//! it. Only a bond type whose law has an `r0` parameter accepts one (checked
//! when the deck is validated, at the value's position). `cellmd build …
//! --rest-from-geometry` writes every bond's length as built here, so an
//! irregular mesh starts force-free.
//!
//! A `[ tetrahedra ]` line names a `tetra` type of the force field and four
//! particles: a volume element whose rest shape is its corners as written
//! here (either winding; a degenerate element is refused when the deck is
//! validated). An element across a periodic boundary is written unwrapped
//! (its corners contiguous, not wrapped into the box).
//!
//! Each body must be a closed, consistently oriented 2-manifold of sphere
//! topology (every edge in exactly two faces, once in each direction; one fan
//! of faces around each vertex; connected; Euler characteristic 2): see
//! `src/topology/surface.rs` for the checks and their messages, which name
//! the offending face at its line.

mod merge;
mod parse;
mod surface;
mod types;

pub use self::merge::Clash;
pub use self::parse::{parse_box_axis, parse_topology};
pub use self::types::{BoxAxis, Topology, TypedTerm};
