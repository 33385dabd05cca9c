// cable: tension-only spring on the strain s = (r − r0)/r0 + τ: E = ½k·r0·s² for s > 0; p = [k, r0, τ].
fn cable_radial(p: array<f32, 8>, r: f32) -> Radial {
    let strain = (r - p[CABLE_R0]) / p[CABLE_R0] + p[CABLE_TAU];
    if strain > 0.0 {
        return Radial(0.5 * p[CABLE_K] * p[CABLE_R0] * strain * strain, p[CABLE_K] * strain);
    }
    return RADIAL_ZERO;
}
