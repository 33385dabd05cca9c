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
//! ITEM: ATOMS id type x y z ix iy iz
//! 3 1 3 7.25 -1.5 0 0 0
//! ...
//! ```
//!
//! * Boundary letters come from [`SimBox::boundary_letter`](crate::system::SimBox::boundary_letter)
//!   (`p` periodic, `f` fixed).
//! * Atom lines are sorted by user id; `type` is the 1-based type number
//!   (type index + 1, the order of the force field's type names); positions
//!   are the stored (wrapped) ones with image flags `ix iy iz`, so the
//!   unwrapped position is `x + ix·Lx`. Reals use shortest round-trip form.
//! * The simulated time is not written (`ITEM: TIME` is not understood by
//!   every reader); it is `step · dt` for a constant time step, and the MCAP
//!   and XYZ outputs carry it.

use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::Path;

use super::{check_frame, check_topology, FrameView, Real, TopologyView, TrajectoryWriter};

/// Writes LAMMPS text dump frames to a file.
pub struct LammpsDumpWriter {
    out: BufWriter<File>,
    ids: Vec<u64>,
    types: Vec<u32>,
    /// Internal indices sorted by user id.
    order: Vec<usize>,
}

impl LammpsDumpWriter {
    /// Creates (or truncates) `path`.
    pub fn create(path: &Path, topology: &TopologyView) -> io::Result<Self> {
        check_topology(topology)?;
        let mut order: Vec<usize> = (0..topology.ids.len()).collect();
        order.sort_by_key(|&i| topology.ids[i]);
        Ok(Self { out: BufWriter::new(File::create(path)?), ids: topology.ids.to_vec(), types: topology.types.to_vec(), order })
    }
}

impl TrajectoryWriter for LammpsDumpWriter {
    fn write_frame(&mut self, frame: &FrameView) -> io::Result<()> {
        check_frame(self.ids.len(), frame)?;
        let b = frame.sim_box;
        let out = &mut self.out;
        writeln!(out, "ITEM: TIMESTEP\n{}", frame.step)?;
        writeln!(out, "ITEM: NUMBER OF ATOMS\n{}", self.ids.len())?;
        writeln!(out, "ITEM: BOX BOUNDS {0}{0} {1}{1} {2}{2}", b.boundary_letter(0), b.boundary_letter(1), b.boundary_letter(2))?;
        for a in 0..3 {
            writeln!(out, "{} {}", Real(b.lo[a]), Real(b.hi[a]))?;
        }
        writeln!(out, "ITEM: ATOMS id type x y z ix iy iz")?;
        for &i in &self.order {
            let x = frame.positions[i];
            let im = frame.image(i);
            writeln!(out, "{} {} {} {} {} {} {} {}", self.ids[i], self.types[i] + 1, Real(x.x), Real(x.y), Real(x.z), im[0], im[1], im[2])?;
        }
        Ok(())
    }

    fn finish(mut self: Box<Self>) -> io::Result<()> {
        self.out.flush()?;
        self.out.get_ref().sync_data()
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
        let mut w: Box<dyn TrajectoryWriter> = Box::new(LammpsDumpWriter::create(&path, &s.topology()).unwrap());
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
            assert_eq!(fr[8], "ITEM: ATOMS id type x y z ix iy iz");
            let mut last_id = 0;
            for line in &fr[9..] {
                let cols: Vec<&str> = line.split(' ').collect();
                assert_eq!(cols.len(), 8, "{line}");
                let id: u64 = cols[0].parse().unwrap();
                assert!(id > last_id, "sorted by id");
                last_id = id;
                let i = s.ids.iter().position(|&x| x == id).unwrap();
                assert_eq!(cols[1].parse::<u32>().unwrap(), s.types[i] + 1);
                for a in 0..3 {
                    let x: f64 = cols[2 + a].parse().unwrap();
                    assert_eq!(x.to_bits(), s.frames[f][i][a].to_bits(), "{line}");
                    assert_eq!(cols[5 + a].parse::<i32>().unwrap(), s.images[i][a]);
                }
            }
        }
        assert_eq!(lines[9], "3 1 3 7.25 -1.5 0 0 0");
        assert_eq!(lines[10], "7 2 9.95 5 2.5 -1 2 0");
    }
}
