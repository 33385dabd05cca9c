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

// E″(r) = 4ε(156(σ/r)¹² − 42(σ/r)⁶)/r² (shared with wca), for the stiffness
// block of the implicit step (shaders/common/implicit.wgsl).
fn lennard_jones_curvature(epsilon: f32, sigma: f32, r: f32) -> f32 {
    let s2 = sigma * sigma / (r * r);
    let s6 = s2 * s2 * s2;
    return 4.0 * epsilon * (156.0 * s6 * s6 - 42.0 * s6) / (r * r);
}

fn lj_curvature(p: array<f32, 8>, r: f32) -> f32 {
    if r < p[LJ_RC] {
        return lennard_jones_curvature(p[LJ_EPSILON], p[LJ_SIGMA], r);
    }
    return 0.0;
}
