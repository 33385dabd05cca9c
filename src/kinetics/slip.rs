#![doc = include_str!("slip.md")]

use super::{kinetic_rule, Effect};
use crate::interactions::ParamSpec;
use crate::units::Dim;

const K0: usize = 0;
const X_BETA: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("k0", Dim::Rate, "off-rate at zero force").non_negative(),
    ParamSpec::new("x_beta", Dim::Length, "distance to the transition state xβ").non_negative(),
];

/// k_off(F) = k0·exp(|F|·xβ/kT).
pub(crate) fn rate(p: &[f64], force: f64, kt: f64) -> f64 {
    p[K0] * (force.abs() * p[X_BETA] / kt).exp()
}

kinetic_rule!(Slip, "slip", "Bell slip bond k_off = k0·exp(|F|·xβ/kT)", Effect::Unbind(rate));

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bell_rate() {
        let p = [2.0, 0.5];
        assert_eq!(rate(&p, 0.0, 1.0), 2.0);
        assert!((rate(&p, 4.0, 1.0) - 2.0 * 2f64.exp()).abs() < 1e-12);
        assert_eq!(rate(&p, -4.0, 1.0), rate(&p, 4.0, 1.0));
    }
}
