// soft_repulsion: E = ½k(σ − r)² for r < σ; p = [k, σ].
fn soft_repulsion_radial(p: array<f32, 8>, r: f32) -> Radial {
    let overlap = p[SOFT_REPULSION_SIGMA] - r;
    if overlap > 0.0 {
        return Radial(0.5 * p[SOFT_REPULSION_K] * overlap * overlap, -p[SOFT_REPULSION_K] * overlap);
    }
    return RADIAL_ZERO;
}
