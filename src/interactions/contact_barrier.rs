#![doc = include_str!("contact_barrier.md")]

use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const DHAT: usize = 0;
const KAPPA: usize = 1;

static PARAMS: [ParamSpec; 2] = [
    ParamSpec::new("dhat", Dim::Length, "activation distance d̂: the barrier acts on node–face pairs closer than d̂").positive(),
    ParamSpec::new("kappa", Dim::Stiffness, "barrier stiffness κ (energy κ·d̂²·O(1) at d = d̂/2)").positive(),
];

/// b(d) = −κ(d − d̂)²·ln(d/d̂) for 0 < d < d̂, with b′ and b″; +∞ (and a
/// force of −∞ along the separation) at d ≤ 0, which the step clamp of the
/// explicit integrator never lets happen.
fn eval(p: &[f64], d: f64) -> Radial {
    let (dhat, kappa) = (p[DHAT], p[KAPPA]);
    if d >= dhat {
        return Radial::ZERO;
    }
    if d <= 0.0 {
        return Radial { energy: f64::INFINITY, de_dr: f64::NEG_INFINITY, d2e_dr2: f64::INFINITY };
    }
    let (gap, log) = (d - dhat, (d / dhat).ln());
    Radial {
        energy: -kappa * gap * gap * log,
        de_dr: -kappa * (2.0 * gap * log + gap * gap / d),
        d2e_dr2: -kappa * (2.0 * log + 4.0 * gap / d - gap * gap / (d * d)),
    }
}

fn range(p: &[f64]) -> f64 {
    p[DHAT]
}

interaction!(
    ContactBarrier,
    "contact_barrier",
    Kind::Contact,
    "IPC log barrier between a node and a face of different bodies, b(d) = −κ(d − d̂)²·ln(d/d̂) for d < d̂",
    Law::Contact { eval, range }
);

#[cfg(test)]
mod tests {
    use glam::DVec3;

    use super::*;
    use crate::interactions::testing::*;
    use crate::interactions::Interaction;

    fn law(p: &[f64], d: f64) -> Radial {
        eval(p, d)
    }

    #[test]
    fn barrier_vanishes_smoothly_at_dhat_and_diverges_at_contact() {
        let p = params_of(&ContactBarrier, &[("dhat", 0.1), ("kappa", 10.0)]);
        // b(d̂) = b′(d̂) = 0 exactly, and nothing beyond.
        assert_eq!(law(&p, 0.1), Radial { energy: 0.0, de_dr: 0.0, d2e_dr2: 0.0 });
        assert_eq!(law(&p, 0.2), Radial::ZERO);
        // Just inside, b and b′ are second and first order in the gap: C¹ at d̂.
        let inside = law(&p, 0.1 * (1.0 - 1e-6));
        assert!(inside.energy > 0.0 && inside.energy < 1e-12 && inside.de_dr < 0.0 && inside.de_dr > -1e-5, "{inside:?}");
        // Positive, decreasing (repulsive) and convex on (0, d̂), unbounded at 0.
        let mut last = law(&p, 1e-9);
        assert!(last.energy > 1e-2 && last.de_dr < -1e6);
        for k in 1..1000 {
            let now = law(&p, 0.1 * k as f64 / 1000.0);
            assert!(now.energy > 0.0 && now.energy < last.energy, "b not decreasing at step {k}");
            assert!(now.de_dr < 0.0 && now.de_dr > last.de_dr, "b′ not negative and increasing at step {k}");
            assert!(now.d2e_dr2 > 0.0);
            last = now;
        }
        assert_eq!(law(&p, 0.0).energy, f64::INFINITY);
        // The closed form at one point: κ = 10, d̂ = 0.1, d = 0.05 gives 10·0.0025·ln 2.
        assert!((law(&p, 0.05).energy - 0.025 * 2f64.ln()).abs() < 1e-15);
    }

    #[test]
    fn derivatives_agree_with_finite_differences() {
        let p = params_of(&ContactBarrier, &[("dhat", 0.3), ("kappa", 7.0)]);
        for d in [0.01, 0.07, 0.15, 0.29] {
            let h = 1e-7;
            let numeric = (law(&p, d + h).energy - law(&p, d - h).energy) / (2.0 * h);
            assert!((numeric - law(&p, d).de_dr).abs() < 1e-6 * law(&p, d).de_dr.abs(), "d = {d}");
            assert_radial_curvature(&ContactBarrier, &p, d, 1e-7);
        }
    }

    /// A node over each Voronoi region of a tilted face, all within d̂.
    fn configurations() -> Vec<(&'static str, [DVec3; 4])> {
        let (a, b, c) = (DVec3::new(0.0, 0.0, 0.02), DVec3::new(0.4, 0.05, 0.0), DVec3::new(0.1, 0.35, -0.03));
        let centroid = (a + b + c) / 3.0;
        let normal = (b - a).cross(c - a).normalize();
        let out_of = |v: DVec3, edge_mid: DVec3| (edge_mid - centroid).normalize() * 0.04 + normal * 0.05 + v;
        vec![
            ("face", [centroid + 0.06 * normal, a, b, c]),
            ("face below", [centroid - 0.03 * normal + DVec3::new(0.02, -0.01, 0.0), a, b, c]),
            ("edge ab", [out_of((a + b) / 2.0, (a + b) / 2.0), a, b, c]),
            ("edge bc", [out_of((b + c) / 2.0, (b + c) / 2.0), a, b, c]),
            ("edge ca", [out_of((c + a) / 2.0, (c + a) / 2.0), a, b, c]),
            ("vertex a", [a + (a - centroid).normalize() * 0.05 + 0.02 * normal, a, b, c]),
            ("vertex b", [b + (b - centroid).normalize() * 0.06 - 0.01 * normal, a, b, c]),
            ("vertex c", [c + (c - centroid).normalize() * 0.04, a, b, c]),
        ]
    }

    #[test]
    fn shared_checks_in_every_closest_point_region() {
        let p = params_of(&ContactBarrier, &[("dhat", 0.1), ("kappa", 10.0)]);
        for (region, x) in configurations() {
            let pt = crate::mesh::point_triangle(x[0], [x[1], x[2], x[3]]);
            let active = pt.weights.iter().filter(|w| **w > 0.0).count();
            let expected = match region.split(' ').next().unwrap() {
                "face" => 3,
                "edge" => 2,
                _ => 1,
            };
            assert_eq!(active, expected, "{region}: weights {:?}", pt.weights);
            assert!(pt.distance > 0.0 && pt.distance < 0.1, "{region}: d = {}", pt.distance);
            assert_all_checks(&ContactBarrier, &p, &x, 1e-7, 0.0);
            assert_radial_curvature(&ContactBarrier, &p, pt.distance, 1e-8);
        }
    }

    #[test]
    fn the_node_is_pushed_away_from_the_face_and_the_face_back() {
        let p = params_of(&ContactBarrier, &[("dhat", 0.1), ("kappa", 10.0)]);
        let x = [DVec3::new(0.2, 0.2, 0.05), DVec3::ZERO, DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 1.0, 0.0)];
        let (energy, f) = evaluate(ContactBarrier.law(), &p, &x);
        assert!(energy > 0.0);
        assert!(f[0].z > 0.0 && f[0].x.abs().max(f[0].y.abs()) < 1e-12 * f[0].z, "{:?}", f[0]);
        // The reaction is split by the barycentric weights (0.6, 0.2, 0.2) of the foot.
        for (k, w) in [0.6, 0.2, 0.2].iter().enumerate() {
            assert!((f[k + 1] + *w * f[0]).length() < 1e-12 * f[0].length());
        }
        // Beyond d̂: nothing.
        let far = [DVec3::new(0.2, 0.2, 0.1), x[1], x[2], x[3]];
        assert_eq!(evaluate(ContactBarrier.law(), &p, &far), (0.0, vec![DVec3::ZERO; 4]));
    }
}
