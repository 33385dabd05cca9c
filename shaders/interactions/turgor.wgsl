// turgor: ΔP = ΔP0 + K(V0 − V)/V0 pushing each corner by ΔP·A_t n̂_t/3; the
// body's energy −ΔP0(V − V0) + K(V − V0)²/(2V0) shared equally by its faces.
// p: k, dp0, v0.
fn turgor_face(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> SurfaceFace {
    let dv = body.volume - p[2];
    let f = (p[1] - p[0] * dv / p[2]) * g.gv;
    return SurfaceFace((-p[1] * dv + 0.5 * p[0] * dv * dv / p[2]) / body.faces, f, f, f);
}
