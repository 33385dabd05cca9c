// cosine_angle: E = K(1 + cos θ), θ the angle at j; p = [K].
fn cosine_angle_three(p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> ThreeBody {
    let u = ri - rj;
    let v = rk - rj;
    let lu = length(u);
    let lv = length(v);
    let uh = u / lu;
    let vh = v / lv;
    let c = dot(uh, vh);
    let fi = -p[0] * (vh - c * uh) / lu;
    let fk = -p[0] * (uh - c * vh) / lv;
    return ThreeBody(p[0] * (1.0 + c), fi, -fi - fk, fk);
}
