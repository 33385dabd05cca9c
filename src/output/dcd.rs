//! DCD trajectories (CHARMM/NAMD binary; read by MDAnalysis, MDTraj, VMD).
//!
//! # Format
//!
//! Little-endian Fortran unformatted records, each framed by its byte length
//! as an `i32` before and after:
//!
//! 1. `CORD` and 20 `i32` control words: frame count (`NSET`), first step
//!    (`ISTART`), steps between frames (`NSAVC`), last step (`NSTEP`), the
//!    time step as an `f32` in AKMA time units (`DELTA`, word 10; see
//!    below), 1 in word 11 (a unit cell
//!    precedes each frame) and 24 in word 20 (CHARMM version, which readers
//!    take as "CHARMM format");
//! 2. two 80-byte title lines (`cellmd VERSION`, the unit system);
//! 3. the particle count;
//! 4. per frame: the unit cell as six `f64` `[Lx, cos γ, Ly, cos β, cos α, Lz]`
//!    (orthorhombic: cosines 0, read as 90°), then three records of `f32`:
//!    all x, all y, all z.
//!
//! Particles are sorted by user id (like the LAMMPS dump), so a topology
//! written in id order (a LAMMPS data file from `cellmd export-lammps`, a PDB)
//! lines up with the coordinates. Positions are the stored (wrapped) ones in
//! the deck's length unit, rounded to `f32`; readers label them Å.
//!
//! Time: CHARMM's DCD stores `DELTA` in AKMA time units (1 AKMA =
//! 4.888821·10⁻² ps), and readers convert it: MDAnalysis reports
//! `dt = DELTA·NSAVC·0.04888821` ps. cellmd writes `DELTA = dt / 0.04888821`
//! (dt the deck's time step in its own unit), so that a reader's time is the
//! deck's number for number, as its lengths are: MDAnalysis reads a frame
//! interval of 0.01 s as `dt = 0.01` ("ps") and each frame's `time` as
//! step·dt. For `cell` units read "Å" as µm and "ps" as seconds (DCD has no
//! unit field; the second title line names the unit system). The box origin is not
//! stored (DCD has none); image counters are not either: use the LAMMPS dump
//! (`xu yu zu`) or the MCAP for unwrapped paths.
//!
//! The header's counters are rewritten after every frame, so a file cut off
//! after a frame is a valid trajectory up to it. `NSAVC` and `DELTA` come
//! from the first two frames (`DELTA = Δtime/Δstep/0.04888821`); a single-frame file has
//! `NSAVC = 1` and `DELTA = 0`.

use std::fs::File;
use std::io::{self, Write};

use super::records::RecordFile;
use super::{check_frame, check_topology, units_keyword, FrameView, TopologyView, TrajectoryWriter};

/// Byte offset of the control words (after the record marker and `CORD`).
const CONTROL_OFFSET: u64 = 8;
/// The CHARMM version written in control word 20.
const CHARMM_VERSION: i32 = 24;
/// One AKMA time unit in picoseconds (CHARMM's, as MDAnalysis converts it).
pub const AKMA_PS: f64 = 4.888821e-2;

/// Writes DCD frames to a file.
pub struct DcdWriter {
    out: RecordFile,
    /// Internal indices sorted by user id.
    order: Vec<usize>,
    frames: i32,
    /// Step and time of the first frame.
    first: Option<(u64, f64)>,
    /// `NSAVC` and `DELTA`, fixed by the second frame.
    interval: Option<(i32, f32)>,
    last_step: u64,
    coords: Vec<u8>,
}

impl DcdWriter {
    /// Writes the header to `file` (empty, as opened for output).
    pub fn new(file: File, topology: &TopologyView) -> io::Result<Self> {
        check_topology(topology)?;
        let n = i32::try_from(topology.ids.len())
            .ok()
            .filter(|&n| n <= i32::MAX / 4)
            .ok_or_else(|| super::invalid_input(format!("{} particles are more than a DCD file holds", topology.ids.len())))?;
        let mut order: Vec<usize> = (0..topology.ids.len()).collect();
        order.sort_by_key(|&i| topology.ids[i]);
        let mut w = Self {
            out: RecordFile::new(file),
            order,
            frames: 0,
            first: None,
            interval: None,
            last_step: 0,
            coords: Vec::with_capacity(4 * n as usize),
        };
        let mut head = b"CORD".to_vec();
        head.extend(w.control().iter().flat_map(|c| c.to_le_bytes()));
        record(&mut w.out, &head)?;
        let mut title = 2i32.to_le_bytes().to_vec();
        for line in [format!("cellmd {}", env!("CARGO_PKG_VERSION")), format!("units {}", units_keyword(topology.units))] {
            title.extend(format!("{line:<80.80}").bytes());
        }
        record(&mut w.out, &title)?;
        record(&mut w.out, &n.to_le_bytes())?;
        w.out.commit()?;
        Ok(w)
    }

    /// The 20 control words for the frames written so far.
    fn control(&self) -> [i32; 20] {
        let (first_step, _) = self.first.unwrap_or((0, 0.0));
        let (nsavc, delta) = self.interval.unwrap_or((1, 0.0));
        let mut c = [0i32; 20];
        c[0] = self.frames;
        c[1] = clamp_i32(first_step);
        c[2] = nsavc;
        c[3] = clamp_i32(self.last_step);
        c[9] = delta.to_bits() as i32;
        c[10] = 1;
        c[19] = CHARMM_VERSION;
        c
    }
}

/// `x` as an `i32`, saturating (DCD counters are 32-bit).
fn clamp_i32(x: u64) -> i32 {
    i32::try_from(x).unwrap_or(i32::MAX)
}

/// One Fortran record: length, bytes, length.
fn record(out: &mut impl Write, bytes: &[u8]) -> io::Result<()> {
    let len = (bytes.len() as i32).to_le_bytes();
    out.write_all(&len)?;
    out.write_all(bytes)?;
    out.write_all(&len)
}

impl TrajectoryWriter for DcdWriter {
    fn write_frame(&mut self, frame: &FrameView) -> io::Result<()> {
        check_frame(self.order.len(), frame)?;
        if self.frames == i32::MAX {
            return Err(io::Error::other("a DCD file holds at most 2^31 - 1 frames"));
        }
        match self.first {
            None => self.first = Some((frame.step, frame.time)),
            Some((step0, time0)) if self.interval.is_none() => {
                let steps = frame.step.saturating_sub(step0).max(1);
                // The deck's time per step, as AKMA units whose picoseconds are the same number.
                self.interval = Some((clamp_i32(steps), ((frame.time - time0) / steps as f64 / AKMA_PS) as f32));
            }
            Some(_) => {}
        }
        self.frames += 1;
        self.last_step = frame.step;
        let l = frame.sim_box.lengths();
        let cell: Vec<u8> = [l.x, 0.0, l.y, 0.0, 0.0, l.z].iter().flat_map(|v| v.to_le_bytes()).collect();
        record(&mut self.out, &cell)?;
        for a in 0..3 {
            self.coords.clear();
            self.coords.extend(self.order.iter().flat_map(|&i| (frame.positions[i][a] as f32).to_le_bytes()));
            record(&mut self.out, &self.coords)?;
        }
        // The frame goes to the file whole, then the header counts it.
        self.out.commit()?;
        let control: Vec<u8> = self.control().iter().flat_map(|c| c.to_le_bytes()).collect();
        self.out.overwrite(CONTROL_OFFSET, &control)
    }

    fn finish(mut self: Box<Self>) -> io::Result<()> {
        self.out.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::Sample;
    use super::*;

    /// Splits a DCD file into its records, checking each frame marker.
    fn records(bytes: &[u8]) -> Vec<&[u8]> {
        let mut out = Vec::new();
        let mut k = 0;
        while k < bytes.len() {
            let len = i32::from_le_bytes(bytes[k..k + 4].try_into().unwrap()) as usize;
            let body = &bytes[k + 4..k + 4 + len];
            assert_eq!(&bytes[k + 4 + len..k + 8 + len], &bytes[k..k + 4], "record at byte {k}: end marker");
            out.push(body);
            k += 8 + len;
        }
        out
    }

    fn words(bytes: &[u8]) -> Vec<i32> {
        bytes.chunks(4).map(|c| i32::from_le_bytes(c.try_into().unwrap())).collect()
    }

    #[test]
    fn header_frames_and_id_order_read_back() {
        let s = Sample::new(3);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.dcd");
        let mut w: Box<dyn TrajectoryWriter> = Box::new(DcdWriter::new(File::create(&path).unwrap(), &s.topology()).unwrap());
        for f in 0..3 {
            w.write_frame(&s.frame(f)).unwrap();
        }
        w.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let r = records(&bytes);
        assert_eq!(r.len(), 3 + 3 * 4);
        assert_eq!(&r[0][..4], b"CORD");
        let control = words(&r[0][4..]);
        assert_eq!(control.len(), 20);
        // Three frames from step 0 every 100 steps, 0.1 time units per 100 steps.
        assert_eq!(control[..4], [3, 0, 100, 200]);
        assert_eq!(f32::from_bits(control[9] as u32), (0.1f64 / 100.0 / AKMA_PS) as f32);
        assert_eq!((control[10], control[19]), (1, CHARMM_VERSION));
        assert_eq!(words(&r[1][..4]), [2]);
        assert_eq!(r[1].len(), 4 + 160);
        assert!(r[1][4..].starts_with(b"cellmd "));
        assert_eq!(words(r[2]), [4]);
        let ids_sorted = [3u64, 7, 12, 40];
        for f in 0..3 {
            let cell: Vec<f64> = r[3 + 4 * f].chunks(8).map(|c| f64::from_le_bytes(c.try_into().unwrap())).collect();
            assert_eq!(cell, [10.0, 0.0, 10.0, 0.0, 0.0, 10.0]);
            for a in 0..3 {
                let xs: Vec<f32> = r[4 + 4 * f + a].chunks(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
                for (k, id) in ids_sorted.iter().enumerate() {
                    let i = s.ids.iter().position(|x| x == id).unwrap();
                    assert_eq!(xs[k], s.frames[f][i][a] as f32, "frame {f} id {id} axis {a}");
                }
            }
        }
    }

    #[test]
    fn the_header_counts_the_frames_on_disk_before_finish() {
        let s = Sample::new(1);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("t.dcd");
        let mut w = DcdWriter::new(File::create(&path).unwrap(), &s.topology()).unwrap();
        w.write_frame(&s.frame(0)).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let control = words(&records(&bytes)[0][4..]);
        assert_eq!(control[..4], [1, 0, 1, 0]);
        let mut f = s.frame(0);
        f.positions = &s.frames[0][..2];
        assert_eq!(w.write_frame(&f).unwrap_err().kind(), io::ErrorKind::InvalidInput);
    }
}
