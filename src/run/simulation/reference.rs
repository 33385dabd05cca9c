//! The CPU backend as the reference of a run: forces, energies and virial
//! at the current state, and every measurement thermo and outputs read,
//! whichever backend takes the steps.

use glam::DVec3;
use rayon::prelude::*;

use super::{Backends, Simulation};
use crate::backend::{CpuBackend, Forces};
use crate::deck::ThermoColumn;
use crate::run::thermo::{column_value, Thermo, ThermoInputs};
use crate::run::RunError;
use crate::system::{Model, SimBox, State};

/// The CPU backend of a run. It is built when first needed, for the system
/// as it is then, and dropped where the system changes in a way it cannot
/// follow (new bonds, a pair cutoff, the neighbour settings, a restart) to
/// be built again at the next need: [`Self::get`] builds it, so no caller
/// assumes it exists.
#[derive(Default)]
pub(super) struct Reference(Option<CpuBackend>);

impl Reference {
    /// The backend, built now for the system if it is not.
    pub(super) fn get(&mut self, model: &Model, state: &State, sim_box: &SimBox, skin: f64) -> Result<&mut CpuBackend, RunError> {
        let backend = match self.0.take() {
            Some(backend) => backend,
            None => CpuBackend::new(model, state, sim_box, skin).map_err(RunError::Setup)?,
        };
        Ok(self.0.insert(backend))
    }

    /// The backend if it is built (what it measured at the last force pass).
    pub(super) fn built(&self) -> Option<&CpuBackend> {
        self.0.as_ref()
    }

    pub(super) fn built_mut(&mut self) -> Option<&mut CpuBackend> {
        self.0.as_mut()
    }

    pub(super) fn is_built(&self) -> bool {
        self.0.is_some()
    }

    /// Drops the backend: the system changed in a way it cannot follow.
    pub(super) fn invalidate(&mut self) {
        self.0 = None;
    }
}

impl Simulation {
    /// The smallest node–face distance between different bodies at the last
    /// force evaluation (∞ without `contact` lines or before the first one).
    pub fn min_contact_distance(&self) -> f64 {
        self.backend.cpu.built().map_or(f64::INFINITY, |b| b.min_contact_distance())
    }

    /// Forces, energies by interaction and virial at the current state
    /// (computed now if stale).
    pub fn current_forces(&mut self) -> Result<&Forces, RunError> {
        self.ensure_forces()?;
        Ok(&self.backend.forces)
    }

    /// Calls `read` with the thermo settings and what thermo columns read at
    /// the current state (forces, energies and virial computed now if stale).
    pub(super) fn with_thermo_inputs<R>(&mut self, read: impl FnOnce(&Thermo, &ThermoInputs) -> R) -> Result<R, RunError> {
        self.ensure_forces()?;
        let context = self.step_context();
        let Simulation { backend, model, state, sim_box, outputs, kinetics, reports, constraints, settings, .. } = self;
        let Backends { cpu, forces, .. } = backend;
        let backend: &CpuBackend = cpu.get(model, state, sim_box, settings.neighbor.skin)?;
        let inputs = ThermoInputs {
            model,
            state,
            sim_box,
            backend,
            forces,
            context,
            kinetics: &kinetics.engine,
            solve: reports.last_solve,
            constraints,
            contact_clamps: reports.contact_clamps,
        };
        Ok(read(&outputs.thermo, &inputs))
    }

    /// The value of a thermo column at the current state (forces, energies
    /// and virial computed now if stale), as a thermo row would print it.
    pub fn thermo_value(&mut self, column: &ThermoColumn) -> Result<f64, RunError> {
        self.with_thermo_inputs(|_, inputs| column_value(column, inputs))
    }

    /// The per-particle virial W_i at the current state (see [`crate::measure::stress`]).
    pub fn particle_virial(&mut self) -> Result<Vec<[f64; 6]>, RunError> {
        self.ensure_forces()?;
        let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
        Ok(crate::measure::per_particle_virial(backend, &self.model, &self.state, &self.sim_box))
    }

    /// Tension (dE/dr, positive when stretched) and length of every bond at the current state.
    pub fn bond_tensions(&mut self) -> Result<(Vec<f64>, Vec<f64>), RunError> {
        self.ensure_forces()?;
        let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
        Ok(backend.bond_tensions_at(&self.model, &self.state, &self.sim_box))
    }

    /// Ensures a backend with a fresh neighbour list and forces at the current state.
    pub(super) fn ensure_forces(&mut self) -> Result<(), RunError> {
        if !self.backend.cpu.is_built() {
            self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
            self.backend.forces_current = false;
        }
        if !self.backend.forces_current || !self.backend.energies_current {
            self.compute_forces(true)?;
        }
        Ok(())
    }

    /// Forces at the current state, with energies and virial if `energies`.
    pub(super) fn compute_forces(&mut self, energies: bool) -> Result<(), RunError> {
        let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
        backend.update_contacts(&self.model, &self.state, &self.sim_box).map_err(RunError::Setup)?;
        if energies {
            backend.compute(&self.model, &self.state, &self.sim_box, &mut self.backend.forces);
        } else {
            backend.compute_forces(&self.model, &self.state, &self.sim_box, &mut self.backend.forces);
        }
        self.backend.forces_current = true;
        self.backend.energies_current = energies;
        if let Some(i) = self.backend.forces.forces.par_iter().with_min_len(4096).position_first(|f| !finite_force(*f)) {
            return Err(self.blowup(i, "non-finite force".into()));
        }
        Ok(())
    }

    /// CPU forces (and energies) at the current state, after a GPU segment.
    pub(super) fn refresh_cpu_forces(&mut self, energies: bool) -> Result<(), RunError> {
        let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
        backend.update_neighbors(&self.state, &self.sim_box, true).map_err(RunError::Setup)?;
        self.compute_forces(energies)
    }
}

/// Whether a force and its squared magnitude are finite: `turgor dp0 1e308`
/// gave finite components whose |F| overflowed, and every later step was
/// clamped to nothing instead of stopping.
pub(super) fn finite_force(f: DVec3) -> bool {
    f.length_squared().is_finite()
}
