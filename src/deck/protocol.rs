//! Time-dependent protocols of a validated deck: parameter ramps, prescribed
//! motion, per-axis freezes and rest-length resets (LAMMPS `fix adapt`,
//! `fix move linear`, `fix setforce`-style freezes) and driven indenters.
//!
//! A ramp changes one parameter linearly over the next `run`: at the start of
//! step s of an N-step run the parameter is `from + (to − from)·s/N`, so the
//! forces of the run's first step use `from` and the state at its end has
//! seen `to`, which the parameter keeps afterwards. Moves and freezes stay in
//! force until `unmove` / `unfreeze`. The run (`run::protocol`) applies them.

use glam::DVec3;

use super::plan::{CoeffTarget, Group};

/// One parameter changed linearly over the next `run` (`ramp …`).
#[derive(Clone, Debug, PartialEq)]
pub struct Ramp {
    pub target: CoeffTarget,
    /// Index of the parameter in the term's schema.
    pub param: usize,
    pub from: f64,
    pub to: f64,
}

impl Ramp {
    /// The value at `fraction` ∈ [0, 1] of the run.
    pub fn value(&self, fraction: f64) -> f64 {
        if fraction >= 1.0 {
            self.to
        } else {
            self.from + (self.to - self.from) * fraction
        }
    }
}

/// The velocity of a moved group.
#[derive(Clone, Debug)]
pub enum Velocity {
    /// `linear VX VY VZ`: one constant velocity (LAMMPS `fix move linear`).
    Constant(DVec3),
    /// `velocity "VX" "VY" "VZ"`: a velocity field, each component an
    /// expression of the particle's unwrapped position `x`, `y`, `z` and the
    /// simulated time `t` (deck variables folded in), evaluated for every
    /// particle at the start of every step (LAMMPS `fix move variable` with
    /// velocity variables): a step moves a particle by v(x, t)·dt, explicit
    /// Euler along the field's streamlines.
    Field(Box<[crate::expr::Expr; 3]>),
}

impl Velocity {
    /// The velocity of a particle at unwrapped position `x` at time `t`
    /// (NaN components where an expression leaves its domain).
    pub fn at(&self, x: DVec3, t: f64) -> DVec3 {
        match self {
            Self::Constant(v) => *v,
            Self::Field(components) => {
                let value = |e: &crate::expr::Expr| e.eval(&mut |r| crate::system::position_or_time(r, x, t)).unwrap_or(f64::NAN);
                DVec3::new(value(&components[0]), value(&components[1]), value(&components[2]))
            }
        }
    }
}

/// A protocol command, in deck order.
#[derive(Clone, Debug)]
pub enum Protocol {
    /// `ramp …`: applies over the next `run`.
    Ramp(Ramp),
    /// `move GROUP linear VX VY VZ` / `move GROUP velocity "VX" "VY" "VZ"`:
    /// the group's particles move at this velocity every step whatever the
    /// forces on them (which thermo's `fx/GROUP` … still reports: the
    /// reaction of the driven group).
    Move { group: Group, velocity: Velocity },
    /// `unmove GROUP`.
    Unmove(String),
    /// `freeze GROUP x|y|z…`: the group's coordinates along these axes stay
    /// as they are (drift and noise along them are dropped).
    Freeze { group: Group, axes: [bool; 3] },
    /// `unfreeze GROUP`.
    Unfreeze(String),
    /// `reset_rest BONDTYPE|all`: every bond of these bond types (indices
    /// into `Model::bond_types`) takes its current length as its rest length.
    ResetRest(Vec<usize>),
    /// `indent NAME velocity VX VY VZ [until LOAD]` / `indent NAME stop`:
    /// the centre (`x y z`) of the active external NAME (an `indenter` or
    /// `flat_punch`) moves at `velocity` every step; with `until`, it stops
    /// for good where its load (the magnitude of its summed force on its
    /// group) first reaches LOAD and holds there. A zero velocity stops it.
    Indent { external: String, velocity: DVec3, until: Option<f64> },
}
