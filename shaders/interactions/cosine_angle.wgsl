// cosine_angle: E = K(1 + cos θ), θ the angle at j; p = [K].
fn cosine_angle_three(p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> ThreeBody {
    let a = angle_arms(ri, rj, rk);
    let fi = -p[COSINE_ANGLE_K] * (a.vh - a.c * a.uh) / a.lu;
    let fk = -p[COSINE_ANGLE_K] * (a.uh - a.c * a.vh) / a.lv;
    return ThreeBody(p[COSINE_ANGLE_K] * (1.0 + a.c), fi, -fi - fk, fk);
}
