//! The run loop: actions of a plan applied to a live system.

use std::path::{Path, PathBuf};

use glam::DVec3;
use indicatif::{ProgressBar, ProgressStyle};
use rayon::prelude::*;

use super::blowup::{culprit, RunError};
use super::protocol::{reset_rest, Protocols};
use super::stop::StopSignal;
use super::thermo::{column_value, Thermo, ThermoInputs};
use crate::backend::{CpuBackend, Forces};
use crate::deck::{Action, CheckpointSpec, CoeffTarget, DumpSpec, NeighborSettings, Plan, Protocol, ThermoColumn};
use crate::gpu::backend::StepSettings;
use crate::gpu::{DevicePreference, GpuBackend, GpuContext, GpuHalt};
use crate::input::DeckInputs;
use crate::integrate::constraints::{Constraint, Constraints};
use crate::integrate::fire::{fire_minimize, FireReport, FireSettings};
use crate::integrate::implicit::{implicit_step, ConstrainedBonds, ImplicitError, ImplicitSettings, SolveReport};
use crate::integrate::overdamped::{overdamped_step, Blowup};
use crate::integrate::Integrator;
use crate::kinetics_engine::{initial_bond_state, Binding, Formation, Kinetics};
use crate::output::restart::{read_state, write_state, Counters, RestartData, Resume};
use crate::output::run_log::{model_parameters, LogHeader, Phase, PhaseTimes, RunLog};
use crate::output::{open_writer_with, EventLog, FrameView, LifetimeTable, Measures, TopologyView, TrajectoryWriter, WallPlane};
use crate::system::{Model, SimBox, State, StepClock};

mod stepping;

pub use self::stepping::{ActiveRun, BondTable};

/// The longest GPU segment between read-backs when no output is due.
const GPU_SYNC_STEPS: u64 = 1000;

/// How to run: where outputs go and how to report progress.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// Directory that relative output paths are resolved against.
    pub output_dir: PathBuf,
    /// Show a progress bar (only when attached to a terminal).
    pub progress: bool,
    /// Print thermo and messages to stdout.
    pub echo: bool,
    /// Overrides the deck's `device` (the CLI's `--device`).
    pub device: Option<DevicePreference>,
    /// Set by SIGTERM/SIGINT or a closed stdout: the run stops after the
    /// current step, finalises its outputs and writes a restart.
    pub stop: StopSignal,
    /// Write the run log `NAME.log` in the output directory, with this head.
    pub log: Option<LogHeader>,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self { output_dir: PathBuf::from("."), progress: false, echo: false, device: None, stop: StopSignal::new(), log: None }
    }
}

/// Periodic checkpoints in force, the step of the last one and the files
/// written with a `*` name (oldest first).
struct Checkpoints {
    spec: CheckpointSpec,
    last_step: Option<u64>,
    written: std::collections::VecDeque<PathBuf>,
}

/// `path` with a `*` in its file name replaced by the step (LAMMPS' `write_restart file.*`).
fn with_step(path: &Path, step: u64) -> PathBuf {
    match path.file_name().map(|n| n.to_string_lossy()) {
        Some(name) if name.contains('*') => path.with_file_name(name.replace('*', &step.to_string())),
        _ => path.to_path_buf(),
    }
}

struct ActiveDump {
    spec: DumpSpec,
    path: PathBuf,
    writer: Box<dyn TrajectoryWriter>,
    last_step: Option<u64>,
}

/// A live simulation.
pub struct Simulation {
    pub model: Model,
    pub state: State,
    pub sim_box: SimBox,
    pub forces: Forces,
    pub kt: f64,
    pub dt: f64,
    pub seed: u64,
    pub integrator: Integrator,
    pub neighbor: NeighborSettings,
    backend: Option<CpuBackend>,
    forces_current: bool,
    /// Whether `forces` also holds the energies and virial of the current state.
    energies_current: bool,
    thermo: Thermo,
    dumps: Vec<ActiveDump>,
    /// Bond kinetics: event counts and the CSV event log.
    pub kinetics: Kinetics,
    /// Bond formation (when the force field has `bind` rules).
    formation: Option<Formation>,
    event_log: Option<(EventLog, PathBuf)>,
    /// Lifetimes of broken bonds and where the deck wants their table.
    lifetimes: LifetimeTable,
    lifetime_file: Option<PathBuf>,
    options: RunOptions,
    deck_stem: String,
    scratch: Vec<DVec3>,
    /// Per-particle displacement limits of the contact step clamp.
    step_limits: Vec<f64>,
    /// Explicit steps shortened by the contact step clamp.
    pub contact_clamps: u64,
    /// The last minimisation's outcome.
    pub last_minimize: Option<FireReport>,
    /// The deck's `device` setting.
    pub device: DevicePreference,
    /// The last implicit step's linear solve.
    pub last_solve: SolveReport,
    /// Constrained (inextensible) bonds.
    pub constraints: Constraints,
    /// Constraint tensions of the last implicit step's solve (added to SHAKE's).
    implicit_tension: Vec<f64>,
    /// The opened GPU (kept across `run` commands), or why it could not be used.
    gpu: Option<Result<GpuContext, String>>,
    /// Bond type labels, for outputs.
    bond_type_names: Vec<String>,
    /// The deck and its inputs as read, carried by every restart written.
    inputs: DeckInputs,
    /// Index of the deck action being applied.
    action: usize,
    /// The last step of the `run` in progress.
    run_end: Option<u64>,
    checkpoints: Option<Checkpoints>,
    /// Wall time by phase of the step loop (for the run log).
    pub times: PhaseTimes,
    log: Option<RunLog>,
    /// Ramps, moved and frozen groups in force.
    protocols: Protocols,
}

impl Simulation {
    /// A simulation at the plan's initial state (positions wrapped into the
    /// box), on copies of the plan's model and positions; [`Self::execute`]
    /// takes them instead.
    pub fn new(plan: &Plan, options: RunOptions) -> Self {
        Self::start(plan.model.clone(), plan.sim_box, plan.positions.clone(), &plan.deck_path, plan.inputs.clone(), options)
    }

    fn start(model: Model, sim_box: SimBox, positions: Vec<DVec3>, deck_path: &Path, inputs: DeckInputs, options: RunOptions) -> Self {
        let mut state = State::new(positions);
        for (x, image) in state.positions.iter_mut().zip(state.images.iter_mut()) {
            sim_box.wrap(x, image);
        }
        state.bonds = initial_bond_state(&model);
        let deck_stem = deck_path.file_stem().map_or("cellmd".into(), |s| s.to_string_lossy().into_owned());
        Self {
            thermo: Thermo::new(&model),
            formation: (!model.bind_rules.is_empty()).then(|| Formation::new(&model, &sim_box)),
            bond_type_names: model.bond_types.iter().map(|t| t.label.text.clone()).collect(),
            model,
            state,
            sim_box,
            forces: Forces::default(),
            kt: 0.0,
            dt: 0.0,
            seed: 1,
            integrator: Integrator::default(),
            neighbor: NeighborSettings::default(),
            backend: None,
            forces_current: false,
            energies_current: false,
            dumps: Vec::new(),
            kinetics: Kinetics::default(),
            event_log: None,
            lifetimes: LifetimeTable::default(),
            lifetime_file: None,
            options,
            deck_stem,
            scratch: Vec::new(),
            step_limits: Vec::new(),
            contact_clamps: 0,
            last_minimize: None,
            device: DevicePreference::Cpu,
            last_solve: SolveReport::default(),
            constraints: Constraints::default(),
            implicit_tension: Vec::new(),
            gpu: None,
            inputs,
            action: 0,
            run_end: None,
            checkpoints: None,
            times: PhaseTimes::default(),
            log: None,
            protocols: Protocols::default(),
        }
    }

    /// Runs every action of the plan; output files are closed cleanly even on
    /// error. The simulation takes the plan's model and initial positions
    /// (no second copy of the system stays resident during the run).
    pub fn execute(plan: Plan, options: RunOptions) -> Result<Simulation, RunError> {
        let Plan { deck_path, model, sim_box, positions, actions, inputs, .. } = plan;
        let mut sim = Simulation::start(model, sim_box, positions, &deck_path, inputs, options);
        let result = sim.open_log().and_then(|()| sim.perform(&actions, 0));
        sim.finish(result)
    }

    /// Continues a run from a restart that carries its deck (`cellmd run
    /// --continue`): `plan` is the deck rebuilt from the restart's inputs.
    /// The actions before the stopping point that set things up are applied
    /// again (settings, model edits, outputs, opened anew in the output
    /// directory), then the restart's state and counters are loaded, the
    /// `run` in progress is finished and the rest of the deck is applied.
    /// The final state is the uninterrupted run's, bit for bit (on the CPU).
    pub fn resume(plan: Plan, data: RestartData, restart: &Path, options: RunOptions) -> Result<Simulation, RunError> {
        let Some(resume) = data.resume.clone() else {
            return Err(RunError::Setup(format!("{}: the restart carries no deck to continue", restart.display())));
        };
        let Plan { deck_path, model, sim_box, positions, actions, inputs, .. } = plan;
        let mut sim = Simulation::start(model, sim_box, positions, &deck_path, inputs, options);
        let result = (|| {
            sim.open_log()?;
            let before = actions.get(..resume.action).ok_or_else(|| {
                RunError::Setup(format!("{}: action {} is beyond the deck's {}", restart.display(), resume.action, actions.len()))
            })?;
            if before.iter().any(|a| matches!(a, Action::Branch { .. })) {
                return Err(RunError::Setup(format!(
                    "{}: an `if` decided during the run comes before the stopping point; --continue cannot tell which branch ran",
                    restart.display()
                )));
            }
            for (k, action) in before.iter().enumerate().filter(|(_, a)| a.replays_on_continue()) {
                sim.action = k;
                sim.apply(action)?;
            }
            sim.load_restart(data, restart)?;
            sim.say(&format!("continuing {} from step {} ({})", sim.inputs.deck, sim.state.step, restart.display()));
            let next = match resume.run_end {
                Some(end) if end > sim.state.step => {
                    sim.action = resume.action;
                    sim.run(end - sim.state.step)?;
                    resume.action + 1
                }
                Some(_) => resume.action + 1,
                None => resume.action,
            };
            sim.perform(&actions, next)
        })();
        sim.finish(result)
    }

    /// Applies `actions[from..]` in order, checking for a stop request
    /// before each and following the jumps of the `if`s decided during the
    /// run (and of a `break` inside one).
    fn perform(&mut self, actions: &[Action], from: usize) -> Result<(), RunError> {
        let mut next = from;
        while let Some(action) = actions.get(next) {
            self.action = next;
            self.stop_if_requested()?;
            next += 1 + match action {
                Action::Branch { condition, skip } => {
                    let holds = condition.holds(&mut |c| self.thermo_value(c).map_err(|e| e.to_string())).map_err(RunError::Setup)?;
                    if holds {
                        0
                    } else {
                        *skip
                    }
                }
                Action::Skip(n) => *n,
                other => {
                    self.apply(other)?;
                    0
                }
            };
        }
        Ok(())
    }

    /// Closes every output after the actions (also after an error); the
    /// run log ends with the outcome and the time by phase.
    fn finish(mut self, result: Result<(), RunError>) -> Result<Simulation, RunError> {
        let mut closed = self.close_outputs();
        if let Some(mut log) = self.log.take() {
            let outcome = match &result {
                Ok(()) => format!("finished at step {}", self.state.step),
                Err(e) => format!("ended at step {}: {e}", self.state.step),
            };
            let text = format!(
                "\n{outcome}\nloop time {:.3} s by section (CPU step loop):\n{}",
                self.times.total.as_secs_f64(),
                self.times.table()
            );
            if let Err(e) = log.section(&text) {
                closed = closed.and(Err(self.output_error(&log.path, e)));
            }
        }
        result?;
        closed?;
        Ok(self)
    }

    /// Creates the run log when the options ask for one.
    fn open_log(&mut self) -> Result<(), RunError> {
        let Some(header) = &self.options.log else { return Ok(()) };
        let path = self.output_path(Path::new(&format!("{}.log", self.deck_stem)));
        let log = RunLog::create(&path, header, &self.inputs).map_err(|e| self.output_error(&path, e))?;
        self.log = Some(log);
        Ok(())
    }

    /// Logs the resolved settings and parameters a `run` starts with.
    fn log_run(&mut self, steps: u64, device: &str) -> Result<(), RunError> {
        let Some(log) = &mut self.log else { return Ok(()) };
        let text = format!(
            "\nrun {steps} from step {} on {device}: units {:?}, {} particles, box {:?} to {:?} periodic {:?}\n\
             timestep {:e}, temperature (kT) {:e}, seed {}, integrator {:?}, neighbor {:?}\n{}",
            self.state.step,
            self.model.units,
            self.model.len(),
            self.sim_box.lo.to_array(),
            self.sim_box.hi.to_array(),
            self.sim_box.periodic,
            self.dt,
            self.kt,
            self.seed,
            self.integrator,
            self.neighbor,
            model_parameters(&self.model)
        );
        if let Err(e) = log.section(&text) {
            let path = log.path.clone();
            return Err(self.output_error(&path, e));
        }
        Ok(())
    }

    /// When a stop was requested: writes `NAME.restart` (with the deck and
    /// where the run stands in it) and the lifetime table, and returns
    /// [`RunError::Stopped`]; the caller's error path closes the outputs.
    fn stop_if_requested(&mut self) -> Result<(), RunError> {
        let Some(reason) = self.options.stop.requested() else { return Ok(()) };
        let restart = self.output_path(Path::new(&format!("{}.restart", self.deck_stem)));
        self.write_lifetimes()?;
        write_state(&restart, &self.restart_data()).map_err(|e| self.output_error(&restart, e))?;
        Err(RunError::Stopped { step: self.state.step, reason: reason.to_string(), restart: restart.display().to_string() })
    }

    /// An output that could not be written, with the step it happened at.
    fn output_error(&self, path: &Path, e: impl std::fmt::Display) -> RunError {
        RunError::Io(format!("{}: {e} (at step {})", path.display(), self.state.step))
    }

    /// The simulation as the deck sets it up before its first `run`,
    /// `minimize` or `if` decided during the run: settings, externals, coefficient edits and restarts are
    /// applied; outputs are not opened. For tools that inspect or time the
    /// initial system (`cellmd profile-gpu`, tests).
    pub fn before_first_run(plan: &Plan, options: RunOptions) -> Result<Simulation, RunError> {
        let mut sim = Simulation::new(plan, options);
        for action in plan.actions.iter().take_while(|a| !matches!(a, Action::Run(_) | Action::Minimize(_) | Action::Branch { .. })) {
            if !action.is_output() {
                sim.apply(action)?;
            }
        }
        Ok(sim)
    }

    fn say(&self, message: &str) {
        if self.options.echo {
            self.options.stop.say(message);
        }
    }

    fn output_path(&self, path: &Path) -> PathBuf {
        if path.is_absolute() {
            path.to_path_buf()
        } else {
            self.options.output_dir.join(path)
        }
    }

    /// Applies one action (jumps only make sense within their plan: see
    /// [`Self::perform`]).
    pub fn apply(&mut self, action: &Action) -> Result<(), RunError> {
        match action {
            Action::Branch { .. } | Action::Skip(_) => {
                return Err(RunError::Setup("a jump of an `if` decided during the run is applied with its plan".into()))
            }
            Action::Temperature(kt) => self.kt = *kt,
            Action::Timestep(dt) => self.dt = *dt,
            Action::Seed(seed) => self.seed = *seed,
            Action::Device(device) => self.device = *device,
            Action::Integrator(settings) => self.integrator = *settings,
            Action::Neighbor(settings) => {
                self.neighbor = *settings;
                self.backend = None;
            }
            Action::Thermo { every, columns } => {
                self.thermo.every = *every;
                self.thermo.set_columns(columns.clone(), &self.model);
            }
            Action::EventFile(path) => {
                let path = self.output_path(path);
                let file = std::fs::File::create(&path).map_err(|e| self.output_error(&path, e))?;
                let log = EventLog::create(file, self.model.units).map_err(|e| self.output_error(&path, e))?;
                if let Some((old, old_path)) = self.event_log.replace((log, path)) {
                    old.finish().map_err(|e| self.output_error(&old_path, e))?;
                }
            }
            Action::LifetimeFile(path) => self.lifetime_file = Some(self.output_path(path)),
            Action::ThermoFile(path) => {
                let path = self.output_path(path);
                let file = std::fs::File::create(&path).map_err(|e| self.output_error(&path, e))?;
                self.thermo.set_file(file, path).map_err(|(path, e)| self.output_error(&path, e))?;
            }
            Action::Dump(spec) => {
                let path = self.output_path(&spec.path);
                let writer =
                    open_writer_with(spec.format, &path, &self.topology_view(), &spec.options).map_err(|e| self.output_error(&path, e))?;
                self.dumps.push(ActiveDump { spec: spec.clone(), path, writer, last_step: None });
            }
            Action::Undump(name) => {
                if let Some(k) = self.dumps.iter().position(|d| d.spec.name == *name) {
                    let dump = self.dumps.remove(k);
                    dump.writer.finish().map_err(|e| self.output_error(&dump.path, e))?;
                }
            }
            Action::External(external) => {
                self.model.externals.retain(|e| e.term.label.text != external.term.label.text);
                self.model.externals.push(external.clone());
                self.forces_current = false;
            }
            Action::Unexternal(name) => {
                self.model.externals.retain(|e| e.term.label.text != *name);
                self.protocols.forget_drive(name);
                self.forces_current = false;
            }
            Action::Displace { group, delta } => self.displace(&group.members, *delta)?,
            Action::Coeff { target, param, value } => {
                if let CoeffTarget::PairRule(_) = target {
                    self.backend = None; // the cutoff may change
                }
                target.term_mut(&mut self.model).params[*param] = *value;
                self.forces_current = false;
            }
            Action::Protocol(Protocol::ResetRest(bond_types)) => {
                reset_rest(&mut self.model, &mut self.state, &self.sim_box, bond_types);
                self.backend = None; // bonds now carry state
                self.forces_current = false;
            }
            Action::Protocol(protocol) => self.protocols.apply(protocol),
            Action::Constrain { bond_type, tolerance, max_iterations } => {
                self.constraints.list.retain(|c| self.model.bond_type[c.bond] as usize != *bond_type);
                // Each bond at its rest length now (its own, or the type's `r0`; the deck checked it has one).
                let bonds = (0..self.model.bonds.len()).filter(|&b| self.model.bond_type[b] as usize == *bond_type);
                let (model, state) = (&self.model, self.state.bonds.as_ref());
                self.constraints.list.extend(bonds.map(|bond| Constraint { bond, length: model.rest_length(bond, state) }));
                self.constraints.list.sort_by_key(|c| c.bond);
                self.constraints.tolerance = *tolerance;
                self.constraints.max_iterations = *max_iterations;
                self.constraints.tension.clear();
            }
            Action::Unconstrain(bond_type) => {
                self.constraints.list.retain(|c| self.model.bond_type[c.bond] as usize != *bond_type);
                self.constraints.tension.clear();
            }
            Action::Minimize(settings) => self.minimize(settings)?,
            Action::Run(steps) => self.run(*steps)?,
            Action::WriteState(path) => {
                let path = self.output_path(&with_step(path, self.state.step));
                write_state(&path, &self.restart_data()).map_err(|e| self.output_error(&path, e))?;
                self.say(&format!("wrote state at step {} to {}", self.state.step, path.display()));
            }
            Action::Checkpoint(spec) => {
                self.checkpoints = Some(Checkpoints { spec: spec.clone(), last_step: None, written: Default::default() })
            }
            Action::ReadState(path) => {
                let path = if path.exists() { path.clone() } else { self.output_path(path) };
                let data = read_state(&path).map_err(|e| RunError::Setup(format!("{}: {e}", path.display())))?;
                self.load_restart(data, &path)?;
            }
            Action::Print(text) => self.say(text),
        }
        Ok(())
    }

    /// `displace_atoms`: moves `members` by `delta` (wrapped on periodic axes,
    /// image counters kept, so unwrapped coordinates move by `delta`); the
    /// neighbour list is rebuilt if the move needs it.
    fn displace(&mut self, members: &[u32], delta: DVec3) -> Result<(), RunError> {
        for &i in members {
            let i = i as usize;
            self.state.positions[i] += delta;
            self.sim_box.wrap(&mut self.state.positions[i], &mut self.state.images[i]);
        }
        self.check_in_box()?;
        if let Some(backend) = self.backend.as_mut() {
            backend.update_neighbors(&self.state, &self.sim_box, true).map_err(RunError::Setup)?;
        }
        self.forces_current = false;
        Ok(())
    }

    fn topology_view(&self) -> TopologyView<'_> {
        TopologyView {
            units: self.model.units,
            ids: &self.model.ids,
            types: &self.model.types,
            type_names: &self.model.type_names,
            type_radius: &self.model.type_radius,
            bonds: &self.model.bonds,
            angles: &self.model.angles,
            triangles: &self.model.triangles,
            bond_types: &self.model.bond_type,
            bond_type_names: &self.bond_type_names,
        }
    }

    /// The restart of the current state: with the counters, the deck and
    /// where the run stands in it.
    fn restart_data(&self) -> RestartData {
        let mut data = RestartData::from_state(self.model.units, &self.state, &self.sim_box, &self.model.ids);
        data.counters = Counters {
            breaks: self.kinetics.breaks,
            rebinds: self.kinetics.rebinds,
            forms: self.kinetics.forms,
            resets: self.kinetics.resets,
            contact_clamps: self.contact_clamps,
        };
        data.resume = Some(Resume { inputs: self.inputs.clone(), action: self.action, run_end: self.run_end });
        data
    }

    /// A periodic checkpoint when one is due at this step.
    fn checkpoint(&mut self) -> Result<(), RunError> {
        let step = self.state.step;
        let Some(due) = self.checkpoints.as_ref().filter(|c| step.is_multiple_of(c.spec.every) && c.last_step != Some(step)) else {
            return Ok(());
        };
        let path = self.output_path(&with_step(&due.spec.path, step));
        write_state(&path, &self.restart_data()).map_err(|e| self.output_error(&path, e))?;
        let checkpoints = self.checkpoints.as_mut().expect("due above");
        checkpoints.last_step = Some(step);
        let mut stale = Vec::new();
        if let Some(keep) = checkpoints.spec.keep {
            checkpoints.written.push_back(path);
            while checkpoints.written.len() > keep {
                stale.extend(checkpoints.written.pop_front());
            }
        }
        for old in stale {
            std::fs::remove_file(&old).map_err(|e| self.output_error(&old, e))?;
        }
        Ok(())
    }

    fn load_restart(&mut self, data: RestartData, path: &Path) -> Result<(), RunError> {
        data.check_ids(&self.model.ids).map_err(|e| RunError::Setup(format!("{}: {e}", path.display())))?;
        if data.units != self.model.units {
            return Err(RunError::Setup(format!(
                "{}: the restart was written in {:?} units, the deck uses {:?}",
                path.display(),
                data.units,
                self.model.units
            )));
        }
        let counters = data.counters;
        self.kinetics.breaks = counters.breaks;
        self.kinetics.rebinds = counters.rebinds;
        self.kinetics.forms = counters.forms;
        self.kinetics.resets = counters.resets;
        self.contact_clamps = counters.contact_clamps;
        self.sim_box = data.sim_box;
        if self.formation.is_some() {
            self.formation = Some(Formation::new(&self.model, &self.sim_box));
        }
        self.state = data.to_state();
        match &self.state.bonds {
            Some(bonds) => self.model.set_formed_bonds(&bonds.formed),
            None => self.state.bonds = initial_bond_state(&self.model),
        }
        self.backend = None;
        self.forces_current = false;
        self.check_in_box()
    }

    /// Stops the run, as a blow-up (step, particle id, last good frame), if a
    /// particle left a fixed box or cannot be wrapped into a periodic one:
    /// LAMMPS' "Lost atoms". Checked after every CPU step and at every GPU
    /// read-back.
    fn check_in_box(&mut self) -> Result<(), RunError> {
        let sim_box = self.sim_box;
        let lost = self.state.positions.par_iter().with_min_len(4096).position_first(|&x| sim_box.misplaced_axis(x).is_some());
        match lost {
            Some(i) => {
                let x = self.state.positions[i];
                let axis = sim_box.misplaced_axis(x).expect("found above");
                Err(self.blowup(i, format!("lost: {} (LAMMPS: lost atoms)", sim_box.misplacement(x, axis))))
            }
            None => Ok(()),
        }
    }

    /// The smallest node–face distance between different bodies at the last
    /// force evaluation (∞ without `contact` lines or before the first one).
    pub fn min_contact_distance(&self) -> f64 {
        self.backend.as_ref().map_or(f64::INFINITY, |b| b.min_contact_distance())
    }

    /// Forces, energies by interaction and virial at the current state
    /// (computed now if stale).
    pub fn current_forces(&mut self) -> Result<&Forces, RunError> {
        self.ensure_forces()?;
        Ok(&self.forces)
    }

    /// What thermo columns read, at the current state (backend built).
    fn thermo_inputs(&self) -> ThermoInputs<'_> {
        let (bond_tension, _) = self.backend.as_ref().expect("backend built").bond_tension_and_length();
        ThermoInputs {
            model: &self.model,
            bonds: self.state.bonds.as_ref(),
            bond_tension,
            kinetics: &self.kinetics,
            step: self.state.step,
            time: self.state.time,
            forces: &self.forces,
            n_particles: self.model.len(),
            kt: self.kt,
            volume: self.sim_box.volume(),
            neighbor_builds: self.backend.as_ref().map_or(0, |b| b.neighbor_builds()),
            solve: self.last_solve,
            constraints: &self.constraints,
            positions: &self.state.positions,
            images: self.sim_box.images(),
            backend: self.backend.as_ref().expect("backend built"),
            state: &self.state,
            sim_box: &self.sim_box,
            min_contact_distance: self.min_contact_distance(),
            contact_clamps: self.contact_clamps,
        }
    }

    /// The value of a thermo column at the current state (forces, energies
    /// and virial computed now if stale), as a thermo row would print it.
    pub fn thermo_value(&mut self, column: &ThermoColumn) -> Result<f64, RunError> {
        self.ensure_forces()?;
        Ok(column_value(column, &self.thermo_inputs()))
    }

    /// The per-particle virial W_i at the current state (see [`crate::measure::stress`]).
    pub fn particle_virial(&mut self) -> Result<Vec<[f64; 6]>, RunError> {
        self.ensure_forces()?;
        Ok(crate::measure::per_particle_virial(self.backend.as_ref().expect("backend built"), &self.model, &self.state, &self.sim_box))
    }

    /// Tension (dE/dr, positive when stretched) and length of every bond at the current state.
    pub fn bond_tensions(&mut self) -> Result<(Vec<f64>, Vec<f64>), RunError> {
        self.ensure_forces()?;
        Ok(self.backend.as_ref().expect("backend built").bond_tensions_at(&self.model, &self.state, &self.sim_box))
    }

    /// Ensures a backend with a fresh neighbour list and forces at the current state.
    fn ensure_forces(&mut self) -> Result<(), RunError> {
        if self.backend.is_none() {
            let backend = CpuBackend::new(&self.model, &self.state, &self.sim_box, self.neighbor.skin).map_err(RunError::Setup)?;
            self.backend = Some(backend);
            self.forces_current = false;
        }
        if !self.forces_current || !self.energies_current {
            self.compute_forces(true)?;
        }
        Ok(())
    }

    /// Forces at the current state, with energies and virial if `energies`.
    fn compute_forces(&mut self, energies: bool) -> Result<(), RunError> {
        let backend = self.backend.as_mut().expect("backend built");
        backend.update_contacts(&self.model, &self.state, &self.sim_box).map_err(RunError::Setup)?;
        if energies {
            backend.compute(&self.model, &self.state, &self.sim_box, &mut self.forces);
        } else {
            backend.compute_forces(&self.model, &self.state, &self.sim_box, &mut self.forces);
        }
        self.forces_current = true;
        self.energies_current = energies;
        if let Some(i) = self.forces.forces.par_iter().with_min_len(4096).position_first(|f| !finite_force(*f)) {
            return Err(self.blowup(i, "non-finite force".into()));
        }
        Ok(())
    }

    /// Builds the blow-up report and writes the last good frame.
    fn blowup(&mut self, particle: usize, what: String) -> RunError {
        let parts = match &self.backend {
            Some(b) => b.breakdown(&self.model, &self.state, &self.sim_box, particle),
            None => Vec::new(),
        };
        let mut last_good = Vec::new();
        let step = self.state.step;
        for i in 0..self.dumps.len() {
            if self.dumps[i].last_step != Some(step) && self.write_dump(i).is_ok() {
                last_good.push(self.dumps[i].path.display().to_string());
            }
        }
        let restart = self.output_path(Path::new(&format!("{}.lastgood.restart", self.deck_stem)));
        if write_state(&restart, &self.restart_data()).is_ok() {
            last_good.push(restart.display().to_string());
        }
        RunError::Blowup { step, particle_id: self.model.ids[particle], what, culprit: culprit(parts), last_good }
    }

    fn write_dump(&mut self, i: usize) -> Result<(), RunError> {
        let needs = self.dumps[i].writer.needs();
        let (mut virial, mut tension, mut length) = (Vec::new(), Vec::new(), Vec::new());
        if needs.any() {
            // Measurements read the CPU backend's terms at these positions.
            if self.backend.is_none() {
                self.ensure_forces()?;
            } else if !self.forces_current {
                self.refresh_cpu_forces(false)?;
            }
            let backend = self.backend.as_ref().expect("backend built");
            if needs.virial {
                virial = crate::measure::per_particle_virial(backend, &self.model, &self.state, &self.sim_box);
            }
            if needs.bonds {
                (tension, length) = backend.bond_tensions_at(&self.model, &self.state, &self.sim_box);
            }
        }
        let forces: &[DVec3] = if needs.forces { &self.forces.forces } else { &[] };
        let walls: Vec<WallPlane> = (self.model.externals.iter())
            .filter(|e| e.term.interaction.name() == "wall")
            .filter_map(|e| crate::interactions::wall_plane(&e.term.params))
            .map(|(normal, offset)| WallPlane { normal, offset })
            .collect();
        let frame = FrameView {
            step: self.state.step,
            time: self.state.time,
            sim_box: &self.sim_box,
            positions: &self.state.positions,
            images: &self.state.images,
            measures: Measures { forces, virial: &virial, bond_tension: &tension, bond_length: &length },
            bound: self.state.bonds.as_ref().map_or(&[], |b| &b.bound),
            walls: &walls,
        };
        if let Err(e) = self.dumps[i].writer.write_frame(&frame) {
            return Err(self.output_error(&self.dumps[i].path, e));
        }
        self.dumps[i].last_step = Some(self.state.step);
        Ok(())
    }

    fn outputs_at_step(&mut self, bar: &Option<ProgressBar>, force_thermo: bool) -> Result<(), RunError> {
        let step = self.state.step;
        for i in 0..self.dumps.len() {
            if step.is_multiple_of(self.dumps[i].spec.every) && self.dumps[i].last_step != Some(step) {
                self.write_dump(i)?;
            }
        }
        let due = self.thermo.every > 0 && step.is_multiple_of(self.thermo.every);
        if due || force_thermo {
            let values = self.thermo.values(&self.thermo_inputs());
            let line = self.thermo.row(&values).map_err(|(path, e)| self.output_error(&path, e))?;
            match bar {
                Some(bar) => bar.println(line),
                None => self.say(&line),
            }
        }
        self.checkpoint()
    }

    /// The lifetime table, rewritten after every `run` (and when stopped).
    fn write_lifetimes(&self) -> Result<(), RunError> {
        match &self.lifetime_file {
            Some(path) => self.lifetimes.write(path, &self.model, self.state.bonds.as_ref()).map_err(|e| self.output_error(path, e)),
            None => Ok(()),
        }
    }

    /// `run N`: N overdamped steps, on the CPU backend or the GPU.
    pub fn run(&mut self, steps: u64) -> Result<(), RunError> {
        let run = self.begin_run(steps)?;
        self.advance(&run, run.last)?;
        self.end_run(run)
    }

    /// The start of a `run N`: checks, forces, the backend, the thermo
    /// header and the outputs of the first step.
    pub fn begin_run(&mut self, steps: u64) -> Result<ActiveRun, RunError> {
        self.check_kinetics_temperature()?;
        self.protocols.begin_run(self.state.step, self.state.step + steps);
        if self.protocols.set_ramps(&mut self.model, self.state.step) {
            self.forces_current = false;
        }
        self.ensure_forces()?;
        self.protocols.check_drives(&self.model, &self.state, &self.sim_box);
        let gpu = self.gpu_for_run()?;
        let bar = (self.options.progress && steps >= 1000).then(|| {
            let bar = ProgressBar::new(steps);
            bar.set_style(ProgressStyle::with_template("{bar:40} {pos}/{len} steps  {per_sec}  ETA {eta}").expect("valid template"));
            bar
        });
        let header = self.thermo.header();
        match &bar {
            Some(b) => b.println(header),
            None => self.say(&header),
        }
        let last = self.state.step + steps;
        self.run_end = Some(last);
        self.log_run(steps, if gpu.is_some() { "the GPU" } else { "the CPU" })?;
        self.outputs_at_step(&bar, true)?;
        Ok(ActiveRun { steps, last, gpu, bar, started: std::time::Instant::now() })
    }

    /// Steps of `run` up to step `until` (at most the run's last): on the
    /// CPU the same steps, bit for bit, however the run is cut into
    /// segments; forces are recomputed first if the system changed since.
    pub fn advance(&mut self, run: &ActiveRun, until: u64) -> Result<(), RunError> {
        let until = until.min(run.last);
        if self.backend.is_none() || !self.forces_current {
            self.ensure_forces()?;
        }
        let started = std::time::Instant::now();
        let looped = match &run.gpu {
            Some(context) => self.run_gpu(context, until, run.last, &run.bar),
            None => self.run_cpu(until, run.last, &run.bar),
        };
        self.times.total += started.elapsed();
        looped
    }

    /// The end of a run: writes the lifetime table and reports the loop time.
    pub fn end_run(&mut self, run: ActiveRun) -> Result<(), RunError> {
        if let Some(b) = run.bar {
            b.finish_and_clear();
        }
        self.run_end = None;
        self.protocols.end_run();
        self.write_lifetimes()?;
        let seconds = run.started.elapsed().as_secs_f64();
        self.say(&format!(
            "loop time {seconds:.6} s for {} steps with {} particles: {:.6e} particle-steps/s",
            run.steps,
            self.model.len(),
            (run.steps as f64 * self.model.len() as f64) / seconds
        ));
        Ok(())
    }

    /// CPU steps up to `until` of a run that ends at `last`.
    fn run_cpu(&mut self, until: u64, last: u64, bar: &Option<ProgressBar>) -> Result<(), RunError> {
        let mut before = Vec::new();
        while self.state.step < until {
            self.stop_if_requested()?;
            let mut clock = self.times.clock();
            let (step, start) = (self.state.step, self.state.time);
            if !self.constraints.list.is_empty() {
                before.clone_from(&self.state.positions);
            }
            self.protocols.before_step(&mut self.forces.forces, &self.state);
            let moved = match self.integrator {
                Integrator::Implicit(_, implicit) => self.implicit_step(&implicit)?,
                Integrator::Overdamped(_) => {
                    let n = self.model.len();
                    let limited = self.backend.as_ref().is_some_and(|b| b.contact_step_limits(n, &mut self.step_limits));
                    overdamped_step(
                        &self.model,
                        &mut self.state,
                        &self.forces.forces,
                        &self.sim_box,
                        self.dt,
                        self.kt,
                        self.seed,
                        self.integrator.common(),
                        limited.then_some(self.step_limits.as_slice()),
                        &mut self.scratch,
                    )
                    .inspect(|&fraction| self.contact_clamps += u64::from(fraction < 1.0))
                }
            };
            self.protocols.restore_forces(&mut self.forces.forces);
            let fraction = match moved {
                Ok(fraction) => fraction,
                Err(Blowup { particle, displacement }) => return Err(self.blowup(particle, self.displacement_message(displacement))),
            };
            if !self.constraints.list.is_empty() {
                let projected = self.constraints.project(&self.model, &before, &mut self.state, &self.sim_box, self.dt);
                if self.implicit_tension.len() == self.constraints.tension.len() {
                    self.constraints.tension.iter_mut().zip(&self.implicit_tension).for_each(|(t, extra)| *t += extra);
                }
                if let Err(failure) = projected {
                    let [i, j] = self.model.bonds[failure.bond];
                    return Err(RunError::Setup(format!(
                        "constraint of bond {}-{} not met after {} sweeps at step {}: |r − r0|/r0 = {:e} > tolerance {:e}",
                        self.model.ids[i as usize],
                        self.model.ids[j as usize],
                        self.constraints.max_iterations,
                        self.state.step,
                        failure.relative_error,
                        self.constraints.tolerance
                    )));
                }
            }
            self.protocols.after_step(&mut self.state, &self.sim_box, self.dt);
            clock.lap(&mut self.times, Phase::Integrate);
            self.check_in_box()?;
            if self.model.has_kinetics() {
                self.kinetics_step(StepClock { step, start, length: fraction * self.dt })?;
                clock.lap(&mut self.times, Phase::Kinetics);
            }
            self.protocols.advance_drives(&mut self.model, self.dt);
            self.protocols.set_ramps(&mut self.model, self.state.step);
            let final_step = self.state.step == last;
            let thermo_due = self.thermo.every > 0 && self.state.step.is_multiple_of(self.thermo.every);
            match self.backend.as_mut() {
                Some(backend) => {
                    if self.state.step.is_multiple_of(self.neighbor.every) {
                        backend.update_neighbors(&self.state, &self.sim_box, self.neighbor.check).map_err(RunError::Setup)?;
                        clock.lap(&mut self.times, Phase::Neighbor);
                    }
                    self.compute_forces(thermo_due || final_step)?;
                }
                // Bonds formed: the backend is rebuilt for the new bond list.
                None => self.ensure_forces()?,
            }
            self.protocols.check_drives(&self.model, &self.state, &self.sim_box);
            clock.lap(&mut self.times, Phase::Force);
            self.outputs_at_step(bar, final_step && !thermo_due)?;
            clock.lap(&mut self.times, Phase::Output);
            if let Some(b) = bar {
                b.inc(1);
            }
        }
        Ok(())
    }

    /// One linearly implicit step from the current forces; a failed solve
    /// stops the run, a refused displacement is returned like the explicit one.
    /// One implicit step; returns the fraction of dt it took (below 1 where
    /// the contact clamp shortened it).
    fn implicit_step(&mut self, implicit: &ImplicitSettings) -> Result<Result<f64, Blowup>, RunError> {
        let backend = self.backend.as_ref().expect("backend built");
        let stiffness = backend.stiffness(&self.model, &self.state, &self.sim_box);
        let limited = backend.contact_step_limits(self.model.len(), &mut self.step_limits);
        let (model, forces, sim_box) = (&self.model, &self.forces.forces, &self.sim_box);
        let mut constrained =
            ConstrainedBonds { pairs: self.constraints.list.iter().map(|c| model.bonds[c.bond]).collect(), tension: Vec::new() };
        let outcome = implicit_step(
            model,
            &mut self.state,
            forces,
            &stiffness,
            sim_box,
            self.dt,
            self.kt,
            self.seed,
            self.integrator.common(),
            implicit,
            &mut constrained,
            limited.then_some(self.step_limits.as_slice()),
        );
        self.implicit_tension = constrained.tension;
        match outcome {
            Ok(report) => {
                let fraction = report.step_fraction;
                self.contact_clamps += u64::from(fraction < 1.0);
                self.last_solve = report;
                Ok(Ok(fraction))
            }
            Err(ImplicitError::Blowup(blowup)) => Ok(Err(blowup)),
            Err(ImplicitError::Solve(why)) => Err(RunError::Setup(format!("integrator implicit at step {}: {why}", self.state.step))),
        }
    }

    fn displacement_message(&self, displacement: f64) -> String {
        format!("displacement {displacement:e} in one step exceeds max_displacement {:e}", self.integrator.common().max_displacement)
    }

    /// Why the next `run` cannot use the GPU backend: the first feature in
    /// use that only the CPU backend has (None when the GPU can run it).
    pub fn cpu_only_feature(&self) -> Option<&'static str> {
        if let Some(why) = self.protocols.cpu_only() {
            Some(why)
        } else if matches!(self.integrator, Integrator::Implicit(..)) {
            Some("`integrator implicit` runs on the CPU backend only")
        } else if !self.constraints.list.is_empty() {
            Some("constrained bonds (`constrain`) run on the CPU backend only")
        } else if self.model.has_surface_terms() {
            Some("surface terms of bodies (`body` lines) run on the CPU backend only")
        } else if self.model.has_contact_terms() {
            Some("contact terms between bodies (`contact` lines) run on the CPU backend only")
        } else if self.model.special_bonds.is_fractional() && !self.model.pair_rules.is_empty() {
            Some("fractional `special_bonds` weights run on the CPU backend only")
        } else if self.model.externals.iter().any(|e| !e.expressions.is_empty()) {
            Some("externals with expression parameters (`field`, or a quoted formula of x, y, z, t) run on the CPU backend only")
        } else {
            None
        }
    }

    /// The GPU to run on, per the effective `device` setting (None: the CPU).
    /// The adapter is opened once and announced.
    fn gpu_for_run(&mut self) -> Result<Option<GpuContext>, RunError> {
        let device = self.options.device.unwrap_or(self.device);
        if device == DevicePreference::Cpu {
            return Ok(None);
        }
        if let Some(why) = self.cpu_only_feature() {
            return match device {
                DevicePreference::Gpu => Err(RunError::Setup(format!("device gpu: {why}; use `device cpu` or `device auto`"))),
                _ => {
                    self.say(&format!("device auto: {why}; running on the CPU"));
                    Ok(None)
                }
            };
        }
        if self.gpu.is_none() {
            let opened = GpuContext::open(device == DevicePreference::Auto);
            match &opened {
                Ok(context) => self.say(&format!("device: GPU {}", context.describe())),
                Err(e) if device == DevicePreference::Auto => self.say(&format!("device auto: {e}; running on the CPU")),
                Err(_) => {}
            }
            self.gpu = Some(opened);
        }
        match self.gpu.as_ref().expect("opened above") {
            Ok(context) => Ok(Some(context.clone())),
            Err(_) if device == DevicePreference::Auto => Ok(None),
            Err(e) => Err(RunError::Setup(format!("device gpu: {e}"))),
        }
    }

    /// The steps up to `last` on the GPU. The host synchronises where an
    /// output is due (thermo, dump, the end) and at least every
    /// [`GPU_SYNC_STEPS`] steps (progress, blow-up checks), reading back the
    /// positions only where an output needs them; thermo quantities are then
    /// computed by the CPU backend at the read-back positions. With bond
    /// kinetics the host synchronises every step: it reads the positions back,
    /// measures every bond's tension and length in f64, decides the step's
    /// events exactly as on the CPU, and uploads the changed bond state as one
    /// batch (a new GPU backend when bonds formed). A segment that ends at
    /// `until` before `last` reads the positions back and leaves the CPU
    /// forces current there.
    fn run_gpu(&mut self, context: &GpuContext, until: u64, last: u64, bar: &Option<ProgressBar>) -> Result<(), RunError> {
        let settings = StepSettings {
            dt: self.dt,
            kt: self.kt,
            seed: self.seed,
            skin: self.neighbor.skin,
            neighbor_every: self.neighbor.every,
            neighbor_check: self.neighbor.check,
            integrator: *self.integrator.common(),
        };
        let mut gpu = GpuBackend::new(context, &self.model, &self.state, &self.sim_box, &settings).map_err(RunError::Setup)?;
        let kinetics = self.model.has_kinetics();
        let evolving = self.model.bond_kinetics.iter().flat_map(|k| &k.rules).any(|r| r.rule.evolves_every_step());
        while self.state.step < until {
            let (step, start) = (self.state.step, self.state.time);
            let next_output = self.next_output_step(last).min(self.state.step + GPU_SYNC_STEPS).min(until);
            let steps = if kinetics { 1 } else { next_output - self.state.step };
            let outcome = gpu.run(self.state.step, steps);
            let done = match &outcome {
                Ok(done) => *done,
                Err(GpuHalt::Blowup { step, .. } | GpuHalt::Capacity { step, .. }) => step - self.state.step,
            };
            for _ in 0..done {
                self.state.step += 1;
                self.state.time += self.dt;
            }
            self.forces_current = false;
            let final_step = self.state.step == last;
            let segment_end = self.state.step == until;
            let thermo_due = self.thermo.every > 0 && self.state.step.is_multiple_of(self.thermo.every);
            let dump_due = self.dumps.iter().any(|d| self.state.step.is_multiple_of(d.spec.every));
            // Positions come back only when something reads them; between
            // outputs the sync only reads the GPU's status words.
            let checkpoint_due = self.checkpoints.as_ref().is_some_and(|c| self.state.step.is_multiple_of(c.spec.every));
            let stopping = self.options.stop.requested().is_some();
            let read_back = segment_end || thermo_due || dump_due || checkpoint_due || stopping || outcome.is_err() || kinetics;
            if read_back {
                gpu.download(&mut self.state);
            }
            if let Err(GpuHalt::Capacity { message, .. }) = outcome {
                return Err(RunError::Setup(format!("device gpu at step {}: {message}", self.state.step)));
            }
            if let Err(GpuHalt::Blowup { particle, .. }) = outcome {
                self.refresh_cpu_forces(false)?;
                let what = format!(
                    "its GPU step was non-finite or longer than max_displacement {:e} (force here {:e})",
                    self.integrator.common().max_displacement,
                    self.forces.forces[particle].length()
                );
                return Err(self.blowup(particle, what));
            }
            if read_back {
                self.check_in_box()?;
            }
            if kinetics {
                // As on the CPU: decided from the tensions before the step
                // (measured at the end of the previous one), then measured
                // again at the new positions with the new bond state.
                let resets = self.kinetics.resets;
                // One step per segment with kinetics, never clamped on the GPU.
                let changed = self.kinetics_step(StepClock { step, start, length: self.dt })?;
                if self.backend.is_none() {
                    // Bonds formed: both backends are rebuilt for the new bond list.
                    self.ensure_forces()?;
                    gpu = GpuBackend::new(context, &self.model, &self.state, &self.sim_box, &settings).map_err(RunError::Setup)?;
                } else if changed || evolving || self.kinetics.resets != resets {
                    gpu.update_bonds(&self.model, &self.state, changed).map_err(RunError::Setup)?;
                }
                let backend = self.backend.as_mut().expect("backend built");
                backend.measure_bonds(&self.model, &self.state, &self.sim_box);
            }
            if thermo_due || segment_end {
                self.refresh_cpu_forces(thermo_due || final_step)?;
            }
            self.outputs_at_step(bar, final_step && !thermo_due)?;
            if let Some(b) = bar {
                b.inc(done);
            }
            if stopping {
                // The positions of this sync were read back above.
                self.stop_if_requested()?;
            }
        }
        Ok(())
    }

    /// The first step after the current one at which thermo or a dump is due (or `last`).
    fn next_output_step(&self, last: u64) -> u64 {
        let after = |every: u64| (self.state.step / every + 1) * every;
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

    /// CPU forces (and energies) at the current state, after a GPU segment.
    fn refresh_cpu_forces(&mut self, energies: bool) -> Result<(), RunError> {
        let backend = self.backend.as_mut().expect("backend built");
        backend.update_neighbors(&self.state, &self.sim_box, true).map_err(RunError::Setup)?;
        self.compute_forces(energies)
    }

    /// Bond kinetics of the step just integrated, decided from the tensions of
    /// its force pass; a break or rebind updates the pair exclusions.
    /// Returns whether a bond broke, bound or formed.
    fn kinetics_step(&mut self, clock: StepClock) -> Result<bool, RunError> {
        let backend = self.backend.as_ref().expect("backend built");
        let (tension, length) = backend.bond_tension_and_length();
        let mut report = self.kinetics.step(&self.model, &mut self.state, tension, length, clock, self.kt, self.seed);
        for warning in &report.warnings {
            eprintln!("{warning}");
        }
        let mut formed_any = false;
        if let Some(formation) = &mut self.formation {
            let bindings = formation.decide(&self.model, &self.state, &self.sim_box, clock, self.seed).map_err(RunError::Setup)?;
            formed_any = bindings.iter().any(|b| matches!(b, Binding::New(..)));
            report.bonds_changed |= !bindings.is_empty();
            report.events.extend(self.kinetics.apply_bindings(&mut self.model, &mut self.state, &self.sim_box, bindings, clock));
        }
        if !report.events.is_empty() {
            self.lifetimes.record(&self.model, &report.events, clock.length);
            if let Some((log, path)) = &mut self.event_log {
                if let Err(e) = log.write(&report.events) {
                    let path = path.clone();
                    return Err(self.output_error(&path, e));
                }
            }
            let bound = &self.state.bonds.as_ref().expect("kinetics has bond state").bound;
            let failed =
                self.dumps.iter_mut().find_map(|d| d.writer.write_bond_events(&report.events, bound).err().map(|e| (d.path.clone(), e)));
            if let Some((path, e)) = failed {
                return Err(self.output_error(&path, e));
            }
        }
        if formed_any {
            // New bonds change every per-bond buffer: rebuild the backend.
            self.backend = None;
        } else if report.bonds_changed {
            let backend = self.backend.as_mut().expect("backend built");
            backend.bonds_changed(&self.model, &self.state, &self.sim_box).map_err(RunError::Setup)?;
        }
        Ok(report.bonds_changed)
    }

    /// Rules whose rates depend on kT refuse to run at T = 0.
    fn check_kinetics_temperature(&self) -> Result<(), RunError> {
        if self.kt > 0.0 {
            return Ok(());
        }
        for (t, kinetics) in self.model.bond_kinetics.iter().enumerate() {
            if let Some(rule) = kinetics.rules.iter().find(|r| r.rule.needs_temperature()) {
                return Err(RunError::Setup(format!(
                    "bond type `{}`: kinetic rule `{}` has rates that depend on kT; expected a `temperature` > 0",
                    self.model.bond_types[t].label.text,
                    rule.rule.name()
                )));
            }
        }
        Ok(())
    }

    /// `minimize`: FIRE to max |F| < ftol. The step counter does not advance.
    pub fn minimize(&mut self, settings: &FireSettings) -> Result<(), RunError> {
        self.ensure_forces()?;
        let mass: Vec<f64> = self.model.types.iter().map(|&t| self.model.type_drag[t as usize] * self.dt).collect();
        let mut state = self.state.clone();
        let backend = self.backend.as_mut().expect("backend built");
        let (model, sim_box, forces, protocols) = (&self.model, &self.sim_box, &mut self.forces, &self.protocols);
        let report = fire_minimize(&mut state, sim_box, &mass, self.dt, settings, |s, f, limits| {
            backend.update_neighbors(s, sim_box, true).map_err(RunError::Setup)?;
            backend.update_contacts(model, s, sim_box).map_err(RunError::Setup)?;
            backend.compute(model, s, sim_box, forces);
            backend.contact_step_limits(s.len(), limits);
            f.clone_from(&forces.forces);
            protocols.mask(f);
            Ok::<f64, RunError>(forces.total_energy())
        })?;
        self.state = state;
        self.forces_current = true;
        self.energies_current = true;
        if let Some(i) = self.forces.forces.iter().position(|f| !finite_force(*f)) {
            return Err(self.blowup(i, "non-finite force during minimisation".into()));
        }
        self.check_in_box()?;
        let verdict = if report.converged { "converged" } else { "stopped at maxiter without converging" };
        self.say(&format!(
            "minimize (FIRE): {verdict} after {} iterations: max |F| = {:e} (ftol {:e}), pe = {:e}{}",
            report.iterations,
            report.max_force,
            settings.ftol,
            report.energy,
            if report.clamped > 0 { format!(", {} moves shortened by the contact step clamp", report.clamped) } else { String::new() }
        ));
        self.contact_clamps += report.clamped;
        self.last_minimize = Some(report);
        Ok(())
    }

    /// Finishes every output file (called at the end and on errors).
    pub fn close_outputs(&mut self) -> Result<(), RunError> {
        let mut first_error = None;
        for dump in std::mem::take(&mut self.dumps) {
            if let Err(e) = dump.writer.finish() {
                first_error.get_or_insert(self.output_error(&dump.path, e));
            }
        }
        if let Err((path, e)) = self.thermo.close() {
            first_error.get_or_insert(self.output_error(&path, e));
        }
        if let Some((log, path)) = self.event_log.take() {
            if let Err(e) = log.finish() {
                first_error.get_or_insert(self.output_error(&path, e));
            }
        }
        first_error.map_or(Ok(()), Err)
    }
}

/// Whether a force and its squared magnitude are finite: `turgor dp0 1e308`
/// gave finite components whose |F| overflowed, and every later step was
/// clamped to nothing instead of stopping.
fn finite_force(f: DVec3) -> bool {
    f.length_squared().is_finite()
}
