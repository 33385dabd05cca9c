// Surface (body) terms, in passes before `forces` gathers each particle's
// slots (the passes and the regions of `surf`: src/gpu/surface.rs). No float
// atomics: the same run gives the same bits.
//
// `surface_law` and `node_law` dispatch on the registry index of the term's
// interaction type to `NAME_face` and `NAME_node`
// (shaders/interactions/NAME.wgsl); they are generated from the registry
// when the shader is composed.

var<workgroup> partial: array<vec2<f32>, 256>;

// FACE_WORDS and EDGE_WORDS (the words of a face record and of an edge record
// in `topo`) and NO_NODE are the prelude's (src/gpu/prelude.rs).

// Word k of face f: corners 0–2 (particles), 3 its body, 4–6 the corners' body nodes.
fn face_word(f: u32, k: u32) -> u32 {
    return topo[P.off_faces + FACE_WORDS * f + k];
}

// Word k of edge e: ends 0–1 and wings 2–3 (particles), 4–5 the ends' body nodes, 6 its body.
fn edge_word(e: u32, k: u32) -> u32 {
    return topo[P.off_edges + EDGE_WORDS * e + k];
}

// Where each value lives in `surf`.
fn surf_body(b: u32) -> u32 {
    return P.n_faces + b;
}

fn surf_corner(slot: u32) -> u32 {
    return P.n_faces + P.n_bodies + slot;
}

fn surf_edge(e: u32) -> u32 {
    return 4u * P.n_faces + P.n_bodies + e;
}

fn surf_edge_slot(slot: u32) -> u32 {
    return 4u * P.n_faces + P.n_bodies + P.n_edges + slot;
}

fn surf_node(k: u32) -> u32 {
    return 4u * P.n_faces + P.n_bodies + 5u * P.n_edges + k;
}

fn surf_node_energy(k: u32) -> u32 {
    return 4u * P.n_faces + P.n_bodies + 5u * P.n_edges + P.n_body_nodes + k;
}

// Face f's geometry (`triangle_geometry` of its corners).
fn face_geometry(f: u32) -> FaceGeometry {
    return triangle_geometry(face_word(f, 0u), face_word(f, 1u), face_word(f, 2u));
}

// The geometry of triangle (a, b, c) (particles) from its edge vectors
// (each an exact fixed-point minimum-image difference rounded once to f32).
fn triangle_geometry(a: u32, b: u32, c: u32) -> FaceGeometry {
    let x1 = separation(a, b);
    let x2 = separation(a, c);
    let n = cross(x1, x2);
    let twice = length(n);
    let unit = n / twice;
    return FaceGeometry(x1, x2, 0.5 * twice, 0.5 * cross(x1 - x2, unit), 0.5 * cross(x2, unit), -0.5 * cross(x1, unit), n / 6.0);
}

// Pass 1: surf[f] = (A_t, x_a·(x_b × x_c)) with the corners at their minimum
// images from the body's anchor (the first corner of its first face). A
// corner whose image from the anchor disagrees with its image along the
// face's edges (by more than a quarter box: the body spans over half the
// periodic box) halts the run.
@compute @workgroup_size(256)
fn surface_faces(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let f = linear_index(wg, local);
    if f >= P.n_faces || halted_other_than(HALT_SPAN) {
        return;
    }
    let b = face_word(f, 3u);
    let anchor = face_word(topo[P.off_body_faces + b], 0u);
    let g = face_geometry(f);
    let xa = separation(anchor, face_word(f, 0u));
    let xb = separation(anchor, face_word(f, 1u));
    let xc = separation(anchor, face_word(f, 2u));
    let off = max(abs(xb - xa - g.x1), abs(xc - xa - g.x2));
    if any(off > 0.25 * P.box_len.xyz) {
        atomicOr(&status[ST_HALTED], HALT_SPAN);
        atomicMin(&status[ST_SPAN_BODY], b);
    }
    surf[f] = vec4<f32>(g.area, dot(xa, cross(xb, xc)), 0.0, 0.0);
}

// Pass 2, one workgroup per body: thread t sums faces t, t + 256, … in
// order, then the partial sums are added pairwise (a fixed tree).
// surf[surf_body(b)] = (V, A).
@compute @workgroup_size(256)
fn surface_bodies(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let b = wg.y * P.groups_x + wg.x;
    var sum = vec2<f32>(0.0);
    if b < P.n_bodies {
        let end = topo[P.off_body_faces + b + 1u];
        for (var f = topo[P.off_body_faces + b] + local; f < end; f += WORKGROUP) {
            sum += surf[f].xy;
        }
    }
    partial[local] = sum;
    workgroupBarrier();
    for (var stride = WORKGROUP / 2u; stride > 0u; stride /= 2u) {
        if local < stride {
            partial[local] += partial[local + stride];
        }
        workgroupBarrier();
    }
    if local == 0u && b < P.n_bodies {
        surf[surf_body(b)] = vec4<f32>(partial[0].y / 6.0, partial[0].x, 0.0, 0.0);
    }
}

// Bending angle θ of an edge (i, j) with wings a (face (i, j, a)) and b
// (face (j, i, b)), positive where convex, and ∂(ℓθ) at i, j, a, b; the
// positions are relative to x_i (mesh.rs, `bending_angle`).
struct EdgeBending {
    l_theta: f32,
    gi: vec3<f32>,
    gj: vec3<f32>,
    ga: vec3<f32>,
    gb: vec3<f32>,
}

fn edge_bending(e: u32) -> EdgeBending {
    let i = edge_word(e, 0u);
    let xj = separation(i, edge_word(e, 1u));
    let xa = separation(i, edge_word(e, 2u));
    let xb = separation(i, edge_word(e, 3u));
    let na = cross(xj, xa);
    let nb = cross(-xj, xb - xj);
    let len2 = dot(xj, xj);
    let len = sqrt(len2);
    let unit = xj / len;
    let theta = atan2(dot(cross(na, nb), unit), dot(na, nb));
    let ga = -len * na / dot(na, na);
    let gb = -len * nb / dot(nb, nb);
    let sa = dot(xa, xj) / len2;
    let sb = dot(xb, xj) / len2;
    let gi = -(1.0 - sa) * ga - (1.0 - sb) * gb;
    let gj = -sa * ga - sb * gb;
    // d(ℓθ) = θ·dℓ + ℓ·dθ.
    return EdgeBending(len * theta, -theta * unit + len * gi, theta * unit + len * gj, len * ga, len * gb);
}

// Pass 3a (curvature laws): surf[surf_edge(e)].x = ℓθ.
@compute @workgroup_size(256)
fn surface_edges(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let e = linear_index(wg, local);
    if e >= P.n_edges || halted() {
        return;
    }
    surf[surf_edge(e)] = vec4<f32>(edge_bending(e).l_theta, 0.0, 0.0, 0.0);
}

// Body node k's M = ¼Σ ℓθ over its edges and A = ⅓Σ A_t over its faces
// (mesh order), from passes 1 and 3a's values.
fn node_curvature_sums(k: u32) -> vec2<f32> {
    var m = 0.0;
    let edges_end = topo[P.off_node_edge_offsets + k + 1u];
    for (var q = topo[P.off_node_edge_offsets + k]; q < edges_end; q++) {
        m += surf[surf_edge(topo[P.off_node_edges + q])].x;
    }
    var a = 0.0;
    let faces_end = topo[P.off_node_face_offsets + k + 1u];
    for (var q = topo[P.off_node_face_offsets + k]; q < faces_end; q++) {
        a += surf[topo[P.off_node_faces + q]].x;
    }
    return vec2<f32>(0.25 * m, a / 3.0);
}

// Pass 3b: body node k's M and A (`node_curvature_sums`), and its body's
// curvature terms at (M, A):
// surf[surf_node(k)] = (∂E/∂M, ∂E/∂A), surf[surf_node_energy(k)].w = E.
@compute @workgroup_size(256)
fn surface_nodes(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let k = linear_index(wg, local);
    if k >= P.n_body_nodes || halted() {
        return;
    }
    let sums = node_curvature_sums(k);
    let m = sums.x;
    let a = sums.y;
    let b = topo[P.off_node_body + k];
    var out = NodeCurvature(0.0, 0.0, 0.0);
    let terms_end = topo[P.off_body_term_start + b + 1u];
    for (var t = topo[P.off_body_term_start + b]; t < terms_end; t++) {
        let term = topo[P.off_body_terms + t];
        let c = node_law(topo[P.off_term_kind + term], term_params(term), m, a);
        out.energy += c.energy;
        out.de_dm += c.de_dm;
        out.de_da += c.de_da;
    }
    surf[surf_node(k)] = vec4<f32>(out.de_dm, out.de_da, 0.0, 0.0);
    surf[surf_node_energy(k)] = vec4<f32>(0.0, 0.0, 0.0, out.energy);
}

// Pass 3c: −¼(∂E/∂M_i + ∂E/∂M_j)·∂(ℓθ) on the edge's ends and wings.
@compute @workgroup_size(256)
fn surface_edge_forces(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let e = linear_index(wg, local);
    if e >= P.n_edges || halted() {
        return;
    }
    let coef = -0.25 * (surf[surf_node(edge_word(e, 4u))].x + surf[surf_node(edge_word(e, 5u))].x);
    let g = edge_bending(e);
    surf[surf_edge_slot(4u * e)] = vec4<f32>(coef * g.gi, 0.0);
    surf[surf_edge_slot(4u * e + 1u)] = vec4<f32>(coef * g.gj, 0.0);
    surf[surf_edge_slot(4u * e + 2u)] = vec4<f32>(coef * g.ga, 0.0);
    surf[surf_edge_slot(4u * e + 3u)] = vec4<f32>(coef * g.gb, 0.0);
}

// Pass 4: the body's per-face terms, in force-field order, on face f, and
// the curvature terms' area part −⅓Σ_corners ∂E/∂A_k·∇A_t; the sum goes to
// the face's corner slots with a third of the face's energy share each.
@compute @workgroup_size(256)
fn surface_forces(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let f = linear_index(wg, local);
    if f >= P.n_faces || halted() {
        return;
    }
    let b = face_word(f, 3u);
    let g = face_geometry(f);
    let totals = surf[surf_body(b)];
    let body = BodyTotals(totals.x, totals.y, f32(topo[P.off_body_faces + b + 1u] - topo[P.off_body_faces + b]));
    var out = SurfaceFace(0.0, vec3<f32>(0.0), vec3<f32>(0.0), vec3<f32>(0.0));
    let terms_end = topo[P.off_body_term_start + b + 1u];
    for (var k = topo[P.off_body_term_start + b]; k < terms_end; k++) {
        let term = topo[P.off_body_terms + k];
        let s = surface_law(topo[P.off_term_kind + term], term_params(term), body, g);
        out.energy += s.energy;
        out.f0 += s.f0;
        out.f1 += s.f1;
        out.f2 += s.f2;
    }
    if face_word(f, 4u) != NO_NODE {
        let coef = -(surf[surf_node(face_word(f, 4u))].y + surf[surf_node(face_word(f, 5u))].y + surf[surf_node(face_word(f, 6u))].y) / 3.0;
        out.f0 += coef * g.ga0;
        out.f1 += coef * g.ga1;
        out.f2 += coef * g.ga2;
    }
    let e = out.energy / 3.0;
    surf[surf_corner(3u * f)] = vec4<f32>(out.f0, e);
    surf[surf_corner(3u * f + 1u)] = vec4<f32>(out.f1, e);
    surf[surf_corner(3u * f + 2u)] = vec4<f32>(out.f2, e);
}

// The cross-product matrix [v]ₓ: [v]ₓ·u = v × u.
fn cross_matrix(v: vec3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>(vec3<f32>(0.0, v.z, -v.y), vec3<f32>(-v.z, 0.0, v.x), vec3<f32>(v.y, -v.x, 0.0));
}

// The Hessian ∂²A/∂x_k∂x_l of a face's area, block 3k + l (the CPU's
// `triangle_area_hessian`, src/mesh.rs): −[e_k]ₓ(I − n̂n̂ᵀ)[e_l]ₓ/(2|n|)
// with e = (x_b − x_c, x_c − x_a, x_a − x_b), plus ∓½[n̂]ₓ off the diagonal.
fn triangle_area_hessian(g: FaceGeometry) -> array<mat3x3<f32>, 9> {
    let n = cross(g.x1, g.x2);
    let twice = length(n);
    let unit = n / twice;
    let projector = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0))
        - mat3x3<f32>(unit * unit.x, unit * unit.y, unit * unit.z);
    var edges = array<mat3x3<f32>, 3>(cross_matrix(g.x1 - g.x2), cross_matrix(g.x2), cross_matrix(-g.x1));
    let turn = cross_matrix(unit);
    var out: array<mat3x3<f32>, 9>;
    for (var k = 0u; k < 3u; k++) {
        for (var l = 0u; l < 3u; l++) {
            var second = mat3x3<f32>();
            let offset = (l + 3u - k) % 3u;
            if offset == 1u {
                second = turn * -0.5;
            } else if offset == 2u {
                second = turn * 0.5;
            }
            out[3u * k + l] = edges[k] * projector * edges[l] * (-1.0 / (2.0 * twice)) + second;
        }
    }
    return out;
}

// The 9×9 Hessian (row-major, corner-major) c·∇A_t∇A_tᵀ + τ·∇²A_t of a face
// energy e(A_t) with e′ = `tension` and e″ = `curvature` (the CPU's
// `SurfaceHessian::push_face`, src/hessian.rs).
fn face_area_stencil(g: FaceGeometry, tension: f32, curvature: f32) -> array<f32, 81> {
    var ga = array<vec3<f32>, 3>(g.ga0, g.ga1, g.ga2);
    var second = triangle_area_hessian(g);
    var h: array<f32, 81>;
    for (var k = 0u; k < 3u; k++) {
        for (var l = 0u; l < 3u; l++) {
            let block = second[3u * k + l];
            for (var i = 0u; i < 3u; i++) {
                for (var j = 0u; j < 3u; j++) {
                    h[(3u * k + i) * 9u + 3u * l + j] = curvature * ga[k][i] * ga[l][j] + tension * block[j][i];
                }
            }
        }
    }
    return h;
}
