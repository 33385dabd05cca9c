//! Inextensible bonds (`constrain`) on the device (kernels:
//! shaders/common/shake.wgsl).
//!
//! # The projection
//!
//! As on the CPU (src/integrate/constraints.rs; Ryckaert, Ciccotti &
//! Berendsen, *J. Comput. Phys.* 23, 327 (1977), in its overdamped form),
//! after each explicit step every constrained bond is moved back to its
//! length r0 along its direction before the step, its ends weighted by
//! their mobilities, in sweeps until every |r − r0|/r0 is within the
//! tolerance, and each bond's tension Σg·|r_before|/dt is kept for the
//! thermo's `ctension/TYPE`.
//!
//! # Order, and how the result differs from the CPU's
//!
//! The CPU sweeps the constraints in bond order, one after the other
//! (Gauss–Seidel). The device sweeps them colour by colour: the host colours
//! the constraints greedily in bond order so that no two of a colour share a
//! particle, a colour's corrections run in parallel (they touch disjoint
//! particles, so each is what the sequential sweep would do), and the
//! colours follow one another in a fixed order. Both converge to a point
//! within the tolerance of the constraint manifold, but not to the same
//! point: the two results differ by about the tolerance times the bond
//! length (measured in tests/suite/gpu_constraints.rs). The whole projection runs
//! in ONE workgroup (`shake_solve`, as the implicit solve), so the
//! convergence test is taken on the device every sweep and nothing is read
//! back per step; the host reads the tensions and the last projection's
//! sweeps at its synchronisations.
//!
//! # Precision
//!
//! Positions stay 64-bit fixed point: each correction is an f32
//! displacement added exactly, and each length is an exact fixed-point
//! difference rounded once to f32, so |r − r0|/r0 is known to a few ε_f32
//! (≈ 1e-7). The device therefore projects to max(tolerance,
//! [`F32_TOLERANCE`]) and the run says so when it raises the deck's
//! tolerance (the CPU's default is 1e-10).
//!
//! # Which runs ([`refusal`])
//!
//! With either integrator: with `integrator implicit` the step itself
//! solves the constrained system first (projected CG on the device too,
//! shaders/common/implicit_constraints.wgsl), then SHAKE removes the
//! second-order drift, as on the CPU. Not with bond kinetics, whose
//! breaking and forming would change the constrained bonds under the
//! projection.

use wgpu::util::DeviceExt;

use super::context::GpuContext;
use super::prelude::shake::*;
use super::side_group::SideGroup;
use super::step::{Dispatcher, Over, Phase, StepFeature};
use crate::integrate::constraints::{failure_message, ConstraintMethod, Constraints};
use crate::integrate::fibre::chains::Chains;
use crate::system::Model;

/// The smallest |r − r0|/r0 the device's projection is asked for: ten times
/// the few ε_f32 to which an f32 length is known.
pub const F32_TOLERANCE: f64 = 1e-6;

const HEADER_WORDS: usize = 8;

/// Why the constraints cannot be projected on the device (None: they can).
pub fn refusal(model: &Model, constraints: &Constraints) -> Option<&'static str> {
    if model.has_kinetics() {
        return Some("constrained bonds (`constrain`) with bond kinetics run on the CPU backend only");
    }
    let bonds: Vec<usize> = constraints.list.iter().map(|c| c.bond).collect();
    if !Chains::find(model, &bonds, constraints.method == ConstraintMethod::Fibre, false, |_| None).is_empty() {
        return Some(
            "inextensible fibres (chains of constrained bonds) are solved fibre by fibre on the CPU backend only; \
             `constrain … method shake` projects them on the GPU by SHAKE (explicit bending, small steps)",
        );
    }
    None
}

/// Colours the constraints greedily in list order: each takes the lowest
/// colour none of the earlier constraints at its particles has. Returns
/// each constraint's colour and the number of colours.
fn colors(model: &Model, constraints: &Constraints) -> (Vec<u32>, u32) {
    let mut used: Vec<Vec<u32>> = vec![Vec::new(); model.len()];
    let mut color = Vec::with_capacity(constraints.list.len());
    for c in &constraints.list {
        let [i, j] = model.bonds[c.bond].map(|p| p as usize);
        let pick = (0u32..).find(|k| !used[i].contains(k) && !used[j].contains(k)).expect("a free colour");
        used[i].push(pick);
        used[j].push(pick);
        color.push(pick);
    }
    let count = color.iter().max().map_or(0, |&c| c + 1);
    (color, count)
}

/// The last projection's sweeps, its largest relative error, and the
/// constraint (index in the deck's list) that had it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ShakeReport {
    pub sweeps: usize,
    pub relative_error: f64,
    pub worst: usize,
}

/// The device's projection: its buffers, bind group (group 1) and kernels.
pub(super) struct DeviceShake {
    pub(super) group: wgpu::BindGroup,
    pub(super) solve: wgpu::ComputePipeline,
    pub(super) place: wgpu::ComputePipeline,
    /// `shake_out`: the tensions (list order), then the report.
    pub(super) buffer: wgpu::Buffer,
    pub(super) count: usize,
    pub(super) particles: u32,
    /// The tolerance the device projects to.
    pub(super) tolerance: f64,
    /// The sweep cap.
    max_sweeps: usize,
    /// Each constraint's ends (particle ids), for the failure message.
    ends: Vec<[u64; 2]>,
}

impl DeviceShake {
    /// The sweeps in one workgroup, then each particle's placement (bind group 1: [`Self::group`]).
    pub(super) fn passes(&self) -> [(&wgpu::ComputePipeline, Over); 2] {
        [(&self.solve, Over::Groups(1)), (&self.place, Over::each(self.particles))]
    }

    /// Packs the coloured constraints and compiles the kernels against the
    /// backend's main bind group layout.
    pub(super) fn new(
        ctx: &GpuContext,
        main_layout: &wgpu::BindGroupLayout,
        model: &Model,
        constraints: &Constraints,
    ) -> Result<Self, String> {
        let tolerance = constraints.tolerance.max(F32_TOLERANCE);
        let (color, n_colors) = colors(model, constraints);
        let mut order: Vec<usize> = (0..constraints.list.len()).collect();
        order.sort_by_key(|&k| (color[k], k));
        let mut header = vec![0u32; HEADER_WORDS];
        let mut words = Vec::new();
        header[SH_COUNT] = constraints.list.len() as u32;
        header[SH_COLORS] = n_colors;
        header[SH_OFF_COLOR_START] = HEADER_WORDS as u32;
        words.extend((0..=n_colors).map(|c| order.iter().filter(|&&k| color[k] < c).count() as u32));
        header[SH_OFF_RECORDS] = (HEADER_WORDS + words.len()) as u32;
        for &k in &order {
            let c = constraints.list[k];
            let [i, j] = model.bonds[c.bond];
            words.extend([i, j, (c.length as f32).to_bits(), k as u32]);
        }
        header[SH_MAX_SWEEPS] = constraints.max_iterations.max(1).min(u32::MAX as usize) as u32;
        header[SH_TOLERANCE] = (tolerance as f32).to_bits();
        let mut particles: Vec<u32> = constraints.list.iter().flat_map(|c| model.bonds[c.bond]).collect();
        particles.sort_unstable();
        particles.dedup();
        header[SH_OFF_PARTICLES] = (HEADER_WORDS + words.len()) as u32;
        header[SH_PARTICLES] = particles.len() as u32;
        words.extend(&particles);
        let topo: Vec<u32> = header.into_iter().chain(words).collect();
        let device = &ctx.device;
        let shake_topo = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("shake_topo"),
            contents: bytemuck::cast_slice(&topo),
            usage: wgpu::BufferUsages::STORAGE,
        });
        // The tensions, then the report (sweeps, error, worst constraint).
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("shake_out"),
            size: 4 * (constraints.list.len() as u64 + 4),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        let side = SideGroup::new(ctx, main_layout, model, "constrained bonds", &[(3, true, &shake_topo), (4, false, &buffer)])?;
        Ok(Self {
            solve: side.pipeline(ctx, "shake_solve"),
            place: side.pipeline(ctx, "shake_place"),
            group: side.group,
            buffer,
            count: constraints.list.len(),
            particles: particles.len() as u32,
            tolerance,
            max_sweeps: constraints.max_iterations,
            ends: constraints.list.iter().map(|c| model.bonds[c.bond].map(|p| model.ids[p as usize])).collect(),
        })
    }

    /// The tensions (list order) and the report, from `shake_out`'s bytes.
    pub(super) fn read(&self, bytes: &[u8]) -> (Vec<f64>, ShakeReport) {
        let words: &[f32] = bytemuck::cast_slice(bytes);
        let tension = words[..self.count].iter().map(|&t| f64::from(t)).collect();
        let r = &words[self.count..];
        (tension, ShakeReport { sweeps: r[0].to_bits() as usize, relative_error: f64::from(r[1]), worst: r[2].to_bits() as usize })
    }

    /// Why a projection halted the run (the CPU's message, at the step it was taking).
    pub(super) fn failure(&self, report: &ShakeReport, step: u64) -> String {
        failure_message(self.ends[report.worst], self.max_sweeps, step, report.relative_error, self.tolerance)
    }
}

impl StepFeature for DeviceShake {
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        if phase == Phase::Constrain {
            pass.set_bind_group(1, &self.group, &[]);
            at.dispatch_all(pass, &self.passes());
        }
    }
}
