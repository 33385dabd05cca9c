// harmonic_angle: E = ½k(θ − θ0)², θ the angle at j between i and k; p = [k, θ0 in degrees].
fn harmonic_angle_three(p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> ThreeBody {
    let u = ri - rj;
    let v = rk - rj;
    let lu = length(u);
    let lv = length(v);
    let uh = u / lu;
    let vh = v / lv;
    let c = clamp(dot(uh, vh), -1.0, 1.0);
    let theta = atan2(length(cross(uh, vh)), c);
    let dtheta = theta - radians(p[1]);
    let pi = vh - c * uh;
    let pk = uh - c * vh;
    let ei = pi / max(length(pi), 1e-12);
    let ek = pk / max(length(pk), 1e-12);
    let torque = p[0] * dtheta;
    let fi = torque / lu * ei;
    let fk = torque / lv * ek;
    return ThreeBody(0.5 * p[0] * dtheta * dtheta, fi, -fi - fk, fk);
}
