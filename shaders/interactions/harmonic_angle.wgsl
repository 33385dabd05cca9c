// harmonic_angle: E = ½k(θ − θ0)², θ the angle at j between i and k; p = [k, θ0 in degrees].
fn harmonic_angle_three(p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> ThreeBody {
    let a = angle_arms(ri, rj, rk);
    let c = clamp(a.c, -1.0, 1.0);
    let theta = atan2(length(cross(a.uh, a.vh)), c);
    let dtheta = theta - radians(p[HARMONIC_ANGLE_THETA0]);
    let pi = a.vh - c * a.uh;
    let pk = a.uh - c * a.vh;
    let ei = pi / max(length(pi), 1e-12);
    let ek = pk / max(length(pk), 1e-12);
    let torque = p[HARMONIC_ANGLE_K] * dtheta;
    let fi = torque / a.lu * ei;
    let fk = torque / a.lv * ek;
    return ThreeBody(0.5 * p[HARMONIC_ANGLE_K] * dtheta * dtheta, fi, -fi - fk, fk);
}
