//! The outputs of a run: the run log, messages, dumps, thermo rows, the
//! lifetime table, and closing them all.

use std::fs::File;
use std::path::{Path, PathBuf};

use glam::DVec3;
use indicatif::ProgressBar;

use super::Simulation;
use crate::deck::DumpSpec;
use crate::output::files;
use crate::output::run_log::{model_parameters, RunLog};
use crate::output::{FrameView, Measures, TopologyView, TrajectoryWriter, WallPlane};
use crate::run::RunError;

/// An open dump and the step of its last frame.
pub(super) struct ActiveDump {
    pub(super) spec: DumpSpec,
    pub(super) path: PathBuf,
    pub(super) writer: Box<dyn TrajectoryWriter>,
    pub(super) last_step: Option<u64>,
}

impl Simulation {
    /// Creates the run log when the options ask for one.
    pub(super) fn open_log(&mut self) -> Result<(), RunError> {
        let Some(header) = &self.options.log else { return Ok(()) };
        let path = self.options.output_path(Path::new(&format!("{}.log", self.outputs.deck_stem)));
        let file = self.create_output(&path)?;
        let log = RunLog::create(file, &path, header, &self.deck.inputs).map_err(|e| self.output_error(&path, e))?;
        self.outputs.log = Some(log);
        Ok(())
    }

    /// Logs the resolved settings and parameters a `run` starts with.
    pub(super) fn log_run(&mut self, steps: u64, device: &str) -> Result<(), RunError> {
        let Some(log) = &mut self.outputs.log else { return Ok(()) };
        let text = format!(
            "\nrun {steps} from step {} on {device}: units {:?}, {} particles, box {:?} to {:?} periodic {:?}\n\
             timestep {:e}, temperature (kT) {:e}, seed {}, integrator {:?}, neighbor {:?}\n{}",
            self.state.step,
            self.model.units,
            self.model.len(),
            self.sim_box.lo.to_array(),
            self.sim_box.hi.to_array(),
            self.sim_box.periodic,
            self.settings.dt,
            self.settings.kt,
            self.settings.seed,
            self.settings.integrator,
            self.settings.neighbor,
            model_parameters(&self.model)
        );
        if let Err(e) = log.section(&text) {
            let path = log.path.clone();
            return Err(self.output_error(&path, e));
        }
        Ok(())
    }

    /// Creates (or truncates) the output file `path` (as [`RunOptions::output_path`](super::RunOptions::output_path)
    /// gives it), through no link inside the output directory.
    pub(super) fn create_output(&self, path: &Path) -> Result<File, RunError> {
        files::create(&self.options.output_dir, path).map_err(|e| self.output_error(path, e))
    }

    /// An output that could not be written, with the step it happened at.
    pub(super) fn output_error(&self, path: &Path, e: impl std::fmt::Display) -> RunError {
        RunError::Io(format!("{}: {e} (at step {})", path.display(), self.state.step))
    }

    pub(super) fn topology_view(&self) -> TopologyView<'_> {
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
            bond_type_names: &self.outputs.bond_type_names,
        }
    }

    pub(super) fn write_dump(&mut self, i: usize) -> Result<(), RunError> {
        let needs = self.outputs.dumps[i].writer.needs();
        let (mut virial, mut tension, mut length) = (Vec::new(), Vec::new(), Vec::new());
        if needs.any() {
            // Measurements read the CPU backend's terms at these positions.
            if !self.backend.cpu.is_built() {
                self.ensure_forces()?;
            } else if !self.backend.forces_current {
                self.refresh_cpu_forces(false)?;
            }
            let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
            if needs.virial {
                virial = crate::measure::per_particle_virial(backend, &self.model, &self.state, &self.sim_box);
            }
            if needs.bonds {
                (tension, length) = backend.bond_tensions_at(&self.model, &self.state, &self.sim_box);
            }
        }
        let forces: &[DVec3] = if needs.forces { &self.backend.forces.forces } else { &[] };
        let walls: Vec<WallPlane> = (self.model.externals.iter())
            .filter(|e| e.term.interaction.name() == "wall")
            .filter_map(|e| crate::interactions::wall_plane(&e.term.params))
            .map(|(normal, offset)| WallPlane { normal, offset })
            .collect();
        let clock = self.step_context();
        let frame = FrameView {
            step: clock.step,
            time: clock.time,
            sim_box: &self.sim_box,
            positions: &self.state.positions,
            images: &self.state.images,
            measures: Measures { forces, virial: &virial, bond_tension: &tension, bond_length: &length },
            bound: self.state.bonds.as_ref().map_or(&[], |b| &b.bound),
            walls: &walls,
        };
        if let Err(e) = self.outputs.dumps[i].writer.write_frame(&frame) {
            return Err(self.output_error(&self.outputs.dumps[i].path, e));
        }
        self.outputs.dumps[i].last_step = Some(self.state.step);
        Ok(())
    }

    pub(super) fn outputs_at_step(&mut self, bar: &Option<ProgressBar>, force_thermo: bool) -> Result<(), RunError> {
        let step = self.state.step;
        if let Some((log, path)) = &mut self.outputs.event_log {
            if let Err(e) = log.flush_due() {
                let path = path.clone();
                return Err(self.output_error(&path, e));
            }
        }
        if let Some((path, e)) = self.outputs.dumps.iter_mut().find_map(|d| d.writer.flush_due().err().map(|e| (d.path.clone(), e))) {
            return Err(self.output_error(&path, e));
        }
        for i in 0..self.outputs.dumps.len() {
            if step.is_multiple_of(self.outputs.dumps[i].spec.every) && self.outputs.dumps[i].last_step != Some(step) {
                self.write_dump(i)?;
            }
        }
        let due = self.outputs.thermo.every > 0 && step.is_multiple_of(self.outputs.thermo.every);
        if due || force_thermo {
            let values = self.with_thermo_inputs(|thermo, inputs| thermo.values(inputs))?;
            let line = self.outputs.thermo.row(&values).map_err(|(path, e)| self.output_error(&path, e))?;
            match bar {
                Some(bar) => bar.println(line),
                None => self.options.say(&line),
            }
        }
        self.checkpoint()
    }

    /// The lifetime table, rewritten after every `run` (and when stopped).
    pub(super) fn write_lifetimes(&self) -> Result<(), RunError> {
        match &self.outputs.lifetime_file {
            Some(path) => (self.outputs.lifetimes.write(&self.options.output_dir, path, &self.model, self.state.bonds.as_ref()))
                .map_err(|e| self.output_error(path, e)),
            None => Ok(()),
        }
    }

    /// Finishes every output file (called at the end and on errors).
    pub fn close_outputs(&mut self) -> Result<(), RunError> {
        let mut first_error = None;
        for dump in std::mem::take(&mut self.outputs.dumps) {
            if let Err(e) = dump.writer.finish() {
                first_error.get_or_insert(self.output_error(&dump.path, e));
            }
        }
        if let Err((path, e)) = self.outputs.thermo.close() {
            first_error.get_or_insert(self.output_error(&path, e));
        }
        if let Some((log, path)) = self.outputs.event_log.take() {
            if let Err(e) = log.finish() {
                first_error.get_or_insert(self.output_error(&path, e));
            }
        }
        first_error.map_or(Ok(()), Err)
    }
}
