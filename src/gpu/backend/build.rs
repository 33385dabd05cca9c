//! Building the backend: the model packed into the buffers, the main bind
//! group and its layout, the program compiled into the features' kernels;
//! and the bond state uploaded again after bond kinetics on the host.

use wgpu::util::DeviceExt;

use super::{Bindings, Features, GpuBackend, MainBuffers, StepKernels, StepSettings};
use crate::gpu::adhesion::AdhesionPack;
use crate::gpu::contact::{ContactPack, ContactPasses};
use crate::gpu::context::{storage_entry, GpuContext, WORKGROUP};
use crate::gpu::forces::ForcePasses;
use crate::gpu::kinetics::{DeviceKinetics, KinKernels, KinLayout};
use crate::gpu::neighbours::{DispatchArgs, NeighbourList};
use crate::gpu::nlist::NeighbourStorage;
use crate::gpu::pack::{cell_grid, pack, BoxFrame, FixedPoint, KineticsWords, Packed, Params, Sizes, StepWords};
use crate::gpu::prelude::status::STATUS_WORDS;
use crate::gpu::protocol::{DeviceProtocol, PackedTerms, ProtocolKernels, ProtocolPack};
use crate::gpu::shader;
use crate::neighbor::{Exclusions, ImageShifts};
use crate::system::{BondState, Model, SimBox, State};

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

pub(super) fn words<T: bytemuck::Pod>(data: &[T]) -> &[u8] {
    bytemuck::cast_slice(data)
}

impl GpuBackend {
    pub(super) fn build(
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
        let capture = if kin_words.as_ref().is_some_and(|(_, l)| l.binds()) { crate::gpu::bind::capture(model) } else { 0.0 };
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
            frame: BoxFrame {
                box_len_h: [box_fixed[0].0, box_fixed[1].0, box_fixed[2].0, 0],
                box_len_f: [box_fixed[0].1, box_fixed[1].1, box_fixed[2].1, 0],
                box_lo_h: [lo_fixed[0].0, lo_fixed[1].0, lo_fixed[2].0, 0],
                box_lo_f: [lo_fixed[0].1, lo_fixed[1].1, lo_fixed[2].1, 0],
                periodic: [sim_box.periodic[0] as u32, sim_box.periodic[1] as u32, sim_box.periodic[2] as u32, 0],
                grid: [grid[0], grid[1], grid[2], cells],
                cell_inv_width: [inv_width[0], inv_width[1], inv_width[2], 0.0],
                box_len: [lengths.x as f32, lengths.y as f32, lengths.z as f32, fixed.q as f32],
            },
            sizes: Sizes {
                n: n as u32,
                nlist_cap: initial_capacity(n, sim_box, range, has_pairs),
                n_types: model.type_names.len() as u32,
                steps_wanted: 0,
            },
            step: StepWords {
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
            },
            topo_offsets: packed.topo_offsets,
            fparam_offsets: packed.fparam_offsets,
            surface_offsets: packed.surface_offsets,
            contact: contact_fields,
            kinetics: KineticsWords {
                kin_bonds: kin_words.as_ref().map_or(0, |(_, l)| l.bonds()),
                kin_first_term: kin_words.as_ref().map_or(0, |(_, l)| l.first_term),
                kin_capacity: kin_words.as_ref().map_or(0, |(_, l)| l.capacity),
                kin_types: model.bond_types.len() as u32,
            },
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
        let nlist = NeighbourStorage::new(ctx, n as u32, params.sizes.nlist_cap, nlist_binding_limit)?;
        let force = zeros("force", 16 * n as u64, rw);
        let status = zeros("status", 4 * STATUS_WORDS as u64, rw);
        let surf_bytes = 16 * (packed.surf_entries + contact.surf_entries(n as u32) + adhesion.surf_entries(n as u32));
        check_binding(ctx, "the surface terms' face and body values", surf_bytes)?;
        let surf = zeros("surf", surf_bytes, rw);
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
        let args = DispatchArgs::new(device);
        let mut custom = crate::gpu::custom::source(model)?;
        custom.mover_cases = device_protocol.map(crate::gpu::protocol::mover_cases).transpose()?.unwrap_or_default();
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
            bind_group_layouts: &[Some(&layout), Some(args.layout())],
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
        let main = |entry: &str| pipeline(entry, &main_layout);
        let kinetics = kin_words.map(|(_, layout)| DeviceKinetics { layout, kernels: KinKernels::new(main) });
        let binds = kinetics.as_ref().is_some_and(|k| k.layout.binds());
        let main_group = bind_main(
            device,
            &layout,
            [&uniform, &state_buffer, &next, &reference, &topo, &fparams, &cell_count, &cell_data, &force, &status, &surf, &kin, &protocol],
            &nlist,
        );
        let list_pipeline = |entry: &str, takes_args: bool| pipeline(entry, if takes_args { &decide_layout } else { &main_layout });
        let mut backend = Self {
            ctx: ctx.clone(),
            params,
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
            bindings: Bindings { layout, main: main_group },
            step: StepKernels { integrate: main("integrate"), commit: main("commit"), advance: main("advance") },
            list: NeighbourList::new(nlist, args, nlist_binding_limit, has_pairs, binds, list_pipeline),
            forces: ForcePasses::new(main),
            settings: *settings,
            body_ids: packed.body_ids,
            reads: Default::default(),
            time: settings.context.time,
            features: Features {
                contact_passes: ContactPasses::new(contact.faces(), adhesion.rules(), main),
                contact,
                fractions: Vec::new(),
                adhesion,
                kinetics,
                protocol: protocol_pack,
                protocol_kernels: ProtocolKernels::new(main),
                implicit: None,
                shake: None,
                fire: None,
            },
        };
        backend.set_clock(settings.context.time);
        backend.upload(state);
        Ok(backend)
    }

    pub(super) fn bind_main(&self) -> wgpu::BindGroup {
        bind_main(&self.ctx.device, &self.bindings.layout, self.buffers.in_binding_order(), &self.list.storage)
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
