//! Node–face contact between bodies on the GPU (`contact` lines with a
//! node–face law: `contact_barrier`), with the explicit step clamp as a
//! device reduction; the area-weighted terms (`contact_adhesion`) join its
//! pass ([`super::adhesion`]). Kernels in shaders/common/contact.wgsl; the CPU oracle
//! is src/backend/contact.rs, whose equations these follow:
//!
//! - a node p of one body and a face (x_0, x_1, x_2) of another, at the
//!   distance d = |p − q| to the face's closest point q = Σ w_k x_k (the
//!   exact point–triangle distance by Voronoi region, as `mesh::point_triangle`);
//! - forces −b′(d)·n̂ on the node and b′(d)·w_k·n̂ on corner k, n̂ = (p − q)/d;
//! - each contact node's largest safe displacement L_i = 0.4·min(d̂, d over
//!   its pairs), d̂ the largest contact range, and the step shortened to s·dt
//!   with the largest s ≤ 1 such that s·|a_i| + √s·|b_i| ≤ L_i for every
//!   particle (drift a_i, noise b_i: src/integrate/overdamped.rs).
//!
//! # Candidates: the neighbour list
//!
//! With contact terms the GPU's neighbour list reaches at least
//! d̂ + ℓ (ℓ = [`EDGE_ALLOWANCE`] × the longest face edge at the start of the
//! run) beyond the pair cutoff, plus the skin (at least d̂, as the CPU's
//! contact list: [`ContactPack::skin`]), and keeps the excluded
//! (bonded) pairs between nodes of different contact bodies, marked so that
//! the pair loop skips them (a junction bond must not hide a contact). A
//! node closer than d̂ to a face is closer than d̂ + ℓ to each of its corners,
//! so, by the Verlet argument of the list (no particle has moved more than
//! half the skin since the build), every pair in range is found from the
//! node's row (faces whose first corner is a neighbour) and from each
//! corner's row (the corner's faces, nodes that are neighbours). A face edge
//! longer than ℓ would break that bound: the kernel checks every face each
//! force pass and halts the run with [`reach_message`] instead.
//! The list holds each row's nodes of other contact bodies first
//! (shaders/common/neighbor.wgsl), so both walks stop at the first entry
//! that is not one; a corner's faces (up to eight at a time) share one walk,
//! each culled by its bounding sphere. Measured on an H100 at 324 000
//! particles: 1.91 → 1.24 ms a step (BENCHMARKS.md).
//!
//! # Pass order and determinism
//!
//! After `forces` (per neighbour-list chunk), `contact_forces` runs once per
//! contact node i: as a node, over its row's other-body nodes in order and each neighbour's
//! faces (CSR by first corner, in face order; with area-weighted rules this
//! node part runs in the pass before, `adhesion_nodes`, which also finds the
//! nearest faces); then as a corner, over its
//! faces (CSR, in face order, in batches of eight) and its row's other-body nodes in order. It adds the sum to
//! `force[i]` (and the node's pair energies to `force[i].w`), so each
//! particle gathers its own contributions in an order fixed by the data (no
//! float atomics). A pair's geometry is computed relative to the face's
//! first corner from exact fixed-point separations, so the node and the three
//! corners see the same bits of d, w and n̂. The same invocation computes
//! the particle's step fraction s_i from its final force and the same noise
//! draw as `integrate`, and takes the minimum over particles with an integer
//! `atomicMin` on the bits of s_i (positive f32 order like their bits: the
//! result does not depend on the order). `integrate` moves every particle by
//! s·a + √s·b; `advance` stores each step's s in a ring of
//! [`FRACTION_SLOTS`] entries of `surf`, which the host reads at every sync
//! to advance the clock by s·dt and count clamped steps (`nclamp`). With
//! `integrator implicit` the solve replaces s by the implicit step's clamp
//! and the pairs join its products (src/gpu/implicit.rs).
//!
//! # Cost
//!
//! Per step one invocation per contact node scans its row (≈ 20 entries at
//! d̂ + ℓ + skin ≈ 1.1 µm on the benchmark's cells) once as a node, and once
//! per face it is a corner of (≈ 6) as a corner; neighbours of its own body
//! are skipped first, and, as a corner, nodes outside the face's bounding
//! sphere widened by d̂ before the point–triangle distance. No host work per
//! step beyond the ring of fractions read at each sync. `cellmd profile-gpu`
//! on llvmpipe (2 loaded cores, rough): `inputs/cell_contact.in` (1284
//! nodes, contact only at the patch) 10.9 ms of a 20.4 ms step (forces
//! 8.2 ms); `inputs/aggregate.in` (8100 nodes, every cell 0.2 µm from its
//! neighbours) 164 ms of 242 ms (forces 66 ms), 5× less than without the
//! bounding-sphere test. The list's skin is at least d̂: 0.005 rebuilds per
//! step on cell_contact.in instead of 0.995 with the deck's skin 0.

use super::prelude::contact::*;
pub use super::prelude::contact::{CONTACT_ONLY, FRACTION_SLOTS};
use super::step::{Dispatcher, Over, Phase, StepFeature};
use crate::interactions::ContactLaw;
use crate::system::{registry_index, Model};

/// The reach of the contact search beyond d̂, as a multiple of the longest
/// face edge at the start of the run (faces may stretch by this much).
pub const EDGE_ALLOWANCE: f64 = 1.5;

/// The contact sections of the GPU topology.
#[derive(Default)]
pub struct ContactPack {
    /// In the order of layout.wgsl's `off_cfaces` …: faces (corners, packed
    /// body), faces by first corner (CSR by particle), faces by corner (CSR
    /// by particle, 4·face + role), each particle's packed contact body
    /// (`NO_BODY`: none), each packed body's type, the node–face rules per
    /// (node type, face type) (CSR), whether any rule acts per type pair,
    /// the rules ([`CONTACT_RULE_WORDS`] each).
    sections: [Vec<u32>; 11],
    body_types: u32,
    dhat: f64,
    longest_edge: f64,
}

impl ContactPack {
    /// Packs the bodies some contact rule names (empty without contact rules).
    pub fn new(model: &Model, x: &[glam::DVec3], sim_box: &crate::system::SimBox) -> Self {
        let node_face = |r: usize| matches!(model.contact_rules[r].law, ContactLaw::NodeFace { .. });
        if model.contact_rules.is_empty() {
            return Self::default();
        }
        let types = model.body_type_names.len();
        let pairs = |ab: usize| model.contact_rules_between((ab / types) as u32, (ab % types) as u32);
        let any: Vec<u32> = (0..types * types).map(|ab| pairs(ab).next().is_some() as u32).collect();
        let named = |t: usize| (0..types).any(|u| any[t * types + u] != 0 || any[u * types + t] != 0);
        let n = model.len();
        let images = sim_box.images();
        let (mut faces, mut body_type, mut body) = (Vec::new(), Vec::new(), vec![NO_BODY; n]);
        let (mut first, mut corner) = (vec![Vec::new(); n], vec![Vec::new(); n]);
        let mut longest = 0.0f64;
        for b in model.bodies.iter().filter(|b| named(b.body_type as usize)) {
            let packed = body_type.len() as u32;
            body_type.push(b.body_type);
            b.nodes.iter().for_each(|&p| body[p as usize] = packed);
            for t in b.mesh.triangles() {
                let f = (faces.len() / 4) as u32;
                let c = t.map(|k| b.nodes[k as usize]);
                first[c[0] as usize].push(f);
                for (role, &p) in c.iter().enumerate() {
                    corner[p as usize].push(4 * f + role as u32);
                    let q = c[(role + 1) % 3];
                    longest = longest.max(images.minimum_image(x[q as usize] - x[p as usize]).length());
                }
                faces.extend(c);
                faces.push(packed);
            }
        }
        let rules: Vec<Vec<u32>> = (0..types * types).map(|ab| pairs(ab).filter(|&r| node_face(r)).map(|r| r as u32).collect()).collect();
        let mut table = Vec::new();
        for term in &model.contact_rules {
            let start = table.len();
            table.push(registry_index(term) as u32);
            table.extend(term.params.iter().map(|&p| (p as f32).to_bits()));
            table.resize(start + CONTACT_RULE_WORDS, 0);
        }
        let mut sections: [Vec<u32>; 11] = Default::default();
        let mut csr = |rows: &[Vec<u32>], at: usize| {
            let (mut offsets, mut flat) = (Vec::new(), Vec::new());
            super::pack::push_csr(rows, &mut offsets, &mut flat);
            (sections[at], sections[at + 1]) = (offsets, flat);
        };
        csr(&first, 1);
        csr(&corner, 3);
        csr(&rules, 7);
        (sections[0], sections[5], sections[6], sections[9], sections[10]) = (faces, body, body_type, any, table);
        let dhat = model.contact_rules.iter().map(|t| t.law.range(&t.params)).fold(0.0, f64::max);
        Self { sections, body_types: types as u32, dhat, longest_edge: longest }
    }

    /// Faces of contact bodies (0: no node–face contact on the GPU).
    pub fn faces(&self) -> u32 {
        (self.sections[0].len() / 4) as u32
    }

    /// How far beyond the pair cutoff the neighbour list must reach
    /// (without the skin): d̂ + ℓ (0 without contact).
    pub fn reach(&self) -> f64 {
        if self.faces() == 0 {
            0.0
        } else {
            self.dhat + EDGE_ALLOWANCE * self.longest_edge
        }
    }

    /// The least skin of the neighbour list with contact: d̂, the CPU
    /// contact list's (0 without contact). The deck's skin (often 0 for
    /// decks without pair terms) would rebuild the list almost every step.
    pub fn skin(&self) -> f64 {
        if self.faces() == 0 {
            0.0
        } else {
            self.dhat
        }
    }

    /// The longest face edge the search covers, ℓ.
    pub fn edge_bound(&self) -> f64 {
        EDGE_ALLOWANCE * self.longest_edge
    }

    /// Entries of `surf` the contact kernels use for `n` particles (after
    /// the surface terms'): the ring of step fractions, then each particle's
    /// closest contact distance (at [`Self::closest_entry`]).
    pub fn surf_entries(&self, n: u32) -> u64 {
        if self.faces() == 0 {
            0
        } else {
            FRACTION_SLOTS as u64 + n as u64
        }
    }

    /// The first `surf` entry of the particles' closest contact distances,
    /// for the contact entries from `surf_base` on: written by the contact
    /// pass, read by FIRE's step clamp (src/gpu/fire.rs) and, for its node
    /// part, by the area-weighted terms' passes.
    pub fn closest_entry(&self, surf_base: u64) -> u32 {
        (surf_base + FRACTION_SLOTS as u64) as u32
    }

    /// Appends the sections to `topo` and returns layout.wgsl's contact
    /// fields: the sections' offsets, faces, body types, d̂ and ℓ² (f32
    /// bits), and the first `surf` entry of the fraction ring.
    pub fn append(&self, topo: &mut Vec<u32>, surf_base: u64) -> [u32; 16] {
        let mut fields = [0u32; 16];
        for (k, section) in self.sections.iter().enumerate() {
            fields[k] = topo.len() as u32;
            topo.extend(section);
        }
        let edge = self.edge_bound();
        fields[11..].copy_from_slice(&[
            self.faces(),
            self.body_types,
            (self.dhat as f32).to_bits(),
            ((edge * edge) as f32).to_bits(),
            surf_base as u32,
        ]);
        fields
    }
}

/// Why a run halted in the contact pass: a face edge outgrew the search's reach.
pub fn reach_message(edge: f64) -> String {
    format!(
        "a face of a contact body has an edge longer than {edge:e}, the longest the GPU's contact search covers \
         ({EDGE_ALLOWANCE} × the longest edge at the start of the run); run again from the last output (the reach is set \
         anew at the start of each run) or use `device cpu`"
    )
}

/// Node–face contact as a step feature: the area-weighted contact's node
/// and weight passes ([`super::adhesion`]) and then the contact pass, after
/// the force pass; nothing without contact faces.
pub(super) struct ContactPasses {
    adhesion_nodes: wgpu::ComputePipeline,
    adhesion_weights: wgpu::ComputePipeline,
    contact_forces: wgpu::ComputePipeline,
    /// Whether the model has contact faces, and area-weighted contact rules.
    active: bool,
    adhesion: bool,
}

impl ContactPasses {
    pub(super) fn new(faces: u32, adhesion_rules: u32, pipeline: impl Fn(&str) -> wgpu::ComputePipeline) -> Self {
        Self {
            adhesion_nodes: pipeline("adhesion_nodes"),
            adhesion_weights: pipeline("adhesion_weights"),
            contact_forces: pipeline("contact_forces"),
            active: faces > 0,
            adhesion: adhesion_rules > 0,
        }
    }

    /// The contact pass, as `profile` times it (none without contact).
    pub(super) fn contact_passes(&self) -> Vec<(&wgpu::ComputePipeline, Over)> {
        self.active.then_some((&self.contact_forces, Over::Chunks)).into_iter().collect()
    }

    /// The area-weighted contact's passes, as `profile` times them (none without them).
    pub(super) fn adhesion_passes(&self) -> Vec<(&wgpu::ComputePipeline, Over)> {
        match self.active && self.adhesion {
            true => vec![(&self.adhesion_nodes, Over::Chunks), (&self.adhesion_weights, Over::Particles)],
            false => Vec::new(),
        }
    }
}

impl StepFeature for ContactPasses {
    fn encode(&self, phase: Phase, at: &Dispatcher, pass: &mut wgpu::ComputePass) {
        if phase == Phase::Forces {
            at.dispatch_all(pass, &self.adhesion_passes());
            at.dispatch_all(pass, &self.contact_passes());
        }
    }
}
