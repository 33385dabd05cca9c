#![doc = include_str!("ratchet.md")]

use super::{kinetic_rule, Effect};
use crate::interactions::ParamSpec;
use crate::units::Dim;

const V0: usize = 0;
const DELTA: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("v0", Dim::Velocity, "free polymerisation speed").non_negative(),
    ParamSpec::new("delta", Dim::Length, "monomer step δ (2.7 nm for actin)").positive(),
];

/// dL0/dt = v0·exp(−f·δ/kT) with f = max(−F, 0) the compressive load.
fn rest_length_rate(p: &[f64], force: f64, kt: f64) -> f64 {
    let load = (-force).max(0.0);
    p[V0] * (-load * p[DELTA] / kt).exp()
}

kinetic_rule!(
    Ratchet,
    "ratchet",
    "Polymerisation ratchet: tip segment grows at v0·exp(−f·δ/kT) against load f",
    Effect::RestLengthRate(rest_length_rate),
    needs_temperature = true
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn load_slows_growth_exponentially() {
        let p = [1.0, 0.5];
        assert_eq!(rest_length_rate(&p, 3.0, 2.0), 1.0); // tension is no load
        assert!((rest_length_rate(&p, -4.0, 2.0) - (-1.0f64).exp()).abs() < 1e-15);
    }
}
