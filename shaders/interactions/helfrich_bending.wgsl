// helfrich_bending (Jülicher): node i's energy 2κu²/A_i with u = M_i − (C0/2)·A_i,
// and ∂E/∂M_i = 4κu/A_i, ∂E/∂A_i = −2κu(C0·A_i + u)/A_i². p: kappa, c0.
fn helfrich_bending_node(p: array<f32, 8>, m: f32, a: f32) -> NodeCurvature {
    let u = m - 0.5 * p[HELFRICH_BENDING_C0] * a;
    return NodeCurvature(2.0 * p[HELFRICH_BENDING_KAPPA] * u * u / a, 4.0 * p[HELFRICH_BENDING_KAPPA] * u / a, -2.0 * p[HELFRICH_BENDING_KAPPA] * u * (p[HELFRICH_BENDING_C0] * a + u) / (a * a));
}
// Its stiffness (the implicit step): per node the generalised Gauss–Newton
// term w·g gᵀ, w = 4κ/A_i, g = ∇M_i − β·∇A_i over the node's one-ring with
// β = C0/2 + u/A_i (2κu²/A is convex in (u, A)), as (w, β).
fn helfrich_bending_node_weights(p: array<f32, 8>, m: f32, a: f32) -> vec2<f32> {
    let c = 0.5 * p[HELFRICH_BENDING_C0];
    return vec2<f32>(4.0 * p[HELFRICH_BENDING_KAPPA] / a, c + (m - c * a) / a);
}
