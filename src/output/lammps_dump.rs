//! LAMMPS text dumps (`dump atom`-style, readable by OVITO, VMD, MDAnalysis).
//!
//! # Format
//!
//! Each frame:
//!
//! ```text
//! ITEM: TIMESTEP
//! 100
//! ITEM: NUMBER OF ATOMS
//! 4
//! ITEM: BOX BOUNDS pp pp ff
//! 0 10
//! 0 10
//! -5 5
//! ITEM: ATOMS id type element x y z ix iy iz
//! 3 1 H 3 7.25 -1.5 0 0 0
//! ...
//! ```
//!
//! * Boundary letters come from [`SimBox::boundary_letter`](crate::system::SimBox::boundary_letter)
//!   (`p` periodic, `f` fixed).
//! * Atom lines are sorted by user id; `type` is the 1-based type number
//!   (type index + 1, the order of the force field's type names) and
//!   `element` the chemical symbol standing for the type: type index `t` is
//!   the element of atomic number `t + 1` (H, He, Li, …, as
//!   [`super::element_symbol`] and the extended XYZ's `Z`
//!   column). LAMMPS' `dump_modify element` column holds chemical elements,
//!   and readers take it so: ASE (`ase.io.read(…, format="lammps-dump-text")`)
//!   maps it to atomic numbers and fails on any other name, OVITO and VMD
//!   name the particle types after it. Type names have no column in a dump
//!   that every reader accepts (OVITO refuses a text column it does not
//!   know); the extended XYZ (`species`, `type_name`) and the MCAP carry
//!   them, and the mapping is fixed by the force field's type order (the
//!   first `particle` line is `1`/H, the second `2`/He, …). Positions are
//!   the stored (wrapped) ones with
//!   image flags `ix iy iz`, so the unwrapped position is `x + ix·Lx`. Reals
//!   use shortest round-trip form.
//! * `dump … lammps FILE columns C...` selects the atom columns instead
//!   (LAMMPS `dump custom` style; the header line names them). Without
//!   `columns` the output is the default above, unchanged. See [`AtomColumn`]
//!   for the names and units; the per-particle stress columns follow LAMMPS
//!   `compute stress/atom` (see [`crate::measure::stress`]).
//! * The simulated time is not written (`ITEM: TIME` is not understood by
//!   every reader); it is `step · dt` for a constant time step, and the MCAP
//!   and XYZ outputs carry it.

use std::fs::File;
use std::io::{self, Write};

use super::records::RecordFile;
use super::{check_frame, check_topology, element_symbol, invalid_input, FrameView, Needs, Real, TopologyView, TrajectoryWriter};

/// A per-atom column of a LAMMPS dump (`dump … lammps FILE columns ...`).
///
/// | name | meaning | unit (`cell`) |
/// |---|---|---|
/// | `id`, `type` | user id, 1-based type number | – |
/// | `element` | the chemical symbol whose atomic number is the type number (H for type 1, He for 2, …; ASE, OVITO and VMD read it as the particle type) | – |
/// | `x y z` | stored (wrapped) position | µm |
/// | `ix iy iz` | image flags | – |
/// | `xu yu zu` | unwrapped position x + ix·Lx | µm |
/// | `fx fy fz` | total force | pN |
/// | `wxx wyy wzz wxy wxz wyz` | per-particle virial W_i (Σ_i W_i = the thermo virial; positive in compression) | pN·µm |
/// | `sxx syy szz sxy sxz syz` | LAMMPS `compute stress/atom`: S_i = −W_i (stress × volume; positive in tension) | pN·µm |
/// | `vonmises` | von Mises equivalent of S_i | pN·µm |
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AtomColumn {
    Id,
    Type,
    /// The type's name.
    Element,
    /// Wrapped position component.
    X(usize),
    Image(usize),
    /// Unwrapped position component.
    Unwrapped(usize),
    Force(usize),
    /// Per-particle virial component (xx yy zz xy xz yz).
    Virial(usize),
    /// Per-particle stress × volume, −virial (xx yy zz xy xz yz).
    Stress(usize),
    VonMises,
}

const TENSOR: [&str; 6] = ["xx", "yy", "zz", "xy", "xz", "yz"];
const AXES: [&str; 3] = ["x", "y", "z"];

impl AtomColumn {
    /// Every column, in the order `cellmd` lists them.
    pub fn all() -> Vec<AtomColumn> {
        let mut v = vec![AtomColumn::Id, AtomColumn::Type, AtomColumn::Element];
        v.extend((0..3).map(AtomColumn::X));
        v.extend((0..3).map(AtomColumn::Image));
        v.extend((0..3).map(AtomColumn::Unwrapped));
        v.extend((0..3).map(AtomColumn::Force));
        v.extend((0..6).map(AtomColumn::Virial));
        v.extend((0..6).map(AtomColumn::Stress));
        v.push(AtomColumn::VonMises);
        v
    }

    /// The default columns: `id type element x y z ix iy iz`.
    pub fn defaults() -> Vec<AtomColumn> {
        let mut v = vec![AtomColumn::Id, AtomColumn::Type, AtomColumn::Element];
        v.extend((0..3).map(AtomColumn::X));
        v.extend((0..3).map(AtomColumn::Image));
        v
    }

    /// The deck and header name.
    pub fn name(self) -> String {
        match self {
            AtomColumn::Id => "id".into(),
            AtomColumn::Type => "type".into(),
            AtomColumn::Element => "element".into(),
            AtomColumn::X(a) => AXES[a].into(),
            AtomColumn::Image(a) => format!("i{}", AXES[a]),
            AtomColumn::Unwrapped(a) => format!("{}u", AXES[a]),
            AtomColumn::Force(a) => format!("f{}", AXES[a]),
            AtomColumn::Virial(k) => format!("w{}", TENSOR[k]),
            AtomColumn::Stress(k) => format!("s{}", TENSOR[k]),
            AtomColumn::VonMises => "vonmises".into(),
        }
    }

    /// The column named `name`.
    pub fn from_name(name: &str) -> Option<AtomColumn> {
        AtomColumn::all().into_iter().find(|c| c.name() == name)
    }

    fn needs(self) -> Needs {
        match self {
            AtomColumn::Force(_) => Needs { forces: true, ..Needs::default() },
            AtomColumn::Virial(_) | AtomColumn::Stress(_) | AtomColumn::VonMises => Needs { virial: true, ..Needs::default() },
            _ => Needs::default(),
        }
    }
}

/// Writes LAMMPS text dump frames to a file.
pub struct LammpsDumpWriter {
    out: RecordFile,
    ids: Vec<u64>,
    types: Vec<u32>,
    /// Internal indices sorted by user id.
    order: Vec<usize>,
    columns: Vec<AtomColumn>,
    needs: Needs,
    line: String,
}

impl LammpsDumpWriter {
    /// Writes frames of `columns` (empty: the defaults) to `file` (empty, as opened for output).
    pub fn new(file: File, topology: &TopologyView, columns: &[AtomColumn]) -> io::Result<Self> {
        check_topology(topology)?;
        let mut order: Vec<usize> = (0..topology.ids.len()).collect();
        order.sort_by_key(|&i| topology.ids[i]);
        let columns = if columns.is_empty() { AtomColumn::defaults() } else { columns.to_vec() };
        let needs = columns.iter().fold(Needs::default(), |a, c| {
            let n = c.needs();
            Needs { forces: a.forces || n.forces, virial: a.virial || n.virial, bonds: a.bonds || n.bonds }
        });
        Ok(Self {
            out: RecordFile::new(file),
            ids: topology.ids.to_vec(),
            types: topology.types.to_vec(),
            order,
            columns,
            needs,
            line: String::new(),
        })
    }
}

impl TrajectoryWriter for LammpsDumpWriter {
    fn write_frame(&mut self, frame: &FrameView) -> io::Result<()> {
        check_frame(self.ids.len(), frame)?;
        // Everything is checked before the first byte, so a refused frame leaves no partial record.
        let n = self.ids.len();
        let m = &frame.measures;
        if self.needs.forces && m.forces.len() != n {
            return Err(invalid_input(format!("frame at step {} has {} forces for {n} particles", frame.step, m.forces.len())));
        }
        if self.needs.virial && m.virial.len() != n {
            return Err(invalid_input(format!("frame at step {} has {} virials for {n} particles", frame.step, m.virial.len())));
        }
        let b = frame.sim_box;
        let out = &mut self.out;
        writeln!(out, "ITEM: TIMESTEP\n{}", frame.step)?;
        writeln!(out, "ITEM: NUMBER OF ATOMS\n{}", self.ids.len())?;
        writeln!(out, "ITEM: BOX BOUNDS {0}{0} {1}{1} {2}{2}", b.boundary_letter(0), b.boundary_letter(1), b.boundary_letter(2))?;
        for a in 0..3 {
            writeln!(out, "{} {}", Real(b.lo[a]), Real(b.hi[a]))?;
        }
        let names: Vec<String> = self.columns.iter().map(|c| c.name()).collect();
        writeln!(out, "ITEM: ATOMS {}", names.join(" "))?;
        let line = &mut self.line;
        for &i in &self.order {
            line.clear();
            for (k, c) in self.columns.iter().enumerate() {
                if k > 0 {
                    line.push(' ');
                }
                use std::fmt::Write as _;
                let _ = match *c {
                    AtomColumn::Id => write!(line, "{}", self.ids[i]),
                    AtomColumn::Type => write!(line, "{}", self.types[i] + 1),
                    AtomColumn::Element => line.write_str(element_symbol(self.types[i] as usize)),
                    AtomColumn::X(a) => write!(line, "{}", Real(frame.positions[i][a])),
                    AtomColumn::Image(a) => write!(line, "{}", frame.image(i)[a]),
                    AtomColumn::Unwrapped(a) => write!(line, "{}", Real(b.unwrap(frame.positions[i], frame.image(i))[a])),
                    AtomColumn::Force(a) => write!(line, "{}", Real(m.forces[i][a])),
                    AtomColumn::Virial(t) => write!(line, "{}", Real(m.virial[i][t])),
                    AtomColumn::Stress(t) => write!(line, "{}", Real(-m.virial[i][t])),
                    AtomColumn::VonMises => write!(line, "{}", Real(crate::measure::von_mises(&m.virial[i]))),
                };
            }
            writeln!(out, "{line}")?;
        }
        // The frame goes to the file whole.
        out.commit()
    }

    fn needs(&self) -> Needs {
        self.needs
    }

    fn finish(mut self: Box<Self>) -> io::Result<()> {
        self.out.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::Sample;
    use super::*;

    #[test]
    fn two_frames_read_back() {
        let s = Sample::new(2);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.lammpstrj");
        let mut w: Box<dyn TrajectoryWriter> = Box::new(LammpsDumpWriter::new(File::create(&path).unwrap(), &s.topology(), &[]).unwrap());
        w.write_frame(&s.frame(0)).unwrap();
        w.write_frame(&s.frame(1)).unwrap();
        w.finish().unwrap();

        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        let per_frame = 9 + 4;
        assert_eq!(lines.len(), 2 * per_frame);
        for f in 0..2 {
            let fr = &lines[f * per_frame..(f + 1) * per_frame];
            assert_eq!(fr[0], "ITEM: TIMESTEP");
            assert_eq!(fr[1], (100 * f).to_string());
            assert_eq!(fr[2], "ITEM: NUMBER OF ATOMS");
            assert_eq!(fr[3], "4");
            assert_eq!(fr[4], "ITEM: BOX BOUNDS pp pp ff");
            assert_eq!(&fr[5..8], &["0 10", "0 10", "-5 5"]);
            assert_eq!(fr[8], "ITEM: ATOMS id type element x y z ix iy iz");
            let mut last_id = 0;
            for line in &fr[9..] {
                let cols: Vec<&str> = line.split(' ').collect();
                assert_eq!(cols.len(), 9, "{line}");
                let id: u64 = cols[0].parse().unwrap();
                assert!(id > last_id, "sorted by id");
                last_id = id;
                let i = s.ids.iter().position(|&x| x == id).unwrap();
                assert_eq!(cols[1].parse::<u32>().unwrap(), s.types[i] + 1);
                assert_eq!(cols[2], ["H", "He"][s.types[i] as usize]);
                for a in 0..3 {
                    let x: f64 = cols[3 + a].parse().unwrap();
                    assert_eq!(x.to_bits(), s.frames[f][i][a].to_bits(), "{line}");
                    assert_eq!(cols[6 + a].parse::<i64>().unwrap(), s.images[i][a]);
                }
            }
        }
        assert_eq!(lines[9], "3 1 H 3 7.25 -1.5 0 0 0");
        assert_eq!(lines[10], "7 2 He 9.95 5 2.5 -1 2 0");
    }

    #[test]
    fn selected_columns_write_forces_stress_and_von_mises() {
        let s = Sample::new(1);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("s.lammpstrj");
        let names = "id xu fx wxy sxx syy szz sxy vonmises";
        let columns: Vec<AtomColumn> = names.split(' ').map(|n| AtomColumn::from_name(n).unwrap()).collect();
        let mut w = LammpsDumpWriter::new(File::create(&path).unwrap(), &s.topology(), &columns).unwrap();
        assert_eq!(w.needs(), Needs { forces: true, virial: true, bonds: false });
        // Without the measures the frame is refused, not written with zeros.
        assert!(w.write_frame(&s.frame(0)).is_err());
        let forces: Vec<glam::DVec3> = (0..4).map(|i| glam::DVec3::new(i as f64 + 0.5, 0.0, 0.0)).collect();
        // Particle k: a hydrostatic virial −k·I plus a shear k in xy.
        let virial: Vec<[f64; 6]> = (0..4).map(|k| [-(k as f64), -(k as f64), -(k as f64), k as f64, 0.0, 0.0]).collect();
        let mut frame = s.frame(0);
        frame.measures = super::super::Measures { forces: &forces, virial: &virial, ..Default::default() };
        w.write_frame(&frame).unwrap();
        Box::new(w).finish().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[8], format!("ITEM: ATOMS {names}"));
        for line in &lines[9..] {
            let cols: Vec<f64> = line.split(' ').map(|c| c.parse().unwrap()).collect();
            let i = s.ids.iter().position(|&x| x as f64 == cols[0]).unwrap();
            let k = i as f64;
            let xu = s.sim_box.unwrap(s.frames[0][i], s.images[i]).x;
            assert_eq!(cols[1..5], [xu, k + 0.5, k, k]);
            assert_eq!(cols[5..8], [k, k, -k], "stress is −virial");
            assert!((cols[8] - 3f64.sqrt() * k).abs() < 1e-12, "von Mises of the shear alone: {line}");
        }
    }

    #[test]
    fn column_names_round_trip_and_defaults_name_the_element() {
        for c in AtomColumn::all() {
            assert_eq!(AtomColumn::from_name(&c.name()), Some(c));
        }
        let names: Vec<String> = AtomColumn::defaults().iter().map(|c| c.name()).collect();
        assert_eq!(names.join(" "), "id type element x y z ix iy iz");
        assert_eq!(AtomColumn::from_name("c_stress[1]"), None);
    }
}
