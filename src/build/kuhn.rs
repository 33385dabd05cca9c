//! What the solid meshes (`ball`, `block`) share: the six-tetrahedra (Kuhn)
//! split of a lattice cell, graded node spacings, and the mesh quality
//! they print.
//!
//! A cell's six Kuhn tetrahedra lie around one of its diagonals, one per
//! order in which the path along the diagonal takes the three axes; two
//! cells that take their diagonals the same way, or in mirror image about
//! the face they share, split that face along the same diagonal, so a
//! lattice whose split is mirrored about lattice planes stays conforming.

use glam::DVec3;

use super::{min_mean_max, Writer};
use crate::mesh::tetra_edges;

/// The orders in which a diagonal path takes the axes: one tetrahedron each.
const ORDERS: [[usize; 3]; 6] = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];

/// The lattice corners of the six Kuhn tetrahedra of the cell whose lowest
/// corner is `cell`: each diagonal path starts on the cell's low side along
/// the axes where `upward` holds (and steps up) and on its high side along
/// the others (and steps down).
fn cell_tetrahedra(cell: [usize; 3], upward: [bool; 3]) -> [[[usize; 3]; 4]; 6] {
    let start: [usize; 3] = std::array::from_fn(|a| if upward[a] { cell[a] } else { cell[a] + 1 });
    ORDERS.map(|order| {
        let mut corner = start;
        let mut corners = [start; 4];
        for (step, &axis) in order.iter().enumerate() {
            corner[axis] = if upward[axis] { corner[axis] + 1 } else { corner[axis] - 1 };
            corners[step + 1] = corner;
        }
        corners
    })
}

/// The largest growth ratio of graded spacings: beyond it a cell is more
/// than four times its neighbour.
const MAX_RATIO: f64 = 4.0;

/// The node coordinates 0 = t_0 < … < t_n = `extent` along one axis (or
/// the radii of a ball's shells), and the growth ratio of their spacings:
/// uniform without `spacing`; with it, `core` spacings of that size and
/// then spacings growing by the constant ratio q ∈ [1, 4] that ends the
/// sequence at `extent` (`option` names the extent in errors).
pub(super) fn graded(option: &str, extent: f64, n: usize, spacing: Option<f64>, core: usize) -> Result<(Vec<f64>, f64), String> {
    let Some(h) = spacing else {
        return Ok(((0..=n).map(|i| extent * i as f64 / n as f64).collect(), 1.0));
    };
    let grown = n - core;
    let rest = extent - core as f64 * h;
    // The grown spacings h·q, h·q², …, h·q^g add up to `rest`.
    let sum = |q: f64| (1..=grown).map(|i| h * q.powi(i as i32)).sum::<f64>();
    if rest < sum(1.0) * (1.0 - 1e-12) {
        return Err(format!(
            "expected {option} ≥ {n} × --spacing = {} (the spacings cannot shrink outwards), found {extent}",
            n as f64 * h
        ));
    }
    if sum(MAX_RATIO) < rest {
        return Err(format!(
            "expected a growth ratio of the spacings ≤ {MAX_RATIO} to reach {option} {extent}: give more --cells or a larger --spacing"
        ));
    }
    let (mut lo, mut hi) = (1.0, MAX_RATIO);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if sum(mid) < rest {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let q = 0.5 * (lo + hi);
    let mut t = vec![0.0];
    for i in 1..=n {
        let step = if i <= core { h } else { h * q.powi((i - core) as i32) };
        t.push(t[i - 1] + step);
    }
    t[n] = extent;
    Ok((t, q))
}

/// Puts a tetrahedron's corners in positive orientation (swapping the last
/// two where the signed volume is negative) and returns its volume.
fn orient<T>(nodes: &mut [T; 4], at: &mut [DVec3; 4]) -> f64 {
    if tetra_edges(*at).determinant() < 0.0 {
        nodes.swap(2, 3);
        at.swap(2, 3);
    }
    tetra_edges(*at).determinant() / 6.0
}

/// Mesh quality 6√2·V/ℓ_rms³ of a tetrahedron (1: regular).
fn quality(x: [DVec3; 4]) -> f64 {
    let volume = tetra_edges(x).determinant().abs() / 6.0;
    let sum: f64 = (0..4).flat_map(|a| (a + 1..4).map(move |b| (a, b))).map(|(a, b)| (x[a] - x[b]).length_squared()).sum();
    6.0 * 2f64.sqrt() * volume / (sum / 6.0).powf(1.5)
}

/// The elements a solid mesh writes, cell by cell, with their volumes and
/// qualities for its summary.
#[derive(Default)]
pub(super) struct Elements {
    volumes: Vec<f64>,
    qualities: Vec<f64>,
}

impl Elements {
    /// Writes the six Kuhn tetrahedra of lattice cell `cell` (see
    /// [`cell_tetrahedra`]) in positive orientation: `node` maps a lattice
    /// corner to its index in the positions `x` and the particle ids `id`.
    pub(super) fn cell(
        &mut self,
        writer: &mut Writer,
        tetra_type: &str,
        (cell, upward): ([usize; 3], [bool; 3]),
        node: impl Fn([usize; 3]) -> usize,
        (x, id): (&[DVec3], &[u64]),
    ) {
        for corners in cell_tetrahedra(cell, upward) {
            let mut nodes = corners.map(&node);
            let mut at = nodes.map(|v| x[v]);
            self.volumes.push(orient(&mut nodes, &mut at));
            self.qualities.push(quality(at));
            writer.tetra(tetra_type, nodes.map(|v| id[v]));
        }
    }

    pub(super) fn count(&self) -> usize {
        self.volumes.len()
    }

    pub(super) fn total_volume(&self) -> f64 {
        self.volumes.iter().sum()
    }

    /// The summary line of the element volumes and qualities.
    pub(super) fn summary(&self) -> String {
        let [q_lo, q_mean, _] = min_mean_max(&self.qualities);
        let [v_lo, v_mean, v_hi] = min_mean_max(&self.volumes);
        format!("element volume min {v_lo:.3e} mean {v_mean:.3e} max {v_hi:.3e}; quality 6√2·V/ℓ_rms³ min {q_lo:.3} mean {q_mean:.3} (regular: 1)")
    }
}
