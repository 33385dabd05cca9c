// harmonic: E = ½k(r − r0)²; p = [k, r0].
fn harmonic_radial(p: array<f32, 8>, r: f32) -> Radial {
    let stretch = r - p[1];
    return Radial(0.5 * p[0] * stretch * stretch, p[0] * stretch);
}
