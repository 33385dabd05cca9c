// field: E = e, F = (fx, fy, fz); p = [fx, fy, fz, e] (expression
// parameters are evaluated into p first: src/gpu/custom.rs).
fn field_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {
    return OneBody(p[FIELD_E], vec3<f32>(p[FIELD_FX], p[FIELD_FY], p[FIELD_FZ]));
}
