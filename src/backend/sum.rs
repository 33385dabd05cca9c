//! Deterministic parallel reduction.

use std::ops::Range;

use rayon::prelude::*;

/// Chunk size of [`chunked`]; fixed so results never depend on the number of
/// threads.
const CHUNK: usize = 4096;

/// `fold(range)` for the ranges of items `0..n` cut into chunks of 4096, in
/// parallel, returned in chunk order: the caller combines them left to right,
/// so a reduction over per-item values computed on the fly has an order fixed
/// by the data alone, bit-identical on any thread count.
pub(super) fn chunked<A: Send>(n: usize, fold: impl Fn(Range<usize>) -> A + Sync + Send) -> Vec<A> {
    (0..n.div_ceil(CHUNK)).into_par_iter().map(|c| fold(c * CHUNK..((c + 1) * CHUNK).min(n))).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A sum in chunk order, as the backend's energy reductions do it.
    fn ordered_sum(values: &[f64]) -> f64 {
        chunked(values.len(), |r| values[r].iter().sum::<f64>()).iter().sum()
    }

    #[test]
    fn same_bits_on_one_and_two_threads() {
        let values: Vec<f64> = (0..100_003).map(|i| ((i as f64) * 0.618).sin() * 10f64.powi(i % 7)).collect();
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| ordered_sum(&values));
        let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap().install(|| ordered_sum(&values));
        assert_eq!(one.to_bits(), two.to_bits());
    }
}
