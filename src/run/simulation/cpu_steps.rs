//! The CPU backend's steps: the explicit or implicit step of the reference
//! backend, with the protocols' held particles, the constraints' projection
//! and the contact step clamp, and FIRE minimisation.

use glam::{DMat3, DVec3};

use super::reference::finite_force;
use super::step_loop::{Stepper, Taken};
use super::Simulation;
use crate::backend::{CpuBackend, Forces};
use crate::integrate::constraints::{failure_message, ConstraintMethod, Constraints};
use crate::integrate::context::StepContext;
use crate::integrate::fibre::FibreStep;
use crate::integrate::fire::{fire_minimize, FireReport, FireSettings, MinimizeStyle};
use crate::integrate::implicit::{implicit_step, ConstrainedBonds, ImplicitError, ImplicitSettings};
use crate::integrate::newton::newton_minimize;
use crate::integrate::overdamped::{overdamped_step, Blowup, OverdampedSettings};
use crate::integrate::Integrator;
use crate::output::run_log::{Clock, Phase};
use crate::run::protocol::Protocols;
use crate::run::RunError;
use crate::system::{Model, SimBox, State};

/// The CPU backend as a [`Stepper`]: one step per call, timed by phase
/// for the run log.
#[derive(Default)]
pub(super) struct CpuSteps {
    /// Positions before the step (the constraints project from them).
    before: Vec<DVec3>,
    /// The phase clock of the step in progress.
    clock: Option<Clock>,
}

impl CpuSteps {
    fn lap(&mut self, sim: &mut Simulation, phase: Phase) {
        if let Some(clock) = &mut self.clock {
            clock.lap(&mut sim.reports.times, phase);
        }
    }
}

impl Stepper for CpuSteps {
    fn take(&mut self, sim: &mut Simulation, _until: u64, _last: u64) -> Result<Taken, RunError> {
        sim.stop_if_requested()?;
        self.clock = Some(sim.reports.times.clock());
        let ctx = sim.step_context();
        if !sim.constraints.list.is_empty() {
            self.before.clone_from(&sim.state.positions);
        }
        sim.protocols.before_step(&mut sim.backend.forces.forces, &sim.state);
        let moved = match sim.settings.integrator {
            Integrator::Implicit(settings, implicit) => sim.implicit_step(&ctx, &settings, &implicit)?,
            Integrator::Overdamped(settings) => {
                let n = sim.model.len();
                let limited = sim.backend.cpu.built().is_some_and(|b| b.contact_step_limits(n, &mut sim.backend.step_limits));
                let held = sim.protocols.held_coordinates(n);
                let Constraints { list, fibres, method, .. } = &mut sim.constraints;
                fibres.prepare(&sim.model, list.iter().map(|c| c.bond), *method == ConstraintMethod::Fibre, false);
                let length = |k: usize| list[k].length;
                let fibres = (!fibres.is_empty()).then(|| FibreStep {
                    fibres,
                    constraint_length: &length,
                    held: &held,
                    bond_block: None,
                    theta: settings.theta,
                });
                overdamped_step(
                    &sim.model,
                    &mut sim.state,
                    &sim.backend.forces.forces,
                    &sim.sim_box,
                    &ctx,
                    limited.then_some(sim.backend.step_limits.as_slice()),
                    &mut sim.backend.scratch,
                    fibres,
                )
                .inspect(|&fraction| sim.reports.contact_clamps += u64::from(fraction < 1.0))
            }
        };
        sim.protocols.restore_forces(&mut sim.backend.forces.forces);
        let clock = match moved {
            Ok(fraction) => ctx.advance(&mut sim.state, fraction),
            Err(Blowup { particle, displacement }) => return Err(sim.blowup(particle, sim.settings.displacement_message(displacement))),
        };
        if !sim.constraints.list.is_empty() {
            let projected = sim.constraints.project(&sim.model, &self.before, &mut sim.state, &sim.sim_box, &ctx);
            if sim.backend.implicit_tension.len() == sim.constraints.tension.len() {
                sim.constraints.tension.iter_mut().zip(&sim.backend.implicit_tension).for_each(|(t, extra)| *t += extra);
            }
            if let Err(failure) = projected {
                let c = &sim.constraints;
                let ends = sim.model.bonds[failure.bond].map(|p| sim.model.ids[p as usize]);
                let message = failure_message(ends, c.max_iterations, sim.state.step, failure.relative_error, c.tolerance);
                return Err(RunError::Setup(message));
            }
        }
        if let Err((particle, why)) = sim.protocols.after_step(&mut sim.state, &sim.sim_box, &ctx) {
            return Err(sim.blowup(particle, why));
        }
        self.lap(sim, Phase::Integrate);
        sim.check_in_box()?;
        Ok(Taken { steps: 1, last: Some(clock) })
    }

    fn bonds_changed(&mut self, sim: &mut Simulation, _changed: bool) -> Result<(), RunError> {
        // The kinetics step updated (or dropped, when bonds formed) the CPU backend.
        self.lap(sim, Phase::Kinetics);
        Ok(())
    }

    fn before_outputs(&mut self, sim: &mut Simulation, _until: u64, last: u64, due: bool) -> Result<(), RunError> {
        let ctx = sim.step_context();
        sim.protocols.advance_drives(&mut sim.model, &ctx);
        sim.protocols.set_ramps(&mut sim.model, sim.state.step);
        let final_step = sim.state.step == last;
        if sim.backend.cpu.is_built() {
            if sim.state.step.is_multiple_of(sim.settings.neighbor.every) {
                let backend = sim.backend.cpu.get(&sim.model, &sim.state, &sim.sim_box, sim.settings.neighbor.skin)?;
                backend.update_neighbors(&sim.state, &sim.sim_box, sim.settings.neighbor.check).map_err(RunError::Setup)?;
                self.lap(sim, Phase::Neighbor);
            }
            sim.compute_forces(due || final_step)?;
        } else {
            // Bonds formed: the backend is rebuilt for the new bond list.
            sim.ensure_forces()?;
        }
        sim.protocols.check_drives(&sim.model, &sim.state, &sim.sim_box);
        self.lap(sim, Phase::Force);
        Ok(())
    }

    fn after_outputs(&mut self, sim: &mut Simulation) -> Result<(), RunError> {
        self.lap(sim, Phase::Output);
        Ok(())
    }
}

impl Simulation {
    /// One implicit step; returns the fraction of dt it took (below 1 where
    /// the contact clamp shortened it).
    fn implicit_step(
        &mut self,
        ctx: &StepContext,
        settings: &OverdampedSettings,
        implicit: &ImplicitSettings,
    ) -> Result<Result<f64, Blowup>, RunError> {
        let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
        let limited = backend.contact_step_limits(self.model.len(), &mut self.backend.step_limits);
        let backend = &*backend;
        let (model, forces, sim_box) = (&self.model, &self.backend.forces.forces, &self.sim_box);
        let held = self.protocols.held_coordinates(model.len());
        let mut constrained = ConstrainedBonds { pairs: self.constraints.pairs(model), tension: Vec::new() };
        let Constraints { list, fibres, method, .. } = &mut self.constraints;
        // Elastic chains as preconditioner blocks stall the solve on crosslinked
        // spring networks (inputs/network_shear.in: 3e-3 after 1000 iterations); off until they do not.
        fibres.prepare(model, list.iter().map(|c| c.bond), *method == ConstraintMethod::Fibre, false);
        let stiffness = backend.stiffness_except(model, &self.state, sim_box, &fibres.chains.owned_bonds, &fibres.chains.owned_angles);
        if !fibres.is_empty() {
            let images = sim_box.images();
            let state = &self.state;
            let block = |b: usize| backend.bond_block(b, model, state, &images).unwrap_or(DMat3::ZERO);
            let length = |k: usize| list[k].length;
            let mut step = FibreStep { fibres, constraint_length: &length, held: &held, bond_block: Some(&block), theta: settings.theta };
            if let Err(singular) = step.assemble(model, &state.positions, &images, ctx.dt) {
                return Ok(Err(Blowup { particle: singular.particle as usize, displacement: f64::NAN }));
            }
        }
        let fibres = (!fibres.is_empty()).then_some(fibres);
        let outcome = implicit_step(
            model,
            &mut self.state,
            forces,
            &stiffness,
            sim_box,
            ctx,
            implicit,
            settings.theta,
            &mut constrained,
            fibres,
            limited.then_some(self.backend.step_limits.as_slice()),
            &held,
        );
        self.backend.implicit_tension = constrained.tension;
        match outcome {
            Ok(report) => {
                let fraction = report.step_fraction;
                self.reports.contact_clamps += u64::from(fraction < 1.0);
                self.reports.last_solve = report;
                Ok(Ok(fraction))
            }
            Err(ImplicitError::Blowup(blowup)) => Ok(Err(blowup)),
            Err(ImplicitError::Solve(why)) => Err(RunError::Setup(format!("integrator implicit at step {}: {why}", self.state.step))),
        }
    }

    /// `constrain … reshape yes`: the particles moved onto the constraint lengths now.
    pub(super) fn reshape_to_constraints(&mut self) -> Result<(), RunError> {
        if let Err(failure) = self.constraints.reshape_now(&self.model, &mut self.state, &self.sim_box) {
            let c = &self.constraints;
            let ends = self.model.bonds[failure.bond].map(|p| self.model.ids[p as usize]);
            return Err(RunError::Setup(failure_message(ends, c.max_iterations, self.state.step, failure.relative_error, c.tolerance)));
        }
        self.backend.forces_current = false;
        Ok(())
    }

    /// `minimize`: FIRE to max |F| < ftol, on the device where the run
    /// would use the GPU and FIRE can run there (src/gpu/fire.rs), else on
    /// the CPU. The step counter does not advance.
    pub fn minimize(&mut self, settings: &FireSettings) -> Result<(), RunError> {
        self.ensure_forces()?;
        let report = match settings.style {
            MinimizeStyle::Newton => self.minimize_by_newton(settings)?,
            MinimizeStyle::Fire => match self.minimize_on_gpu(settings)? {
                Some(report) => report,
                None => self.minimize_on_cpu(settings)?,
            },
        };
        if let Some(i) = self.backend.forces.forces.iter().position(|f| !finite_force(*f)) {
            return Err(self.blowup(i, "non-finite force during minimisation".into()));
        }
        self.check_in_box()?;
        let verdict = if report.converged { "converged" } else { "stopped at maxiter without converging" };
        let style = match settings.style {
            MinimizeStyle::Fire => "FIRE",
            MinimizeStyle::Newton => "Newton, on the CPU",
        };
        self.options.say(&format!(
            "minimize ({style}): {verdict} after {} iterations: max |F| = {:e} (ftol {:e}), pe = {:e}{}",
            report.iterations,
            report.max_force,
            settings.ftol,
            report.energy,
            if report.clamped > 0 { format!(", {} moves shortened by the contact step clamp", report.clamped) } else { String::new() }
        ));
        self.reports.contact_clamps += report.clamped;
        self.reports.last_minimize = Some(report);
        Ok(())
    }

    /// FIRE's fictitious masses γ·Δt per particle (infinite for a fixed one).
    pub(super) fn fire_masses(&self) -> Vec<f64> {
        self.model.types.iter().map(|&t| self.model.type_drag[t as usize] * self.settings.dt).collect()
    }

    /// FIRE on the CPU backend, from current forces.
    fn minimize_on_cpu(&mut self, settings: &FireSettings) -> Result<FireReport, RunError> {
        let ctx = self.step_context();
        let mass = self.fire_masses();
        let mut state = self.state.clone();
        let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
        let (model, sim_box, forces, protocols) = (&self.model, &self.sim_box, &mut self.backend.forces, &self.protocols);
        let report = fire_minimize(&mut state, sim_box, &mass, &ctx, settings, |s, f, limits, energy| {
            minimizer_forces(backend, model, sim_box, protocols, forces, s, f, limits, energy)
        })?;
        self.state = state;
        self.backend.forces_current = true;
        self.backend.energies_current = true;
        Ok(report)
    }

    /// Newton minimisation (src/integrate/newton.rs) on the CPU backend, from current forces.
    fn minimize_by_newton(&mut self, settings: &FireSettings) -> Result<FireReport, RunError> {
        let mass = self.fire_masses();
        let held = self.protocols.held_coordinates(self.model.len());
        let mut state = self.state.clone();
        let backend = self.backend.cpu.get(&self.model, &self.state, &self.sim_box, self.settings.neighbor.skin)?;
        let (model, sim_box, forces, protocols) = (&self.model, &self.sim_box, &mut self.backend.forces, &self.protocols);
        // The backend is borrowed by both closures: the forces', then K̃'s at the state taken.
        let backend = std::cell::RefCell::new(backend);
        let report = newton_minimize(
            &mut state,
            sim_box,
            &mass,
            &held,
            settings,
            |s, f, limits| minimizer_forces(&mut backend.borrow_mut(), model, sim_box, protocols, forces, s, f, limits, true),
            |s| backend.borrow().stiffness(model, s, sim_box),
            |why| RunError::Setup(format!("minimize style newton: {why}")),
        )?;
        self.state = state;
        self.backend.forces_current = false;
        self.ensure_forces()?;
        Ok(report)
    }
}

/// A minimiser's evaluation at state `s` on the CPU backend: the neighbour
/// list and contacts brought up to date, the forces into `forces` and, with
/// the protocols' held coordinates masked to 0, into `f`, the contact step
/// limits into `limits`. With `energy`, energies and the virial too, and
/// returns the energy; else NaN (the forces alone cost less).
#[allow(clippy::too_many_arguments)]
fn minimizer_forces(
    backend: &mut CpuBackend,
    model: &Model,
    sim_box: &SimBox,
    protocols: &Protocols,
    forces: &mut Forces,
    s: &State,
    f: &mut Vec<DVec3>,
    limits: &mut Vec<f64>,
    energy: bool,
) -> Result<f64, RunError> {
    backend.update_neighbors(s, sim_box, true).map_err(RunError::Setup)?;
    backend.update_contacts(model, s, sim_box).map_err(RunError::Setup)?;
    if energy {
        backend.compute(model, s, sim_box, forces);
    } else {
        backend.compute_forces(model, s, sim_box, forces);
    }
    backend.contact_step_limits(s.len(), limits);
    f.clone_from(&forces.forces);
    protocols.mask(f);
    Ok(if energy { forces.total_energy() } else { f64::NAN })
}
