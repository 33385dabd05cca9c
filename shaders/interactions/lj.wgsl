// lj: E = 4ε[(σ/r)¹² − (σ/r)⁶] for r < rc (not shifted); p = [ε, σ, rc].
fn lennard_jones(epsilon: f32, sigma: f32, r: f32) -> Radial {
    let s2 = sigma * sigma / (r * r);
    let s6 = s2 * s2 * s2;
    let s12 = s6 * s6;
    return Radial(4.0 * epsilon * (s12 - s6), 4.0 * epsilon * (6.0 * s6 - 12.0 * s12) / r);
}

fn lj_radial(p: array<f32, 8>, r: f32) -> Radial {
    if r < p[LJ_RC] {
        return lennard_jones(p[LJ_EPSILON], p[LJ_SIGMA], r);
    }
    return RADIAL_ZERO;
}
