//! A LAMMPS data file (`read_data`): header counts, box, `Masses`, `Atoms`,
//! `Bonds`, `Angles`, and the `… Coeffs` sections, checked as they are read
//! (every error at `file:line:col`): counts that match the header, types
//! within the declared ranges, atoms that exist, a finite box with
//! hi > lo, finite coordinates.

use std::collections::BTreeMap;

use super::words::{clip, data_lines, Line, Source, Word};

/// Section names a data file may hold (LAMMPS' `read_data`).
const SECTIONS: &[&str] = &[
    "Atoms",
    "Velocities",
    "Masses",
    "Ellipsoids",
    "Lines",
    "Triangles",
    "Bodies",
    "Bonds",
    "Angles",
    "Dihedrals",
    "Impropers",
    "Pair Coeffs",
    "PairIJ Coeffs",
    "Bond Coeffs",
    "Angle Coeffs",
    "Dihedral Coeffs",
    "Improper Coeffs",
    "BondBond Coeffs",
    "BondAngle Coeffs",
    "MiddleBondTorsion Coeffs",
    "EndBondTorsion Coeffs",
    "AngleTorsion Coeffs",
    "AngleAngleTorsion Coeffs",
    "BondBond13 Coeffs",
    "AngleAngle Coeffs",
    "Atom Type Labels",
    "Bond Type Labels",
    "Angle Type Labels",
    "Dihedral Type Labels",
    "Improper Type Labels",
];

/// One atom as read.
#[derive(Clone, Debug)]
pub struct Atom {
    pub id: u64,
    pub type_: usize,
    /// Unwrapped position (image flags applied).
    pub x: [f64; 3],
}

/// A data file's contents.
#[derive(Clone, Debug, Default)]
pub struct Data {
    pub lo: [f64; 3],
    pub hi: [f64; 3],
    pub atom_types: usize,
    pub bond_types: usize,
    pub angle_types: usize,
    /// The `Atoms # STYLE` comment.
    pub style_comment: String,
    pub masses: BTreeMap<usize, f64>,
    /// Type names from `Masses` comments.
    pub names: BTreeMap<usize, String>,
    pub atoms: Vec<Atom>,
    /// (type, atom ids).
    pub bonds: Vec<(usize, [u64; 2])>,
    pub angles: Vec<(usize, [u64; 3])>,
    /// `Pair Coeffs`, `Bond Coeffs`, `Angle Coeffs` lines (type, then coefficients).
    pub coeffs: BTreeMap<&'static str, Vec<Line>>,
    /// What was not translated, one line each.
    pub notes: Vec<String>,
}

/// The columns of the `Atoms` section: (type, first coordinate).
pub fn atom_columns(style: &str) -> Option<(usize, usize)> {
    match style {
        "atomic" => Some((1, 2)),
        "bond" | "angle" | "molecular" => Some((2, 3)),
        "charge" => Some((1, 3)),
        "full" => Some((2, 4)),
        _ => None,
    }
}

/// The most types of each kind a data file may declare: every type is
/// translated (atom types pair by pair), so a count of 4294967297 types
/// would run for hours. Bond types are many where each bond has its own
/// rest length (`export-lammps` writes one type per distinct length).
const MAX_TYPES: [(&str, u64); 3] = [("atom types", 1000), ("bond types", 1_000_000), ("angle types", 1_000_000)];

/// How many box lengths an atom may lie from the box (unwrapped): 2^52,
/// beyond which a position no longer resolves a box length's fraction.
const FARTHEST: f64 = 4_503_599_627_370_496.0;

/// Reads a data file; `atom_style` is the script's (else the `Atoms`
/// comment's, else `atomic`).
pub fn read(source: &Source, text: &str, atom_style: Option<&str>) -> Result<Data, String> {
    let lines = data_lines(text);
    let mut data = Data::default();
    let mut counts: BTreeMap<String, u64> = BTreeMap::new();
    let mut have_box = [false; 3];
    let mut k = 0;
    // The header: until the first section name.
    while k < lines.len() && !is_section(&lines[k]) {
        let l = &lines[k];
        k += 1;
        let Some(first) = l.words.first() else { continue };
        let all: Vec<&str> = l.words.iter().map(|w| w.text.as_str()).collect();
        let rest = &all[1..];
        match all.as_slice() {
            [_, _, lo, hi] if lo.ends_with("lo") && hi.ends_with("hi") => {
                let a = match (*lo, *hi) {
                    ("xlo", "xhi") => 0,
                    ("ylo", "yhi") => 1,
                    ("zlo", "zhi") => 2,
                    _ => return Err(source.error(&l.words[2], format!("found `{lo} {hi}`, expected xlo xhi, ylo yhi or zlo zhi"))),
                };
                let (a_lo, a_hi) = (source.number(first, "a box bound")?, source.number(&l.words[1], "a box bound")?);
                if a_hi <= a_lo || !(a_hi - a_lo).is_finite() {
                    return Err(source.error(first, format!("found the box edge [{a_lo}, {a_hi}], expected finite bounds with hi > lo")));
                }
                (data.lo[a], data.hi[a], have_box[a]) = (a_lo, a_hi, true);
            }
            [_, _, _, "xy", "xz", "yz"] => {
                data.notes.push(source.at_line(l.line, format!("`{}`: a triclinic box is not translated; the box is orthogonal", l.text)));
            }
            _ => {
                // `N atoms`, `N atom types`, `N extra bond per atom`, …
                let key = rest.join(" ");
                let n = source.count(first, &format!("the number of {key}"))?;
                if let Some(&(_, most)) = MAX_TYPES.iter().find(|(k, _)| *k == key) {
                    if n > most {
                        return Err(source.error(first, format!("found {n} {key}, expected at most {most}")));
                    }
                }
                counts.insert(key, n);
            }
        }
    }
    if let Some(a) = (0..3).find(|&a| !have_box[a]) {
        let axis = ["x", "y", "z"][a];
        // At the header's end: the first section's head, or the file's last line.
        let end = lines.get(k).or(lines.last()).map_or(1, |l| l.line);
        return Err(source.at(end, 1, format!("the header has no `LO HI {axis}lo {axis}hi` line, expected the box along {axis}")));
    }
    let count = |key: &str| counts.get(key).copied().unwrap_or(0) as usize;
    (data.atom_types, data.bond_types, data.angle_types) = (count("atom types"), count("bond types"), count("angle types"));
    // Sections.
    let mut sections: Vec<(&Line, Vec<&Line>)> = Vec::new();
    while k < lines.len() {
        let l = &lines[k];
        k += 1;
        if is_section(l) {
            sections.push((l, Vec::new()));
        } else if !l.words.is_empty() {
            match sections.last_mut() {
                Some((_, body)) => body.push(l),
                None => return Err(source.error(&l.words[0], format!("found `{}`, expected a section name", clip(&l.text)))),
            }
        }
    }
    let style = atom_style
        .map(str::to_string)
        .or_else(|| sections.iter().find(|(h, _)| h.text == "Atoms").map(|(h, _)| h.comment.clone()).filter(|c| !c.is_empty()));
    let style = style.unwrap_or_else(|| "atomic".into());
    for (head, body) in &sections {
        match head.text.as_str() {
            "Masses" => masses(source, body, &mut data)?,
            "Atoms" => {
                data.style_comment = head.comment.clone();
                atoms(source, head, body, &style, &mut data, count("atoms"))?;
            }
            "Bonds" => data.bonds = terms::<2>(source, head, body, data.bond_types, count("bonds"))?,
            "Angles" => data.angles = terms::<3>(source, head, body, data.angle_types, count("angles"))?,
            "Pair Coeffs" | "Bond Coeffs" | "Angle Coeffs" => {
                let name = SECTIONS.iter().find(|s| **s == head.text).expect("listed");
                data.coeffs.insert(name, body.iter().map(|l| (*l).clone()).collect());
            }
            "Velocities" => {
                data.notes.push(source.at_line(head.line, "section `Velocities` is not translated (overdamped dynamics has no velocities)"))
            }
            other => data.notes.push(source.at_line(head.line, format!("section `{other}` is not translated"))),
        }
    }
    if !sections.iter().any(|(h, _)| h.text == "Atoms") {
        return Err(source.at(lines.last().map_or(1, |l| l.line), 1, "found no `Atoms` section, expected one"));
    }
    let ids: std::collections::BTreeSet<u64> = data.atoms.iter().map(|a| a.id).collect();
    for (what, members) in data.bonds.iter().map(|b| ("bond", b.1.to_vec())).chain(data.angles.iter().map(|a| ("angle", a.1.to_vec()))) {
        if let Some(missing) = members.iter().find(|m| !ids.contains(m)) {
            // The first line of the section that names it.
            let section = if what == "bond" { "Bonds" } else { "Angles" };
            let body = sections.iter().filter(|(h, _)| h.text == section).flat_map(|(_, b)| b.iter());
            let word = body.flat_map(|l| l.words.iter().skip(2)).find(|w| w.text.parse::<u64>().ok() == Some(*missing));
            let message = format!("a {what} names atom {missing}, which the `Atoms` section does not list");
            return Err(match word {
                Some(w) => source.error(w, message),
                None => source.at(1, 1, message),
            });
        }
    }
    Ok(data)
}

fn is_section(l: &Line) -> bool {
    SECTIONS.contains(&l.text.as_str())
}

fn masses(source: &Source, body: &[&Line], data: &mut Data) -> Result<(), String> {
    for l in body {
        let t = type_of(source, &l.words[0], data.atom_types, "atom type")?;
        let m = source.number(l.words.get(1).ok_or_else(|| source.error(&l.words[0], "expected a type and its mass"))?, "a mass")?;
        data.masses.insert(t, m);
        if let Some(name) = l.comment.split_whitespace().next() {
            data.names.insert(t, name.to_string());
        }
    }
    Ok(())
}

/// A type number within 1..=n.
pub fn type_of(source: &Source, w: &Word, n: usize, what: &str) -> Result<usize, String> {
    match w.text.parse::<usize>() {
        Ok(t) if (1..=n).contains(&t) => Ok(t),
        _ => Err(source.error(w, format!("found `{}`, expected an {what} from 1 to {n}", clip(&w.text)))),
    }
}

fn atoms(source: &Source, head: &Line, body: &[&Line], style: &str, data: &mut Data, expected: usize) -> Result<(), String> {
    let (type_col, x_col) = atom_columns(style).ok_or_else(|| {
        source.error(
            &head.words[0],
            format!("atom style `{style}` is not translated; expected atomic, bond, angle, molecular, charge or full"),
        )
    })?;
    let length: Vec<f64> = (0..3).map(|a| data.hi[a] - data.lo[a]).collect();
    let charge_col = match style {
        "charge" => Some(2),
        "full" => Some(3),
        _ => None,
    };
    let mut charged = false;
    for l in body {
        let w = &l.words;
        if w.len() < x_col + 3 {
            return Err(source.error(
                &w[0],
                format!("found {} columns, expected {} for atom style `{style}` (id … x y z [ix iy iz])", w.len(), x_col + 3),
            ));
        }
        let id = source.count(&w[0], "an atom id")?;
        if id == 0 {
            return Err(source.error(&w[0], "found atom id 0, expected a positive id"));
        }
        let t = type_of(source, &w[type_col], data.atom_types, "atom type")?;
        let mut x = [0.0; 3];
        for a in 0..3 {
            let image = match w.get(x_col + 3 + a) {
                Some(i) => i
                    .text
                    .parse::<i64>()
                    .map_err(|_| source.error(i, format!("found `{}`, expected an image flag (an integer)", clip(&i.text))))?,
                None => 0,
            };
            x[a] = source.number(&w[x_col + a], "a coordinate")? + image as f64 * length[a];
            // LAMMPS remaps an atom into a periodic box; one this far away cannot be (nor placed in a fixed one).
            let lengths_away = ((x[a] - data.lo[a]) / length[a]).abs();
            if lengths_away.is_nan() || lengths_away >= FARTHEST {
                let shown = &w[x_col + a];
                return Err(
                    source.error(shown, format!("found atom {id} {lengths_away:e} box lengths from the box, expected at most 2^52"))
                );
            }
        }
        if let Some(q) = charge_col.and_then(|k| w.get(k)) {
            charged |= source.number(q, "a charge")? != 0.0;
        }
        data.atoms.push(Atom { id, type_: t, x });
    }
    if charged {
        data.notes.push(source.at_line(head.line, "the atoms' charges are not translated (cellmd has no electrostatics)"));
    }
    if data.atoms.len() != expected {
        return Err(
            source.error(&head.words[0], format!("found {} atoms in `Atoms`, expected {expected} (the header's count)", data.atoms.len()))
        );
    }
    Ok(())
}

fn terms<const N: usize>(
    source: &Source,
    head: &Line,
    body: &[&Line],
    types: usize,
    expected: usize,
) -> Result<Vec<(usize, [u64; N])>, String> {
    let what = if N == 2 { "bond" } else { "angle" };
    let mut out = Vec::new();
    for l in body {
        let w = &l.words;
        if w.len() < 2 + N {
            return Err(source.error(&w[0], format!("found {} columns, expected an id, a {what} type and {N} atom ids", w.len())));
        }
        let t = type_of(source, &w[1], types, &format!("{what} type"))?;
        let mut ids = [0; N];
        for (k, id) in ids.iter_mut().enumerate() {
            *id = source.count(&w[2 + k], "an atom id")?;
        }
        out.push((t, ids));
    }
    if out.len() != expected {
        return Err(
            source.error(&head.words[0], format!("found {} lines in `{}`, expected {expected} (the header's count)", out.len(), head.text))
        );
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn src() -> Source {
        Source { name: "d.data".into() }
    }

    const DATA: &str = "title\n\n2 atoms\n1 bonds\n2 atom types\n1 bond types\n\n0 10 xlo xhi\n0 10 ylo yhi\n-1 1 zlo zhi\n\n\
                        Masses\n\n1 1.0 # actin\n2 2.5\n\nAtoms # molecular\n\n1 1 1 0.5 0.5 0 1 0 0\n2 1 2 1.5 0.5 0\n\nBonds\n\n1 1 1 2\n";

    #[test]
    fn a_molecular_data_file_reads_with_unwrapped_positions_and_names() {
        let d = read(&src(), DATA, None).unwrap();
        assert_eq!((d.atom_types, d.bond_types), (2, 1));
        assert_eq!(d.atoms[0].x, [10.5, 0.5, 0.0]);
        assert_eq!(d.names[&1], "actin");
        assert_eq!(d.masses[&2], 2.5);
        assert_eq!(d.bonds, vec![(1, [1, 2])]);
    }

    #[test]
    fn bad_data_is_an_error_at_its_token() {
        let bad = |from: &str, to: &str| read(&src(), &DATA.replace(from, to), None).unwrap_err();
        assert_eq!(bad("2 atoms", "two atoms"), "d.data:3:1: found `two`, expected the number of atoms (a whole number)");
        assert_eq!(bad("0 10 ylo", "0 inf ylo"), "d.data:9:3: found `inf`, expected a box bound (a finite number)");
        assert_eq!(bad("0 10 ylo", "NaN 10 ylo"), "d.data:9:1: found `NaN`, expected a box bound (a finite number)");
        assert!(bad("-1 1 zlo", "1 -1 zlo").starts_with("d.data:10:1: found the box edge [1, -1]"));
        assert_eq!(bad("2 1 2 1.5", "2 1 3 1.5"), "d.data:20:5: found `3`, expected an atom type from 1 to 2");
        assert_eq!(bad("1 1 1 2\n", "1 1 1 7\n"), "d.data:24:7: a bond names atom 7, which the `Atoms` section does not list");
        assert_eq!(bad("2 atom types", "1001 atom types"), "d.data:5:1: found 1001 atom types, expected at most 1000");
        assert_eq!(bad("2 1 2 1.5 0.5 0\n", ""), "d.data:17:1: found 1 atoms in `Atoms`, expected 2 (the header's count)");
        assert_eq!(bad("-1 1 zlo zhi", ""), "d.data:12:1: the header has no `LO HI zlo zhi` line, expected the box along z");
        assert_eq!(bad("Atoms # molecular", "Velocities"), "d.data:24:1: found no `Atoms` section, expected one");
        assert!(bad("Atoms # molecular", "Atoms # ellipsoid").contains("atom style `ellipsoid` is not translated"));
    }
}
