// area_conservation: dE/dA_t = k_a(A − A0)/A0 + k_l(A_t − a0)/a0 with
// a0 = A0/N_faces, times −∇A_t on the face's corners; the global energy
// ½k_a(A − A0)²/A0 shared equally by the faces, plus the face's own
// ½k_l(A_t − a0)²/a0. p: ka, kl, a0.
fn area_conservation_face(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> SurfaceFace {
    let a0_face = p[AREA_CONSERVATION_A0] / body.faces;
    let body_excess = body.area - p[AREA_CONSERVATION_A0];
    let face_excess = g.area - a0_face;
    let tension = p[AREA_CONSERVATION_KA] * body_excess / p[AREA_CONSERVATION_A0] + p[AREA_CONSERVATION_KL] * face_excess / a0_face;
    let energy = 0.5 * p[AREA_CONSERVATION_KA] * body_excess * body_excess / p[AREA_CONSERVATION_A0] / body.faces + 0.5 * p[AREA_CONSERVATION_KL] * face_excess * face_excess / a0_face;
    return SurfaceFace(energy, -tension * g.ga0, -tension * g.ga1, -tension * g.ga2);
}
// Its stiffness (the implicit step): per face (k_l/a0)·∇A_t∇A_tᵀ +
// (dE/dA_t)·∇²A_t (projected per face by the caller); over the whole body
// the global term's (k_a/A0)·∇A∇Aᵀ, as (volume weight, area weight).
fn area_conservation_face_hessian(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> array<f32, 81> {
    let a0_face = p[AREA_CONSERVATION_A0] / body.faces;
    let tension = p[AREA_CONSERVATION_KA] * (body.area - p[AREA_CONSERVATION_A0]) / p[AREA_CONSERVATION_A0]
        + p[AREA_CONSERVATION_KL] * (g.area - a0_face) / a0_face;
    return face_area_stencil(g, tension, p[AREA_CONSERVATION_KL] / a0_face);
}
fn area_conservation_body_weights(p: array<f32, 8>, body: BodyTotals) -> vec2<f32> {
    return vec2<f32>(0.0, select(0.0, p[AREA_CONSERVATION_KA] / p[AREA_CONSERVATION_A0], p[AREA_CONSERVATION_KA] > 0.0));
}
