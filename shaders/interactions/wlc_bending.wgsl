// wlc_bending: E = (κ/ℓ)(1 − t̂1·t̂2) with t̂1 = (rj − ri)/|·|, t̂2 = (rk − rj)/|·|; p = [κ, ℓ].
// The two arms a = rj − ri, b = rk − rj: lengths, unit vectors, f = t̂1·t̂2
// and its gradients g_a = ∂f/∂a = (t̂2 − f t̂1)/|a|, g_b = ∂f/∂b = (t̂1 − f t̂2)/|b|.
struct WlcBendingArms {
    la: f32,
    lb: f32,
    t1: vec3<f32>,
    t2: vec3<f32>,
    c: f32,
    ga: vec3<f32>,
    gb: vec3<f32>,
}

fn wlc_bending_arms(ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> WlcBendingArms {
    let a = rj - ri;
    let b = rk - rj;
    let la = length(a);
    let lb = length(b);
    let t1 = a / la;
    let t2 = b / lb;
    let c = dot(t1, t2);
    return WlcBendingArms(la, lb, t1, t2, c, (t2 - c * t1) / la, (t1 - c * t2) / lb);
}

fn wlc_bending_three(p: array<f32, 8>, ri: vec3<f32>, rj: vec3<f32>, rk: vec3<f32>) -> ThreeBody {
    let strength = p[WLC_BENDING_KAPPA] / p[WLC_BENDING_L0];
    let arms = wlc_bending_arms(ri, rj, rk);
    let fi = -strength * arms.ga;
    let fk = strength * arms.gb;
    return ThreeBody(strength * (1.0 - arms.c), fi, -fi - fk, fk);
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
    let p1 = identity3() - outer3(arms.t1, arms.t1);
    let p2 = identity3() - outer3(arms.t2, arms.t2);
    let faa = (outer3(arms.t1, arms.ga) + outer3(arms.ga, arms.t1)) * (-1.0 / arms.la) - p1 * (arms.c / (arms.la * arms.la));
    let fbb = (outer3(arms.t2, arms.gb) + outer3(arms.gb, arms.t2)) * (-1.0 / arms.lb) - p2 * (arms.c / (arms.lb * arms.lb));
    let fab = (p1 * p2) * (1.0 / (arms.la * arms.lb));
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
