// Area-weighted contact terms between bodies (contact_adhesion): the passes,
// the equations and the determinism argument are in src/gpu/adhesion.rs.
// `contact_area_switch` and `contact_area_density` dispatch on the registry
// index of the rule's interaction type to `NAME_switch` and `NAME_density`
// (shaders/interactions/NAME.wgsl).

// Where each value lives in `surf`: per rule slot j particle i's (s or, during the node pass, the nearest
// distance; s′; nearest face as an exact f32, −1 for none; s″) and its
// (pull b′ = ε·s′·B; the implicit step's Gauss–Newton weight ε·s″·B).
fn adhesion_switch(i: u32, j: u32) -> u32 {
    return P.off_aswitch + i * P.n_arules + j;
}

fn adhesion_pull(i: u32, j: u32) -> u32 {
    return P.off_apull + i * P.n_arules + j;
}

// The contact rule of slot j.
fn area_rule(j: u32) -> u32 {
    return topo[P.off_arules + j];
}

fn area_kind(j: u32) -> u32 {
    return topo[P.off_crules + CONTACT_RULE_WORDS * area_rule(j)];
}

// During the node pass: face f at distance d from node i, for the rules of
// type pair `types`; keeps the nearest (the lower face index on a tie).
fn adhesion_track(i: u32, types: u32, f: u32, d: f32) {
    let end = topo[P.off_arule_start + types + 1u];
    for (var q = topo[P.off_arule_start + types]; q < end; q++) {
        let slot = adhesion_switch(i, topo[P.off_arule_list + q]);
        let best = surf[slot];
        if d < best.x || (d == best.x && f32(f) < best.z) {
            surf[slot] = vec4<f32>(d, 0.0, f32(f), 0.0);
        }
    }
}

// Pass 1, per contact node: the node part of the contact pass, the nearest
// face per rule, and s, s′ there.
@compute @workgroup_size(256)
fn adhesion_nodes(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = chunk_particle(wg, local);
    if !in_chunk(i) || halted() {
        return;
    }
    let body = contact_body(i);
    if body == NO_BODY {
        return;
    }
    // Only faces closer than every range count (s = 0 beyond: no face).
    for (var j = 0u; j < P.n_arules; j++) {
        surf[adhesion_switch(i, j)] = vec4<f32>(P.contact_dhat, 0.0, -1.0, 0.0);
    }
    let part = contact_node_part(i, body, true);
    force[i] += vec4<f32>(part.f, part.e);
    surf[contact_closest(i)] = vec4<f32>(part.closest, 0.0, 0.0, 0.0);
    for (var j = 0u; j < P.n_arules; j++) {
        let best = surf[adhesion_switch(i, j)];
        if best.z >= 0.0 {
            let p = contact_rule_params(area_rule(j));
            let s = contact_area_switch(area_kind(j), p, best.x);
            surf[adhesion_switch(i, j)] = vec4<f32>(s.energy, s.de_dr, best.z, contact_area_switch_curvature(area_kind(j), p, best.x));
        } else {
            surf[adhesion_switch(i, j)] = vec4<f32>(0.0, 0.0, -1.0, 0.0);
        }
    }
}

// s of rule slot j at particle k (after the node pass).
fn adhesion_s(k: u32, j: u32) -> f32 {
    return surf[adhesion_switch(k, j)].x;
}

fn contact_face_geometry(f: u32) -> FaceGeometry {
    return triangle_geometry(contact_face(f, 0u), contact_face(f, 1u), contact_face(f, 2u));
}

// Pass 2, per particle: B_k = Σ_{t ∋ k} A_t·Π_{c ≠ k} s_c per rule (face
// order), the pull ε·s′_k·B_k and the weight ε·s″_k·B_k (0 where s′ = 0).
@compute @workgroup_size(256)
fn adhesion_weights(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = linear_index(wg, local);
    if i >= P.n || halted() || contact_body(i) == NO_BODY {
        return;
    }
    for (var j = 0u; j < P.n_arules; j++) {
        let found = surf[adhesion_switch(i, j)];
        var pull = vec2<f32>(0.0);
        if found.y != 0.0 {
            var sum = 0.0;
            let end = topo[P.off_corner_start + i + 1u];
            for (var q = topo[P.off_corner_start + i]; q < end; q++) {
                let slot = topo[P.off_corner_faces + q];
                let face = slot / 4u;
                let role = slot % 4u;
                let others = adhesion_s(contact_face(face, (role + 1u) % 3u), j) * adhesion_s(contact_face(face, (role + 2u) % 3u), j);
                sum += contact_face_geometry(face).area * others;
            }
            let density = contact_area_density(area_kind(j), contact_rule_params(area_rule(j)));
            pull = vec2<f32>(density * found.y * sum, density * found.w * sum);
        }
        surf[adhesion_pull(i, j)] = vec4<f32>(pull, 0.0, 0.0);
    }
}

// In the contact pass, particle i's own adhesion forces (xyz) and energy
// (w): the area part over its faces (face order; the energy on each face's
// first corner), then its pull towards its nearest face per rule.
fn adhesion_own(i: u32) -> vec4<f32> {
    var f = vec3<f32>(0.0);
    var e = 0.0;
    let end = topo[P.off_corner_start + i + 1u];
    for (var q = topo[P.off_corner_start + i]; q < end; q++) {
        let slot = topo[P.off_corner_faces + q];
        let face = slot / 4u;
        let role = slot % 4u;
        var weight = 0.0;
        for (var j = 0u; j < P.n_arules; j++) {
            let p = adhesion_s(contact_face(face, 0u), j) * adhesion_s(contact_face(face, 1u), j) * adhesion_s(contact_face(face, 2u), j);
            weight += contact_area_density(area_kind(j), contact_rule_params(area_rule(j))) * p;
        }
        if weight != 0.0 {
            let g = contact_face_geometry(face);
            var gradient = array<vec3<f32>, 3>(g.ga0, g.ga1, g.ga2);
            f -= weight * gradient[role];
            if role == 0u {
                e += weight * g.area;
            }
        }
    }
    for (var j = 0u; j < P.n_arules; j++) {
        let pull = surf[adhesion_pull(i, j)].x;
        if pull != 0.0 {
            f -= pull * contact_pair(i, u32(surf[adhesion_switch(i, j)].z)).n;
        }
    }
    return vec4<f32>(f, e);
}

// In the contact pass, corner `role` of face f against `node` (pair geometry
// `pair`, type pair `types`): b′·w_role·n̂ per rule whose nearest face of
// the node is f.
fn adhesion_corner(node: u32, f: u32, role: u32, types: u32, pair: ContactPair) -> vec3<f32> {
    var out = vec3<f32>(0.0);
    let end = topo[P.off_arule_start + types + 1u];
    for (var q = topo[P.off_arule_start + types]; q < end; q++) {
        let j = topo[P.off_arule_list + q];
        let pull = surf[adhesion_pull(node, j)].x;
        if pull != 0.0 && surf[adhesion_switch(node, j)].z == f32(f) {
            out += pull * pair.w[role] * pair.n;
        }
    }
    return out;
}
