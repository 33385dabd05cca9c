#![doc = include_str!("rebind.md")]

use super::{kinetic_rule, Effect};
use crate::interactions::ParamSpec;
use crate::units::Dim;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("k_on", Dim::Rate, "binding rate of an unbound bond within capture").non_negative(),
    ParamSpec::new("capture", Dim::Length, "capture radius: rebinding needs L < capture").positive(),
];

fn on_rate(p: &[f64]) -> (f64, f64) {
    (p[0], p[1])
}

kinetic_rule!(Rebind, "rebind", "An unbound bond whose ends are within the capture radius rebinds at rate k_on", Effect::Rebind(on_rate));
