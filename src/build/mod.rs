//! Topology generators (`cellmd build ...`): systems written as ordinary
//! topology files (see [`crate::topology`]), deterministic for given options.
//!
//! Every generator prints a summary (also written atop the file as `#`
//! comments) with what a force field needs: counts, rest lengths and, for
//! filaments, the bending stiffness. Randomness is counter-based: each draw is
//! Philox4x32-10 ([`crate::rng::block`]) keyed by `--seed` and a
//! counter naming what it is for (which filament, which crosslink, which
//! component), never a stateful generator, so the same seed gives the same
//! bytes on every machine and a change to one part of a system does not
//! reshuffle the others. Bad options are refused with a message naming what
//! was expected (`cellmd build` then exits with status 2).
//!
//! | generator | command | what it writes |
//! |---|---|---|
//! | [`icosphere()`], [`icosphere_cell`] | `icosphere` | one cell as a closed triangulated shell (optionally with a nucleus) |
//! | [`filament()`] | `filament` | one straight bead chain with bonds and bending angles |
//! | [`network()`] | `network` | Mikado network: random straight filaments in a periodic box (or a slab between two faces, `--slab`), crosslinked where they cross |
//! | [`aster()`] | `aster` | microtubules radiating from a centrosome node |
//! | [`cortex()`] | `cortex` | great-circle filaments on a sphere, optionally crosslinked |
//! | [`branched()`] | `branched` | Arp2/3 network: mother filaments with daughters at 70° ± a spread |
//! | [`filopodium()`] | `filopodium` | a hexagonal bundle of parallel filaments, crosslinked between neighbours |
//! | [`cells()`] | `cells` | many icosphere cells packed in a spheroid or a confluent layer |
//! | [`sheet()`] | `sheet` | a 2D epithelial sheet (Prakash et al. 2022): hexagonal cells as rings of nodes (or single particles) joined by junction bonds |
//! | [`tensegrity()`] | `tensegrity` | a tensegrity cell (Vassaux & Milan 2017): cortex and nucleus shells, radial microtubule struts, actin cables and stress fibres from focal adhesions |
//! | [`lattice()`] | `lattice` | a diluted triangular lattice of fibres in a disc with a clamped rim (Broedersz et al. 2011), optionally with a contractile force dipole |
//! | [`collagen()`] | `collagen` | a planar collagen fibre network (Ouyang et al. 2022): crosslinks as shared nodes, holes under cells that are rings of nodes with a hub |
//! | [`ball()`] | `ball` | an elastic ball meshed with linear tetrahedra (`[ tetrahedra ]`, for `neo_hookean`/`linear_elastic`) |
//! | [`block()`] | `block` | an elastic block meshed with linear tetrahedra, graded towards its top face's centre (a half-space for contact; optionally a symmetric quarter) |
//! | [`merge()`] | `merge` | several topology files composed into one by the deck's rule for several `topology` lines |
//!
//! **Rest lengths** (`--rest-from-geometry`, every generator): by default a
//! bond line is `type i j`, and the force field's `r0` of the type applies to
//! all its bonds; where a structure's bonds of one type differ in length (a
//! jittered sheet, icosphere edges, crosslinks, actin cables) it then starts
//! pre-stressed. With the flag each bond line ends with the bond's length as
//! built (minimum image on a periodic `[ box ]`), its own r0, so the structure
//! starts force-free. It is opt-in: a per-bond r0 cannot be changed by
//! `coeff bond TYPE r0` (the deck refuses it), exports as one LAMMPS bond type
//! per distinct length, and some structures are meant to start loaded.
//!
//! **Filaments** (of `filament`, `network`, `aster`, `cortex`, `branched`
//! and `filopodium`) are chains of beads with a
//! bond between consecutive beads and an angle on every consecutive triple
//! (vertex in the middle), the form of [`wlc_bending`](crate::interactions)
//! and `cosine_angle`. A chain of contour length L has `--segments n` bonds
//! (or n = round(L/ℓ) for `--segment-length ℓ`), so n + 1 beads a distance
//! ℓ = L/n apart. For a persistence length Lp at temperature T the summary
//! prints κ = Lp·kT and the per-angle stiffness K = κ/ℓ:
//!
//! ```text
//! angle bend wlc_bending  kappa κ l0 ℓ     # or
//! angle bend cosine_angle K κ/ℓ
//! ```
//!
//! ```
//! use cellmd::build::{icosphere_cell, IcosphereCell};
//! let cell = icosphere_cell(&IcosphereCell { level: 1, radius: 5.0, ..Default::default() });
//! let shell = &cell.shells[0];
//! assert_eq!((shell.nodes, shell.edges, shell.faces), (42, 120, 80));
//! assert!(cell.text.contains("[ triangles ]"));
//! ```
//!
//! A filament for a deck:
//!
//! ```
//! use cellmd::build::{filament, Chain, FilamentArgs};
//! let chain = Chain { length: 2.0, segments: Some(20), persistence_length: Some(17.0), ..Chain::default() };
//! let built = filament(&FilamentArgs { chain, ..FilamentArgs::default() }).unwrap();
//! assert_eq!((built.particles, built.bonds, built.angles), (21, 20, 19));
//! assert!(built.summary().contains("wlc_bending kappa"));
//! ```

mod aster;
mod ball;
mod block;
mod branched;
mod cells;
mod collagen;
mod cortex;
mod filament;
mod filopodium;
mod icosphere;
mod kuhn;
mod lattice;
mod merge;
mod network;
mod sheet;
mod substrate;
mod tensegrity;

use std::f64::consts::TAU;
use std::fmt::Write;
use std::path::PathBuf;

use glam::{DQuat, DVec3};

use crate::rng::{self, open_unit_52};
use crate::units::BOLTZMANN_PN_UM_PER_K;

pub use self::aster::{aster, AsterArgs};
pub use self::ball::{ball, BallArgs};
pub use self::block::{block, BlockArgs};
pub use self::branched::{branched, BranchedArgs};
pub use self::cells::{cells, CellsArgs, Layout};
pub use self::collagen::{collagen, CellLayout, CollagenArgs};
pub use self::cortex::{cortex, CortexArgs};
pub use self::filament::{filament, FilamentArgs};
pub use self::filopodium::{filopodium, FilopodiumArgs};
pub use self::icosphere::{icosphere, icosphere_cell, IcosphereArgs, IcosphereCell, Nucleus, ShellOptions};
pub use self::lattice::{lattice, LatticeArgs};
pub use self::merge::{merge, MergeArgs};
pub use self::network::{network, NetworkArgs, SlabAxis};
pub use self::sheet::{sheet, SheetArgs};
pub use self::substrate::SubstrateOptions;
pub use self::tensegrity::{tensegrity, TensegrityArgs};

/// The `cellmd build` subcommands: one per generator.
#[derive(clap::Subcommand, Clone, Debug)]
pub enum Generator {
    /// One cell as a closed triangulated shell: the icosphere of subdivision
    /// LEVEL (12, 42, 162, 642, 2562 … nodes), nodes on a sphere of RADIUS,
    /// faces as the outward-wound triangles of one body, edges as bonds;
    /// optionally a nucleus, a second body inside it.
    Icosphere(IcosphereArgs),
    /// One straight filament: a bead chain with bonds and bending angles;
    /// prints κ = Lp·kT and the per-angle stiffness.
    Filament(FilamentArgs),
    /// Mikado network: random straight filaments in a periodic box,
    /// crosslinked where beads of different filaments come within a capture distance.
    Network(NetworkArgs),
    /// Aster: microtubules radiating from a centrosome node, each bonded to it.
    Aster(AsterArgs),
    /// Cortex: filaments as great-circle arcs on a sphere, optionally crosslinked.
    Cortex(CortexArgs),
    /// Arp2/3 branched network: mother filaments with daughters at 70° ± a spread.
    Branched(BranchedArgs),
    /// Filopodium: parallel filaments on a hexagonal lattice, crosslinked between neighbours.
    Filopodium(FilopodiumArgs),
    /// Many icosphere cells packed without overlap in a spheroid or a confluent layer.
    Cells(CellsArgs),
    /// A 2D epithelial sheet (Prakash et al. 2022): hexagonal cells, each a ring of
    /// nodes with edge bonds and a centre node with spokes (or one particle),
    /// neighbours joined by junction bonds.
    Sheet(SheetArgs),
    /// A tensegrity cell (Vassaux & Milan 2017): a cortex shell, a nucleus shell (or a
    /// centrosome node), radial microtubule struts, actin cables from the
    /// cortex to the nucleus and stress fibres from focal adhesions.
    Tensegrity(TensegrityArgs),
    /// A diluted triangular lattice of fibres in a disc with a clamped rim
    /// (Broedersz et al. 2011): each bond present with a probability,
    /// optionally bending-stiff lattice lines and a contractile force dipole.
    Lattice(LatticeArgs),
    /// A planar collagen fibre network (Ouyang et al. 2022): random straight
    /// fibres crosslinked where they cross (shared nodes), holes under the
    /// cells, each cell a ring of nodes (83 by default) with a hub and spokes;
    /// cells in a pair, a square or at random.
    Collagen(CollagenArgs),
    /// An elastic ball of radius RADIUS meshed with linear tetrahedra (a cubed-sphere
    /// map of a lattice of CELLS³ cubes, six tetrahedra each), for `tetra` volume laws.
    Ball(BallArgs),
    /// An elastic block meshed with linear tetrahedra, its spacings graded
    /// towards the centre of its top face (a half-space for a contact there),
    /// base nodes typed for holding; optionally the symmetric quarter.
    Block(BlockArgs),
    /// Several topology files composed into one by the rule of a deck with
    /// several `topology` lines (ids shifted by --offset, by default the
    /// largest so far; body ids follow; shared type names; the first box).
    Merge(MergeArgs),
}

impl Generator {
    /// Runs the generator.
    pub fn build(&self) -> Result<Built, String> {
        match self {
            Self::Icosphere(a) => icosphere(a),
            Self::Filament(a) => filament(a),
            Self::Network(a) => network(a),
            Self::Aster(a) => aster(a),
            Self::Cortex(a) => cortex(a),
            Self::Branched(a) => branched(a),
            Self::Filopodium(a) => filopodium(a),
            Self::Cells(a) => cells(a),
            Self::Sheet(a) => sheet(a),
            Self::Tensegrity(a) => tensegrity(a),
            Self::Lattice(a) => lattice(a),
            Self::Collagen(a) => collagen(a),
            Self::Ball(a) => ball(a),
            Self::Block(a) => block(a),
            Self::Merge(a) => merge(a),
        }
    }

    /// The topology file to write.
    pub fn output(&self) -> &std::path::Path {
        match self {
            Self::Icosphere(a) => a.output.as_path(),
            Self::Filament(a) => a.common.output.as_path(),
            Self::Network(a) => a.common.output.as_path(),
            Self::Aster(a) => a.common.output.as_path(),
            Self::Cortex(a) => a.common.output.as_path(),
            Self::Branched(a) => a.common.output.as_path(),
            Self::Filopodium(a) => a.common.output.as_path(),
            Self::Cells(a) => a.common.output.as_path(),
            Self::Sheet(a) => a.common.output.as_path(),
            Self::Tensegrity(a) => a.common.output.as_path(),
            Self::Lattice(a) => a.common.output.as_path(),
            Self::Collagen(a) => a.common.output.as_path(),
            Self::Ball(a) => a.output.as_path(),
            Self::Block(a) => a.output.as_path(),
            Self::Merge(a) => a.output.as_path(),
        }
    }
}

/// Options every random generator takes.
#[derive(clap::Args, Clone, Debug, Default)]
pub struct Common {
    /// Seed of the counter-based random numbers: the same seed writes the same file.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Write each bond's length as built as its own rest length r0 (`type i j r0`), so the structure starts force-free.
    #[arg(long)]
    pub rest_from_geometry: bool,
    /// The topology file to write.
    #[arg(short, long)]
    pub output: PathBuf,
}

/// Statistics of one closed shell (a cell or a nucleus) as written.
#[derive(Clone, Debug)]
pub struct Shell {
    /// Its body, if it was written as one.
    pub body_id: Option<u64>,
    pub nodes: usize,
    pub edges: usize,
    pub faces: usize,
    /// Enclosed volume and area of the mesh as written (a polyhedron inscribed
    /// in the sphere: slightly less than 4πR³/3 and 4πR²).
    pub volume: f64,
    pub area: f64,
    /// Shortest, mean and longest edge.
    pub edge_lengths: [f64; 3],
}

impl Shell {
    /// `N nodes, E edges, F faces; enclosed volume …, area …; edge length min … mean … max …`.
    pub fn summary(&self) -> String {
        let [lo, mean, hi] = self.edge_lengths;
        format!(
            "{} nodes, {} edges, {} faces; enclosed volume {:.12e}, area {:.12e}; edge length min {lo:.6e} mean {mean:.6e} max {hi:.6e}",
            self.nodes, self.edges, self.faces, self.volume, self.area
        )
    }
}

/// A generated topology and what a force field needs to know about it.
#[derive(Clone, Debug, Default)]
pub struct Built {
    /// The topology file.
    pub text: String,
    /// The summary, one line each (printed by `cellmd build`, written atop the file).
    pub lines: Vec<String>,
    pub particles: usize,
    pub bonds: usize,
    pub angles: usize,
    pub bodies: usize,
    pub triangles: usize,
    pub tetrahedra: usize,
    /// The closed shells written (cells, nuclei), in body order.
    pub shells: Vec<Shell>,
}

impl Built {
    /// The summary printed by `cellmd build` and written atop the file.
    pub fn summary(&self) -> String {
        self.lines.join("\n")
    }
}

/// Collects particles and terms and renders them as a topology file.
/// Particle ids are consecutive from `first_id` in order of addition.
#[derive(Clone, Debug)]
pub(crate) struct Writer {
    first_id: u64,
    box_axes: Option<[(f64, f64, bool); 3]>,
    particles: Vec<(String, DVec3, Option<u64>)>,
    bonds: Vec<(String, u64, u64)>,
    bonds_comment: String,
    /// Write each bond's length as built as its rest length (`type i j r0`).
    rest_from_geometry: bool,
    /// Bond types whose bonds always carry their length as built as r0.
    own_rest: Vec<String>,
    angles: Vec<(String, [u64; 3])>,
    bodies: Vec<(u64, String)>,
    triangles: Vec<(u64, [u64; 3])>,
    tetrahedra: Vec<(String, [u64; 4])>,
    pub shells: Vec<Shell>,
}

impl Writer {
    pub fn new(first_id: u64) -> Self {
        Self {
            first_id,
            box_axes: None,
            particles: Vec::new(),
            bonds: Vec::new(),
            bonds_comment: "# type  i  j".into(),
            rest_from_geometry: false,
            own_rest: Vec::new(),
            angles: Vec::new(),
            bodies: Vec::new(),
            triangles: Vec::new(),
            tetrahedra: Vec::new(),
            shells: Vec::new(),
        }
    }

    /// Adds a particle and returns its id.
    pub fn particle(&mut self, type_name: &str, x: DVec3, body: Option<u64>) -> u64 {
        self.particles.push((type_name.to_string(), x, body));
        self.first_id + self.particles.len() as u64 - 1
    }

    /// The id the next particle will get.
    pub fn next_id(&self) -> u64 {
        self.first_id + self.particles.len() as u64
    }

    /// Gives particle `id` another type.
    pub fn set_type(&mut self, id: u64, type_name: &str) {
        self.particles[(id - self.first_id) as usize].0 = type_name.to_string();
    }

    /// Particles of type `type_name` written so far.
    pub fn count_type(&self, type_name: &str) -> usize {
        self.particles.iter().filter(|p| p.0 == type_name).count()
    }

    /// The position of particle `id`.
    pub fn position(&self, id: u64) -> DVec3 {
        self.particles[(id - self.first_id) as usize].1
    }

    pub fn bond(&mut self, type_name: &str, i: u64, j: u64) {
        self.bonds.push((type_name.to_string(), i, j));
    }

    /// An angle term with its vertex at `j`.
    pub fn angle(&mut self, type_name: &str, i: u64, j: u64, k: u64) {
        self.angles.push((type_name.to_string(), [i, j, k]));
    }

    pub fn body(&mut self, id: u64, type_name: &str) {
        self.bodies.push((id, type_name.to_string()));
    }

    pub fn triangle(&mut self, body: u64, ids: [u64; 3]) {
        self.triangles.push((body, ids));
    }

    /// A volume element of type `type_name` on particles `ids`.
    pub fn tetra(&mut self, type_name: &str, ids: [u64; 4]) {
        self.tetrahedra.push((type_name.to_string(), ids));
    }

    /// Whether each bond's line ends with its length as built, its own rest length.
    pub fn set_rest_from_geometry(&mut self, on: bool) {
        self.rest_from_geometry = on;
    }

    /// Bonds of `type_name` carry their length as built as r0 whatever
    /// `set_rest_from_geometry` says (a network whose bonds differ by construction).
    pub fn set_own_rest(&mut self, type_name: &str) {
        self.own_rest.push(type_name.to_string());
    }

    /// Whether a bond of `type_name` is written with its own r0.
    fn writes_rest(&self, type_name: &str) -> bool {
        self.rest_from_geometry || self.own_rest.iter().any(|t| t == type_name)
    }

    /// The length of the bond between `i` and `j` as written: the minimum
    /// image on the `[ box ]`'s periodic axes, as the engine measures it.
    fn bond_length(&self, i: u64, j: u64) -> f64 {
        let mut d = self.position(j) - self.position(i);
        if let Some(axes) = self.box_axes {
            let sim_box =
                crate::system::SimBox::new(DVec3::from_array(axes.map(|a| a.0)), DVec3::from_array(axes.map(|a| a.1)), axes.map(|a| a.2));
            d = sim_box.minimum_image(d);
        }
        d.length()
    }

    pub fn set_bonds_comment(&mut self, comment: &str) {
        self.bonds_comment = comment.to_string();
    }

    /// A `[ box ]` section: `(lo, hi, periodic)` per axis.
    pub fn set_box(&mut self, axes: [(f64, f64, bool); 3]) {
        self.box_axes = Some(axes);
    }

    /// A fixed cubic box of half-width `h` around `centre`, which must hold every particle.
    pub fn fixed_cube(&mut self, centre: DVec3, h: f64) -> Result<(), String> {
        if !(h.is_finite() && h > 0.0) {
            return Err(format!("expected --box HALF_WIDTH > 0, found {h}"));
        }
        let reach = self.particles.iter().map(|p| (p.1 - centre).abs().max_element()).fold(0.0, f64::max);
        if reach >= h {
            return Err(format!(
                "expected --box HALF_WIDTH to hold every particle: found {h}, but a particle lies {reach} from the centre"
            ));
        }
        self.set_box([0, 1, 2].map(|a| (centre[a] - h, centre[a] + h, false)));
        Ok(())
    }

    /// Wraps every position into the box on its periodic axes (`[lo, hi)`).
    pub fn wrap_periodic(&mut self) {
        let Some(axes) = self.box_axes else { return };
        for p in &mut self.particles {
            for (a, &(lo, hi, periodic)) in axes.iter().enumerate() {
                if periodic {
                    p.1[a] = wrap(p.1[a], lo, hi);
                }
            }
        }
    }

    /// The topology text: `title` and the generator's command atop, then the
    /// summary `lines` as comments, then the sections.
    pub fn finish(self, title: &str, command: &str, mut lines: Vec<String>) -> Built {
        if self.rest_from_geometry && !self.bonds.is_empty() {
            lines.push("rest lengths: each bond's r0 is its length as built (--rest-from-geometry, 4th field of [ bonds ]): the type's r0 does not apply to them".into());
        }
        let mut t = String::new();
        writeln!(t, "# {title}\n# (written by `cellmd build {command}`)").unwrap();
        for line in &lines {
            writeln!(t, "# {line}").unwrap();
        }
        if let Some(axes) = self.box_axes {
            writeln!(t, "[ box ]").unwrap();
            for (name, (lo, hi, periodic)) in ["x", "y", "z"].iter().zip(axes) {
                writeln!(t, "{name} {lo:?} {hi:?} {}", if periodic { "p" } else { "f" }).unwrap();
            }
        }
        let with_body = self.particles.iter().any(|p| p.2.is_some());
        writeln!(t, "[ particles ]\n# id  type  x  y  z{}", if with_body { "  body" } else { "" }).unwrap();
        for (k, (type_name, x, body)) in self.particles.iter().enumerate() {
            write!(t, "{} {type_name} {:?} {:?} {:?}", self.first_id + k as u64, x.x, x.y, x.z).unwrap();
            match body {
                Some(b) => writeln!(t, " {b}").unwrap(),
                None => writeln!(t).unwrap(),
            }
        }
        if !self.bonds.is_empty() {
            let r0 = if self.bonds.iter().any(|b| self.writes_rest(&b.0)) { "  [r0]" } else { "" };
            let r0 = if self.rest_from_geometry { "  r0" } else { r0 };
            writeln!(t, "[ bonds ]\n{}{r0}", self.bonds_comment).unwrap();
            for (type_name, i, j) in &self.bonds {
                if self.writes_rest(type_name) {
                    writeln!(t, "{type_name} {i} {j} {:?}", self.bond_length(*i, *j)).unwrap();
                } else {
                    writeln!(t, "{type_name} {i} {j}").unwrap();
                }
            }
        }
        if !self.angles.is_empty() {
            writeln!(t, "[ angles ]\n# type  i  j  k   (vertex j)").unwrap();
            for (type_name, [i, j, k]) in &self.angles {
                writeln!(t, "{type_name} {i} {j} {k}").unwrap();
            }
        }
        if !self.bodies.is_empty() {
            writeln!(t, "[ bodies ]").unwrap();
            for (id, type_name) in &self.bodies {
                writeln!(t, "{id} {type_name}").unwrap();
            }
        }
        if !self.triangles.is_empty() {
            writeln!(t, "[ triangles ]\n# body  i  j  k   (counter-clockwise seen from outside)").unwrap();
            for (body, [i, j, k]) in &self.triangles {
                writeln!(t, "{body} {i} {j} {k}").unwrap();
            }
        }
        if !self.tetrahedra.is_empty() {
            writeln!(t, "[ tetrahedra ]\n# type  i  j  k  l").unwrap();
            for (type_name, [i, j, k, l]) in &self.tetrahedra {
                writeln!(t, "{type_name} {i} {j} {k} {l}").unwrap();
            }
        }
        Built {
            text: t,
            lines,
            particles: self.particles.len(),
            bonds: self.bonds.len(),
            angles: self.angles.len(),
            bodies: self.bodies.len(),
            triangles: self.triangles.len(),
            tetrahedra: self.tetrahedra.len(),
            shells: self.shells,
        }
    }
}

/// `x` wrapped into `[lo, hi)`.
pub(crate) fn wrap(mut x: f64, lo: f64, hi: f64) -> f64 {
    let l = hi - lo;
    x -= l * ((x - lo) / l).floor();
    while x >= hi {
        x -= l;
    }
    while x < lo {
        x += l;
    }
    x
}

/// Counter-based random numbers of one generator: the draw for
/// `(item, purpose)` is Philox4x32-10 of `counter = [purpose, stream, item]`
/// under `key = seed` ([`block`] with `step = item`, `id = purpose`), a pure
/// function of its arguments.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Draws {
    seed: u64,
    stream: u32,
}

/// Philox streams of the generators (distinct from the dynamics' 0, 1 and kinetics' small numbers).
pub(crate) mod stream {
    pub const FILAMENT: u32 = 0x6275_0001;
    pub const NETWORK: u32 = 0x6275_0002;
    pub const ASTER: u32 = 0x6275_0003;
    pub const CORTEX: u32 = 0x6275_0004;
    pub const BRANCHED: u32 = 0x6275_0005;
    pub const FILOPODIUM: u32 = 0x6275_0006;
    pub const CELLS: u32 = 0x6275_0007;
    pub const SHEET: u32 = 0x6275_0008;
    pub const TENSEGRITY: u32 = 0x6275_0009;
    pub const LATTICE: u32 = 0x6275_000a;
    /// The same number as LATTICE (two branches took it at once): the
    /// collagen study's committed network and its measured ratios are drawn
    /// from it, and no system combines the two generators' draws.
    pub const COLLAGEN: u32 = 0x6275_000a;
}

impl Draws {
    pub fn new(seed: u64, stream: u32) -> Self {
        Self { seed, stream }
    }

    /// Two independent uniforms in the open interval (0, 1) (52 bits each).
    pub fn uniform2(&self, item: u64, purpose: u32) -> [f64; 2] {
        let b = rng::block(self.seed, item, purpose, self.stream);
        [open_unit_52(b[0], b[1]), open_unit_52(b[2], b[3])]
    }

    pub fn uniform(&self, item: u64, purpose: u32) -> f64 {
        self.uniform2(item, purpose)[0]
    }

    /// A direction uniform on the unit sphere (Archimedes: z uniform in (−1, 1)).
    pub fn unit_vector(&self, item: u64, purpose: u32) -> DVec3 {
        let [a, b] = self.uniform2(item, purpose);
        let z = 2.0 * a - 1.0;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let (s, c) = (TAU * b).sin_cos();
        DVec3::new(r * c, r * s, z)
    }

    /// A rotation uniform on SO(3) (Shoemake's unit quaternion), from purposes `purpose` and `purpose + 1`.
    pub fn rotation(&self, item: u64, purpose: u32) -> DQuat {
        let [u1, u2] = self.uniform2(item, purpose);
        let u3 = self.uniform(item, purpose + 1);
        let (a, b) = ((1.0 - u1).sqrt(), u1.sqrt());
        let (s2, c2) = (TAU * u2).sin_cos();
        let (s3, c3) = (TAU * u3).sin_cos();
        DQuat::from_xyzw(a * s2, a * c2, b * s3, b * c3).normalize()
    }

    /// `k` distinct indices of `0..n` in increasing order (partial Fisher–Yates).
    pub fn choose(&self, item: u64, purpose: u32, n: usize, k: usize) -> Vec<usize> {
        let mut all: Vec<usize> = (0..n).collect();
        for s in 0..k.min(n) {
            let u = self.uniform(item.wrapping_mul(1 << 20).wrapping_add(s as u64), purpose);
            let pick = s + ((u * (n - s) as f64) as usize).min(n - s - 1);
            all.swap(s, pick);
        }
        all.truncate(k.min(n));
        all.sort_unstable();
        all
    }
}

/// The smallest, mean and largest of `values` (all 0 when there are none).
pub(crate) fn min_mean_max(values: &[f64]) -> [f64; 3] {
    if values.is_empty() {
        return [0.0; 3];
    }
    let lo = values.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = values.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    [lo, values.iter().sum::<f64>() / values.len() as f64, hi]
}

/// Expects a finite positive value of option `name`.
pub(crate) fn positive(name: &str, v: f64) -> Result<f64, String> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("expected {name} > 0, found {v}"))
    }
}

/// Expects three finite numbers for option `name`.
pub(crate) fn vec3(name: &str, v: &[f64]) -> Result<DVec3, String> {
    match v {
        [x, y, z] if v.iter().all(|c| c.is_finite()) => Ok(DVec3::new(*x, *y, *z)),
        _ => Err(format!("expected {name} X Y Z (three finite numbers), found {v:?}")),
    }
}

/// The filament options every chain generator shares.
#[derive(clap::Args, Clone, Debug)]
pub struct Chain {
    /// Contour length of each filament (µm).
    #[arg(allow_negative_numbers = true, long)]
    pub length: f64,
    /// Bonds per filament (n + 1 beads); or give --segment-length.
    #[arg(long, conflicts_with = "segment_length")]
    pub segments: Option<u32>,
    /// Target segment length ℓ (µm): n = round(L/ℓ) segments of exactly L/n.
    #[arg(allow_negative_numbers = true, long)]
    pub segment_length: Option<f64>,
    /// Particle type of the beads.
    #[arg(long, default_value = "bead")]
    pub particle_type: String,
    /// Bond type between consecutive beads.
    #[arg(long, default_value = "segment")]
    pub bond_type: String,
    /// Angle type on consecutive bead triples (bending).
    #[arg(long, default_value = "bend")]
    pub angle_type: String,
    /// Persistence length Lp (µm) for the printed bending stiffness
    /// [default: 17 (actin); 5200 for `aster` (microtubules)].
    #[arg(allow_negative_numbers = true, long)]
    pub persistence_length: Option<f64>,
    /// Temperature (K) of kT in κ = Lp·kT.
    #[arg(allow_negative_numbers = true, long, default_value_t = 298.0)]
    pub temperature: f64,
}

impl Default for Chain {
    fn default() -> Self {
        Self {
            length: 1.0,
            segments: Some(10),
            segment_length: None,
            particle_type: "bead".into(),
            bond_type: "segment".into(),
            angle_type: "bend".into(),
            persistence_length: None,
            temperature: 298.0,
        }
    }
}

impl Chain {
    /// The segment count n and length ℓ = L/n, checked.
    pub fn segmentation(&self) -> Result<(usize, f64), String> {
        positive("--length", self.length)?;
        let n = match (self.segments, self.segment_length) {
            (Some(0), _) => return Err("expected --segments >= 1, found 0".into()),
            (Some(n), _) => n as usize,
            (None, Some(l)) => (self.length / positive("--segment-length", l)?).round().max(1.0) as usize,
            (None, None) => return Err("expected --segments N or --segment-length L".into()),
        };
        if n > 10_000_000 {
            return Err(format!("expected at most 10 000 000 segments per filament, found {n}"));
        }
        Ok((n, self.length / n as f64))
    }

    /// κ = Lp·kT (pN·µm²) and the summary line with the force-field lines,
    /// for segments of length `ell` (the bond rest length).
    pub fn bending_line(&self, ell: f64, default_lp: f64) -> Result<(f64, String), String> {
        let lp = positive("--persistence-length", self.persistence_length.unwrap_or(default_lp))?;
        let t = positive("--temperature", self.temperature)?;
        let kt = BOLTZMANN_PN_UM_PER_K * t;
        let kappa = lp * kt;
        let k = kappa / ell;
        Ok((
            kappa,
            format!(
                "bending: κ = Lp·kT = {kappa:.6e} pN·µm² (Lp {lp} µm, kT {kt:.6e} pN·µm at {t} K); per angle K = κ/ℓ = {k:.6e} pN·µm: `angle {a} wlc_bending kappa {kappa:.6e} l0 {ell:.6e}` or `angle {a} cosine_angle K {k:.6e}`",
                a = self.angle_type
            ),
        ))
    }

    /// Writes one chain through `points`: beads, bonds between neighbours and
    /// angles on every consecutive triple. Returns the bead ids.
    pub(crate) fn write(&self, w: &mut Writer, points: &[DVec3]) -> Vec<u64> {
        self.write_with_ends(w, points, [&self.particle_type, &self.particle_type])
    }

    /// [`write`](Self::write) with the first and last beads of particle types
    /// `ends` (anchored ends); the others are `--particle-type`.
    pub(crate) fn write_with_ends(&self, w: &mut Writer, points: &[DVec3], ends: [&str; 2]) -> Vec<u64> {
        let last = points.len() - 1;
        let type_of = |k: usize| match k {
            0 => ends[0],
            k if k == last => ends[1],
            _ => &self.particle_type,
        };
        let ids: Vec<u64> = points.iter().enumerate().map(|(k, p)| w.particle(type_of(k), *p, None)).collect();
        for pair in ids.windows(2) {
            w.bond(&self.bond_type, pair[0], pair[1]);
        }
        for triple in ids.windows(3) {
            w.angle(&self.angle_type, triple[0], triple[1], triple[2]);
        }
        ids
    }
}

/// Crosslinker bond types with the fraction of crosslinks each takes:
/// `xl_stiff:0.5,xl_soft:0.5` (a bare name takes fraction 1). Fractions are
/// normalised by their sum.
#[derive(Clone, Debug, PartialEq)]
pub struct CrosslinkerTypes(pub Vec<(String, f64)>);

impl Default for CrosslinkerTypes {
    fn default() -> Self {
        Self(vec![("crosslink".into(), 1.0)])
    }
}

impl std::str::FromStr for CrosslinkerTypes {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let mut types = Vec::new();
        for item in s.split(',') {
            let (name, fraction) = match item.split_once(':') {
                Some((name, f)) => (name.trim(), f.trim().parse::<f64>().map_err(|_| format!("found fraction `{f}`, expected a number"))?),
                None => (item.trim(), 1.0),
            };
            if name.is_empty() || name.contains(char::is_whitespace) || name.starts_with('#') {
                return Err(format!("found type name `{name}`, expected NAME:FRACTION[,NAME:FRACTION…]"));
            }
            if !(fraction.is_finite() && fraction >= 0.0) {
                return Err(format!("found fraction {fraction} for `{name}`, expected a fraction >= 0"));
            }
            if types.iter().any(|(n, _): &(String, f64)| n == name) {
                return Err(format!("crosslinker type `{name}` given twice"));
            }
            types.push((name.to_string(), fraction));
        }
        let sum: f64 = types.iter().map(|t| t.1).sum();
        if sum <= 0.0 {
            return Err("expected fractions summing to more than 0".into());
        }
        Ok(Self(types.into_iter().map(|(n, f)| (n, f / sum)).collect()))
    }
}

impl CrosslinkerTypes {
    /// The type for a uniform draw `u` in (0, 1): by cumulative fraction.
    pub fn pick(&self, u: f64) -> usize {
        let mut acc = 0.0;
        for (k, (_, f)) in self.0.iter().enumerate() {
            acc += f;
            if u < acc {
                return k;
            }
        }
        self.0.iter().rposition(|t| t.1 > 0.0).unwrap_or(0)
    }
}

/// Crosslinks written by [`crosslink`]: (type index, bead ids, length).
pub(crate) struct Crosslinks {
    pub links: Vec<(usize, u64, u64, f64)>,
}

impl Crosslinks {
    /// Writes the crosslinks as bonds, picking each one's type from its draw.
    pub fn from_pairs(pairs: Vec<(u64, u64, f64)>, types: &CrosslinkerTypes, draws: &Draws, purpose: u32) -> Self {
        let links = pairs.into_iter().enumerate().map(|(k, (i, j, d))| (types.pick(draws.uniform(k as u64, purpose)), i, j, d)).collect();
        Self { links }
    }

    pub fn write(&self, w: &mut Writer, types: &CrosslinkerTypes) {
        for &(t, i, j, _) in &self.links {
            w.bond(&types.0[t].0, i, j);
        }
    }

    /// For each crosslink between bead i and its partner j, the bond of the
    /// same type from i to whichever neighbour of j along j's filament is
    /// nearer to i (separations through `minimum_image`).
    pub fn pins(&self, filaments: &[(Vec<u64>, Vec<DVec3>)], minimum_image: impl Fn(DVec3) -> DVec3) -> Self {
        let mut place = std::collections::HashMap::new();
        for (f, (ids, _)) in filaments.iter().enumerate() {
            place.extend(ids.iter().enumerate().map(|(k, id)| (*id, (f, k))));
        }
        let position = |id: u64| {
            let (f, k) = place[&id];
            filaments[f].1[k]
        };
        let links = self
            .links
            .iter()
            .filter_map(|&(t, i, j, _)| {
                let (f, k) = place[&j];
                let ids = &filaments[f].0;
                let neighbours = [k.checked_sub(1), (k + 1 < ids.len()).then_some(k + 1)];
                let distance = |n: usize| minimum_image(filaments[f].1[n] - position(i)).length();
                let nearer = neighbours.into_iter().flatten().min_by(|&a, &b| distance(a).total_cmp(&distance(b)))?;
                Some((t, i, ids[nearer], distance(nearer)))
            })
            .collect();
        Self { links }
    }

    /// `M crosslinks (a 12, b 9); length min … mean … max …`.
    pub fn summary(&self, types: &CrosslinkerTypes) -> String {
        let counts: Vec<String> =
            types.0.iter().enumerate().map(|(t, (name, _))| format!("{name} {}", self.links.iter().filter(|l| l.0 == t).count())).collect();
        let mut s = format!("{} crosslinks ({})", self.links.len(), counts.join(", "));
        if !self.links.is_empty() {
            let [lo, mean, hi] = min_mean_max(&self.links.iter().map(|l| l.3).collect::<Vec<_>>());
            write!(s, "; crosslink length min {lo:.6e} mean {mean:.6e} max {hi:.6e} (for r0)").unwrap();
        }
        s
    }
}

/// For every pair of filaments (bead ids and positions), the closest pair of
/// their beads if it is closer than `capture` (separations through
/// `minimum_image`): one crosslink per pair of filaments, where they cross.
pub(crate) fn closest_pairs(
    filaments: &[(Vec<u64>, Vec<DVec3>)],
    capture: f64,
    minimum_image: impl Fn(DVec3) -> DVec3,
) -> Vec<(u64, u64, f64)> {
    // Bounding spheres: skip pairs whose centres are too far apart.
    let spheres: Vec<(DVec3, f64)> = filaments
        .iter()
        .map(|(_, x)| {
            let c = x.iter().copied().sum::<DVec3>() / x.len() as f64;
            (c, x.iter().map(|p| (*p - c).length()).fold(0.0, f64::max))
        })
        .collect();
    let mut out = Vec::new();
    for a in 0..filaments.len() {
        for b in a + 1..filaments.len() {
            if minimum_image(spheres[b].0 - spheres[a].0).length() > spheres[a].1 + spheres[b].1 + capture {
                continue;
            }
            let mut best: Option<(u64, u64, f64)> = None;
            for (i, xi) in filaments[a].0.iter().zip(&filaments[a].1) {
                for (j, xj) in filaments[b].0.iter().zip(&filaments[b].1) {
                    let d = minimum_image(*xj - *xi).length();
                    if d < capture && best.is_none_or(|(_, _, bd)| d < bd) {
                        best = Some((*i, *j, d));
                    }
                }
            }
            out.extend(best);
        }
    }
    out
}

#[cfg(test)]
pub(crate) mod testing {
    use crate::input::SourceFile;
    use crate::topology::{parse_topology, Topology};

    use super::Built;

    /// Parses a generated topology (which also checks its bodies are closed surfaces).
    pub fn parse(built: &Built) -> Topology {
        parse_topology(&SourceFile::new("built.top", built.text.clone())).unwrap_or_else(|e| panic!("{e}\n{}", built.text))
    }

    /// The positions of the bonds of type `name`, as pairs.
    pub fn bonds_of<'t>(top: &'t Topology, name: &'t str) -> impl Iterator<Item = [glam::DVec3; 2]> + 't {
        top.bonds.iter().filter(move |b| b.type_name.text == name).map(|b| b.particles.map(|i| top.positions[i as usize]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crosslinker_types_parse_and_pick_by_fraction() {
        let t: CrosslinkerTypes = "xl_stiff:0.25, xl_soft:0.75".parse().unwrap();
        assert_eq!(t.0, vec![("xl_stiff".into(), 0.25), ("xl_soft".into(), 0.75)]);
        assert_eq!((t.pick(0.1), t.pick(0.3), t.pick(0.999)), (0, 1, 1));
        assert_eq!("xl".parse::<CrosslinkerTypes>().unwrap().0, vec![("xl".into(), 1.0)]);
        assert_eq!("a:2,b:2".parse::<CrosslinkerTypes>().unwrap().0[1].1, 0.5);
        assert!("a:-1".parse::<CrosslinkerTypes>().unwrap_err().contains("expected a fraction >= 0"));
        assert!("a:0".parse::<CrosslinkerTypes>().unwrap_err().contains("summing to more than 0"));
        assert!("a:1,a:1".parse::<CrosslinkerTypes>().unwrap_err().contains("twice"));
        assert!("a:x".parse::<CrosslinkerTypes>().unwrap_err().contains("expected a number"));
    }

    #[test]
    fn draws_are_pure_functions_of_seed_and_counter() {
        let d = Draws::new(7, stream::NETWORK);
        assert_eq!(d.uniform2(3, 1), Draws::new(7, stream::NETWORK).uniform2(3, 1));
        assert_ne!(d.uniform2(3, 1), d.uniform2(4, 1));
        assert_ne!(d.uniform2(3, 1), d.uniform2(3, 2));
        assert_ne!(d.uniform2(3, 1), Draws::new(8, stream::NETWORK).uniform2(3, 1));
        assert!((d.unit_vector(0, 0).length() - 1.0).abs() < 1e-15);
        let q = d.rotation(0, 0);
        assert!((q.length() - 1.0).abs() < 1e-15);
        let picked = d.choose(0, 0, 10, 4);
        assert_eq!(picked.len(), 4);
        assert!(picked.windows(2).all(|w| w[0] < w[1]) && picked.iter().all(|&i| i < 10));
        assert_eq!(d.choose(0, 0, 3, 3), vec![0, 1, 2]);
    }

    #[test]
    fn segmentation_and_its_errors() {
        let c = Chain { length: 2.0, segments: None, segment_length: Some(0.3), ..Chain::default() };
        let (n, ell) = c.segmentation().unwrap();
        assert_eq!(n, 7);
        assert!((ell - 2.0 / 7.0).abs() < 1e-15);
        assert_eq!(Chain { segments: Some(0), ..Chain::default() }.segmentation().unwrap_err(), "expected --segments >= 1, found 0");
        assert_eq!(Chain { length: -1.0, ..Chain::default() }.segmentation().unwrap_err(), "expected --length > 0, found -1");
        assert!(Chain { segments: None, segment_length: Some(-0.1), ..Chain::default() }
            .segmentation()
            .unwrap_err()
            .contains("--segment-length > 0"));
        assert!(Chain { segments: None, ..Chain::default() }
            .segmentation()
            .unwrap_err()
            .contains("expected --segments N or --segment-length"));
        assert_eq!(wrap(-0.5, 0.0, 10.0), 9.5);
        assert_eq!(wrap(-1e-18, 0.0, 10.0), 0.0);
        assert_eq!(wrap(25.0, 0.0, 10.0), 5.0);
    }
}
