//! Surface (body) terms on the GPU (every built-in one; custom body terms
//! are refused), without float atomics and in an order
//! fixed by the data, so a run repeats bit for bit (kernels in
//! shaders/common/surface.wgsl). Each force evaluation runs, before the
//! `forces` kernel:
//!
//! 1. `surface_faces`, one invocation per face: the face's area and its
//!    share 6·v_t = x_a·(x_b × x_c) of six times the enclosed volume, with
//!    the corners placed relative to the body's anchor (the first corner of
//!    its first face) at their minimum images.
//! 2. `surface_bodies`, one workgroup per body: the body's volume and area,
//!    summed over its faces (contiguous after packing) by a fixed tree:
//!    thread t sums faces t, t + 256, … in order, then the 256 partial sums
//!    are added pairwise in shared memory. The totals stay on the device.
//! 3. Only for bodies with a curvature law ([`SurfaceGpu::NodeCurvature`]:
//!    `helfrich_bending`): `surface_edges`, one invocation per edge, its
//!    ℓ·θ; `surface_nodes`, one per body node, its M_i = ¼Σ ℓθ over its
//!    edges and A_i = ⅓Σ A_t over its faces (in mesh order), and each
//!    curvature term's energy with ∂E/∂M_i and ∂E/∂A_i; then
//!    `surface_edge_forces`, one per edge, −¼(∂E/∂M_i + ∂E/∂M_j)·∂(ℓθ) on
//!    its ends and wings, into four edge slots.
//! 4. `surface_forces`, one invocation per face: each of the body's per-face
//!    terms ([`SurfaceGpu::PerFace`], in force-field order) gives the force
//!    on the face's corners from the face's edge vectors and the body's
//!    totals, plus −⅓Σ_corners ∂E/∂A_k·∇A_t of the curvature terms; the sum
//!    goes to the face's three corner slots with a third of its energy share.
//! 5. The `forces` kernel gathers each particle's slots (corner, edge and
//!    node-energy slots: CSR by particle, ascending body, then in mesh order).
//!
//! A body wider than half the periodic box along an axis has no
//! unambiguous minimum images from its anchor: pass 1 detects it (a corner
//! whose image from the anchor disagrees with its image along the face's
//! edges) and halts the run with [`span_message`]; the CPU backend unwraps
//! such bodies along the mesh edges instead.
//!
//! `surf` (vec4 per entry) holds, in order: per face (A_t, 6v_t); per body
//! (V, A); per face corner (force, energy share); per edge (ℓθ); per edge
//! slot (force); per body node (∂E/∂M, ∂E/∂A); per body node (energy in w).

use super::pack::push_csr;
use super::prelude::surface::*;
use crate::interactions::{Law, SurfaceGpu};
use crate::system::Model;

/// The surface sections of the GPU topology.
#[derive(Default)]
pub struct SurfacePack {
    /// Face records (`FACE_WORDS`); faces of a body contiguous.
    pub faces: Vec<u32>,
    /// Body b's faces are `body_faces[b]..body_faces[b + 1]`.
    pub body_faces: Vec<u32>,
    /// Body b's terms are `body_terms[body_term_start[b]..body_term_start[b + 1]]`.
    pub body_term_start: Vec<u32>,
    /// Term indices (into the packed term list).
    pub body_terms: Vec<u32>,
    /// Particle i's `surf` entries are `node_slots[node_slot_offsets[i]..node_slot_offsets[i + 1]]`.
    pub node_slot_offsets: Vec<u32>,
    pub node_slots: Vec<u32>,
    /// Edge records (`EDGE_WORDS`) of the bodies with a curvature law.
    pub edges: Vec<u32>,
    /// The packed body of each body node.
    pub node_body: Vec<u32>,
    /// Body node k's edges (where it is an end) and faces, CSR, in mesh order.
    pub node_edge_offsets: Vec<u32>,
    pub node_edges: Vec<u32>,
    pub node_face_offsets: Vec<u32>,
    pub node_faces: Vec<u32>,
    /// The user id of each packed body (for messages).
    pub body_ids: Vec<u64>,
}

/// A particle's `surf` entry before the region sizes are known.
#[derive(Clone, Copy)]
enum Slot {
    Corner(u32),
    Edge(u32),
    NodeEnergy(u32),
}

impl SurfacePack {
    pub fn faces(&self) -> u32 {
        (self.faces.len() / FACE_WORDS) as u32
    }

    pub fn bodies(&self) -> u32 {
        self.body_ids.len() as u32
    }

    pub fn edges(&self) -> u32 {
        (self.edges.len() / EDGE_WORDS) as u32
    }

    pub fn body_nodes(&self) -> u32 {
        self.node_body.len() as u32
    }

    /// Entries of the `surf` buffer.
    pub fn surf_entries(&self) -> u64 {
        let (f, b, e, n) = (self.faces() as u64, self.bodies() as u64, self.edges() as u64, self.body_nodes() as u64);
        4 * f + b + 5 * e + 2 * n
    }

    /// The topology sections in the order of layout.wgsl's `off_faces` …
    pub fn sections(&self) -> [&Vec<u32>; 12] {
        [
            &self.faces,
            &self.body_faces,
            &self.body_term_start,
            &self.body_terms,
            &self.node_slot_offsets,
            &self.node_slots,
            &self.edges,
            &self.node_body,
            &self.node_edge_offsets,
            &self.node_edges,
            &self.node_face_offsets,
            &self.node_faces,
        ]
    }

    /// Faces, bodies, edges and body nodes (layout.wgsl's `n_faces` …).
    pub fn counts(&self) -> [u32; 4] {
        [self.faces(), self.bodies(), self.edges(), self.body_nodes()]
    }
}

/// The bodies [`pack_surfaces`] packs (those with surface terms), in its
/// order, with their terms.
fn packed_bodies(model: &Model) -> impl Iterator<Item = (&crate::system::Body, Vec<usize>)> {
    model.bodies.iter().enumerate().map(|(b, body)| (body, model.rules_of_body(b).collect::<Vec<_>>())).filter(|(_, r)| !r.is_empty())
}

/// The faces, bodies and body nodes (those of bodies with a curvature law)
/// [`pack_surfaces`] packs.
pub fn packed_counts(model: &Model) -> (usize, usize, usize) {
    packed_bodies(model).fold((0, 0, 0), |(faces, bodies, nodes), (body, rules)| {
        let curvature = if has_curvature(model, &rules) { body.nodes.len() } else { 0 };
        (faces + body.mesh.triangles().len(), bodies + 1, nodes + curvature)
    })
}

/// Whether any of `rules` (a body's terms) is a curvature law.
fn has_curvature(model: &Model, rules: &[usize]) -> bool {
    rules.iter().any(|&r| matches!(model.body_rules[r].interaction.law(), Law::Surface { gpu: SurfaceGpu::NodeCurvature, .. }))
}

/// Packs the bodies that have surface terms; the model's surface term r is
/// term `term_base + r` of the packed term list.
pub fn pack_surfaces(model: &Model, term_base: usize) -> SurfacePack {
    let mut out = SurfacePack { body_faces: vec![0], body_term_start: vec![0], ..Default::default() };
    let mut rows: Vec<Vec<Slot>> = vec![Vec::new(); model.len()];
    let (mut node_edges, mut node_faces) = (Vec::new(), Vec::new());
    for (body, rules) in packed_bodies(model) {
        let packed_body = out.body_ids.len() as u32;
        let curvature = has_curvature(model, &rules);
        let node_base = out.node_body.len() as u32;
        let body_node = |k: u32| if curvature { node_base + k } else { NO_NODE };
        let particle = |k: u32| body.nodes[k as usize];
        if curvature {
            out.node_body.extend(std::iter::repeat_n(packed_body, body.nodes.len()));
            node_edges.resize(out.node_body.len(), Vec::new());
            node_faces.resize(out.node_body.len(), Vec::new());
        }
        for face in body.mesh.triangles() {
            let f = out.faces() as u32;
            for (k, &node) in face.iter().enumerate() {
                rows[particle(node) as usize].push(Slot::Corner(3 * f + k as u32));
                if curvature {
                    node_faces[body_node(node) as usize].push(f);
                }
            }
            out.faces.extend(face.map(particle));
            out.faces.push(packed_body);
            out.faces.extend(face.map(body_node));
            out.faces.push(0);
        }
        if curvature {
            for edge in body.mesh.edges() {
                let e = out.edges() as u32;
                let stencil = [edge.ends[0], edge.ends[1], edge.wings[0], edge.wings[1]];
                for (role, &node) in stencil.iter().enumerate() {
                    rows[particle(node) as usize].push(Slot::Edge(4 * e + role as u32));
                }
                for end in edge.ends {
                    node_edges[body_node(end) as usize].push(e);
                }
                out.edges.extend(stencil.map(particle));
                out.edges.extend(edge.ends.map(body_node));
                out.edges.extend([packed_body, 0]);
            }
            for k in 0..body.nodes.len() as u32 {
                rows[particle(k) as usize].push(Slot::NodeEnergy(body_node(k)));
            }
        }
        out.body_faces.push(out.faces());
        out.body_terms.extend(rules.iter().map(|&r| (term_base + r) as u32));
        out.body_term_start.push(out.body_terms.len() as u32);
        out.body_ids.push(body.id);
    }
    push_csr(&node_edges, &mut out.node_edge_offsets, &mut out.node_edges);
    push_csr(&node_faces, &mut out.node_face_offsets, &mut out.node_faces);
    // Absolute `surf` indices (the region order of the module docs).
    let (f, b, e, n) = (out.faces(), out.bodies(), out.edges(), out.body_nodes());
    let corner_base = f + b;
    let edge_slot_base = corner_base + 3 * f + e;
    let energy_base = edge_slot_base + 4 * e + n;
    let absolute = |slot: &Slot| match *slot {
        Slot::Corner(s) => corner_base + s,
        Slot::Edge(s) => edge_slot_base + s,
        Slot::NodeEnergy(k) => energy_base + k,
    };
    let rows: Vec<Vec<u32>> = rows.iter().map(|row| row.iter().map(absolute).collect()).collect();
    push_csr(&rows, &mut out.node_slot_offsets, &mut out.node_slots);
    out
}

/// Why a run halted in pass 1: body `id` spans more than half the box.
pub fn span_message(id: u64) -> String {
    format!(
        "body {id} spans more than half of the periodic box along an axis, so the GPU's surface kernels cannot place its nodes \
         at consistent images; enlarge the box or use `device cpu` (which unwraps bodies along their mesh edges)"
    )
}
