//! The device step as its features see it: the phases of one step, the
//! dispatcher that sizes and chunks a kernel's dispatch, and the one trait
//! ([`StepFeature`]) each feature implements to put its kernels into a step.
//!
//! A step is encoded phase by phase ([`Phase`]); in each phase the backend asks every feature it composes, in a fixed order, to encode its
//! kernels of that phase (most features have kernels in one or two). The
//! order of the features and of the phases is the order of the dispatches,
//! which the results depend on only through the data the kernels share, so
//! it is fixed: the same model gives the same command stream, the same bits.
//! [`Phase::Move`] goes to the one integrator in force (explicit, implicit
//! or FIRE) alone. Before [`Phase::AfterCommit`] the backend commits the
//! moved positions (all integrators but FIRE, which moves the state
//! itself); before [`Phase::End`] it advances the step counter. A force
//! evaluation encodes [`Phase::Neighbours`] and [`Phase::Forces`] only.

use super::context::WORKGROUP;
use super::nlist::NeighbourStorage;
use super::pack::Params;

/// A phase of a device step, in step order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Phase {
    /// Before anything reads the state: ramped parameters, the kinetics' room check.
    Start,
    /// The neighbour list's check and, when due, its rebuild. `checked_after_last`:
    /// the list was checked after the last step's commit (`bind` on the device),
    /// so only its overflow halt remains.
    Neighbours { checked_after_last: bool },
    /// The force passes: surface and volume terms, pairs and bonds, contact.
    Forces,
    /// After the forces, before the move: driven indenters' load check, bond lengths.
    BeforeMove,
    /// The move of the one integrator in force (explicit, implicit or FIRE).
    Move,
    /// The constraints' projection on the moved positions.
    Constrain,
    /// After the commit of the new positions: decisions on the new state.
    AfterCommit,
    /// After the step counter advanced: halts for the next step.
    End,
}

/// How many workgroups a kernel runs.
#[derive(Clone, Copy, Debug)]
pub(super) enum Over {
    Groups(u32),
    /// One invocation per particle.
    Particles,
    /// One invocation per particle, dispatched per neighbour-list chunk.
    Chunks,
}

impl Over {
    /// One invocation per item of `count`.
    pub(super) fn each(count: u32) -> Self {
        Over::Groups(count.div_ceil(WORKGROUP))
    }
}

/// What a feature needs to dispatch its kernels: the layout parameters, the
/// main bind group and the neighbour list's chunking.
pub(super) struct Dispatcher<'a> {
    pub(super) params: &'a Params,
    pub(super) main: &'a wgpu::BindGroup,
    pub(super) list: &'a NeighbourStorage,
}

impl Dispatcher<'_> {
    /// Dispatches `pipeline` over `over`: wider than the dispatch width,
    /// split along y; over the neighbour-list chunks, once per chunk with the
    /// chunk bound (chunk 0 is bound again afterwards).
    pub(super) fn dispatch(&self, pass: &mut wgpu::ComputePass, pipeline: &wgpu::ComputePipeline, over: Over) {
        pass.set_pipeline(pipeline);
        let width = self.params.step.groups_x;
        let direct = |pass: &mut wgpu::ComputePass, groups: u32| pass.dispatch_workgroups(groups.min(width), groups.div_ceil(width), 1);
        match over {
            Over::Groups(groups) => direct(pass, groups),
            Over::Particles => direct(pass, self.params.sizes.n.div_ceil(WORKGROUP)),
            Over::Chunks => self.per_chunk(pass, |pass| direct(pass, self.list.per_chunk.div_ceil(WORKGROUP))),
        }
    }

    /// Dispatches each of `kernels` in order.
    pub(super) fn dispatch_all(&self, pass: &mut wgpu::ComputePass, kernels: &[(&wgpu::ComputePipeline, Over)]) {
        for &(pipeline, over) in kernels {
            self.dispatch(pass, pipeline, over);
        }
    }

    /// Runs `dispatch` once per neighbour-list chunk with that chunk bound,
    /// then binds chunk 0 again (what every other kernel sees).
    pub(super) fn per_chunk(&self, pass: &mut wgpu::ComputePass, mut dispatch: impl FnMut(&mut wgpu::ComputePass)) {
        for c in 0..self.list.chunks {
            pass.set_bind_group(0, self.main, &self.list.offsets(c));
            dispatch(pass);
        }
        if self.list.chunks > 1 {
            self.bind_main(pass);
        }
    }

    /// Binds the main group with the neighbour list's chunk 0.
    pub(super) fn bind_main(&self, pass: &mut wgpu::ComputePass) {
        pass.set_bind_group(0, self.main, &self.list.offsets(0));
    }
}

/// One device feature's part of a step: it owns its buffers and pipelines
/// and encodes its kernels of each phase.
pub(super) trait StepFeature {
    /// Encodes this feature's kernels of `phase` into `pass` (nothing in the
    /// phases it has no kernels in).
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass);
}
