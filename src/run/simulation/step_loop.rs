//! The step loop of a `run`: one loop over a [`Stepper`], the backend that
//! takes the steps — the CPU backend (`cpu_steps`, the reference for thermo
//! and measurements) or the GPU (`gpu_steps`).
//!
//! A stepper takes the steps up to the next point where the host must look
//! (one step on the CPU; on the GPU up to the next output, sync or bond
//! kinetics decision), ending each with the step context
//! ([`StepContext::advance`], the one place simulated time advances). The
//! loop does the rest once for both: bond kinetics of the step just taken
//! (decided on the host from the CPU backend's tensions), the outputs due,
//! progress and stop requests. What is resident where stays the stepper's
//! business: a GPU that keeps shells, contact, constraints, the implicit
//! step or bond kinetics on the device implements the same hooks.

use indicatif::{ProgressBar, ProgressStyle};

use super::cpu_steps::CpuSteps;
use super::gpu_steps::GpuSteps;
use super::stepping::ActiveRun;
use super::Simulation;
use crate::integrate::context::StepContext;
use crate::kinetics_engine::{Binding, Event};
use crate::run::RunError;
use crate::system::StepClock;

/// What a stepper's call took.
pub(super) struct Taken {
    /// Steps taken (each ended with [`StepContext::advance`]).
    pub(super) steps: u64,
    /// The clock of the last of them (None when none was taken).
    pub(super) last: Option<StepClock>,
}

/// A backend that takes the steps of a run (see the module docs).
pub(super) trait Stepper {
    /// Takes the steps from the current one up to the next point where the
    /// host must look, never beyond `until` (`last`: the run's last step),
    /// and leaves the positions the outputs due there read on the host.
    fn take(&mut self, sim: &mut Simulation, until: u64, last: u64) -> Result<Taken, RunError>;

    /// After bond kinetics of the step just taken (`changed`: a bond broke,
    /// bound or formed): the stepper's copy of the bonds follows.
    fn bonds_changed(&mut self, sim: &mut Simulation, changed: bool) -> Result<(), RunError>;

    /// Before the outputs of the step reached: the CPU forces the outputs
    /// read are brought to the new state (with energies where thermo is
    /// `due` or the run ends at `last`), and the next step is prepared.
    fn before_outputs(&mut self, sim: &mut Simulation, until: u64, last: u64, due: bool) -> Result<(), RunError>;

    /// After the outputs of the step reached: a requested stop is honoured
    /// where the stepper has the state to write.
    fn after_outputs(&mut self, sim: &mut Simulation) -> Result<(), RunError>;

    /// Whether the stepper decides bond kinetics itself (on the device) and
    /// records their events in `take`; otherwise the loop decides them on
    /// the host after every call.
    fn decides_kinetics(&self) -> bool {
        false
    }
}

impl Simulation {
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
        self.kinetics.host_formations = 0;
        self.protocols.begin_run(self.state.step, self.state.step + steps);
        if self.protocols.set_ramps(&mut self.model, self.state.step) {
            self.backend.forces_current = false;
        }
        self.ensure_forces()?;
        self.protocols.check_drives(&self.model, &self.state, &self.sim_box);
        let gpu = self.gpu_for_run()?;
        let bar = (self.options.progress && steps >= 1000).then(|| {
            let bar = ProgressBar::new(steps);
            bar.set_style(ProgressStyle::with_template("{bar:40} {pos}/{len} steps  {per_sec}  ETA {eta}").expect("valid template"));
            bar
        });
        let header = self.outputs.thermo.header();
        match &bar {
            Some(b) => b.println(header),
            None => self.options.say(&header),
        }
        let last = self.state.step + steps;
        self.deck.run_end = Some(last);
        self.log_run(steps, if gpu.is_some() { "the GPU" } else { "the CPU" })?;
        self.outputs_at_step(&bar, true)?;
        Ok(ActiveRun { steps, last, gpu, bar, started: std::time::Instant::now() })
    }

    /// Steps of `run` up to step `until` (at most the run's last): on the
    /// CPU the same steps, bit for bit, however the run is cut into
    /// segments; forces are recomputed first if the system changed since.
    pub fn advance(&mut self, run: &ActiveRun, until: u64) -> Result<(), RunError> {
        let until = until.min(run.last);
        if !self.backend.cpu.is_built() || !self.backend.forces_current {
            self.ensure_forces()?;
        }
        let started = std::time::Instant::now();
        let looped = match &run.gpu {
            Some(context) => GpuSteps::new(self, context).and_then(|mut gpu| self.step_loop(&mut gpu, until, run.last, &run.bar)),
            None => self.step_loop(&mut CpuSteps::default(), until, run.last, &run.bar),
        };
        self.reports.times.total += started.elapsed();
        looped
    }

    /// The steps up to `until` of a run that ends at `last`, on `stepper`.
    fn step_loop(&mut self, stepper: &mut dyn Stepper, until: u64, last: u64, bar: &Option<ProgressBar>) -> Result<(), RunError> {
        while self.state.step < until {
            let taken = stepper.take(self, until, last)?;
            if self.model.has_kinetics() && !stepper.decides_kinetics() {
                // Decided from the tensions of the step's force pass.
                let changed = match taken.last {
                    Some(clock) => self.kinetics_step(clock)?,
                    None => false,
                };
                stepper.bonds_changed(self, changed)?;
            }
            let final_step = self.state.step == last;
            let thermo_due = self.outputs.thermo_due(self.state.step);
            stepper.before_outputs(self, until, last, thermo_due)?;
            self.outputs_at_step(bar, final_step && !thermo_due)?;
            stepper.after_outputs(self)?;
            if let Some(b) = bar {
                b.inc(taken.steps);
            }
        }
        Ok(())
    }

    /// The end of a run: writes the lifetime table and reports the loop time.
    pub fn end_run(&mut self, run: ActiveRun) -> Result<(), RunError> {
        if let Some(b) = run.bar {
            b.finish_and_clear();
        }
        self.deck.run_end = None;
        self.protocols.end_run();
        self.write_lifetimes()?;
        let seconds = run.started.elapsed().as_secs_f64();
        if self.kinetics.host_formations > 0 {
            self.options.say(&format!(
                "device gpu: the `bind` formation of {} steps was decided on the host (the device's bond pool, slots, candidate list \
                 or neighbour list ran out of room; each rebuilt the GPU backend)",
                self.kinetics.host_formations
            ));
        }
        self.options.say(&format!(
            "loop time {seconds:.6} s for {} steps with {} particles: {:.6e} particle-steps/s",
            run.steps,
            self.model.len(),
            (run.steps as f64 * self.model.len() as f64) / seconds
        ));
        Ok(())
    }

    /// The context of the next step: the deck's settings in force and the state's clock.
    pub fn step_context(&self) -> StepContext {
        self.settings.step_context(&self.state)
    }

    /// Bond kinetics of the step just integrated, decided from the tensions of
    /// its force pass; a break or rebind updates the pair exclusions.
    /// Returns whether a bond broke, bound or formed.
    pub(super) fn kinetics_step(&mut self, clock: StepClock) -> Result<bool, RunError> {
        let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
        let (tension, length) = backend.bond_tension_and_length();
        let mut report = self.kinetics.engine.step(&self.model, &mut self.state, tension, length, clock);
        for warning in &report.warnings {
            eprintln!("{warning}");
        }
        let (bindings, formed_any) = self.bind_on_host(clock)?;
        report.bonds_changed |= !bindings.is_empty();
        report.events.extend(bindings);
        self.record_events(&report.events, clock.length)?;
        if formed_any {
            // New bonds change every per-bond buffer: rebuild the backend.
            self.backend.cpu.invalidate();
        } else if report.bonds_changed {
            let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
            backend.bonds_changed(&self.model, &self.state, &self.sim_box).map_err(RunError::Setup)?;
        }
        Ok(report.bonds_changed)
    }

    /// The bindings of the step `clock` describes (after its breaks and
    /// rebinds), decided and applied on the host (src/kinetics_engine/formation.rs):
    /// their events, and whether new bonds formed.
    pub(super) fn bind_on_host(&mut self, clock: StepClock) -> Result<(Vec<Event>, bool), RunError> {
        let Some(formation) = &mut self.kinetics.formation else { return Ok((Vec::new(), false)) };
        let bindings = formation.decide(&self.model, &self.state, &self.sim_box, clock).map_err(RunError::Setup)?;
        let formed_any = bindings.iter().any(|b| matches!(b, Binding::New(..)));
        Ok((self.kinetics.engine.apply_bindings(&mut self.model, &mut self.state, &self.sim_box, bindings, clock), formed_any))
    }

    /// The events of one step (`dt` long; none: nothing) into the lifetime
    /// sums, the event log and the dumps (with the bond state after them).
    pub(super) fn record_events(&mut self, events: &[Event], dt: f64) -> Result<(), RunError> {
        if events.is_empty() {
            return Ok(());
        }
        self.outputs.lifetimes.record(&self.model, events, dt);
        if let Some((log, path)) = &mut self.outputs.event_log {
            if let Err(e) = log.write(events) {
                let path = path.clone();
                return Err(self.output_error(&path, e));
            }
        }
        let bound = &self.state.bonds.as_ref().expect("kinetics has bond state").bound;
        let failed =
            self.outputs.dumps.iter_mut().find_map(|d| d.writer.write_bond_events(events, bound).err().map(|e| (d.path.clone(), e)));
        if let Some((path, e)) = failed {
            return Err(self.output_error(&path, e));
        }
        Ok(())
    }

    /// Rules whose rates depend on kT refuse to run at T = 0.
    fn check_kinetics_temperature(&self) -> Result<(), RunError> {
        if self.settings.kt > 0.0 {
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
}
