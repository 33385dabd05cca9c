//! `cellmd check --selftest`: the shared physics checks of
//! [`crate::interactions::testing`] (F = −∇E by central differences, Σf = 0,
//! Σ r×f = 0, rigid-motion invariance, E″ against differences of E′ for
//! radial laws) run on every `custom` term of a model, at geometries taken
//! from the deck's initial configuration: each bond type at the length of
//! its first bond and ±10 %, each pair rule at 0.3, 0.55, 0.8 and 0.95
//! of its cutoff (and its energy and force just inside the cutoff
//! reported), each angle type at its first angle and at 45°, 100° and 160°,
//! each external at its first members' positions, each body term on the
//! first body it acts on.
//!
//! [`custom_warnings`] is the cheap part every `check` and `run` prints: a
//! custom law that is not finite where the deck starts (each bond and angle
//! at its initial geometry, at its `r0`/`theta0` if it declares one, each
//! external at its members' positions), and a pair law truncated at its
//! cutoff.

use std::panic::{catch_unwind, AssertUnwindSafe};

use glam::DVec3;

use super::{External, Model, SimBox};
use crate::forcefield::TermType;
use crate::forcefield::Typed;
use crate::interactions::testing::{assert_all_checks, assert_surface_checks};
use crate::interactions::{Law, RadialLaw};

/// One line per custom term: `Ok("bond spring: 3 geometries")` or the
/// first check that failed.
/// `externals` are the deck's (`external` commands), which the model gets
/// as the run reaches them.
pub fn check_custom_terms(model: &Model, externals: &[&External], positions: &[DVec3], sim_box: &SimBox) -> Vec<Result<String, String>> {
    let custom = |t: &TermType| t.interaction.name() == "custom";
    let images = sim_box.images();
    let mut out = Vec::new();
    for (k, term) in model.bond_types.iter().enumerate().filter(|(_, t)| custom(t)) {
        let length = model
            .bonds
            .iter()
            .zip(&model.bond_type)
            .find(|(_, &t)| t as usize == k)
            .map(|([i, j], _)| images.minimum_image(positions[*j as usize] - positions[*i as usize]).length())
            .filter(|r| *r > 0.0)
            .unwrap_or(1.0);
        let geometries = [0.9, 1.0, 1.1].map(|s| pair_at(s * length)).to_vec();
        out.push(run("bond", &term.label.text, term, &geometries, length));
    }
    for (term, &(a, b)) in model.pair_rules.iter().zip(&model.pair_rule_types).filter(|(t, _)| custom(t)) {
        let cutoff = term.params[0];
        let geometries = [0.3, 0.55, 0.8, 0.95].map(|s| pair_at(s * cutoff)).to_vec();
        let kind = format!("pair {} {}", model.type_names[a as usize], model.type_names[b as usize]);
        out.push(run(&kind, "", term, &geometries, cutoff).map(|line| format!("{line}; {}", at_cutoff(term, cutoff))));
    }
    for (k, term) in model.angle_types.iter().enumerate().filter(|(_, t)| custom(t)) {
        let first = model.angles.iter().zip(&model.angle_type).find(|(_, &t)| t as usize == k).map(|(a, _)| *a);
        let mut geometries: Vec<Vec<DVec3>> = [45.0, 100.0, 160.0].map(angle_at).to_vec();
        let mut size = 1.0;
        if let Some([i, j, l]) = first {
            let xj = positions[j as usize];
            let (u, v) = (images.minimum_image(positions[i as usize] - xj), images.minimum_image(positions[l as usize] - xj));
            size = u.length().max(v.length()).max(f64::MIN_POSITIVE);
            geometries.push(vec![xj + u, xj, xj + v]);
        }
        out.push(run("angle", &term.label.text, term, &geometries, size));
    }
    for external in externals.iter().filter(|e| custom(&e.term)) {
        let geometries: Vec<Vec<DVec3>> = external.members.iter().take(3).map(|&m| vec![positions[m as usize]]).collect();
        out.push(run("external", &external.term.label.text, &external.term, &geometries, 1.0));
    }
    for (term, &body_type) in model.body_rules.iter().zip(&model.body_rule_type).filter(|(t, _)| custom(t)) {
        let Some(body) = model.bodies.iter().find(|b| b.body_type == body_type) else { continue };
        let mut x = Vec::new();
        body.mesh.unwrap_into(|n| positions[body.nodes[n as usize] as usize], |d| images.minimum_image(d), &mut x);
        let centre = body.mesh.centroid(&x);
        let size = x.iter().map(|p| (*p - centre).length()).fold(0.0, f64::max).max(f64::MIN_POSITIVE);
        let result = checked(|| assert_surface_checks(term.interaction, &term.params, &body.mesh, &x, 1e-6 * size, 1e-9));
        out.push(
            result
                .map(|()| format!("body {} custom: ok on body {}", term.label.text, body.id))
                .map_err(|e| format!("body {}: {e}", term.label.text)),
        );
    }
    out
}

/// Warnings (`file:line:col: warning: …`, at the law's label) for the
/// custom terms of `model` whose energy or force is not finite at the
/// deck's initial geometry or at a declared rest value (`r0`, `theta0`), and
/// for custom pair laws truncated at their cutoff (see `at_cutoff`).
/// `externals` are the deck's `external` commands.
pub fn custom_warnings(model: &Model, externals: &[&External], positions: &[DVec3], sim_box: &SimBox) -> Vec<String> {
    let custom = |t: &TermType| t.interaction.name() == "custom";
    let images = sim_box.images();
    let warn = |term: &TermType, what: &str, message: String| {
        let l = &term.label;
        format!("{}:{}:{}: warning: {what} (custom): {message}", l.file.path, l.line, l.col)
    };
    let named = |what: &str, term: &TermType| format!("{what} `{}`", term.label.text);
    let declared = |term: &TermType, name: &str| term.interaction.params().iter().position(|p| p.name == name).map(|k| term.params[k]);
    let mut out = Vec::new();
    for (k, term) in model.bond_types.iter().enumerate().filter(|(_, t)| custom(t)) {
        let Law::Radial { eval, .. } = term.interaction.law() else { continue };
        let lengths = model.bonds.iter().zip(&model.bond_type).filter(|(_, &t)| t as usize == k).map(|([i, j], _)| {
            (
                format!("at the initial length of bond {}–{}", model.ids[*i as usize], model.ids[*j as usize]),
                images.minimum_image(positions[*j as usize] - positions[*i as usize]).length(),
            )
        });
        let rest = declared(term, "r0").map(|r0| ("at its rest length r0".to_string(), r0));
        if let Some((place, r)) = rest.into_iter().chain(lengths).find(|(_, r)| !finite_radial(eval(&term.params, *r))) {
            let e = eval(&term.params, r);
            out.push(warn(term, &named("bond", term), format!("E = {:e}, dE/dr = {:e} {place} (r = {r:e})", e.energy, e.de_dr)));
        }
    }
    for (k, term) in model.angle_types.iter().enumerate().filter(|(_, t)| custom(t)) {
        let Law::ThreeBody(eval) = term.interaction.law() else { continue };
        let finite = |x: [DVec3; 3]| {
            let e = eval(&term.params, x);
            e.energy.is_finite() && e.forces.iter().all(|f| f.is_finite())
        };
        let rest = declared(term, "theta0").filter(|t| !finite([DVec3::X, DVec3::ZERO, DVec3::new(t.cos(), t.sin(), 0.0)]));
        if let Some(theta0) = rest {
            out.push(warn(term, &named("angle", term), format!("not finite at its rest angle theta0 = {:.6}°", theta0.to_degrees())));
        }
        let bad = model.angles.iter().zip(&model.angle_type).filter(|(_, &t)| t as usize == k).find(|([i, j, l], _)| {
            let xj = positions[*j as usize];
            let (u, v) = (images.minimum_image(positions[*i as usize] - xj), images.minimum_image(positions[*l as usize] - xj));
            !finite([xj + u, xj, xj + v])
        });
        if let Some(([i, j, l], _)) = bad {
            let ids = [i, j, l].map(|&p| model.ids[p as usize]);
            out.push(warn(
                term,
                &named("angle", term),
                format!("not finite at the initial geometry of angle {}–{}–{}", ids[0], ids[1], ids[2]),
            ));
        }
    }
    for external in externals.iter().filter(|e| custom(&e.term)) {
        let term = &external.term;
        let Law::OneBody(eval) = term.interaction.law() else { continue };
        let bad = external.members.iter().find(|&&m| {
            let e = eval(&term.params, positions[m as usize]);
            !(e.energy.is_finite() && e.force.is_finite())
        });
        if let Some(&m) = bad {
            out.push(warn(
                term,
                &named("external", term),
                format!("not finite at the initial position of particle {}", model.ids[m as usize]),
            ));
        }
    }
    for (term, &(a, b)) in model.pair_rules.iter().zip(&model.pair_rule_types).filter(|(t, _)| custom(t)) {
        let note = at_cutoff(term, term.params[0]);
        if let Some(note) = note.strip_prefix("warning: ") {
            let what = format!("pair {} {}", model.type_names[a as usize], model.type_names[b as usize]);
            out.push(warn(term, &what, format!("{}; the dynamics feel the jump (`cellmd check --selftest` runs every check)", note)));
        }
    }
    out
}

fn finite_radial(e: crate::interactions::Radial) -> bool {
    e.energy.is_finite() && e.de_dr.is_finite()
}

/// Whether the energy and the force vanish just inside the cutoff (to 1e-9
/// of the largest |E| and |dE/dr| at the checked distances): where they do
/// not, the truncation is a jump the dynamics feel as an impulse, reported
/// as a warning (not refused: LAMMPS' unshifted pair styles truncate alike).
fn at_cutoff(term: &Typed<RadialLaw>, cutoff: f64) -> String {
    let RadialLaw { eval, .. } = term.law;
    let inside: Vec<_> = [0.3, 0.55, 0.8].iter().map(|s| eval(&term.params, s * cutoff)).collect();
    let (e_scale, f_scale) = inside.iter().fold((0.0f64, 0.0f64), |(e, f), x| (e.max(x.energy.abs()), f.max(x.de_dr.abs())));
    let edge = eval(&term.params, cutoff * (1.0 - 1e-12));
    let mut notes = Vec::new();
    if !(edge.energy.abs() <= 1e-9 * e_scale) {
        notes.push(format!("E = {:e}", edge.energy));
    }
    if !(edge.de_dr.abs() <= 1e-9 * f_scale) {
        notes.push(format!("dE/dr = {:e}", edge.de_dr));
    }
    if notes.is_empty() {
        "E and F continuous at the cutoff".into()
    } else {
        format!("warning: truncated at the cutoff with {} just inside", notes.join(", "))
    }
}

fn pair_at(r: f64) -> Vec<DVec3> {
    let a = DVec3::new(0.2, -0.1, 0.3) * r;
    vec![a, a + DVec3::new(2.0, -2.0, 1.0) / 3.0 * r]
}

fn angle_at(deg: f64) -> Vec<DVec3> {
    let t = f64::to_radians(deg);
    vec![DVec3::new(0.0, 1.0, 0.2), DVec3::ZERO, DVec3::new(0.3, t.cos(), t.sin())]
}

/// The checks of `term` (named `kind label`) at each geometry.
fn run(kind: &str, label: &str, term: &TermType, geometries: &[Vec<DVec3>], size: f64) -> Result<String, String> {
    let name = if label.is_empty() { kind.to_string() } else { format!("{kind} {label}") };
    checked(|| {
        for x in geometries {
            assert_all_checks(term.interaction, &term.params, x, 1e-6 * size, 1e-9);
        }
    })
    .map(|()| format!("{name} custom: ok at {} geometries", geometries.len()))
    .map_err(|e| format!("{name}: {e}"))
}

/// Runs a check that panics on failure; the panic's message, silenced.
fn checked(check: impl FnOnce()) -> Result<(), String> {
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let result = catch_unwind(AssertUnwindSafe(check));
    std::panic::set_hook(hook);
    result.map_err(|payload| {
        payload.downcast_ref::<String>().cloned().or_else(|| payload.downcast_ref::<&str>().map(|s| s.to_string())).unwrap_or_default()
    })
}
