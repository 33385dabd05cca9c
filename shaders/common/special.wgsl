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
        let w = bitcast<f32>(topo[P.off_special + 2u * s + 1u]);
        let rules = pair_rules_at(i, topo[P.off_special + 2u * s], ti);
        f += w * rules.xyz;
        e += 0.5 * w * rules.w;
    }
    return vec4<f32>(f, e);
}
