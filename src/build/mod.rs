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
mod chain;
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
mod writer;

use std::f64::consts::TAU;
use std::path::PathBuf;

use glam::{DQuat, DVec3};

use crate::rng::{self, open_unit_52};

pub use self::aster::{aster, AsterArgs};
pub use self::ball::{ball, BallArgs};
pub use self::block::{block, BlockArgs};
pub use self::branched::{branched, BranchedArgs};
pub use self::cells::{cells, CellsArgs, Layout};
pub(crate) use self::chain::{closest_pairs, Crosslinks};
pub use self::chain::{Chain, CrosslinkerTypes};
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
pub(crate) use self::writer::Writer;

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
mod tests;
