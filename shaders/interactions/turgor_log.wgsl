// turgor_log: ΔP = ΔP0 − K·ln(V/V0) pushing each corner by ΔP·A_t n̂_t/3;
// the body's energy −ΔP0(V − V0) + K(V·ln(V/V0) − V + V0) shared equally by
// its faces. A collapsed or inverted body (V ≤ 0) has no finite pressure:
// the largest f32 stands for it, so the step is refused. p: k, dp0, v0.
fn turgor_log_face(p: array<f32, 8>, body: BodyTotals, g: FaceGeometry) -> SurfaceFace {
    let v = body.volume;
    let v0 = p[2];
    let ln_ratio = log(max(v, 1e-30) / v0);
    let pressure = select(p[1] - p[0] * ln_ratio, 3.4e38, v <= 0.0);
    let energy = select(-p[1] * (v - v0) + p[0] * (v * ln_ratio - v + v0), 3.4e38, v <= 0.0);
    let f = pressure * g.gv;
    return SurfaceFace(energy / body.faces, f, f, f);
}
