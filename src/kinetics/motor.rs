#![doc = include_str!("motor.md")]

use super::{kinetic_rule, Effect};
use crate::interactions::ParamSpec;
use crate::units::Dim;

const V0: usize = 0;
const FS: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("v0", Dim::Velocity, "unloaded contraction speed").non_negative(),
    ParamSpec::new("fs", Dim::Force, "stall force").positive(),
];

/// dL0/dt = −v0·(1 − F/Fs) below stall, 0 at and beyond it.
fn rest_length_rate(p: &[f64], force: f64, _kt: f64) -> f64 {
    -p[V0] * (1.0 - force / p[FS]).max(0.0)
}

kinetic_rule!(
    Motor,
    "motor",
    "Contractile motor: rest length shortens at v0·(1 − F/Fs), stalling at Fs",
    Effect::RestLengthRate(rest_length_rate)
);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn linear_force_velocity_with_stall() {
        let p = [2.0, 4.0];
        assert_eq!(rest_length_rate(&p, 0.0, 1.0), -2.0);
        assert_eq!(rest_length_rate(&p, 2.0, 1.0), -1.0);
        assert_eq!(rest_length_rate(&p, 4.0, 1.0), 0.0);
        assert_eq!(rest_length_rate(&p, 9.0, 1.0), 0.0);
    }
}
