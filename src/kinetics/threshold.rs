#![doc = include_str!("threshold.md")]

use super::{kinetic_rule, Effect};
use crate::interactions::ParamSpec;
use crate::units::Dim;

const STRAIN: usize = 0;
const FORCE: usize = 1;
const SPREAD: usize = 2;
const RATE: usize = 3;

static PARAMS: [ParamSpec; 4] = [
    ParamSpec::new("strain", Dim::Dimensionless, "strain threshold |L − L0|/L0 (0: no strain criterion)").non_negative().default(0.0),
    ParamSpec::new("force", Dim::Force, "tension threshold (0: no force criterion)").non_negative().default(0.0),
    ParamSpec::new("spread", Dim::Dimensionless, "per-bond disorder: threshold × (1 + spread·(u − ½)), u uniform per bond")
        .non_negative()
        .at_most(2.0)
        .default(0.0),
    ParamSpec::new("rate", Dim::Rate, "break rate above threshold (0: break at once)").non_negative().default(0.0),
];

/// The break rate of a bond beyond its threshold (infinite: now), or `None` below it.
pub(crate) fn beyond(p: &[f64], force: f64, strain: f64, u: f64) -> Option<f64> {
    let factor = 1.0 + p[SPREAD] * (u - 0.5);
    let over_strain = p[STRAIN] > 0.0 && strain.abs() > p[STRAIN] * factor;
    let over_force = p[FORCE] > 0.0 && force > p[FORCE] * factor;
    (over_strain || over_force).then(|| if p[RATE] > 0.0 { p[RATE] } else { f64::INFINITY })
}

/// The strain threshold of a deterministic strain-only rule (no force
/// criterion, no spread, breaking at once), which LAMMPS `fix bond/break`
/// can express; `None` otherwise.
pub(crate) fn deterministic_strain(p: &[f64]) -> Option<f64> {
    (p[STRAIN] > 0.0 && p[FORCE] == 0.0 && p[SPREAD] == 0.0 && p[RATE] == 0.0).then_some(p[STRAIN])
}

fn validate(p: &[f64]) -> Result<(), String> {
    if p[STRAIN] == 0.0 && p[FORCE] == 0.0 {
        return Err("a `strain` or `force` threshold > 0".into());
    }
    Ok(())
}

kinetic_rule!(
    Threshold,
    "threshold",
    "Break when strain or tension exceeds a (per-bond disordered) threshold",
    Effect::Threshold(beyond),
    validate = validate
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thresholds() {
        let p = [0.5, 0.0, 0.0, 0.0];
        assert_eq!(beyond(&p, 100.0, 0.49, 0.3), None);
        assert_eq!(beyond(&p, 0.0, -0.51, 0.3), Some(f64::INFINITY));
        // Uniform thresholds on [0, 1]: value ½, spread 2.
        let q = [0.5, 0.0, 2.0, 0.0];
        assert_eq!(beyond(&q, 0.0, 0.2, 0.1), Some(f64::INFINITY));
        assert_eq!(beyond(&q, 0.0, 0.2, 0.3), None);
        let r = [0.0, 3.0, 0.0, 7.0];
        assert_eq!(beyond(&r, 3.5, 0.0, 0.5), Some(7.0));
        assert!(validate(&[0.0, 0.0, 0.0, 0.0]).is_err());
        assert_eq!(deterministic_strain(&p), Some(0.5));
        assert_eq!(deterministic_strain(&q), None);
        assert_eq!(deterministic_strain(&r), None);
    }
}
