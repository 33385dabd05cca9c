#![doc = include_str!("plastic.md")]

use super::{kinetic_rule, Effect};
use crate::interactions::ParamSpec;
use crate::units::Dim;

static PARAMS: [ParamSpec; 1] =
    [ParamSpec::new("threshold", Dim::Dimensionless, "relative length change |L − L0|/L0 that triggers a reset").positive()];

fn threshold(p: &[f64]) -> f64 {
    p[0]
}

kinetic_rule!(Plastic, "plastic", "Plastic reset: when |L − L0|/L0 exceeds a threshold, L0 becomes L", Effect::PlasticReset(threshold));
