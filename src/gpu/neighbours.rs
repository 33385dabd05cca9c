//! The neighbour list as a step feature: its kernels (shaders/common/neighbor.wgsl),
//! its storage ([`super::nlist`]) and what the host knows of its builds.
//!
//! Each step checks the largest displacement since the last build against
//! half the skin (the Verlet list, Verlet 1967, with the displacement
//! criterion of Allen & Tildesley, *Computer Simulation of Liquids*) and,
//! when due, rebuilds the list from a cell list: count per cell, a scan,
//! scatter, a sort of each cell, then each particle's row. The check decides on the device and writes the rebuild's
//! dispatch sizes, so the rebuild is a chain of indirect dispatches and the
//! host reads nothing back. With `bind` on the device ([`super::bind`]) the
//! list is checked again after each step's commit, for the capture search
//! and the next step's forces.

use super::context::{storage_entry, GpuContext};
use super::nlist::NeighbourStorage;
use super::step::{Dispatcher, Over, Phase, StepFeature};

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

/// The indirect dispatch arguments the check writes for the rebuild (bind group 1 of `nb_decide`).
pub(super) struct DispatchArgs {
    layout: wgpu::BindGroupLayout,
    group: wgpu::BindGroup,
    buffer: wgpu::Buffer,
}

impl DispatchArgs {
    pub(super) fn new(device: &wgpu::Device) -> Self {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("dispatch_args"),
            size: 4 * 12,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDIRECT,
            mapped_at_creation: false,
        });
        let layout = device
            .create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some("cellmd args"), entries: &[storage_entry(0, false)] });
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("cellmd args"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() }],
        });
        Self { layout, group, buffer }
    }

    /// The layout of bind group 1 of the decision kernel.
    pub(super) fn layout(&self) -> &wgpu::BindGroupLayout {
        &self.layout
    }
}

/// The neighbour list: storage, kernels and bookkeeping.
pub(super) struct NeighbourList {
    pub(super) storage: NeighbourStorage,
    kernels: ListKernels,
    args: DispatchArgs,
    /// Whether the model has anything to list (pairs, contact or capture); no kernel runs without.
    pub(super) active: bool,
    /// Whether the list is checked after each step's commit too (`bind` on the device).
    checks_after_commit: bool,
    /// The largest storage binding the neighbour list's chunks may take.
    pub(super) binding_limit: u64,
    pub(super) builds: u64,
    pub(super) grown: u32,
    /// The largest neighbour count of an overflow that did not halt the step (bind.wgsl).
    pub(super) overflow_met: u32,
    /// The next `run` or `evaluate` rebuilds the neighbour list first.
    pub(super) pending_rebuild: bool,
}

impl NeighbourList {
    /// The list's kernels from `pipeline(entry, takes_args)` (`takes_args`:
    /// the kernel binds the dispatch arguments as group 1).
    pub(super) fn new(
        storage: NeighbourStorage,
        args: DispatchArgs,
        binding_limit: u64,
        active: bool,
        checks_after_commit: bool,
        pipeline: impl Fn(&str, bool) -> wgpu::ComputePipeline,
    ) -> Self {
        let main = |entry: &str| pipeline(entry, false);
        let kernels = ListKernels {
            displacement: main("nb_displacement"),
            decide: pipeline("nb_decide", true),
            clear: main("nb_clear"),
            count: main("nb_count"),
            scan_blocks: main("nb_scan_blocks"),
            scan_totals: main("nb_scan_totals"),
            scan_add: main("nb_scan_add"),
            scatter: main("nb_scatter"),
            sort: main("nb_sort"),
            build: main("nb_build"),
            after_step: main("nb_after_step"),
            list_ready: main("nb_list_ready"),
        };
        Self {
            storage,
            kernels,
            args,
            active,
            checks_after_commit,
            binding_limit,
            builds: 0,
            grown: 0,
            overflow_met: 0,
            pending_rebuild: true,
        }
    }

    /// Lays the list out again for `n` particles of `capacity` neighbours
    /// (bound anew by the caller); rebuilt before the next step.
    pub(super) fn resize(&mut self, ctx: &GpuContext, n: u32, capacity: u32) -> Result<(), String> {
        self.storage = NeighbourStorage::new(ctx, n, capacity, self.binding_limit)?;
        self.pending_rebuild = true;
        Ok(())
    }

    /// The check and its decision, each timed alone by `profile`, with the
    /// bind group 1 they read.
    pub(super) fn check_passes(&self) -> (Vec<(&wgpu::ComputePipeline, Over)>, &wgpu::BindGroup) {
        let k = &self.kernels;
        (vec![(&k.displacement, Over::Particles), (&k.decide, Over::Groups(1))], &self.args.group)
    }

    /// A full rebuild's kernels sized for every cell and particle (`cells`:
    /// the cell grid's cells), as `profile` times them.
    pub(super) fn build_passes(&self, cells: u32) -> Vec<(&wgpu::ComputePipeline, Over)> {
        let (k, cells) = (&self.kernels, Over::each(cells));
        vec![
            (&k.clear, cells),
            (&k.count, Over::Particles),
            (&k.scan_blocks, cells),
            (&k.scan_totals, Over::Groups(1)),
            (&k.scan_add, cells),
            (&k.scatter, Over::Particles),
            (&k.sort, cells),
            (&k.build, Over::Chunks),
        ]
    }

    /// The check and, when due, the rebuild (indirect dispatches).
    fn encode_check(&self, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        let k = &self.kernels;
        at.dispatch(pass, &k.displacement, Over::Particles);
        pass.set_pipeline(&k.decide);
        pass.set_bind_group(1, &self.args.group, &[]);
        pass.dispatch_workgroups(1, 1, 1);
        let indirect = |pass: &mut wgpu::ComputePass, pipeline: &wgpu::ComputePipeline, slot: u64| {
            pass.set_pipeline(pipeline);
            pass.dispatch_workgroups_indirect(&self.args.buffer, 12 * slot);
        };
        indirect(pass, &k.clear, 1);
        indirect(pass, &k.count, 0);
        indirect(pass, &k.scan_blocks, 1);
        indirect(pass, &k.scan_totals, 2);
        indirect(pass, &k.scan_add, 1);
        indirect(pass, &k.scatter, 0);
        indirect(pass, &k.sort, 1);
        at.per_chunk(pass, |pass| indirect(pass, &k.build, 3));
    }
}

impl StepFeature for NeighbourList {
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        let k = &self.kernels;
        match phase {
            Phase::Neighbours { checked_after_last: true } if self.active => at.dispatch(pass, &k.list_ready, Over::Groups(1)),
            Phase::Neighbours { .. } if self.active => self.encode_check(at, pass),
            Phase::AfterCommit if self.checks_after_commit => {
                // `bind` captures at the new positions (src/gpu/bind.rs): the
                // list is checked (and rebuilt if due) now, for the capture
                // search and the next step's forces, so no pair within the
                // capture radius can be missing from it.
                at.dispatch(pass, &k.after_step, Over::Groups(1));
                self.encode_check(at, pass);
                at.dispatch(pass, &k.after_step, Over::Groups(1));
            }
            _ => {}
        }
    }
}
