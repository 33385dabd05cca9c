//! Integrators: the explicit overdamped step, the linearly implicit step,
//! bond constraints, and FIRE and Newton minimisation. Their random numbers come from the
//! leaf module `rng`.

pub mod constraints;
pub mod context;
pub mod fire;
pub mod implicit;
pub mod newton;
pub mod overdamped;
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
