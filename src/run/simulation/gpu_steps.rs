//! The GPU backend's steps: which runs it can take, the adapter, and the
//! GPU as a [`Stepper`].

use super::step_loop::{Stepper, Taken};
use super::Simulation;
use crate::gpu::backend::StepSettings;
use crate::gpu::protocol::{DeviceProtocol, HeldCoordinates};
use crate::gpu::{DevicePreference, GpuBackend, GpuContext, GpuHalt};
use crate::integrate::fire::{max_residual_force, FireReport, FireSettings};
use crate::integrate::Integrator;
use crate::run::RunError;
use crate::system::StepClock;

/// Why custom surface terms of bodies keep a run (or a minimisation) on the CPU.
const CUSTOM_SURFACE_TERMS: &str = "custom surface terms of bodies (`custom` body lines) run on the CPU backend only";

/// Why `integrator … theta` other than 1 keeps a run on the CPU.
const THETA_ON_CPU: &str = "steps with `theta` other than 1 (the device's steps are backward Euler) run on the CPU backend only";

/// Why average-nodal-pressure volume elements keep a run on the CPU.
const NODAL_PRESSURE_TETRA: &str = "average-nodal-pressure volume elements (`neo_hookean_anp`) run on the CPU backend only";

/// Why a box with periodic edges shorter than twice the pair range keeps a run on the CPU.
const SHORT_PERIODIC_EDGES: &str =
    "pairs through several periodic images (a periodic box edge shorter than 2·(pair cutoff + skin)) run on the CPU backend only";

/// The longest GPU segment between read-backs when no output is due.
const GPU_SYNC_STEPS: u64 = 1000;

/// The GPU as a [`Stepper`]. The host synchronises where an output is due
/// (thermo, dump, checkpoint, the end) and at least every
/// [`GPU_SYNC_STEPS`] steps (progress, blow-up checks), reading back the
/// positions only where an output needs them; thermo quantities are then
/// computed by the CPU backend at the read-back positions. Bond kinetics
/// whose rules the device has (src/gpu/kinetics.rs) are decided there: a
/// segment is as long as without kinetics (it ends early only when the
/// event buffer is full), and at its end the host drains the events, counts,
/// logs and applies them step by step, and reads the ages back with the
/// positions. With other bond kinetics the host synchronises every step: it reads the positions back,
/// measures every bond's tension and length in f64, decides the step's
/// events exactly as on the CPU, and uploads the changed bond state as one
/// batch (a new GPU backend when bonds formed). A segment that ends at
/// `until` before `last` reads the positions back and leaves the CPU
/// forces current there. Held coordinates, moving groups, ramps and driven
/// indenters run on the device (src/gpu/protocol.rs): the host hands each
/// segment the ramps' values and the drives' centres of its steps, and at
/// the segment's end sets the ramps' values and the centres the drives
/// reached in the model (and whether they hold), for the outputs.
pub(super) struct GpuSteps {
    context: GpuContext,
    settings: StepSettings,
    gpu: GpuBackend,
    /// Some kinetic rule changes the bond state every step.
    evolving: bool,
    /// The reset count before the kinetics of the step just taken.
    resets: u64,
    /// A stop was requested when the last segment synchronised.
    stopping: bool,
    /// Bond kinetics are decided on the device.
    device_kinetics: bool,
    /// The protocols in force, as the device takes them.
    protocol: DeviceProtocol,
}

impl GpuSteps {
    /// The GPU backend for the steps of a run from the current state.
    pub(super) fn new(sim: &Simulation, context: &GpuContext) -> Result<Self, RunError> {
        let settings = sim.step_settings();
        let device_kinetics = sim.model.has_kinetics() && crate::gpu::kinetics::refusal(&sim.model).is_none();
        let (model, state, sim_box) = (&sim.model, &sim.state, &sim.sim_box);
        let protocol = sim.protocols.for_device(model);
        let warned = device_kinetics.then(|| sim.kinetics.engine.warned(model));
        let mut gpu =
            GpuBackend::with_protocol(context, model, state, sim_box, &settings, warned.as_deref(), &protocol).map_err(RunError::Setup)?;
        if let Integrator::Implicit(_, implicit) = &sim.settings.integrator {
            // The implicit step on the device (src/gpu/implicit.rs): f32 CG has a tolerance floor.
            if implicit.solver == crate::integrate::implicit::LinearSolver::Cholesky {
                sim.options.say(&format!(
                    "device gpu: integrator implicit solver cholesky has no device form: its steps are solved by f32 conjugate \
                     gradients to relative residual {:e}, and reach the same equilibrium",
                    crate::gpu::implicit::F32_TOLERANCE
                ));
            } else if implicit.tolerance < crate::gpu::implicit::F32_TOLERANCE {
                sim.options.say(&format!(
                    "device gpu: integrator implicit solves to relative residual {:e} in f32 (the deck asks for {:e})",
                    crate::gpu::implicit::F32_TOLERANCE,
                    implicit.tolerance
                ));
            }
            gpu.step_implicitly(context, model, &settings, implicit, &sim.constraints.pairs(model)).map_err(RunError::Setup)?;
            if gpu.implicit_is_split() {
                sim.options.say(&format!(
                    "device gpu: integrator implicit: conjugate gradients split over every workgroup ({} particles; gpu_workgroups one keeps them in one)",
                    model.len()
                ));
            }
        }
        if !sim.constraints.list.is_empty() {
            // The constraints' projection on the device (src/gpu/shake.rs): f32 lengths have a tolerance floor.
            let tolerance = gpu.constrain_bonds(context, model, &sim.constraints).map_err(RunError::Setup)?;
            if tolerance > sim.constraints.tolerance {
                sim.options.say(&format!(
                    "device gpu: constraints are projected to |r − r0|/r0 ≤ {tolerance:e} in f32 (the deck asks for {:e})",
                    sim.constraints.tolerance
                ));
            }
        }
        let evolving = sim.model.bond_kinetics.iter().flat_map(|k| &k.rules).any(|r| r.rule.evolves_every_step());
        Ok(Self { context: context.clone(), settings, gpu, evolving, resets: 0, stopping: false, device_kinetics, protocol })
    }
}

impl Stepper for GpuSteps {
    fn take(&mut self, sim: &mut Simulation, until: u64, last: u64) -> Result<Taken, RunError> {
        // Bond kinetics decided on the host: one step per segment.
        let kinetics = sim.model.has_kinetics() && !self.device_kinetics;
        let next_output = sim.outputs.next_due(sim.state.step, last).min(sim.state.step + GPU_SYNC_STEPS).min(until);
        let steps = if kinetics { 1 } else { next_output - sim.state.step };
        self.gpu.set_time(sim.state.time);
        if sim.protocols.has_ramps() {
            self.gpu.set_ramps(sim.state.step, sim.protocols.ramp_rows(sim.state.step, steps));
        }
        let centres = sim.protocols.drive_centres(&sim.model, sim.settings.dt, steps);
        self.gpu.set_drives(centres.clone());
        let outcome = self.gpu.run(sim.state.step, steps);
        sim.protocols.follow_device_drives(&mut sim.model, &centres, &self.gpu.drive_states());
        let done = match &outcome {
            Ok(done) => *done,
            Err(GpuHalt::Blowup { step, .. } | GpuHalt::Capacity { step, .. } | GpuHalt::Reach { step } | GpuHalt::Formation { step }) => {
                step - sim.state.step
            }
        };
        // Each step took s·dt: below 1 where the contact step clamp shortened it (src/gpu/contact.rs).
        let mut taken = Taken { steps: done, last: None };
        if let Some(report) = self.gpu.implicit_report() {
            sim.reports.last_solve = report;
        }
        let mut clocks = Vec::new();
        for k in 0..done {
            let fraction = self.gpu.step_fraction(k);
            sim.reports.contact_clamps += u64::from(fraction < 1.0);
            let clock = sim.step_context().advance(&mut sim.state, fraction);
            clocks.extend(Some(clock).filter(|_| self.device_kinetics));
            taken.last = Some(clock);
        }
        if self.device_kinetics {
            self.record_device_kinetics(sim, &clocks)?;
        }
        // The outputs here see the ramps' values of this step, as on the CPU.
        sim.protocols.set_ramps(&mut sim.model, sim.state.step);
        sim.backend.forces_current = false;
        let segment_end = sim.state.step == until;
        // Positions come back only when something reads them; between
        // outputs the sync only reads the GPU's status words.
        let output_due = sim.outputs.reads_positions_at(sim.state.step);
        self.stopping = sim.options.stop.requested().is_some();
        let read_back = segment_end || output_due || self.stopping || outcome.is_err() || kinetics;
        if read_back {
            self.gpu.download(&mut sim.state);
            if let Some(bonds) = sim.state.bonds.as_mut() {
                self.gpu.download_bond_state(bonds);
            }
            if let Some((tension, report)) = self.gpu.constraint_state() {
                sim.constraints.tension = tension;
                sim.constraints.iterations = report.sweeps;
            }
        }
        if let Err(GpuHalt::Reach { .. }) = outcome {
            // A face outgrew the contact search (src/gpu/contact.rs): the
            // backend is built anew from this state, with the reach of its
            // faces now, and the run goes on.
            *self = GpuSteps::new(sim, &self.context)?;
            return Ok(taken);
        }
        if let (Err(GpuHalt::Formation { .. }), Some(clock)) = (&outcome, taken.last) {
            // The device left the last step's `bind` formation to the host
            // (src/gpu/bind.rs): decided here from the state read back, then
            // a backend with the formed bonds in its rows and an empty pool.
            sim.kinetics.host_formations += 1;
            let (events, _) = sim.bind_on_host(clock)?;
            sim.record_events(&events, clock.length)?;
            sim.backend.cpu.invalidate();
            // The new backend keeps the neighbour capacity this one needed.
            let met = self.gpu.neighbors_met();
            *self = GpuSteps::new(sim, &self.context)?;
            self.gpu.reserve_neighbors(met).map_err(RunError::Setup)?;
            return Ok(taken);
        }
        if let Err(GpuHalt::Capacity { message, .. }) = outcome {
            return Err(RunError::Setup(format!("device gpu at step {}: {message}", sim.state.step)));
        }
        if let Err(GpuHalt::Blowup { particle, .. }) = outcome {
            sim.refresh_cpu_forces(false)?;
            let what = format!(
                "its GPU step was non-finite or longer than max_displacement {:e} (force here {:e})",
                sim.settings.integrator.common().max_displacement,
                sim.backend.forces.forces[particle].length()
            );
            return Err(sim.blowup(particle, what));
        }
        if read_back {
            sim.check_in_box()?;
        }
        // As on the CPU, bond kinetics (one step per segment) are decided from
        // the tensions before the step (measured at the end of the previous
        // one), then measured again at the new positions with the new bond state.
        self.resets = sim.kinetics.engine.resets;
        Ok(taken)
    }

    fn bonds_changed(&mut self, sim: &mut Simulation, changed: bool) -> Result<(), RunError> {
        if !sim.backend.cpu.is_built() {
            // Bonds formed: both backends are rebuilt for the new bond list.
            sim.ensure_forces()?;
            let (model, state, sim_box) = (&sim.model, &sim.state, &sim.sim_box);
            self.gpu = GpuBackend::with_protocol(&self.context, model, state, sim_box, &self.settings, None, &self.protocol)
                .map_err(RunError::Setup)?;
        } else if changed || self.evolving || sim.kinetics.engine.resets != self.resets {
            self.gpu.update_bonds(&sim.model, &sim.state, changed).map_err(RunError::Setup)?;
        }
        let backend = sim.backend.cpu.get(&sim.model, &sim.state, &sim.sim_box, sim.settings.neighbor.skin)?;
        backend.measure_bonds(&sim.model, &sim.state, &sim.sim_box);
        Ok(())
    }

    fn before_outputs(&mut self, sim: &mut Simulation, until: u64, last: u64, due: bool) -> Result<(), RunError> {
        if due || sim.state.step == until {
            sim.refresh_cpu_forces(due || sim.state.step == last)?;
        }
        Ok(())
    }

    fn after_outputs(&mut self, sim: &mut Simulation) -> Result<(), RunError> {
        if self.stopping {
            // The positions of this sync were read back above.
            sim.stop_if_requested()?;
        }
        Ok(())
    }

    fn decides_kinetics(&self) -> bool {
        self.device_kinetics
    }
}

impl GpuSteps {
    /// The events the device decided in the segment whose steps `clocks`
    /// describe: counted, applied to the host's bound flags and recorded
    /// step by step (so each step's dump sees its own bond state), with the
    /// coarse-step warnings; the CPU backend's exclusions follow.
    fn record_device_kinetics(&mut self, sim: &mut Simulation, clocks: &[StepClock]) -> Result<(), RunError> {
        let decided = self.gpu.drain_kinetics();
        for &(t, step, rate_dt) in &decided.coarse {
            if let Some(warning) = sim.kinetics.engine.warn_coarse(&sim.model, t, step, rate_dt) {
                eprintln!("{warning}");
            }
        }
        let Some(first) = clocks.first().map(|c| c.step) else { return Ok(()) };
        let mut formed = false;
        for group in decided.events.chunk_by(|a, b| a.step == b.step) {
            let clock = clocks[(group[0].step - first) as usize];
            let mut events = Vec::with_capacity(group.len());
            for e in group {
                events.push(match e.formed {
                    Some((t, particles)) => {
                        formed = true;
                        let (model, state) = (&mut sim.model, &mut sim.state);
                        sim.kinetics.engine.apply_formed(model, state, e.bond, t, particles, clock, e.length).map_err(RunError::Setup)?
                    }
                    None => sim.kinetics.engine.apply_decided(&sim.model, &mut sim.state, e.bond, e.kind, clock, e.force, e.length, e.age),
                });
            }
            sim.record_events(&events, clock.length)?;
        }
        if formed {
            // New bonds: the CPU backend is built anew where it is next needed.
            sim.backend.cpu.invalidate();
        } else if !decided.events.is_empty() {
            let backend = sim.backend.cpu.get(&sim.model, &sim.state, &sim.sim_box, sim.settings.neighbor.skin)?;
            backend.bonds_changed(&sim.model, &sim.state, &sim.sim_box).map_err(RunError::Setup)?;
        }
        Ok(())
    }
}

impl Simulation {
    /// Why the next `run` cannot use the GPU backend: the first feature in
    /// use that only the CPU backend has (None when the GPU can run it).
    pub fn cpu_only_feature(&self) -> Option<&'static str> {
        if let Some(why) = self.implicit_refusal() {
            Some(why)
        } else if let Some(why) = self.constraint_refusal() {
            Some(why)
        } else if self.settings.integrator.common().theta != 1.0 {
            Some(THETA_ON_CPU)
        } else if self.model.has_cpu_only_surface_terms() {
            Some(CUSTOM_SURFACE_TERMS)
        } else if self.model.has_nodal_pressure_tetras() {
            Some(NODAL_PRESSURE_TETRA)
        } else if self.model.max_pair_cutoff() > 0.0
            && crate::neighbor::ImageShifts::has_short_edges(&self.sim_box, self.model.max_pair_cutoff() + self.settings.neighbor.skin)
        {
            Some(SHORT_PERIODIC_EDGES)
        } else {
            None
        }
    }

    /// The GPU backend's step settings: the step context and the neighbour list's.
    pub fn step_settings(&self) -> StepSettings {
        StepSettings {
            context: self.step_context(),
            skin: self.settings.neighbor.skin,
            neighbor_every: self.settings.neighbor.every,
            neighbor_check: self.settings.neighbor.check,
        }
    }

    /// `minimize` on the device (src/gpu/fire.rs) where the run would use
    /// the GPU and FIRE can run there: the iterations in segments of
    /// [`GPU_SYNC_STEPS`], then the positions read back and the verdict, max
    /// |F| and energy from the CPU's f64 forces there (masked as the CPU's
    /// FIRE masks them). None: the CPU minimises.
    pub(super) fn minimize_on_gpu(&mut self, settings: &FireSettings) -> Result<Option<FireReport>, RunError> {
        let device = self.options.device.unwrap_or(self.settings.device);
        if device == DevicePreference::Cpu {
            return Ok(None);
        }
        // Only what the forces need decides (not the integrator's or the constraints' refusals).
        if self.model.has_cpu_only_surface_terms() {
            self.options.say(&format!("minimize on the CPU: {CUSTOM_SURFACE_TERMS}"));
            return Ok(None);
        }
        if self.model.has_nodal_pressure_tetras() {
            self.options.say(&format!("minimize on the CPU: {NODAL_PRESSURE_TETRA}"));
            return Ok(None);
        }
        let Some(context) = self.open_gpu(device)? else { return Ok(None) };
        let mut gpu = self.fire_backend(&context, settings)?;
        // The counts of the backends before this one (see `Reach` below).
        let (mut iterations, mut clamped, mut before) = (0, 0, (0, 0));
        while iterations < settings.max_iterations {
            let segment = (settings.max_iterations - iterations).min(GPU_SYNC_STEPS);
            let outcome = gpu.run(self.state.step, segment);
            let (now, shortened) = gpu.fire_counts().unwrap_or_default();
            (iterations, clamped) = (before.0 + now, before.1 + shortened);
            match outcome {
                Ok(done) if done == segment => {}
                Ok(_) => break,
                Err(GpuHalt::Reach { .. }) => {
                    // A face outgrew the contact search (src/gpu/contact.rs): FIRE
                    // goes on from this state on a backend built with the faces'
                    // reach now, from rest (v = 0, Δt₀, α₀), as a new `minimize` would.
                    gpu.download(&mut self.state);
                    before = (iterations, clamped);
                    gpu = self.fire_backend(&context, settings)?;
                }
                Err(GpuHalt::Blowup { particle, .. }) => {
                    gpu.download(&mut self.state);
                    self.backend.forces_current = false;
                    return Err(self.blowup(particle, "non-finite FIRE move on the GPU during minimisation".into()));
                }
                Err(GpuHalt::Capacity { message, .. }) => return Err(RunError::Setup(format!("device gpu: minimize: {message}"))),
                // No `bind` runs in a device minimisation; should one halt it, say so rather than panic.
                Err(halt) => return Err(RunError::Setup(format!("device gpu: minimize stopped: {halt:?}"))),
            }
        }
        gpu.download(&mut self.state);
        self.backend.forces_current = false;
        self.ensure_forces()?;
        let mut forces = self.backend.forces.forces.clone();
        self.protocols.mask(&mut forces);
        let max_force = max_residual_force(&forces, &self.fire_masses());
        let energy = self.backend.forces.total_energy();
        Ok(Some(FireReport { converged: max_force < settings.ftol, iterations, energy, max_force, clamped }))
    }

    /// A GPU backend at the current state that takes FIRE iterations, with
    /// the protocols' held axes only (a minimisation takes no step, so
    /// nothing moves or ramps).
    fn fire_backend(&self, context: &GpuContext, settings: &FireSettings) -> Result<GpuBackend, RunError> {
        let full = self.protocols.for_device(&self.model);
        let held = full.held.into_iter().map(|h| HeldCoordinates { mover: None, ..h }).collect();
        let protocol = DeviceProtocol { held, ..Default::default() };
        let (model, state, sim_box) = (&self.model, &self.state, &self.sim_box);
        let mut gpu =
            GpuBackend::with_protocol(context, model, state, sim_box, &self.step_settings(), None, &protocol).map_err(RunError::Setup)?;
        gpu.minimize_with_fire(context, model, settings, self.settings.dt).map_err(RunError::Setup)?;
        Ok(gpu)
    }

    /// Why the constraints cannot be projected on the device (src/gpu/shake.rs).
    fn constraint_refusal(&self) -> Option<&'static str> {
        (!self.constraints.list.is_empty()).then(|| crate::gpu::shake::refusal(&self.model, &self.constraints)).flatten()
    }

    /// Why the implicit step cannot run on the device (src/gpu/implicit.rs).
    fn implicit_refusal(&self) -> Option<&'static str> {
        match &self.settings.integrator {
            Integrator::Implicit(..) => crate::gpu::implicit::refusal(&self.model),
            Integrator::Overdamped(_) => None,
        }
    }

    /// The GPU to run on, per the effective `device` setting (None: the CPU).
    /// The adapter is opened once and announced.
    pub(super) fn gpu_for_run(&mut self) -> Result<Option<GpuContext>, RunError> {
        let device = self.options.device.unwrap_or(self.settings.device);
        if device == DevicePreference::Cpu {
            return Ok(None);
        }
        if let Some(why) = self.cpu_only_feature() {
            return match device {
                DevicePreference::Gpu => Err(RunError::Setup(format!("device gpu: {why}; use `device cpu` or `device auto`"))),
                _ => {
                    self.options.say(&format!("device auto: {why}; running on the CPU"));
                    Ok(None)
                }
            };
        }
        self.open_gpu(device)
    }

    /// The adapter of `device` (gpu or auto), opened once and announced;
    /// None where `device auto` found no hardware adapter.
    fn open_gpu(&mut self, device: DevicePreference) -> Result<Option<GpuContext>, RunError> {
        let opened = match self.backend.gpu.take() {
            Some(opened) => opened,
            None => {
                let opened = GpuContext::open(device == DevicePreference::Auto);
                match &opened {
                    Ok(context) => self.options.say(&format!("device: GPU {}", context.describe())),
                    Err(e) if device == DevicePreference::Auto => self.options.say(&format!("device auto: {e}; running on the CPU")),
                    Err(_) => {}
                }
                opened
            }
        };
        match self.backend.gpu.insert(opened) {
            Ok(context) => Ok(Some(context.clone())),
            Err(_) if device == DevicePreference::Auto => Ok(None),
            Err(e) => Err(RunError::Setup(format!("device gpu: {e}"))),
        }
    }
}
