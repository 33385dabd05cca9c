//! Per-bond tension as CSV (`dump NAME every N bonds FILE.csv`).
//!
//! One header line, then per frame one row per bond in topology order:
//!
//! ```text
//! step,time[s],bond,type,id1,id2,length[µm],tension[pN],x[µm],y[µm],z[µm]
//! 100,0.1,0,fil,1,2,0.5002,0.2,0.25,0,0
//! ```
//!
//! * `bond` is the bond's 0-based index in the topology, `type` its bond
//!   type, `id1 id2` its particles' user ids (in topology order).
//! * `tension` is T = dE/dr of the bond's law at its length: **positive when
//!   stretched** (the bond pulls its ends together with force T each),
//!   negative when compressed, 0 when a kinetic bond is unbound; the same
//!   quantity as the thermo column `tension/TYPE` sums.
//! * `x y z` is the bond's midpoint (x_1 + d/2 with d the minimum-image
//!   separation; not wrapped), so tension can be plotted along a filament.
//!
//! Reals use shortest round-trip form. Bonds formed during the run (`bind`
//! rules) are not in the file: it lists the bonds that existed when it was
//! opened.

use std::fs::File;
use std::io::{self, Write};

use super::records::RecordFile;
use super::{check_frame, check_topology, invalid_input, FrameView, Needs, Real, TopologyView, TrajectoryWriter};
use crate::units::Dim;

/// Writes one CSV row per bond per frame.
pub struct BondCsvWriter {
    out: RecordFile,
    ids: Vec<u64>,
    bonds: Vec<[u32; 2]>,
    type_name: Vec<String>,
}

impl BondCsvWriter {
    /// Writes the header to `file` (empty, as opened for output).
    pub fn new(file: File, topology: &TopologyView) -> io::Result<Self> {
        check_topology(topology)?;
        let type_name = (0..topology.bonds.len())
            .map(|b| match topology.bond_types.get(b) {
                Some(&t) => super::token(topology.bond_type_names.get(t as usize).map_or("", String::as_str)),
                None => "_".into(),
            })
            .collect();
        let mut out = RecordFile::new(file);
        let u = topology.units;
        let (l, t, f) = (u.label(Dim::Length), u.label(Dim::Time), u.label(Dim::Force));
        writeln!(out, "step,time[{t}],bond,type,id1,id2,length[{l}],tension[{f}],x[{l}],y[{l}],z[{l}]")?;
        out.commit()?;
        Ok(Self { out, ids: topology.ids.to_vec(), bonds: topology.bonds.to_vec(), type_name })
    }
}

impl TrajectoryWriter for BondCsvWriter {
    fn write_frame(&mut self, frame: &FrameView) -> io::Result<()> {
        check_frame(self.ids.len(), frame)?;
        let m = &frame.measures;
        let nb = self.bonds.len();
        // Bonds formed during the run come after the topology's and are not written.
        if m.bond_tension.len() < nb || m.bond_length.len() < nb {
            return Err(invalid_input(format!("frame at step {} has {} bond tensions for {nb} bonds", frame.step, m.bond_tension.len())));
        }
        let images = frame.sim_box.images();
        for (b, &[i, j]) in self.bonds.iter().enumerate() {
            let xi = frame.positions[i as usize];
            let mid = xi + 0.5 * images.minimum_image(frame.positions[j as usize] - xi);
            writeln!(
                self.out,
                "{},{},{b},{},{},{},{},{},{},{},{}",
                frame.step,
                Real(frame.time),
                self.type_name[b],
                self.ids[i as usize],
                self.ids[j as usize],
                Real(m.bond_length[b]),
                Real(m.bond_tension[b]),
                Real(mid.x),
                Real(mid.y),
                Real(mid.z)
            )?;
        }
        // The frame's rows go to the file whole.
        self.out.commit()
    }

    fn finish(mut self: Box<Self>) -> io::Result<()> {
        self.out.finish()
    }

    fn needs(&self) -> Needs {
        Needs { bonds: true, ..Needs::default() }
    }
}

#[cfg(test)]
mod tests {
    use super::super::test_support::Sample;
    use super::super::Measures;
    use super::*;

    #[test]
    fn rows_name_bonds_by_id_and_type_with_tension_and_midpoint() {
        let s = Sample::new(1);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("b.csv");
        let names = vec!["actin".to_string(), "cross link".to_string()];
        let mut topology = s.topology();
        let types = [1u32, 0];
        topology.bond_types = &types;
        topology.bond_type_names = &names;
        let mut w: Box<dyn TrajectoryWriter> = Box::new(BondCsvWriter::new(File::create(&path).unwrap(), &topology).unwrap());
        assert!(w.write_frame(&s.frame(0)).is_err(), "a frame without tensions is refused");
        let mut frame = s.frame(0);
        frame.measures = Measures { bond_tension: &[1.5, -0.25], bond_length: &[0.1, 5.0], ..Default::default() };
        w.write_frame(&frame).unwrap();
        w.finish().unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines[0], "step,time[s],bond,type,id1,id2,length[µm],tension[pN],x[µm],y[µm],z[µm]");
        // Bond 0 joins ids 7 (x 9.95) and 12 (x 0.05) across the periodic x face: midpoint at x = 10.
        let row: Vec<&str> = lines[1].split(',').collect();
        assert_eq!(row[..8], ["0", "0", "0", "cross_link", "7", "12", "0.1", "1.5"]);
        let mid: Vec<f64> = row[8..].iter().map(|c| c.parse().unwrap()).collect();
        assert!((mid[0] - 10.0).abs() < 1e-12 && mid[1] == 5.0 && mid[2] == 2.5, "{}", lines[1]);
        assert!(lines[2].starts_with("0,0,1,actin,40,3,5,-0.25,"), "{}", lines[2]);
        assert_eq!(lines.len(), 3);
    }
}
