// turgor: ΔP = ΔP0 + K(V0 − V)/V0 pushing each corner by ΔP·A_t n̂_t/3; the
// body's energy −ΔP0(V − V0) + K(V − V0)²/(2V0) shared equally by its faces.
// p: k, dp0, v0.
fn turgor_face(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> SurfaceFace {
    let dv = body.volume - p[TURGOR_V0];
    let f = (p[TURGOR_DP0] - p[TURGOR_K] * dv / p[TURGOR_V0]) * g.gv;
    return SurfaceFace((-p[TURGOR_DP0] * dv + 0.5 * p[TURGOR_K] * dv * dv / p[TURGOR_V0]) / body.faces, f, f, f);
}
// Its stiffness (the implicit step): no face stencil; the Gauss–Newton term
// (K/V0)·∇V∇Vᵀ over the whole body, as (volume weight, area weight).
fn turgor_face_hessian(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> array<f32, 81> {
    return array<f32, 81>();
}
fn turgor_body_weights(p: array<f32, 8>, body: BodyTotals) -> vec2<f32> {
    return vec2<f32>(select(0.0, p[TURGOR_K] / p[TURGOR_V0], p[TURGOR_K] > 0.0), 0.0);
}
