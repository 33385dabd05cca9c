//! Node–face contact between bodies on the CPU (`contact` lines), gathered
//! per particle.
//!
//! A contact term b(d) acts between a node p of one body and a face
//! (x_0, x_1, x_2) of another, d = |p − q| the distance to the face's closest
//! point q = Σ w_k x_k ([`point_triangle`]); the forces are −b′·n̂ on the node
//! and b′·w_k·n̂ on corner k ([`node_face_forces`]).
//!
//! 1. **Candidates** (Verlet style): every (node, face) pair of different
//!    bodies, with a contact rule between their types, closer than
//!    r_s = 2·d̂ (d̂ the largest contact range: a skin of d̂). They are found
//!    through the cell list of [`NeighborList`] over the contact nodes with
//!    cutoff r_s + ℓ_max (ℓ_max the longest face edge): every point of a face
//!    lies within ℓ_max of each of its corners, so a node within r_s of a
//!    face is within r_s + ℓ_max of the face's first corner. Pairs are sorted
//!    by (node, face). The list is rebuilt as soon as a contact node has
//!    moved more than d̂/2 since the last build (checked before every force
//!    pass), so a pair outside it is always farther apart than d̂.
//! 2. **Pass** (parallel over pairs): each pair writes its four forces and
//!    its distance into its own slot; positions are made image-consistent
//!    around the face's first corner.
//! 3. **Gather**: each particle sums its slots in ascending pair order, as
//!    surface terms are gathered: bit-identical on any thread count.
//!
//! Area-weighted terms ([`Law::ContactArea`]: adhesion) reuse the candidate
//! list: after the pair pass each node finds its nearest candidate face per
//! rule (see `src/backend/adhesion.rs`); their distance forces join the
//! pairs' slots, their area forces the particles' face slots.
//!
//! [`Contacts::fill_step_limits`] gives the explicit integrator each
//! particle's largest safe displacement: 0.4 × the distance of its closest
//! candidate pair and at most 0.4·d̂ (pairs outside the list are beyond d̂).
//! With every node and corner moving at most 0.4·d along a straight step,
//! a pair closes by at most 0.8·d (additive CCD bound: the distance is
//! 1-Lipschitz in each point), so no node passes through a face.

use glam::DVec3;
use rayon::prelude::*;

use super::adhesion::Adhesion;
use super::contact_mesh::{csr, face_corners, push_pair_blocks, Candidates, ContactMesh, Face};
use super::stiffness_blocks::StiffnessBlock;
use super::virial::{add6, outer};
use crate::interactions::{node_face_forces, ContactLaw, Radial};
use crate::mesh::{point_triangle, PointTriangle};
use crate::neighbor::{Exclusions, NeighborList};
use crate::system::{registry_index, Images, Model, SimBox};

/// Fraction of the distance to its closest contact a particle may move in one step.
pub const STEP_FRACTION: f64 = 0.4;

/// Candidate pairs, their per-pair results and each particle's slots.
#[derive(Default)]
pub(super) struct Contacts {
    mesh: ContactMesh,
    /// Faces by their first corner (compact node index), CSR.
    first_offsets: Vec<u32>,
    first_faces: Vec<u32>,
    /// Node–face rules ([`Law::Contact`]) between a node of body type a and a
    /// face of body type b, at `a·types + b`; `any` also counts area-weighted ones.
    barriers: Vec<Vec<Barrier>>,
    any: Vec<bool>,
    body_types: usize,
    /// The largest contact range d̂ (also the skin).
    dhat: f64,
    /// Contact-node positions at the last build (`None`: never built).
    reference: Option<Vec<DVec3>>,
    builds: u64,
    candidates: Candidates,
    /// Particle i's slots are `slots[offsets[i]..offsets[i + 1]]`: (pair, role 0–3).
    offsets: Vec<u32>,
    slots: Vec<[u32; 2]>,
    adhesion: Adhesion,
}

/// A node–face contact rule: its index into `Model::contact_rules` and its law.
#[derive(Clone, Copy)]
struct Barrier {
    index: u32,
    eval: fn(&[f64], f64) -> Radial,
    range: fn(&[f64]) -> f64,
}

impl Barrier {
    /// The node–face rule of contact rule `index`, if it is one.
    fn of(model: &Model, index: usize) -> Option<Self> {
        match model.contact_rules[index].law {
            ContactLaw::NodeFace { eval, range } => Some(Barrier { index: index as u32, eval, range }),
            ContactLaw::Area { .. } => None,
        }
    }

    /// b(d) (zero beyond the range).
    #[inline]
    fn radial(&self, model: &Model, d: f64) -> Radial {
        let params = &model.contact_rules[self.index as usize].params;
        if d < (self.range)(params) {
            (self.eval)(params, d)
        } else {
            Radial::ZERO
        }
    }
}

impl Contacts {
    pub(super) fn new(model: &Model) -> Self {
        if !model.has_contact_terms() {
            return Self::default();
        }
        let types = model.body_type_names.len();
        let barriers: Vec<Vec<Barrier>> = (0..types * types)
            .map(|ab| model.contact_rules_between((ab / types) as u32, (ab % types) as u32).filter_map(|r| Barrier::of(model, r)).collect())
            .collect();
        let any: Vec<bool> =
            (0..types * types).map(|ab| model.contact_rules_between((ab / types) as u32, (ab % types) as u32).next().is_some()).collect();
        let named = |b: usize| {
            let t = model.bodies[b].body_type as usize;
            (0..types).any(|u| any[t * types + u] || any[u * types + t])
        };
        let (mut nodes, mut node_body, mut faces): (Vec<u32>, Vec<u32>, Vec<Face>) = (Vec::new(), Vec::new(), Vec::new());
        for (b, body) in model.bodies.iter().enumerate().filter(|(b, _)| named(*b)) {
            nodes.extend(&body.nodes);
            node_body.extend(std::iter::repeat_n(b as u32, body.nodes.len()));
            faces.extend(body.mesh.triangles().iter().map(|t| (t.map(|k| body.nodes[k as usize]), b as u32)));
        }
        // Bodies are disjoint but not in particle order: sort nodes by particle.
        let mut order: Vec<usize> = (0..nodes.len()).collect();
        order.sort_unstable_by_key(|&k| nodes[k]);
        let (nodes, node_body): (Vec<u32>, Vec<u32>) = order.iter().map(|&k| (nodes[k], node_body[k])).unzip();
        let mesh = ContactMesh { nodes, node_body, faces };
        let mut rows = vec![Vec::new(); mesh.nodes.len()];
        for (f, (corners, _)) in mesh.faces.iter().enumerate() {
            rows[mesh.compact(corners[0])].push(f as u32);
        }
        let (first_offsets, first_faces) = csr(rows);
        let dhat = model.contact_rules.iter().map(|t| t.law.range(&t.params)).fold(0.0, f64::max);
        Self {
            adhesion: Adhesion::new(model, &mesh),
            mesh,
            first_offsets,
            first_faces,
            barriers,
            any,
            body_types: types,
            dhat,
            offsets: vec![0; model.len() + 1],
            ..Self::default()
        }
    }

    /// Whether there is anything to evaluate.
    pub(super) fn is_empty(&self) -> bool {
        self.mesh.nodes.is_empty()
    }

    /// Candidate-list builds so far.
    pub(super) fn builds(&self) -> u64 {
        self.builds
    }

    /// Index of the body-type pair (node's body, face's body) in the rule tables.
    fn type_pair(&self, node_body: u32, face_body: u32, model: &Model) -> usize {
        let t = |b: u32| model.bodies[b as usize].body_type as usize;
        t(node_body) * self.body_types + t(face_body)
    }

    /// The node–face rules of pair `k`.
    fn barriers_of(&self, k: usize, model: &Model) -> &[Barrier] {
        let [node, face] = self.candidates.pairs[k];
        &self.barriers[self.type_pair(self.mesh.node_body[node as usize], self.mesh.faces[face as usize].1, model)]
    }

    /// Rebuilds the candidate list if never built or a contact node moved more than d̂/2.
    pub(super) fn update(&mut self, model: &Model, x: &[DVec3], sim_box: &SimBox) -> Result<(), String> {
        if self.is_empty() {
            return Ok(());
        }
        let images = sim_box.images();
        let half = 0.5 * self.dhat;
        let stale = self.reference.as_ref().is_none_or(|reference| {
            self.mesh.nodes.par_iter().zip(reference.par_iter()).any(|(&p, x0)| {
                let d = images.minimum_image(x[p as usize] - *x0).length();
                d.is_nan() || d > half
            })
        });
        if stale {
            self.rebuild(model, x, sim_box)?;
        }
        Ok(())
    }

    fn rebuild(&mut self, model: &Model, x: &[DVec3], sim_box: &SimBox) -> Result<(), String> {
        let images = sim_box.images();
        let compact_x: Vec<DVec3> = self.mesh.nodes.iter().map(|&p| x[p as usize]).collect();
        let longest = self
            .mesh
            .faces
            .par_iter()
            .map(|(c, _)| {
                let [a, b, c] = c.map(|p| x[p as usize]);
                images.minimum_image(b - a).length().max(images.minimum_image(c - a).length()).max(images.minimum_image(c - b).length())
            })
            .reduce(|| 0.0, f64::max);
        let search = 2.0 * self.dhat;
        let mut list = NeighborList::new(search + longest, 0.0);
        list.build(&compact_x, sim_box, &Exclusions::none()).map_err(|e| format!("contact search: {e}"))?;
        let this = &*self;
        let rows: Vec<Vec<u32>> = (0..this.mesh.nodes.len())
            .into_par_iter()
            .map(|k| {
                let body = this.mesh.node_body[k];
                let mut mine = Vec::new();
                for &j in list.neighbors(k) {
                    let j = j as usize;
                    for &f in &this.first_faces[this.first_offsets[j] as usize..this.first_offsets[j + 1] as usize] {
                        let (corners, face_body) = this.mesh.faces[f as usize];
                        if face_body != body
                            && this.any[this.type_pair(body, face_body, model)]
                            && closest(x, &images, this.mesh.nodes[k], corners).distance < search
                        {
                            mine.push(f);
                        }
                    }
                }
                mine.sort_unstable();
                mine
            })
            .collect();
        let (offsets, faces) = csr(rows);
        let candidates = &mut self.candidates;
        candidates.pairs = (0..offsets.len() - 1)
            .flat_map(|k| faces[offsets[k] as usize..offsets[k + 1] as usize].iter().map(move |&f| [k as u32, f]))
            .collect();
        candidates.offsets = offsets;
        let mut slots = vec![Vec::new(); model.len()];
        for (k, &[node, face]) in candidates.pairs.iter().enumerate() {
            let (corners, _) = self.mesh.faces[face as usize];
            for (role, p) in [self.mesh.nodes[node as usize], corners[0], corners[1], corners[2]].into_iter().enumerate() {
                slots[p as usize].push([k as u32, role as u32]);
            }
        }
        (self.offsets, self.slots) = csr(slots);
        let pairs = candidates.pairs.len();
        candidates.points.resize(pairs, PointTriangle { distance: f64::INFINITY, weights: [0.0; 3], normal: DVec3::ZERO });
        candidates.forces.resize(pairs, [DVec3::ZERO; 4]);
        self.reference = Some(compact_x);
        self.builds += 1;
        Ok(())
    }

    /// Evaluates every candidate pair into its slot, then the area-weighted
    /// terms (the list must be current: [`Self::update`]).
    pub(super) fn prepare(&mut self, model: &Model, x: &[DVec3], images: &Images) {
        let this = &*self;
        let results: Vec<(PointTriangle, [DVec3; 4])> = (0..this.candidates.pairs.len())
            .into_par_iter()
            .with_min_len(256)
            .map(|k| {
                let [node, face] = this.candidates.pairs[k];
                let pt = closest(x, images, this.mesh.nodes[node as usize], this.mesh.faces[face as usize].0);
                let mut forces = [DVec3::ZERO; 4];
                for r in this.barriers_of(k, model) {
                    let f = node_face_forces(&r.radial(model, pt.distance), &pt);
                    forces.iter_mut().zip(f).for_each(|(a, b)| *a += b);
                }
                (pt, forces)
            })
            .collect();
        for (k, (pt, f)) in results.into_iter().enumerate() {
            self.candidates.points[k] = pt;
            self.candidates.forces[k] = f;
        }
        self.adhesion.prepare(model, &self.mesh, &mut self.candidates, x, images);
    }

    /// Contact force on particle `i`: its pair slots in ascending pair order,
    /// then its area-weighted face slots.
    #[inline]
    pub(super) fn force_on(&self, i: usize) -> DVec3 {
        let pairs = self.slots[self.offsets[i] as usize..self.offsets[i + 1] as usize]
            .iter()
            .map(|&[k, role]| self.candidates.forces[k as usize][role as usize])
            .fold(DVec3::ZERO, |a, b| a + b);
        pairs + self.adhesion.force_on(i)
    }

    /// The smallest node–face distance over the candidate pairs (∞ when there are none).
    pub(super) fn min_distance(&self) -> f64 {
        self.candidates.points.iter().map(|pt| pt.distance).fold(f64::INFINITY, f64::min)
    }

    /// Each particle's largest safe displacement in the next step (∞ for
    /// particles of no contact body); see the module docs.
    pub(super) fn fill_step_limits(&self, n: usize, limits: &mut Vec<f64>) {
        limits.clear();
        limits.resize(n, f64::INFINITY);
        let cap = STEP_FRACTION * self.dhat;
        self.mesh.nodes.iter().for_each(|&p| limits[p as usize] = cap);
        limits.par_iter_mut().enumerate().with_min_len(1024).for_each(|(i, limit)| {
            for &[k, _] in &self.slots[self.offsets[i] as usize..self.offsets[i + 1] as usize] {
                *limit = limit.min(STEP_FRACTION * self.candidates.points[k as usize].distance);
            }
        });
    }

    /// Appends each candidate pair's Gauss–Newton stiffness blocks
    /// max(b″, 0)·g_a g_bᵀ ([`push_pair_blocks`]) in pair order, then the
    /// area-weighted terms' (adhesion: per node and rule at its nearest pair),
    /// at the positions of the last [`Self::prepare`] (see
    /// `src/backend/stiffness.rs`).
    pub(super) fn stiffness(&self, model: &Model, blocks: &mut Vec<StiffnessBlock>) {
        for (k, pt) in self.candidates.points.iter().enumerate() {
            let curvature: f64 = self.barriers_of(k, model).iter().map(|r| r.radial(model, pt.distance).d2e_dr2).sum();
            push_pair_blocks(&self.mesh, &self.candidates, k, curvature, blocks);
        }
        self.adhesion.stiffness(model, &self.mesh, &self.candidates, blocks);
    }

    /// Energies per registry entry and the virial, pair by pair (d·n̂ ⊗ f_node)
    /// then the area-weighted terms, at the positions of the last [`Self::prepare`].
    pub(super) fn energy(&self, model: &Model, x: &[DVec3], images: &Images, energy: &mut [f64], virial: &mut [f64; 6]) {
        for (k, pt) in self.candidates.points.iter().enumerate() {
            for r in self.barriers_of(k, model) {
                energy[registry_index(&model.contact_rules[r.index as usize])] += r.radial(model, pt.distance).energy;
            }
            add6(virial, outer(pt.distance * pt.normal, self.candidates.forces[k][0]));
        }
        self.adhesion.energy(model, &self.mesh, x, images, energy, virial);
    }
}

/// Closest point of face `corners` to particle `p`, image-consistent around corner 0.
#[inline]
fn closest(x: &[DVec3], images: &Images, p: u32, corners: [u32; 3]) -> PointTriangle {
    let face = face_corners(x, images, corners);
    point_triangle(face[0] + images.minimum_image(x[p as usize] - face[0]), face)
}
