// wca: E = 4ε[(σ/r)¹² − (σ/r)⁶] + ε for r < 2^(1/6)σ; p = [ε, σ]. Uses lennard_jones from lj.wgsl.
fn wca_radial(p: array<f32, 8>, r: f32) -> Radial {
    if r < 1.122462048309373 * p[WCA_SIGMA] {
        var out = lennard_jones(p[WCA_EPSILON], p[WCA_SIGMA], r);
        out.energy += p[WCA_EPSILON];
        return out;
    }
    return RADIAL_ZERO;
}
