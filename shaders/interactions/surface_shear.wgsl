// surface_shear: E_t = k(S/(4√3·A_t) − 1) with S = Σ_e ℓ_e², forces
// −(k/(4√3))(∇S − (S/A_t)∇A_t)/A_t, corners a = 0, b = x1, c = x2. p: k.
fn surface_shear_face(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> SurfaceFace {
    let shape = 0.14433756729740643;
    let x21 = g.x2 - g.x1;
    let s = dot(g.x1, g.x1) + dot(x21, x21) + dot(g.x2, g.x2);
    let ratio = s / g.area;
    let c = -p[SURFACE_SHEAR_K] * shape / g.area;
    let f0 = c * (-2.0 * (g.x1 + g.x2) - ratio * g.ga0);
    let f1 = c * (2.0 * (2.0 * g.x1 - g.x2) - ratio * g.ga1);
    let f2 = c * (2.0 * (2.0 * g.x2 - g.x1) - ratio * g.ga2);
    return SurfaceFace(p[SURFACE_SHEAR_K] * (shape * ratio - 1.0), f0, f1, f2);
}
