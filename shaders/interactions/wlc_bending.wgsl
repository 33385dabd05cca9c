// wlc_bending: E = (κ/ℓ)(1 − t̂1·t̂2) with t̂1 = (rj − ri)/|·|, t̂2 = (rk − rj)/|·|; p = [κ, ℓ].
fn wlc_bending_three(p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> ThreeBody {
    let strength = p[WLC_BENDING_KAPPA] / p[WLC_BENDING_L0];
    let a = rj - ri;
    let b = rk - rj;
    let la = length(a);
    let lb = length(b);
    let t1 = a / la;
    let t2 = b / lb;
    let c = dot(t1, t2);
    let fi = -strength * (t2 - c * t1) / la;
    let fk = strength * (t1 - c * t2) / lb;
    return ThreeBody(strength * (1.0 - c), fi, -fi - fk, fk);
}
