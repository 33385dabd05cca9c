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
// Its stiffness (the implicit step): the exact Hessian of c·S/A_t per face
// (c = k/(4√3); projected per face by the caller):
// c·[∇²S/A − (∇S∇Aᵀ + ∇A∇Sᵀ)/A² + S·(2∇A∇Aᵀ/A³ − ∇²A/A²)], ∇²S = 2·L⊗I
// with L the triangle's graph Laplacian (2 on the diagonal, −1 off it);
// nothing over the whole body.
fn surface_shear_face_hessian(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> array<f32, 81> {
    let c = p[SURFACE_SHEAR_K] * 0.14433756729740643;
    let x21 = g.x2 - g.x1;
    let s = dot(g.x1, g.x1) + dot(x21, x21) + dot(g.x2, g.x2);
    let a = g.area;
    // c·S·(2∇A∇Aᵀ/A³ − ∇²A/A²): the area stencil of e(A) = cS/A at fixed S.
    var h = face_area_stencil(g, -c * s / (a * a), 2.0 * c * s / (a * a * a));
    var gs = array<vec3<f32>, 3>(-2.0 * (g.x1 + g.x2), 2.0 * (2.0 * g.x1 - g.x2), 2.0 * (2.0 * g.x2 - g.x1));
    var ga = array<vec3<f32>, 3>(g.ga0, g.ga1, g.ga2);
    for (var k = 0u; k < 3u; k++) {
        for (var l = 0u; l < 3u; l++) {
            for (var i = 0u; i < 3u; i++) {
                for (var j = 0u; j < 3u; j++) {
                    let laplacian = select(0.0, select(-2.0, 4.0, k == l), i == j);
                    h[(3u * k + i) * 9u + 3u * l + j] += c * (laplacian / a - (gs[k][i] * ga[l][j] + ga[k][i] * gs[l][j]) / (a * a));
                }
            }
        }
    }
    return h;
}
fn surface_shear_body_weights(p: array<f32, 8>, body: BodyTotals) -> vec2<f32> {
    return vec2<f32>(0.0);
}
