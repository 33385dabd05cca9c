//! Pair terms between bonded neighbours with a fractional `special_bonds`
//! weight (LAMMPS `special_bonds lj W12 W13 W14`, 0 < W < 1).
//!
//! Every bonded neighbour pair whose weight is not 1 is left out of the
//! neighbour list (`Model::excluded_pairs`); those with a weight strictly
//! between 0 and 1 are evaluated here instead, each pair rule of their types
//! within its cutoff scaled by the weight: E = w·E_pair(r), F = w·F_pair(r).
//! The list follows the bound bonds (rebuilt with the exclusions). Pairs are
//! summed serially in list order after the parallel gather, so forces stay
//! independent of the thread count.

use glam::DVec3;

use super::virial::{add6, outer};
use crate::interactions::{Radial, RadialLaw};
use crate::system::{registry_index, Images, Model};

/// The bonded neighbour pairs of fractional weight (i < j, weight).
#[derive(Clone, Debug, Default)]
pub(super) struct SpecialPairs {
    list: Vec<(u32, u32, f64)>,
}

impl SpecialPairs {
    pub fn new(model: &Model, bound: Option<&[bool]>) -> Self {
        if !model.special_bonds.is_fractional() || model.pair_rules.is_empty() {
            return Self::default();
        }
        Self { list: model.special_pairs(bound).into_iter().filter(|&(_, _, w)| w > 0.0).collect() }
    }

    /// Calls `visit(i, j, d, r, weighted radial, rule)` for each pair and
    /// each of its rules within range; d = x_j − x_i (minimum image).
    pub fn for_each(&self, model: &Model, x: &[DVec3], images: &Images, mut visit: impl FnMut(u32, u32, DVec3, f64, Radial, usize)) {
        for &(i, j, w) in &self.list {
            let d = images.minimum_image(x[j as usize] - x[i as usize]);
            let r = d.length();
            for &rule in model.pair_rules_between(model.types[i as usize], model.types[j as usize]) {
                let term = &model.pair_rules[rule as usize];
                let RadialLaw { eval, range, .. } = term.law;
                if r < range(&term.params) {
                    let e = eval(&term.params, r);
                    let weighted = Radial { energy: w * e.energy, de_dr: w * e.de_dr, d2e_dr2: w * e.d2e_dr2 };
                    visit(i, j, d, r, weighted, rule as usize);
                }
            }
        }
    }

    /// Adds the weighted pair forces, and with `energies` their energy (per
    /// registry entry) and virial.
    pub fn add(&self, model: &Model, x: &[DVec3], images: &Images, forces: &mut [DVec3], energies: Option<(&mut [f64], &mut [f64; 6])>) {
        if self.list.is_empty() {
            return;
        }
        let mut energies = energies;
        self.for_each(model, x, images, |i, j, d, r, radial, rule| {
            let f = radial.force_along(d, r);
            forces[i as usize] += f;
            forces[j as usize] -= f;
            if let Some((energy, virial)) = energies.as_mut() {
                energy[registry_index(&model.pair_rules[rule])] += radial.energy;
                add6(virial, outer(d, -f));
            }
        });
    }
}
