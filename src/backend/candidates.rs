//! The candidate filter of the pair loop: which partners of a
//! neighbour-list row are within reach, and their separations.
//!
//! A list with a skin holds several times more candidates than pairs in
//! range (33.6 per half-list row for 6 on the benchmark network at skin 1.0),
//! in no predictable pattern, so this filter rather than the laws is most of
//! the pair loop. [`Near::keep`] takes a batch of up to [`BATCH`] candidates
//! j of row i and computes, per candidate,
//!
//! - the separation d = Δ − L·nearest(Δ/L) with Δ = x_j − x_i (minimum image
//!   as [`Images::minimum_image`]: nearest(q) = (q + 1.5·2⁵²) − 1.5·2⁵²),
//! - r² = (d_x·d_x + d_y·d_y) + d_z·d_z (as `DVec3::length_squared`),
//! - whether r² < reach²(j),
//!
//! and lists the kept candidates in batch order, without a branch per
//! candidate (which candidates are in reach follows no pattern a branch
//! predictor could learn): each index is written at the kept count and the
//! count advances by the comparison.
//!
//! Two implementations, chosen at run time. The portable one is that loop
//! over candidates (the x86-64 baseline target has only SSE2, and glam's
//! `DVec3` is three scalars). On a CPU with AVX2 one iteration handles four
//! candidates: their coordinates are gathered straight from the position
//! array into registers, the arithmetic runs on four lanes, the comparison
//! gives a 4-bit mask, and a 16-entry table appends the kept indices at
//! once. Both do the same IEEE operations in the same order, and Rust never
//! contracts a·b + c into a fused multiply-add, so the separations, r² and
//! the kept set are the same bits on either path (tested below).

use glam::DVec3;

use crate::system::Images;

/// Candidates per batch.
pub(super) const BATCH: usize = 64;

/// Candidates per iteration of the AVX2 filter (four f64 in a register).
#[cfg(target_arch = "x86_64")]
const LANES: usize = 4;

/// One batch's candidates: separations and r² by candidate, and the
/// indices (within the batch) of those within reach. One per block of rows.
pub(super) struct Near {
    /// d_x, d_y, d_z by candidate.
    d: [[f64; BATCH]; 3],
    r2: [f64; BATCH],
    kept: [u8; BATCH],
    /// Whether to run the AVX2 filter.
    avx2: bool,
}

impl Near {
    /// The filter for this CPU (AVX2 when it has it).
    pub(super) fn new() -> Self {
        #[cfg(target_arch = "x86_64")]
        let avx2 = std::arch::is_x86_feature_detected!("avx2") && std::arch::is_x86_feature_detected!("popcnt");
        #[cfg(not(target_arch = "x86_64"))]
        let avx2 = false;
        Self::with_avx2(avx2)
    }

    fn with_avx2(avx2: bool) -> Self {
        Self { d: [[0.0; BATCH]; 3], r2: [0.0; BATCH], kept: [0; BATCH], avx2 }
    }

    /// Filters `batch` (at most [`BATCH`] candidates j of the row of x_i)
    /// and returns how many are kept: afterwards [`Self::kept`] lists, in
    /// batch order, the candidates with r² < `reach2(j)`.
    #[inline(always)]
    pub(super) fn keep(&mut self, batch: &[u32], xi: DVec3, x: &[DVec3], images: &Images, reach2: impl Fn(u32) -> f64) -> usize {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is true only when the CPU reported AVX2 and POPCNT.
            return unsafe { self.keep_avx2(batch, xi, x, images, reach2) };
        }
        self.keep_scalar(batch, xi, x, images, reach2)
    }

    /// The portable filter, one candidate at a time.
    #[inline(always)]
    fn keep_scalar(&mut self, batch: &[u32], xi: DVec3, x: &[DVec3], images: &Images, reach2: impl Fn(u32) -> f64) -> usize {
        let mut kept = 0;
        for (k, &j) in batch.iter().enumerate() {
            let d = images.minimum_image(x[j as usize] - xi);
            let r2 = d.length_squared();
            (self.d[0][k], self.d[1][k], self.d[2][k], self.r2[k]) = (d.x, d.y, d.z, r2);
            self.kept[kept] = k as u8;
            kept += usize::from(r2 < reach2(j));
        }
        kept
    }

    /// The AVX2 filter, four candidates at a time (the module docs).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,popcnt")]
    fn keep_avx2(&mut self, batch: &[u32], xi: DVec3, x: &[DVec3], images: &Images, reach2: impl Fn(u32) -> f64) -> usize {
        use std::arch::x86_64::*;
        const { assert!(size_of::<DVec3>() == 3 * size_of::<f64>() && BATCH.is_multiple_of(LANES)) };
        let n = batch.len();
        // The gathers below read x[j] unchecked: check every j once (a vector max).
        let last = batch.iter().fold(0, |m, &j| m.max(j)) as usize;
        assert!(n <= BATCH && (n == 0 || last < x.len()) && x.len() <= i32::MAX as usize / 3);
        let (lengths, inverses) = images.lengths_and_inverses();
        let axis = |a: usize| (_mm256_set1_pd(xi[a]), _mm256_set1_pd(lengths[a]), _mm256_set1_pd(inverses[a]));
        let axes = [axis(0), axis(1), axis(2)];
        let shift = _mm256_set1_pd(Images::SHIFT);
        let base = x.as_ptr().cast::<f64>();
        let mut kept = 0;
        for g in (0..n).step_by(LANES) {
            let lanes = (n - g).min(LANES);
            let load = _mm_cmplt_epi32(_mm_setr_epi32(0, 1, 2, 3), _mm_set1_epi32(lanes as i32));
            // SAFETY: the mask loads only batch[g..g + lanes] (the rest read as 0).
            let j = unsafe { _mm_maskload_epi32(batch.as_ptr().add(g).cast(), load) };
            let j3 = _mm_add_epi32(_mm_add_epi32(j, j), j);
            let mut d = [_mm256_setzero_pd(); 3];
            for (a, &(xa, length, inverse)) in axes.iter().enumerate() {
                // SAFETY: every j is < x.len() (checked above), so 3·j + a
                // (< 2³¹) indexes the f64s of x.
                let xj = unsafe { _mm256_i32gather_pd::<8>(base.add(a), j3) };
                let delta = _mm256_sub_pd(xj, xa);
                let nearest = _mm256_sub_pd(_mm256_add_pd(_mm256_mul_pd(delta, inverse), shift), shift);
                d[a] = _mm256_sub_pd(delta, _mm256_mul_pd(length, nearest));
            }
            let r2 = _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(d[0], d[0]), _mm256_mul_pd(d[1], d[1])), _mm256_mul_pd(d[2], d[2]));
            for (a, &da) in d.iter().enumerate() {
                // SAFETY: g + LANES ≤ BATCH (BATCH is a multiple of LANES).
                unsafe { _mm256_storeu_pd(self.d[a][g..g + LANES].as_mut_ptr(), da) };
            }
            unsafe { _mm256_storeu_pd(self.r2[g..g + LANES].as_mut_ptr(), r2) };
            let reach = |l: usize| batch.get(g + l).map_or(0.0, |&j| reach2(j));
            let within = _mm256_cmp_pd::<_CMP_LT_OQ>(r2, _mm256_setr_pd(reach(0), reach(1), reach(2), reach(3)));
            let mask = _mm256_movemask_pd(within) as usize & ((1 << lanes) - 1);
            // The kept lanes' indices, packed, at the kept count (kept ≤ g, so kept + 4 ≤ BATCH).
            self.kept[kept..kept + LANES].copy_from_slice(&(COMPACT[mask] + 0x0101_0101 * g as u32).to_le_bytes());
            kept += mask.count_ones() as usize;
        }
        kept
    }

    /// The indices (within the batch) of the `kept` candidates kept by the
    /// last [`Self::keep`].
    #[inline(always)]
    pub(super) fn kept(&self, kept: usize) -> &[u8] {
        &self.kept[..kept]
    }

    /// Separation d = x_j − x_i (minimum image) and r² of candidate `k` of the last batch.
    #[inline(always)]
    pub(super) fn separation(&self, k: usize) -> (DVec3, f64) {
        (DVec3::new(self.d[0][k], self.d[1][k], self.d[2][k]), self.r2[k])
    }
}

/// For each 4-bit mask, the positions of its set bits packed into the low
/// bytes of a u32 (little-endian: first position in the lowest byte).
#[cfg(target_arch = "x86_64")]
const COMPACT: [u32; 16] = {
    let mut table = [0u32; 16];
    let mut mask = 0;
    while mask < 16 {
        let (mut lane, mut at) = (0, 0);
        while lane < LANES {
            if mask & (1 << lane) != 0 {
                table[mask] |= (lane as u32) << (8 * at);
                at += 1;
            }
            lane += 1;
        }
        mask += 1;
    }
    table
};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::system::SimBox;

    /// Every batch length from 1 to [`BATCH`], two reach functions, a box
    /// periodic on two axes with particles far outside it: each path of the
    /// filter keeps exactly the candidates that the scalar minimum image
    /// keeps, in order, with the same bits of d and r²; and the AVX2 path
    /// (where the CPU has it) gives the bits of the SSE2 one.
    #[test]
    fn filter_paths_match_the_scalar_minimum_image() {
        let images = SimBox::new(DVec3::ZERO, DVec3::new(7.0, 9.0, 5.0), [true, true, false]).images();
        let mut seed = 0x2545_f491_4f6c_dd1d_u64;
        let mut uniform = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        let x: Vec<DVec3> = (0..500).map(|_| DVec3::new(30.0 * uniform() - 10.0, 9.0 * uniform(), 12.0 * uniform() - 3.0)).collect();
        let reaches: [&dyn Fn(u32) -> f64; 2] = [&|_| 6.25, &|j| if j % 3 == 0 { 1.0 } else { 9.0 }];
        let mut paths = vec![Near::with_avx2(false)];
        if Near::new().avx2 {
            paths.push(Near::with_avx2(true));
        } else {
            eprintln!("this CPU has no AVX2: only the SSE2 path is checked");
        }
        let mut total = [0; 2];
        for (i, n) in (1..=BATCH).enumerate() {
            let batch: Vec<u32> = (0..n).map(|k| ((i * 37 + k * 11) % x.len()) as u32).collect();
            let xi = x[(i * 101) % x.len()];
            for reach2 in reaches {
                let expect: Vec<(u8, DVec3, f64)> = (batch.iter().enumerate())
                    .map(|(k, &j)| (k as u8, images.minimum_image(x[j as usize] - xi)))
                    .map(|(k, d)| (k, d, d.length_squared()))
                    .filter(|&(k, _, r2)| r2 < reach2(batch[k as usize]))
                    .collect();
                for (p, near) in paths.iter_mut().enumerate() {
                    let kept = near.keep(&batch, xi, &x, &images, reach2);
                    let got: Vec<(u8, DVec3, f64)> =
                        (near.kept(kept).iter()).map(|&k| (k, near.separation(k as usize))).map(|(k, (d, r2))| (k, d, r2)).collect();
                    let bits = |v: &[(u8, DVec3, f64)]| {
                        v.iter().map(|(k, d, r2)| (*k, d.to_array().map(f64::to_bits), r2.to_bits())).collect::<Vec<_>>()
                    };
                    assert_eq!(bits(&got), bits(&expect), "path {p}, batch of {n}");
                    total[p] += kept;
                }
            }
        }
        assert!(total[0] > 100 && total[0] < 64 * 65, "the test keeps some candidates and drops others: {total:?}");
    }
}
