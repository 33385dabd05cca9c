//! Surface (body) terms on the CPU, gathered per particle.
//!
//! A surface term couples all nodes of a body (its volume, its area, its
//! curvature), so it is evaluated once per body and force pass:
//!
//! 1. **Per-body pass** (parallel over bodies): the body's node positions are
//!    made image-consistent (each node placed at the minimum image of its
//!    parent in a breadth-first tree over the mesh edges, so a cell may
//!    straddle a periodic boundary), then each of the body's terms writes its
//!    energy and the force on every node into its own slots.
//! 2. **Gather**: each particle sums its slots in a fixed order — ascending
//!    body, then the body's terms in force-field order — as angles are
//!    gathered in [`bonded`](super::bonded).
//!
//! **Stiffness** (for `integrator implicit`): each term's second-order model
//! at the same image-consistent positions ([`SurfaceHessian`]: stencil
//! Hessians, projected here onto their PSD part, and Gauss–Newton rank-one
//! terms over the whole body), see `src/backend/stiffness.rs`.
//!
//! Energies and the virial W = Σ_k r_k ⊗ f_k (image-consistent positions
//! relative to the body's centroid) are summed body by body, term by term,
//! sequentially: results never depend on the thread count.

use glam::{DMat3, DVec3};
use rayon::prelude::*;

use super::stiffness_blocks::{push_blocks, RankOneTerm, StiffnessBlock};
use super::virial::{add6, outer};
use crate::hessian::{project_psd, SurfaceHessian};
use crate::system::{registry_index, Images, Model};

/// One body's scratch: positions and per-term slots.
struct BodyScratch {
    x: Vec<DVec3>,
    /// Surface terms (indices into `Model::body_rules`) acting on this body.
    rules: Vec<usize>,
    /// forces[r][k]: force of term `rules[r]` on local node k.
    forces: Vec<Vec<DVec3>>,
    energy: Vec<f64>,
}

/// Per-body slots and each particle's list of them.
#[derive(Default)]
pub(super) struct Surfaces {
    bodies: Vec<BodyScratch>,
    /// Particle i's slots are `slots[offsets[i]..offsets[i + 1]]`: (body, local node).
    offsets: Vec<u32>,
    slots: Vec<[u32; 2]>,
}

impl Surfaces {
    pub(super) fn new(model: &Model) -> Self {
        let bodies: Vec<BodyScratch> = (0..model.bodies.len())
            .map(|b| {
                let rules: Vec<usize> = model.rules_of_body(b).collect();
                let nodes = model.bodies[b].nodes.len();
                BodyScratch {
                    x: Vec::with_capacity(nodes),
                    forces: vec![vec![DVec3::ZERO; nodes]; rules.len()],
                    energy: vec![0.0; rules.len()],
                    rules,
                }
            })
            .collect();
        let n = model.len();
        let mut rows: Vec<Vec<[u32; 2]>> = vec![Vec::new(); n];
        for (b, body) in model.bodies.iter().enumerate() {
            if bodies[b].rules.is_empty() {
                continue;
            }
            for (k, &p) in body.nodes.iter().enumerate() {
                rows[p as usize].push([b as u32, k as u32]);
            }
        }
        let mut offsets = Vec::with_capacity(n + 1);
        let mut slots = Vec::new();
        offsets.push(0);
        for row in rows {
            slots.extend(row);
            offsets.push(slots.len() as u32);
        }
        Self { bodies, offsets, slots }
    }

    /// Whether there is anything to evaluate.
    pub(super) fn is_empty(&self) -> bool {
        self.slots.is_empty()
    }

    /// Pass 1: evaluates every term of every body into its slots.
    pub(super) fn prepare(&mut self, model: &Model, x: &[DVec3], images: &Images) {
        if self.is_empty() {
            return;
        }
        self.bodies.par_iter_mut().enumerate().for_each(|(b, scratch)| {
            if scratch.rules.is_empty() {
                return;
            }
            let body = &model.bodies[b];
            body.mesh.unwrap_into(|k| x[body.nodes[k as usize] as usize], |d| images.minimum_image(d), &mut scratch.x);
            for (r, &rule) in scratch.rules.iter().enumerate() {
                let term = &model.body_rules[rule];
                let forces = &mut scratch.forces[r];
                forces.fill(DVec3::ZERO);
                scratch.energy[r] = (term.law.eval)(&term.params, &body.mesh, &scratch.x, forces);
            }
        });
    }

    /// Surface force on particle `i`: its slots in ascending body, then term order.
    #[inline]
    pub(super) fn force_on(&self, i: usize) -> DVec3 {
        let mut f = DVec3::ZERO;
        for &[b, k] in &self.slots[self.offsets[i] as usize..self.offsets[i + 1] as usize] {
            for forces in &self.bodies[b as usize].forces {
                f += forces[k as usize];
            }
        }
        f
    }

    /// Energies (per registry entry, added to `energy`) and virial (added to
    /// `virial`), body by body, term by term.
    pub(super) fn energy(&self, model: &Model, energy: &mut [f64], virial: &mut [f64; 6]) {
        for scratch in &self.bodies {
            if scratch.rules.is_empty() {
                continue;
            }
            let centre = scratch.x.iter().sum::<DVec3>() / scratch.x.len() as f64;
            for (r, &rule) in scratch.rules.iter().enumerate() {
                energy[registry_index(&model.body_rules[rule])] += scratch.energy[r];
                for (x, f) in scratch.x.iter().zip(&scratch.forces[r]) {
                    add6(virial, outer(*x - centre, *f));
                }
            }
        }
    }

    /// Calls `visit(nodes, x, forces)` for every term of every body at the
    /// last evaluation: the body's nodes (internal indices), their
    /// image-consistent positions and the term's force on each.
    pub(super) fn for_each_term(&self, model: &Model, mut visit: impl FnMut(&[u32], &[DVec3], &[DVec3])) {
        for (b, scratch) in self.bodies.iter().enumerate() {
            for forces in &scratch.forces {
                visit(&model.bodies[b].nodes, &scratch.x, forces);
            }
        }
    }

    /// Appends the surface terms' stiffness at the last evaluation's
    /// positions: every stencil's PSD projection (stencils in parallel) and
    /// every local Gauss–Newton term as blocks, in body, term and stencil
    /// order, and returns the whole-body rank-one terms in the same order.
    pub(super) fn stiffness(&self, model: &Model, blocks: &mut Vec<StiffnessBlock>) -> Vec<RankOneTerm> {
        let mut rank_one = Vec::new();
        for (b, scratch) in self.bodies.iter().enumerate() {
            let body = &model.bodies[b];
            for &rule in &scratch.rules {
                let term = &model.body_rules[rule];
                let mut local = SurfaceHessian::default();
                (term.law.hessian)(&term.params, &body.mesh, &scratch.x, &mut local);
                let projected: Vec<Vec<StiffnessBlock>> = local
                    .stencils
                    .par_iter()
                    .map(|stencil| {
                        let particles: Vec<u32> = stencil.nodes.iter().map(|&k| body.nodes[k as usize]).collect();
                        let mut out = Vec::with_capacity(particles.len() * particles.len());
                        push_blocks(&particles, &project_psd(&stencil.matrix), &mut out);
                        out
                    })
                    .collect();
                blocks.extend(projected.into_iter().flatten());
                for term in &local.gauss_newton {
                    let particles: Vec<u32> = term.nodes.iter().map(|&k| body.nodes[k as usize]).collect();
                    for (&i, gi) in particles.iter().zip(&term.gradient) {
                        for (&j, gj) in particles.iter().zip(&term.gradient) {
                            let block = DMat3::from_cols(*gi * gj.x, *gi * gj.y, *gi * gj.z) * term.weight;
                            blocks.push(StiffnessBlock { i, j, block });
                        }
                    }
                }
                rank_one.extend(local.rank_one.into_iter().map(|r| RankOneTerm {
                    weight: r.weight,
                    particles: body.nodes.clone(),
                    gradient: r.gradient,
                }));
            }
        }
        rank_one
    }

    /// The surface terms on particle `i` with their forces (diagnostics):
    /// (index into `Model::body_rules`, force).
    pub(super) fn terms_on(&self, i: usize) -> Vec<(usize, DVec3)> {
        let mut parts = Vec::new();
        for &[b, k] in &self.slots[self.offsets[i] as usize..self.offsets[i + 1] as usize] {
            let scratch = &self.bodies[b as usize];
            for (r, &rule) in scratch.rules.iter().enumerate() {
                parts.push((rule, scratch.forces[r][k as usize]));
            }
        }
        parts
    }
}
