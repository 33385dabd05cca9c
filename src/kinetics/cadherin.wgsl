// cadherin (src/kinetics/cadherin.rs): the closed-form effective off-rate of
// its three-state generator, k = (k1·(kr + k2) + ks·k2)/(kr + k2 + ks), each
// rate a Bell law of F = max(tension, 0).
fn cadherin_rate(p: array<f32, 8>, f: f32, kt: f32) -> f32 {
    let g = max(f, 0.0);
    let k1 = p[CADHERIN_K10] * exp(g * p[CADHERIN_X1] / kt);
    let ks = p[CADHERIN_KS0] * exp(g * p[CADHERIN_XS] / kt);
    let kr = p[CADHERIN_KR0] * exp(-g * p[CADHERIN_XR] / kt);
    let k2 = p[CADHERIN_K20] * exp(g * p[CADHERIN_X2] / kt);
    return (k1 * (kr + k2) + ks * k2) / (kr + k2 + ks);
}
