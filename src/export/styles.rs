//! How each registered interaction type is written in LAMMPS, with the
//! conversion of its parameters (the one place that knows both conventions).
//!
//! | cellmd | LAMMPS | conversion |
//! |---|---|---|
//! | `harmonic` ½k(r−r0)² | `bond_style harmonic` K(r−r0)² | K = k/2 |
//! | `fene` | `bond_style fene` | identical (K, R0, ε, σ) |
//! | `cable`, `spring`, `asymmetric` | `bond_style lepton` | exact expression in Δr = r − r0 (LAMMPS' lepton bond variable) |
//! | `harmonic_angle` ½k(θ−θ0)² | `angle_style harmonic` K(θ−θ0)² | K = k/2 |
//! | `cosine_angle` K(1+cos θ) | `angle_style cosine` | identical |
//! | `wlc_bending` (κ/ℓ)(1−t1·t2) | `angle_style cosine` | K = κ/ℓ, since t1·t2 = −cos θ |
//! | `lj` | `pair_style lj/cut` | identical, not shifted |
//! | `wca` | `pair_style lj/cut` at 2^(1/6)σ | `pair_modify shift yes` |
//! | `soft_repulsion` ½k(σ−r)² | `pair_style harmonic/cut` k(rc−r)² | k/2, rc = σ |
//! | `soft` | `pair_style soft` | identical |
//! | `wall` (axis-aligned normal) | `fix wall/harmonic` ε(r−rc)² | ε = k/2, wall placed at d − rc; a `d` of t only is an equal-style variable of `time` |
//! | `constant_force` | `fix addforce` | identical; its scalar is −F·x on unwrapped x |
//! | `indenter` (K/3)(R−r)³ | `fix indent … sphere` | identical (K, centre, R) |
//! | `field` | `fix addforce v_fx v_fy v_fz energy v_e` | one atom-style variable per parameter ([`super::formula`]) |
//! | `custom` bond, angle, pair | `bond_style lepton` (r0 = 0), `angle_style lepton` (θ0 = 0), `pair_style lepton` | the expression, parameters as numbers ([`super::lepton`]); r0 = 0 and θ0 = 0 make Lepton's displacement variables the distance and the angle |
//! | `custom` external | `fix addforce v_fx v_fy v_fz energy v_e` | atom-style variables of −∇E (symbolic derivatives) and E ([`super::formula`]); refused when E reads a periodic axis's coordinate |

use crate::forcefield::TermType;
use crate::interactions::{param_index, Law};

use super::number::num;

/// A custom term's energy as a Lepton expression, its parameters as numbers.
fn custom_expression(term: &TermType) -> Result<String, String> {
    let expr = term.interaction.expression().ok_or_else(|| unsupported(term))?;
    let names = term.interaction.params();
    super::lepton::lepton(expr, &|n| names.iter().position(|p| p.name == n).map(|k| term.params[k]))
        .map_err(|e| format!("{} `{}`: {e}", term.interaction.kind().with_article(), term.label.text))
}

fn param(term: &TermType, name: &str) -> f64 {
    term.params[param_index(term.interaction, name).unwrap_or_else(|| panic!("{} has no `{name}`", term.interaction.name()))]
}

/// A bonded style: the sub-style name and the coefficients after it.
#[derive(Clone, Debug, PartialEq)]
pub struct Styled {
    pub style: &'static str,
    pub coeffs: String,
}

/// A pair style instance: style, coefficients (including the cutoff), and
/// whether the style's energy is shifted to zero at the cutoff.
#[derive(Clone, Debug, PartialEq)]
pub struct PairStyled {
    pub style: &'static str,
    pub coeffs: String,
    pub cutoff: f64,
    pub shift: bool,
}

pub(super) fn unsupported(term: &TermType) -> String {
    format!(
        "{} `{}` uses `{}`, which LAMMPS cannot express",
        term.interaction.kind().with_article(),
        term.label.text,
        term.interaction.name()
    )
}

/// The `bond_style` sub-style and `bond_coeff` values of a bond type.
pub fn bond(term: &TermType) -> Result<Styled, String> {
    let p = |n| param(term, n);
    let lepton = |expression: String, r0: f64| Styled { style: "lepton", coeffs: format!("{} \"{expression}\"", num(r0)) };
    Ok(match term.interaction.name() {
        "harmonic" => Styled { style: "harmonic", coeffs: format!("{} {}", num(0.5 * p("k")), num(p("r0"))) },
        "fene" => Styled { style: "fene", coeffs: format!("{} {} {} {}", num(p("K")), num(p("R0")), num(p("epsilon")), num(p("sigma"))) },
        // In LAMMPS' lepton bond the variable r is the displacement r − r0.
        "cable" => {
            let (k, r0, tau) = (p("k"), p("r0"), p("tau"));
            lepton(format!("0.5*{}*{}*max(0,r/{}+({}))^2", num(k), num(r0), num(r0), num(tau)), r0)
        }
        "spring" => {
            let (k, r0, tau) = (p("k"), p("r0"), p("tau"));
            lepton(format!("0.5*{}*{}*(r/{}+({}))^2", num(k), num(r0), num(r0), num(tau)), r0)
        }
        "asymmetric" => {
            let (kt, kc) = (p("k_tension"), p("k_compression"));
            lepton(format!("0.5*({}*step(r)+{}*(1-step(r)))*r^2", num(kt), num(kc)), p("r0"))
        }
        "custom" => lepton(custom_expression(term)?, 0.0),
        _ => return Err(unsupported(term)),
    })
}

/// The `angle_style` sub-style and `angle_coeff` values of an angle type.
pub fn angle(term: &TermType) -> Result<Styled, String> {
    let p = |n| param(term, n);
    Ok(match term.interaction.name() {
        "harmonic_angle" => Styled { style: "harmonic", coeffs: format!("{} {}", num(0.5 * p("k")), num(p("theta0"))) },
        "cosine_angle" => Styled { style: "cosine", coeffs: num(p("K")) },
        "wlc_bending" => Styled { style: "cosine", coeffs: num(p("kappa") / p("l0")) },
        // Lepton's angle variable is θ − θ0 in radians: θ0 = 0 makes it θ.
        "custom" => Styled { style: "lepton", coeffs: format!("0.0 \"{}\"", custom_expression(term)?) },
        _ => return Err(unsupported(term)),
    })
}

/// The `pair_style` instance and `pair_coeff` values of a pair rule.
pub fn pair(term: &TermType) -> Result<PairStyled, String> {
    let p = |n| param(term, n);
    let Law::Radial { range, .. } = term.interaction.law() else { return Err(unsupported(term)) };
    let cutoff = range(&term.params);
    let (style, coeffs, shift) = match term.interaction.name() {
        "lj" => ("lj/cut", format!("{} {} {}", num(p("epsilon")), num(p("sigma")), num(cutoff)), false),
        "wca" => ("lj/cut", format!("{} {} {}", num(p("epsilon")), num(p("sigma")), num(cutoff)), true),
        "soft_repulsion" => ("harmonic/cut", format!("{} {}", num(0.5 * p("k")), num(cutoff)), false),
        "soft" => ("soft", format!("{} {}", num(p("A")), num(cutoff)), false),
        "custom" => ("lepton", format!("\"{}\" {}", custom_expression(term)?, num(cutoff)), false),
        _ => return Err(unsupported(term)),
    };
    Ok(PairStyled { style, coeffs, cutoff, shift })
}

/// A wall whose offset d is a formula of time: the LAMMPS formula of d and
/// the equal-style variable that will hold the wall's face position.
pub struct MovingWall<'a> {
    pub d: &'a str,
    pub variable: &'a str,
}

/// A LAMMPS fix equivalent to an external field: the fix style and its
/// arguments after the group, and for a [`MovingWall`] the `variable` line
/// to write before the fix. `axis_length(a)` is the box edge along axis a,
/// `periodic(a)` whether that axis is periodic.
pub fn external(
    term: &TermType,
    axis_length: impl Fn(usize) -> f64,
    periodic: impl Fn(usize) -> bool,
    moving: Option<MovingWall>,
) -> Result<(String, Option<String>), String> {
    let p = |n| param(term, n);
    match term.interaction.name() {
        "constant_force" => Ok((format!("addforce {} {} {}", num(p("fx")), num(p("fy")), num(p("fz"))), None)),
        // LAMMPS: F(r) = −K(r − R)² outward inside the sphere, energy K(R − r)³/3.
        "indenter" => {
            Ok((format!("indent {} sphere {} {} {} {} units box", num(p("k")), num(p("x")), num(p("y")), num(p("z")), num(p("r"))), None))
        }
        "wall" => {
            let n = [p("nx"), p("ny"), p("nz")];
            let axes: Vec<usize> = (0..3).filter(|&a| n[a] != 0.0).collect();
            let [axis] = axes[..] else {
                return Err(format!(
                    "external `{}`: a wall with the oblique normal ({}, {}, {}) has no LAMMPS equivalent (fix wall/* faces are axis-aligned)",
                    term.label.text, n[0], n[1], n[2]
                ));
            };
            if periodic(axis) {
                return Err(format!(
                    "external `{}`: LAMMPS cannot put a wall across the periodic axis {}",
                    term.label.text,
                    "xyz".as_bytes()[axis] as char
                ));
            }
            // E = ε(r − rc)² for r < rc with r the distance from the LAMMPS wall:
            // a wall rc below the cellmd plane gives ε(d − n̂·x)² = ½k(d − n̂·x)².
            // rc only has to exceed the deepest penetration; a small rc keeps
            // the round-off of (r − rc) small.
            let rc = axis_length(axis).max(1.0);
            let d = p("d");
            let letter = "xyz".as_bytes()[axis] as char;
            let (side, position, variable) = match (&moving, n[axis] > 0.0) {
                (None, true) => ("lo", num(d - rc), None),
                (None, false) => ("hi", num(-d + rc), None),
                // LAMMPS re-evaluates an equal-style face position every step.
                (Some(m), lo) => {
                    let formula = if lo { format!("{}-{}", m.d, num(rc)) } else { format!("-{}+{}", m.d, num(rc)) };
                    (
                        if lo { "lo" } else { "hi" },
                        format!("v_{}", m.variable),
                        Some(format!("variable {} equal \"{formula}\"", m.variable)),
                    )
                }
            };
            Ok((format!("wall/harmonic {letter}{side} {position} {} 1.0 {} units box", num(0.5 * p("k")), num(rc)), variable))
        }
        _ => Err(unsupported(term)),
    }
}
