//! Extended XYZ trajectories (OVITO, ASE, VMD with the extxyz plugin).
//!
//! # Format
//!
//! Each frame is `N + 2` lines:
//!
//! ```text
//! 4
//! Lattice="10 0 0 0 10 0 0 0 10" Origin="0 0 -5" Properties=species:S:1:pos:R:3:Z:I:1:type_name:S:1:id:I:1 Time=0.1 Step=100 pbc="T T F" Units=cell
//! cortex 0.30000000000000004 1e-300 -0 1 cortex 40
//! adhesion_site 9.95 5 2.5 2 adhesion_site 7
//! ...
//! ```
//!
//! * `Lattice` holds the three cell vectors (orthorhombic here) row by row,
//!   `Origin` the lower corner `lo`, `pbc` the periodic flags (`T`/`F`).
//! * `Time` (time units of `Units`) and `Step` are extra per-frame keys.
//! * One line per particle in internal order: its type name (whitespace
//!   replaced by `_`) as `species`, the stored (wrapped) position, the atomic
//!   number `Z` standing for its type, the type name again as `type_name`, the
//!   user id. Reals are printed in shortest round-trip form, so they read
//!   back bit-exactly.
//!
//! # Type names and elements: how readers see them
//!
//! Type index `t` stands for the element of atomic number `Z = t + 1`
//! (wrapping after 118; [`element_symbol`](super::element_symbol): H, He, Li, …), the same mapping
//! as the LAMMPS dump's `element` column. OVITO names its particle types
//! after `species`, so it shows the type names (`cortex`, `adhesion_site`);
//! ASE builds its atoms from `Z` when a file has it (`species` is then not
//! read as chemical symbols, which type names are not), so `ase.io.read`
//! gives H, He, … as `get_chemical_symbols()` and the names as
//! `atoms.arrays["type_name"]`. Both are checked with the readers
//! themselves in `tests/suite/formats.rs`.
//!
//! Image counters are not written (extended XYZ has no standard column for
//! them); use the LAMMPS dump or MCAP output when unwrapped paths matter.

use std::fs::File;
use std::io::{self, Write};

use super::records::RecordFile;
use super::{atomic_number, check_frame, check_topology, token, units_keyword, FrameView, Real, TopologyView, TrajectoryWriter};

/// Writes extended XYZ frames to a file.
pub struct XyzWriter {
    out: RecordFile,
    ids: Vec<u64>,
    /// Atomic number standing for each particle's type.
    numbers: Vec<usize>,
    /// Type-name token of each particle.
    type_names: Vec<String>,
    units: &'static str,
}

impl XyzWriter {
    /// Writes frames to `file` (empty, as opened for output).
    pub fn new(file: File, topology: &TopologyView) -> io::Result<Self> {
        check_topology(topology)?;
        let names: Vec<String> = topology.type_names.iter().map(|n| token(n)).collect();
        Ok(Self {
            out: RecordFile::new(file),
            ids: topology.ids.to_vec(),
            numbers: topology.types.iter().map(|&t| atomic_number(t as usize)).collect(),
            type_names: topology.types.iter().map(|&t| names[t as usize].clone()).collect(),
            units: units_keyword(topology.units),
        })
    }
}

impl TrajectoryWriter for XyzWriter {
    fn write_frame(&mut self, frame: &FrameView) -> io::Result<()> {
        check_frame(self.ids.len(), frame)?;
        let b = frame.sim_box;
        let l = b.lengths();
        let tf = |p: bool| if p { 'T' } else { 'F' };
        let out = &mut self.out;
        writeln!(out, "{}", self.ids.len())?;
        writeln!(
            out,
            "Lattice=\"{} 0 0 0 {} 0 0 0 {}\" Origin=\"{} {} {}\" \
             Properties=species:S:1:pos:R:3:Z:I:1:type_name:S:1:id:I:1 Time={} Step={} pbc=\"{} {} {}\" Units={}",
            Real(l.x),
            Real(l.y),
            Real(l.z),
            Real(b.lo.x),
            Real(b.lo.y),
            Real(b.lo.z),
            Real(frame.time),
            frame.step,
            tf(b.periodic[0]),
            tf(b.periodic[1]),
            tf(b.periodic[2]),
            self.units
        )?;
        for (i, x) in frame.positions.iter().enumerate() {
            let name = &self.type_names[i];
            writeln!(out, "{name} {} {} {} {} {name} {}", Real(x.x), Real(x.y), Real(x.z), self.numbers[i], self.ids[i])?;
        }
        // The frame goes to the file whole.
        out.commit()
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
        let path = dir.path().join("t.xyz");
        let mut w: Box<dyn TrajectoryWriter> = Box::new(XyzWriter::new(File::create(&path).unwrap(), &s.topology()).unwrap());
        w.write_frame(&s.frame(0)).unwrap();
        w.write_frame(&s.frame(1)).unwrap();
        w.finish().unwrap();

        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 2 * (4 + 2));
        for f in 0..2 {
            let frame = &lines[f * 6..(f + 1) * 6];
            assert_eq!(frame[0], "4");
            assert!(frame[1].starts_with("Lattice=\"10 0 0 0 10 0 0 0 10\" Origin=\"0 0 -5\" "), "{}", frame[1]);
            assert!(frame[1].contains("Properties=species:S:1:pos:R:3:Z:I:1:type_name:S:1:id:I:1"));
            assert!(frame[1].contains("pbc=\"T T F\""));
            assert!(frame[1].contains(&format!("Step={} ", 100 * f)));
            let time: f64 = frame[1].split("Time=").nth(1).unwrap().split(' ').next().unwrap().parse().unwrap();
            assert_eq!(time, 0.1 * f as f64);
            for (i, line) in frame[2..].iter().enumerate() {
                let cols: Vec<&str> = line.split(' ').collect();
                assert_eq!(cols.len(), 7, "{line}");
                assert_eq!(cols[0], ["cortex", "adhesion_site"][s.types[i] as usize]);
                assert_eq!(cols[4], ["1", "2"][s.types[i] as usize]);
                assert_eq!(cols[5], cols[0]);
                let x: Vec<f64> = cols[1..4].iter().map(|c| c.parse().unwrap()).collect();
                let want = s.frames[f][i];
                for a in 0..3 {
                    assert_eq!(x[a].to_bits(), want[a].to_bits(), "particle {i} axis {a}: {line}");
                }
                assert_eq!(cols[6].parse::<u64>().unwrap(), s.ids[i]);
            }
        }
        assert_eq!(lines[2], "cortex 0.30000000000000004 1e-300 -0 1 cortex 40");
    }

    #[test]
    fn wrong_particle_count_is_an_error() {
        let s = Sample::new(1);
        let dir = tempfile::tempdir().unwrap();
        let mut w = XyzWriter::new(File::create(dir.path().join("t.xyz")).unwrap(), &s.topology()).unwrap();
        let mut f = s.frame(0);
        f.positions = &s.frames[0][..3];
        assert_eq!(w.write_frame(&f).unwrap_err().kind(), io::ErrorKind::InvalidInput);
    }
}
