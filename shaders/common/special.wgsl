// Pair terms between bonded neighbours with a fractional `special_bonds`
// weight (src/gpu/special.rs): particle i's own list of such partners
// (left out of the neighbour list), each with its weight w; every pair rule
// of the two types scaled by w, half of the energy on each side. Returns the
// force on i (xyz) and its energy share (w).
fn special_pair_forces(i: u32, ti: u32) -> vec4<f32> {
    var f = vec3<f32>(0.0);
    var e = 0.0;
    let end = topo[P.off_special_offsets + i + 1u];
    for (var s = topo[P.off_special_offsets + i]; s < end; s++) {
        let j = topo[P.off_special + 2u * s];
        let w = bitcast<f32>(topo[P.off_special + 2u * s + 1u]);
        let pair = ti * P.n_types + topo[j];
        let d = separation(i, j);
        let r2 = dot(d, d);
        if r2 >= fparams[P.off_skip2 + pair] {
            continue;
        }
        let r = sqrt(r2);
        let rules_end = topo[P.off_pair_start + pair + 1u];
        for (var q = topo[P.off_pair_start + pair]; q < rules_end; q++) {
            let term = topo[P.off_pair_terms + q];
            let radial = radial_law(topo[P.off_term_kind + term], term_params(term), r);
            f += w * force_along(radial, d, r);
            e += 0.5 * w * radial.energy;
        }
    }
    return vec4<f32>(f, e);
}
