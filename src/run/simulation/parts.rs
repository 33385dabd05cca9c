//! The sub-states a [`Simulation`](super::Simulation) is made of, besides
//! the system itself (model, state, box), the constraints and the
//! protocols: each owns one concern of a run, and the methods that read
//! only that concern live on it.

use std::collections::HashMap;
use std::path::PathBuf;

use glam::DVec3;

use super::outputs::ActiveDump;
use super::reference::Reference;
use super::restarts::Checkpoints;
use crate::backend::Forces;
use crate::deck::NeighborSettings;
use crate::gpu::{DevicePreference, GpuContext};
use crate::input::DeckInputs;
use crate::integrate::context::StepContext;
use crate::integrate::fire::FireReport;
use crate::integrate::implicit::SolveReport;
use crate::integrate::Integrator;
use crate::kinetics_engine::{Formation, Kinetics};
use crate::output::restart::Resume;
use crate::output::run_log::{PhaseTimes, RunLog};
use crate::output::{EventLog, LifetimeTable};
use crate::run::thermo::Thermo;
use crate::system::State;

/// The deck's settings in force for the next step: `temperature`,
/// `timestep`, `seed`, `integrator`, `neighbor` and `device`.
#[derive(Clone, Debug)]
pub struct Settings {
    /// Thermal energy kT.
    pub kt: f64,
    /// The time step.
    pub dt: f64,
    pub seed: u64,
    pub integrator: Integrator,
    pub neighbor: NeighborSettings,
    /// The deck's `device` setting (the CLI's `--device` overrides it).
    pub device: DevicePreference,
}

impl Default for Settings {
    fn default() -> Self {
        Self {
            kt: 0.0,
            dt: 0.0,
            seed: 1,
            integrator: Integrator::default(),
            neighbor: NeighborSettings::default(),
            device: DevicePreference::Cpu,
        }
    }
}

impl Settings {
    /// The context of the step that starts from `state`: these settings and the state's clock.
    pub fn step_context(&self, state: &State) -> StepContext {
        StepContext {
            dt: self.dt,
            kt: self.kt,
            seed: self.seed,
            noise: self.integrator.common().noise,
            max_displacement: self.integrator.common().max_displacement,
            step: state.step,
            time: state.time,
        }
    }

    /// Why a step of `displacement` is a blow-up.
    pub(super) fn displacement_message(&self, displacement: f64) -> String {
        format!("displacement {displacement:e} in one step exceeds max_displacement {:e}", self.integrator.common().max_displacement)
    }
}

/// The backends of a run and what they computed at the current state: the
/// CPU backend (the reference for thermo and measurements, whichever
/// backend steps), the opened GPU, the forces, and the CPU steps' work arrays.
#[derive(Default)]
pub struct Backends {
    /// Forces, energies by interaction and virial of the last force pass.
    pub forces: Forces,
    /// The CPU backend (the reference for thermo and measurements).
    pub(super) cpu: Reference,
    /// The opened GPU (kept across `run` commands), or why it could not be used.
    pub(super) gpu: Option<Result<GpuContext, String>>,
    /// Whether `forces` holds the forces of the current state.
    pub(super) forces_current: bool,
    /// Whether `forces` also holds the energies and virial of the current state.
    pub(super) energies_current: bool,
    /// The explicit step's work array.
    pub(super) scratch: Vec<DVec3>,
    /// Per-particle displacement limits of the contact step clamp.
    pub(super) step_limits: Vec<f64>,
    /// Constraint tensions of the last implicit step's solve (added to SHAKE's).
    pub(super) implicit_tension: Vec<f64>,
}

/// Bond kinetics: the host's event counts and decisions, and bond formation.
#[derive(Default)]
pub struct KineticsState {
    /// Event counts, warnings and the per-step decisions of the host.
    pub engine: Kinetics,
    /// Bond formation (when the force field has `bind` rules).
    pub(super) formation: Option<Formation>,
    /// GPU steps whose `bind` formation the device left to the host (its
    /// bond pool, slots, candidate list or neighbour list ran out of room,
    /// src/gpu/bind.rs), this run.
    pub host_formations: u64,
}

/// What the run reports about its own steps: counters and the last solves.
#[derive(Default)]
pub struct Reports {
    /// Explicit steps shortened by the contact step clamp.
    pub contact_clamps: u64,
    /// The last minimisation's outcome.
    pub last_minimize: Option<FireReport>,
    /// The last implicit step's linear solve.
    pub last_solve: SolveReport,
    /// Wall time by phase of the step loop (for the run log).
    pub times: PhaseTimes,
}

/// The outputs a deck opened: thermo, dumps, the event log, the lifetime
/// table, checkpoints and the run log, with the names they label things by.
pub(super) struct Outputs {
    pub(super) thermo: Thermo,
    pub(super) dumps: Vec<ActiveDump>,
    pub(super) event_log: Option<(EventLog, PathBuf)>,
    /// Lifetimes of broken bonds and where the deck wants their table.
    pub(super) lifetimes: LifetimeTable,
    pub(super) lifetime_file: Option<PathBuf>,
    pub(super) checkpoints: Option<Checkpoints>,
    pub(super) log: Option<RunLog>,
    /// Bond type labels, for outputs.
    pub(super) bond_type_names: Vec<String>,
    /// The deck's file stem, which names the run log and the restarts a run writes itself.
    pub(super) deck_stem: String,
}

impl Outputs {
    pub(super) fn new(thermo: Thermo, bond_type_names: Vec<String>, deck_stem: String) -> Self {
        Self {
            thermo,
            dumps: Vec::new(),
            event_log: None,
            lifetimes: LifetimeTable::default(),
            lifetime_file: None,
            checkpoints: None,
            log: None,
            bond_type_names,
            deck_stem,
        }
    }

    /// Whether a thermo row is due at `step`.
    pub(super) fn thermo_due(&self, step: u64) -> bool {
        self.thermo.every > 0 && step.is_multiple_of(self.thermo.every)
    }

    /// Whether an output that reads the positions (thermo, a dump, a
    /// checkpoint) is due at `step`.
    pub(super) fn reads_positions_at(&self, step: u64) -> bool {
        self.thermo_due(step)
            || self.dumps.iter().any(|d| step.is_multiple_of(d.spec.every))
            || self.checkpoints.as_ref().is_some_and(|c| step.is_multiple_of(c.spec.every))
    }

    /// The first step after `step` at which thermo, a dump or a checkpoint is due (or `last`).
    pub(super) fn next_due(&self, step: u64, last: u64) -> u64 {
        let after = |every: u64| (step / every + 1) * every;
        let mut next = last;
        if self.thermo.every > 0 {
            next = next.min(after(self.thermo.every));
        }
        for dump in &self.dumps {
            next = next.min(after(dump.spec.every));
        }
        if let Some(c) = &self.checkpoints {
            next = next.min(after(c.spec.every));
        }
        next
    }
}

/// Where the run stands in its deck, as a restart carries it.
pub(super) struct DeckProgress {
    /// The deck and its inputs as read, carried by every restart written.
    pub(super) inputs: DeckInputs,
    /// Index of the deck action being applied.
    pub(super) action: usize,
    /// The last step of the `run` in progress.
    pub(super) run_end: Option<u64>,
    /// The thermo values each run-time `if` (by its place in the deck, so
    /// across the iterations of a loop) read at its last decision, for its
    /// `previous(…)`.
    pub(super) decisions: HashMap<String, Vec<f64>>,
}

impl DeckProgress {
    /// Where a restart written now resumes the deck.
    pub(super) fn resume(&self) -> Resume {
        Resume { inputs: self.inputs.clone(), action: self.action, run_end: self.run_end }
    }
}
