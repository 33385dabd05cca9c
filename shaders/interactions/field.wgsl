// field: E = e, F = (fx, fy, fz) with constant parameters (expression
// parameters run on the CPU backend only); p = [fx, fy, fz, e].
fn field_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {
    return OneBody(p[FIELD_E], vec3<f32>(p[FIELD_FX], p[FIELD_FY], p[FIELD_FZ]));
}
