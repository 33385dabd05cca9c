//! The LAMMPS data file of an exported deck (`data.lammps`): box, types,
//! atoms with their image flags, bonds (with the exported bond types) and
//! angles; and the largest bonded distance, which LAMMPS' ghost cutoff
//! must reach.

use std::fmt::Write;

use super::bond_types::LammpsBondTypes;
use crate::deck::Plan;
use crate::interactions::lammps::num;

/// Writes the data file.
pub(super) fn data_file(plan: &Plan, bond_types: &LammpsBondTypes, title: &str) -> String {
    let m = &plan.model;
    let b = &plan.sim_box;
    let mut s = format!("{title}\n\n{} atoms\n{} bonds\n{} angles\n", m.len(), m.bonds.len(), m.angles.len());
    let _ = writeln!(
        s,
        "{} atom types\n{} bond types\n{} angle types\n",
        m.type_names.len(),
        bond_types.count().max(1),
        m.angle_types.len().max(1)
    );
    for (a, (lo, hi)) in ["x", "y", "z"].iter().zip(b.lo.to_array().iter().zip(b.hi.to_array())) {
        let _ = writeln!(s, "{} {} {a}lo {a}hi", num(*lo), num(hi));
    }
    s += "\nMasses\n\n";
    for (t, name) in m.type_names.iter().enumerate() {
        let _ = writeln!(s, "{} 1.0  # {name}", t + 1);
    }
    s += "\nAtoms # angle\n\n";
    for (i, x) in plan.positions.iter().enumerate() {
        let (mut x, mut image) = (*x, [0; 3]);
        b.wrap(&mut x, &mut image);
        let _ =
            writeln!(s, "{} 1 {} {} {} {} {} {} {}", m.ids[i], m.types[i] + 1, num(x.x), num(x.y), num(x.z), image[0], image[1], image[2]);
    }
    if !m.bonds.is_empty() {
        s += "\nBonds\n\n";
        for (k, &[i, j]) in m.bonds.iter().enumerate() {
            let _ = writeln!(s, "{} {} {} {}", k + 1, bond_types.of_bond(k) + 1, m.ids[i as usize], m.ids[j as usize]);
        }
    }
    if !m.angles.is_empty() {
        s += "\nAngles\n\n";
        for (k, (&[i, j, l], t)) in m.angles.iter().zip(&m.angle_type).enumerate() {
            let _ = writeln!(s, "{} {} {} {} {}", k + 1, t + 1, m.ids[i as usize], m.ids[j as usize], m.ids[l as usize]);
        }
    }
    s
}

/// Largest distance between particles of one bond or angle (minimum image), so
/// LAMMPS' ghost cutoff reaches every bonded partner.
pub(super) fn bonded_extent(plan: &Plan) -> f64 {
    let x = &plan.positions;
    let d = |i: u32, j: u32| plan.sim_box.minimum_image(x[j as usize] - x[i as usize]).length();
    let bonds = plan.model.bonds.iter().map(|&[i, j]| d(i, j));
    let angles = plan.model.angles.iter().map(|&[i, j, k]| d(i, j) + d(j, k));
    bonds.chain(angles).fold(0.0, f64::max)
}
