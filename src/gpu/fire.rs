//! `minimize` (FIRE) on the device (kernels: shaders/common/fire.wgsl).
//!
//! # The iteration
//!
//! As on the CPU (src/integrate/fire.rs; Bitzek et al., *Phys. Rev. Lett.*
//! 97, 170201 (2006)): fictitious inertial dynamics with mass mᵢ = γᵢ·Δt₀,
//! the velocities mixed towards the force while the power P = Σ F·v stays
//! positive (Δt grows ×1.1 up to 10Δt₀ and α shrinks ×0.99 after 5 such
//! iterations) and zeroed when it turns negative (Δt halves, α back to 0.1),
//! each move capped at dmax, until max |F| < ftol. `fixed` particles and
//! held axes carry no force, as the CPU masks them. Each iteration is the
//! neighbour check and force pass of a step followed by three kernels (four with contact); the
//! host runs the iterations as the steps of the backend's `run`
//! (src/gpu/backend/mod.rs), which stops at convergence (a halt bit the control
//! kernel sets) and reads nothing back in between.
//!
//! # Determinism and precision
//!
//! The sums P, Σ|v|², Σ|F|² and max |F| are fixed trees (per workgroup,
//! then over the workgroups in order), so the same minimisation gives the
//! same bits. Forces and velocities are f32 and positions fixed point, so
//! the path differs from the CPU's by rounding, and FIRE's branch on the
//! sign of P can take the other turn where P is near 0: the two runs can
//! take different numbers of iterations to the same minimum (measured in
//! tests/suite/gpu_minimize.rs). The verdict and the reported max |F| and energy
//! are the CPU's f64 evaluation at the positions the device reached.
//!
//! # Contact between bodies
//!
//! As on the CPU, every move is scaled by s = min(1, minᵢ Lᵢ/|Δxᵢ|), Lᵢ =
//! 0.4 × particle i's closest contact distance at the evaluated positions
//! (which the contact pass keeps, src/gpu/contact.rs), a line search that
//! keeps every body outside every other; the velocities are kept. `fire_move`
//! min-reduces s on the bits of the positive f32s (the order does not
//! matter) and `fire_clamped_move` moves by s·Δx, counting the shortened
//! moves for the report. Protocols enter as their held axes alone (a
//! minimisation takes no step, so nothing moves or ramps), as the CPU masks
//! those forces.

use wgpu::util::DeviceExt;

use super::context::GpuContext;
use super::prelude::fire::*;
use super::side_group::SideGroup;
use super::step::{Dispatcher, Over, Phase, StepFeature};
use crate::integrate::fire::{FireSettings, ALPHA0, DT_MAX_FACTOR};
use crate::system::Model;

/// The device's FIRE: velocities, control words and partial sums, and the kernels.
pub(super) struct DeviceFire {
    pub(super) group: wgpu::BindGroup,
    pub(super) partials: wgpu::ComputePipeline,
    pub(super) control: wgpu::ComputePipeline,
    pub(super) moves: wgpu::ComputePipeline,
    /// The clamped move after `moves`, with contact between bodies.
    pub(super) clamped_moves: Option<wgpu::ComputePipeline>,
    /// `fire`: the control words, then the partials.
    pub(super) buffer: wgpu::Buffer,
}

impl DeviceFire {
    /// Zero velocities, Δt = Δt₀ (`dt`), α = 0.1, and the kernels compiled
    /// against the backend's main bind group layout.
    pub(super) fn new(
        ctx: &GpuContext,
        main_layout: &wgpu::BindGroupLayout,
        model: &Model,
        settings: &FireSettings,
        dt: f64,
        workgroup: u32,
    ) -> Result<Self, String> {
        let n = model.len();
        let blocks = (n as u32).div_ceil(workgroup);
        let mut control = vec![[0f32; 4]; FIRE_PARTIALS + blocks as usize];
        control[FIRE_STATE] = [dt as f32, ALPHA0 as f32, f32::from_bits(0), f32::from_bits(0)];
        control[FIRE_MIXING] = [0.0, 0.0, dt as f32, (DT_MAX_FACTOR * dt) as f32];
        control[FIRE_LIMITS] = [settings.ftol as f32, settings.dmax as f32, 0.0, f32::from_bits(blocks)];
        let device = &ctx.device;
        // wgpu zeroes a new buffer: the velocities start at rest.
        let velocities = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("fire_v"),
            size: 16 * n.max(1) as u64,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("fire"),
            contents: bytemuck::cast_slice(&control),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC,
        });
        let side = SideGroup::new(ctx, main_layout, model, "minimize on the device", &[(5, false, &velocities), (6, false, &buffer)])?;
        Ok(Self {
            partials: side.pipeline(ctx, "fire_partials"),
            control: side.pipeline(ctx, "fire_control"),
            moves: side.pipeline(ctx, "fire_move"),
            clamped_moves: model.has_contact_terms().then(|| side.pipeline(ctx, "fire_clamped_move")),
            group: side.group,
            buffer,
        })
    }

    /// The bytes of the control entries that [`Self::counts`] reads.
    pub(super) const COUNT_BYTES: u64 = 16 * FIRE_PARTIALS as u64;

    /// The iterations taken and the moves the contact step clamp shortened,
    /// from the control entries' bytes.
    pub(super) fn counts(bytes: &[u8]) -> (u64, u64) {
        let entries: [[f32; 4]; FIRE_PARTIALS] = bytemuck::pod_read_unaligned(&bytes[..Self::COUNT_BYTES as usize]);
        (u64::from(entries[FIRE_STATE][3].to_bits()), u64::from(entries[FIRE_CLAMPED][0].to_bits()))
    }
}

impl StepFeature for DeviceFire {
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        if phase == Phase::Move {
            pass.set_bind_group(1, &self.group, &[]);
            at.dispatch_all(pass, &[(&self.partials, Over::Particles), (&self.control, Over::Groups(1)), (&self.moves, Over::Particles)]);
            if let Some(clamped) = &self.clamped_moves {
                at.dispatch(pass, clamped, Over::Particles);
            }
        }
    }
}
