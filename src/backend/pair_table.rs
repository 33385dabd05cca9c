//! Pair rules resolved per particle-type pair, once per force evaluation.
//!
//! The model keeps pair rules as force-field terms behind `dyn Interaction`;
//! asking each term for its law, its range and its parameters per neighbour
//! pair costs more than the physics. [`PairTable`] resolves them into a flat
//! table of kernels (evaluator, parameters, cutoff, energy column) grouped by
//! type pair, with the largest squared cutoff of each type pair, so the pair
//! loop does one table look-up per neighbour and skips pairs beyond every
//! cutoff before taking a square root.
//!
//! The list is a half list (each pair once, in the row of its lower index):
//! [`PairTable::row_forces`] gives each pair's force once, for the
//! Newton's-third-law accumulation of [`super::newton`], from the laws'
//! force-only evaluators (no energy, no square root where the law needs
//! none); energies and the virial are added in the same pass on thermo
//! steps, so forces have the same bits with or without them. The kernels of
//! a type pair keep the force field's rule order and rows are in ascending
//! partner order, so every sum has an order fixed by the data.

use glam::DVec3;

use super::candidates::{Near, BATCH};
use super::virial::{add6, outer};
use crate::interactions::{Radial, RadialLaw};
use crate::neighbor::NeighborList;
use crate::system::{Images, Model};

/// One pair rule ready to evaluate.
#[derive(Clone, Copy)]
struct Kernel {
    eval: fn(&[f64], f64) -> Radial,
    /// (dE/dr)/r from r² ([`Law::Radial`]).
    force: fn(&[f64], f64) -> f64,
    /// Range of this rule's parameters in [`PairTable::params`].
    params: (u32, u32),
    cutoff: f64,
    /// Column of this rule's interaction among the pair interactions in use.
    column: u32,
}

/// What the pair loop reads: positions, types, the neighbour list, the box.
pub(super) struct PairGeometry<'a> {
    pub x: &'a [DVec3],
    pub types: &'a [u32],
    pub list: &'a NeighborList,
    pub images: Images,
}

/// Pair kernels by particle-type pair; reused between evaluations.
#[derive(Default)]
pub(super) struct PairTable {
    n_types: usize,
    kernels: Vec<Kernel>,
    /// Type pair `a·n_types + b` owns `kernels[start[p]..start[p + 1]]`.
    start: Vec<u32>,
    /// Per type pair: a bound above the largest cutoff², for a quick skip.
    skip2: Vec<f64>,
    params: Vec<f64>,
}

impl PairTable {
    /// Re-resolves the table from `model` (no allocation once sized).
    /// `rule_column[r]` is the energy column of pair rule `r`.
    pub(super) fn update(&mut self, model: &Model, rule_column: &[usize]) {
        let nt = model.type_names.len();
        self.n_types = nt;
        self.kernels.clear();
        self.params.clear();
        self.start.clear();
        self.skip2.clear();
        self.start.push(0);
        for a in 0..nt as u32 {
            for b in 0..nt as u32 {
                let mut reach = 0.0f64;
                for &rule in model.pair_rules_between(a, b) {
                    let term = &model.pair_rules[rule as usize];
                    let RadialLaw { eval, force, range } = term.law;
                    let cutoff = range(&term.params);
                    let first = self.params.len() as u32;
                    self.params.extend_from_slice(&term.params);
                    self.kernels.push(Kernel {
                        eval,
                        force,
                        params: (first, self.params.len() as u32),
                        cutoff,
                        column: rule_column[rule as usize] as u32,
                    });
                    reach = reach.max(cutoff);
                }
                self.start.push(self.kernels.len() as u32);
                // Slightly above cutoff², so that rounding in r² never skips a
                // pair that the exact test `r < cutoff` would keep.
                self.skip2.push(reach * reach * (1.0 + 1e-12));
            }
        }
    }

    /// Calls `visit(column, d, r, radial, j)` for every pair term between
    /// particle `i` and a partner `j > i` (d = x_j − x_i, minimum image),
    /// partners in list order and rules in force-field order.
    #[inline(always)]
    pub(super) fn for_each_term(&self, i: usize, g: &PairGeometry, mut visit: impl FnMut(usize, DVec3, f64, Radial, u32)) {
        let PairGeometry { x, types, list, images } = g;
        let row = types[i] as usize * self.n_types;
        if list.image_shifts().is_some() {
            // A box with short periodic edges: every image of every partner (i's own as j = i).
            list.for_each_separation(i, x, images, |j, d| {
                let pair = row + types[j as usize] as usize;
                let r2 = d.length_squared();
                if r2 < self.skip2[pair] {
                    let r = r2.sqrt();
                    for k in self.kernels_of(pair) {
                        if r < k.cutoff {
                            visit(k.column as usize, d, r, (k.eval)(self.params_of(k), r), j);
                        }
                    }
                }
            });
            return;
        }
        let xi = x[i];
        for &j in list.neighbors(i) {
            let pair = row + types[j as usize] as usize;
            let d = images.minimum_image(x[j as usize] - xi);
            let r2 = d.length_squared();
            if r2 >= self.skip2[pair] {
                continue;
            }
            let r = r2.sqrt();
            for k in self.kernels_of(pair) {
                if r < k.cutoff {
                    visit(k.column as usize, d, r, (k.eval)(self.params_of(k), r), j);
                }
            }
        }
    }

    /// The pair forces of row `i` (its partners `j > i`): calls `visit(j, f)`
    /// with the force f on `i` (−f acts on `j`) of every pair that exerts
    /// one, in list order. With `ENERGY`, also adds each term's energy to its
    /// column of `energy` and r_ij ⊗ f_ij to `virial`; the forces are the
    /// same bits either way.
    ///
    /// The row is walked in batches: first the candidates within reach
    /// ([`Near::keep`], see [`super::candidates`]), then the laws on those.
    #[inline(always)]
    pub(super) fn row_forces<const ENERGY: bool>(
        &self,
        i: usize,
        g: &PairGeometry,
        near: &mut Near,
        energy: &mut [f64],
        virial: &mut [f64; 6],
        mut visit: impl FnMut(usize, DVec3),
    ) {
        let PairGeometry { x, types, list, images } = g;
        let xi = x[i];
        let row = types[i] as usize * self.n_types;
        if list.image_shifts().is_some() {
            // A box with short periodic edges: every image of every partner,
            // one at a time. A particle's own images add energy and virial;
            // their forces cancel in ± pairs, so none is applied.
            list.for_each_separation(i, x, images, |j, d| {
                let pair = row + types[j as usize] as usize;
                let r2 = d.length_squared();
                if r2 >= self.skip2[pair] {
                    return;
                }
                let over_r = self.pair_force::<ENERGY>(pair, r2, energy);
                if over_r != 0.0 {
                    let f = d * over_r;
                    if ENERGY {
                        add6(virial, outer(-d, f));
                    }
                    if j as usize != i {
                        visit(j as usize, f);
                    }
                }
            });
            return;
        }
        for batch in list.neighbors(i).chunks(BATCH) {
            // One particle type (the common case): one reach, no type look-up.
            let kept = match self.skip2[..] {
                [reach2] => near.keep(batch, xi, x, images, |_| reach2),
                _ => near.keep(batch, xi, x, images, |j| self.skip2[row + types[j as usize] as usize]),
            };
            for &k in near.kept(kept) {
                let (j, (d, r2)) = (batch[k as usize] as usize, near.separation(k as usize));
                let over_r = self.pair_force::<ENERGY>(row + types[j] as usize, r2, energy);
                if over_r != 0.0 {
                    let f = d * over_r;
                    if ENERGY {
                        // r_ij ⊗ f_ij with r_ij = x_i − x_j = −d.
                        add6(virial, outer(-d, f));
                    }
                    visit(j, f);
                }
            }
        }
    }

    /// (dE/dr)/r of type pair `pair` at r², summed over its kernels in
    /// force-field order; with `ENERGY`, each kernel's energy within its
    /// cutoff added to its column of `energy`.
    #[inline(always)]
    fn pair_force<const ENERGY: bool>(&self, pair: usize, r2: f64, energy: &mut [f64]) -> f64 {
        let mut over_r = 0.0;
        for kernel in self.kernels_of(pair) {
            over_r += (kernel.force)(self.params_of(kernel), r2);
            if ENERGY {
                let r = r2.sqrt();
                if r < kernel.cutoff {
                    energy[kernel.column as usize] += (kernel.eval)(self.params_of(kernel), r).energy;
                }
            }
        }
        over_r
    }

    #[inline(always)]
    fn kernels_of(&self, pair: usize) -> &[Kernel] {
        &self.kernels[self.start[pair] as usize..self.start[pair + 1] as usize]
    }

    #[inline(always)]
    fn params_of(&self, k: &Kernel) -> &[f64] {
        &self.params[k.params.0 as usize..k.params.1 as usize]
    }
}
