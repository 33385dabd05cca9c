//! Trajectory output (MCAP, extended XYZ, LAMMPS dump) and restart files.
//!
//! A run hands each writer borrowed views of what it has: a [`TopologyView`]
//! once, when the writer is opened, and a [`FrameView`] per frame. Writers
//! copy the few topology arrays they need, so the run keeps ownership of
//! everything.
//!
//! | format | keyword | module | contents |
//! |---|---|---|---|
//! | MCAP (Foxglove), zstd chunks | `mcap` | [`mcap_writer`], [`scene`] | topology, frames, bond state, a protobuf (or JSON) 3D scene |
//! | extended XYZ (OVITO, ASE) | `xyz` | [`xyz`] | type name (species), position, atomic number Z standing for the type, type name, id; box and pbc per frame |
//! | LAMMPS text dump | `lammps` | [`lammps_dump`] | id, type, element (chemical symbol standing for the type), position, image flags, sorted by id; or the columns the deck names (forces, per-particle stress, von Mises) |
//! | DCD (CHARMM/NAMD binary; MDAnalysis, MDTraj, VMD) | `dcd` | [`dcd`] | f32 positions sorted by id, box lengths per frame |
//! | per-bond tension (CSV) | `bonds` | [`bond_csv`] | per frame and bond: ids, type, length, tension dE/dr, midpoint |
//! | restart (JSON) | — | [`restart`] | step, time, box, ids, positions, images, bond state, counters, the deck's inputs |
//! | run log (text) | — | [`run_log`] | version, git hash, command line, inputs as read, parameters of each run, time by phase |
//!
//! Conventions shared by all writers:
//!
//! * Particles are stored by internal index `0..N`; outputs name them by their
//!   user id `ids[i]`. Bonds, angles and triangles in a [`TopologyView`] hold
//!   internal indices and are written as user ids.
//! * `types[i]` indexes `type_names` (and `type_radius`); LAMMPS dumps write
//!   the 1-based number `types[i] + 1`. Where a reader expects a chemical
//!   element (the LAMMPS dump's `element` column, the extended XYZ's `Z`,
//!   which ASE reads), type `t` is written as the element of atomic number
//!   `t + 1` ([`element_symbol`], [`atomic_number`]: H, He, Li, …) and the
//!   type name goes where readers take names from (the extended XYZ's
//!   `species`, which OVITO names its types after, and `type_name`).
//! * Positions are the stored ones (wrapped into the box on periodic axes);
//!   the image counters give the unwrapped position `x + image·L`.
//! * `images` may be empty (e.g. a minimiser that does not track images): it
//!   then reads as all zeros.
//! * Text formats print f64 in Rust's shortest round-trip form (`{}`, or
//!   `{:e}` outside `1e-5 ≤ |x| < 1e16`), so a value read back is bit-identical
//!   to the one written.
//!
//! # What survives a kill or a full disk
//!
//! Files are opened through [`files`]: inside the output directory no
//! symbolic link (file or subdirectory) is followed. Streams are written in
//! whole records through [`records`]: each trajectory frame (an MCAP chunk,
//! an XYZ/LAMMPS/DCD frame, the bond rows of a frame) and each thermo row is
//! written with one write as soon as it is complete; the event log's rows,
//! and an MCAP's bond events between frames, are batched for at most 1 s. After a SIGKILL every output therefore ends
//! at its last complete record (an MCAP lacks only its summary and footer;
//! streaming readers recover every message before the cut). A failed write
//! (`ENOSPC`) is cut back to the last whole record and stops the run with
//! `OUTPUT_ERROR_STATUS`. Restarts and the lifetime table are written
//! atomically (a synced `NAME.tmp` renamed over `NAME`).

use std::fmt;
use std::fs::File;
use std::io;

use glam::DVec3;

use crate::system::SimBox;
use crate::units::UnitSystem;

pub mod bond_csv;
pub mod dcd;
pub mod event_log;
pub mod files;
pub mod lammps_dump;
pub mod lifetimes;
pub mod mcap_messages;
pub mod mcap_writer;
pub mod records;
pub mod restart;
pub mod run_log;
pub mod scene;
pub mod xyz;

pub use self::bond_csv::BondCsvWriter;
pub use self::dcd::DcdWriter;
pub use self::event_log::EventLog;
pub use self::lammps_dump::{AtomColumn, LammpsDumpWriter};
pub use self::lifetimes::LifetimeTable;
pub use self::mcap_writer::McapWriter;
pub use self::restart::{read_state, write_state, RestartData};
pub use self::xyz::XyzWriter;

/// The static description of the particles, borrowed from the run.
#[derive(Clone, Copy, Debug)]
pub struct TopologyView<'a> {
    pub units: UnitSystem,
    /// User id of each particle, by internal index.
    pub ids: &'a [u64],
    /// Type index (into `type_names`) of each particle.
    pub types: &'a [u32],
    pub type_names: &'a [String],
    /// Radius per type (length units; 0 = not set). May be shorter than `type_names`.
    pub type_radius: &'a [f64],
    /// Bonded pairs, internal indices.
    pub bonds: &'a [[u32; 2]],
    /// Angle triples, internal indices.
    pub angles: &'a [[u32; 3]],
    /// Surface triangles, internal indices.
    pub triangles: &'a [[u32; 3]],
    /// Type index of each bond (into `bond_type_names`); may be empty.
    pub bond_types: &'a [u32],
    pub bond_type_names: &'a [String],
}

/// One frame of the trajectory, borrowed from the run.
#[derive(Clone, Copy, Debug)]
pub struct FrameView<'a> {
    pub step: u64,
    pub time: f64,
    pub sim_box: &'a SimBox,
    /// Positions by internal index (wrapped on periodic axes).
    pub positions: &'a [DVec3],
    /// Image counters by internal index, or empty for all zeros.
    pub images: &'a [[i64; 3]],
    /// What the writer asked for in [`TrajectoryWriter::needs`]; empty otherwise.
    pub measures: Measures<'a>,
    /// Bound flag per bond (topology order, formed bonds appended), or empty for all bound.
    pub bound: &'a [bool],
    /// The wall planes acting at this frame (drawn by the MCAP scene).
    pub walls: &'a [WallPlane],
}

/// A wall's plane `normal·x = offset` (unit normal; see the `wall` interaction).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WallPlane {
    pub normal: DVec3,
    pub offset: f64,
}

/// Per-frame quantities beyond positions, filled when a writer needs them.
#[derive(Clone, Copy, Debug, Default)]
pub struct Measures<'a> {
    /// Total force on each particle (force units).
    pub forces: &'a [DVec3],
    /// Per-particle virial W_i (xx, yy, zz, xy, xz, yz; energy units), see
    /// [`crate::measure::stress`].
    pub virial: &'a [[f64; 6]],
    /// Per bond: tension dE/dr (positive when stretched, 0 when unbound) and length.
    pub bond_tension: &'a [f64],
    pub bond_length: &'a [f64],
}

/// The per-frame quantities a writer reads beyond positions.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Needs {
    pub forces: bool,
    pub virial: bool,
    pub bonds: bool,
}

impl Needs {
    pub fn any(self) -> bool {
        self.forces || self.virial || self.bonds
    }
}

impl FrameView<'_> {
    /// The image counter of particle `i` (zeros when `images` is empty).
    #[inline]
    pub fn image(&self, i: usize) -> [i64; 3] {
        self.images.get(i).copied().unwrap_or([0; 3])
    }

    /// Whether bond `k` is bound (true when `bound` is empty).
    #[inline]
    pub fn is_bound(&self, k: usize) -> bool {
        self.bound.get(k).copied().unwrap_or(true)
    }
}

/// A trajectory sink: frames in, a complete file after [`finish`](Self::finish).
pub trait TrajectoryWriter: Send {
    /// Appends one frame.
    fn write_frame(&mut self, frame: &FrameView) -> io::Result<()>;
    /// Flushes and completes the file (MCAP writes its summary and footer here).
    fn finish(self: Box<Self>) -> io::Result<()>;
    /// Records the bond events of one step and the bound flags after them.
    /// Formats without a channel for them ignore this.
    fn write_bond_events(&mut self, _events: &[crate::kinetics_engine::Event], _bound: &[bool]) -> io::Result<()> {
        Ok(())
    }
    /// Writes the whole records that have waited in memory for
    /// [`records::BATCH_INTERVAL`] (an MCAP's bond events between frames);
    /// called once per step, between records.
    fn flush_due(&mut self) -> io::Result<()> {
        Ok(())
    }
    /// The quantities the writer reads from [`FrameView::measures`].
    fn needs(&self) -> Needs {
        Needs::default()
    }
}

/// The trajectory formats a deck can ask for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DumpFormat {
    Mcap,
    Xyz,
    Lammps,
    /// Per-bond tension and length, CSV.
    Bonds,
    /// CHARMM/NAMD DCD (binary, f32).
    Dcd,
}

impl DumpFormat {
    /// Every format, in the order the deck's usage lists them.
    pub const ALL: [DumpFormat; 5] = [Self::Mcap, Self::Xyz, Self::Lammps, Self::Bonds, Self::Dcd];

    /// Parses the deck keyword (`mcap`, `xyz`, `lammps`, `bonds`, `dcd`).
    pub fn from_keyword(word: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.keyword() == word)
    }

    /// The deck keyword.
    pub fn keyword(self) -> &'static str {
        match self {
            Self::Mcap => "mcap",
            Self::Xyz => "xyz",
            Self::Lammps => "lammps",
            Self::Bonds => "bonds",
            Self::Dcd => "dcd",
        }
    }

    /// The customary file extension.
    pub fn extension(self) -> &'static str {
        match self {
            Self::Mcap => "mcap",
            Self::Xyz => "xyz",
            Self::Lammps => "lammpstrj",
            Self::Bonds => "csv",
            Self::Dcd => "dcd",
        }
    }
}

/// How the MCAP writer encodes its channels (deck: `dump … mcap FILE
/// encoding protobuf|json`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Encoding {
    /// Typed protobuf messages with their descriptor sets (the default):
    /// cellmd's own (see [`mcap_messages`]) and Foxglove's `SceneUpdate`.
    #[default]
    Protobuf,
    /// The same messages as JSON with JSON Schemas.
    Json,
}

impl Encoding {
    /// Parses the deck keyword `protobuf` or `json`.
    pub fn from_keyword(word: &str) -> Option<Self> {
        match word {
            "protobuf" => Some(Self::Protobuf),
            "json" => Some(Self::Json),
            _ => None,
        }
    }
}

/// Per-format options of a dump.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WriterOptions {
    /// LAMMPS dump atom columns (empty: the default `id type element x y z ix iy iz`).
    pub columns: Vec<AtomColumn>,
    /// Encoding of the MCAP channels.
    pub encoding: Encoding,
}

/// A writer of `format` into `file` (empty, as [`files::create`] opens it),
/// with options: LAMMPS dumps take `columns`, MCAP files an `encoding`; a
/// non-default option for another format is an error.
pub fn open_writer(
    format: DumpFormat,
    file: File,
    topology: &TopologyView,
    options: &WriterOptions,
) -> io::Result<Box<dyn TrajectoryWriter>> {
    if !options.columns.is_empty() && format != DumpFormat::Lammps {
        return Err(invalid_input(format!("only `lammps` dumps take columns, not `{}`", format.keyword())));
    }
    if options.encoding != Encoding::default() && format != DumpFormat::Mcap {
        return Err(invalid_input(format!("only `mcap` dumps take an encoding, not `{}`", format.keyword())));
    }
    Ok(match format {
        DumpFormat::Mcap => Box::new(McapWriter::new(file, topology, options.encoding)?),
        DumpFormat::Xyz => Box::new(XyzWriter::new(file, topology)?),
        DumpFormat::Lammps => Box::new(LammpsDumpWriter::new(file, topology, &options.columns)?),
        DumpFormat::Bonds => Box::new(BondCsvWriter::new(file, topology)?),
        DumpFormat::Dcd => Box::new(DcdWriter::new(file, topology)?),
    })
}

/// The deck keyword of a unit system (`cell`, `lj`).
pub(crate) fn units_keyword(units: UnitSystem) -> &'static str {
    match units {
        UnitSystem::Cell => "cell",
        UnitSystem::Lj => "lj",
    }
}

pub(crate) fn invalid_input(message: String) -> io::Error {
    io::Error::new(io::ErrorKind::InvalidInput, message)
}

/// Checks that the arrays of a topology agree with each other.
pub(crate) fn check_topology(t: &TopologyView) -> io::Result<()> {
    let n = t.ids.len();
    if t.types.len() != n {
        return Err(invalid_input(format!("topology has {n} ids but {} types", t.types.len())));
    }
    if let Some((i, &ty)) = t.types.iter().enumerate().find(|(_, &ty)| ty as usize >= t.type_names.len()) {
        return Err(invalid_input(format!(
            "particle {} has type index {ty} but only {} type names are given",
            t.ids[i],
            t.type_names.len()
        )));
    }
    let out_of_range = |what: &str, k: usize, idx: &[u32]| -> io::Result<()> {
        match idx.iter().find(|&&p| p as usize >= n) {
            Some(p) => Err(invalid_input(format!("{what} {k} names particle index {p}, but there are {n} particles"))),
            None => Ok(()),
        }
    };
    for (k, b) in t.bonds.iter().enumerate() {
        out_of_range("bond", k, b)?;
    }
    for (k, a) in t.angles.iter().enumerate() {
        out_of_range("angle", k, a)?;
    }
    for (k, tri) in t.triangles.iter().enumerate() {
        out_of_range("triangle", k, tri)?;
    }
    Ok(())
}

/// Checks that a frame has one position (and image, unless empty) per particle.
pub(crate) fn check_frame(n: usize, frame: &FrameView) -> io::Result<()> {
    if frame.positions.len() != n {
        return Err(invalid_input(format!("frame at step {} has {} positions for {n} particles", frame.step, frame.positions.len())));
    }
    if !frame.images.is_empty() && frame.images.len() != n {
        return Err(invalid_input(format!("frame at step {} has {} image counters for {n} particles", frame.step, frame.images.len())));
    }
    Ok(())
}

/// An f64 printed in shortest round-trip form: plain decimal for moderate
/// magnitudes, scientific (`1e-300`) otherwise.
#[derive(Clone, Copy)]
pub(crate) struct Real(pub f64);

impl fmt::Display for Real {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let x = self.0;
        let a = x.abs();
        if x == 0.0 || !x.is_finite() || (1e-5..1e16).contains(&a) {
            write!(f, "{x}")
        } else {
            write!(f, "{x:e}")
        }
    }
}

/// Chemical symbols by atomic number − 1.
const ELEMENTS: [&str; 118] = [
    "H", "He", "Li", "Be", "B", "C", "N", "O", "F", "Ne", "Na", "Mg", "Al", "Si", "P", "S", "Cl", "Ar", "K", "Ca", "Sc", "Ti", "V", "Cr",
    "Mn", "Fe", "Co", "Ni", "Cu", "Zn", "Ga", "Ge", "As", "Se", "Br", "Kr", "Rb", "Sr", "Y", "Zr", "Nb", "Mo", "Tc", "Ru", "Rh", "Pd",
    "Ag", "Cd", "In", "Sn", "Sb", "Te", "I", "Xe", "Cs", "Ba", "La", "Ce", "Pr", "Nd", "Pm", "Sm", "Eu", "Gd", "Tb", "Dy", "Ho", "Er",
    "Tm", "Yb", "Lu", "Hf", "Ta", "W", "Re", "Os", "Ir", "Pt", "Au", "Hg", "Tl", "Pb", "Bi", "Po", "At", "Rn", "Fr", "Ra", "Ac", "Th",
    "Pa", "U", "Np", "Pu", "Am", "Cm", "Bk", "Cf", "Es", "Fm", "Md", "No", "Lr", "Rf", "Db", "Sg", "Bh", "Hs", "Mt", "Ds", "Rg", "Cn",
    "Nh", "Fl", "Mc", "Lv", "Ts", "Og",
];

/// The element symbol standing for type index `t` where a reader wants one:
/// atomic number `t + 1` (H, He, Li, …), cycling after the 118th type.
pub fn element_symbol(t: usize) -> &'static str {
    ELEMENTS[t % ELEMENTS.len()]
}

/// The atomic number of [`element_symbol`]`(t)`: `t + 1`, wrapping after 118.
pub fn atomic_number(t: usize) -> usize {
    t % ELEMENTS.len() + 1
}

/// A type name usable as one whitespace-free token (whitespace becomes `_`).
pub(crate) fn token(name: &str) -> String {
    if name.is_empty() {
        return "_".to_string();
    }
    name.chars().map(|c| if c.is_whitespace() { '_' } else { c }).collect()
}

#[cfg(test)]
pub(crate) mod test_support {
    //! A small system shared by the writer tests.
    use super::*;

    pub struct Sample {
        pub ids: Vec<u64>,
        pub types: Vec<u32>,
        pub type_names: Vec<String>,
        pub type_radius: Vec<f64>,
        pub bonds: Vec<[u32; 2]>,
        pub angles: Vec<[u32; 3]>,
        pub triangles: Vec<[u32; 3]>,
        pub sim_box: SimBox,
        /// Positions per frame.
        pub frames: Vec<Vec<DVec3>>,
        pub images: Vec<[i64; 3]>,
    }

    impl Sample {
        pub fn new(n_frames: usize) -> Self {
            let base =
                [DVec3::new(0.1 + 0.2, 1e-300, -0.0), DVec3::new(9.95, 5.0, 2.5), DVec3::new(0.05, 5.0, 2.5), DVec3::new(3.0, 7.25, -1.5)];
            let frames = (0..n_frames)
                .map(|f| {
                    // Frame 0 keeps the awkward values (adding 0.0 would turn −0.0 into +0.0).
                    let shift = DVec3::new(0.0, 0.0, 0.001 * f as f64 / 3.0);
                    base.iter().map(|p| if f == 0 { *p } else { *p + shift }).collect()
                })
                .collect();
            Self {
                ids: vec![40, 7, 12, 3],
                types: vec![0, 1, 1, 0],
                type_names: vec!["cortex".into(), "adhesion site".into()],
                type_radius: vec![0.25, 0.0],
                bonds: vec![[1, 2], [0, 3]],
                angles: vec![[0, 1, 2]],
                triangles: vec![[0, 1, 3]],
                sim_box: SimBox::new(DVec3::new(0.0, 0.0, -5.0), DVec3::new(10.0, 10.0, 5.0), [true, true, false]),
                frames,
                images: vec![[0, 0, 0], [-1, 2, 0], [1, 0, 0], [0, 0, 0]],
            }
        }

        pub fn topology(&self) -> TopologyView<'_> {
            TopologyView {
                units: UnitSystem::Cell,
                ids: &self.ids,
                types: &self.types,
                type_names: &self.type_names,
                type_radius: &self.type_radius,
                bonds: &self.bonds,
                angles: &self.angles,
                triangles: &self.triangles,
                bond_types: &[],
                bond_type_names: &[],
            }
        }

        pub fn frame(&self, f: usize) -> FrameView<'_> {
            FrameView {
                step: 100 * f as u64,
                time: 0.1 * f as f64,
                sim_box: &self.sim_box,
                positions: &self.frames[f],
                images: &self.images,
                measures: Measures::default(),
                bound: &[],
                walls: &[],
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::test_support::Sample;
    use super::*;

    #[test]
    fn keywords_round_trip() {
        for f in DumpFormat::ALL {
            assert_eq!(DumpFormat::from_keyword(f.keyword()), Some(f));
        }
        assert_eq!(DumpFormat::from_keyword("h5md"), None);
        assert_eq!(Encoding::from_keyword("json"), Some(Encoding::Json));
        assert_eq!(Encoding::from_keyword("cbor"), None);
        assert_eq!((element_symbol(0), element_symbol(1), element_symbol(117), element_symbol(118)), ("H", "He", "Og", "H"));
        assert_eq!((atomic_number(0), atomic_number(117), atomic_number(118)), (1, 118, 1));
    }

    #[test]
    fn reals_print_in_round_trip_form() {
        for x in [0.1 + 0.2, 1e-300, -0.0, 1e16, 123.456, -7e-6, 5e-324, f64::MAX, 1.0 / 3.0] {
            let s = Real(x).to_string();
            assert_eq!(s.parse::<f64>().unwrap().to_bits(), x.to_bits(), "{s}");
        }
        assert_eq!(Real(0.5).to_string(), "0.5");
        assert_eq!(Real(1e-300).to_string(), "1e-300");
        assert_eq!(token("adhesion site"), "adhesion_site");
    }

    #[test]
    fn inconsistent_topologies_and_frames_are_rejected() {
        let s = Sample::new(1);
        let mut t = s.topology();
        let short = [0u32; 3];
        t.types = &short;
        assert!(check_topology(&t).unwrap_err().to_string().contains("4 ids but 3 types"));
        let bad_type = [0u32, 0, 5, 0];
        let mut t = s.topology();
        t.types = &bad_type;
        assert!(check_topology(&t).unwrap_err().to_string().contains("type index 5"));
        let bad_bond = [[0u32, 4]];
        let mut t = s.topology();
        t.bonds = &bad_bond;
        assert!(check_topology(&t).unwrap_err().to_string().contains("bond 0 names particle index 4"));
        let mut f = s.frame(0);
        f.positions = &s.frames[0][..2];
        assert!(check_frame(4, &f).is_err());
        let mut f = s.frame(0);
        f.images = &[];
        assert!(check_frame(4, &f).is_ok());
        assert_eq!(f.image(2), [0; 3]);
    }

    #[test]
    fn open_writer_makes_every_format() {
        let s = Sample::new(2);
        let dir = tempfile::tempdir().unwrap();
        for format in [DumpFormat::Mcap, DumpFormat::Xyz, DumpFormat::Lammps, DumpFormat::Dcd] {
            let path = dir.path().join(format!("traj.{}", format.extension()));
            let mut w = open_writer(format, File::create(&path).unwrap(), &s.topology(), &WriterOptions::default()).unwrap();
            w.write_frame(&s.frame(0)).unwrap();
            w.write_frame(&s.frame(1)).unwrap();
            w.finish().unwrap();
            assert!(std::fs::metadata(&path).unwrap().len() > 0);
        }
        let json = WriterOptions { encoding: Encoding::Json, ..Default::default() };
        assert!(open_writer(DumpFormat::Xyz, File::create(dir.path().join("x.xyz")).unwrap(), &s.topology(), &json).is_err());
    }
}
