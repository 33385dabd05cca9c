//! Stepping and inspecting a [`Simulation`] from outside a deck (the Python
//! API). A `run N` can be advanced in segments — [`Simulation::begin_run`],
//! then [`Simulation::advance`] to chosen steps, then
//! [`Simulation::end_run`] — and between segments the caller may read the
//! system or change it (a deck action through [`Simulation::apply`], or new
//! positions): the next segment recomputes the forces if anything changed.
//! Cut into segments or not, a CPU run takes the same steps bit for bit;
//! thermo rows, dumps and the run's final outputs fall on the same steps.
//!
//! ```no_run
//! # fn demo(plan: &cellmd::deck::Plan) -> Result<(), cellmd::run::RunError> {
//! use cellmd::run::{RunOptions, Simulation};
//! let mut sim = Simulation::before_first_run(plan, RunOptions::default())?;
//! let run = sim.begin_run(1000)?;
//! for until in (100..=1000).step_by(100) {
//!     sim.advance(&run, until)?;
//!     let volumes = sim.body_volumes_and_areas(); // … or change a parameter
//! }
//! sim.end_run(run)?;
//! # Ok(()) }
//! ```

use std::time::Instant;

use glam::DVec3;
use indicatif::ProgressBar;

use super::Simulation;
use crate::gpu::GpuContext;
use crate::run::RunError;

/// A `run N` in progress (from [`Simulation::begin_run`]).
pub struct ActiveRun {
    pub(super) steps: u64,
    /// The step the run ends at.
    pub(super) last: u64,
    /// The GPU it runs on (None: the CPU backend).
    pub(super) gpu: Option<GpuContext>,
    pub(super) bar: Option<ProgressBar>,
    pub(super) started: Instant,
}

impl ActiveRun {
    /// The step the run ends at.
    pub fn last(&self) -> u64 {
        self.last
    }

    /// Whether the run's steps are taken on the GPU.
    pub fn on_gpu(&self) -> bool {
        self.gpu.is_some()
    }
}

/// Every bond's state at the current positions, in the model's bond order.
#[derive(Clone, Debug, Default)]
pub struct BondTable {
    /// Whether the bond is bound (always true without bond kinetics).
    pub bound: Vec<bool>,
    /// dE/dr, positive when stretched (force units).
    pub tension: Vec<f64>,
    pub length: Vec<f64>,
    /// The bond's own rest length, else its type's `r0` (NaN if its law has none).
    pub rest_length: Vec<f64>,
}

impl Simulation {
    /// Tension, length, bound flag and rest length of every bond.
    pub fn bond_table(&mut self) -> Result<BondTable, RunError> {
        let (tension, length) = self.bond_tensions()?;
        let bonds = self.state.bonds.as_ref();
        let n = self.model.bonds.len();
        Ok(BondTable {
            bound: (0..n).map(|b| bonds.is_none_or(|s| s.bound[b])).collect(),
            tension,
            length,
            rest_length: (0..n).map(|b| self.model.rest_length(b, bonds)).collect(),
        })
    }

    /// Enclosed volume and area of every body (`[ bodies ]` order) at the current positions.
    pub fn body_volumes_and_areas(&self) -> Vec<(f64, f64)> {
        let images = self.sim_box.images();
        (0..self.model.bodies.len()).map(|b| self.model.body_volume_and_area(b, &self.state.positions, &images)).collect()
    }

    /// Moves every particle to `positions` (wrapped into the box on periodic
    /// axes; image counters kept, as `displace_atoms` does); the forces and
    /// the neighbour list follow.
    pub fn set_positions(&mut self, positions: &[DVec3]) -> Result<(), RunError> {
        if positions.len() != self.model.len() {
            return Err(RunError::Setup(format!("found {} positions, expected one per particle ({})", positions.len(), self.model.len())));
        }
        if let Some(i) = positions.iter().position(|x| !x.is_finite()) {
            return Err(RunError::Setup(format!(
                "found a non-finite position of particle {}, expected finite coordinates",
                self.model.ids[i]
            )));
        }
        for ((x, image), new) in self.state.positions.iter_mut().zip(self.state.images.iter_mut()).zip(positions) {
            *x = *new;
            self.sim_box.wrap(x, image);
        }
        if let Some(backend) = self.backend.cpu.built_mut() {
            backend.update_neighbors(&self.state, &self.sim_box, true).map_err(RunError::Setup)?;
        }
        self.backend.forces_current = false;
        Ok(())
    }

    /// Keeps every thermo row in memory from now on (see [`Self::thermo_log`]).
    pub fn record_thermo(&mut self) {
        self.outputs.thermo.record = true;
    }

    /// The thermo columns' labels and the rows recorded since recording
    /// began or the columns last changed.
    pub fn thermo_log(&self) -> (&[String], &[Vec<f64>]) {
        (&self.outputs.thermo.labels, &self.outputs.thermo.log)
    }
}
