#![doc = include_str!("contact_adhesion.md")]

use super::{Kind, Law, ParamSpec, Radial};
use crate::units::Dim;

const W: usize = 0;
const D_ON: usize = 1;
const D_OFF: usize = 2;

static PARAMS: [ParamSpec; 3] = [
    ParamSpec::new("w", Dim::Tension, "adhesion w: the tension a face in contact with another body loses (energy per area)").positive(),
    ParamSpec::new("d_on", Dim::Length, "distance below which a node counts fully as in contact (s = 1)").non_negative(),
    ParamSpec::new("d_off", Dim::Length, "distance from which a node counts as free (s = 0); > d_on").positive(),
];

fn validate(p: &[f64]) -> Result<(), String> {
    if p[D_OFF] > p[D_ON] {
        Ok(())
    } else {
        Err(format!("`d_off` > `d_on` (the switch needs a width), found d_on = {} and d_off = {}", p[D_ON], p[D_OFF]))
    }
}

/// The quintic switch s(d) = 1 − (10t³ − 15t⁴ + 6t⁵), t = (d − d_on)/(d_off − d_on),
/// 1 below d_on and 0 from d_off on, with s′ and s″ (in the `energy`,
/// `de_dr` and `d2e_dr2` fields).
fn switch(p: &[f64], d: f64) -> Radial {
    let (on, off) = (p[D_ON], p[D_OFF]);
    if d >= off {
        return Radial::ZERO;
    }
    if d <= on {
        return Radial { energy: 1.0, de_dr: 0.0, d2e_dr2: 0.0 };
    }
    let width = off - on;
    let t = (d - on) / width;
    let t2 = t * t;
    Radial {
        energy: 1.0 - t2 * t * (10.0 - 15.0 * t + 6.0 * t2),
        de_dr: -30.0 * t2 * (1.0 - t) * (1.0 - t) / width,
        d2e_dr2: -60.0 * t * (1.0 - t) * (1.0 - 2.0 * t) / (width * width),
    }
}

/// Energy per area of a face in full contact: −w.
fn density(p: &[f64]) -> f64 {
    -p[W]
}

fn range(p: &[f64]) -> f64 {
    p[D_OFF]
}

interaction!(
    ContactAdhesion,
    "contact_adhesion",
    Kind::Contact,
    "Adhesion between bodies: each body's faces in contact with another lose tension w, E = −w·Σ_t A_t·s_a·s_b·s_c",
    Law::ContactArea { switch, density, range },
    validate = validate
);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;
    use crate::interactions::Entry;

    #[test]
    fn switch_is_c2_from_full_contact_to_free() {
        let p = params_of(&ContactAdhesion, &[("w", 30.0), ("d_on", 0.05), ("d_off", 0.25)]);
        assert_eq!((density(&p), range(&p)), (-30.0, 0.25));
        // Full contact up to d_on, nothing from d_off on.
        let full = Radial { energy: 1.0, de_dr: 0.0, d2e_dr2: 0.0 };
        assert_eq!((switch(&p, 0.0), switch(&p, 0.05)), (full, full));
        assert_eq!((switch(&p, 0.25), switch(&p, 1.0)), (Radial::ZERO, Radial::ZERO));
        // s, s′ and s″ are continuous at both ends of the switch.
        for (edge, inside) in [(0.05, 0.05 + 1e-9), (0.25, 0.25 - 1e-9)] {
            let (a, b) = (switch(&p, edge), switch(&p, inside));
            assert!((a.energy - b.energy).abs() < 1e-9 && (a.de_dr - b.de_dr).abs() < 1e-7, "{edge}: {a:?} vs {b:?}");
            assert!((a.d2e_dr2 - b.d2e_dr2).abs() < 1e-3, "{edge}: {a:?} vs {b:?}");
        }
        // One half at the midpoint (the switch is point-symmetric), where it
        // falls fastest, s′ = −15/(8·width); decreasing throughout.
        let mid = switch(&p, 0.15);
        assert!((mid.energy - 0.5).abs() < 1e-15 && (mid.de_dr + 15.0 / (8.0 * 0.2)).abs() < 1e-12, "{mid:?}");
        let mut last = 1.0;
        for k in 1..=200 {
            let now = switch(&p, 0.05 + 0.2 * k as f64 / 200.0);
            assert!(now.energy < last && now.de_dr <= 0.0, "s not decreasing at step {k}");
            last = now.energy;
        }
        // ∫ s dd over the switch is half its width (point symmetry).
        let n = 10_000;
        let integral: f64 = (0..n).map(|k| switch(&p, 0.05 + 0.2 * (k as f64 + 0.5) / n as f64).energy).sum::<f64>() * 0.2 / n as f64;
        assert!((integral - 0.1).abs() < 1e-9, "{integral}");
    }

    #[test]
    fn switch_derivatives_agree_with_finite_differences() {
        let p = params_of(&ContactAdhesion, &[("w", 7.0), ("d_on", 0.0), ("d_off", 0.3)]);
        // (Not at the midpoint 0.15, where s″ = 0 and a relative check is void.)
        for d in [0.01, 0.07, 0.13, 0.22, 0.29] {
            let h = 1e-7;
            let numeric = (switch(&p, d + h).energy - switch(&p, d - h).energy) / (2.0 * h);
            assert!((numeric - switch(&p, d).de_dr).abs() < 1e-6 * switch(&p, d).de_dr.abs(), "d = {d}");
            assert_radial_curvature(&ContactAdhesion, &p, d, 1e-7);
        }
    }

    #[test]
    fn parameters_need_a_switch_of_positive_width() {
        assert!(ContactAdhesion.validate(&[1.0, 0.1, 0.2]).is_ok());
        let error = ContactAdhesion.validate(&[1.0, 0.2, 0.2]).unwrap_err();
        assert_eq!(error, "`d_off` > `d_on` (the switch needs a width), found d_on = 0.2 and d_off = 0.2");
    }
}
