// wca: E = 4ε[(σ/r)¹² − (σ/r)⁶] + ε for r < 2^(1/6)σ; p = [ε, σ]. Uses lennard_jones from lj.wgsl.
fn wca_radial(p: array<f32, 8>, r: f32) -> Radial {
    if r < 1.122462048309373 * p[1] {
        var out = lennard_jones(p[0], p[1], r);
        out.energy += p[0];
        return out;
    }
    return RADIAL_ZERO;
}
