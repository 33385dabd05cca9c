// wlc_bending: E = (κ/ℓ)(1 − t̂1·t̂2) with t̂1 = (rj − ri)/|·|, t̂2 = (rk − rj)/|·|; p = [κ, ℓ].
// The two arms a = rj − ri, b = rk − rj: lengths, unit vectors, t̂1·t̂2.
struct WlcBendingArms {
    la: f32,
    lb: f32,
    t1: vec3<f32>,
    t2: vec3<f32>,
    c: f32,
}

fn wlc_bending_arms(ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> WlcBendingArms {
    let a = rj - ri;
    let b = rk - rj;
    let la = length(a);
    let lb = length(b);
    return WlcBendingArms(la, lb, a / la, b / lb, dot(a / la, b / lb));
}

fn wlc_bending_three(p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> ThreeBody {
    let strength = p[WLC_BENDING_KAPPA] / p[WLC_BENDING_L0];
    let arms = wlc_bending_arms(ri, rj, rk);
    let la = arms.la;
    let lb = arms.lb;
    let t1 = arms.t1;
    let t2 = arms.t2;
    let c = arms.c;
    let fi = -strength * (t2 - c * t1) / la;
    let fk = strength * (t1 - c * t2) / lb;
    return ThreeBody(strength * (1.0 - c), fi, -fi - fk, fk);
}

// The exact 9×9 Hessian of E (rows and columns i, j, k; row-major), not yet
// projected, for the implicit step (shaders/common/implicit.wgsl). With
// a = rj − ri, b = rk − rj and f = t̂1·t̂2, E = (κ/ℓ)(1 − f):
//   ∂²f/∂a² = −(t̂1 g_aᵀ + g_a t̂1ᵀ)/|a| − f·P1/|a|², g_a = (t̂2 − f t̂1)/|a|, P1 = I − t̂1t̂1ᵀ,
//   ∂²f/∂b² likewise, ∂²f/∂a∂b = P1·P2/(|a||b|),
// mapped to positions by a = −ri + rj, b = −rj + rk.
fn wlc_bending_hessian(p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> array<f32, 81> {
    let strength = p[WLC_BENDING_KAPPA] / p[WLC_BENDING_L0];
    let arms = wlc_bending_arms(ri, rj, rk);
    let la = arms.la;
    let lb = arms.lb;
    let t1 = arms.t1;
    let t2 = arms.t2;
    let c = arms.c;
    let ga = (t2 - c * t1) / la;
    let gb = (t1 - c * t2) / lb;
    let p1 = identity3() - outer3(t1, t1);
    let p2 = identity3() - outer3(t2, t2);
    let faa = (outer3(t1, ga) + outer3(ga, t1)) * (-1.0 / la) - p1 * (c / (la * la));
    let fbb = (outer3(t2, gb) + outer3(gb, t2)) * (-1.0 / lb) - p2 * (c / (lb * lb));
    let fab = (p1 * p2) * (1.0 / (la * lb));
    let s = -strength;
    var h: array<f32, 81>;
    put_block(&h, 0u, 0u, faa * s);
    put_block(&h, 0u, 1u, (fab - faa) * s);
    put_block(&h, 0u, 2u, fab * (-s));
    put_block(&h, 1u, 1u, (faa - fab - transpose(fab) + fbb) * s);
    put_block(&h, 1u, 2u, (fab - fbb) * s);
    put_block(&h, 2u, 2u, fbb * s);
    put_block(&h, 1u, 0u, transpose((fab - faa) * s));
    put_block(&h, 2u, 0u, transpose(fab * (-s)));
    put_block(&h, 2u, 1u, transpose((fab - fbb) * s));
    return h;
}
