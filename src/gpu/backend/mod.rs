//! Buffers, pipelines and the GPU-resident step loop.
//!
//! [`GpuBackend::run`] encodes `steps` steps — neighbour check and rebuild
//! (indirect dispatches sized on the GPU), forces, integration, commit —
//! and reads back only the status words at the end. Overflow of the
//! neighbour list halts the remaining kernels; the host grows the list and
//! resumes from the last completed step, so the result is the same as with a
//! large enough list. A refused step (blow-up) halts too, leaving the state
//! of the last completed step in place.
//!
//! Surface (body) terms run in their own passes before the force pass
//! ([`super::surface`]); a body wider than half the periodic box halts the
//! run ([`GpuHalt::Capacity`], with the body named).
//!
//! Bond kinetics are decided on the device where the model allows it
//! ([`GpuBackend::with_device_kinetics`], [`super::kinetics`]); otherwise on
//! the host from the read-back positions, and
//! [`GpuBackend::update_bonds`] then uploads the new bond state (bound bonds,
//! their rest lengths and scales, the exclusions of the bound bonds) as one
//! batch and has the neighbour list rebuilt.
//!
//! A step is encoded phase by phase (src/gpu/step.rs): the backend asks
//! each step feature it composes — the neighbour list, the force passes,
//! contact, the protocols, the device kinetics, in that order — for its
//! kernels of the phase, and encodes the move (explicit, implicit or FIRE),
//! the constraints' projection, the commit and the step counter itself.
//! Here: the struct, the run loop and its halts; `build.rs`: packing and
//! compiling; `list.rs`: the host's side of the neighbour list;
//! `readback.rs`: reading buffers back; `profile.rs`: timing the phases.

use super::adhesion::AdhesionPack;
use super::contact::{reach_message, ContactPack, ContactPasses, FRACTION_SLOTS};
use super::context::{GpuContext, WORKGROUP};
use super::fire::DeviceFire;
use super::forces::ForcePasses;
use super::implicit::ImplicitSolver;
use super::kinetics::DeviceKinetics;
use super::neighbours::NeighbourList;
use super::pack::{FixedPoint, Params};
use super::prelude::implicit_split::HALT_BUDGET;
use super::prelude::status::*;
use super::protocol::{DeviceProtocol, ProtocolKernels, ProtocolPack, RAMP_ROWS};
use super::shake::DeviceShake;
use super::step::{Dispatcher, Over, Phase, StepFeature};
use crate::integrate::constraints::Constraints;
use crate::integrate::context::StepContext;
use crate::integrate::fire::FireSettings;
use crate::integrate::implicit::ImplicitSettings;
use crate::system::{Model, SimBox, State};
use build::words;
use glam::DVec3;

mod build;
mod list;
mod profile;
mod readback;

/// Steps per command buffer.
const STEPS_PER_SUBMIT: u64 = 64;

/// How a run on the GPU stopped early.
#[derive(Clone, Debug, PartialEq)]
pub enum GpuHalt {
    /// The step of `particle` (internal index) was refused at `step`; the
    /// state is that of `step`.
    Blowup { step: u64, particle: usize },
    /// The neighbour list had to grow beyond what the adapter can bind, or a
    /// body spans more than half the periodic box, or the implicit step's
    /// solve did not converge; the state is that of `step`.
    Capacity { step: u64, message: String },
    /// A face of a contact body outgrew the contact search, whose reach is
    /// set when the backend is built; the state is that of `step`.
    Reach { step: u64 },
    /// The formation of the step before `step` might have overflowed the
    /// device's bond pool, slots or candidate list, or its neighbour list
    /// overflowed, so the device bound nothing in it (src/gpu/bind.rs); the
    /// state, breaks and rebinds are those of `step`.
    Formation { step: u64 },
}

/// Settings the kernels need besides the model.
#[derive(Clone, Copy, Debug)]
pub struct StepSettings {
    /// The run's step context: dt, kT, seed, noise kind and displacement
    /// bound (the steps are counted by [`GpuBackend::run`]'s caller).
    pub context: StepContext,
    pub skin: f64,
    pub neighbor_every: u64,
    pub neighbor_check: bool,
}

/// The GPU force engine and integrator for one model: the step features it
/// composes, the buffers they share and the host's bookkeeping.
pub struct GpuBackend {
    ctx: GpuContext,
    params: Params,
    sim_box: SimBox,
    fixed: FixedPoint,
    buffers: MainBuffers,
    bindings: Bindings,
    /// The explicit step's move, commit and step counter (integrate.wgsl).
    step: StepKernels,
    /// The neighbour list (src/gpu/neighbours.rs).
    list: NeighbourList,
    /// Surface, volume, pair, bonded and external forces (src/gpu/forces.rs).
    forces: ForcePasses,
    settings: StepSettings,
    /// The user id of each packed body (for the span halt's message).
    body_ids: Vec<u64>,
    /// Read-backs so far (each waits for the GPU): tests count the synchronisations.
    reads: std::cell::Cell<u64>,
    /// Simulated time at the next step (see [`GpuBackend::set_time`]).
    time: f64,
    /// What the model asks of the device beyond pair, bond and surface forces.
    features: Features,
}

/// The explicit step's kernels: the move, the commit of the new positions
/// (after the move of any integrator but FIRE's) and the step counter.
struct StepKernels {
    integrate: wgpu::ComputePipeline,
    commit: wgpu::ComputePipeline,
    advance: wgpu::ComputePipeline,
}

impl StepFeature for StepKernels {
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        if phase == Phase::Move {
            at.dispatch(pass, &self.integrate, Over::Particles);
        }
    }
}

/// The buffers of the main bind group (shaders/common/layout.wgsl), in binding order.
struct MainBuffers {
    uniform: wgpu::Buffer,
    state: wgpu::Buffer,
    next: wgpu::Buffer,
    reference: wgpu::Buffer,
    topo: wgpu::Buffer,
    fparams: wgpu::Buffer,
    cell_count: wgpu::Buffer,
    cell_data: wgpu::Buffer,
    force: wgpu::Buffer,
    status: wgpu::Buffer,
    /// Face, body and corner-slot values of the surface terms.
    surf: wgpu::Buffer,
    /// Bond kinetics on the device (src/gpu/kinetics.rs; binding 13).
    kin: wgpu::Buffer,
    /// The run's protocols (src/gpu/protocol.rs; binding 14).
    protocol: wgpu::Buffer,
}

impl MainBuffers {
    fn in_binding_order(&self) -> [&wgpu::Buffer; 13] {
        let b = self;
        [
            &b.uniform,
            &b.state,
            &b.next,
            &b.reference,
            &b.topo,
            &b.fparams,
            &b.cell_count,
            &b.cell_data,
            &b.force,
            &b.status,
            &b.surf,
            &b.kin,
            &b.protocol,
        ]
    }
}

/// The main bind group and its layout.
struct Bindings {
    layout: wgpu::BindGroupLayout,
    main: wgpu::BindGroup,
}

/// The device features a model may use, each owning its layout and kernels.
struct Features {
    /// The contact bodies' faces and rules (src/gpu/contact.rs).
    contact: ContactPack,
    /// The fraction of dt each step of the last `run` took (with contact).
    fractions: Vec<f32>,
    /// The area-weighted contact rules (src/gpu/adhesion.rs).
    adhesion: AdhesionPack,
    /// The contact and area-weighted contact passes.
    contact_passes: ContactPasses,
    /// Bond kinetics on the device (src/gpu/kinetics.rs): its layout and kernels.
    kinetics: Option<DeviceKinetics>,
    /// The run's protocols (src/gpu/protocol.rs): their layout, and their kernels.
    protocol: Option<ProtocolPack>,
    protocol_kernels: ProtocolKernels,
    /// The implicit step on the device (src/gpu/implicit.rs), in place of `integrate`.
    implicit: Option<ImplicitSolver>,
    /// The constraints' projection after each step (src/gpu/shake.rs).
    shake: Option<DeviceShake>,
    /// FIRE iterations in place of steps (src/gpu/fire.rs).
    fire: Option<DeviceFire>,
}

impl GpuBackend {
    /// Uploads the model and state and compiles the kernels.
    pub fn new(ctx: &GpuContext, model: &Model, state: &State, sim_box: &SimBox, settings: &StepSettings) -> Result<Self, String> {
        Self::build(ctx, model, state, sim_box, settings, None, None)
    }

    /// As [`Self::new`] (or [`Self::with_device_kinetics`] with `warned`),
    /// with the run's protocols on the device (src/gpu/protocol.rs).
    pub fn with_protocol(
        ctx: &GpuContext,
        model: &Model,
        state: &State,
        sim_box: &SimBox,
        settings: &StepSettings,
        warned: Option<&[bool]>,
        protocol: &DeviceProtocol,
    ) -> Result<Self, String> {
        if let Some(why) = warned.and_then(|_| super::kinetics::refusal(model)) {
            return Err(format!("bond kinetics on the device: {why} is decided on the host"));
        }
        Self::build(ctx, model, state, sim_box, settings, warned, Some(protocol))
    }

    /// As [`Self::new`], with the bond kinetics decided on the device
    /// (src/gpu/kinetics.rs; the model must pass its `refusal`); `warned`:
    /// the bond types already warned about a coarse step.
    pub fn with_device_kinetics(
        ctx: &GpuContext,
        model: &Model,
        state: &State,
        sim_box: &SimBox,
        settings: &StepSettings,
        warned: &[bool],
    ) -> Result<Self, String> {
        if let Some(why) = super::kinetics::refusal(model) {
            return Err(format!("bond kinetics on the device: {why} is decided on the host"));
        }
        Self::build(ctx, model, state, sim_box, settings, Some(warned), None)
    }

    /// Steps by the linearly implicit step on the device from now on, in
    /// place of the explicit one (src/gpu/implicit.rs; the model must pass
    /// its `refusal`).
    pub fn step_implicitly(
        &mut self,
        ctx: &GpuContext,
        model: &Model,
        settings: &StepSettings,
        implicit: &ImplicitSettings,
        constrained: &[[u32; 2]],
    ) -> Result<(), String> {
        let context = (settings.context.dt, settings.context.kt);
        self.features.implicit = Some(ImplicitSolver::new(ctx, &self.bindings.layout, model, context, implicit, constrained)?);
        self.implicit_list_check()
    }

    /// Projects the constrained bonds after every step from now on
    /// (src/gpu/shake.rs; the run must pass its `refusal`). Returns the
    /// tolerance the device projects to.
    pub fn constrain_bonds(&mut self, ctx: &GpuContext, model: &Model, constraints: &Constraints) -> Result<f64, String> {
        let shake = DeviceShake::new(ctx, &self.bindings.layout, model, constraints)?;
        let tolerance = shake.tolerance;
        self.features.shake = Some(shake);
        Ok(tolerance)
    }

    /// Takes FIRE iterations in place of steps from now on (`minimize`,
    /// src/gpu/fire.rs): each
    /// [`Self::run`] step is one iteration, and a run ends early when max |F|
    /// falls below `settings.ftol`. `dt`: the deck's timestep (Δt₀, masses γ·Δt₀).
    pub fn minimize_with_fire(&mut self, ctx: &GpuContext, model: &Model, settings: &FireSettings, dt: f64) -> Result<(), String> {
        self.features.fire = Some(DeviceFire::new(ctx, &self.bindings.layout, model, settings, dt, WORKGROUP)?);
        Ok(())
    }

    /// Whether the implicit step's CG is split over every workgroup (src/gpu/implicit_split.rs).
    pub fn implicit_is_split(&self) -> bool {
        self.features.implicit.as_ref().is_some_and(ImplicitSolver::is_split)
    }

    /// The adapter this backend runs on.
    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    /// Caps the workgroups per dispatch along x (the adapter's limit, at most
    /// 65 535, by default); wider dispatches are split along y. Lowering it
    /// exercises the split on small systems.
    pub fn limit_dispatch_width(&mut self, groups: u32) {
        self.params.step.groups_x = groups.clamp(1, self.params.step.groups_x);
    }

    fn reset_status(&self, force_rebuild: bool) {
        let mut status = [0u32; STATUS_WORDS];
        status[ST_BLOWUP_PARTICLE] = NO_PARTICLE;
        status[ST_SPAN_BODY] = NO_PARTICLE;
        status[ST_FORCE_REBUILD] = force_rebuild as u32;
        status[ST_FRACTION] = 1f32.to_bits();
        status[ST_ELAPSED] = 0f32.to_bits();
        self.ctx.queue.write_buffer(&self.buffers.status, 0, words(&status));
    }

    /// Sets the simulated time of the next step (`t` of externals with
    /// expression parameters); `run` advances it by dt per step taken.
    pub fn set_time(&mut self, time: f64) {
        self.time = time;
        self.set_clock(time);
    }

    /// The ramps' values, one row per step in the protocol's ramp order, from
    /// `first_step`: they must cover every step of the next [`Self::run`]
    /// (src/gpu/protocol.rs; nothing without ramps).
    pub fn set_ramps(&mut self, first_step: u64, rows: Vec<Vec<f64>>) {
        if let Some(pack) = &mut self.features.protocol {
            pack.set_values(first_step, rows);
        }
    }

    /// Starts the drives of the next [`Self::run`] (src/gpu/protocol.rs):
    /// per driven indenter (in the protocol's order) its centres from the
    /// current one, one per step of the run and one, and whether it holds.
    pub fn set_drives(&mut self, drives: Vec<(Vec<DVec3>, bool)>) {
        if let Some(pack) = &mut self.features.protocol {
            pack.set_drives(drives);
        }
    }

    /// Per driven indenter: how many steps of the last [`Self::run`] moved
    /// it, and whether it holds now.
    pub fn drive_states(&self) -> Vec<(u64, bool)> {
        self.features.protocol.as_ref().map_or_else(Vec::new, ProtocolPack::drive_states)
    }

    /// Writes `time` into the parameters as an f32 high part and remainder.
    fn set_clock(&mut self, time: f64) {
        let high = time as f32;
        self.params.clock[0] = high;
        self.params.clock[1] = (time - high as f64) as f32;
    }

    fn write_params(&self) {
        self.ctx.queue.write_buffer(&self.buffers.uniform, 0, words(&[self.params]));
    }

    /// What the features dispatch through.
    fn dispatcher(&self) -> Dispatcher<'_> {
        Dispatcher { params: &self.params, main: &self.bindings.main, list: &self.list.storage }
    }

    /// The step features in the order their kernels of a phase are encoded.
    fn step_features(&self) -> impl Iterator<Item = &dyn StepFeature> {
        let kinetics = self.features.kinetics.as_ref().map(|k| k as &dyn StepFeature);
        let shake = self.features.shake.as_ref().map(|s| s as &dyn StepFeature);
        let composed: [&dyn StepFeature; 4] = [&self.list, &self.forces, &self.features.contact_passes, &self.features.protocol_kernels];
        composed.into_iter().chain(kinetics).chain(shake)
    }

    /// The integrator in force: FIRE iterations (src/gpu/fire.rs), the
    /// implicit step (src/gpu/implicit.rs), or the explicit step.
    fn mover(&self) -> &dyn StepFeature {
        match (&self.features.fire, &self.features.implicit) {
            (Some(fire), _) => fire,
            (None, Some(solver)) => solver,
            (None, None) => &self.step,
        }
    }

    /// Encodes one neighbour check/rebuild and force pass, and optionally the
    /// integration of one step. `checked_after_last`: the list was checked
    /// after the last step's `commit` in this submission (`bind` on the
    /// device), which was this step's check; only its overflow halt remains.
    fn encode_step(&self, pass: &mut wgpu::ComputePass, integrate: bool, checked_after_last: bool) {
        let at = self.dispatcher();
        let encode = |phase: Phase, pass: &mut wgpu::ComputePass| self.step_features().for_each(|f| f.encode(phase, &at, pass));
        at.bind_main(pass);
        if integrate {
            encode(Phase::Start, pass);
        }
        encode(Phase::Neighbours { checked_after_last }, pass);
        encode(Phase::Forces, pass);
        if !integrate {
            return;
        }
        encode(Phase::BeforeMove, pass);
        self.mover().encode(Phase::Move, &at, pass);
        encode(Phase::Constrain, pass);
        if self.features.fire.is_none() {
            at.dispatch(pass, &self.step.commit, Over::Particles);
        }
        encode(Phase::AfterCommit, pass);
        at.dispatch(pass, &self.step.advance, Over::Groups(1));
        encode(Phase::End, pass);
    }

    /// The message of a body-span halt (see [`super::surface`]) or of a
    /// face that outgrew the contact search ([`super::contact`]), if there was one.
    fn span_halt(&self, status: &[u32; STATUS_WORDS]) -> Option<String> {
        if status[ST_HALTED] & HALT_REACH != 0 {
            return Some(reach_message(self.features.contact.edge_bound()));
        }
        (status[ST_HALTED] & HALT_SPAN != 0).then(|| super::surface::span_message(self.body_ids[status[ST_SPAN_BODY] as usize]))
    }

    /// Whether node–face contact runs ([`super::contact`]).
    fn has_contact(&self) -> bool {
        self.features.contact.faces() > 0
    }

    /// The fraction of dt step `k` of the last [`Self::run`] took (below 1
    /// where the contact step clamp shortened it; 1 without contact).
    pub fn step_fraction(&self, k: u64) -> f64 {
        self.features.fractions.get(k as usize).map_or(1.0, |&s| f64::from(s))
    }

    /// The simulated time the first `steps` steps of the last [`Self::run`]
    /// took: each step its own fraction of dt.
    fn elapsed(&self, steps: u64) -> f64 {
        (0..steps).map(|k| self.step_fraction(k)).sum::<f64>() * self.settings.context.dt
    }

    /// Forces at the current state (neighbour list rebuilt first); an error
    /// if the neighbour list cannot grow to hold every neighbour.
    pub fn evaluate(&mut self) -> Result<(), String> {
        loop {
            self.list.pending_rebuild = false;
            self.reset_status(true);
            self.set_clock(self.time);
            self.write_params();
            let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
            {
                let mut pass = encoder.begin_compute_pass(&Default::default());
                self.encode_step(&mut pass, false, false);
            }
            self.ctx.queue.submit([encoder.finish()]);
            let status = self.status();
            self.list.builds += status[ST_BUILDS] as u64;
            if let Some(message) = self.span_halt(&status) {
                return Err(message);
            }
            if !self.grow_if_overflowed(&status)? {
                return Ok(());
            }
        }
    }

    /// Runs `steps` steps from step number `first_step`, GPU-resident.
    /// Returns the number of steps done (all of them unless halted).
    pub fn run(&mut self, first_step: u64, steps: u64) -> Result<u64, GpuHalt> {
        let mut done = 0u64;
        let mut force_rebuild = std::mem::take(&mut self.list.pending_rebuild);
        self.features.fractions.clear();
        while done < steps {
            let step = first_step + done;
            // With contact, the ring of step fractions bounds a chunk.
            let most = if self.has_contact() { FRACTION_SLOTS as u64 } else { u32::MAX as u64 / 2 };
            // With ramps or drives, so do the tables of their values (src/gpu/protocol.rs).
            let ramped = self.features.protocol.as_ref().is_some_and(ProtocolPack::ramps);
            let driven = self.features.protocol.as_ref().is_some_and(ProtocolPack::drives);
            let chunk = (steps - done).min(if ramped || driven { most.min(RAMP_ROWS) } else { most });
            if let Some(pack) = self.features.protocol.as_mut() {
                if ramped {
                    let rows = pack.rows(step, chunk);
                    self.ctx.queue.write_buffer(&self.buffers.protocol, 4 * pack.fields[5] as u64, words(&rows));
                }
                for (at, data) in pack.drive_words(chunk) {
                    self.ctx.queue.write_buffer(&self.buffers.protocol, 4 * at as u64, words(&data));
                }
                self.params.protocol = pack.fields;
            }
            self.params.step.step_lo = step as u32;
            self.params.step.step_hi = (step >> 32) as u32;
            self.params.sizes.steps_wanted = chunk as u32;
            self.set_clock(self.time + self.elapsed(done));
            self.write_params();
            self.reset_status(force_rebuild);
            let binds = self.features.kinetics.as_ref().is_some_and(|k| k.layout.binds());
            let mut encoded = 0;
            while encoded < chunk {
                let batch = (chunk - encoded).min(STEPS_PER_SUBMIT);
                let mut encoder = self.ctx.device.create_command_encoder(&Default::default());
                {
                    let mut pass = encoder.begin_compute_pass(&Default::default());
                    for k in 0..batch {
                        // With `bind` on the device the list is checked after each
                        // step's `commit`, for the next step: the chunk's first step checks it.
                        self.encode_step(&mut pass, true, binds && encoded + k > 0);
                    }
                }
                self.ctx.queue.submit([encoder.finish()]);
                encoded += batch;
            }
            let status = self.status();
            self.list.builds += status[ST_BUILDS] as u64;
            done += status[ST_STEPS_DONE] as u64;
            if driven {
                let (at, count) = self.features.protocol.as_ref().map(ProtocolPack::drive_state_range).expect("drives");
                let state: Vec<u32> = bytemuck::cast_slice(&self.read_at(&self.buffers.protocol, 4 * at as u64, 4 * count as u64)).to_vec();
                self.features.protocol.as_mut().expect("drives").follow_drives(&state);
            }
            // A rebuild the last step asked for (device kinetics changed the exclusions) carries over.
            let requested = status[ST_FORCE_REBUILD] != 0;
            self.list.pending_rebuild = requested;
            if self.has_contact() && status[ST_STEPS_DONE] > 0 {
                let ring = 16 * self.params.contact[15] as u64;
                let entries: Vec<[f32; 4]> =
                    bytemuck::cast_slice(&self.read_at(&self.buffers.surf, ring, 16 * status[ST_STEPS_DONE] as u64)).to_vec();
                self.features.fractions.extend(entries.iter().map(|e| e[0]));
            }
            if status[ST_HALTED] & HALT_CONVERGED != 0 {
                // FIRE converged (src/gpu/fire.rs): no further iteration.
                break;
            }
            if status[ST_HALTED] & HALT_BLOWUP != 0 {
                return Err(GpuHalt::Blowup { step: first_step + done, particle: status[ST_BLOWUP_PARTICLE] as usize });
            }
            if status[ST_HALTED] & HALT_REACH != 0 {
                return Err(GpuHalt::Reach { step: first_step + done });
            }
            if status[ST_HALTED] & HALT_FORMATION != 0 {
                self.list.overflow_met = self.list.overflow_met.max(status[ST_OVERFLOW_NEED]);
                return Err(GpuHalt::Formation { step: first_step + done });
            }
            if let Some(message) = self.span_halt(&status) {
                return Err(GpuHalt::Capacity { step: first_step + done, message });
            }
            if let Some(split) =
                self.features.implicit.as_mut().and_then(ImplicitSolver::split_mut).filter(|_| status[ST_HALTED] & HALT_BUDGET != 0)
            {
                // The step that ran out of iterations moved nothing: take it again with a larger budget.
                split.grow();
            }
            if let Some(solver) = self.features.implicit.as_ref().filter(|_| status[ST_HALTED] & HALT_SOLVE != 0) {
                let message = solver.failure(&self.implicit_report().unwrap_or_default());
                return Err(GpuHalt::Capacity { step: first_step + done, message });
            }
            if let Some(shake) = self.features.shake.as_ref().filter(|_| status[ST_HALTED] & HALT_CONSTRAINT != 0) {
                let report = self.constraint_state().map(|(_, report)| report).unwrap_or_default();
                // The step the projection failed in is the one after the last done.
                return Err(GpuHalt::Capacity { step: first_step + done, message: shake.failure(&report, first_step + done + 1) });
            }
            if status[ST_HALTED] & HALT_EVENTS != 0 {
                // The event buffer is full: the host drains it and goes on.
                break;
            }
            force_rebuild =
                self.grow_if_overflowed(&status).map_err(|message| GpuHalt::Capacity { step: first_step + done, message })? || requested;
        }
        self.time += self.elapsed(done);
        self.fit_split_budget();
        Ok(done)
    }

    /// After a run: the split solve's budget fitted to the most iterations a
    /// step took, and that count cleared (one small read-back).
    fn fit_split_budget(&mut self) {
        let Some(solver) = self.features.implicit.as_ref().filter(|s| s.is_split()) else { return };
        let bytes = self.read_at(&solver.buffer, solver.report_at, 16);
        self.ctx.queue.write_buffer(&solver.buffer, solver.report_at + 8, &[0; 4]);
        let most = ImplicitSolver::most_iterations(&bytes);
        if most > 0 {
            self.features.implicit.as_mut().and_then(ImplicitSolver::split_mut).expect("a split solve").fit(most);
        }
    }
}
