#![doc = include_str!("wlc_bending.md")]

use glam::DVec3;

use super::lammps::{bonded, num, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, ThreeBody};
use crate::units::Dim;

const KAPPA: usize = 0;
const L0: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("kappa", Dim::BendingModulus, "bending modulus κ = kT·Lp (actin: ≈ 0.07 pN·µm²)").non_negative(),
    ParamSpec::new("l0", Dim::Length, "rest segment length ℓ of the discretisation").positive(),
];

fn eval(p: &[f64], [ri, rj, rk]: [DVec3; 3]) -> ThreeBody {
    let strength = strength(p);
    let a = rj - ri;
    let b = rk - rj;
    // Two divisions, not twelve (this is the inner loop of a fibre's step).
    let (ia, ib) = (1.0 / a.length(), 1.0 / b.length());
    let t1 = a * ia;
    let t2 = b * ib;
    let c = t1.dot(t2);
    // ∂c/∂a and ∂c/∂b for c = t1·t2.
    let dc_da = (t2 - c * t1) * ia;
    let dc_db = (t1 - c * t2) * ib;
    // E = (κ/ℓ)(1 − c); a = rj − ri, b = rk − rj.
    let fi = -strength * dc_da;
    let fk = strength * dc_db;
    ThreeBody { energy: strength * (1.0 - c), forces: [fi, -fi - fk, fk] }
}

/// LAMMPS `angle_style cosine` K(1 + cos θ): K = κ/ℓ, since t1·t2 = −cos θ.
fn lammps(term: &LammpsTerm) -> Translation {
    bonded("cosine", num(term.params[KAPPA] / term.params[L0]))
}

interaction!(
    WlcBending,
    "wlc_bending",
    Kind::Angle,
    "Discrete worm-like-chain bending E = (κ/ℓ)(1 − t1·t2) (Cytosim)",
    Law::ThreeBody(eval),
    lammps = lammps,
    fibre_bending = strength
);

/// The fibre-bending strength s = κ/ℓ of E = s·(1 − t₁·t₂).
fn strength(p: &[f64]) -> f64 {
    p[KAPPA] / p[L0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    fn actin() -> Vec<f64> {
        params_of(&WlcBending, &[("kappa", 0.07), ("l0", 0.1)])
    }

    #[test]
    fn shared_checks() {
        let p = actin();
        let j = DVec3::new(0.3, -0.2, 0.5);
        let configs = [
            [j + DVec3::new(-0.1, 0.0, 0.0), j, j + DVec3::new(0.09, 0.02, -0.01)],
            [j + DVec3::new(-0.07, 0.05, 0.02), j, j + DVec3::new(0.04, 0.1, 0.03)],
            [j + DVec3::new(0.05, 0.08, 0.0), j, j + DVec3::new(0.08, 0.0, 0.06)],
        ];
        for x in &configs {
            assert_all_checks(&WlcBending, &p, x, 1e-7, 1e-3);
        }
        let straight = DVec3::new(1.0, 2.0, -2.0) / 3.0;
        assert_zero_force_at_rest(&WlcBending, &p, &[j - 0.1 * straight, j, j + 0.13 * straight], 1.0);
    }

    #[test]
    fn both_forms_of_the_energy_agree() {
        let p = actin();
        let x = [DVec3::new(0.0, 0.0, 0.0), DVec3::new(0.1, 0.01, 0.0), DVec3::new(0.17, 0.08, 0.02)];
        let t1 = (x[1] - x[0]).normalize();
        let t2 = (x[2] - x[1]).normalize();
        let e = eval(&p, x).energy;
        assert!((e - 0.07 / (2.0 * 0.1) * (t2 - t1).length_squared()).abs() < 1e-15);
    }

    /// Total energy of a chain of `joints` joints whose chords of length ℓ lie on a
    /// circle of radius `radius`, and the turning angle per joint.
    fn arc_energy(p: &[f64], radius: f64, joints: usize) -> (f64, f64) {
        let l = p[L0];
        let theta = 2.0 * (l / (2.0 * radius)).asin();
        let beads: Vec<DVec3> = (0..joints + 2)
            .map(|n| {
                let phi = n as f64 * theta;
                DVec3::new(radius * phi.cos(), radius * phi.sin(), 0.0)
            })
            .collect();
        let total = beads.windows(3).map(|w| eval(p, [w[0], w[1], w[2]]).energy).sum();
        (total, theta)
    }

    #[test]
    fn circular_arc_gives_the_continuum_wlc_energy() {
        let kappa = 0.07;
        let radius = 1.0;
        let arc_length = 2.0; // µm of filament bent along the circle
        let mut previous_error = f64::INFINITY;
        for l in [0.1, 0.05, 0.025] {
            let p = params_of(&WlcBending, &[("kappa", kappa), ("l0", l)]);
            let joints = (arc_length / l).round() as usize;
            let (e, theta) = arc_energy(&p, radius, joints);
            // L = joints × ℓ (chord length): the discrete energy equals κL/(2R²)
            // exactly, since 1 − cos θ = 2 sin²(θ/2) = ℓ²/(2R²).
            let chord_length = joints as f64 * l;
            let continuum = kappa * chord_length / (2.0 * radius * radius);
            let rel = (e - continuum).abs() / continuum;
            assert!(rel < 5e-3, "ℓ = {l}: E = {e}, κL/(2R²) = {continuum}, rel. err {rel:e}");
            assert!(rel < 1e-9, "ℓ = {l}: chord identity broken, rel. err {rel:e}");
            // Against the arc's contour length L = joints·R·θ the discretisation
            // error is ≈ (ℓ/R)²/24 and shrinks ~4× when ℓ is halved.
            let contour = joints as f64 * radius * theta;
            let continuum = kappa * contour / (2.0 * radius * radius);
            let rel = (e - continuum).abs() / continuum;
            assert!(rel < 5e-3, "ℓ = {l}: rel. err vs contour length {rel:e}");
            assert!((rel / ((l / radius).powi(2) / 24.0) - 1.0).abs() < 0.01, "ℓ = {l}: rel. err {rel:e}");
            assert!(rel < previous_error / 3.9, "error did not shrink: {rel:e} after {previous_error:e}");
            previous_error = rel;
        }
    }
}
