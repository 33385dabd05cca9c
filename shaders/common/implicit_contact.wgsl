// Contact between bodies in the implicit step (the equations, the order and
// the determinism argument: src/gpu/implicit.rs, "Contact between bodies").
// Every node–face pair in range adds the Gauss–Newton term c·g gᵀ,
// g = (n̂, −w_0·n̂, −w_1·n̂, −w_2·n̂) over (node, corners 0–2) at its closest
// point, c = max(Σ_rules b″(d), 0) for the node–face rules and
// c = max(ε·s″·B, 0) per area-weighted rule at the node's nearest face (as
// the CPU's `push_pair_blocks`). The terms are applied matrix-free: each
// product walks the pairs as the force pass does (`contact_forces`), from
// the node's row and from each corner's faces, and computes every pair's
// d, w and n̂ again relative to the face's first corner, so the four
// participants of a pair see the same bits and K̃ stays symmetric.

// max(Σ b″(d), 0) over the node–face rules of type pair `types`, in rule order.
fn contact_stiffness(types: u32, d: f32) -> f32 {
    var c = 0.0;
    let end = topo[P.off_crule_start + types + 1u];
    for (var q = topo[P.off_crule_start + types]; q < end; q++) {
        let rule = topo[P.off_crule_list + q];
        c += contact_curvature(topo[P.off_crules + CONTACT_RULE_WORDS * rule], contact_rule_params(rule), d);
    }
    return max(c, 0.0);
}

// The area-weighted rules' weights max(ε·s″·B, 0) at `node` whose nearest face is f.
fn adhesion_stiffness(node: u32, f: u32, types: u32) -> f32 {
    var c = 0.0;
    let end = topo[P.off_arule_start + types + 1u];
    for (var q = topo[P.off_arule_start + types]; q < end; q++) {
        let j = topo[P.off_arule_list + q];
        if surf[adhesion_switch(node, j)].z == f32(f) {
            c += max(surf[adhesion_pull(node, j)].y, 0.0);
        }
    }
    return c;
}

// The row of the participant with coefficient `g` (1 for the node, −w_k for
// corner k) of the pair (node, face) with weight c: c·g·(g_pair·v)·n̂, with
// g_pair·v = n̂·(v_node − Σ_k w_k·v_k) for the vector in `section`; with
// `diagonal_only`, its diagonal c·g²·n̂∘n̂.
fn contact_term(c: f32, g: f32, node: u32, face: u32, pair: ContactPair, section: u32, diagonal_only: bool) -> vec3<f32> {
    if c == 0.0 {
        return vec3<f32>(0.0);
    }
    if diagonal_only {
        return c * g * g * pair.n * pair.n;
    }
    let corners = pair.w.x * imp_vec(section, contact_face(face, 0u)) + pair.w.y * imp_vec(section, contact_face(face, 1u))
        + pair.w.z * imp_vec(section, contact_face(face, 2u));
    return c * g * dot(pair.n, imp_vec(section, node) - corners) * pair.n;
}

// Particle i's contact rows applied to the vector in `section` (or their
// diagonal): as a node, over its pairs (`next_node_pair`)
// and its area-weighted rules' nearest faces; as a corner, over its pairs
// (`next_corner_pair`) — the force pass's walks, in its order.
fn contact_rows(i: u32, section: u32, diagonal_only: bool) -> vec3<f32> {
    var out = vec3<f32>(0.0);
    let body = contact_body(i);
    if body == NO_BODY {
        return out;
    }
    var nodes = node_walk(i, body);
    while next_node_pair(&nodes) {
        let pair = contact_pair(i, nodes.face);
        out += contact_term(contact_stiffness(nodes.types, pair.d), 1.0, i, nodes.face, pair, section, diagonal_only);
    }
    for (var j = 0u; j < P.n_arules; j++) {
        let c = max(surf[adhesion_pull(i, j)].y, 0.0);
        if c > 0.0 {
            let face = u32(surf[adhesion_switch(i, j)].z);
            out += contact_term(c, 1.0, i, face, contact_pair(i, face), section, diagonal_only);
        }
    }
    var corners = corner_walk(i, body);
    while next_corner_pair(&corners) {
        let pair = contact_pair(corners.node, corners.face);
        var c = contact_stiffness(corners.types, pair.d);
        if P.n_arules > 0u {
            c += adhesion_stiffness(corners.node, corners.face, corners.types);
        }
        out += contact_term(c, -pair.w[corners.role], corners.node, corners.face, pair, section, diagonal_only);
    }
    return out;
}

var<workgroup> workgroup_fraction: atomic<u32>;

// The contact step clamp of the solved step (in the solve's one workgroup):
// s = min(1, min_i L_i/|Δx_i|) (`contact_move_fraction`, from the closest
// distances the contact pass kept), min-reduced through the bits of positive
// f32s (the order does not matter), into ST_FRACTION — replacing the explicit
// step's fraction the force pass left there. `implicit_move` moves by s·Δx,
// and `advance` records s for the clock.
fn clamp_step(local: u32) {
    if !CONTACT_TERMS {
        return;
    }
    if local == 0u {
        atomicStore(&workgroup_fraction, 0x3f800000u);
    }
    workgroupBarrier();
    for (var i = local; i < P.n; i += WORKGROUP) {
        let s = contact_move_fraction(i, imp_vec(VEC_X, i));
        if s < 1.0 {
            atomicMin(&workgroup_fraction, bitcast<u32>(s));
        }
    }
    workgroupBarrier();
    if local == 0u {
        atomicStore(&status[ST_FRACTION], atomicLoad(&workgroup_fraction));
    }
}
