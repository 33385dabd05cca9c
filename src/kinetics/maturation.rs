#![doc = include_str!("maturation.md")]

use super::{kinetic_rule, Effect};
use crate::interactions::ParamSpec;
use crate::units::Dim;

static PARAMS: [ParamSpec; 1] = [ParamSpec::new("tau", Dim::Time, "maturation time τ_mature").positive()];

/// N(t)/N0 = 1 − exp(−age/τ).
fn scale(p: &[f64], age: f64) -> f64 {
    1.0 - (-age / p[0]).exp()
}

kinetic_rule!(Maturation, "maturation", "Stiffness grows with age as N(t)/N0 = 1 − exp(−t/τ_mature)", Effect::Maturation(scale));
