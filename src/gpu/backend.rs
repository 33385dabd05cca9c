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

use glam::DVec3;
use wgpu::util::DeviceExt;

use super::adhesion::AdhesionPack;
use super::contact::{reach_message, ContactPack, CONTACT_ONLY, FRACTION_SLOTS};
use super::context::{storage_entry, GpuContext, WORKGROUP};
use super::fire::DeviceFire;
use super::implicit::ImplicitSolver;
use super::kinetics::{KinKernels, KinLayout};
use super::nlist::NeighbourStorage;
use super::pack::{cell_grid, pack, FixedPoint, Packed, Params};
use super::prelude::implicit_split::HALT_BUDGET;
use super::prelude::status::*;
use super::protocol::{DeviceProtocol, PackedTerms, ProtocolPack, RAMP_ROWS};
use super::shader;
use super::shake::{DeviceShake, ShakeReport};
use crate::integrate::constraints::Constraints;
use crate::integrate::context::StepContext;
use crate::integrate::fire::FireSettings;
use crate::integrate::implicit::{ImplicitSettings, SolveReport};
use crate::neighbor::{Exclusions, ImageShifts};
use crate::system::{BondState, Model, SimBox, State};

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

/// Seconds per call of each phase of a step, each timed alone
/// ([`GpuBackend::profile`]).
#[derive(Clone, Copy, Debug, Default)]
pub struct PhaseTimes {
    /// Displacement check and rebuild decision (every step).
    pub check: f64,
    /// A full neighbour-list rebuild (binning, scan, scatter, sort, list).
    pub neighbor_build: f64,
    /// Pair, bonded, external and surface forces (the surface passes included).
    pub forces: f64,
    /// Integration (or the implicit step's blocks, solve and moves), commit
    /// and step counter.
    pub integrate: f64,
    /// Reading positions back to the host (thermo, dump, end of run).
    pub readback: f64,
    /// Node–face contact and the step clamp (0 without contact), apart from `forces`.
    pub contact: f64,
    /// The area-weighted contact terms' node and weight passes (0 without them), apart from `contact`.
    pub adhesion: f64,
    /// Bond kinetics decided on the device and `bind` formation (0 without
    /// them; src/gpu/kinetics.rs, src/gpu/bind.rs), at the deck's start.
    pub kinetics: f64,
    /// The constraints' projection (0 without `constrain`; src/gpu/shake.rs).
    pub constraints: f64,
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

struct Kernels {
    /// The neighbour list's check and build (nlist.wgsl).
    list: ListKernels,
    /// The surface terms' passes (surface.wgsl).
    surface: SurfaceKernels,
    forces: wgpu::ComputePipeline,
    integrate: wgpu::ComputePipeline,
    commit: wgpu::ComputePipeline,
    advance: wgpu::ComputePipeline,
    /// Node–face contact and the step clamp (src/gpu/contact.rs).
    contact_forces: wgpu::ComputePipeline,
    /// Volume elements' corner forces (src/gpu/tetra.rs).
    tetra_forces: wgpu::ComputePipeline,
    /// Area-weighted contact's node and weight passes (src/gpu/adhesion.rs).
    adhesion_nodes: wgpu::ComputePipeline,
    adhesion_weights: wgpu::ComputePipeline,
    /// Ramped parameters' values of the step, driven indenters' load check and advance (src/gpu/protocol.rs).
    protocol_ramps: wgpu::ComputePipeline,
    protocol_drive_check: wgpu::ComputePipeline,
    protocol_drive_advance: wgpu::ComputePipeline,
}

/// The neighbour list's kernels.
struct ListKernels {
    displacement: wgpu::ComputePipeline,
    decide: wgpu::ComputePipeline,
    clear: wgpu::ComputePipeline,
    count: wgpu::ComputePipeline,
    scan_blocks: wgpu::ComputePipeline,
    scan_totals: wgpu::ComputePipeline,
    scan_add: wgpu::ComputePipeline,
    scatter: wgpu::ComputePipeline,
    sort: wgpu::ComputePipeline,
    build: wgpu::ComputePipeline,
    after_step: wgpu::ComputePipeline,
    /// The start of a step whose list was checked after the last `commit`: its overflow halt only.
    list_ready: wgpu::ComputePipeline,
}

/// The surface terms' kernels: face, body, edge and node passes, then the gathers.
struct SurfaceKernels {
    faces: wgpu::ComputePipeline,
    bodies: wgpu::ComputePipeline,
    edges: wgpu::ComputePipeline,
    nodes: wgpu::ComputePipeline,
    edge_forces: wgpu::ComputePipeline,
    forces: wgpu::ComputePipeline,
}

/// The GPU force engine and integrator for one model.
pub struct GpuBackend {
    ctx: GpuContext,
    params: Params,
    has_pairs: bool,
    sim_box: SimBox,
    fixed: FixedPoint,
    buffers: MainBuffers,
    bindings: Bindings,
    kernels: Kernels,
    /// The neighbour list and its bookkeeping.
    list: ListState,
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

/// The main bind group, its layout, and the indirect dispatch arguments' group.
struct Bindings {
    layout: wgpu::BindGroupLayout,
    main: wgpu::BindGroup,
    args: wgpu::BindGroup,
    args_buffer: wgpu::Buffer,
}

/// The neighbour list's storage and what the host knows of its builds.
struct ListState {
    storage: NeighbourStorage,
    /// The largest storage binding the neighbour list's chunks may take.
    binding_limit: u64,
    builds: u64,
    grown: u32,
    /// The largest neighbour count of an overflow that did not halt the step (bind.wgsl).
    overflow_met: u32,
    /// The next `run` or `evaluate` rebuilds the neighbour list first.
    pending_rebuild: bool,
}

/// The device features a model may use, each owning its layout and kernels.
struct Features {
    /// The contact bodies' faces and rules (src/gpu/contact.rs).
    contact: ContactPack,
    /// The fraction of dt each step of the last `run` took (with contact).
    fractions: Vec<f32>,
    /// The area-weighted contact rules (src/gpu/adhesion.rs).
    adhesion: AdhesionPack,
    /// Bond kinetics on the device (src/gpu/kinetics.rs): its layout and kernels.
    kinetics: Option<(KinLayout, KinKernels)>,
    /// The run's protocols (src/gpu/protocol.rs): their layout.
    protocol: Option<ProtocolPack>,
    /// The implicit step on the device (src/gpu/implicit.rs), in place of `integrate`.
    implicit: Option<ImplicitSolver>,
    /// The constraints' projection after each step (src/gpu/shake.rs).
    shake: Option<DeviceShake>,
    /// FIRE iterations in place of steps (src/gpu/fire.rs).
    fire: Option<DeviceFire>,
}

/// Refuses a storage buffer the adapter cannot bind (wgpu would abort).
fn check_binding(ctx: &GpuContext, what: &str, bytes: u64) -> Result<(), String> {
    let limit = ctx.limits.max_storage_buffer_binding_size.min(ctx.limits.max_buffer_size);
    if bytes > limit {
        return Err(format!(
            "{what} needs {:.0} MiB, more than the largest storage buffer {} can bind ({:.0} MiB); \
             reduce the particle count, the cutoff or the neighbour skin, use a GPU with a larger limit, or `device cpu`",
            bytes as f64 / 1048576.0,
            ctx.info.name,
            limit as f64 / 1048576.0
        ));
    }
    Ok(())
}

fn words<T: bytemuck::Pod>(data: &[T]) -> &[u8] {
    bytemuck::cast_slice(data)
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

    /// The constraint tensions of the last step (the deck's list order) and
    /// the last projection's report (one small read-back; None without
    /// constraints).
    pub fn constraint_state(&self) -> Option<(Vec<f64>, ShakeReport)> {
        let shake = self.features.shake.as_ref()?;
        let (mut tension, report) = shake.read(&self.read(&shake.buffer, 4 * (shake.count as u64 + 4)));
        if let Some(solver) = self.features.implicit.as_ref().filter(|s| s.constraints > 0) {
            // The implicit step's constraint forces, before SHAKE's (as the CPU sums them).
            let bytes = self.read_at(&solver.buffer, solver.constraints_at, 48 * solver.constraints as u64);
            tension.iter_mut().zip(solver.constraint_tensions(&bytes)).for_each(|(t, implicit)| *t += implicit);
        }
        Some((tension, report))
    }

    /// Takes FIRE iterations in place of steps from now on (`minimize`,
    /// src/gpu/fire.rs): each
    /// [`Self::run`] step is one iteration, and a run ends early when max |F|
    /// falls below `settings.ftol`. `dt`: the deck's timestep (Δt₀, masses γ·Δt₀).
    pub fn minimize_with_fire(&mut self, ctx: &GpuContext, model: &Model, settings: &FireSettings, dt: f64) -> Result<(), String> {
        self.features.fire = Some(DeviceFire::new(ctx, &self.bindings.layout, model, settings, dt, WORKGROUP)?);
        Ok(())
    }

    /// FIRE iterations taken so far and the moves the contact step clamp
    /// shortened (one small read-back; None without FIRE).
    pub fn fire_counts(&self) -> Option<(u64, u64)> {
        let fire = self.features.fire.as_ref()?;
        Some(DeviceFire::counts(&self.read(&fire.buffer, DeviceFire::COUNT_BYTES)))
    }

    /// Whether the implicit step's CG is split over every workgroup (src/gpu/implicit_split.rs).
    pub fn implicit_is_split(&self) -> bool {
        self.features.implicit.as_ref().is_some_and(ImplicitSolver::is_split)
    }

    /// The last implicit step's iterations and relative residual (one small
    /// read-back; None without the implicit step).
    pub fn implicit_report(&self) -> Option<SolveReport> {
        let solver = self.features.implicit.as_ref()?;
        Some(solver.report(&self.read_at(&solver.buffer, solver.report_at, 16)))
    }

    fn build(
        ctx: &GpuContext,
        model: &Model,
        state: &State,
        sim_box: &SimBox,
        settings: &StepSettings,
        device_kinetics: Option<&[bool]>,
        device_protocol: Option<&DeviceProtocol>,
    ) -> Result<Self, String> {
        if model.has_cpu_only_surface_terms() {
            return Err(
                "the GPU backend has no kernels for custom surface terms of bodies (`custom` body lines) yet; use `device cpu`".into()
            );
        }
        if model.max_pair_cutoff() > 0.0 && ImageShifts::has_short_edges(sim_box, model.max_pair_cutoff() + settings.skin) {
            return Err(format!(
                "the GPU backend has no kernels yet for pairs through several periodic images (a periodic box edge shorter \
                 than 2·(pair cutoff + skin) = {}); use `device cpu`",
                2.0 * (model.max_pair_cutoff() + settings.skin)
            ));
        }
        let n = model.len();
        if n == 0 {
            return Err("the GPU backend needs at least one particle".into());
        }
        let contact = ContactPack::new(model, &state.positions, sim_box);
        let adhesion = AdhesionPack::new(model, contact.faces())?;
        let (packed, exclusions, contact_fields, adhesion_fields) =
            pack_state(model, state, settings, device_kinetics.is_some(), &contact, &adhesion)?;
        let kin_words = match (device_kinetics, state.bonds.as_ref()) {
            (Some(warned), Some(bonds)) => {
                let (c, kt) = (settings.context.dt, settings.context.kt);
                Some(KinLayout::pack(model, bonds, &packed, &exclusions, c, kt, warned))
            }
            _ => None,
        };
        let cutoff = model.max_pair_cutoff();
        // The list also serves the contact search (src/gpu/contact.rs).
        let has_pairs = (!model.pair_rules.is_empty() && cutoff > 0.0) || contact.faces() > 0;
        let skin = settings.skin.max(contact.skin());
        // With `bind` on the device, the list also serves the capture search (src/gpu/bind.rs).
        let capture = if kin_words.as_ref().is_some_and(|(_, l)| l.binds()) { super::bind::capture(model) } else { 0.0 };
        let has_pairs = has_pairs || capture > 0.0;
        let range = cutoff.max(contact.reach()).max(capture) + skin;
        let (grid, inv_width) = if has_pairs { cell_grid(sim_box, range, n) } else { ([1, 1, 1], [0.0; 3]) };
        let cells = grid.iter().product::<u32>();
        let scan_blocks = cells.div_ceil(WORKGROUP);
        let lengths = sim_box.lengths();
        let fixed = FixedPoint::for_box(sim_box);
        let box_fixed = [0, 1, 2].map(|a| fixed.encode(lengths[a]));
        let lo_fixed = [0, 1, 2].map(|a| fixed.encode(sim_box.lo[a]));
        let groups_x = ctx.limits.max_compute_workgroups_per_dimension.min(65_535);
        let params = Params {
            box_len_h: [box_fixed[0].0, box_fixed[1].0, box_fixed[2].0, 0],
            box_len_f: [box_fixed[0].1, box_fixed[1].1, box_fixed[2].1, 0],
            box_len: [lengths.x as f32, lengths.y as f32, lengths.z as f32, fixed.q as f32],
            box_lo_h: [lo_fixed[0].0, lo_fixed[1].0, lo_fixed[2].0, 0],
            box_lo_f: [lo_fixed[0].1, lo_fixed[1].1, lo_fixed[2].1, 0],
            periodic: [sim_box.periodic[0] as u32, sim_box.periodic[1] as u32, sim_box.periodic[2] as u32, 0],
            grid: [grid[0], grid[1], grid[2], cells],
            cell_inv_width: [inv_width[0], inv_width[1], inv_width[2], 0.0],
            n: n as u32,
            nlist_cap: initial_capacity(n, sim_box, range, has_pairs),
            n_types: model.type_names.len() as u32,
            steps_wanted: 0,
            range2: (range * range) as f32,
            half_skin2: (0.25 * skin * skin) as f32,
            max_disp2: (settings.context.max_displacement * settings.context.max_displacement) as f32,
            neighbor_every: settings.neighbor_every.max(1) as u32,
            seed_lo: settings.context.seed as u32,
            seed_hi: (settings.context.seed >> 32) as u32,
            step_lo: 0,
            step_hi: 0,
            neighbor_check: settings.neighbor_check as u32,
            scan_blocks,
            groups_x,
            gaussian: (settings.context.noise == crate::rng::Noise::Gaussian) as u32,
            topo_offsets: packed.topo_offsets,
            fparam_offsets: packed.fparam_offsets,
            surface_offsets: packed.surface_offsets,
            contact: contact_fields,
            kin_bonds: kin_words.as_ref().map_or(0, |(_, l)| l.bonds()),
            kin_first_term: kin_words.as_ref().map_or(0, |(_, l)| l.first_term),
            kin_capacity: kin_words.as_ref().map_or(0, |(_, l)| l.capacity),
            kin_types: model.bond_types.len() as u32,
            tetra_offsets: packed.tetra_offsets,
            clock: [0.0, 0.0, settings.context.dt as f32, 0.0],
            special_offsets: packed.special_offsets,
            adhesion: adhesion_fields,
            protocol: [0; 8],
        };
        let device = &ctx.device;
        let init = |label: &str, contents: &[u8], usage: wgpu::BufferUsages| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let rw = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST;
        let zeros = |label: &str, bytes: u64, usage: wgpu::BufferUsages| {
            device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size: bytes.max(16), usage, mapped_at_creation: false })
        };
        let particle_bytes = 3 * 16 * n as u64;
        check_binding(ctx, "the particle state", particle_bytes)?;
        check_binding(ctx, "the cell list", 4 * (cells as u64 + 1 + scan_blocks as u64 + n as u64))?;
        check_binding(ctx, "the topology", 4 * packed.topo.len() as u64)?;
        let uniform = init("params", words(&[params]), wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST);
        let state_buffer = zeros("state", particle_bytes, rw);
        let next = zeros("next", particle_bytes, rw);
        let reference = zeros("reference", particle_bytes, rw);
        let uploads = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let topo = init("topo", words(&pad16(packed.topo)), uploads);
        let fparams = init("fparams", words(&pad16(packed.fparams)), uploads);
        let cell_count = zeros("cell_count", 4 * cells as u64, rw);
        let cell_data = zeros("cell_data", 4 * (cells as u64 + 1 + scan_blocks as u64 + n as u64), rw);
        let nlist_binding_limit = ctx.limits.max_storage_buffer_binding_size.min(ctx.limits.max_buffer_size);
        let nlist = NeighbourStorage::new(ctx, n as u32, params.nlist_cap, nlist_binding_limit)?;
        let force = zeros("force", 16 * n as u64, rw);
        let status = zeros("status", 4 * STATUS_WORDS as u64, rw);
        let surf_bytes = 16 * (packed.surf_entries + contact.surf_entries(n as u32) + adhesion.surf_entries(n as u32));
        check_binding(ctx, "the surface terms' face and body values", surf_bytes)?;
        let surf = zeros("surf", surf_bytes, rw);
        let args = zeros("dispatch_args", 4 * 12, wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT);
        let mut protocol_pack = device_protocol.map(|p| ProtocolPack::new(p, model, settings.context.dt, &fixed));
        let mut params = params;
        let protocol = match &mut protocol_pack {
            Some(pack) => {
                let slots = pack.slots(
                    model,
                    &packed_terms(&packed.fparam_offsets, &packed.own_bonds, packed.first_own_term),
                    state.bonds.as_ref(),
                );
                let at = pack.fields[4] as usize;
                pack.words[at..at + slots.len()].copy_from_slice(&slots);
                params.protocol = pack.fields;
                check_binding(ctx, "the protocols' held coordinates and ramp table", 4 * pack.words.len() as u64)?;
                init("protocol", words(&pad16(pack.words.clone())), rw)
            }
            None => zeros("protocol", 16, rw),
        };
        let kin = match &kin_words {
            Some((words_, _)) => {
                check_binding(ctx, "the bond kinetics' state and event buffer", 4 * words_.len() as u64)?;
                init("kin", words(words_), rw)
            }
            None => zeros("kin", 16, rw),
        };

        let mut entries = vec![wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: false, min_binding_size: None },
            count: None,
        }];
        entries.extend((1..=10).map(|b| storage_entry(b, b == 4)));
        // The neighbour list and its chunk's uniform are bound per chunk (nlist.rs).
        entries[8].ty = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: false },
            has_dynamic_offset: true,
            min_binding_size: None,
        };
        entries.push(wgpu::BindGroupLayoutEntry {
            binding: 11,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer { ty: wgpu::BufferBindingType::Uniform, has_dynamic_offset: true, min_binding_size: None },
            count: None,
        });
        entries.push(storage_entry(12, false));
        entries.push(storage_entry(13, false));
        entries.push(storage_entry(14, false));
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("cellmd main"), entries: &entries });
        let args_layout = device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("cellmd args"), entries: &[storage_entry(0, false)] });
        let args_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cellmd args"),
            layout: &args_layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: args.as_entire_binding() }],
        });
        let mut custom = super::custom::source(model)?;
        custom.mover_cases = device_protocol.map(super::protocol::mover_cases).transpose()?.unwrap_or_default();
        let program = shader::compose_with(&custom);
        let module = device
            .create_shader_module(wgpu::ShaderModuleDescriptor { label: Some("cellmd"), source: wgpu::ShaderSource::Wgsl(program.into()) });
        let main_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cellmd main"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let decide_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("cellmd decide"),
            bind_group_layouts: &[Some(&layout), Some(&args_layout)],
            immediate_size: 0,
        });
        let pipeline = |entry: &str, layout: &wgpu::PipelineLayout| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry),
                layout: Some(layout),
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                cache: None,
            })
        };
        let kernels = Kernels {
            list: ListKernels {
                displacement: pipeline("nb_displacement", &main_layout),
                decide: pipeline("nb_decide", &decide_layout),
                clear: pipeline("nb_clear", &main_layout),
                count: pipeline("nb_count", &main_layout),
                scan_blocks: pipeline("nb_scan_blocks", &main_layout),
                scan_totals: pipeline("nb_scan_totals", &main_layout),
                scan_add: pipeline("nb_scan_add", &main_layout),
                scatter: pipeline("nb_scatter", &main_layout),
                sort: pipeline("nb_sort", &main_layout),
                build: pipeline("nb_build", &main_layout),
                after_step: pipeline("nb_after_step", &main_layout),
                list_ready: pipeline("nb_list_ready", &main_layout),
            },
            surface: SurfaceKernels {
                faces: pipeline("surface_faces", &main_layout),
                bodies: pipeline("surface_bodies", &main_layout),
                edges: pipeline("surface_edges", &main_layout),
                nodes: pipeline("surface_nodes", &main_layout),
                edge_forces: pipeline("surface_edge_forces", &main_layout),
                forces: pipeline("surface_forces", &main_layout),
            },
            forces: pipeline("forces", &main_layout),
            integrate: pipeline("integrate", &main_layout),
            commit: pipeline("commit", &main_layout),
            advance: pipeline("advance", &main_layout),
            contact_forces: pipeline("contact_forces", &main_layout),
            tetra_forces: pipeline("tetra_forces", &main_layout),
            adhesion_nodes: pipeline("adhesion_nodes", &main_layout),
            adhesion_weights: pipeline("adhesion_weights", &main_layout),
            protocol_ramps: pipeline("protocol_ramps", &main_layout),
            protocol_drive_check: pipeline("protocol_drive_check", &main_layout),
            protocol_drive_advance: pipeline("protocol_drive_advance", &main_layout),
        };
        let kinetics = kin_words.map(|(_, layout)| (layout, KinKernels::new(|entry| pipeline(entry, &main_layout))));
        let main_group = bind_main(
            device,
            &layout,
            [&uniform, &state_buffer, &next, &reference, &topo, &fparams, &cell_count, &cell_data, &force, &status, &surf, &kin, &protocol],
            &nlist,
        );
        let mut backend = Self {
            ctx: ctx.clone(),
            params,
            has_pairs,
            sim_box: *sim_box,
            fixed,
            buffers: MainBuffers {
                uniform,
                state: state_buffer,
                next,
                reference,
                topo,
                fparams,
                cell_count,
                cell_data,
                force,
                status,
                surf,
                kin,
                protocol,
            },
            bindings: Bindings { layout, main: main_group, args: args_group, args_buffer: args },
            kernels,
            list: ListState {
                storage: nlist,
                binding_limit: nlist_binding_limit,
                builds: 0,
                grown: 0,
                overflow_met: 0,
                pending_rebuild: true,
            },
            settings: *settings,
            body_ids: packed.body_ids,
            reads: Default::default(),
            time: settings.context.time,
            features: Features {
                contact,
                fractions: Vec::new(),
                adhesion,
                kinetics,
                protocol: protocol_pack,
                implicit: None,
                shake: None,
                fire: None,
            },
        };
        backend.set_clock(settings.context.time);
        backend.upload(state);
        Ok(backend)
    }

    fn bind_main(&self) -> wgpu::BindGroup {
        bind_main(&self.ctx.device, &self.bindings.layout, self.buffers.in_binding_order(), &self.list.storage)
    }

    /// The adapter this backend runs on.
    pub fn context(&self) -> &GpuContext {
        &self.ctx
    }

    /// Neighbour-list builds so far.
    pub fn neighbor_builds(&self) -> u64 {
        self.list.builds
    }

    /// How many times the neighbour list had to grow (overflow and retry).
    pub fn neighbor_list_growths(&self) -> u32 {
        self.list.grown
    }

    /// Caps the workgroups per dispatch along x (the adapter's limit, at most
    /// 65 535, by default); wider dispatches are split along y. Lowering it
    /// exercises the split on small systems.
    pub fn limit_dispatch_width(&mut self, groups: u32) {
        self.params.groups_x = groups.clamp(1, self.params.groups_x);
    }

    /// Neighbour-list capacity per particle.
    pub fn neighbor_capacity(&self) -> u32 {
        self.params.nlist_cap
    }

    /// Chunks the neighbour list is bound in (1 unless it exceeds one binding).
    pub fn neighbor_chunks(&self) -> u32 {
        self.list.storage.chunks
    }

    /// Caps the bytes of one neighbour-list binding (the adapter's limit by
    /// default) and lays the list out again; lowering it exercises the
    /// chunked list on small systems. An error when 64 particles' rows do not fit.
    pub fn limit_neighbor_binding(&mut self, bytes: u64) -> Result<(), String> {
        self.list.binding_limit = bytes.min(self.list.binding_limit);
        self.list.storage = NeighbourStorage::new(&self.ctx, self.params.n, self.params.nlist_cap, self.list.binding_limit)?;
        self.bindings.main = self.bind_main();
        self.list.pending_rebuild = true;
        Ok(())
    }

    /// Uploads positions and images (and asks for a neighbour rebuild).
    pub fn upload(&mut self, state: &State) {
        let n = state.len();
        let mut data = vec![[0u32; 4]; 3 * n];
        for (i, (x, image)) in state.positions.iter().zip(&state.images).enumerate() {
            let rel = *x - self.sim_box.lo;
            for a in 0..3 {
                (data[i][a], data[n + i][a]) = self.fixed.encode(rel[a]);
                data[2 * n + i][a] = image[a] as u32;
            }
        }
        self.ctx.queue.write_buffer(&self.buffers.state, 0, words(&data));
        self.list.pending_rebuild = true;
    }

    /// Uploads the bond state of `state` (after bond kinetics changed it) as
    /// one batch: the bound bonds with their own rest lengths and scales, and
    /// the exclusions of the bound bonds; `rebuild` asks for a neighbour-list
    /// rebuild before the next step (when bonds broke or bound, so that the
    /// pair exclusions changed).
    pub fn update_bonds(&mut self, model: &Model, state: &State, rebuild: bool) -> Result<(), String> {
        if self.features.kinetics.is_some() {
            return Err("the bond state of device kinetics lives on the device".into());
        }
        let (packed, _, contact_fields, adhesion_fields) =
            pack_state(model, state, &self.settings, false, &self.features.contact, &self.features.adhesion)?;
        let (topo, fparams) = (pad16(packed.topo), pad16(packed.fparams));
        let fits = |buffer: &wgpu::Buffer, bytes: usize| bytes as u64 <= buffer.size();
        if fits(&self.buffers.topo, 4 * topo.len()) && fits(&self.buffers.fparams, 4 * fparams.len()) {
            self.ctx.queue.write_buffer(&self.buffers.topo, 0, words(&topo));
            self.ctx.queue.write_buffer(&self.buffers.fparams, 0, words(&fparams));
        } else {
            check_binding(&self.ctx, "the topology", 4 * topo.len() as u64)?;
            let uploads = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
            let init = |label: &str, contents: &[u8]| {
                self.ctx.device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage: uploads })
            };
            self.buffers.topo = init("topo", words(&topo));
            self.buffers.fparams = init("fparams", words(&fparams));
            self.bindings.main = self.bind_main();
        }
        self.params.topo_offsets = packed.topo_offsets;
        self.params.fparam_offsets = packed.fparam_offsets;
        self.params.surface_offsets = packed.surface_offsets;
        self.params.contact = contact_fields;
        self.params.tetra_offsets = packed.tetra_offsets;
        self.params.special_offsets = packed.special_offsets;
        self.params.adhesion = adhesion_fields;
        if let Some(pack) = &mut self.features.protocol {
            // Bonds with their own terms were renumbered: the ramped slots follow.
            let slots =
                pack.slots(model, &packed_terms(&packed.fparam_offsets, &packed.own_bonds, packed.first_own_term), state.bonds.as_ref());
            self.ctx.queue.write_buffer(&self.buffers.protocol, 4 * pack.fields[4] as u64, words(&slots));
            self.params.protocol = pack.fields;
        }
        self.list.pending_rebuild |= rebuild;
        Ok(())
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

    /// Positions (wrapped, f64) and images of the current GPU state.
    pub fn download(&self, state: &mut State) {
        let n = state.len();
        let data: Vec<[u32; 4]> = bytemuck::cast_slice(&self.read(&self.buffers.state, 48 * n as u64)).to_vec();
        for i in 0..n {
            let mut x = DVec3::ZERO;
            for a in 0..3 {
                x[a] = self.sim_box.lo[a] + self.fixed.decode(data[i][a], data[n + i][a]);
                // The GPU counts images in i32: the i64 counter moves by the
                // wrapping difference (exact while a particle crosses fewer
                // than 2³¹ boxes between read-backs).
                let moved = (data[2 * n + i][a] as i32).wrapping_sub(state.images[i][a] as i32);
                state.images[i][a] += i64::from(moved);
            }
            state.positions[i] = x;
        }
    }

    /// Forces (f32, widened) and per-particle energy shares from the last force pass.
    pub fn forces_and_energies(&self) -> Vec<(DVec3, f64)> {
        let n = self.params.n as u64;
        let data: Vec<[f32; 4]> = bytemuck::cast_slice(&self.read(&self.buffers.force, 16 * n)).to_vec();
        data.iter().map(|f| (DVec3::new(f[0] as f64, f[1] as f64, f[2] as f64), f[3] as f64)).collect()
    }

    /// The neighbour list of the last build, each particle's list sorted.
    pub fn neighbor_lists(&self) -> Vec<Vec<u32>> {
        let n = self.params.n as usize;
        let cap = self.params.nlist_cap as usize;
        let data: Vec<u32> = bytemuck::cast_slice(&self.read(&self.list.storage.list, 4 * (n * (1 + cap)) as u64)).to_vec();
        (0..n)
            .map(|i| {
                let start = i * (1 + cap);
                let mut row = data[start + 1..start + 1 + (data[start] as usize).min(cap)].to_vec();
                // Excluded pairs kept for the contact search only are no neighbours.
                row.retain(|&j| j & CONTACT_ONLY == 0);
                row.sort_unstable();
                row
            })
            .collect()
    }

    fn read(&self, buffer: &wgpu::Buffer, bytes: u64) -> Vec<u8> {
        self.read_at(buffer, 0, bytes)
    }

    /// Whether the bond kinetics are decided on the device, and its buffer's layout.
    pub(super) fn device_kinetics(&self) -> Option<&KinLayout> {
        self.features.kinetics.as_ref().map(|(layout, _)| layout)
    }

    /// `count` words of the device kinetics' buffer from word `at`.
    pub(super) fn read_kin(&self, at: u64, count: u64) -> Vec<u32> {
        bytemuck::cast_slice(&self.read_at(&self.buffers.kin, 4 * at, 4 * count)).to_vec()
    }

    /// Writes `data` into the device kinetics' buffer at word `at`.
    pub(super) fn write_kin(&self, at: u64, data: &[u32]) {
        self.ctx.queue.write_buffer(&self.buffers.kin, 4 * at, words(data));
    }

    /// Read-backs from the GPU so far (each one a synchronisation).
    pub fn read_backs(&self) -> u64 {
        self.reads.get()
    }

    fn read_at(&self, buffer: &wgpu::Buffer, offset: u64, bytes: u64) -> Vec<u8> {
        self.reads.set(self.reads.get() + 1);
        let device = &self.ctx.device;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: bytes.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer, offset, &staging, 0, bytes);
        self.ctx.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |r| r.expect("mapping a readback buffer"));
        device.poll(wgpu::PollType::wait_indefinitely()).expect("waiting for the GPU");
        let out = slice.get_mapped_range().expect("mapped readback").to_vec();
        staging.unmap();
        out
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

    /// Times each phase alone, `repetitions` times in one submission (after a
    /// warm-up), waiting for the GPU at the end; seconds per call. The state
    /// is left as it was (integration is timed on a copy of the positions).
    pub fn profile(&mut self, repetitions: u32) -> Result<PhaseTimes, String> {
        self.evaluate()?;
        let saved = self.read(&self.buffers.state, 48 * self.params.n as u64);
        let particles = Over::Particles;
        let cells = Over::Groups(self.params.grid[3].div_ceil(WORKGROUP));
        let k = &self.kernels;
        let mut build: Vec<(&wgpu::ComputePipeline, Over)> = Vec::new();
        if self.has_pairs {
            build = vec![
                (&k.list.clear, cells),
                (&k.list.count, particles),
                (&k.list.scan_blocks, cells),
                (&k.list.scan_totals, Over::Groups(1)),
                (&k.list.scan_add, cells),
                (&k.list.scatter, particles),
                (&k.list.sort, cells),
                (&k.list.build, Over::Chunks),
            ];
        }
        // `group`: the bind group 1 the kernels read (the neighbour decision's
        // arguments, the implicit solver's or the projection's buffers).
        let time = |this: &Self, kernels: &[(&wgpu::ComputePipeline, Over)], group: Option<&wgpu::BindGroup>| {
            let run = |reps: u32| {
                let started = std::time::Instant::now();
                let mut encoder = this.ctx.device.create_command_encoder(&Default::default());
                {
                    let mut pass = encoder.begin_compute_pass(&Default::default());
                    pass.set_bind_group(0, &this.bindings.main, &this.list.storage.offsets(0));
                    if let Some(group) = group {
                        pass.set_bind_group(1, group, &[]);
                    }
                    for _ in 0..reps {
                        for (pipeline, over) in kernels {
                            this.dispatch(&mut pass, pipeline, *over);
                        }
                    }
                }
                this.ctx.queue.submit([encoder.finish()]);
                this.ctx.device.poll(wgpu::PollType::wait_indefinitely()).expect("waiting for the GPU");
                started.elapsed().as_secs_f64()
            };
            run(1);
            run(repetitions) / repetitions as f64
        };
        let args = Some(&self.bindings.args);
        let check =
            if self.has_pairs { time(self, &[(&k.list.displacement, particles), (&k.list.decide, Over::Groups(1))], args) } else { 0.0 };
        let neighbor_build = if self.has_pairs { time(self, &build, None) } else { 0.0 };
        let mut force_pass = self.surface_passes();
        force_pass.push((&k.forces, Over::Chunks));
        let forces = time(self, &force_pass, None);
        let contact = if self.has_contact() { time(self, &[(&k.contact_forces, Over::Chunks)], None) } else { 0.0 };
        let adhesion = if self.features.adhesion.rules() > 0 {
            time(self, &[(&k.adhesion_nodes, Over::Chunks), (&k.adhesion_weights, Over::Particles)], None)
        } else {
            0.0
        };
        let integrate = match &self.features.implicit {
            // The implicit step in place of `integrate` (src/gpu/implicit.rs).
            Some(solver) => {
                // In the step's order (`encode_step`).
                let passes: Vec<_> = solver.step_passes().into_iter().map(|(k, groups)| (k, Over::Groups(groups))).collect();
                time(self, &passes, Some(&solver.group)) + time(self, &[(&k.commit, particles), (&k.advance, Over::Groups(1))], None)
            }
            None => time(self, &[(&k.integrate, particles), (&k.commit, particles), (&k.advance, Over::Groups(1))], None),
        };
        let constraints = match &self.features.shake {
            Some(shake) => {
                let place = Over::Groups(shake.particles.div_ceil(WORKGROUP));
                time(self, &[(&shake.solve, Over::Groups(1)), (&shake.place, place)], Some(&shake.group))
            }
            None => 0.0,
        };
        let kinetics = match &self.features.kinetics {
            Some((layout, kin)) => {
                let bonds = Over::Groups(layout.bonds().div_ceil(WORKGROUP));
                let mut passes = vec![(&kin.measure, bonds), (&kin.decide, bonds), (&kin.scan, Over::Groups(1)), (&kin.emit, bonds)];
                if layout.binds() {
                    passes.extend([
                        (&kin.bind_count, Over::Chunks),
                        (&kin.bind_scan, Over::Groups(1)),
                        (&kin.bind_write, Over::Chunks),
                        (&kin.bind_accept, Over::Groups(1)),
                    ]);
                }
                time(self, &passes, None)
            }
            None => 0.0,
        };
        let started = std::time::Instant::now();
        for _ in 0..repetitions {
            self.read(&self.buffers.state, 48 * self.params.n as u64);
        }
        let readback = started.elapsed().as_secs_f64() / repetitions as f64;
        self.ctx.queue.write_buffer(&self.buffers.state, 0, &saved);
        self.list.pending_rebuild = true;
        Ok(PhaseTimes { check, neighbor_build, forces, integrate, readback, contact, adhesion, kinetics, constraints })
    }

    /// Dispatches `pipeline` over `over`: wider than the dispatch width,
    /// split along y; over the neighbour-list chunks, once per chunk with the
    /// chunk bound (chunk 0 is bound again afterwards).
    fn dispatch(&self, pass: &mut wgpu::ComputePass, pipeline: &wgpu::ComputePipeline, over: Over) {
        pass.set_pipeline(pipeline);
        let direct = |pass: &mut wgpu::ComputePass, groups: u32| {
            pass.dispatch_workgroups(groups.min(self.params.groups_x), groups.div_ceil(self.params.groups_x), 1);
        };
        match over {
            Over::Groups(groups) => direct(pass, groups),
            Over::Particles => direct(pass, self.params.n.div_ceil(WORKGROUP)),
            Over::Chunks => self.per_chunk(pass, |pass| direct(pass, self.list.storage.per_chunk.div_ceil(WORKGROUP))),
        }
    }

    /// Runs `dispatch` once per neighbour-list chunk with that chunk bound,
    /// then binds chunk 0 again (what every other kernel sees).
    fn per_chunk(&self, pass: &mut wgpu::ComputePass, mut dispatch: impl FnMut(&mut wgpu::ComputePass)) {
        for c in 0..self.list.storage.chunks {
            pass.set_bind_group(0, &self.bindings.main, &self.list.storage.offsets(c));
            dispatch(pass);
        }
        if self.list.storage.chunks > 1 {
            pass.set_bind_group(0, &self.bindings.main, &self.list.storage.offsets(0));
        }
    }

    /// Encodes one neighbour check/rebuild and force pass, and optionally the
    /// integration of one step. `checked_after_last`: the list was checked
    /// after the last step's `commit` in this submission (`bind` on the
    /// device), which was this step's check; only its overflow halt remains.
    fn encode_step(&self, pass: &mut wgpu::ComputePass, integrate: bool, checked_after_last: bool) {
        let k = &self.kernels;
        pass.set_bind_group(0, &self.bindings.main, &self.list.storage.offsets(0));
        let kinetics = self.features.kinetics.as_ref().map(|(layout, kernels)| (Over::Groups(layout.bonds().div_ceil(WORKGROUP)), kernels));
        if integrate && self.params.protocol[1] > 0 {
            self.dispatch(pass, &k.protocol_ramps, Over::Groups(self.params.protocol[1].div_ceil(WORKGROUP)));
        }
        if let Some((_, kin)) = kinetics.filter(|_| integrate) {
            self.dispatch(pass, &kin.room, Over::Groups(1));
        }
        if self.has_pairs && checked_after_last {
            self.dispatch(pass, &k.list.list_ready, Over::Groups(1));
        } else if self.has_pairs {
            self.encode_neighbors(pass);
        }
        for (pipeline, over) in self.surface_passes() {
            self.dispatch(pass, pipeline, over);
        }
        self.dispatch(pass, &k.forces, Over::Chunks);
        if self.has_contact() {
            // Area-weighted contact's node and weight passes first (src/gpu/adhesion.rs).
            if self.features.adhesion.rules() > 0 {
                self.dispatch(pass, &k.adhesion_nodes, Over::Chunks);
                self.dispatch(pass, &k.adhesion_weights, Over::Particles);
            }
            self.dispatch(pass, &k.contact_forces, Over::Chunks);
        }
        let drives = integrate && self.params.protocol[6] > 0;
        if drives {
            self.dispatch(pass, &k.protocol_drive_check, Over::Groups(1));
        }
        if integrate {
            if let Some((bonds, kin)) = kinetics {
                self.dispatch(pass, &kin.measure, bonds);
            }
            if let Some(fire) = &self.features.fire {
                // A FIRE iteration (src/gpu/fire.rs) in place of the step: it
                // moves `state` itself, so there is nothing to commit.
                pass.set_bind_group(1, &fire.group, &[]);
                self.dispatch(pass, &fire.partials, Over::Particles);
                self.dispatch(pass, &fire.control, Over::Groups(1));
                self.dispatch(pass, &fire.moves, Over::Particles);
                if let Some(clamped) = &fire.clamped_moves {
                    self.dispatch(pass, clamped, Over::Particles);
                }
            } else if let Some(solver) = &self.features.implicit {
                // The implicit step (src/gpu/implicit.rs) in place of `integrate`.
                pass.set_bind_group(1, &solver.group, &[]);
                for (kernel, groups) in solver.step_passes() {
                    self.dispatch(pass, kernel, Over::Groups(groups));
                }
            } else {
                self.dispatch(pass, &k.integrate, Over::Particles);
            }
            if let Some(shake) = &self.features.shake {
                // The constraints' projection (src/gpu/shake.rs) on the new positions.
                pass.set_bind_group(1, &shake.group, &[]);
                self.dispatch(pass, &shake.solve, Over::Groups(1));
                self.dispatch(pass, &shake.place, Over::Groups(shake.particles.div_ceil(WORKGROUP)));
            }
            if self.features.fire.is_none() {
                self.dispatch(pass, &k.commit, Over::Particles);
            }
            let binds = self.bind_kernels();
            if binds.is_some() {
                // `bind` captures at the new positions (src/gpu/bind.rs): the
                // list is checked (and rebuilt if due) now, for the capture
                // search and the next step's forces, so no pair within the
                // capture radius can be missing from it.
                self.dispatch(pass, &k.list.after_step, Over::Groups(1));
                self.encode_neighbors(pass);
                self.dispatch(pass, &k.list.after_step, Over::Groups(1));
            }
            if drives {
                self.dispatch(pass, &k.protocol_drive_advance, Over::Groups(1));
            }
            if let Some((bonds, kin)) = kinetics {
                self.dispatch(pass, &kin.decide, bonds);
                self.dispatch(pass, &kin.scan, Over::Groups(1));
                self.dispatch(pass, &kin.emit, bonds);
            }
            if let Some(kin) = binds {
                self.dispatch(pass, &kin.bind_count, Over::Chunks);
                self.dispatch(pass, &kin.bind_scan, Over::Groups(1));
                self.dispatch(pass, &kin.bind_write, Over::Chunks);
                self.dispatch(pass, &kin.bind_accept, Over::Groups(1));
            }
            self.dispatch(pass, &k.advance, Over::Groups(1));
            if let Some(kin) = binds {
                self.dispatch(pass, &kin.bind_halt, Over::Groups(1));
            }
        }
    }

    /// The kinetics kernels when `bind` forms bonds on the device (src/gpu/bind.rs).
    fn bind_kernels(&self) -> Option<&KinKernels> {
        self.features.kinetics.as_ref().filter(|(layout, _)| layout.binds()).map(|(_, kernels)| kernels)
    }

    /// The neighbour-list check and, when due, its rebuild (indirect dispatches).
    fn encode_neighbors(&self, pass: &mut wgpu::ComputePass) {
        let k = &self.kernels;
        self.dispatch(pass, &k.list.displacement, Over::Particles);
        pass.set_pipeline(&k.list.decide);
        pass.set_bind_group(1, &self.bindings.args, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        let indirect = |pass: &mut wgpu::ComputePass, pipeline: &wgpu::ComputePipeline, slot: u64| {
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups_indirect(&self.bindings.args_buffer, 12 * slot);
        };
        indirect(pass, &k.list.clear, 1);
        indirect(pass, &k.list.count, 0);
        indirect(pass, &k.list.scan_blocks, 1);
        indirect(pass, &k.list.scan_totals, 2);
        indirect(pass, &k.list.scan_add, 1);
        indirect(pass, &k.list.scatter, 0);
        indirect(pass, &k.list.sort, 1);
        self.per_chunk(pass, |pass| indirect(pass, &k.list.build, 3));
    }

    fn status(&self) -> [u32; STATUS_WORDS] {
        bytemuck::cast_slice(&self.read(&self.buffers.status, 4 * STATUS_WORDS as u64)).try_into().expect("status words")
    }

    /// The surface kernels in order (none without surface terms; the
    /// curvature passes only with a curvature law), see [`super::surface`],
    /// then the volume elements' kernel (none without elements).
    fn surface_passes(&self) -> Vec<(&wgpu::ComputePipeline, Over)> {
        let k = &self.kernels;
        let [faces, bodies, edges, nodes] = [12, 13, 14, 15].map(|c| self.params.surface_offsets[c]);
        let over = |count: u32| Over::Groups(count.div_ceil(WORKGROUP));
        let mut passes = Vec::new();
        if faces > 0 {
            passes.extend([(&k.surface.faces, over(faces)), (&k.surface.bodies, Over::Groups(bodies))]);
            if edges > 0 {
                passes.extend([(&k.surface.edges, over(edges)), (&k.surface.nodes, over(nodes)), (&k.surface.edge_forces, over(edges))]);
            }
            passes.push((&k.surface.forces, over(faces)));
        }
        // Then the volume elements' pass (src/gpu/tetra.rs).
        if self.params.tetra_offsets[5] > 0 {
            passes.push((&k.tetra_forces, over(self.params.tetra_offsets[5])));
        }
        passes
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

    /// Handles an overflow: grows the list and clears the halt. Returns
    /// whether there was one, or why the list cannot grow.
    fn grow_if_overflowed(&mut self, status: &[u32; STATUS_WORDS]) -> Result<bool, String> {
        if status[ST_HALTED] & HALT_OVERFLOW == 0 {
            return Ok(false);
        }
        self.reserve_neighbors(status[ST_OVERFLOW_NEED])?;
        Ok(true)
    }

    /// Grows the neighbour list to hold `need` neighbours per particle (with
    /// a quarter's margin); nothing if it does. The list is rebuilt before the next step.
    pub fn reserve_neighbors(&mut self, need: u32) -> Result<(), String> {
        if need <= self.params.nlist_cap {
            return Ok(());
        }
        let need = need as u64;
        let cap = (need + need / 4 + 8).next_multiple_of(8) as u32;
        self.list.storage = NeighbourStorage::new(&self.ctx, self.params.n, cap, self.list.binding_limit)?;
        self.params.nlist_cap = cap;
        self.bindings.main = self.bind_main();
        self.list.pending_rebuild = true;
        self.list.grown += 1;
        self.implicit_list_check()
    }

    /// The implicit step's one-workgroup solve reads the pair rows from one
    /// binding of the neighbour list (src/gpu/implicit.rs): a list bound in
    /// chunks is refused.
    fn implicit_list_check(&self) -> Result<(), String> {
        if self.features.implicit.is_some() && self.has_pairs && self.list.storage.chunks > 1 {
            return Err(format!(
                "integrator implicit with pair terms: the neighbour list ({} particles × {} neighbours) needs {} bindings on {}; \
                 the device's implicit solve reads it from one (use `device cpu`)",
                self.params.n, self.params.nlist_cap, self.list.storage.chunks, self.ctx.info.name
            ));
        }
        Ok(())
    }

    /// The neighbours per particle the list met, at least its capacity: with
    /// the largest count of a check after `commit` that overflowed (which
    /// halts with [`GpuHalt::Formation`], src/gpu/bind.rs), so a backend
    /// built anew can [`Self::reserve_neighbors`] them.
    pub fn neighbors_met(&self) -> u32 {
        self.params.nlist_cap.max(self.list.overflow_met)
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
            self.params.step_lo = step as u32;
            self.params.step_hi = (step >> 32) as u32;
            self.params.steps_wanted = chunk as u32;
            self.set_clock(self.time + self.elapsed(done));
            self.write_params();
            self.reset_status(force_rebuild);
            let binds = self.bind_kernels().is_some();
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

/// How many workgroups a kernel runs.
#[derive(Clone, Copy)]
enum Over {
    Groups(u32),
    /// One invocation per particle.
    Particles,
    /// One invocation per particle, dispatched per neighbour-list chunk.
    Chunks,
}

/// The main bind group: the buffers of layout.wgsl in binding order, the
/// neighbour list (binding 8) and its chunk uniform (binding 11) bound per chunk.
fn bind_main(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    buffers: [&wgpu::Buffer; 13],
    nlist: &NeighbourStorage,
) -> wgpu::BindGroup {
    let mut entries: Vec<wgpu::BindGroupEntry> = buffers
        .iter()
        .zip((0..8).chain(9..11).chain(12..15))
        .map(|(buf, b)| wgpu::BindGroupEntry { binding: b, resource: buf.as_entire_binding() })
        .collect();
    entries.extend(nlist.entries());
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some("cellmd main"), layout, entries: &entries })
}

/// What the protocols' ramped slots depend on in a packing (src/gpu/protocol.rs).
fn packed_terms<'a>(fparam_offsets: &[u32; 4], own_bonds: &'a [u32], first_own_term: u32) -> PackedTerms<'a> {
    PackedTerms { params: fparam_offsets[0], own_bonds, first_own_term }
}

fn pad16<T: bytemuck::Pod + Default>(mut v: Vec<T>) -> Vec<T> {
    let per = 16 / std::mem::size_of::<T>();
    v.resize(v.len().next_multiple_of(per).max(per), T::default());
    v
}

/// A first neighbour-list capacity from the mean density (1.25 × the mean
/// count in a sphere of the list range, plus 8, at least 32); overflow grows it.
fn initial_capacity(n: usize, sim_box: &SimBox, range: f64, has_pairs: bool) -> u32 {
    if !has_pairs {
        return 1;
    }
    let volume = sim_box.volume();
    let mean = if volume > 0.0 { n as f64 / volume * 4.0 / 3.0 * std::f64::consts::PI * range.powi(3) } else { n as f64 };
    ((1.25 * mean + 8.0).ceil() as u32).clamp(32, n.max(32) as u32).next_multiple_of(8)
}

/// [`pack`] for the model at `state`: with bond state, only the bound bonds
/// (with their own rest lengths and scales) and the exclusions they make.
/// With `device_kinetics`, every bond is packed as bound with its
/// exclusions (the device's bound flags switch them off). The contact
/// sections follow the others in `topo`, the fraction ring the surface
/// entries in `surf`; returns the layout's contact fields too. The
/// area-weighted contact sections and `surf` regions follow those.
fn pack_state(
    model: &Model,
    state: &State,
    settings: &StepSettings,
    device_kinetics: bool,
    contact: &ContactPack,
    adhesion: &AdhesionPack,
) -> Result<(Packed, Exclusions, [u32; 16], [u32; 8]), String> {
    let all_bound = state.bonds.as_ref().filter(|_| device_kinetics).map(|b| BondState { bound: vec![true; b.len()], ..b.clone() });
    let bonds = all_bound.as_ref().or(state.bonds.as_ref());
    let bound = bonds.map(|b| b.bound.as_slice());
    let exclusions = Exclusions::from_pairs(model.len(), &model.excluded_pairs(bound));
    let mut packed = pack(model, &exclusions, settings.context.dt, settings.context.kt, bonds)?;
    let (fields, n) = (contact.append(&mut packed.topo, packed.surf_entries), model.len() as u32);
    let adhesion_base = packed.surf_entries + contact.surf_entries(n);
    let adhesion_fields = adhesion.append(&mut packed.topo, adhesion_base, n, contact.closest_entry(packed.surf_entries));
    Ok((packed, exclusions, fields, adhesion_fields))
}
