//! Closed triangulated surfaces (cell shells): connectivity, the geometry the
//! surface interactions share, and the icosphere; and the rest shape of a
//! linear tetrahedron ([`TetraRest`]), which the volume elements share.
//!
//! A [`SurfaceMesh`] holds one body's faces in local node numbering
//! (`0..nodes`), each face wound counter-clockwise seen from outside, so its
//! normal (x_b − x_a) × (x_c − x_a) points out of the body. Every edge is
//! listed once with its two **wings**: the third corners of the two faces
//! that share it.
//!
//! # Geometry
//!
//! - Face area A_t = ½|(x_b − x_a) × (x_c − x_a)| with gradient
//!   ∂A_t/∂x_a = ½ (x_b − x_c) × n̂ (cyclic in a, b, c). Its Hessian, with
//!   n = (x_b − x_a) × (x_c − x_a), P = I − n̂n̂ᵀ, \[v\]ₓ the cross-product
//!   matrix and e_a = x_b − x_c (cyclic): ∂²A_t/∂x_k∂x_l =
//!   −\[e_k\]ₓ P \[e_l\]ₓ/(2|n|) + ½M_kl, where M_kk = 0, M_ab = M_bc = M_ca =
//!   −\[n̂\]ₓ and M_ba = M_cb = M_ac = \[n̂\]ₓ (the second-order part of n̂·n).
//!   Indefinite: a face shrinks to second order when two corners slide
//!   apart across each other.
//! - Enclosed volume by the divergence theorem,
//!   V = (1/6) Σ_t (x_a − o)·((x_b − o) × (x_c − o)), independent of the
//!   origin o for a closed surface; ∂V/∂x_a = (1/6) Σ_t (x_b − o) × (x_c − o),
//!   which summed around a node is (1/3) Σ_t A_t n̂_t: the pressure force
//!   ΔP·A_t n̂_t/3 on each corner of each face is exactly ΔP·∂V/∂x.
//! - Bending angle θ_e of an edge e = (i, j) with wings a (face (i, j, a))
//!   and b (face (j, i, b)): the signed angle between the two outward face
//!   normals, positive where the surface is convex (a ridge seen from
//!   outside), zero where flat. Its gradient is ∂θ/∂x_a = −|e|·N_a/|N_a|²,
//!   ∂θ/∂x_b = −|e|·N_b/|N_b|² (N the unnormalised face normals) and, with
//!   s_w = (x_w − x_i)·e/|e|² the position of wing w's foot along the edge,
//!   ∂θ/∂x_i = −Σ_w (1 − s_w)·∂θ/∂x_w, ∂θ/∂x_j = −Σ_w s_w·∂θ/∂x_w
//!   (Bridson, Marino and Fedkiw 2003; the four sum to zero).
//! - Point–triangle distance d = |p − q|, q the closest point of the face
//!   (interior, edge or vertex region; [`point_triangle`]), with gradient
//!   ∂d/∂p = n̂ and ∂d/∂x_k = −w_k·n̂ (w_k the barycentric weights of q,
//!   n̂ = (p − q)/d): what node–face contact between cells needs.
//!
//! ```
//! use cellmd::mesh::{icosphere, SurfaceMesh};
//! let (x, faces) = icosphere(3, 1.0);
//! let mesh = SurfaceMesh::new(x.len(), faces).unwrap();
//! assert_eq!((mesh.nodes(), mesh.edges().len(), mesh.triangles().len()), (642, 1920, 1280));
//! // An inscribed polyhedron: 0.86 % less volume than the unit sphere.
//! let sphere = 4.0 / 3.0 * std::f64::consts::PI;
//! assert!((sphere - mesh.volume(&x)) / sphere < 0.01);
//! ```

use std::collections::HashMap;

use glam::{DMat3, DVec3};

/// An edge (i, j) of a closed mesh and its wings: face (i, j, a) and face (j, i, b).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MeshEdge {
    pub ends: [u32; 2],
    pub wings: [u32; 2],
}

/// One closed, consistently oriented surface in local node numbering.
#[derive(Clone, Debug, PartialEq)]
pub struct SurfaceMesh {
    nodes: usize,
    triangles: Vec<[u32; 3]>,
    edges: Vec<MeshEdge>,
    /// Breadth-first spanning tree over the edges from node 0: (node, parent)
    /// in visiting order, for making positions image-consistent.
    tree: Vec<[u32; 2]>,
}

impl SurfaceMesh {
    /// Builds the edge list of a closed, consistently oriented triangulation
    /// (each directed edge once, each with its reverse). Edges are numbered in
    /// order of first appearance. The topology parser has already checked a
    /// body's faces (with positions in the file); this check is for meshes
    /// built in code.
    pub fn new(nodes: usize, triangles: Vec<[u32; 3]>) -> Result<Self, String> {
        let mut directed: HashMap<(u32, u32), u32> = HashMap::with_capacity(3 * triangles.len());
        for (t, &[a, b, c]) in triangles.iter().enumerate() {
            if [a, b, c].iter().any(|&p| p as usize >= nodes) {
                return Err(format!("face {t} names a node beyond {nodes}"));
            }
            for (u, v, w) in [(a, b, c), (b, c, a), (c, a, b)] {
                if directed.insert((u, v), w).is_some() {
                    return Err(format!("edge {u}→{v} is traversed twice in the same direction"));
                }
            }
        }
        let mut edges = Vec::with_capacity(directed.len() / 2);
        for &[a, b, c] in &triangles {
            for (u, v, w) in [(a, b, c), (b, c, a), (c, a, b)] {
                let Some(&opposite) = directed.get(&(v, u)) else { return Err(format!("edge {u}–{v} has one face only")) };
                if u < v {
                    edges.push(MeshEdge { ends: [u, v], wings: [w, opposite] });
                }
            }
        }
        let mut neighbours = vec![Vec::new(); nodes];
        for e in &edges {
            neighbours[e.ends[0] as usize].push(e.ends[1]);
            neighbours[e.ends[1] as usize].push(e.ends[0]);
        }
        let mut seen = vec![false; nodes];
        let mut tree = Vec::with_capacity(nodes.saturating_sub(1));
        let mut queue = std::collections::VecDeque::from([0u32]);
        if nodes > 0 {
            seen[0] = true;
        }
        while let Some(p) = queue.pop_front() {
            for &q in &neighbours[p as usize] {
                if !seen[q as usize] {
                    seen[q as usize] = true;
                    tree.push([q, p]);
                    queue.push_back(q);
                }
            }
        }
        if seen.iter().any(|s| !s) {
            return Err("the mesh is not connected (or a node is in no face)".into());
        }
        Ok(Self { nodes, triangles, edges, tree })
    }

    pub fn nodes(&self) -> usize {
        self.nodes
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    pub fn edges(&self) -> &[MeshEdge] {
        &self.edges
    }

    /// Euler characteristic V − E + F (2 for a closed surface of sphere topology).
    pub fn euler_characteristic(&self) -> i64 {
        self.nodes as i64 - self.edges.len() as i64 + self.triangles.len() as i64
    }

    /// Fills `out` with image-consistent positions: node 0 where it is, every
    /// other node at its tree parent plus `minimum_image(x_node − x_parent)`.
    /// Right whenever each edge is shorter than half the periodic box.
    pub fn unwrap_into(&self, x: impl Fn(u32) -> DVec3, minimum_image: impl Fn(DVec3) -> DVec3, out: &mut Vec<DVec3>) {
        out.clear();
        out.resize(self.nodes, DVec3::ZERO);
        if self.nodes == 0 {
            return;
        }
        out[0] = x(0);
        for &[node, parent] in &self.tree {
            out[node as usize] = out[parent as usize] + minimum_image(x(node) - x(parent));
        }
    }

    /// The centroid of the nodes (a well-conditioned origin for the volume).
    pub fn centroid(&self, x: &[DVec3]) -> DVec3 {
        x.iter().sum::<DVec3>() / self.nodes as f64
    }

    /// Enclosed volume (divergence theorem), positive for outward-wound faces.
    pub fn volume(&self, x: &[DVec3]) -> f64 {
        let o = self.centroid(x);
        self.triangles.iter().map(|&[a, b, c]| (x[a as usize] - o).dot((x[b as usize] - o).cross(x[c as usize] - o))).sum::<f64>() / 6.0
    }

    /// Enclosed volume and its gradient (added to `grad`).
    pub fn volume_gradient(&self, x: &[DVec3], grad: &mut [DVec3]) -> f64 {
        let o = self.centroid(x);
        let mut six_v = 0.0;
        for &[a, b, c] in &self.triangles {
            let (ra, rb, rc) = (x[a as usize] - o, x[b as usize] - o, x[c as usize] - o);
            six_v += ra.dot(rb.cross(rc));
            grad[a as usize] += rb.cross(rc) / 6.0;
            grad[b as usize] += rc.cross(ra) / 6.0;
            grad[c as usize] += ra.cross(rb) / 6.0;
        }
        six_v / 6.0
    }

    /// Total area.
    pub fn area(&self, x: &[DVec3]) -> f64 {
        self.triangles.iter().map(|&t| triangle_area(t.map(|p| x[p as usize]))).sum()
    }

    /// The positions' corners of face `t`.
    #[inline]
    pub fn corners(&self, t: usize, x: &[DVec3]) -> [DVec3; 3] {
        self.triangles[t].map(|p| x[p as usize])
    }
}

/// Area of a triangle.
#[inline]
pub fn triangle_area([a, b, c]: [DVec3; 3]) -> f64 {
    0.5 * (b - a).cross(c - a).length()
}

/// Area of a triangle and its gradient with respect to the three corners.
#[inline]
pub fn triangle_area_gradient([a, b, c]: [DVec3; 3]) -> (f64, [DVec3; 3]) {
    let n = (b - a).cross(c - a);
    let twice = n.length();
    let unit = n / twice;
    (0.5 * twice, [0.5 * (b - c).cross(unit), 0.5 * (c - a).cross(unit), 0.5 * (a - b).cross(unit)])
}

/// The cross-product matrix \[v\]ₓ: \[v\]ₓ·u = v × u.
#[inline]
pub fn cross_matrix(v: DVec3) -> DMat3 {
    DMat3::from_cols(DVec3::new(0.0, v.z, -v.y), DVec3::new(-v.z, 0.0, v.x), DVec3::new(v.y, -v.x, 0.0))
}

/// The Hessian ∂²A/∂x_k∂x_l of a triangle's area, as 3×3 blocks `[k][l]`
/// (see the module docs).
pub fn triangle_area_hessian([a, b, c]: [DVec3; 3]) -> [[DMat3; 3]; 3] {
    let n = (b - a).cross(c - a);
    let twice = n.length();
    let unit = n / twice;
    let projector = DMat3::IDENTITY - DMat3::from_cols(unit * unit.x, unit * unit.y, unit * unit.z);
    let edges = [b - c, c - a, a - b].map(cross_matrix);
    let turn = cross_matrix(unit);
    std::array::from_fn(|k| {
        std::array::from_fn(|l| {
            let second = match (l + 3 - k) % 3 {
                0 => DMat3::ZERO,
                1 => -0.5 * turn,
                _ => 0.5 * turn,
            };
            -(edges[k] * projector * edges[l]) / (2.0 * twice) + second
        })
    })
}

/// Bending angle of edge (i, j) with wings a (face (i, j, a)) and b (face
/// (j, i, b)): positive where convex. Returns θ and ∂θ/∂(x_i, x_j, x_a, x_b).
#[inline]
pub fn bending_angle(xi: DVec3, xj: DVec3, xa: DVec3, xb: DVec3) -> (f64, [DVec3; 4]) {
    let e = xj - xi;
    let na = e.cross(xa - xi);
    let nb = (xi - xj).cross(xb - xj);
    let len2 = e.length_squared();
    let len = len2.sqrt();
    let theta = na.cross(nb).dot(e / len).atan2(na.dot(nb));
    let ga = -len * na / na.length_squared();
    let gb = -len * nb / nb.length_squared();
    let sa = (xa - xi).dot(e) / len2;
    let sb = (xb - xi).dot(e) / len2;
    let gi = -(1.0 - sa) * ga - (1.0 - sb) * gb;
    let gj = -sa * ga - sb * gb;
    (theta, [gi, gj, ga, gb])
}

/// The closest point of a triangle to a point `p`, as barycentric weights.
///
/// `distance` = |p − q| with q = Σ_k w_k x_k the closest point of the
/// triangle [x_0, x_1, x_2] (face interior, an edge or a vertex, after
/// Ericson, *Real-Time Collision Detection*, §5.1.5) and `normal` the unit
/// vector (p − q)/|p − q|. Because q minimises the distance, the gradient
/// needs no derivative of q (envelope theorem), in every region:
/// ∂d/∂p = n̂ and ∂d/∂x_k = −w_k·n̂, which sum to zero.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointTriangle {
    pub distance: f64,
    pub weights: [f64; 3],
    pub normal: DVec3,
}

/// The closest point of triangle `[a, b, c]` to `p` (see [`PointTriangle`]).
pub fn point_triangle(p: DVec3, [a, b, c]: [DVec3; 3]) -> PointTriangle {
    let weights = closest_weights(p, a, b, c);
    let q = weights[0] * a + weights[1] * b + weights[2] * c;
    let d = p - q;
    let distance = d.length();
    PointTriangle { distance, weights, normal: d / distance }
}

/// Barycentric weights of the point of triangle (a, b, c) closest to p,
/// by Voronoi region: three vertices, three edges, then the interior. The
/// GPU's f32 twin, line by line, is `closest_weights` in `src/mesh.wgsl`.
fn closest_weights(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> [f64; 3] {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    [1.0 - v - w, v, w]
}

/// The icosphere of subdivision `level` and `radius` centred at the origin:
/// the regular icosahedron (level 0, 12 nodes), each level splitting every
/// face into four at its edge midpoints, new nodes pushed onto the sphere.
/// 10·4ⁿ + 2 nodes (12, 42, 162, 642, 2562, …) and 20·4ⁿ faces, wound
/// counter-clockwise seen from outside. Deterministic: nodes are numbered in
/// order of creation (faces in order, their edges in order).
pub fn icosphere(level: u32, radius: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let phi = (1.0 + 5f64.sqrt()) / 2.0;
    let mut x: Vec<DVec3> = [
        (-1.0, phi, 0.0),
        (1.0, phi, 0.0),
        (-1.0, -phi, 0.0),
        (1.0, -phi, 0.0),
        (0.0, -1.0, phi),
        (0.0, 1.0, phi),
        (0.0, -1.0, -phi),
        (0.0, 1.0, -phi),
        (phi, 0.0, -1.0),
        (phi, 0.0, 1.0),
        (-phi, 0.0, -1.0),
        (-phi, 0.0, 1.0),
    ]
    .iter()
    .map(|&(a, b, c)| DVec3::new(a, b, c).normalize())
    .collect();
    let mut faces: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..level {
        let mut midpoint: HashMap<(u32, u32), u32> = HashMap::new();
        let mut middle = |a: u32, b: u32, x: &mut Vec<DVec3>| -> u32 {
            *midpoint.entry((a.min(b), a.max(b))).or_insert_with(|| {
                x.push(((x[a as usize] + x[b as usize]) / 2.0).normalize());
                x.len() as u32 - 1
            })
        };
        let mut next = Vec::with_capacity(4 * faces.len());
        for &[a, b, c] in &faces {
            let ab = middle(a, b, &mut x);
            let bc = middle(b, c, &mut x);
            let ca = middle(c, a, &mut x);
            next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        faces = next;
    }
    (x.into_iter().map(|p| p * radius).collect(), faces)
}

/// The rest shape of a linear (constant-strain) tetrahedron with corners
/// x_0 … x_3: D_m⁻¹ and the rest volume V_0 = |det D_m|/6, where
/// D_m = [X_1 − X_0, X_2 − X_0, X_3 − X_0] (columns) at rest.
///
/// The deformation gradient of the current corners x is
/// F = D_s·D_m⁻¹ with D_s = [x_1 − x_0, x_2 − x_0, x_3 − x_0]; it is the same
/// for either winding of the corners (det F > 0 unless the element turned
/// inside out). An energy V_0·W(F) with first Piola stress P = ∂W/∂F exerts
/// the forces [f_1 f_2 f_3] = −V_0·P·D_m⁻ᵀ (columns) and f_0 = −(f_1 + f_2 + f_3)
/// ([`TetraRest::forces`]; Sifakis and Barbič, SIGGRAPH course 2012).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TetraRest {
    pub dm_inv: DMat3,
    pub volume: f64,
}

/// The edge matrix [x_1 − x_0, x_2 − x_0, x_3 − x_0] of a tetrahedron.
pub fn tetra_edges(x: [DVec3; 4]) -> DMat3 {
    DMat3::from_cols(x[1] - x[0], x[2] - x[0], x[3] - x[0])
}

impl TetraRest {
    /// The rest shape of corners `x`; an error (for the caller to place)
    /// when they are degenerate: a rest volume below 10⁻¹² of the cube of
    /// the longest edge, where D_m⁻¹ would be meaningless.
    pub fn new(x: [DVec3; 4]) -> Result<Self, String> {
        let dm = tetra_edges(x);
        let signed = dm.determinant() / 6.0;
        let longest = (0..4).flat_map(|a| (a + 1..4).map(move |b| (a, b))).map(|(a, b)| (x[a] - x[b]).length()).fold(0.0, f64::max);
        if !(signed.abs() > 1e-12 * longest.powi(3)) {
            return Err(format!("the four corners are degenerate (rest volume {signed:e} for a longest edge of {longest:e})"));
        }
        Ok(Self { dm_inv: dm.inverse(), volume: signed.abs() })
    }

    /// F = D_s·D_m⁻¹ at corners `x`.
    pub fn deformation_gradient(&self, x: [DVec3; 4]) -> DMat3 {
        tetra_edges(x) * self.dm_inv
    }

    /// The corner forces of an energy V_0·W(F) whose first Piola stress is `piola`.
    pub fn forces(&self, piola: DMat3) -> [DVec3; 4] {
        let h = -self.volume * piola * self.dm_inv.transpose();
        let [f1, f2, f3] = [h.x_axis, h.y_axis, h.z_axis];
        [-(f1 + f2 + f3), f1, f2, f3]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn icosphere_counts_orientation_and_volume_converge() {
        let mut last_error = f64::INFINITY;
        for level in 0..5 {
            let (x, faces) = icosphere(level, 2.0);
            let n = 10 * 4usize.pow(level) + 2;
            assert_eq!(x.len(), n);
            let mesh = SurfaceMesh::new(n, faces).unwrap();
            assert_eq!(mesh.euler_characteristic(), 2);
            assert!(x.iter().all(|p| (p.length() - 2.0).abs() < 1e-12));
            // Outward: every face normal points away from the centre.
            for t in 0..mesh.triangles().len() {
                let [a, b, c] = mesh.corners(t, &x);
                assert!((b - a).cross(c - a).dot(a + b + c) > 0.0, "level {level}: face {t} is wound inwards");
            }
            let exact = 4.0 / 3.0 * std::f64::consts::PI * 8.0;
            let error = (exact - mesh.volume(&x)) / exact;
            // Second order in the edge length: the error falls ≈ 4× per level (3.1× from level 0 to 1).
            assert!(error > 0.0 && error < last_error / 3.0, "level {level}: volume error {error:e} after {last_error:e}");
            last_error = error;
        }
    }

    #[test]
    fn volume_is_origin_free_and_its_gradient_is_a_third_of_the_area_normals() {
        let (mut x, faces) = icosphere(1, 1.0);
        for (k, p) in x.iter_mut().enumerate() {
            *p += DVec3::new(0.03 * (k as f64).sin(), 0.02 * (k as f64 * 1.7).cos(), 0.01 * k as f64 / 42.0) + DVec3::splat(5.0);
        }
        let mesh = SurfaceMesh::new(x.len(), faces).unwrap();
        let mut grad = vec![DVec3::ZERO; x.len()];
        let v = mesh.volume_gradient(&x, &mut grad);
        assert!((v - mesh.volume(&x)).abs() < 1e-14);
        let mut third = vec![DVec3::ZERO; x.len()];
        for t in 0..mesh.triangles().len() {
            let [a, b, c] = mesh.corners(t, &x);
            let area_normal = 0.5 * (b - a).cross(c - a);
            for p in mesh.triangles()[t] {
                third[p as usize] += area_normal / 3.0;
            }
        }
        for (g, t) in grad.iter().zip(&third) {
            assert!((*g - *t).length() < 1e-14, "{g} vs {t}");
        }
    }

    #[test]
    fn bending_angle_sign_value_and_gradient() {
        let (xi, xj, xa) = (DVec3::ZERO, DVec3::X, DVec3::new(0.4, 1.0, 0.0));
        for t in [-0.7, -0.2, 0.0, 0.3, 1.1] {
            let xb = DVec3::new(0.6, -1.0, -t);
            let (theta, g) = bending_angle(xi, xj, xa, xb);
            // A roof bent down on the far side (t > 0) is convex seen from +z.
            assert!((theta - t.atan()).abs() < 1e-14, "t = {t}: θ = {theta}");
            let sum: DVec3 = g.iter().sum();
            assert!(sum.length() < 1e-14);
            let h = 1e-6;
            let points = [xi, xj, xa, xb];
            for (k, gk) in g.iter().enumerate() {
                for axis in 0..3 {
                    let (mut p, mut m) = (points, points);
                    p[k][axis] += h;
                    m[k][axis] -= h;
                    let numeric = (bending_angle(p[0], p[1], p[2], p[3]).0 - bending_angle(m[0], m[1], m[2], m[3]).0) / (2.0 * h);
                    assert!((numeric - gk[axis]).abs() < 1e-8, "t = {t}, point {k}, axis {axis}: {numeric} vs {}", gk[axis]);
                }
            }
        }
    }

    #[test]
    fn point_triangle_finds_the_face_edge_and_vertex_regions_and_its_gradient() {
        let tri = [DVec3::ZERO, DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.5, 1.5, 0.0)];
        // Points over the interior, edges ab, bc and ca, then vertices a, b and c.
        let cases = [
            DVec3::new(0.7, 0.5, 0.3),
            DVec3::new(1.0, -0.4, 0.2),
            DVec3::new(1.6, 1.0, -0.1),
            DVec3::new(-0.6, 0.4, 0.25),
            DVec3::new(-0.5, -0.3, 0.1),
            DVec3::new(2.5, -0.2, 0.3),
            DVec3::new(0.5, 2.2, -0.4),
        ];
        for (k, p) in cases.iter().enumerate() {
            let pt = point_triangle(*p, tri);
            let q = pt.weights[0] * tri[0] + pt.weights[1] * tri[1] + pt.weights[2] * tri[2];
            // q is in the triangle and no sampled point of it is closer.
            assert!(pt.weights.iter().all(|w| (-1e-15..=1.0 + 1e-15).contains(w)) && (pt.weights.iter().sum::<f64>() - 1.0).abs() < 1e-14);
            for i in 0..=40 {
                for j in 0..=40 - i {
                    let (u, v) = (i as f64 / 40.0, j as f64 / 40.0);
                    let s = (1.0 - u - v) * tri[0] + u * tri[1] + v * tri[2];
                    assert!((*p - s).length() >= pt.distance - 1e-12, "case {k}: a closer point {s}");
                }
            }
            assert!(((*p - q).length() - pt.distance).abs() < 1e-14);
            // ∂d/∂p = n̂, ∂d/∂x_k = −w_k n̂ by central differences.
            let h = 1e-6;
            let mut points = [*p, tri[0], tri[1], tri[2]];
            let grads = [pt.normal, -pt.weights[0] * pt.normal, -pt.weights[1] * pt.normal, -pt.weights[2] * pt.normal];
            for (m, g) in grads.iter().enumerate() {
                for axis in 0..3 {
                    let x0 = points[m][axis];
                    points[m][axis] = x0 + h;
                    let up = point_triangle(points[0], [points[1], points[2], points[3]]).distance;
                    points[m][axis] = x0 - h;
                    let down = point_triangle(points[0], [points[1], points[2], points[3]]).distance;
                    points[m][axis] = x0;
                    assert!(((up - down) / (2.0 * h) - g[axis]).abs() < 1e-8, "case {k}, point {m}, axis {axis}");
                }
            }
        }
        // The regions themselves.
        let region = |p: DVec3| point_triangle(p, tri).weights.iter().filter(|w| **w > 0.0).count();
        assert_eq!(cases.map(region), [3, 2, 2, 2, 1, 1, 1]);
    }

    #[test]
    fn the_area_hessian_matches_second_differences_of_the_area() {
        let tri = [DVec3::new(0.1, -0.2, 0.3), DVec3::new(1.3, 0.1, -0.2), DVec3::new(0.4, 0.9, 0.5)];
        let analytic = triangle_area_hessian(tri);
        let h = 1e-4;
        let moved = |k: usize, a: usize, s: f64, l: usize, b: usize, t: f64| {
            let mut x = tri;
            x[k][a] += s;
            x[l][b] += t;
            triangle_area(x)
        };
        let mut largest: f64 = 0.0;
        for (k, l, a, b) in (0..81).map(|n| (n / 27, n / 9 % 3, n / 3 % 3, n % 3)) {
            let fd =
                (moved(k, a, h, l, b, h) - moved(k, a, h, l, b, -h) - moved(k, a, -h, l, b, h) + moved(k, a, -h, l, b, -h)) / (4.0 * h * h);
            let exact = analytic[k][l].col(b)[a];
            assert!((fd - exact).abs() < 1e-6, "corner {k} axis {a}, corner {l} axis {b}: {fd} vs {exact}");
            largest = largest.max(exact.abs());
        }
        assert!(largest > 0.1);
        // Indefinite: some motion shrinks the face to second order.
        let matrix = faer::Mat::<f64>::from_fn(9, 9, |r, c| analytic[r / 3][c / 3].col(c % 3)[r % 3]);
        let eigen = matrix.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
        assert!(eigen[0] < -0.1 && eigen[8] > 0.1, "eigenvalues {eigen:?}");
    }

    #[test]
    fn a_bad_mesh_is_refused() {
        assert!(SurfaceMesh::new(4, vec![[0, 2, 1], [0, 1, 3], [1, 2, 3]]).unwrap_err().contains("one face only"));
        assert!(SurfaceMesh::new(4, vec![[0, 2, 1], [0, 1, 3], [1, 3, 2], [2, 0, 3]]).unwrap_err().contains("twice in the same direction"));
    }
}
