//! Checks of the initial configuration in its box, at `cellmd check`: what
//! would otherwise pass validation and blow up at step 0 (or run on silently).
//!
//! * every particle is inside a fixed axis' bounds, and close enough to a
//!   periodic box to be wrapped into it ([`SimBox::misplaced_axis`]; LAMMPS
//!   refuses atoms outside a fixed box too);
//! * no bond, and no arm of an angle, joins two coincident particles (its
//!   direction, and so its force, is undefined);
//! * no face of a body has zero area (corners coincident or collinear: its
//!   normal is undefined), to a relative [`FLAT`].
//!
//! Each error names the particles by id and points at their line.

use glam::DVec3;

use crate::input::InputError;
use crate::system::SimBox;
use crate::topology::Topology;

/// A face is degenerate when |e₁ × e₂| ≤ FLAT · |e₁| · |e₂| (the sine of its
/// angle between two edges).
pub const FLAT: f64 = 1e-12;

/// Checks the topology's initial positions in `sim_box`.
pub(super) fn check_placement(topology: &Topology, sim_box: &SimBox) -> Result<(), InputError> {
    let x = &topology.positions;
    let id = |p: u32| topology.ids[p as usize];
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
    for bond in &topology.bonds {
        let [i, j] = bond.particles;
        if separation(i, j) == DVec3::ZERO {
            return Err(bond.type_name.error(format!(
                "bond `{}` joins particles {} and {} at the same position; expected bonded particles apart (the bond's direction is undefined)",
                bond.type_name.text,
                id(i),
                id(j)
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
