// soft_repulsion: E = ½k(σ − r)² for r < σ; p = [k, σ].
fn soft_repulsion_radial(p: array<f32, 8>, r: f32) -> Radial {
    let overlap = p[SOFT_REPULSION_SIGMA] - r;
    if overlap > 0.0 {
        return Radial(0.5 * p[SOFT_REPULSION_K] * overlap * overlap, -p[SOFT_REPULSION_K] * overlap);
    }
    return RADIAL_ZERO;
}

// E″(r) = k inside σ, for the stiffness block of the implicit step (shaders/common/implicit.wgsl).
fn soft_repulsion_curvature(p: array<f32, 8>, r: f32) -> f32 {
    return select(0.0, p[SOFT_REPULSION_K], r < p[SOFT_REPULSION_SIGMA]);
}
