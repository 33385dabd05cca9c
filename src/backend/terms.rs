//! Every force term as *segments*: the decomposition that measurements
//! (per-particle virial, method-of-planes tension, cortical tension) read.
//!
//! A term with particles p_1 … p_n and forces f_1 … f_n (Σ f = 0) is written
//! as segments (from, d, f): the force `f` acts on the particle at
//! `from + d`, and is transmitted to it along the segment from `from`.
//!
//! | term | segments | virial Σ d ⊗ f |
//! |---|---|---|
//! | bond, pair (i, j) | (x_i, x_j − x_i, f_j) | r_ji ⊗ f_j = r_ij ⊗ f_i |
//! | angle (i, j, k), vertex j | (x_j, x_i − x_j, f_i), (x_j, x_k − x_j, f_k) | as the global virial |
//! | body term on nodes k | (c, x_k − c, f_k), c the nodes' centroid | as the global virial |
//! | volume element (x_0 … x_3) | (x_0, x_k − x_0, f_k), k = 1, 2, 3 | as the global virial |
//!
//! Positions are image-consistent (minimum image from `from`), so the sum of
//! the segments' d ⊗ f over all terms is exactly the virial tensor W of
//! [`Forces::virial`](super::Forces::virial), term by term. External fields
//! are one-body terms: they transmit nothing and have no segments (and no
//! virial, as in the thermo pressure).
//!
//! Terms are read from the backend's state at its last force evaluation
//! (`compute` or `compute_forces` at the same positions): pair kernels,
//! angle slots and body slots are reused, not re-evaluated.

use glam::DVec3;

use super::bonded::{eval_angle, eval_tetra};
use super::pair_table::PairGeometry;
use super::CpuBackend;
use crate::system::{Model, SimBox, State};

/// What kind of force-field entry a [`Term`] comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TermKind {
    Bond,
    Pair,
    Angle,
    /// A surface (`body`) term; segments start at the body's node centroid.
    Body,
    /// A volume element; segments start at its first corner.
    Tetra,
}

/// One segment of a term: `force` acts on the particle at `from + d`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Segment {
    pub from: DVec3,
    pub d: DVec3,
    pub force: DVec3,
}

/// One force term: its particles (internal indices) and its segments.
#[derive(Clone, Copy, Debug)]
pub struct Term<'a> {
    pub kind: TermKind,
    pub particles: &'a [u32],
    pub segments: &'a [Segment],
    /// For bonds: the bond index (tension per bond); otherwise `usize::MAX`.
    pub bond: usize,
}

impl CpuBackend {
    /// Calls `visit` for every bond, pair (each unordered pair once), angle,
    /// volume element and body term at `state`, in that order. Unbound bonds and terms that
    /// exert no force are skipped. Needs a force evaluation at `state` first.
    pub fn for_each_term(&self, model: &Model, state: &State, sim_box: &SimBox, mut visit: impl FnMut(&Term)) {
        let x = &state.positions;
        let images = sim_box.images();
        let bond_state = state.bonds.as_ref();
        let bonded = self.bonded();
        for (b, pair) in model.bonds.iter().enumerate() {
            let [i, j] = *pair;
            let d = images.minimum_image(x[j as usize] - x[i as usize]);
            let r = d.length();
            let Some(radial) = bonded.bond_radial(b, model.bond_type[b] as usize, r, model, bond_state) else { continue };
            let segment = Segment { from: x[i as usize], d, force: -radial.force_along(d, r) };
            visit(&Term { kind: TermKind::Bond, particles: pair, segments: &[segment], bond: b });
        }
        if let Some(list) = self.neighbor_list() {
            let geometry = PairGeometry { x, types: &model.types, list, images };
            for (i, &xi) in x.iter().enumerate() {
                self.pair_table().for_each_term(i, &geometry, |_, d, r, radial, j| {
                    let segment = Segment { from: xi, d, force: -radial.force_along(d, r) };
                    visit(&Term { kind: TermKind::Pair, particles: &[i as u32, j], segments: &[segment], bond: usize::MAX });
                });
            }
        }
        self.special_pairs().for_each(model, x, &images, |i, j, d, r, radial, _| {
            let segment = Segment { from: x[i as usize], d, force: -radial.force_along(d, r) };
            visit(&Term { kind: TermKind::Pair, particles: &[i, j], segments: &[segment], bond: usize::MAX });
        });
        for a in 0..model.angles.len() {
            let ([xi, xj, xk], out) = eval_angle(model, a, x, &images);
            let segments = [Segment { from: xj, d: xi - xj, force: out.forces[0] }, Segment { from: xj, d: xk - xj, force: out.forces[2] }];
            visit(&Term { kind: TermKind::Angle, particles: &model.angles[a], segments: &segments, bond: usize::MAX });
        }
        for e in 0..model.tetras.len() {
            let (at, out) = eval_tetra(model, e, x, &images, &bonded.nodal);
            let segments = [1usize, 2, 3].map(|k| Segment { from: at[0], d: at[k] - at[0], force: out.forces[k] });
            visit(&Term { kind: TermKind::Tetra, particles: &model.tetras[e], segments: &segments, bond: usize::MAX });
        }
        let mut segments = Vec::new();
        self.surfaces().for_each_term(model, |nodes, xs, forces| {
            let centre = xs.iter().sum::<DVec3>() / xs.len() as f64;
            segments.clear();
            segments.extend(xs.iter().zip(forces).map(|(p, f)| Segment { from: centre, d: *p - centre, force: *f }));
            visit(&Term { kind: TermKind::Body, particles: nodes, segments: &segments, bond: usize::MAX });
        });
    }
}
