// spring: E = ½k·r0·s², s = (r − r0)/r0 + τ; p = [k, r0, τ].
fn spring_radial(p: array<f32, 8>, r: f32) -> Radial {
    let strain = (r - p[1]) / p[1] + p[2];
    return Radial(0.5 * p[0] * p[1] * strain * strain, p[0] * strain);
}
