// cable: tension-only spring on the strain s = (r − r0)/r0 + τ: E = ½k·r0·s² for s > 0; p = [k, r0, τ].
fn cable_radial(p: array<f32, 8>, r: f32) -> Radial {
    let strain = (r - p[1]) / p[1] + p[2];
    if strain > 0.0 {
        return Radial(0.5 * p[0] * p[1] * strain * strain, p[0] * strain);
    }
    return RADIAL_ZERO;
}
