// helfrich_bending (Jülicher): node i's energy 2κu²/A_i with u = M_i − (C0/2)·A_i,
// and ∂E/∂M_i = 4κu/A_i, ∂E/∂A_i = −2κu(C0·A_i + u)/A_i². p: kappa, c0.
fn helfrich_bending_node(p: array<f32, 8>, m: f32, a: f32) -> NodeCurvature {
    let u = m - 0.5 * p[HELFRICH_BENDING_C0] * a;
    return NodeCurvature(2.0 * p[HELFRICH_BENDING_KAPPA] * u * u / a, 4.0 * p[HELFRICH_BENDING_KAPPA] * u / a, -2.0 * p[HELFRICH_BENDING_KAPPA] * u * (p[HELFRICH_BENDING_C0] * a + u) / (a * a));
}
