//! The contact bodies' nodes and faces and the node–face candidate pairs, as
//! data shared by the node–face terms (`contact.rs`) and the area-weighted
//! ones (`adhesion.rs`), with the helpers both use.

use glam::{DMat3, DVec3};

use super::stiffness_blocks::StiffnessBlock;
use crate::mesh::PointTriangle;
use crate::system::Images;

/// A face of a contact body: its corners (particle indices) and its body.
pub(super) type Face = ([u32; 3], u32);

/// The nodes and faces of the bodies some contact rule names (fixed for a model).
#[derive(Default)]
pub(super) struct ContactMesh {
    /// Particles that are nodes of those bodies (ascending), and their body.
    pub(super) nodes: Vec<u32>,
    pub(super) node_body: Vec<u32>,
    /// Faces of those bodies.
    pub(super) faces: Vec<Face>,
}

impl ContactMesh {
    /// The compact index of contact node `p` (a particle).
    pub(super) fn compact(&self, p: u32) -> usize {
        self.nodes.binary_search(&p).expect("a contact node")
    }
}

/// The candidate pairs and, at the last evaluation, their geometry and forces.
#[derive(Default)]
pub(super) struct Candidates {
    /// (compact node, face), sorted; node k's pairs are `offsets[k]..offsets[k + 1]`.
    pub(super) pairs: Vec<[u32; 2]>,
    pub(super) offsets: Vec<u32>,
    /// Per pair: the closest point of the face to the node, and the forces
    /// [node, corner 0, corner 1, corner 2] of every term on the pair.
    pub(super) points: Vec<PointTriangle>,
    pub(super) forces: Vec<[DVec3; 4]>,
}

/// Appends the Gauss–Newton blocks c·g_a g_bᵀ of candidate pair `k` for a
/// curvature c = ∂²E/∂d² > 0 (nothing for c ≤ 0), g = (n̂, −w_0 n̂, −w_1 n̂,
/// −w_2 n̂) over (node, corner 0, corner 1, corner 2) at its closest point.
pub(super) fn push_pair_blocks(mesh: &ContactMesh, candidates: &Candidates, k: usize, curvature: f64, blocks: &mut Vec<StiffnessBlock>) {
    if curvature <= 0.0 {
        return;
    }
    let (pt, [node, face]) = (&candidates.points[k], candidates.pairs[k]);
    let corners = mesh.faces[face as usize].0;
    let nn = DMat3::from_cols(pt.normal * pt.normal.x, pt.normal * pt.normal.y, pt.normal * pt.normal.z) * curvature;
    let particles = [mesh.nodes[node as usize], corners[0], corners[1], corners[2]];
    let g = [1.0, -pt.weights[0], -pt.weights[1], -pt.weights[2]];
    for a in 0..4 {
        for b in 0..4 {
            blocks.push(StiffnessBlock { i: particles[a], j: particles[b], block: nn * (g[a] * g[b]) });
        }
    }
}

/// Corners of face `corners`, image-consistent around the first.
#[inline]
pub(super) fn face_corners(x: &[DVec3], images: &Images, corners: [u32; 3]) -> [DVec3; 3] {
    let a = x[corners[0] as usize];
    corners.map(|q| a + images.minimum_image(x[q as usize] - a))
}

/// Rows to CSR (offsets, flat).
pub(super) fn csr<T>(rows: Vec<Vec<T>>) -> (Vec<u32>, Vec<T>) {
    let mut offsets = Vec::with_capacity(rows.len() + 1);
    let mut flat = Vec::new();
    offsets.push(0);
    for row in rows {
        flat.extend(row);
        offsets.push(flat.len() as u32);
    }
    (offsets, flat)
}
