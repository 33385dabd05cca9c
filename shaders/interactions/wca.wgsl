// wca: E = 4ε[(σ/r)¹² − (σ/r)⁶] + ε for r < 2^(1/6)σ; p = [ε, σ]. Uses lennard_jones from lj.wgsl.
fn wca_radial(p: array<f32, 8>, r: f32) -> Radial {
    if r < 1.122462048309373 * p[WCA_SIGMA] {
        var out = lennard_jones(p[WCA_EPSILON], p[WCA_SIGMA], r);
        out.energy += p[WCA_EPSILON];
        return out;
    }
    return RADIAL_ZERO;
}

// E″(r), for the stiffness block of the implicit step (shaders/common/implicit.wgsl).
fn wca_curvature(p: array<f32, 8>, r: f32) -> f32 {
    if r < 1.122462048309373 * p[WCA_SIGMA] {
        return lennard_jones_curvature(p[WCA_EPSILON], p[WCA_SIGMA], r);
    }
    return 0.0;
}
