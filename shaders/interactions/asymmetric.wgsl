// asymmetric: E = ½k(r − r0)² with k = k_tension for r > r0, k_compression otherwise; p = [k_tension, k_compression, r0].
fn asymmetric_radial(p: array<f32, 8>, r: f32) -> Radial {
    let stretch = r - p[ASYMMETRIC_R0];
    let k = select(p[ASYMMETRIC_K_COMPRESSION], p[ASYMMETRIC_K_TENSION], stretch > 0.0);
    return Radial(0.5 * k * stretch * stretch, k * stretch);
}
