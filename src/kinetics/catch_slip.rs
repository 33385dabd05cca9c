#![doc = include_str!("catch_slip.md")]

use super::{kinetic_rule, Effect};
use crate::interactions::ParamSpec;
use crate::units::Dim;

const KC0: usize = 0;
const XC: usize = 1;
const KS0: usize = 2;
const XS: usize = 3;

static PARAMS: [ParamSpec; 4] = [
    ParamSpec::new("kc0", Dim::Rate, "catch-pathway off-rate at zero force").non_negative(),
    ParamSpec::new("xc", Dim::Length, "catch-pathway distance (force suppresses this pathway)").non_negative(),
    ParamSpec::new("ks0", Dim::Rate, "slip-pathway off-rate at zero force").non_negative(),
    ParamSpec::new("xs", Dim::Length, "slip-pathway distance (force accelerates this pathway)").non_negative(),
];

/// k_off(F) = kc0·exp(−F·xc/kT) + ks0·exp(F·xs/kT), F = max(tension, 0).
pub(crate) fn rate(p: &[f64], force: f64, kt: f64) -> f64 {
    let f = force.max(0.0);
    p[KC0] * (-f * p[XC] / kt).exp() + p[KS0] * (f * p[XS] / kt).exp()
}

kinetic_rule!(
    CatchSlip,
    "catch_slip",
    "Pereverzev two-pathway catch-slip bond k_off = kc0·e^(−F·xc/kT) + ks0·e^(F·xs/kT)",
    Effect::Unbind(rate)
);

#[cfg(test)]
mod tests {
    use super::*;

    /// Oracle: the force of longest lifetime, F* = kT·ln(kc0·xc/(ks0·xs))/(xc + xs).
    fn longest_lifetime_force(p: &[f64], kt: f64) -> f64 {
        kt * (p[KC0] * p[XC] / (p[KS0] * p[XS])).ln() / (p[XC] + p[XS])
    }

    #[test]
    fn rate_is_smallest_at_the_analytic_force() {
        let p = [10.0, 2.0, 0.05, 1.0];
        let kt = 4.114;
        let f_star = longest_lifetime_force(&p, kt);
        assert!(f_star > 0.0);
        // Golden-section search on the runtime rate function.
        let (mut a, mut b) = (0.0, 10.0 * f_star);
        let g = (5f64.sqrt() - 1.0) / 2.0;
        for _ in 0..200 {
            let (c, d) = (b - g * (b - a), a + g * (b - a));
            if rate(&p, c, kt) < rate(&p, d, kt) {
                b = d;
            } else {
                a = c;
            }
        }
        assert!(((a + b) / 2.0 - f_star).abs() < 1e-6 * f_star, "numeric {} analytic {f_star}", (a + b) / 2.0);
    }
}
