// harmonic: E = ½k(r − r0)²; p = [k, r0].
fn harmonic_radial(p: array<f32, 8>, r: f32) -> Radial {
    let stretch = r - p[HARMONIC_R0];
    return Radial(0.5 * p[HARMONIC_K] * stretch * stretch, p[HARMONIC_K] * stretch);
}
