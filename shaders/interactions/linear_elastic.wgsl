// linear_elastic (St Venant–Kirchhoff): E = ½(FᵀF − I), W = μ·E:E + λ/2·(tr E)²,
// P = F·(2μE + λ·tr E·I); p = [e, nu].
fn linear_elastic_tetra(p: array<f32, 8>, f: mat3x3<f32>, j: f32, f_inv_t: mat3x3<f32>) -> TetraDensity {
    let lm = lame_constants(p[LINEAR_ELASTIC_E], p[LINEAR_ELASTIC_NU]);
    let identity = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    let green = 0.5 * (transpose(f) * f - identity);
    let trace = green[0].x + green[1].y + green[2].z;
    let ee = dot(green[0], green[0]) + dot(green[1], green[1]) + dot(green[2], green[2]);
    let w = lm.x * ee + 0.5 * lm.y * trace * trace;
    return TetraDensity(w, f * (2.0 * lm.x * green + (lm.y * trace) * identity));
}
