//! Reading the device's buffers back (each read a synchronisation): the
//! state, the forces, the neighbour list, the status words and the features'
//! reports.

use glam::DVec3;

use super::GpuBackend;
use crate::gpu::contact::CONTACT_ONLY;
use crate::gpu::fire::DeviceFire;
use crate::gpu::kinetics::KinLayout;
use crate::gpu::prelude::status::STATUS_WORDS;
use crate::gpu::shake::ShakeReport;
use crate::integrate::implicit::SolveReport;
use crate::system::State;

impl GpuBackend {
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

    /// FIRE iterations taken so far and the moves the contact step clamp
    /// shortened (one small read-back; None without FIRE).
    pub fn fire_counts(&self) -> Option<(u64, u64)> {
        let fire = self.features.fire.as_ref()?;
        Some(DeviceFire::counts(&self.read(&fire.buffer, DeviceFire::COUNT_BYTES)))
    }

    /// The last implicit step's iterations and relative residual (one small
    /// read-back; None without the implicit step).
    pub fn implicit_report(&self) -> Option<SolveReport> {
        let solver = self.features.implicit.as_ref()?;
        Some(solver.report(&self.read_at(&solver.buffer, solver.report_at, 16)))
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
        let n = self.params.sizes.n as u64;
        let data: Vec<[f32; 4]> = bytemuck::cast_slice(&self.read(&self.buffers.force, 16 * n)).to_vec();
        data.iter().map(|f| (DVec3::new(f[0] as f64, f[1] as f64, f[2] as f64), f[3] as f64)).collect()
    }

    /// The neighbour list of the last build, each particle's list sorted.
    pub fn neighbor_lists(&self) -> Vec<Vec<u32>> {
        let n = self.params.sizes.n as usize;
        let cap = self.params.sizes.nlist_cap as usize;
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

    pub(super) fn read(&self, buffer: &wgpu::Buffer, bytes: u64) -> Vec<u8> {
        self.read_at(buffer, 0, bytes)
    }

    /// Whether the bond kinetics are decided on the device, and its buffer's layout.
    pub(in crate::gpu) fn device_kinetics(&self) -> Option<&KinLayout> {
        self.features.kinetics.as_ref().map(|k| &k.layout)
    }

    /// `count` words of the device kinetics' buffer from word `at`.
    pub(in crate::gpu) fn read_kin(&self, at: u64, count: u64) -> Vec<u32> {
        bytemuck::cast_slice(&self.read_at(&self.buffers.kin, 4 * at, 4 * count)).to_vec()
    }

    /// Writes `data` into the device kinetics' buffer at word `at`.
    pub(in crate::gpu) fn write_kin(&self, at: u64, data: &[u32]) {
        self.ctx.queue.write_buffer(&self.buffers.kin, 4 * at, super::words(data));
    }

    /// Read-backs from the GPU so far (each one a synchronisation).
    pub fn read_backs(&self) -> u64 {
        self.reads.get()
    }

    pub(super) fn read_at(&self, buffer: &wgpu::Buffer, offset: u64, bytes: u64) -> Vec<u8> {
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

    pub(super) fn status(&self) -> [u32; STATUS_WORDS] {
        bytemuck::cast_slice(&self.read(&self.buffers.status, 4 * STATUS_WORDS as u64)).try_into().expect("status words")
    }
}
