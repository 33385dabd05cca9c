#![doc = include_str!("wall.md")]

use glam::DVec3;

use super::lammps::{num, LammpsStyle, LammpsTerm, Moving, Translation};
use super::{Kind, Law, OneBody, ParamSpec};
use crate::units::Dim;

const NX: usize = 0;
const NY: usize = 1;
const NZ: usize = 2;
const D: usize = 3;
const K: usize = 4;

static PARAMS: [ParamSpec; 5] = [
    ParamSpec::new("nx", Dim::Dimensionless, "x component of the wall normal (normalised internally)").default(0.0),
    ParamSpec::new("ny", Dim::Dimensionless, "y component of the wall normal (normalised internally)").default(0.0),
    ParamSpec::new("nz", Dim::Dimensionless, "z component of the wall normal (normalised internally)").default(0.0),
    ParamSpec::new("d", Dim::Length, "offset of the plane n̂·x = d from the origin, along n̂").default(0.0),
    ParamSpec::new("k", Dim::Stiffness, "stiffness of the wall").non_negative(),
];

/// The unit normal, or `None` for a zero (or non-finite) normal.
fn unit_normal(p: &[f64]) -> Option<DVec3> {
    let n = DVec3::new(p[NX], p[NY], p[NZ]);
    // Scale first so that huge or tiny components neither overflow nor underflow.
    let scale = n.abs().max_element();
    if !(scale > 0.0 && scale.is_finite()) {
        return None;
    }
    Some((n / scale).normalize())
}

/// The wall's plane `n̂·x = d` as (unit normal, d), or `None` for a zero normal.
pub fn plane(p: &[f64]) -> Option<(DVec3, f64)> {
    unit_normal(p).map(|n| (n, p[D]))
}

fn eval(p: &[f64], x: DVec3) -> OneBody {
    let Some(n) = unit_normal(p) else {
        return OneBody { energy: 0.0, force: DVec3::ZERO };
    };
    let depth = p[D] - n.dot(x);
    if depth > 0.0 {
        OneBody { energy: 0.5 * p[K] * depth * depth, force: p[K] * depth * n }
    } else {
        OneBody { energy: 0.0, force: DVec3::ZERO }
    }
}

/// LAMMPS `fix wall/harmonic` ε(r − rc)² for an axis-aligned normal: ε =
/// k/2, the LAMMPS wall placed rc below the cellmd plane; a `d` that is a
/// formula of time only becomes an equal-style variable of `time`.
fn lammps(term: &LammpsTerm) -> Translation {
    let p = term.params;
    let moving = match &term.moving {
        Moving::Fixed => None,
        Moving::Time { index: D, formula: Ok(formula), variable } => Some((formula, *variable)),
        Moving::Time { index: D, formula: Err(e), .. } => return Some(Err(format!("external `{}`: {e}", term.label))),
        Moving::Time { .. } | Moving::Other => return None,
    };
    let n = [p[NX], p[NY], p[NZ]];
    let axes: Vec<usize> = (0..3).filter(|&a| n[a] != 0.0).collect();
    let [axis] = axes[..] else {
        return Some(Err(format!(
            "external `{}`: a wall with the oblique normal ({}, {}, {}) has no LAMMPS equivalent (fix wall/* faces are axis-aligned)",
            term.label, n[0], n[1], n[2]
        )));
    };
    let letter = "xyz".as_bytes()[axis] as char;
    if term.periodic[axis] {
        return Some(Err(format!("external `{}`: LAMMPS cannot put a wall across the periodic axis {letter}", term.label)));
    }
    // E = ε(r − rc)² for r < rc with r the distance from the LAMMPS wall:
    // a wall rc below the cellmd plane gives ε(d − n̂·x)² = ½k(d − n̂·x)².
    // rc only has to exceed the deepest penetration; a small rc keeps the
    // round-off of (r − rc) small.
    let rc = term.box_lengths[axis].max(1.0);
    let lo = n[axis] > 0.0;
    let side = if lo { "lo" } else { "hi" };
    let (position, variable) = match moving {
        None => (if lo { num(p[D] - rc) } else { num(-p[D] + rc) }, None),
        // LAMMPS re-evaluates an equal-style face position every step.
        Some((d, name)) => {
            let formula = if lo { format!("{d}-{}", num(rc)) } else { format!("-{d}+{}", num(rc)) };
            (format!("v_{name}"), Some(format!("variable {name} equal \"{formula}\"")))
        }
    };
    let args = format!("wall/harmonic {letter}{side} {position} {} 1.0 {} units box", num(0.5 * p[K]), num(rc));
    Some(Ok(LammpsStyle::Fix { args, variable }))
}

interaction!(
    Wall,
    "wall",
    Kind::External,
    "One-sided harmonic plane (substrate): E = ½k(d − n̂·x)² when n̂·x < d",
    Law::OneBody(eval),
    validate = validate,
    lammps = lammps
);

fn validate(p: &[f64]) -> Result<(), String> {
    match unit_normal(p) {
        Some(_) => Ok(()),
        None => Err(format!("a nonzero wall normal (nx, ny, nz), e.g. `nz 1` for a floor, found ({}, {}, {})", p[NX], p[NY], p[NZ])),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::interactions::testing::*;

    #[test]
    fn shared_checks() {
        let p = params_of(&Wall, &[("nx", 1.0), ("ny", -2.0), ("nz", 2.0), ("d", 0.5), ("k", 100.0)]);
        for x in [DVec3::new(0.1, 0.2, 0.3), DVec3::new(-1.0, 3.0, -2.0), DVec3::new(2.0, 0.0, 1.0)] {
            assert_all_checks(&Wall, &p, &[x], 1e-6, 1.0);
        }
        // On the allowed side, n̂·x >= d: no force.
        assert_zero_force_at_rest(&Wall, &p, &[DVec3::new(1.0, -1.0, 1.0)], 100.0);
        assert_zero_force_at_rest(&Wall, &p, &[DVec3::new(1.5, 0.0, 0.0)], 100.0);
    }

    #[test]
    fn floor_pushes_up_only_below_it() {
        let p = params_of(&Wall, &[("nz", 1.0), ("d", 1.0), ("k", 50.0)]);
        let below = eval(&p, DVec3::new(3.0, -4.0, 0.8));
        assert!((below.energy - 0.5 * 50.0 * 0.04).abs() < 1e-12);
        assert!((below.force - DVec3::new(0.0, 0.0, 10.0)).length() < 1e-12);
        assert_eq!(eval(&p, DVec3::new(3.0, -4.0, 1.2)).force, DVec3::ZERO);
        // The normal is normalised: (0, 0, 7) is the same wall.
        let q = params_of(&Wall, &[("nz", 7.0), ("d", 1.0), ("k", 50.0)]);
        assert_eq!(eval(&q, DVec3::new(3.0, -4.0, 0.8)), below);
    }

    #[test]
    fn zero_normal_is_rejected_with_what_is_expected() {
        let err = Wall.validate(&[0.0, 0.0, 0.0, 0.0, 10.0]).unwrap_err();
        assert!(err.contains("nonzero wall normal"), "{err}");
        assert!(Wall.validate(&[0.0, 1e-300, 0.0, 0.0, 10.0]).is_ok());
        assert!(Wall.validate(&[1e300, 1e300, 0.0, 0.0, 10.0]).is_ok());
    }
}
