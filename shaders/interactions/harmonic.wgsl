// harmonic: E = ½k(r − r0)²; p = [k, r0].
fn harmonic_radial(p: array<f32, 8>, r: f32) -> Radial {
    let stretch = r - p[HARMONIC_R0];
    return Radial(0.5 * p[HARMONIC_K] * stretch * stretch, p[HARMONIC_K] * stretch);
}

// E″(r) = k, for the stiffness block of the implicit step (shaders/common/implicit.wgsl).
fn harmonic_curvature(p: array<f32, 8>, r: f32) -> f32 {
    return p[HARMONIC_K];
}
