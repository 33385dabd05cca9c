//! Deterministic parallel reduction.

use rayon::prelude::*;

/// Chunk size of [`ordered_sum`]; fixed so the result never depends on the
/// number of threads.
const CHUNK: usize = 4096;

/// Sum of `values` in an order fixed by the data alone (chunks of 4096 summed
/// left to right in parallel, then the chunk sums left to right): bit-identical
/// on any thread count.
pub fn ordered_sum(values: &[f64]) -> f64 {
    let partial: Vec<f64> = values.par_chunks(CHUNK).map(|c| c.iter().sum::<f64>()).collect();
    partial.iter().sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_bits_on_one_and_two_threads() {
        let values: Vec<f64> = (0..100_003).map(|i| ((i as f64) * 0.618).sin() * 10f64.powi(i % 7)).collect();
        let one = rayon::ThreadPoolBuilder::new().num_threads(1).build().unwrap().install(|| ordered_sum(&values));
        let two = rayon::ThreadPoolBuilder::new().num_threads(2).build().unwrap().install(|| ordered_sum(&values));
        assert_eq!(one.to_bits(), two.to_bits());
    }
}
