// catch_slip (src/kinetics/catch_slip.rs): k_off = kc0·exp(−F·xc/kT) + ks0·exp(F·xs/kT), F = max(tension, 0).
fn catch_slip_rate(p: array<f32, 8>, f: f32, kt: f32) -> f32 {
    let g = max(f, 0.0);
    return p[CATCH_SLIP_KC0] * exp(-g * p[CATCH_SLIP_XC] / kt) + p[CATCH_SLIP_KS0] * exp(g * p[CATCH_SLIP_XS] / kt);
}
