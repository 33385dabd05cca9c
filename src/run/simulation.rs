//! A live simulation: the actions of a plan applied to a system.
//!
//! [`Simulation`] orchestrates; its state is the system (model, state,
//! box), the constraints, the protocols and the sub-states of `parts`
//! (settings, backends, kinetics, reports, outputs, deck progress), and
//! each responsibility has its own file:
//! `step_loop` (the one loop of a `run` over a `Stepper`), `cpu_steps` and
//! `gpu_steps` (the two steppers), `reference` (the CPU backend as the
//! reference for forces, thermo and measurements), `outputs`, `restarts`
//! (checkpoints, stops, blow-ups) and `stepping` (driving a run from outside
//! a deck).

use std::collections::HashMap;
use std::path::{Path, PathBuf};

use glam::DVec3;

use super::blowup::RunError;
use super::protocol::{reset_rest, Protocols};
use super::stop::StopSignal;
use super::thermo::Thermo;
use crate::deck::{Action, CoeffTarget, Plan, Protocol};
use crate::gpu::DevicePreference;
use crate::input::DeckInputs;
use crate::integrate::constraints::{Constraint, Constraints};
use crate::kinetics_engine::{initial_bond_state, Formation};
use crate::output::open_writer;
use crate::output::restart::{read_state, write_state, RestartData};
use crate::output::run_log::LogHeader;
use crate::output::EventLog;
use crate::system::{Model, SimBox, State};

mod cpu_steps;
mod gpu_steps;
mod outputs;
mod parts;
mod reference;
mod restarts;
mod step_loop;
mod stepping;

use self::outputs::ActiveDump;
pub use self::parts::{Backends, KineticsState, Reports, Settings};
use self::parts::{DeckProgress, Outputs};
use self::restarts::{with_step, Checkpoints};
pub use self::stepping::{ActiveRun, BondTable};

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

impl RunOptions {
    /// Prints `message` on stdout when the options echo (a closed stdout requests a stop).
    fn say(&self, message: &str) {
        if self.echo {
            self.stop.say(message);
        }
    }

    /// `path` resolved against the output directory.
    fn output_path(&self, path: &Path) -> PathBuf {
        if path.is_absolute() {
            path.to_path_buf()
        } else {
            self.output_dir.join(path)
        }
    }
}

/// A live simulation: the system (model, state, box) and the sub-states of
/// the run that steps it (src/run/simulation/parts.rs).
pub struct Simulation {
    pub model: Model,
    pub state: State,
    pub sim_box: SimBox,
    /// The deck's settings in force.
    pub settings: Settings,
    /// Constrained (inextensible) bonds.
    pub constraints: Constraints,
    /// Ramps, moved and frozen groups in force.
    protocols: Protocols,
    /// Bond kinetics: event counts and bond formation.
    pub kinetics: KineticsState,
    /// The backends and the forces they computed.
    pub backend: Backends,
    /// Counters and the last solves of the run.
    pub reports: Reports,
    outputs: Outputs,
    /// Where the run stands in its deck.
    deck: DeckProgress,
    options: RunOptions,
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
            kinetics: KineticsState {
                formation: (!model.bind_rules.is_empty()).then(|| Formation::new(&model, &sim_box)),
                ..KineticsState::default()
            },
            outputs: Outputs::new(Thermo::new(&model), model.bond_types.iter().map(|t| t.label.text.clone()).collect(), deck_stem),
            model,
            state,
            sim_box,
            settings: Settings::default(),
            constraints: Constraints::default(),
            protocols: Protocols::default(),
            backend: Backends::default(),
            reports: Reports::default(),
            deck: DeckProgress { inputs, action: 0, run_end: None, decisions: HashMap::new() },
            options,
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
        Simulation::check_restart(&plan, &data, restart).map_err(RunError::Setup)?;
        let resume = data.resume.clone().expect("check_restart requires one");
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
                sim.deck.action = k;
                sim.apply(action)?;
            }
            sim.load_restart(data, restart)?;
            sim.options.say(&format!("continuing {} from step {} ({})", sim.deck.inputs.deck, sim.state.step, restart.display()));
            let next = match resume.run_end {
                Some(end) if end > sim.state.step => {
                    sim.deck.action = resume.action;
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
            self.deck.action = next;
            self.stop_if_requested()?;
            next += 1 + match action {
                Action::Branch { condition, skip } => {
                    let mut last = self.deck.decisions.remove(condition.place()).unwrap_or_default();
                    let holds = condition.holds(&mut |c| self.thermo_value(c).map_err(|e| e.to_string()), &mut last);
                    self.deck.decisions.insert(condition.place().to_string(), last);
                    let holds = holds.map_err(RunError::Setup)?;
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
        if let Some(mut log) = self.outputs.log.take() {
            let outcome = match &result {
                Ok(()) => format!("finished at step {}", self.state.step),
                Err(e) => format!("ended at step {}: {e}", self.state.step),
            };
            let text = format!(
                "\n{outcome}\nloop time {:.3} s by section (CPU step loop):\n{}",
                self.reports.times.total.as_secs_f64(),
                self.reports.times.table()
            );
            if let Err(e) = log.section(&text) {
                closed = closed.and(Err(self.output_error(&log.path, e)));
            }
        }
        result?;
        closed?;
        Ok(self)
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

    /// Applies one action (jumps only make sense within their plan: see
    /// `perform`).
    pub fn apply(&mut self, action: &Action) -> Result<(), RunError> {
        match action {
            Action::Branch { .. } | Action::Skip(_) => {
                return Err(RunError::Setup("a jump of an `if` decided during the run is applied with its plan".into()))
            }
            Action::Temperature(kt) => self.settings.kt = *kt,
            Action::Timestep(dt) => self.settings.dt = *dt,
            Action::Seed(seed) => self.settings.seed = *seed,
            Action::Device(device) => self.settings.device = *device,
            Action::Integrator(settings) => self.settings.integrator = *settings,
            Action::Neighbor(settings) => {
                self.settings.neighbor = *settings;
                self.backend.cpu.invalidate();
            }
            Action::Thermo { every, columns } => {
                self.outputs.thermo.every = *every;
                self.outputs.thermo.set_columns(columns.clone(), &self.model);
            }
            Action::EventFile(path) => {
                let path = self.options.output_path(path);
                let file = self.create_output(&path)?;
                let log = EventLog::create(file, self.model.units).map_err(|e| self.output_error(&path, e))?;
                if let Some((old, old_path)) = self.outputs.event_log.replace((log, path)) {
                    old.finish().map_err(|e| self.output_error(&old_path, e))?;
                }
            }
            Action::LifetimeFile(path) => self.outputs.lifetime_file = Some(self.options.output_path(path)),
            Action::ThermoFile(path) => {
                let path = self.options.output_path(path);
                let file = self.create_output(&path)?;
                self.outputs.thermo.set_file(file, path).map_err(|(path, e)| self.output_error(&path, e))?;
            }
            Action::Dump(spec) => {
                let path = self.options.output_path(&spec.path);
                let file = self.create_output(&path)?;
                let writer =
                    open_writer(spec.format, file, &self.topology_view(), &spec.options).map_err(|e| self.output_error(&path, e))?;
                self.outputs.dumps.push(ActiveDump { spec: spec.clone(), path, writer, last_step: None });
            }
            Action::Undump(name) => {
                if let Some(k) = self.outputs.dumps.iter().position(|d| d.spec.name == *name) {
                    let dump = self.outputs.dumps.remove(k);
                    dump.writer.finish().map_err(|e| self.output_error(&dump.path, e))?;
                }
            }
            Action::External(external) => {
                self.model.externals.retain(|e| e.term.label.text != external.term.label.text);
                self.model.externals.push(external.clone());
                self.backend.forces_current = false;
            }
            Action::Unexternal(name) => {
                self.model.externals.retain(|e| e.term.label.text != *name);
                self.protocols.forget_drive(name);
                self.backend.forces_current = false;
            }
            Action::Displace { group, delta } => self.displace(&group.members, *delta)?,
            Action::Coeff { target, param, value } => {
                if let CoeffTarget::PairRule(_) = target {
                    self.backend.cpu.invalidate(); // the cutoff may change
                }
                target.set(&mut self.model, *param, *value);
                self.backend.forces_current = false;
            }
            Action::Protocol(Protocol::ResetRest(bond_types)) => {
                reset_rest(&mut self.model, &mut self.state, &self.sim_box, bond_types);
                self.backend.cpu.invalidate(); // bonds now carry state
                self.backend.forces_current = false;
            }
            Action::Protocol(protocol) => self.protocols.apply(protocol),
            Action::Constrain { bond_type, tolerance, max_iterations, reshape, method } => {
                self.constraints.list.retain(|c| self.model.bond_type[c.bond] as usize != *bond_type);
                // Each bond at its rest length now (its own, or the type's `r0`; the deck checked it has one).
                let bonds = (0..self.model.bonds.len()).filter(|&b| self.model.bond_type[b] as usize == *bond_type);
                let (model, state) = (&self.model, self.state.bonds.as_ref());
                self.constraints.list.extend(bonds.map(|bond| Constraint { bond, length: model.rest_length(bond, state) }));
                self.constraints.list.sort_by_key(|c| c.bond);
                self.constraints.tolerance = *tolerance;
                self.constraints.max_iterations = *max_iterations;
                self.constraints.method = *method;
                self.constraints.tension.clear();
                if *reshape {
                    self.reshape_to_constraints()?;
                }
            }
            Action::Unconstrain(bond_type) => {
                self.constraints.list.retain(|c| self.model.bond_type[c.bond] as usize != *bond_type);
                self.constraints.tension.clear();
            }
            Action::Minimize(settings) => self.minimize(settings)?,
            Action::Run(steps) => self.run(*steps)?,
            Action::WriteState(path) => {
                let path = self.options.output_path(&with_step(path, self.state.step));
                write_state(&self.options.output_dir, &path, &self.restart_data()).map_err(|e| self.output_error(&path, e))?;
                self.options.say(&format!("wrote state at step {} to {}", self.state.step, path.display()));
            }
            Action::Checkpoint(spec) => {
                self.outputs.checkpoints = Some(Checkpoints { spec: spec.clone(), last_step: None, written: Default::default() })
            }
            Action::ReadState(path) => {
                let path = if path.exists() { path.clone() } else { self.options.output_path(path) };
                let data = read_state(&path).map_err(RunError::Setup)?;
                self.load_restart(data, &path)?;
            }
            Action::Print(text) => self.options.say(text),
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
        if let Some(backend) = self.backend.cpu.built_mut() {
            backend.update_neighbors(&self.state, &self.sim_box, true).map_err(RunError::Setup)?;
        }
        self.backend.forces_current = false;
        Ok(())
    }
}
