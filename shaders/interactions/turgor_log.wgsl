// turgor_log: ΔP = ΔP0 − K·ln(V/V0) pushing each corner by ΔP·A_t n̂_t/3;
// the body's energy −ΔP0(V − V0) + K(V·ln(V/V0) − V + V0) shared equally by
// its faces. A collapsed or inverted body (V ≤ 0) has no finite pressure:
// the largest f32 stands for it, so the step is refused. p: k, dp0, v0.
fn turgor_log_face(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> SurfaceFace {
    let v = body.volume;
    let v0 = p[TURGOR_LOG_V0];
    let ln_ratio = log(max(v, 1e-30) / v0);
    let pressure = select(p[TURGOR_LOG_DP0] - p[TURGOR_LOG_K] * ln_ratio, 3.4e38, v <= 0.0);
    let energy = select(-p[TURGOR_LOG_DP0] * (v - v0) + p[TURGOR_LOG_K] * (v * ln_ratio - v + v0), 3.4e38, v <= 0.0);
    let f = pressure * g.gv;
    return SurfaceFace(energy / body.faces, f, f, f);
}
// Its stiffness (the implicit step): no face stencil; the Gauss–Newton term
// (K/V)·∇V∇Vᵀ over the whole body (nothing for V ≤ 0), as (volume weight,
// area weight).
fn turgor_log_face_hessian(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> array<f32, 81> {
    return array<f32, 81>();
}
fn turgor_log_body_weights(p: array<f32, 8>, body: BodyTotals) -> vec2<f32> {
    return vec2<f32>(select(0.0, p[TURGOR_LOG_K] / body.volume, p[TURGOR_LOG_K] > 0.0 && body.volume > 0.0), 0.0);
}
