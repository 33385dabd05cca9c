// spring: E = ½k·r0·s², s = (r − r0)/r0 + τ; p = [k, r0, τ].
fn spring_radial(p: array<f32, 8>, r: f32) -> Radial {
    let strain = (r - p[SPRING_R0]) / p[SPRING_R0] + p[SPRING_TAU];
    return Radial(0.5 * p[SPRING_K] * p[SPRING_R0] * strain * strain, p[SPRING_K] * strain);
}
