//! Shared physics checks run on every interaction type (CONVENTIONS §5).
//!
//! Each [`Law`] is viewed as a function of the positions of its particles,
//! E(r₁…rₙ) with forces f₁…fₙ, and checked for:
//! - F = −∇E by central differences (relative error < 1e-6 of the force scale);
//! - Σf = 0 and Σ r×f = 0 (momentum and angular momentum) when the law is internal;
//! - translation and rotation invariance of the energy (internal laws);
//! - zero force at the rest configuration the caller names;
//! - for [`Law::Radial`], d²E/dr² against a central difference of dE/dr.

use glam::{DMat3, DVec3};

pub use super::Interaction;
use super::Law;

/// Energy and per-particle forces of `law` at `positions` (1, 2 or 3 particles).
pub fn evaluate(law: Law, params: &[f64], positions: &[DVec3]) -> (f64, Vec<DVec3>) {
    match law {
        Law::Radial { eval, .. } => {
            let d = positions[1] - positions[0];
            let r = d.length();
            let out = eval(params, r);
            let f_j = -out.de_dr * d / r;
            (out.energy, vec![-f_j, f_j])
        }
        Law::ThreeBody(eval) => {
            let out = eval(params, [positions[0], positions[1], positions[2]]);
            (out.energy, out.forces.to_vec())
        }
        Law::OneBody(eval) => {
            let out = eval(params, positions[0]);
            (out.energy, vec![out.force])
        }
    }
}

/// Resolves a name=value list against the schema, filling defaults.
pub fn params_of(interaction: &dyn Interaction, values: &[(&str, f64)]) -> Vec<f64> {
    let params: Vec<f64> = interaction
        .params()
        .iter()
        .map(|spec| {
            values
                .iter()
                .find(|(n, _)| *n == spec.name)
                .map(|(_, v)| *v)
                .or(spec.default)
                .unwrap_or_else(|| panic!("{}: test gives no `{}`", interaction.name(), spec.name))
        })
        .collect();
    for (spec, v) in interaction.params().iter().zip(&params) {
        spec.check(*v).unwrap();
    }
    interaction.validate(&params).unwrap();
    params
}

fn largest_force(forces: &[DVec3]) -> f64 {
    forces.iter().map(|f| f.length()).fold(0.0, f64::max)
}

/// F = −∇E by central differences with step `h` (length units).
///
/// Passes when every component agrees to `1e-6 × max(|F|max, force_floor)`.
pub fn assert_force_is_minus_gradient(interaction: &dyn Interaction, params: &[f64], positions: &[DVec3], h: f64, force_floor: f64) {
    let law = interaction.law();
    let (_, forces) = evaluate(law, params, positions);
    let scale = largest_force(&forces).max(force_floor);
    for (p, f) in forces.iter().enumerate() {
        for axis in 0..3 {
            let mut plus = positions.to_vec();
            let mut minus = positions.to_vec();
            plus[p][axis] += h;
            minus[p][axis] -= h;
            let numeric = -(evaluate(law, params, &plus).0 - evaluate(law, params, &minus).0) / (2.0 * h);
            let err = (numeric - f[axis]).abs() / scale;
            assert!(
                err < 1e-6,
                "{}: F = -grad E fails on particle {p} axis {axis}: analytic {} numeric {numeric} (rel. err {err:e}) at {positions:?}",
                interaction.name(),
                f[axis]
            );
        }
    }
}

/// Σf = 0 and Σ r×f = 0 (internal forces conserve momentum and angular momentum).
pub fn assert_momentum_conserved(interaction: &dyn Interaction, params: &[f64], positions: &[DVec3]) {
    let (_, forces) = evaluate(interaction.law(), params, positions);
    let scale = largest_force(&forces).max(f64::MIN_POSITIVE);
    let sum: DVec3 = forces.iter().sum();
    assert!(sum.length() / scale < 1e-12, "{}: sum of forces {sum:?}", interaction.name());
    let centre = positions.iter().sum::<DVec3>() / positions.len() as f64;
    let size = positions.iter().map(|p| (*p - centre).length()).fold(0.0, f64::max);
    let torque: DVec3 = positions.iter().zip(&forces).map(|(p, f)| (*p - centre).cross(*f)).sum();
    assert!(torque.length() / (scale * size) < 1e-12, "{}: net torque {torque:?}", interaction.name());
}

/// E is unchanged by a translation and by a rotation of all positions.
pub fn assert_invariant_under_rigid_motion(interaction: &dyn Interaction, params: &[f64], positions: &[DVec3]) {
    let law = interaction.law();
    let (e0, f0) = evaluate(law, params, positions);
    let shift = DVec3::new(0.37, -1.21, 2.03);
    let rotation = DMat3::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.813);
    let moved: Vec<DVec3> = positions.iter().map(|p| rotation * *p + shift).collect();
    let (e1, f1) = evaluate(law, params, &moved);
    let tol = 1e-12 * e0.abs().max(1.0);
    assert!((e1 - e0).abs() < tol, "{}: energy changed under rigid motion: {e0} -> {e1}", interaction.name());
    let scale = largest_force(&f0).max(f64::MIN_POSITIVE);
    for (a, b) in f0.iter().zip(&f1) {
        assert!((rotation * *a - *b).length() / scale < 1e-10, "{}: forces do not rotate with the system", interaction.name());
    }
}

/// All forces vanish at a rest configuration.
pub fn assert_zero_force_at_rest(interaction: &dyn Interaction, params: &[f64], rest: &[DVec3], force_scale: f64) {
    let (_, forces) = evaluate(interaction.law(), params, rest);
    let worst = largest_force(&forces);
    assert!(worst <= 1e-9 * force_scale, "{}: force {worst} at rest {rest:?}", interaction.name());
}

/// For a radial law, d²E/dr² matches a central difference of dE/dr at `r`.
pub fn assert_radial_curvature(interaction: &dyn Interaction, params: &[f64], r: f64, h: f64) {
    let Law::Radial { eval, .. } = interaction.law() else { panic!("{} is not radial", interaction.name()) };
    let numeric = (eval(params, r + h).de_dr - eval(params, r - h).de_dr) / (2.0 * h);
    let analytic = eval(params, r).d2e_dr2;
    let scale = analytic.abs().max(numeric.abs()).max(1e-300);
    assert!((analytic - numeric).abs() / scale < 1e-5, "{}: d2E/dr2 at r = {r}: analytic {analytic} numeric {numeric}", interaction.name());
}

/// Runs every generic check appropriate to the law at `positions`.
///
/// `internal` is false for external fields (which need not conserve momentum).
pub fn assert_all_checks(interaction: &dyn Interaction, params: &[f64], positions: &[DVec3], h: f64, force_floor: f64) {
    assert_force_is_minus_gradient(interaction, params, positions, h, force_floor);
    if !matches!(interaction.law(), Law::OneBody(_)) {
        assert_momentum_conserved(interaction, params, positions);
        assert_invariant_under_rigid_motion(interaction, params, positions);
    }
    if matches!(interaction.law(), Law::Radial { .. }) {
        assert_radial_curvature(interaction, params, (positions[1] - positions[0]).length(), h);
    }
}
