//! The host's side of the neighbour list (src/gpu/neighbours.rs): its
//! counters, its growth after an overflow and the limits tests lower.

use super::GpuBackend;
use crate::gpu::prelude::status::{HALT_OVERFLOW, STATUS_WORDS, ST_HALTED, ST_OVERFLOW_NEED};

impl GpuBackend {
    /// Neighbour-list builds so far.
    pub fn neighbor_builds(&self) -> u64 {
        self.list.builds
    }

    /// How many times the neighbour list had to grow (overflow and retry).
    pub fn neighbor_list_growths(&self) -> u32 {
        self.list.grown
    }

    /// Neighbour-list capacity per particle.
    pub fn neighbor_capacity(&self) -> u32 {
        self.params.sizes.nlist_cap
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
        self.list.resize(&self.ctx, self.params.sizes.n, self.params.sizes.nlist_cap)?;
        self.bindings.main = self.bind_main();
        Ok(())
    }

    /// Handles an overflow: grows the list and clears the halt. Returns
    /// whether there was one, or why the list cannot grow.
    pub(super) fn grow_if_overflowed(&mut self, status: &[u32; STATUS_WORDS]) -> Result<bool, String> {
        if status[ST_HALTED] & HALT_OVERFLOW == 0 {
            return Ok(false);
        }
        self.reserve_neighbors(status[ST_OVERFLOW_NEED])?;
        Ok(true)
    }

    /// Grows the neighbour list to hold `need` neighbours per particle (with
    /// a quarter's margin); nothing if it does. The list is rebuilt before the next step.
    pub fn reserve_neighbors(&mut self, need: u32) -> Result<(), String> {
        if need <= self.params.sizes.nlist_cap {
            return Ok(());
        }
        let need = need as u64;
        let cap = (need + need / 4 + 8).next_multiple_of(8) as u32;
        self.list.resize(&self.ctx, self.params.sizes.n, cap)?;
        self.params.sizes.nlist_cap = cap;
        self.bindings.main = self.bind_main();
        self.list.grown += 1;
        self.implicit_list_check()
    }

    /// The implicit step's one-workgroup solve reads the pair rows from one
    /// binding of the neighbour list (src/gpu/implicit.rs): a list bound in
    /// chunks is refused.
    pub(super) fn implicit_list_check(&self) -> Result<(), String> {
        if self.features.implicit.is_some() && self.list.active && self.list.storage.chunks > 1 {
            return Err(format!(
                "integrator implicit with pair terms: the neighbour list ({} particles × {} neighbours) needs {} bindings on {}; \
                 the device's implicit solve reads it from one (use `device cpu`)",
                self.params.sizes.n, self.params.sizes.nlist_cap, self.list.storage.chunks, self.ctx.info.name
            ));
        }
        Ok(())
    }

    /// The neighbours per particle the list met, at least its capacity: with
    /// the largest count of a check after `commit` that overflowed (which
    /// halts with [`GpuHalt::Formation`](super::GpuHalt::Formation), src/gpu/bind.rs), so a backend
    /// built anew can [`Self::reserve_neighbors`] them.
    pub fn neighbors_met(&self) -> u32 {
        self.params.sizes.nlist_cap.max(self.list.overflow_met)
    }
}
