//! Newton's-third-law force accumulation, deterministic on any thread count.
//!
//! A pair term evaluated once adds f to one particle and −f to the other.
//! Done in parallel, those scattered additions would race, and with atomics
//! the order of the float additions (so the last bits of every force) would
//! depend on the thread count and scheduling. [`Newton`] instead fixes the
//! order by the data alone:
//!
//! - Particles are cut into blocks of [`BLOCK`] consecutive indices (a
//!   constant, never the thread count).
//! - **Scatter** (parallel over blocks): block b visits its rows in ascending
//!   index order; a term of row i (a pair (i, j), or any term whose forces
//!   the row adds particle by particle) adds its force on each particle
//!   directly in the block's own slice of the force array when the particle
//!   is in the block, and otherwise appends (particle, force) to the block's
//!   *spill* bucket for that particle's block.
//! - **Gather** (parallel over blocks): block t adds to its particles the
//!   spills addressed to it by blocks 0, 1, 2, … in block order, each bucket
//!   in the order it was filled.
//!
//! So particle p receives: first its in-block terms in (row, term) order,
//! then the spills of block 0, block 1, …, each in (row, term) order. That
//! sequence is a function of which terms act (e.g. which pairs of the half
//! neighbour list are within their cutoff) and of nothing else: not of the
//! thread count, and not of when the neighbour list was rebuilt (a half-list
//! row is sorted and only pairs within the cutoff add anything).
//!
//! Memory: one 32-byte spill per term whose partner lies in another block
//! (with particles numbered along the space, as builders and lattices do,
//! a minority), plus one empty bucket per (block, block), reused between
//! steps: no allocation once the buckets have grown.

use std::ops::Range;

use glam::DVec3;
use rayon::prelude::*;

/// Particles per block: fixed, so results never depend on the thread count.
pub(super) const BLOCK: usize = 4096;

/// The spill buckets, kept between force passes.
#[derive(Default)]
pub(super) struct Newton {
    /// `spills[source][target]`: (particle, force) added by block `source`
    /// to particles of block `target`, in the order they were produced.
    spills: Vec<Vec<Vec<(u32, DVec3)>>>,
}

/// One block's view during the scatter: its slice of the force array and
/// its spill buckets.
pub(super) struct Scatter<'a> {
    start: usize,
    local: &'a mut [DVec3],
    spill: &'a mut [Vec<(u32, DVec3)>],
}

impl Scatter<'_> {
    /// Adds f to particle `p` (anywhere).
    #[inline(always)]
    pub(super) fn add(&mut self, p: usize, f: DVec3) {
        match self.local.get_mut(p.wrapping_sub(self.start)) {
            Some(fp) => *fp += f,
            None => self.spill[p / BLOCK].push((p as u32, f)),
        }
    }

    /// Adds f to particle `i` (in this block) and −f to particle `j` (anywhere).
    #[inline(always)]
    pub(super) fn pair(&mut self, i: usize, j: usize, f: DVec3) {
        self.local[i - self.start] += f;
        self.partner(j, f);
    }

    /// The force so far on particle `i` (in this block). A row of pairs
    /// (i, j > i) adds to i in a register, [`Self::own`] then each f, then
    /// [`Self::set_own`]: the same additions in the same order as
    /// [`Self::pair`] per pair, since no partner j is i.
    #[inline(always)]
    pub(super) fn own(&self, i: usize) -> DVec3 {
        self.local[i - self.start]
    }

    /// Stores the force on particle `i` (in this block) back (see [`Self::own`]).
    #[inline(always)]
    pub(super) fn set_own(&mut self, i: usize, f: DVec3) {
        self.local[i - self.start] = f;
    }

    /// Adds −f to particle `j` (anywhere): the partner's half of a pair.
    #[inline(always)]
    pub(super) fn partner(&mut self, j: usize, f: DVec3) {
        match self.local.get_mut(j.wrapping_sub(self.start)) {
            Some(fj) => *fj -= f,
            None => self.spill[j / BLOCK].push((j as u32, -f)),
        }
    }
}

impl Newton {
    /// Scatter: zeroes `forces`, then runs `rows(range, scatter)` for each
    /// block's range of particles, in parallel. `rows` must visit its rows in
    /// ascending order and each row's terms in a fixed order. Returns what
    /// each block returned, in block order (for ordered energy reductions).
    pub(super) fn scatter<A: Send>(&mut self, forces: &mut [DVec3], rows: impl Fn(Range<usize>, &mut Scatter) -> A + Sync) -> Vec<A> {
        let blocks = forces.len().div_ceil(BLOCK);
        if self.spills.len() != blocks {
            self.spills = (0..blocks).map(|_| (0..blocks).map(|_| Vec::new()).collect()).collect();
        }
        forces
            .par_chunks_mut(BLOCK)
            .zip(self.spills.par_iter_mut())
            .enumerate()
            .map(|(b, (local, spill))| {
                local.fill(DVec3::ZERO);
                spill.iter_mut().for_each(Vec::clear);
                let start = b * BLOCK;
                let range = start..start + local.len();
                rows(range, &mut Scatter { start, local, spill })
            })
            .collect()
    }

    /// Gather: adds to `block` (block `t` of the force array) the spills
    /// addressed to it, source blocks in ascending order. Nothing to do
    /// before the first scatter.
    #[inline]
    pub(super) fn gather(&self, t: usize, block: &mut [DVec3]) {
        let start = t * BLOCK;
        for source in &self.spills {
            for &(j, f) in &source[t] {
                block[j as usize - start] += f;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Pair "forces" between particles far apart in index (so most spill),
    /// summed by scatter + gather on 1 and 3 threads: the same bits, and
    /// equal to a sequential sum in the documented order.
    #[test]
    fn scatter_gather_is_ordered_and_thread_independent() {
        let n = 3 * BLOCK + 77;
        let partners = |i: usize| [(i * 7 + 1) % n, (i * 131 + 4000) % n, (i + 1) % n];
        let force = |i: usize, j: usize| DVec3::new((i as f64 * 0.37).sin(), (j as f64).cos() * 1e3, 1.0 / (1 + i + j) as f64);
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let mut newton = Newton::default();
                let mut f = vec![DVec3::splat(f64::NAN); n];
                newton.scatter(&mut f, |rows, s| {
                    for i in rows {
                        for j in partners(i).into_iter().filter(|&j| j > i) {
                            s.pair(i, j, force(i, j));
                        }
                    }
                });
                f.par_chunks_mut(BLOCK).enumerate().for_each(|(t, block)| newton.gather(t, block));
                f
            })
        };
        let (one, three) = (run(1), run(3));
        assert!(one.iter().zip(&three).all(|(a, b)| a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits)));
        // The documented order: in-block terms by (row, term), then spills by source block.
        let mut expect = vec![DVec3::ZERO; n];
        let mut spilled: Vec<Vec<(usize, DVec3)>> = vec![Vec::new(); n.div_ceil(BLOCK)];
        for i in 0..n {
            for j in partners(i).into_iter().filter(|&j| j > i) {
                expect[i] += force(i, j);
                if j / BLOCK == i / BLOCK {
                    expect[j] -= force(i, j);
                } else {
                    spilled[i / BLOCK].push((j, -force(i, j)));
                }
            }
        }
        for source in &spilled {
            for &(j, f) in source {
                expect[j] += f;
            }
        }
        assert_eq!(one, expect);
        assert!(spilled.iter().map(Vec::len).sum::<usize>() > n / 2, "the test exercises the spills");
    }
}
