#![doc = include_str!("cosine_angle.md")]

use glam::DVec3;

use super::lammps::{bonded, num, LammpsTerm, Translation};
use super::{Kind, Law, ParamSpec, ThreeBody};
use crate::units::Dim;

const K: usize = 0;

static PARAMS: [ParamSpec; 1] = [ParamSpec::new("K", Dim::Energy, "bending energy scale (E = K[1 + cos θ])").non_negative()];

fn eval(p: &[f64], [ri, rj, rk]: [DVec3; 3]) -> ThreeBody {
    let u = ri - rj;
    let v = rk - rj;
    let (lu, lv) = (u.length(), v.length());
    let (uh, vh) = (u / lu, v / lv);
    let c = uh.dot(vh);
    // E = K(1 + c); ∂c/∂u = (v̂ − c·û)/|u|, ∂c/∂v = (û − c·v̂)/|v|. No singularity.
    let fi = -p[K] * (vh - c * uh) / lu;
    let fk = -p[K] * (uh - c * vh) / lv;
    ThreeBody { energy: p[K] * (1.0 + c), forces: [fi, -fi - fk, fk] }
}

/// LAMMPS `angle_style cosine`: identical.
fn lammps(term: &LammpsTerm) -> Translation {
    bonded("cosine", num(term.params[K]))
}

interaction!(
    CosineAngle,
    "cosine_angle",
    Kind::Angle,
    "Cosine angle E = K[1 + cos θ] (LAMMPS angle_style cosine)",
    Law::ThreeBody(eval),
    lammps = lammps,
    fibre_bending = strength
);

/// The fibre-bending strength: K(1 + cos θ) = K(1 − t₁·t₂), since the
/// vertex angle's cosine is −t₁·t₂ for the tangents along the chain.
fn strength(p: &[f64]) -> f64 {
    p[K]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    fn at_angle(deg: f64) -> [DVec3; 3] {
        let j = DVec3::new(-0.3, 0.1, 0.6);
        let t = deg.to_radians();
        [j + 0.25 * DVec3::Y, j, j + 0.4 * DVec3::new(0.0, t.cos(), t.sin())]
    }

    #[test]
    fn shared_checks() {
        let p = params_of(&CosineAngle, &[("K", 0.7)]);
        for deg in [10.0, 70.0, 110.0, 179.0] {
            assert_all_checks(&CosineAngle, &p, &at_angle(deg), 1e-7, 1e-2);
        }
        let j = DVec3::new(0.1, 0.2, 0.3);
        assert_all_checks(&CosineAngle, &p, &[j + DVec3::new(0.1, 0.2, -0.1), j, j + DVec3::new(-0.2, 0.1, 0.15)], 1e-7, 1e-2);
        // Rest: the straight chain (θ = 180°).
        let dir = DVec3::new(2.0, -1.0, 2.0) / 3.0;
        assert_zero_force_at_rest(&CosineAngle, &p, &[j - 0.25 * dir, j, j + 0.4 * dir], 5.0);
    }

    #[test]
    fn matches_lammps_angle_cosine() {
        let p = params_of(&CosineAngle, &[("K", 0.7)]);
        for deg in [0.0, 60.0, 90.0, 180.0] {
            let e = eval(&p, at_angle(deg)).energy;
            assert!((e - 0.7 * (1.0 + f64::to_radians(deg).cos())).abs() < 1e-14, "θ = {deg}: {e}");
        }
        // At 90° the force on i is K/|u| towards k... pulling the angle open: −K·v̂/|u|.
        let f = eval(&p, at_angle(90.0)).forces[0];
        assert!((f - DVec3::new(0.0, 0.0, -0.7 / 0.25)).length() < 1e-12, "{f:?}");
    }
}
