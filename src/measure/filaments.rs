//! Filament statistics: chains of bonds of one bond type.
//!
//! # Chains
//!
//! The filaments of a bond type are the unbranched paths of its bonds
//! (bound or not): each path runs between two particles that do not have
//! exactly two bonds of the type (chain ends and branch points), so a
//! branched network splits at its branch points. Closed rings with no end
//! are not filaments and are left out. A chain's particles are ordered from
//! the end found first (lowest internal index).
//!
//! # Columns
//!
//! | column | meaning | unit |
//! |---|---|---|
//! | `e2e/BONDTYPE` | mean over chains of the end-to-end distance \|Σ_s d_s\| (bond vectors d_s at their minimum image, so chains may cross periodic boundaries) | µm |
//! | `tcorr/BONDTYPE/LAG` | tangent correlation ⟨t_s·t_{s+LAG}⟩ over every pair of bonds LAG apart along a chain, all chains pooled; t_s = d_s/\|d_s\| | – |
//!
//! A straight chain of n bonds of length b has e2e = n·b and tcorr = 1 at
//! every lag; bonds of equal length on a circular arc turning by θ per bond
//! have tcorr/…/LAG = cos(LAG·θ). For a worm-like chain of persistence
//! length ℓ_p, tcorr ≈ exp(−LAG·b/ℓ_p). Columns are NaN when the type has
//! no chain (e2e) or no bond pair LAG apart (tcorr).

use glam::DVec3;

use crate::system::{Model, SimBox};

/// The chains of bond type `bond_type`: ordered particle indices, ≥ 2 each.
pub fn chains(model: &Model, bond_type: usize) -> Vec<Vec<u32>> {
    let n = model.len();
    let bonds: Vec<[u32; 2]> =
        (0..model.bonds.len()).filter(|&b| model.bond_type[b] as usize == bond_type).map(|b| model.bonds[b]).collect();
    let mut adjacency: Vec<Vec<(u32, usize)>> = vec![Vec::new(); n];
    for (k, &[i, j]) in bonds.iter().enumerate() {
        adjacency[i as usize].push((j, k));
        adjacency[j as usize].push((i, k));
    }
    let mut used = vec![false; bonds.len()];
    let mut out = Vec::new();
    for start in 0..n {
        if adjacency[start].len() == 2 {
            continue;
        }
        for &(first, k) in &adjacency[start] {
            if used[k] {
                continue;
            }
            used[k] = true;
            let mut chain = vec![start as u32, first];
            let mut at = first as usize;
            while adjacency[at].len() == 2 {
                let Some(&(next, k)) = adjacency[at].iter().find(|(_, k)| !used[*k]) else { break };
                used[k] = true;
                chain.push(next);
                at = next as usize;
            }
            out.push(chain);
        }
    }
    out
}

/// The bond vectors of a chain at their minimum image.
fn bond_vectors(chain: &[u32], positions: &[DVec3], sim_box: &SimBox) -> Vec<DVec3> {
    let images = sim_box.images();
    chain.windows(2).map(|w| images.minimum_image(positions[w[1] as usize] - positions[w[0] as usize])).collect()
}

/// Mean end-to-end distance of the chains (NaN without chains).
pub fn end_to_end(chains: &[Vec<u32>], positions: &[DVec3], sim_box: &SimBox) -> f64 {
    let total: f64 = chains.iter().map(|c| bond_vectors(c, positions, sim_box).iter().sum::<DVec3>().length()).sum();
    total / chains.len() as f64
}

/// ⟨t_s·t_{s+lag}⟩ pooled over the chains (NaN when no pair is `lag` apart).
pub fn tangent_correlation(chains: &[Vec<u32>], positions: &[DVec3], sim_box: &SimBox, lag: usize) -> f64 {
    let (mut sum, mut count) = (0.0, 0usize);
    for c in chains {
        let t: Vec<DVec3> = bond_vectors(c, positions, sim_box).iter().map(|d| d.normalize()).collect();
        for s in 0..t.len().saturating_sub(lag) {
            sum += t[s].dot(t[s + lag]);
            count += 1;
        }
    }
    sum / count as f64
}
