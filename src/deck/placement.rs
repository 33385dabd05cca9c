//! Checks of the initial configuration in its box, at `cellmd check`: what
//! would otherwise pass validation and blow up at step 0 (or run on silently).
//!
//! * a bond listed twice (same type, same particles) is counted twice: only a
//!   bond type with kinetic rules may repeat a bond, each copy a molecule that
//!   breaks and rebinds on its own (a documented opt-in: parallel bonds);
//! * every particle is inside a fixed axis' bounds, and close enough to a
//!   periodic box to be wrapped into it ([`SimBox::misplaced_axis`]; LAMMPS
//!   refuses atoms outside a fixed box too);
//! * no bond whose law exerts a force at zero length (a harmonic spring with
//!   r0 > 0), and no arm of an angle, joins two coincident particles: the
//!   force's direction is undefined (a slack `cable` or a FENE bond exerts
//!   none there, and its coincident ends are harmless);
//! * no face of a body has zero area (corners coincident or collinear: its
//!   normal is undefined), to a relative [`FLAT`].
//!
//! Each error names the particles by id and points at their line.

use glam::DVec3;

use crate::input::InputError;
use crate::system::{Model, SimBox};
use crate::topology::Topology;

/// A face is degenerate when |e₁ × e₂| ≤ FLAT · |e₁| · |e₂| (the sine of its
/// angle between two edges).
pub const FLAT: f64 = 1e-12;

/// Whether bond `b` (a topology bond, with its own r0 if it has one) pulls
/// or pushes its ends at zero length.
fn pulls_at_zero_length(model: &Model, b: usize) -> bool {
    let t = model.bond_type[b] as usize;
    let mut params = model.bond_types[t].params.clone();
    if let (Some(k), Some(rest)) = (model.bond_kinetics[t].rest_index, model.initial_rest_length(b)) {
        params[k] = rest;
    }
    (model.bond_types[t].law.eval)(&params, 0.0).de_dr != 0.0
}

/// Checks the topology's initial positions in `sim_box` (`model` built from it).
pub(super) fn check_placement(topology: &Topology, model: &Model, sim_box: &SimBox) -> Result<(), InputError> {
    let x = &topology.positions;
    let id = |p: u32| topology.ids[p as usize];
    for &(b, first) in &topology.parallel_bonds {
        if model.bond_kinetics[model.bond_type[b] as usize].rules.is_empty() {
            let bond = &topology.bonds[b];
            return Err(bond.type_name.error(format!(
                "bond `{}` {}–{} is already listed at line {first}; expected each bond once (parallel bonds only of a bond type with \
                 kinetic rules)",
                bond.type_name.text,
                id(bond.particles[0]),
                id(bond.particles[1])
            )));
        }
    }
    for (i, &at) in x.iter().enumerate() {
        if let Some(axis) = sim_box.misplaced_axis(at) {
            return Err(topology.type_names[i].error(format!(
                "particle {} at {}; expected every particle in the box",
                topology.ids[i],
                sim_box.misplacement(at, axis)
            )));
        }
    }
    let images = sim_box.images();
    let separation = |i: u32, j: u32| images.minimum_image(x[j as usize] - x[i as usize]);
    for (b, bond) in topology.bonds.iter().enumerate() {
        let [i, j] = bond.particles;
        if separation(i, j) == DVec3::ZERO && pulls_at_zero_length(model, b) {
            return Err(bond.type_name.error(format!(
                "bond `{}` joins particles {} and {} at the same position, where its law `{}` exerts a force of undefined direction; \
                 expected bonded particles apart",
                bond.type_name.text,
                id(i),
                id(j),
                model.bond_types[model.bond_type[b] as usize].interaction.name()
            )));
        }
    }
    for angle in &topology.angles {
        let [i, j, k] = angle.particles;
        if let Some(p) = [i, k].into_iter().find(|&p| separation(j, p) == DVec3::ZERO) {
            return Err(angle.type_name.error(format!(
                "angle `{}` has particles {} and {} at the same position; expected its arms of non-zero length (the angle is undefined)",
                angle.type_name.text,
                id(p),
                id(j)
            )));
        }
    }
    for ((body, [a, b, c]), token) in topology.triangles.iter().zip(&topology.face_tokens) {
        let (e1, e2) = (separation(*a, *b), separation(*a, *c));
        if e1.cross(e2).length() <= FLAT * e1.length() * e2.length() {
            return Err(token.error(format!(
                "face ({}, {}, {}) of body {body} has zero area at its initial positions (corners coincident or collinear); expected a proper triangle",
                id(*a),
                id(*b),
                id(*c)
            )));
        }
    }
    Ok(())
}
