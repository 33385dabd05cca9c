// surface_tension: E = γ·A, −γ·∇A_t on each face's corners. p: gamma.
fn surface_tension_face(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> SurfaceFace {
    let gamma = p[SURFACE_TENSION_GAMMA];
    return SurfaceFace(gamma * g.area, -gamma * g.ga0, -gamma * g.ga1, -gamma * g.ga2);
}
