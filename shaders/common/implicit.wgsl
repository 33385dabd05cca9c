// The linearly implicit step on the device (src/gpu/implicit.rs has the
// equation, the buffer layout and the precision argument):
//   (γ/dt·I + K̃)·Δx = F + √(2kT·γ/dt)·ξ,   x ← x + Δx,
// solved by Jacobi-preconditioned conjugate gradients, matrix-free. After
// the force pass of a step:
//   1. `implicit_angles` (one invocation per angle): the angle's exact 9×9
//      Hessian from its law's `NAME_hessian`, projected onto its positive
//      semi-definite part (cyclic Jacobi), as the CPU's blocks.
//   1b. `implicit_tetras` (one invocation per volume element): its exact
//      12×12 Hessian from its law's `NAME_tetra_hessian`, projected likewise.
//   1c. `implicit_faces` (one invocation per face of a body with surface
//      terms): each term's 9×9 stencil from its law's `NAME_face_hessian`,
//      projected term by term and summed, as the CPU's blocks.
//   1d. `implicit_nodes` (one invocation per node of a body with a
//      curvature law): the weights w, β of its Gauss–Newton term
//      w·g gᵀ, g = ∇M_i − β·∇A_i over its one-ring (`NAME_node_weights`).
//   2. `implicit_blocks` (one per particle): the projected radial block of
//      each of its bond ends and the Hessian of each of its externals, and
//      the Jacobi diagonal from them and its angles' diagonal blocks.
//   3. `implicit_solve` (ONE workgroup; or the split solve of
//      shaders/common/implicit_split.wgsl over every workgroup, one
//      dispatch per phase): the whole CG, every product K̃·v
//      gathered per particle from its own terms in a fixed order, every dot
//      product a fixed tree over the workgroup; the convergence test is
//      taken on the device each iteration and nothing is read back. A body's
//      Gauss–Newton terms over all its nodes (turgor's (K/V0)·∇V∇Vᵀ, the
//      global area term's (k_a/A0)·∇A∇Aᵀ) stay rank one: before each
//      product the body's ∇V·v and ∇A·v are summed face by face
//      (`body_dots`), and each node gathers w·(g·v)·g_i from its faces; so
//      do the curvature nodes' one-ring terms, g·v per node from its edges
//      and faces, gathered through the edge and face-corner slots.
//      With contact between bodies, the pairs' Gauss–Newton terms join each
//      product and the step clamp s follows the solve
//      (shaders/common/implicit_contact.wgsl).
//   4. `implicit_move` (one per particle): x ← x + s·Δx in fixed point, the
//      blow-up check of the explicit step (`step_particle`).
// No float atomics: the same run gives the same bits.

@group(1) @binding(1) var<storage, read> imp_topo: array<u32>;
@group(1) @binding(2) var<storage, read_write> imp: array<vec4<f32>>;

// The header words of `imp_topo` (IMP_*, src/gpu/implicit.rs writes them) and
// the block sizes ANGLE_VEC4, TETRA_VEC4 and FACE_VEC4 are the prelude's (src/gpu/prelude.rs).

// Per-particle vectors of `imp`: section s of particle i is imp[s·n + i].
const VEC_X: u32 = 0u;    // Δx
const VEC_R: u32 = 1u;    // residual (first the right-hand side)
const VEC_Z: u32 = 2u;    // preconditioned residual
const VEC_P: u32 = 3u;    // search direction
const VEC_Q: u32 = 4u;    // A·p
const VEC_DINV: u32 = 5u; // inverse Jacobi diagonal
// Row stride of the matrices `project_psd` works on.
const PSD_STRIDE: u32 = 12u;

fn identity3() -> mat3x3<f32> {
    return mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
}

// u·vᵀ.
fn outer3(u: vec3<f32>, v: vec3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(u * v.x, u * v.y, u * v.z);
}

// Writes the 3×3 block (rb, cb) of a row-major 9×9 matrix.
fn put_block(h: ptr<function, array<f32, 81>>, rb: u32, cb: u32, m: mat3x3<f32>) {
    for (var row = 0u; row < 3u; row++) {
        for (var col = 0u; col < 3u; col++) {
            (*h)[(3u * rb + row) * 9u + 3u * cb + col] = m[col][row];
        }
    }
}

// The positive semi-definite part Σ max(λ, 0)·v vᵀ of the symmetric
// leading dim×dim block of a row-major 12×12 matrix (an angle's 9×9, a volume
// element's 12×12) (cyclic Jacobi rotations,
// Numerical Recipes §11.1, until the off-diagonal mass is below 1e-14 of the
// whole); left as it is when no eigenvalue is negative, as on the CPU.
fn project_psd(h: ptr<function, array<f32, 144>>, dim: u32) {
    var a = *h;
    var v: array<f32, 144>;
    var whole = 0.0;
    for (var k = 0u; k < dim; k++) {
        v[k * PSD_STRIDE + k] = 1.0;
        for (var l = 0u; l < dim; l++) {
            whole += a[k * PSD_STRIDE + l] * a[k * PSD_STRIDE + l];
        }
    }
    for (var sweep = 0u; sweep < 16u; sweep++) {
        var off = 0.0;
        for (var p = 0u; p < dim; p++) {
            for (var q = p + 1u; q < dim; q++) {
                off += a[p * PSD_STRIDE + q] * a[p * PSD_STRIDE + q];
            }
        }
        if !(off > 1e-14 * whole) {
            break;
        }
        for (var p = 0u; p < dim; p++) {
            for (var q = p + 1u; q < dim; q++) {
                let apq = a[p * PSD_STRIDE + q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (a[q * PSD_STRIDE + q] - a[p * PSD_STRIDE + p]) / (2.0 * apq);
                let direction = select(1.0, -1.0, theta < 0.0);
                var t = direction / (abs(theta) + sqrt(theta * theta + 1.0));
                if abs(theta) > 1e18 {
                    t = 0.5 / theta;
                }
                let c = 1.0 / sqrt(t * t + 1.0);
                let s = t * c;
                for (var k = 0u; k < dim; k++) {
                    let kp = a[k * PSD_STRIDE + p];
                    let kq = a[k * PSD_STRIDE + q];
                    a[k * PSD_STRIDE + p] = c * kp - s * kq;
                    a[k * PSD_STRIDE + q] = s * kp + c * kq;
                }
                for (var k = 0u; k < dim; k++) {
                    let pk = a[p * PSD_STRIDE + k];
                    let qk = a[q * PSD_STRIDE + k];
                    a[p * PSD_STRIDE + k] = c * pk - s * qk;
                    a[q * PSD_STRIDE + k] = s * pk + c * qk;
                }
                for (var k = 0u; k < dim; k++) {
                    let kp = v[k * PSD_STRIDE + p];
                    let kq = v[k * PSD_STRIDE + q];
                    v[k * PSD_STRIDE + p] = c * kp - s * kq;
                    v[k * PSD_STRIDE + q] = s * kp + c * kq;
                }
            }
        }
    }
    var negative = false;
    for (var e = 0u; e < dim; e++) {
        negative = negative || a[e * PSD_STRIDE + e] < 0.0;
    }
    if !negative {
        return;
    }
    for (var r = 0u; r < dim; r++) {
        for (var c = 0u; c < dim; c++) {
            var sum = 0.0;
            for (var e = 0u; e < dim; e++) {
                sum += max(a[e * PSD_STRIDE + e], 0.0) * v[r * PSD_STRIDE + e] * v[c * PSD_STRIDE + e];
            }
            (*h)[r * PSD_STRIDE + c] = sum;
        }
    }
}

// γ/dt of particle i (0 for a fixed particle).
fn imp_drag(i: u32) -> f32 {
    return bitcast<f32>(imp_topo[imp_topo[IMP_OFF_DRAG] + topo[i]]);
}

// A symmetric 3×3 block stored as two entries (xx, xy, xz, yy), (yz, zz).
fn put_sym(at: u32, m: mat3x3<f32>) {
    imp[at] = vec4<f32>(m[0][0], m[1][0], m[2][0], m[1][1]);
    imp[at + 1u] = vec4<f32>(m[2][1], m[2][2], 0.0, 0.0);
}

fn sym_times(at: u32, v: vec3<f32>) -> vec3<f32> {
    let a = imp[at];
    let b = imp[at + 1u];
    return vec3<f32>(a.x * v.x + a.y * v.y + a.z * v.z, a.y * v.x + a.w * v.y + b.x * v.z, a.z * v.x + b.x * v.y + b.y * v.z);
}

fn sym_diagonal(at: u32) -> vec3<f32> {
    return vec3<f32>(imp[at].x, imp[at].w, imp[at + 1u].y);
}

// Entry f of angle a's row-major 9×9 block.
fn angle_entry(a: u32, f: u32) -> f32 {
    return imp[imp_topo[IMP_V_ANGLES] + ANGLE_VEC4 * a + f / 4u][f % 4u];
}

@compute @workgroup_size(256)
fn implicit_angles(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let a = linear_index(wg, local);
    if a >= imp_topo[IMP_ANGLES] || halted() {
        return;
    }
    let rec = imp_topo[IMP_OFF_ANGLES] + 4u * a;
    let pj = imp_topo[rec + 1u];
    let term = imp_topo[rec + 3u];
    // The vertex j at the origin, i and k at their minimum images (as the force pass).
    let ri = separation(pj, imp_topo[rec]);
    let rk = separation(pj, imp_topo[rec + 2u]);
    let hessian = three_body_hessian(topo[P.off_term_kind + term], term_params(term), ri, vec3<f32>(0.0), rk);
    var h: array<f32, 144>;
    for (var r = 0u; r < 9u; r++) {
        for (var c = 0u; c < 9u; c++) {
            h[r * PSD_STRIDE + c] = hessian[r * 9u + c];
        }
    }
    project_psd(&h, 9u);
    var packed: array<f32, 84>;
    for (var r = 0u; r < 9u; r++) {
        for (var c = 0u; c < 9u; c++) {
            packed[r * 9u + c] = h[r * PSD_STRIDE + c];
        }
    }
    let base = imp_topo[IMP_V_ANGLES] + ANGLE_VEC4 * a;
    for (var k = 0u; k < ANGLE_VEC4; k++) {
        imp[base + k] = vec4<f32>(packed[4u * k], packed[4u * k + 1u], packed[4u * k + 2u], packed[4u * k + 3u]);
    }
}

// Entry f of volume element e's row-major 12×12 block (`project_psd`'s storage, row stride PSD_STRIDE).
fn tetra_entry(e: u32, f: u32) -> f32 {
    return imp[imp_topo[IMP_V_TETRAS] + TETRA_VEC4 * e + f / 4u][f % 4u];
}

// One invocation per volume element: its exact 12×12 Hessian
// V_0·Σ_AB g_c[A]·g_d[B]·∂²W/∂F_αA∂F_βB (g_k the row k − 1 of D_m⁻¹ for
// corners k = 1–3, g_0 = −(g_1 + g_2 + g_3): ∂F_αA/∂x_kα = g_k[A]), with
// ∂²W/∂F∂F from the law's `NAME_tetra_hessian`, projected onto its positive
// semi-definite part as the angles' (the CPU takes the same Hessian by
// central differences of the element's forces). An element turned inside out
// (J ≤ 0) has no block: its forces stop the run first.
@compute @workgroup_size(256)
fn implicit_tetras(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let e = linear_index(wg, local);
    if e >= P.n_tetras || halted() {
        return;
    }
    let shape = tetra_shape(e);
    var h: array<f32, 144>;
    if shape.j > 0.0 {
        let c = tetra_hessian(topo[P.off_term_kind + shape.term], term_params(shape.term), shape.f, shape.j, shape.cofactor * (1.0 / shape.j));
        let rows = transpose(shape.dm_inv);
        let g = array<vec3<f32>, 4>(-(rows[0] + rows[1] + rows[2]), rows[0], rows[1], rows[2]);
        for (var k = 0u; k < 4u; k++) {
            for (var al = 0u; al < 3u; al++) {
                for (var l = 0u; l < 4u; l++) {
                    for (var be = 0u; be < 3u; be++) {
                        var sum = 0.0;
                        for (var a = 0u; a < 3u; a++) {
                            for (var b = 0u; b < 3u; b++) {
                                sum += g[k][a] * g[l][b] * c[(3u * a + al) * 9u + 3u * b + be];
                            }
                        }
                        h[(3u * k + al) * PSD_STRIDE + 3u * l + be] = shape.v0 * sum;
                    }
                }
            }
        }
        project_psd(&h, 12u);
    }
    let base = imp_topo[IMP_V_TETRAS] + TETRA_VEC4 * e;
    for (var k = 0u; k < TETRA_VEC4; k++) {
        imp[base + k] = vec4<f32>(h[4u * k], h[4u * k + 1u], h[4u * k + 2u], h[4u * k + 3u]);
    }
}

// Entry f of face e's row-major 9×9 block.
fn face_entry(e: u32, f: u32) -> f32 {
    return imp[imp_topo[IMP_V_FACES] + FACE_VEC4 * e + f / 4u][f % 4u];
}

// Packed body b's volume, area and face count at the step's force pass.
fn body_totals(b: u32) -> BodyTotals {
    let totals = surf[surf_body(b)];
    return BodyTotals(totals.x, totals.y, f32(topo[P.off_body_faces + b + 1u] - topo[P.off_body_faces + b]));
}

// One invocation per face: Σ over its body's terms of the PSD part of each
// term's 9×9 stencil (`NAME_face_hessian`), as the CPU projects each term's
// stencil alone.
@compute @workgroup_size(256)
fn implicit_faces(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let f = linear_index(wg, local);
    if f >= P.n_faces || halted() {
        return;
    }
    let b = face_word(f, 3u);
    let g = face_geometry(f);
    let body = body_totals(b);
    var sum: array<f32, 84>;
    let terms_end = topo[P.off_body_term_start + b + 1u];
    for (var t = topo[P.off_body_term_start + b]; t < terms_end; t++) {
        let term = topo[P.off_body_terms + t];
        let stencil = face_hessian(topo[P.off_term_kind + term], term_params(term), body, g);
        var h: array<f32, 144>;
        for (var r = 0u; r < 9u; r++) {
            for (var c = 0u; c < 9u; c++) {
                h[r * PSD_STRIDE + c] = stencil[r * 9u + c];
            }
        }
        project_psd(&h, 9u);
        for (var r = 0u; r < 9u; r++) {
            for (var c = 0u; c < 9u; c++) {
                sum[r * 9u + c] += h[r * PSD_STRIDE + c];
            }
        }
    }
    let base = imp_topo[IMP_V_FACES] + FACE_VEC4 * f;
    for (var k = 0u; k < FACE_VEC4; k++) {
        imp[base + k] = vec4<f32>(sum[4u * k], sum[4u * k + 1u], sum[4u * k + 2u], sum[4u * k + 3u]);
    }
}

// The weights (w_V, w_A) of packed body b's Gauss–Newton terms over all its
// nodes, w_V·∇V∇Vᵀ + w_A·∇A∇Aᵀ (`NAME_body_weights` of its terms, summed).
fn body_weight_sum(b: u32) -> vec2<f32> {
    let body = body_totals(b);
    var w = vec2<f32>(0.0);
    let terms_end = topo[P.off_body_term_start + b + 1u];
    for (var t = topo[P.off_body_term_start + b]; t < terms_end; t++) {
        let term = topo[P.off_body_terms + t];
        w += body_weights(topo[P.off_term_kind + term], term_params(term), body);
    }
    return w;
}

// Particle i's surface slot s as (face, corner), or NO_NODE in x for a slot
// that is not a face corner.
fn corner_slot(s: u32) -> vec2<u32> {
    let c = topo[P.off_node_slots + s] - surf_corner(0u);
    return select(vec2<u32>(NO_NODE, 0u), vec2<u32>(c / 3u, c % 3u), c < 3u * P.n_faces);
}

// ∂A_t/∂x at corner k of a face.
fn corner_area_gradient(g: FaceGeometry, k: u32) -> vec3<f32> {
    return select(select(g.ga2, g.ga1, k == 1u), g.ga0, k == 0u);
}

// One invocation per curvature node k: its M_k and A_k (`node_curvature_sums`,
// from the force pass's edge and face values) and the weights (w, β) of its
// body's curvature term there.
@compute @workgroup_size(256)
fn implicit_nodes(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = linear_index(wg, local);
    if k >= P.n_body_nodes || halted() {
        return;
    }
    let sums = node_curvature_sums(k);
    let b = topo[P.off_node_body + k];
    var w = vec2<f32>(0.0);
    let terms_end = topo[P.off_body_term_start + b + 1u];
    for (var t = topo[P.off_body_term_start + b]; t < terms_end; t++) {
        let term = topo[P.off_body_terms + t];
        w += node_weights(topo[P.off_term_kind + term], term_params(term), sums.x, sums.y);
    }
    imp[imp_topo[IMP_V_NODES] + k] = vec4<f32>(w, 0.0, 0.0);
}

// ∂(ℓθ)/∂x at role r (0, 1: ends; 2, 3: wings) of an edge.
fn edge_gradient_at(g: EdgeBending, r: u32) -> vec3<f32> {
    return select(select(select(g.gb, g.ga, r == 2u), g.gj, r == 1u), g.gi, r == 0u);
}

// For every packed body: (∇V·v, ∇A·v) of the vector in `section` beside its
// weights (`store_body_weights`), each body's sums taken face by face in
// order by one invocation (`body_dot`); for every curvature node k: g_k·v
// (`node_dot`); then a barrier, so that `apply_row` can gather them
// (`multiply` calls it before each product; the split solve dispatches
// `implicit_split_body_dots` instead).
fn body_dots(local: u32, section: u32) {
    for (var k = local; k < P.n_body_nodes; k += WORKGROUP) {
        node_dot(k, section);
    }
    for (var b = local; b < P.n_bodies; b += WORKGROUP) {
        body_dot(b, section);
    }
    storageBarrier();
}

// Curvature node k's g_k·v = ¼Σ_edges ∂(ℓθ)·v − β_k·⅓Σ_faces ∇A_t·v over its
// edges and faces in order, for the vector in `section`.
fn node_dot(k: u32, section: u32) {
    var dm = 0.0;
    let edges_end = topo[P.off_node_edge_offsets + k + 1u];
    for (var q = topo[P.off_node_edge_offsets + k]; q < edges_end; q++) {
        let e = topo[P.off_node_edges + q];
        let g = edge_bending(e);
        dm += dot(g.gi, imp_vec(section, edge_word(e, 0u))) + dot(g.gj, imp_vec(section, edge_word(e, 1u)))
            + dot(g.ga, imp_vec(section, edge_word(e, 2u))) + dot(g.gb, imp_vec(section, edge_word(e, 3u)));
    }
    var da = 0.0;
    let faces_end = topo[P.off_node_face_offsets + k + 1u];
    for (var q = topo[P.off_node_face_offsets + k]; q < faces_end; q++) {
        let f = topo[P.off_node_faces + q];
        let g = face_geometry(f);
        da += dot(g.ga0, imp_vec(section, face_word(f, 0u))) + dot(g.ga1, imp_vec(section, face_word(f, 1u)))
            + dot(g.ga2, imp_vec(section, face_word(f, 2u)));
    }
    let at = imp_topo[IMP_V_NODES] + k;
    imp[at].z = 0.25 * dm - imp[at].y * da / 3.0;
}

// Packed body b's (∇V·v, ∇A·v) for the vector in `section`, face by face in order.
fn body_dot(b: u32, section: u32) {
    var dots = vec2<f32>(0.0);
    let faces_end = topo[P.off_body_faces + b + 1u];
    for (var f = topo[P.off_body_faces + b]; f < faces_end; f++) {
        let g = face_geometry(f);
        let va = imp_vec(section, face_word(f, 0u));
        let vb = imp_vec(section, face_word(f, 1u));
        let vc = imp_vec(section, face_word(f, 2u));
        dots += vec2<f32>(dot(g.gv, va + vb + vc), dot(g.ga0, va) + dot(g.ga1, vb) + dot(g.ga2, vc));
    }
    let at = imp_topo[IMP_V_BODIES] + b;
    imp[at].z = dots.x;
    imp[at].w = dots.y;
}

// Every packed body's weights (w_V, w_A), fixed within a step: stored once
// before the solve's first product (`body_dots` adds the dots beside them).
fn store_body_weights(local: u32) {
    for (var b = local; b < P.n_bodies; b += WORKGROUP) {
        store_body_weight(b);
    }
}

fn store_body_weight(b: u32) {
    imp[imp_topo[IMP_V_BODIES] + b] = vec4<f32>(body_weight_sum(b), 0.0, 0.0);
}

// Particle i's rows of its faces' blocks and of its bodies' rank-one terms
// applied to the vector in `section`: Σ_faces block·v over the face's corners
// plus w_V·(∇V·v)·∂V_t/∂x_i + w_A·(∇A·v)·∂A_t/∂x_i (`body_dots` first).
fn surface_rows(i: u32, section: u32) -> vec3<f32> {
    var out = vec3<f32>(0.0);
    let slots_end = topo[P.off_node_slot_offsets + i + 1u];
    for (var s = topo[P.off_node_slot_offsets + i]; s < slots_end; s++) {
        let slot = corner_slot(s);
        if slot.x == NO_NODE {
            continue;
        }
        for (var c = 0u; c < 3u; c++) {
            let vc = imp_vec(section, face_word(slot.x, c));
            for (var m = 0u; m < 3u; m++) {
                let row = (3u * slot.y + m) * 9u + 3u * c;
                out[m] += face_entry(slot.x, row) * vc.x + face_entry(slot.x, row + 1u) * vc.y + face_entry(slot.x, row + 2u) * vc.z;
            }
        }
        let rank_one = imp[imp_topo[IMP_V_BODIES] + face_word(slot.x, 3u)];
        var area_coef = rank_one.y * rank_one.w;
        if face_word(slot.x, 4u) != NO_NODE {
            // −w_k·(g_k·v)·β_k·⅓∇A_t for each corner k of the face (curvature nodes).
            for (var c = 0u; c < 3u; c++) {
                let node = imp[imp_topo[IMP_V_NODES] + face_word(slot.x, 4u + c)];
                area_coef -= node.x * node.z * node.y / 3.0;
            }
        }
        if rank_one.x != 0.0 || area_coef != 0.0 {
            let g = face_geometry(slot.x);
            out += rank_one.x * rank_one.z * g.gv + area_coef * corner_area_gradient(g, slot.y);
        }
    }
    return out + curvature_edge_rows(i);
}

// Particle i's edge slots (bodies with a curvature law) as (edge, role), or
// NO_NODE in x for a slot that is not an edge slot.
fn edge_slot(s: u32) -> vec2<u32> {
    let c = topo[P.off_node_slots + s] - surf_edge_slot(0u);
    return select(vec2<u32>(NO_NODE, 0u), vec2<u32>(c / 4u, c % 4u), c < 4u * P.n_edges);
}

// Σ over particle i's edge slots of w_k·(g_k·v)·¼∂(ℓθ)/∂x_i for each end k
// of the edge (`body_dots` first).
fn curvature_edge_rows(i: u32) -> vec3<f32> {
    var out = vec3<f32>(0.0);
    let slots_end = topo[P.off_node_slot_offsets + i + 1u];
    for (var s = topo[P.off_node_slot_offsets + i]; s < slots_end; s++) {
        let slot = edge_slot(s);
        if slot.x == NO_NODE {
            continue;
        }
        let k0 = imp[imp_topo[IMP_V_NODES] + edge_word(slot.x, 4u)];
        let k1 = imp[imp_topo[IMP_V_NODES] + edge_word(slot.x, 5u)];
        out += 0.25 * (k0.x * k0.z + k1.x * k1.z) * edge_gradient_at(edge_bending(slot.x), slot.y);
    }
    return out;
}

// Particle i's share of the Jacobi diagonal from its faces' blocks and its
// bodies' rank-one terms, w·g_i² with g_i = Σ over its faces (its slots
// are in ascending body order, so each body's faces are consecutive). The
// curvature nodes' terms add w_k·c² for each face and edge contribution c
// to g_k at i, without the cross terms between contributions of one node
// (a preconditioner only: the CPU's exact diagonal changes the iterations,
// not the solution).
fn surface_diagonal(i: u32) -> vec3<f32> {
    var diagonal = vec3<f32>(0.0);
    var body = NO_NODE;
    var w = vec2<f32>(0.0);
    var gv = vec3<f32>(0.0);
    var ga = vec3<f32>(0.0);
    let slots_end = topo[P.off_node_slot_offsets + i + 1u];
    for (var s = topo[P.off_node_slot_offsets + i]; s < slots_end; s++) {
        let slot = corner_slot(s);
        if slot.x == NO_NODE {
            continue;
        }
        for (var m = 0u; m < 3u; m++) {
            diagonal[m] += face_entry(slot.x, (3u * slot.y + m) * 10u);
        }
        let b = face_word(slot.x, 3u);
        if b != body {
            diagonal += w.x * gv * gv + w.y * ga * ga;
            body = b;
            w = body_weight_sum(b);
            gv = vec3<f32>(0.0);
            ga = vec3<f32>(0.0);
        }
        let g = face_geometry(slot.x);
        gv += g.gv;
        ga += corner_area_gradient(g, slot.y);
        if face_word(slot.x, 4u) != NO_NODE {
            for (var c = 0u; c < 3u; c++) {
                let node = imp[imp_topo[IMP_V_NODES] + face_word(slot.x, 4u + c)];
                let part = node.y / 3.0 * corner_area_gradient(g, slot.y);
                diagonal += node.x * part * part;
            }
        }
    }
    for (var s = topo[P.off_node_slot_offsets + i]; s < slots_end; s++) {
        let slot = edge_slot(s);
        if slot.x == NO_NODE {
            continue;
        }
        let part = 0.25 * edge_gradient_at(edge_bending(slot.x), slot.y);
        diagonal += (imp[imp_topo[IMP_V_NODES] + edge_word(slot.x, 4u)].x + imp[imp_topo[IMP_V_NODES] + edge_word(slot.x, 5u)].x) * part * part;
    }
    return diagonal + w.x * gv * gv + w.y * ga * ga;
}

// Particle i's volume-element slots (the forces' node → (element, corner)
// CSR, ascending element): element and corner of slot s.
fn tetra_slot(s: u32) -> vec2<u32> {
    let slot = topo[P.off_tetra_slots + s] - P.tetra_surf_base;
    return vec2<u32>(slot / 4u, slot % 4u);
}

// The projected block of a radial term along d (as src/backend/stiffness.rs):
// max(E″, 0)·ûûᵀ + max(E′/r, 0)·(I − ûûᵀ).
fn radial_block(kind: u32, p: array<f32, 8>, d: vec3<f32>) -> mat3x3<f32> {
    let r = length(d);
    if r == 0.0 {
        return mat3x3<f32>();
    }
    let u = d / r;
    let uu = outer3(u, u);
    let along = max(radial_curvature(kind, p, r), 0.0);
    let across = max(radial_law(kind, p, r).de_dr / r, 0.0);
    return uu * along + (identity3() - uu) * across;
}

// The block of every pair rule between particles i (of type ti) and j, each
// rule's clamped as the CPU's (0 beyond the type pair's reach).
fn pair_block(i: u32, j: u32, ti: u32) -> mat3x3<f32> {
    let pair = ti * P.n_types + topo[j];
    let d = separation(i, j);
    var h = mat3x3<f32>();
    if dot(d, d) >= fparams[P.off_skip2 + pair] {
        return h;
    }
    let rules_end = topo[P.off_pair_start + pair + 1u];
    for (var q = topo[P.off_pair_start + pair]; q < rules_end; q++) {
        let term = topo[P.off_pair_terms + q];
        h += radial_block(topo[P.off_term_kind + term], term_params(term), d);
    }
    return h;
}

// Particle i's pair rows applied to the vector in `section` (with v_i = vi):
// Σ_j h_ij·(v_i − v_j) over its neighbour-list row and, weighted, its
// fractional `special_bonds` partners; with `diagonal_only`, Σ_j diag(h_ij)
// (the Jacobi diagonal's share). A pair's block is computed again at each
// product from the positions (both ends get the same bits: the separation
// is an exact fixed-point difference rounded once, the block even in it).
fn pair_rows(i: u32, section: u32, vi: vec3<f32>, diagonal_only: bool) -> vec3<f32> {
    var out = vec3<f32>(0.0);
    let pair_rules = topo[P.off_pair_start + P.n_types * P.n_types];
    if pair_rules == 0u {
        return out;
    }
    let ti = topo[i];
    let row = nlist_row(i);
    let count = min(nlist[row], P.nlist_cap);
    for (var k = 0u; k < count; k++) {
        let j = nlist[row + 1u + k];
        if j >= CONTACT_ONLY { continue; } // an excluded pair kept for the contact search
        let h = pair_block(i, j, ti);
        out += select(h * (vi - imp_vec(section, j)), vec3<f32>(h[0].x, h[1].y, h[2].z), diagonal_only);
    }
    let end = topo[P.off_special_offsets + i + 1u];
    for (var s = topo[P.off_special_offsets + i]; s < end; s++) {
        let w = bitcast<f32>(topo[P.off_special + 2u * s + 1u]);
        let h = pair_block(i, topo[P.off_special + 2u * s], ti) * w;
        out += select(h * (vi - imp_vec(section, topo[P.off_special + 2u * s])), vec3<f32>(h[0].x, h[1].y, h[2].z), diagonal_only);
    }
    return out;
}

@compute @workgroup_size(256)
fn implicit_blocks(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() {
        return;
    }
    let drag = imp_drag(i);
    let dinv = P.n * VEC_DINV + i;
    if drag == 0.0 {
        imp[dinv] = vec4<f32>(1.0, 1.0, 1.0, 0.0); // a fixed particle: the identity row
        return;
    }
    var diagonal = vec3<f32>(drag);
    let bonds_end = topo[P.off_bond_offsets + i + 1u];
    for (var b = topo[P.off_bond_offsets + i]; b < bonds_end; b++) {
        let term = topo[P.off_bond_ends + 2u * b + 1u];
        let scale = fparams[P.off_term_scale + term] * bond_on(term);
        let h = radial_block(topo[P.off_term_kind + term], term_params(term), separation(i, topo[P.off_bond_ends + 2u * b])) * scale;
        let at = imp_topo[IMP_V_BONDS] + 2u * b;
        put_sym(at, h);
        diagonal += sym_diagonal(at);
    }
    let externals_end = topo[P.off_ext_offsets + i + 1u];
    if externals_end > topo[P.off_ext_offsets + i] {
        let x = unwrapped(i);
        for (var t = topo[P.off_ext_offsets + i]; t < externals_end; t++) {
            let term = topo[P.off_ext_terms + t];
            let at = imp_topo[IMP_V_EXTERNALS] + 2u * t;
            put_sym(at, one_body_hessian(topo[P.off_term_kind + term], term_params(term), x));
            diagonal += sym_diagonal(at);
        }
    }
    let slots_end = imp_topo[imp_topo[IMP_OFF_SLOT_START] + i + 1u];
    for (var s = imp_topo[imp_topo[IMP_OFF_SLOT_START] + i]; s < slots_end; s++) {
        let a = imp_topo[imp_topo[IMP_OFF_SLOTS] + 2u * s];
        let role = imp_topo[imp_topo[IMP_OFF_SLOTS] + 2u * s + 1u];
        for (var m = 0u; m < 3u; m++) {
            diagonal[m] += angle_entry(a, (3u * role + m) * 10u);
        }
    }
    let tetras_end = topo[P.off_tetra_slot_offsets + i + 1u];
    for (var s = topo[P.off_tetra_slot_offsets + i]; s < tetras_end; s++) {
        let slot = tetra_slot(s);
        for (var m = 0u; m < 3u; m++) {
            diagonal[m] += tetra_entry(slot.x, (3u * slot.y + m) * (PSD_STRIDE + 1u));
        }
    }
    diagonal += surface_diagonal(i);
    diagonal += pair_rows(i, VEC_X, vec3<f32>(0.0), true);
    if CONTACT_TERMS {
        diagonal += contact_rows(i, VEC_X, true);
    }
    // A held coordinate (`freeze`, `move`): the identity row.
    imp[dinv] = vec4<f32>(select(vec3<f32>(1.0), 1.0 / diagonal, free_axes(i) != vec3<f32>(0.0)), 0.0);
}

fn imp_vec(section: u32, i: u32) -> vec3<f32> {
    return imp[P.n * section + i].xyz;
}

// (A·v)_i for the vector in `section`: γ/dt·v_i plus particle i's rows of its
// bond ends, externals, angles, volume elements, faces and bodies, pairs and
// contacts between bodies, in that order (`body_dots` of the section first; a fixed particle, and a
// held coordinate of `freeze` or `move`: v_i). Their entries of every vector
// the solve forms are 0, so their couplings drop out as in the CPU's matrix.
fn apply_row(i: u32, section: u32) -> vec3<f32> {
    let vi = imp_vec(section, i);
    let drag = imp_drag(i);
    if drag == 0.0 {
        return vi;
    }
    var out = drag * vi;
    let bonds_end = topo[P.off_bond_offsets + i + 1u];
    for (var b = topo[P.off_bond_offsets + i]; b < bonds_end; b++) {
        let other = topo[P.off_bond_ends + 2u * b];
        out += sym_times(imp_topo[IMP_V_BONDS] + 2u * b, vi - imp_vec(section, other));
    }
    let externals_end = topo[P.off_ext_offsets + i + 1u];
    for (var t = topo[P.off_ext_offsets + i]; t < externals_end; t++) {
        out += sym_times(imp_topo[IMP_V_EXTERNALS] + 2u * t, vi);
    }
    let slots_end = imp_topo[imp_topo[IMP_OFF_SLOT_START] + i + 1u];
    for (var s = imp_topo[imp_topo[IMP_OFF_SLOT_START] + i]; s < slots_end; s++) {
        let a = imp_topo[imp_topo[IMP_OFF_SLOTS] + 2u * s];
        let role = imp_topo[imp_topo[IMP_OFF_SLOTS] + 2u * s + 1u];
        let rec = imp_topo[IMP_OFF_ANGLES] + 4u * a;
        for (var c = 0u; c < 3u; c++) {
            let vc = imp_vec(section, imp_topo[rec + c]);
            for (var m = 0u; m < 3u; m++) {
                let row = (3u * role + m) * 9u + 3u * c;
                out[m] += angle_entry(a, row) * vc.x + angle_entry(a, row + 1u) * vc.y + angle_entry(a, row + 2u) * vc.z;
            }
        }
    }
    let tetras_end = topo[P.off_tetra_slot_offsets + i + 1u];
    for (var s = topo[P.off_tetra_slot_offsets + i]; s < tetras_end; s++) {
        let slot = tetra_slot(s);
        let rec = P.off_tetras + TETRA_WORDS * slot.x;
        for (var c = 0u; c < 4u; c++) {
            let vc = imp_vec(section, topo[rec + c]);
            for (var m = 0u; m < 3u; m++) {
                let row = (3u * slot.y + m) * PSD_STRIDE + 3u * c;
                out[m] += tetra_entry(slot.x, row) * vc.x + tetra_entry(slot.x, row + 1u) * vc.y + tetra_entry(slot.x, row + 2u) * vc.z;
            }
        }
    }
    if BODY_TERMS {
        out += surface_rows(i, section);
    }
    out += pair_rows(i, section, vi, false);
    if CONTACT_TERMS {
        out += contact_rows(i, section, false);
    }
    return select(vi, out, free_axes(i) != vec3<f32>(0.0));
}

var<workgroup> partial_sums: array<vec3<f32>, 256>;
var<workgroup> workgroup_total: vec3<f32>;
var<workgroup> workgroup_flag: u32;
// The iteration cap and the tolerance's bits, loaded once as workgroup-uniform values.
var<workgroup> workgroup_limits: vec2<u32>;

// The sum of each invocation's `v` over the workgroup by a fixed pairwise
// tree (the same bits on every run), the same value in every invocation.
fn workgroup_sum(local: u32, v: vec3<f32>) -> vec3<f32> {
    partial_sums[local] = v;
    workgroupBarrier();
    for (var width = WORKGROUP / 2u; width > 0u; width = width >> 1u) {
        if local < width {
            partial_sums[local] = partial_sums[local] + partial_sums[local + width];
        }
        workgroupBarrier();
    }
    if local == 0u {
        workgroup_total = partial_sums[0];
    }
    return workgroupUniformLoad(&workgroup_total);
}

// q = A·v into VEC_Q for the vector v in `section`; returns vᵀAv (the same
// in every invocation). Each solve kernel calls it at ONE place in its loop,
// so the first product (A·x₀) and the last (the constrained step's
// residual) go through the same call: llvmpipe compiles every call site's
// inlined copy of `apply_row` at the first dispatch (hertz_octant's first
// run on a clean shader cache: 150 s with four call sites and the body-term
// gathers in every model, 38 s with one and `BODY_TERMS`).
fn multiply(local: u32, section: u32) -> f32 {
    storageBarrier();
    if BODY_TERMS {
        body_dots(local, section);
    }
    var vq = 0.0;
    for (var i = local; i < P.n; i += WORKGROUP) {
        let q = apply_row(i, section);
        imp[P.n * VEC_Q + i] = vec4<f32>(q, 0.0);
        vq += dot(imp_vec(section, i), q);
    }
    return workgroup_sum(local, vec3<f32>(vq, 0.0, 0.0)).x;
}

// The start of a solve kernel: loads the iteration cap and tolerance and
// stores the bodies' weights; false when the run has halted (every
// invocation sees the same flag), and the kernel returns at once.
fn begin_solve(local: u32) -> bool {
    if local == 0u {
        workgroup_flag = atomicLoad(&status[ST_HALTED]);
        workgroup_limits = vec2<u32>(imp_topo[IMP_MAX_ITER], imp_topo[IMP_TOLERANCE]);
    }
    if workgroupUniformLoad(&workgroup_flag) != 0u {
        return false;
    }
    if BODY_TERMS {
        store_body_weights(local);
    }
    return true;
}

// Particle i's right-hand side F + √(2kT·γ/dt)·ξ, 0 on its held coordinates
// (the CPU masks their forces; the protocols put them back after the step).
fn implicit_rhs(i: u32) -> vec3<f32> {
    if imp_drag(i) == 0.0 {
        return vec3<f32>(0.0);
    }
    let kick = bitcast<f32>(imp_topo[imp_topo[IMP_OFF_KICK] + topo[i]]);
    if kick == 0.0 {
        return free_axes(i) * force[i].xyz;
    }
    return free_axes(i) * (force[i].xyz + kick * unit_noise(i));
}

// The preconditioned CG's per-particle steps, shared by the one-workgroup
// solve (`implicit_solve`) and the split one (implicit_split.wgsl), so both
// do the same arithmetic. Each returns particle i's share of the sums that
// follow it.

// The first residual: b (in VEC_R) − A·x₀ (in VEC_Q) into VEC_R, z = D⁻¹r
// into VEC_Z and the first direction p = z into VEC_P; returns
// (r·z, r·r, b·b).
fn first_residual(i: u32) -> vec3<f32> {
    let n = P.n;
    let b = imp_vec(VEC_R, i);
    let r = b - imp_vec(VEC_Q, i);
    let z = imp[n * VEC_DINV + i].xyz * r;
    imp[n * VEC_R + i] = vec4<f32>(r, 0.0);
    imp[n * VEC_Z + i] = vec4<f32>(z, 0.0);
    imp[n * VEC_P + i] = vec4<f32>(z, 0.0);
    return vec3<f32>(dot(r, z), dot(r, r), dot(b, b));
}

// One iteration's update x += αp, r −= αq (q = A·p in VEC_Q), z = D⁻¹r;
// returns (r·z, r·r, 0) of the new residual.
fn cg_update(i: u32, alpha: f32) -> vec3<f32> {
    let n = P.n;
    let x = imp_vec(VEC_X, i) + alpha * imp_vec(VEC_P, i);
    let r = imp_vec(VEC_R, i) - alpha * imp_vec(VEC_Q, i);
    let z = imp[n * VEC_DINV + i].xyz * r;
    imp[n * VEC_X + i] = vec4<f32>(x, 0.0);
    imp[n * VEC_R + i] = vec4<f32>(r, 0.0);
    imp[n * VEC_Z + i] = vec4<f32>(z, 0.0);
    return vec3<f32>(dot(r, z), dot(r, r), 0.0);
}

// The next direction p = z + βp.
fn cg_direction(i: u32, beta: f32) {
    imp[P.n * VEC_P + i] = vec4<f32>(imp_vec(VEC_Z, i) + beta * imp_vec(VEC_P, i), 0.0);
}

@compute @workgroup_size(256)
fn implicit_solve(@builtin(local_invocation_index) local: u32) {
    if !begin_solve(local) {
        return;
    }
    let n = P.n;
    // The Jacobi step as the first guess, Δx = D⁻¹b, as on the CPU (0 where b is:
    // fixed particles and held coordinates).
    for (var i = local; i < n; i += WORKGROUP) {
        let b = implicit_rhs(i);
        imp[n * VEC_R + i] = vec4<f32>(b, 0.0);
        imp[n * VEC_X + i] = vec4<f32>(imp[n * VEC_DINV + i].xyz * b, 0.0);
    }
    let limits = workgroupUniformLoad(&workgroup_limits);
    let cap = limits.x;
    var threshold = 0.0;
    var b_norm = 0.0;
    var rz = 0.0;
    var residual = 0.0;
    var iterations = 0u;
    // The first pass multiplies x₀ (the residual b − Ax₀), the others p.
    var section = VEC_X;
    loop {
        let curvature = multiply(local, section);
        if section == VEC_X {
            var sums = vec3<f32>(0.0);
            for (var i = local; i < n; i += WORKGROUP) {
                sums += first_residual(i);
            }
            let start = workgroup_sum(local, sums);
            rz = start.x;
            residual = sqrt(start.y);
            b_norm = sqrt(start.z);
            threshold = bitcast<f32>(limits.y) * b_norm;
            section = VEC_P;
        } else {
            if !(curvature > 0.0) {
                break;
            }
            let alpha = rz / curvature;
            var next = vec3<f32>(0.0);
            for (var i = local; i < n; i += WORKGROUP) {
                next += cg_update(i, alpha);
            }
            let after = workgroup_sum(local, next);
            let beta = after.x / rz;
            rz = after.x;
            residual = sqrt(after.y);
            for (var i = local; i < n; i += WORKGROUP) {
                cg_direction(i, beta);
            }
            iterations += 1u;
        }
        if b_norm == 0.0 || residual < threshold || iterations >= cap {
            break;
        }
    }
    clamp_step(local);
    if local == 0u {
        let relative = select(residual / b_norm, 0.0, b_norm == 0.0);
        imp[imp_topo[IMP_V_REPORT]] = vec4<f32>(bitcast<f32>(iterations), relative, 0.0, 0.0);
        if !(b_norm == 0.0 || residual < threshold) {
            atomicOr(&status[ST_HALTED], HALT_SOLVE);
        }
    }
}

@compute @workgroup_size(256)
fn implicit_move(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() {
        return;
    }
    // s < 1 only where the contact step clamp shortened the step (`clamp_step`).
    let s = bitcast<f32>(atomicLoad(&status[ST_FRACTION]));
    step_particle(i, s * imp_vec(VEC_X, i));
}
