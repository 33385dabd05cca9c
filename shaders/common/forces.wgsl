// Force on each particle as the sum of its own terms (no float atomics, no
// write conflicts; the order is fixed by the data, so a run repeats bit for
// bit): pairs from the neighbour list, its bonds from its own side, its
// angle slots, the external fields acting on it, and its slots of the
// surface terms (shaders/common/surface.wgsl) and of its volume elements
// (shaders/common/tetra.wgsl). `force[i].w` is the particle's share of the
// potential energy (half of each pair and bond, a third of each angle, all
// of its externals, its surface and element slots' shares).
//
// `radial_law`, `three_body_law` and `one_body_law` dispatch on the
// registry index of the term's interaction type; they are generated from the
// registry when the shader is composed.

// Every pair rule between particles i (of type ti) and j: the force on i
// (xyz) and the pair's energy (w); zero beyond the type pair's reach.
fn pair_rules_at(i: u32, j: u32, ti: u32) -> vec4<f32> {
    let pair = ti * P.n_types + topo[j];
    let d = separation(i, j);
    let r2 = dot(d, d);
    var f = vec3<f32>(0.0);
    var e = 0.0;
    if r2 >= fparams[P.off_skip2 + pair] {
        return vec4<f32>(f, e);
    }
    let r = sqrt(r2);
    let rules_end = topo[P.off_pair_start + pair + 1u];
    for (var q = topo[P.off_pair_start + pair]; q < rules_end; q++) {
        let term = topo[P.off_pair_terms + q];
        let radial = radial_law(topo[P.off_term_kind + term], term_params(term), r);
        f += force_along(radial, d, r);
        e += radial.energy;
    }
    return vec4<f32>(f, e);
}

@compute @workgroup_size(256)
fn forces(@builtin(workgroup_id) wg: vec3<u32>, @builtin(local_invocation_index) local: u32) {
    let i = chunk_particle(wg, local);
    if !in_chunk(i) || halted() {
        return;
    }
    let ti = topo[i];
    var f = vec3<f32>(0.0);
    var e = 0.0;

    // Pairs.
    let row = nlist_row(i);
    // No pair rules (a list kept for the contact search only): no pair loop.
    let pair_rules = topo[P.off_pair_start + P.n_types * P.n_types];
    let count = select(0u, min(nlist[row], P.nlist_cap), pair_rules > 0u);
    for (var k = 0u; k < count; k++) {
        let j = nlist[row + 1u + k];
        if j >= CONTACT_ONLY { continue; } // an excluded pair kept for the contact search
        let rules = pair_rules_at(i, j, ti);
        f += rules.xyz;
        e += 0.5 * rules.w;
    }

    // Bonded neighbours of fractional `special_bonds` weight (shaders/common/special.wgsl).
    let special = special_pair_forces(i, ti);
    f += special.xyz;
    e += special.w;

    // Bonds, from this particle's side.
    let bonds_end = topo[P.off_bond_offsets + i + 1u];
    for (var b = topo[P.off_bond_offsets + i]; b < bonds_end; b++) {
        let other = topo[P.off_bond_ends + 2u * b];
        let term = topo[P.off_bond_ends + 2u * b + 1u];
        let d = separation(i, other);
        let r = length(d);
        let radial = radial_law(topo[P.off_term_kind + term], term_params(term), r);
        // A kinetic bond's maturation scale (1 for every other bond).
        let scale = fparams[P.off_term_scale + term] * bond_on(term); // 0 for an unbound bond with device kinetics
        f += scale * force_along(radial, d, r);
        e += 0.5 * scale * radial.energy;
    }
    // Bonds formed on the device since the backend was built (bind.wgsl).
    let formed = formed_bond_forces(i);
    f += formed.xyz;
    e += formed.w;

    // Angles: evaluated around the vertex j with i and k at their minimum images.
    let angles_end = topo[P.off_angle_offsets + i + 1u];
    for (var a = topo[P.off_angle_offsets + i]; a < angles_end; a++) {
        let slot = P.off_angle_slots + 5u * a;
        let pi = topo[slot];
        let pj = topo[slot + 1u];
        let pk = topo[slot + 2u];
        let term = topo[slot + 3u];
        let role = topo[slot + 4u];
        let three = three_body_law(topo[P.off_term_kind + term], term_params(term), separation(pj, pi), vec3<f32>(0.0), separation(pj, pk));
        if role == 0u {
            f += three.fi;
        } else if role == 1u {
            f += three.fj;
        } else {
            f += three.fk;
        }
        e += three.energy / 3.0;
    }

    // External fields, on the unwrapped position.
    let externals_end = topo[P.off_ext_offsets + i + 1u];
    if externals_end > topo[P.off_ext_offsets + i] {
        let x = unwrapped(i);
        for (var t = topo[P.off_ext_offsets + i]; t < externals_end; t++) {
            let term = topo[P.off_ext_terms + t];
            let one = one_body_law(topo[P.off_term_kind + term], term_params(term), x);
            f += one.force;
            e += one.energy;
        }
    }
    // Surface terms: this particle's slots (face corners, edge stencils, node energies) in a fixed order.
    let slots_end = topo[P.off_node_slot_offsets + i + 1u];
    for (var s = topo[P.off_node_slot_offsets + i]; s < slots_end; s++) {
        let slot = surf[topo[P.off_node_slots + s]];
        f += slot.xyz;
        e += slot.w;
    }
    // Volume elements: this particle's corner slots (shaders/common/tetra.wgsl), ascending element.
    let tetra_end = topo[P.off_tetra_slot_offsets + i + 1u];
    for (var s = topo[P.off_tetra_slot_offsets + i]; s < tetra_end; s++) {
        let slot = surf[topo[P.off_tetra_slots + s]];
        f += slot.xyz;
        e += slot.w;
    }
    force[i] = vec4<f32>(f, e);
}
