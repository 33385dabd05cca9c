//! Restarts of a run: periodic checkpoints, the restart a stop request
//! writes, loading one, and the blow-up report with its last good frame.

use std::collections::VecDeque;
use std::path::{Path, PathBuf};

use rayon::prelude::*;

use super::Simulation;
use crate::deck::{Action, CheckpointSpec, Plan};
use crate::kinetics_engine::{initial_bond_state, Formation};
use crate::output::files;
use crate::output::restart::{write_state, Counters, RestartData};
use crate::run::blowup::culprit;
use crate::run::RunError;

/// Periodic checkpoints in force, the step of the last one and the files
/// written with a `*` name (oldest first).
pub(super) struct Checkpoints {
    pub(super) spec: CheckpointSpec,
    pub(super) last_step: Option<u64>,
    pub(super) written: VecDeque<PathBuf>,
}

/// `path` with a `*` in its file name replaced by the step (LAMMPS' `write_restart file.*`).
pub(super) fn with_step(path: &Path, step: u64) -> PathBuf {
    match path.file_name().map(|n| n.to_string_lossy()) {
        Some(name) if name.contains('*') => path.with_file_name(name.replace('*', &step.to_string())),
        _ => path.to_path_buf(),
    }
}

impl Simulation {
    /// Why `data` (read from `restart`) cannot continue `plan` with
    /// [`Simulation::resume`]: the restart against the deck's system (see
    /// [`RestartData::check_against`]), and where it stands in the deck
    /// against the deck's actions. `cellmd run --continue` checks this before
    /// it creates any output.
    pub fn check_restart(plan: &Plan, data: &RestartData, restart: &Path) -> Result<(), String> {
        let fail = |e: String| format!("{}: {e}", restart.display());
        data.check_against(&plan.model, plan.sim_box.periodic).map_err(fail)?;
        let Some(resume) = &data.resume else { return Err(fail("resume: found none, expected the deck to continue".into())) };
        let actions = plan.actions.len();
        match (plan.actions.get(resume.action), resume.run_end) {
            (None, _) if resume.action > actions => {
                Err(fail(format!("resume.action: found {}, expected at most {actions} (the deck's actions)", resume.action)))
            }
            (Some(Action::Run(steps)), Some(end)) if end.saturating_sub(data.step) > *steps => Err(fail(format!(
                "resume.run_end: found {end}, expected at most {} (step {} + the {steps} steps of its `run`)",
                data.step.saturating_add(*steps),
                data.step
            ))),
            (Some(Action::Run(_)), _) | (_, None) => Ok(()),
            (_, Some(end)) => Err(fail(format!("resume.run_end: found {end}, expected none (action {} is not a `run`)", resume.action))),
        }
    }

    /// When a stop was requested: writes `NAME.restart` (with the deck and
    /// where the run stands in it) and the lifetime table, and returns
    /// [`RunError::Stopped`]; the caller's error path closes the outputs.
    pub(super) fn stop_if_requested(&mut self) -> Result<(), RunError> {
        let Some(reason) = self.options.stop.requested() else { return Ok(()) };
        let restart = self.options.output_path(Path::new(&format!("{}.restart", self.outputs.deck_stem)));
        self.write_lifetimes()?;
        write_state(&self.options.output_dir, &restart, &self.restart_data()).map_err(|e| self.output_error(&restart, e))?;
        Err(RunError::Stopped { step: self.state.step, reason: reason.to_string(), restart: restart.display().to_string() })
    }

    /// The restart of the current state: with the counters, the deck and
    /// where the run stands in it.
    pub(super) fn restart_data(&self) -> RestartData {
        let mut data = RestartData::from_state(self.model.units, &self.state, &self.sim_box, &self.model.ids);
        data.counters = Counters {
            breaks: self.kinetics.engine.breaks,
            rebinds: self.kinetics.engine.rebinds,
            forms: self.kinetics.engine.forms,
            resets: self.kinetics.engine.resets,
            contact_clamps: self.reports.contact_clamps,
        };
        data.resume = Some(self.deck.resume());
        data
    }

    /// A periodic checkpoint when one is due at this step.
    pub(super) fn checkpoint(&mut self) -> Result<(), RunError> {
        let step = self.state.step;
        let Some(due) = self.outputs.checkpoints.as_ref().filter(|c| step.is_multiple_of(c.spec.every) && c.last_step != Some(step)) else {
            return Ok(());
        };
        let path = self.options.output_path(&with_step(&due.spec.path, step));
        write_state(&self.options.output_dir, &path, &self.restart_data()).map_err(|e| self.output_error(&path, e))?;
        let checkpoints = self.outputs.checkpoints.as_mut().expect("due above");
        checkpoints.last_step = Some(step);
        let mut stale = Vec::new();
        if let Some(keep) = checkpoints.spec.keep {
            checkpoints.written.push_back(path);
            while checkpoints.written.len() > keep {
                stale.extend(checkpoints.written.pop_front());
            }
        }
        for old in stale {
            files::remove(&self.options.output_dir, &old).map_err(|e| self.output_error(&old, e))?;
        }
        Ok(())
    }

    /// Continues from a restart, checked against the system first (see
    /// [`RestartData::check_against`]).
    pub(super) fn load_restart(&mut self, data: RestartData, path: &Path) -> Result<(), RunError> {
        data.check_against(&self.model, self.sim_box.periodic).map_err(|e| RunError::Setup(format!("{}: {e}", path.display())))?;
        let counters = data.counters;
        self.kinetics.engine.breaks = counters.breaks;
        self.kinetics.engine.rebinds = counters.rebinds;
        self.kinetics.engine.forms = counters.forms;
        self.kinetics.engine.resets = counters.resets;
        self.reports.contact_clamps = counters.contact_clamps;
        self.sim_box = data.sim_box;
        if self.kinetics.formation.is_some() {
            self.kinetics.formation = Some(Formation::new(&self.model, &self.sim_box));
        }
        self.state = data.to_state();
        match &self.state.bonds {
            Some(bonds) => self.model.set_formed_bonds(&bonds.formed),
            None => self.state.bonds = initial_bond_state(&self.model),
        }
        self.backend.cpu.invalidate();
        self.backend.forces_current = false;
        self.check_in_box()
    }

    /// Stops the run, as a blow-up (step, particle id, last good frame), if a
    /// particle left a fixed box or cannot be wrapped into a periodic one:
    /// LAMMPS' "Lost atoms". Checked after every CPU step and at every GPU
    /// read-back.
    pub(super) fn check_in_box(&mut self) -> Result<(), RunError> {
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

    /// Builds the blow-up report and writes the last good frame.
    pub(super) fn blowup(&mut self, particle: usize, what: String) -> RunError {
        let parts = match self.backend.cpu.built() {
            Some(b) => b.breakdown(&self.model, &self.state, &self.sim_box, particle),
            None => Vec::new(),
        };
        let mut last_good = Vec::new();
        let step = self.state.step;
        for i in 0..self.outputs.dumps.len() {
            if self.outputs.dumps[i].last_step != Some(step) && self.write_dump(i).is_ok() {
                last_good.push(self.outputs.dumps[i].path.display().to_string());
            }
        }
        let restart = self.options.output_path(Path::new(&format!("{}.lastgood.restart", self.outputs.deck_stem)));
        if write_state(&self.options.output_dir, &restart, &self.restart_data()).is_ok() {
            last_good.push(restart.display().to_string());
        }
        RunError::Blowup { step, particle_id: self.model.ids[particle], what, culprit: culprit(parts), last_good }
    }
}
