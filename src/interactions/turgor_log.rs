#![doc = include_str!("turgor_log.md")]

use glam::DVec3;

use super::{Kind, Law, ParamSpec, SurfaceGpu, SurfaceHessian, SurfaceMesh};
use crate::hessian::RankOne;
use crate::units::Dim;

const K: usize = 0;
const DP0: usize = 1;
const V0: usize = 2;

static PARAMS: [ParamSpec; 3] = [
    ParamSpec::new("k", Dim::Pressure, "bulk modulus K of the contents (compressible fluid)").non_negative(),
    ParamSpec::new("dp0", Dim::Pressure, "pressure difference ΔP0 across the surface at the rest volume (inside minus outside)")
        .default(0.0),
    ParamSpec::new("v0", Dim::Volume, "rest volume V0").positive(),
];

/// The pressure ΔP(V) = ΔP0 − K·ln(V/V0) and the energy E(V) whose −dE/dV it
/// is. A collapsed or inverted body (V ≤ 0) has no finite pressure: NaN.
pub fn pressure_and_energy(p: &[f64], volume: f64) -> (f64, f64) {
    if volume <= 0.0 {
        return (f64::NAN, f64::NAN);
    }
    let v0 = p[V0];
    let log = (volume / v0).ln();
    (p[DP0] - p[K] * log, -p[DP0] * (volume - v0) + p[K] * (volume * log - volume + v0))
}

fn eval(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64 {
    let mut grad = vec![DVec3::ZERO; x.len()];
    let volume = mesh.volume_gradient(x, &mut grad);
    let (pressure, energy) = pressure_and_energy(p, volume);
    for (f, g) in forces.iter_mut().zip(&grad) {
        *f += pressure * *g;
    }
    energy
}

/// The Gauss–Newton model E″(V)·∇V∇Vᵀ = (K/V)·∇V∇Vᵀ, as for
/// [`turgor`](super::turgor) (nothing for a collapsed body, V ≤ 0).
fn hessian(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], out: &mut SurfaceHessian) {
    let mut gradient = vec![DVec3::ZERO; x.len()];
    let volume = mesh.volume_gradient(x, &mut gradient);
    if p[K] > 0.0 && volume > 0.0 {
        out.rank_one.push(RankOne { weight: p[K] / volume, gradient });
    }
}

interaction!(
    TurgorLog,
    "turgor_log",
    Kind::Body,
    "Pressure of the enclosed volume by the log law, ΔP = ΔP0 − K·ln(V/V0) (SimuCell3D)",
    Law::Surface { eval, hessian, gpu: SurfaceGpu::PerFace }
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        for (_, mesh, x) in deformed_icospheres(&[0, 1, 2]) {
            let v = mesh.volume(&x);
            for (k, dp0, v0) in [(1000.0, 0.0, 1.1 * v), (500.0, 40.0, 0.7 * v), (0.0, 133.0, v)] {
                let p = params_of(&TurgorLog, &[("k", k), ("dp0", dp0), ("v0", v0)]);
                assert_surface_checks(&TurgorLog, &p, &mesh, &x, 1e-6, 1e-3);
            }
            let p = params_of(&TurgorLog, &[("k", 1000.0), ("v0", v)]);
            assert_surface_zero_force_at_rest(&TurgorLog, &p, &mesh, &x, 1000.0);
        }
    }

    #[test]
    fn energy_is_minus_the_integral_of_the_pressure_and_matches_the_linear_law_near_v0() {
        let p = [800.0, 35.0, 2.0];
        for v in [0.3, 1.7, 2.0, 3.1, 9.0] {
            let n = 4000;
            let h = (v - 2.0) / n as f64;
            let integral: f64 = (0..n).map(|k| pressure_and_energy(&p, 2.0 + (k as f64 + 0.5) * h).0 * h).sum();
            let e = pressure_and_energy(&p, v).1;
            assert!((e + integral).abs() < 1e-7 * (1.0 + e.abs()), "V = {v}: E = {e}, −∫ΔP dV = {}", -integral);
        }
        // −K ln(V/V0) = K(V0 − V)/V0 + O((V − V0)²).
        for dv in [1e-3, -1e-3] {
            let v = 2.0 + dv;
            let (log_law, _) = pressure_and_energy(&p, v);
            let (linear, _) = crate::interactions::turgor::pressure_and_energy(&p, v);
            assert!((log_law - linear).abs() < 800.0 * (dv / 2.0f64).powi(2));
        }
        assert!(pressure_and_energy(&p, 0.0).0.is_nan() && pressure_and_energy(&p, -1.0).1.is_nan());
    }

    #[test]
    fn stiffness_is_the_gauss_newton_volume_term() {
        let (mesh, x) = deformed_icosphere(1, 1.5, 0.05);
        let v = mesh.volume(&x);
        for (dp0, v0) in [(0.0, v), (40.0, 0.7 * v)] {
            let p = params_of(&TurgorLog, &[("k", 900.0), ("dp0", dp0), ("v0", v0)]);
            let (pressure, _) = pressure_and_energy(&p, v);
            assert_surface_hessian(&TurgorLog, &p, &mesh, &x, |y| -pressure * mesh.volume(y), 1e-4, 1e-5);
        }
    }
}
