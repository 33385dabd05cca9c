//! The validated form of a deck: an initial system and a list of actions.

use std::path::PathBuf;

use super::protocol::Protocol;
use crate::forcefield::TermType;
use crate::integrate::constraints::ConstraintMethod;
use crate::integrate::fire::FireSettings;
use crate::integrate::Integrator;
use crate::output::DumpFormat;
use crate::system::{External, Model, SimBox};

/// `neighbor skin S every N check yes|no`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NeighborSettings {
    /// Extra range beyond the largest pair cutoff (length units).
    pub skin: f64,
    /// Consider a rebuild every N steps.
    pub every: u64,
    /// Rebuild only when some particle moved more than skin/2.
    pub check: bool,
}

impl Default for NeighborSettings {
    fn default() -> Self {
        Self { skin: 0.0, every: 1, check: true }
    }
}

/// A thermo output column.
#[derive(Clone, Debug, PartialEq)]
pub enum ThermoColumn {
    Step,
    Time,
    /// Total potential energy less the potential −F·x of `constant_force` externals.
    Pe,
    /// Σ F·x of the `constant_force` externals (unwrapped x): `pe − work` is the
    /// whole potential energy.
    Work,
    /// Summed force of a named external on its particles along an axis (`fx/NAME`).
    ExternalForce {
        name: String,
        axis: usize,
    },
    /// Energy of a named external (`pe/NAME`).
    ExternalEnergy(String),
    /// Potential energy of one registered interaction type (registry index).
    PeOf(usize),
    /// Largest |F| on a particle.
    Fmax,
    /// √(Σ|F|²).
    Fnorm,
    /// Pressure (trace/3 of the pressure tensor).
    Press,
    /// Pressure tensor component (0..6 = xx yy zz xy xz yz).
    Pressure(usize),
    /// Neighbour-list builds so far.
    Nbuild,
    /// Cumulative count of bond events of one kind.
    Events(crate::kinetics_engine::EventKind),
    /// Bound bonds of a bond type (index into `Model::bond_types`).
    Bound(usize),
    /// Summed tension of the bound bonds of a bond type (e.g. clutch traction).
    Tension(usize),
    /// Iterations of the last implicit step's linear solve (`integrator implicit`).
    SolverIterations,
    /// Relative residual of the last implicit step's linear solve.
    SolverResidual,
    /// Summed constraint tension of a constrained bond type (index into `Model::bond_types`).
    ConstraintTension(usize),
    /// Summed enclosed volume of the bodies of a body type (index into `Model::body_type_names`).
    BodyVolume(usize),
    /// Summed surface area of the bodies of a body type.
    BodyArea(usize),
    /// Smallest node–face distance between different bodies (`contact` lines).
    MinDistance,
    /// Explicit steps shortened by the contact step clamp so far.
    ContactClamps,
    /// Force transmitted across the plane x_axis = pos, tension positive
    /// (`planetension/AXIS/POS`; see [`crate::measure::planes`]).
    PlaneTension {
        axis: usize,
        pos: f64,
    },
    /// Method-of-planes cortical tension γ of the bodies of a body type (`gamma/BODYTYPE`).
    CorticalTension(usize),
    /// Mean end-to-end distance of the chains of a bond type (`e2e/BONDTYPE`;
    /// see [`crate::measure::filaments`]).
    EndToEnd(usize),
    /// Tangent correlation at a lag in bonds along the chains of a bond type (`tcorr/BONDTYPE/LAG`).
    TangentCorrelation {
        bond_type: usize,
        lag: usize,
    },
    /// Fracture of a sheet's junctions of a bond type (`fracture/BONDTYPE/QUANTITY`;
    /// see [`crate::measure::fracture`]).
    Fracture {
        bond_type: usize,
        quantity: crate::measure::fracture::FractureQuantity,
    },
    /// A quantity of a group's particles (`fx/GROUP`, `xu/GROUP`,
    /// `xspan/GROUP`, `fabs/GROUP`, …).
    Group {
        group: Group,
        quantity: GroupQuantity,
    },
    /// Fibre clustering S_max/S_min of a bond type across the band between
    /// two groups (`clustering/BONDTYPE/GROUP_A/GROUP_B`; see
    /// [`crate::measure::clustering`]).
    Clustering {
        bond_type: usize,
        a: Group,
        b: Group,
    },
    /// Magnitude of the summed force an indenter external exerts on its
    /// group, its reaction (`load/NAME`).
    IndenterLoad(String),
    /// Deepest penetration δ of a particle into an indenter external (`depth/NAME`).
    IndenterDepth(String),
}

/// What a group thermo column measures over the group's particles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum GroupQuantity {
    /// Summed force along an axis (`fx/`, `fy/`, `fz/`), pN; on `fixed` and
    /// moved particles the reaction of what holds them.
    Force(usize),
    /// Mean unwrapped coordinate along an axis (`xu/`, `yu/`, `zu/`), µm.
    Position(usize),
    /// Extent, largest minus smallest unwrapped coordinate along an axis
    /// (`xspan/`, `yspan/`, `zspan/`), µm: e.g. a nucleus' height.
    Span(usize),
    /// Σ|f_i|, the summed magnitudes of the particles' forces (`fabs/`), pN:
    /// Vassaux & Milan's (2017) "total resultant force at the focal
    /// adhesions", which the vector sum `fx/` … would cancel.
    ForceMagnitudes,
    /// Area of the convex hull of the particles' (x, y) projection
    /// (`hullarea/`), µm²: a cell's footprint, its spread area on a substrate.
    HullArea,
}

impl GroupQuantity {
    /// The quantity a column prefix names (`fx`, `xu`, `zspan`, `fabs`).
    pub fn from_prefix(prefix: &str) -> Option<Self> {
        let axis = |c: u8| usize::from(c - b'x');
        match prefix {
            "fx" | "fy" | "fz" => Some(Self::Force(axis(prefix.as_bytes()[1]))),
            "xu" | "yu" | "zu" => Some(Self::Position(axis(prefix.as_bytes()[0]))),
            "xspan" | "yspan" | "zspan" => Some(Self::Span(axis(prefix.as_bytes()[0]))),
            "fabs" => Some(Self::ForceMagnitudes),
            "hullarea" => Some(Self::HullArea),
            _ => None,
        }
    }

    /// The column prefix (inverse of [`Self::from_prefix`]).
    pub fn prefix(self) -> String {
        let axis = |a: usize| ["x", "y", "z"][a];
        match self {
            Self::Force(a) => format!("f{}", axis(a)),
            Self::Position(a) => format!("{}u", axis(a)),
            Self::Span(a) => format!("{}span", axis(a)),
            Self::ForceMagnitudes => "fabs".into(),
            Self::HullArea => "hullarea".into(),
        }
    }

    /// The quantity's dimension.
    pub fn dim(self) -> crate::units::Dim {
        use crate::units::Dim;
        match self {
            Self::Force(_) | Self::ForceMagnitudes => Dim::Force,
            Self::Position(_) | Self::Span(_) => Dim::Length,
            Self::HullArea => Dim::Area,
        }
    }
}

/// A named trajectory output.
#[derive(Clone, Debug)]
pub struct DumpSpec {
    pub name: String,
    pub every: u64,
    pub format: DumpFormat,
    pub path: PathBuf,
    /// LAMMPS dump atom columns (`columns ...`) and the MCAP scene's `encoding`.
    pub options: crate::output::WriterOptions,
}

/// Periodic restart files (`write_state FILE every N [keep K]`): written at
/// every step that is a multiple of `every` during a run, each atomically.
/// A `*` in the file name stands for the step; then only the last `keep`
/// files (when given) are kept.
#[derive(Clone, Debug, PartialEq)]
pub struct CheckpointSpec {
    pub path: PathBuf,
    pub every: u64,
    pub keep: Option<usize>,
}

/// A named particle group (deck `group`).
#[derive(Clone, Debug, PartialEq)]
pub struct Group {
    pub name: String,
    /// Internal indices, ascending.
    pub members: Vec<u32>,
}

/// One executable step of a deck, in order.
#[derive(Clone, Debug)]
pub enum Action {
    Temperature(f64),
    Timestep(f64),
    Seed(u64),
    /// Which backend runs the steps (`device cpu|gpu|auto`).
    Device(crate::gpu::DevicePreference),
    Integrator(Integrator),
    Neighbor(NeighborSettings),
    Thermo {
        every: u64,
        columns: Vec<ThermoColumn>,
    },
    ThermoFile(PathBuf),
    /// CSV log of bond kinetics events.
    EventFile(PathBuf),
    /// CSV table of bond lifetimes per bond type, rewritten after every `run`.
    LifetimeFile(PathBuf),
    Dump(DumpSpec),
    Undump(String),
    External(External),
    Unexternal(String),
    /// Moves every particle of a group by `delta` at once (`displace_atoms
    /// GROUP move DX DY DZ`), wrapping periodic axes.
    Displace {
        group: Group,
        delta: glam::DVec3,
    },
    /// Changes one parameter of a bond type, angle type, pair rule, body
    /// surface term or active external.
    Coeff {
        target: CoeffTarget,
        param: usize,
        value: f64,
    },
    /// Holds the bonds of a bond type at their rest length (`constrain`).
    Constrain {
        bond_type: usize,
        tolerance: f64,
        max_iterations: usize,
        /// Move the particles onto the lengths at once (`reshape yes`).
        reshape: bool,
        /// Chains solved fibre by fibre, or every constraint by SHAKE (`method`).
        method: ConstraintMethod,
    },
    /// Releases a constrained bond type (`unconstrain`).
    Unconstrain(usize),
    /// A time-dependent protocol command (`ramp`, `move`, `freeze`, `reset_rest`, …).
    Protocol(Protocol),
    Minimize(FireSettings),
    Run(u64),
    WriteState(PathBuf),
    /// Periodic checkpoints from now on (replacing earlier ones).
    Checkpoint(CheckpointSpec),
    ReadState(PathBuf),
    Print(String),
    /// An `if` decided during the run: when the condition does not hold,
    /// the next `skip` actions (its then-branch) are skipped.
    Branch {
        condition: super::Condition,
        skip: usize,
    },
    /// Skips the next N actions (the end of a then-branch jumping over its
    /// else-branch, or a `break` decided during the run jumping to its loop's end).
    Skip(usize),
}

impl Action {
    /// Whether the action only opens, closes or writes output (thermo,
    /// dumps, event log, restarts, prints) and leaves the physics alone.
    pub fn is_output(&self) -> bool {
        matches!(
            self,
            Action::Thermo { .. }
                | Action::ThermoFile(_)
                | Action::EventFile(_)
                | Action::LifetimeFile(_)
                | Action::Dump(_)
                | Action::Undump(_)
                | Action::WriteState(_)
                | Action::Checkpoint(_)
                | Action::Print(_)
        )
    }

    /// Whether `cellmd run --continue` applies the action again, before the
    /// restart's state, when it came before the point the run stopped at:
    /// settings, model edits and opened outputs are; what moved particles
    /// or wrote files (runs, minimisations, displacements, state files,
    /// prints) is not, the restart holds its outcome.
    pub fn replays_on_continue(&self) -> bool {
        !matches!(
            self,
            Action::Run(_)
                | Action::Minimize(_)
                | Action::Displace { .. }
                | Action::WriteState(_)
                | Action::ReadState(_)
                | Action::Print(_)
                | Action::Branch { .. }
                | Action::Skip(_)
        )
    }
}

/// What a `coeff` or `ramp` command changes: an index into the model's
/// tables, or the name of an active external.
#[derive(Clone, Debug, PartialEq)]
pub enum CoeffTarget {
    BondType(usize),
    AngleType(usize),
    PairRule(usize),
    /// A surface term of a body type (index into `Model::body_rules`).
    BodyRule(usize),
    /// The active external of this name.
    External(String),
}

impl CoeffTarget {
    /// The term this target names in `model`; an external must be active
    /// there (the deck checked it is at this point of the deck).
    pub fn term<'a>(&self, model: &'a Model) -> &'a TermType {
        match self {
            CoeffTarget::BondType(k) => &model.bond_types[*k],
            CoeffTarget::AngleType(k) => &model.angle_types[*k],
            CoeffTarget::PairRule(k) => &model.pair_rules[*k],
            CoeffTarget::BodyRule(k) => &model.body_rules[*k],
            CoeffTarget::External(name) => {
                &model.externals.iter().find(|e| e.term.label.text == *name).expect("the deck checked the external is active").term
            }
        }
    }

    /// The parameters of [`CoeffTarget::term`], to change them.
    fn params_mut<'a>(&self, model: &'a mut Model) -> &'a mut Vec<f64> {
        match self {
            CoeffTarget::BondType(k) => model.bond_types[*k].params_mut(),
            CoeffTarget::AngleType(k) => model.angle_types[*k].params_mut(),
            CoeffTarget::PairRule(k) => model.pair_rules[*k].params_mut(),
            CoeffTarget::BodyRule(k) => model.body_rules[*k].params_mut(),
            CoeffTarget::External(name) => model
                .externals
                .iter_mut()
                .find(|e| e.term.label.text == *name)
                .expect("the deck checked the external is active")
                .term
                .params_mut(),
        }
    }

    /// Sets parameter `param` of the term this target names in `model`: the
    /// one application of a `coeff` edit or a ramp's value, in the deck's
    /// checks and in the run.
    pub fn set(&self, model: &mut Model, param: usize, value: f64) {
        self.params_mut(model)[param] = value;
    }
}

/// A validated deck.
#[derive(Clone, Debug)]
pub struct Plan {
    pub deck_path: PathBuf,
    pub model: Model,
    pub sim_box: SimBox,
    pub positions: Vec<glam::DVec3>,
    pub actions: Vec<Action>,
    /// The deck's path, `--var` overrides and input files as read.
    pub inputs: crate::input::DeckInputs,
    /// `file:line:col: warning: …` lines: accepted but suspicious input
    /// (printed by `cellmd check` and `run`).
    pub warnings: Vec<String>,
}
