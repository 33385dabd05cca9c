// surface_tension: E = γ·A, −γ·∇A_t on each face's corners. p: gamma.
fn surface_tension_face(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> SurfaceFace {
    let gamma = p[SURFACE_TENSION_GAMMA];
    return SurfaceFace(gamma * g.area, -gamma * g.ga0, -gamma * g.ga1, -gamma * g.ga2);
}
// Its stiffness (the implicit step): the exact Hessian γ·∇²A_t of each face
// (projected per face by the caller), nothing over the whole body.
fn surface_tension_face_hessian(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> array<f32, 81> {
    return face_area_stencil(g, p[SURFACE_TENSION_GAMMA], 0.0);
}
fn surface_tension_body_weights(p: array<f32, 8>, body: BodyTotals) -> vec2<f32> {
    return vec2<f32>(0.0);
}
