//! Inextensible bonds (deck `constrain BONDTYPE`): every bond of the type is
//! held at the rest length r0 of its law by SHAKE (Ryckaert, Ciccotti &
//! Berendsen 1977) applied after each step, in its overdamped form: the
//! correction of particle i along the bond's direction before the step is
//! weighted by its mobility 1/γ_i, which is what a constraint force moving it
//! over one step would do (x_i += dt/γ_i·F_i). A `fixed` particle has mobility
//! 0. Constraints are swept in bond order, sequentially (Gauss–Seidel), until
//! every |r − r0|/r0 < `tolerance`, so the result is the same on any thread
//! count.
//!
//! The constraint tension of each bond — the force along it that the
//! projection applied, positive when it pulls the ends together — is
//! T = Σg·|r_before|/dt over the sweeps (g the SHAKE multiplier); this is how
//! axial tension along an inextensible filament is read (thermo
//! `ctension/TYPE`). The force of the bond's own law still acts (it vanishes
//! at r0 for harmonic-like laws).
//!
//! Constraints that form fibres — linear chains, the filaments of
//! Cytosim — are not swept: each chain is solved exactly by the fibre
//! solver ([`super::fibre`]), whose step keeps the lengths to first order
//! and whose reshape restores them to the tolerance by Newton's method on
//! one multiplier per segment. Where other constraints join fibres (a
//! constrained crosslink, a branch), the fibres' and those constraints'
//! lengths are restored together by one Newton projection of the whole
//! graph ([`super::fibre::coupled`]); SHAKE handles the constraints that
//! touch no fibre.
//!
//! The GPU backend projects on the device with the same equation, the
//! constraints swept colour by colour (src/gpu/shake.rs).

use glam::DVec3;

use super::context::StepContext;
use super::fibre::coupled::Coupling;
use super::fibre::{FibreInputs, Fibres};
use crate::system::{Model, SimBox, State};

/// One constrained bond.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Constraint {
    pub bond: usize,
    pub length: f64,
}

/// The constrained bonds with their settings and last tensions.
#[derive(Clone, Debug, PartialEq)]
pub struct Constraints {
    pub list: Vec<Constraint>,
    /// Largest |r − r0|/r0 accepted.
    pub tolerance: f64,
    pub max_iterations: usize,
    /// Tension of each constraint over the last step (force units).
    pub tension: Vec<f64>,
    /// Sweeps (or, on fibres, Newton iterations) the last projection took.
    pub iterations: usize,
    /// How chains of constraints are solved (`constrain … method`).
    pub method: ConstraintMethod,
    /// The chains among the constraints and their solver.
    pub fibres: Fibres,
}

/// How constrained chains are solved (`constrain … method fibre|shake`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ConstraintMethod {
    /// Fibre by fibre, with their bending implicit ([`super::fibre`]); SHAKE for the rest.
    #[default]
    Fibre,
    /// Every constraint by SHAKE after the step (the GPU's projection).
    Shake,
}

/// The message of a projection that failed at `step`: the constraint's
/// ends (particle ids), the sweep cap, its relative error and the tolerance
/// (the CPU's and the device's, src/gpu/shake.rs).
pub fn failure_message(ends: [u64; 2], max_iterations: usize, step: u64, relative_error: f64, tolerance: f64) -> String {
    format!(
        "constraint of bond {}-{} not met after {max_iterations} sweeps at step {step}: |r − r0|/r0 = {relative_error:e} > tolerance {tolerance:e}",
        ends[0], ends[1]
    )
}

/// Why a projection failed.
#[derive(Clone, Debug, PartialEq)]
pub struct ConstraintFailure {
    pub bond: usize,
    pub relative_error: f64,
}

impl Default for Constraints {
    fn default() -> Self {
        Self {
            list: Vec::new(),
            tolerance: 1e-10,
            max_iterations: 1000,
            tension: Vec::new(),
            iterations: 0,
            method: ConstraintMethod::Fibre,
            fibres: Fibres::default(),
        }
    }
}

impl Constraints {
    /// The fibre solver with the chains of the current list (found again
    /// when the list changed); with `elastic`, also the elastic chains.
    pub fn fibres(&mut self, model: &Model, elastic: bool) -> &mut Fibres {
        self.fibres.prepare(model, self.list.iter().map(|c| c.bond), self.method == ConstraintMethod::Fibre, elastic);
        &mut self.fibres
    }

    /// Moves `state` onto the constraint lengths at once (`constrain …
    /// reshape yes`): the fibres' projection and SHAKE from the current
    /// positions, each particle weighted by its mobility.
    pub fn reshape_now(&mut self, model: &Model, state: &mut State, sim_box: &SimBox) -> Result<(), ConstraintFailure> {
        let images = sim_box.images();
        self.fibres.prepare(model, self.list.iter().map(|c| c.bond), self.method == ConstraintMethod::Fibre, false);
        let list = &self.list;
        let length = |k: usize| list[k].length;
        let inputs =
            FibreInputs { model, positions: &state.positions, images: &images, constraint_length: &length, held: &[], bond_block: None };
        self.fibres.load(&inputs);
        let before = state.positions.clone();
        let projected = self.project(model, &before, state, sim_box, &StepContext { dt: 1.0, ..Default::default() });
        self.tension.clear();
        projected
    }

    /// The particles of each constrained bond, in list order.
    pub fn pairs(&self, model: &Model) -> Vec<[u32; 2]> {
        self.list.iter().map(|c| model.bonds[c.bond]).collect()
    }

    /// Projects `state` (just advanced from positions `before`) back onto the
    /// constraint lengths; the context's dt converts the corrections to tensions.
    pub fn project(
        &mut self,
        model: &Model,
        before: &[DVec3],
        state: &mut State,
        sim_box: &SimBox,
        ctx: &StepContext,
    ) -> Result<(), ConstraintFailure> {
        let dt = ctx.dt;
        let images = sim_box.images();
        let mobility = |i: usize| {
            let gamma = model.type_drag[model.types[i] as usize];
            if gamma.is_finite() {
                1.0 / gamma
            } else {
                0.0
            }
        };
        self.tension.clear();
        self.tension.resize(self.list.len(), 0.0);
        self.iterations = 0;
        let chained = &self.fibres.chains.chained_constraints;
        let in_chain = |k: usize| chained.len() == self.list.len() && chained[k];
        let general = (0..self.list.len()).any(|k| !in_chain(k));
        // Constraints joined to fibres are restored with them, in one
        // projection of the whole graph; SHAKE sweeps the others.
        let on_fibre = |k: usize| model.bonds[self.list[k].bond].iter().any(|&p| self.fibres.holds(p as usize));
        let coupled = general && (0..self.list.len()).any(|k| !in_chain(k) && on_fibre(k));
        let couplings: Vec<Coupling> = (0..self.list.len())
            .filter(|&k| coupled && !in_chain(k))
            .map(|k| Coupling { entry: k, ends: model.bonds[self.list[k].bond], length: self.list[k].length })
            .collect();
        let swept = general && !coupled;
        // The directions before the step, along which SHAKE corrects (only
        // the constraints it sweeps need them).
        let reference: Vec<DVec3> = if swept {
            self.list
                .iter()
                .map(|c| {
                    let [i, j] = model.bonds[c.bond];
                    images.minimum_image(before[j as usize] - before[i as usize])
                })
                .collect()
        } else {
            Vec::new()
        };
        let x = &mut state.positions;
        let mut worst = (0, 0.0);
        for sweep in 0..if swept { self.max_iterations.max(1) } else { 0 } {
            worst = (0, 0.0);
            for (k, c) in self.list.iter().enumerate().filter(|(k, _)| !in_chain(*k)) {
                let [i, j] = model.bonds[c.bond];
                let (i, j) = (i as usize, j as usize);
                let r = images.minimum_image(x[j] - x[i]);
                let error = (r.length() - c.length) / c.length;
                if error.abs() > worst.1 {
                    worst = (k, error.abs());
                }
                if error.abs() <= self.tolerance {
                    continue;
                }
                let (wi, wj) = (mobility(i), mobility(j));
                let along = r.dot(reference[k]);
                if wi + wj == 0.0 || along == 0.0 {
                    continue;
                }
                let g = (r.length_squared() - c.length * c.length) / (2.0 * (wi + wj) * along);
                x[i] += g * wi * reference[k];
                x[j] -= g * wj * reference[k];
                self.tension[k] += g * reference[k].length() / dt;
            }
            self.iterations = sweep + 1;
            if worst.1 <= self.tolerance {
                break;
            }
        }
        if !self.fibres.is_empty() {
            let restored = if coupled {
                let coordinates = |i: usize| DVec3::splat(mobility(i));
                self.fibres.reshape_coupled(
                    x,
                    &images,
                    dt,
                    self.tolerance,
                    self.max_iterations,
                    &couplings,
                    &coordinates,
                    &mut self.tension,
                )
            } else {
                self.fibres.reshape(x, &images, dt, self.tolerance, self.max_iterations, &mut self.tension)
            };
            match restored {
                Ok(iterations) => self.iterations = self.iterations.max(iterations),
                Err((constraint, relative_error)) => return Err(ConstraintFailure { bond: self.list[constraint].bond, relative_error }),
            }
        }
        for (x, image) in x.iter_mut().zip(state.images.iter_mut()) {
            sim_box.wrap(x, image);
        }
        if worst.1 > self.tolerance {
            // The last sweep's worst error, re-measured after its corrections.
            let c = self.list[worst.0];
            let [i, j] = model.bonds[c.bond];
            let r = images.minimum_image(x[j as usize] - x[i as usize]);
            let relative_error = ((r.length() - c.length) / c.length).abs();
            if relative_error > self.tolerance {
                return Err(ConstraintFailure { bond: c.bond, relative_error });
            }
        }
        Ok(())
    }
}
