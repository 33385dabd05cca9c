//! Timing each phase of a step alone ([`GpuBackend::profile`]).

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

use super::GpuBackend;
use crate::gpu::step::Over;

impl GpuBackend {
    /// Times each phase alone, `repetitions` times in one submission (after a
    /// warm-up), waiting for the GPU at the end; seconds per call. The state
    /// is left as it was (integration is timed on a copy of the positions).
    pub fn profile(&mut self, repetitions: u32) -> Result<PhaseTimes, String> {
        self.evaluate()?;
        let saved = self.read(&self.buffers.state, 48 * self.params.sizes.n as u64);
        let particles = Over::Particles;
        let at = self.dispatcher();
        // `group`: the bind group 1 the kernels read (the neighbour decision's
        // arguments, the implicit solver's or the projection's buffers).
        let time = |kernels: &[(&wgpu::ComputePipeline, Over)], group: Option<&wgpu::BindGroup>| {
            if kernels.is_empty() {
                return 0.0;
            }
            let this = &*self;
            let run = |reps: u32| {
                let started = std::time::Instant::now();
                let mut encoder = this.ctx.device.create_command_encoder(&Default::default());
                {
                    let mut pass = encoder.begin_compute_pass(&Default::default());
                    at.bind_main(&mut pass);
                    if let Some(group) = group {
                        pass.set_bind_group(1, group, &[]);
                    }
                    for _ in 0..reps {
                        at.dispatch_all(&mut pass, kernels);
                    }
                }
                this.ctx.queue.submit([encoder.finish()]);
                this.ctx.device.poll(wgpu::PollType::wait_indefinitely()).expect("waiting for the GPU");
                started.elapsed().as_secs_f64()
            };
            run(1);
            run(repetitions) / repetitions as f64
        };
        let (check, neighbor_build) = match self.list.active {
            true => {
                let (passes, args) = self.list.check_passes();
                (time(&passes, Some(args)), time(&self.list.build_passes(self.params.frame.grid[3]), None))
            }
            false => (0.0, 0.0),
        };
        let forces = time(&self.forces.passes(&at), None);
        let contact = time(&self.features.contact_passes.contact_passes(), None);
        let adhesion = time(&self.features.contact_passes.adhesion_passes(), None);
        let k = &self.step;
        let integrate = match &self.features.implicit {
            // The implicit step in place of `integrate` (src/gpu/implicit.rs).
            Some(solver) => {
                // In the step's order (`encode_step`).
                let passes: Vec<_> = solver.step_passes().into_iter().map(|(k, groups)| (k, Over::Groups(groups))).collect();
                time(&passes, Some(&solver.group)) + time(&[(&k.commit, particles), (&k.advance, Over::Groups(1))], None)
            }
            None => time(&[(&k.integrate, particles), (&k.commit, particles), (&k.advance, Over::Groups(1))], None),
        };
        let constraints = match &self.features.shake {
            Some(shake) => time(&shake.passes(), Some(&shake.group)),
            None => 0.0,
        };
        let kinetics = self.features.kinetics.as_ref().map_or(0.0, |kinetics| time(&kinetics.profiled(), None));
        let started = std::time::Instant::now();
        for _ in 0..repetitions {
            self.read(&self.buffers.state, 48 * self.params.sizes.n as u64);
        }
        let readback = started.elapsed().as_secs_f64() / repetitions as f64;
        self.ctx.queue.write_buffer(&self.buffers.state, 0, &saved);
        self.list.pending_rebuild = true;
        Ok(PhaseTimes { check, neighbor_build, forces, integrate, readback, contact, adhesion, kinetics, constraints })
    }
}
