//! Area-weighted contact terms between bodies on the CPU ([`Law::ContactArea`],
//! e.g. `contact_adhesion`), gathered per particle.
//!
//! A rule with density ε (energy per area) and switch s(d) acts on every face
//! t of a body it names: E = ε·Σ_t A_t·s_a·s_b·s_c, s_k = s(d_k) with d_k the
//! distance of corner k to the nearest face of a body the rule pairs it
//! with. With P_t = s_a·s_b·s_c,
//!
//! −∂E/∂x = −ε·Σ_t P_t·∂A_t/∂x − Σ_k ε·s′_k·B_k·∂d_k/∂x,
//! B_k = Σ_{t ∋ k} A_t·Π_{c ∈ t, c ≠ k} s_c,
//!
//! the second part acting on node k and the corners of its nearest face
//! exactly as a node–face term with b′ = ε·s′_k·B_k ([`node_face_forces`]).
//!
//! After the node–face pair pass of the contact terms (`contact::Contacts`,
//! which has every candidate pair's closest point):
//!
//! 1. **Faces** (parallel): A_t and ∂A_t/∂x of every contact face, corners
//!    image-consistent around the first.
//! 2. **Nodes** (parallel): per rule the nearest of the node's candidate
//!    pairs that the rule covers (the first in pair order on a tie), and
//!    s, s′ there. Pairs beyond the candidate list are farther than every
//!    contact range, so s = 0 for them.
//! 3. **Face weights** (parallel): Φ_t = Σ_rules ε·P_t.
//! 4. **Node weights** (parallel): B_k per rule, from the node's faces.
//! 5. **Distance part** (node order): each pull ε·s′_k·B_k is added to the
//!    forces of the node's nearest pair, gathered with the node–face terms.
//! 6. **Gather**: particle i adds −Φ_t·∂A_t/∂x_i over its faces, in face order.
//!
//! Every sum has a fixed order: bit-identical on any thread count.

use glam::DVec3;
use rayon::prelude::*;

use super::contact_mesh::{csr, face_corners, push_pair_blocks, Candidates, ContactMesh};
use super::stiffness_blocks::StiffnessBlock;
use super::virial::{add6, outer};
use crate::interactions::{node_face_forces, ContactLaw, Radial};
use crate::mesh::triangle_area_gradient;
use crate::system::{registry_index, Images, Model};

/// The area-weighted rules, the faces each particle is a corner of, and the
/// per-face and per-node results of the last evaluation.
#[derive(Default)]
pub(super) struct Adhesion {
    /// The area-weighted rules, in `Model::contact_rules` order.
    rules: Vec<AreaRule>,
    /// For (node body type a, face body type b) at `a·types + b`: the rules
    /// (positions in `rules`) acting between them.
    between: Vec<Vec<u32>>,
    body_types: usize,
    /// Compact node indices of each contact face's corners.
    face_nodes: Vec<[u32; 3]>,
    /// Particle i is corner `role` of face `face` for each (face, role) in
    /// `corner_of[offsets[i]..offsets[i + 1]]`, faces ascending.
    offsets: Vec<u32>,
    corner_of: Vec<[u32; 2]>,
    /// Per face: A_t, ∂A_t/∂(corners) and Φ_t.
    area: Vec<f64>,
    gradient: Vec<[DVec3; 3]>,
    weight: Vec<f64>,
    /// Per compact node k and rule j, at `k·rules + j`: s, s′, s″ and the
    /// nearest pair (`u32::MAX`: no candidate face), then B_k (0 where s′ = 0).
    switch: Vec<Radial>,
    nearest: Vec<u32>,
    shared: Vec<f64>,
}

/// An area-weighted contact rule: its index into `Model::contact_rules` and its law.
#[derive(Clone, Copy)]
struct AreaRule {
    index: u32,
    switch: fn(&[f64], f64) -> Radial,
    density: fn(&[f64]) -> f64,
    range: fn(&[f64]) -> f64,
}

impl AreaRule {
    /// The area-weighted rule of contact rule `index`, if it is one.
    fn of(model: &Model, index: usize) -> Option<Self> {
        match model.contact_rules[index].law {
            ContactLaw::Area { switch, density, range } => Some(AreaRule { index: index as u32, switch, density, range }),
            ContactLaw::NodeFace { .. } => None,
        }
    }

    fn params<'a>(&self, model: &'a Model) -> &'a [f64] {
        &model.contact_rules[self.index as usize].params
    }

    /// Switch s(d) (in `energy`, with s′ in `de_dr`); s = 0 beyond the range.
    fn switch(&self, model: &Model, d: f64) -> Radial {
        let p = self.params(model);
        if d < (self.range)(p) {
            (self.switch)(p, d)
        } else {
            Radial::ZERO
        }
    }

    /// Density ε (energy per area).
    fn density(&self, model: &Model) -> f64 {
        (self.density)(self.params(model))
    }
}

impl Adhesion {
    pub(super) fn new(model: &Model, mesh: &ContactMesh) -> Self {
        let rules: Vec<AreaRule> = (0..model.contact_rules.len()).filter_map(|r| AreaRule::of(model, r)).collect();
        if rules.is_empty() {
            return Self::default();
        }
        let types = model.body_type_names.len();
        let between = (0..types * types)
            .map(|ab| {
                let covered: Vec<usize> = model.contact_rules_between((ab / types) as u32, (ab % types) as u32).collect();
                (0..rules.len() as u32).filter(|&j| covered.contains(&(rules[j as usize].index as usize))).collect()
            })
            .collect();
        let face_nodes: Vec<[u32; 3]> = mesh.faces.iter().map(|(corners, _)| corners.map(|p| mesh.compact(p) as u32)).collect();
        let mut rows = vec![Vec::new(); model.len()];
        for (f, (corners, _)) in mesh.faces.iter().enumerate() {
            for (role, &p) in corners.iter().enumerate() {
                rows[p as usize].push([f as u32, role as u32]);
            }
        }
        let (offsets, corner_of) = csr(rows);
        let (faces, slots) = (mesh.faces.len(), mesh.nodes.len() * rules.len());
        Self {
            between,
            body_types: types,
            face_nodes,
            offsets,
            corner_of,
            area: vec![0.0; faces],
            gradient: vec![[DVec3::ZERO; 3]; faces],
            weight: vec![0.0; faces],
            switch: vec![Radial::ZERO; slots],
            nearest: vec![u32::MAX; slots],
            shared: vec![0.0; slots],
            rules,
        }
    }

    /// Evaluates the area-weighted rules at the candidates' closest points
    /// (filled by the pair pass) and adds their distance forces to the pairs.
    pub(super) fn prepare(&mut self, model: &Model, mesh: &ContactMesh, candidates: &mut Candidates, x: &[DVec3], images: &Images) {
        if self.rules.is_empty() {
            return;
        }
        let count = self.rules.len();
        let densities: Vec<f64> = self.rules.iter().map(|r| r.density(model)).collect();
        let Self { rules, between, body_types, face_nodes, offsets, corner_of, area, gradient, weight, switch, nearest, shared } = self;
        area.par_iter_mut().zip(gradient.par_iter_mut()).zip(&mesh.faces).with_min_len(256).for_each(|((a, g), (corners, _))| {
            (*a, *g) = triangle_area_gradient(face_corners(x, images, *corners));
        });
        let found = &*candidates;
        switch.par_chunks_mut(count).zip(nearest.par_chunks_mut(count)).enumerate().with_min_len(64).for_each(|(k, (switch, nearest))| {
            // `switch[j].energy` holds the nearest distance until it is replaced by s there.
            switch.fill(Radial { energy: f64::INFINITY, ..Radial::ZERO });
            nearest.fill(u32::MAX);
            let node_type = model.bodies[mesh.node_body[k] as usize].body_type as usize;
            for pair in found.offsets[k]..found.offsets[k + 1] {
                let face_body = mesh.faces[found.pairs[pair as usize][1] as usize].1;
                let face_type = model.bodies[face_body as usize].body_type as usize;
                let d = found.points[pair as usize].distance;
                for &j in &between[node_type * *body_types + face_type] {
                    if d < switch[j as usize].energy {
                        (switch[j as usize].energy, nearest[j as usize]) = (d, pair);
                    }
                }
            }
            for ((s, &pair), &rule) in switch.iter_mut().zip(nearest.iter()).zip(rules.iter()) {
                *s = if pair == u32::MAX { Radial::ZERO } else { rule.switch(model, s.energy) };
            }
        });
        let switch = &*switch;
        let s = |k: u32, j: usize| switch[k as usize * count + j].energy;
        weight.par_iter_mut().zip(face_nodes.par_iter()).with_min_len(256).for_each(|(w, &[a, b, c])| {
            *w = densities.iter().enumerate().map(|(j, eps)| eps * s(a, j) * s(b, j) * s(c, j)).sum();
        });
        let area = &*area;
        shared.par_chunks_mut(count).enumerate().with_min_len(64).for_each(|(k, shared)| {
            let p = mesh.nodes[k] as usize;
            for (j, shared) in shared.iter_mut().enumerate() {
                *shared = if switch[k * count + j].de_dr == 0.0 {
                    0.0
                } else {
                    let others = |&[f, role]: &[u32; 2]| {
                        let corners = face_nodes[f as usize];
                        area[f as usize] * s(corners[(role as usize + 1) % 3], j) * s(corners[(role as usize + 2) % 3], j)
                    };
                    corner_of[offsets[p] as usize..offsets[p + 1] as usize].iter().map(others).sum::<f64>()
                };
            }
        });
        for (slot, (&pair, &b)) in nearest.iter().zip(shared.iter()).enumerate().filter(|(_, (_, b))| **b != 0.0) {
            let de_dd = densities[slot % count] * switch[slot].de_dr * b;
            let f = node_face_forces(&Radial { energy: 0.0, de_dr: de_dd, d2e_dr2: 0.0 }, &candidates.points[pair as usize]);
            candidates.forces[pair as usize].iter_mut().zip(f).for_each(|(a, b)| *a += b);
        }
    }

    /// Appends each node's Gauss–Newton blocks per rule, max(ε·s″_k·B_k, 0)·g gᵀ
    /// at its nearest pair ([`push_pair_blocks`]), in node and rule order, at
    /// the last evaluation (the area part is left out: `src/backend/stiffness.rs`).
    pub(super) fn stiffness(&self, model: &Model, mesh: &ContactMesh, candidates: &Candidates, blocks: &mut Vec<StiffnessBlock>) {
        let densities: Vec<f64> = self.rules.iter().map(|r| r.density(model)).collect();
        for (slot, (&pair, &b)) in self.nearest.iter().zip(&self.shared).enumerate().filter(|(_, (_, b))| **b != 0.0) {
            let curvature = densities[slot % self.rules.len()] * self.switch[slot].d2e_dr2 * b;
            push_pair_blocks(mesh, candidates, pair as usize, curvature, blocks);
        }
    }

    /// Area force on particle `i`: −Φ_t·∂A_t/∂x_i over its faces in face order.
    #[inline]
    pub(super) fn force_on(&self, i: usize) -> DVec3 {
        if self.rules.is_empty() {
            return DVec3::ZERO;
        }
        self.corner_of[self.offsets[i] as usize..self.offsets[i + 1] as usize]
            .iter()
            .map(|&[f, role]| -self.weight[f as usize] * self.gradient[f as usize][role as usize])
            .fold(DVec3::ZERO, |a, b| a + b)
    }

    /// Energy of each rule (ε·Σ_t A_t·P_t, face order) and the virial of the
    /// area forces (Σ_corners (x − x_first) ⊗ f per face, face order); the
    /// distance forces are in the pairs' virial.
    pub(super) fn energy(
        &self,
        model: &Model,
        mesh: &ContactMesh,
        x: &[DVec3],
        images: &Images,
        energy: &mut [f64],
        virial: &mut [f64; 6],
    ) {
        let count = self.rules.len();
        if count == 0 {
            return;
        }
        let s = |k: u32, j: usize| self.switch[k as usize * count + j].energy;
        for (j, &rule) in self.rules.iter().enumerate() {
            let eps = rule.density(model);
            let sum: f64 = self.face_nodes.iter().zip(&self.area).map(|(&[a, b, c], area)| eps * area * s(a, j) * s(b, j) * s(c, j)).sum();
            energy[registry_index(&model.contact_rules[rule.index as usize])] += sum;
        }
        for (f, (corners, _)) in mesh.faces.iter().enumerate().filter(|(f, _)| self.weight[*f] != 0.0) {
            let at = face_corners(x, images, *corners);
            for role in 1..3 {
                add6(virial, outer(at[role] - at[0], -self.weight[f] * self.gradient[f][role]));
            }
        }
    }
}
