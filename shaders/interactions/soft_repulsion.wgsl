// soft_repulsion: E = ½k(σ − r)² for r < σ; p = [k, σ].
fn soft_repulsion_radial(p: array<f32, 8>, r: f32) -> Radial {
    let overlap = p[1] - r;
    if overlap > 0.0 {
        return Radial(0.5 * p[0] * overlap * overlap, -p[0] * overlap);
    }
    return RADIAL_ZERO;
}
