// field: E = e, F = (fx, fy, fz) with constant parameters (expression
// parameters run on the CPU backend only); p = [fx, fy, fz, e].
fn field_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {
    return OneBody(p[3], vec3<f32>(p[0], p[1], p[2]));
}
