//! Pair terms between bonded neighbours with a fractional `special_bonds`
//! weight on the GPU (the CPU's: backend/special.rs). Such pairs are left
//! out of the neighbour list with every excluded pair; each particle then
//! evaluates its own list of them (CSR by particle, partners ascending, each
//! with its weight w as f32 bits; kernel in shaders/common/special.wgsl):
//! every pair rule of the two types, scaled by w, half the energy each side.
//! No float atomics, the order fixed by the list. The list follows the
//! bound bonds, so it is packed again with every bond-state upload.

use super::pack::push_csr;
use crate::system::Model;

/// The per-particle list of fractional-weight partners: n + 1 offsets
/// (counting entries), and the entries `(partner, w bits)` flattened.
pub fn pack_special(model: &Model, bound: Option<&[bool]>) -> (Vec<u32>, Vec<u32>) {
    let mut rows: Vec<Vec<u32>> = vec![Vec::new(); model.len()];
    if model.special_bonds.is_fractional() && !model.pair_rules.is_empty() {
        for (i, j, w) in model.special_pairs(bound).into_iter().filter(|&(_, _, w)| w > 0.0) {
            rows[i as usize].extend([j, (w as f32).to_bits()]);
            rows[j as usize].extend([i, (w as f32).to_bits()]);
        }
        rows.iter_mut().for_each(sort_pairs);
    }
    let (mut offsets, mut flat) = (Vec::new(), Vec::new());
    push_csr(&rows, &mut offsets, &mut flat);
    offsets.iter_mut().for_each(|o| *o /= 2);
    (offsets, flat)
}

/// Sorts a row of `(partner, weight)` word pairs by partner.
fn sort_pairs(row: &mut Vec<u32>) {
    let mut pairs: Vec<[u32; 2]> = row.chunks(2).map(|c| [c[0], c[1]]).collect();
    pairs.sort_unstable();
    *row = pairs.concat();
}
