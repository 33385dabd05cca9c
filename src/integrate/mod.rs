//! Integrators: the explicit overdamped step, the linearly implicit step,
//! bond constraints, and FIRE and Newton minimisation. Their random numbers come from the
//! leaf module `rng`.
//!
//! Inextensible fibres and the banded blocks of elastic chains are solved
//! fibre by fibre in [`fibre`], which both steps call.
//!
//! One file-level circle, on purpose: `implicit.rs` ↔ `projected_cg.rs`.
//! The constrained solve of the implicit step lives in its own file (it is
//! half the step's length) and reads the step's settings, constraint list
//! and error type, which belong to `implicit`, whose callers use them.

pub mod constraints;
pub mod context;
pub mod fibre;
pub mod fire;
pub mod implicit;
pub mod newton;
pub mod overdamped;
mod projected_cg;
pub mod system_matrix;

use self::implicit::ImplicitSettings;
use self::overdamped::OverdampedSettings;

/// The step a deck chose (`integrator overdamped|implicit …`), with its
/// options; both steps share the noise kind and the displacement limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Integrator {
    /// Explicit Euler–Maruyama ([`overdamped`]).
    Overdamped(OverdampedSettings),
    /// The linearly implicit step ([`implicit`]) and its linear solver.
    Implicit(OverdampedSettings, ImplicitSettings),
}

impl Integrator {
    /// The options both steps share.
    pub fn common(&self) -> &OverdampedSettings {
        match self {
            Integrator::Overdamped(settings) | Integrator::Implicit(settings, _) => settings,
        }
    }
}

impl Default for Integrator {
    fn default() -> Self {
        Integrator::Overdamped(OverdampedSettings::default())
    }
}
