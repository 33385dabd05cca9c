#![doc = include_str!("cadherin.md")]

use super::{kinetic_rule, Effect};
use crate::interactions::ParamSpec;
use crate::units::Dim;

static PARAMS: [ParamSpec; 8] = [
    ParamSpec::new("k10", Dim::Rate, "dissociation rate from the native state B1 at zero force").non_negative(),
    ParamSpec::new("x1", Dim::Length, "force sensitivity of B1 dissociation").non_negative(),
    ParamSpec::new("ks0", Dim::Rate, "sliding rate B1 → B2 at zero force").non_negative(),
    ParamSpec::new("xs", Dim::Length, "force sensitivity of sliding (force promotes it)").non_negative(),
    ParamSpec::new("kr0", Dim::Rate, "rebinding rate B2 → B1 at zero force").non_negative(),
    ParamSpec::new("xr", Dim::Length, "force sensitivity of rebinding (force suppresses it)").non_negative(),
    ParamSpec::new("k20", Dim::Rate, "dissociation rate from the slid state B2 at zero force").non_negative(),
    ParamSpec::new("x2", Dim::Length, "force sensitivity of B2 dissociation").non_negative(),
];

/// The four Bell rates (k1, ks, kr, k2) of the three-state generator at force F ≥ 0.
fn rates(p: &[f64], f: f64, kt: f64) -> [f64; 4] {
    let bell = |k0: f64, x: f64, sign: f64| k0 * (sign * f * x / kt).exp();
    [bell(p[0], p[1], 1.0), bell(p[2], p[3], 1.0), bell(p[4], p[5], -1.0), bell(p[6], p[7], 1.0)]
}

/// Effective off-rate: the inverse mean first-passage time from B1 to U of
/// the generator (exact for the 3-state chain, solved in closed form):
/// k_eff = (k1·(kr + k2) + ks·k2) / (kr + k2 + ks).
pub(crate) fn rate(p: &[f64], force: f64, kt: f64) -> f64 {
    let [k1, ks, kr, k2] = rates(p, force.max(0.0), kt);
    (k1 * (kr + k2) + ks * k2) / (kr + k2 + ks)
}

fn validate(p: &[f64]) -> Result<(), String> {
    if p[0] + p[2] == 0.0 {
        return Err("k10 + ks0 > 0 (a bond that can never leave B1 never breaks)".into());
    }
    Ok(())
}

kinetic_rule!(
    Cadherin,
    "cadherin",
    "Sliding–rebinding cadherin catch bond: exact effective off-rate of a 3-state (B1, B2, unbound) generator",
    Effect::Unbind(rate),
    validate = validate
);

#[cfg(test)]
mod tests {
    use super::*;

    /// Mean first-passage time from B1 by solving the generator numerically.
    fn mfpt(p: &[f64], f: f64, kt: f64) -> f64 {
        let [k1, ks, kr, k2] = rates(p, f, kt);
        // Q_T τ = −1 with Q_T = [[−(k1+ks), ks], [kr, −(kr+k2)]]: Cramer's rule.
        let (a, b, c, d) = (-(k1 + ks), ks, kr, -(kr + k2));
        let det = a * d - b * c;
        (-d + b) / det
    }

    #[test]
    fn closed_form_matches_the_generator_and_shows_a_catch() {
        let p = [1.0, 0.0008, 0.05, 0.003, 1.0, 0.002, 0.01, 0.0008];
        let kt = 4.114e-3;
        for f in [0.0, 2.0, 5.0, 10.0, 30.0, 60.0] {
            let k = rate(&p, f, kt);
            assert!((k * mfpt(&p, f, kt) - 1.0).abs() < 1e-12, "F = {f}");
        }
        // Force first lengthens the lifetime (catch), then shortens it (slip).
        let lifetime = |f: f64| 1.0 / rate(&p, f, kt);
        // τ ≈ 1.05 s at 0 pN, 13 s at 10 pN, 0.29 s at 30 pN.
        assert!(lifetime(10.0) > 10.0 * lifetime(0.0));
        assert!(lifetime(30.0) < lifetime(0.0));
    }
}
