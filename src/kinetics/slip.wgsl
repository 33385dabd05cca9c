// slip (src/kinetics/slip.rs): k_off = k0·exp(|F|·xβ/kT).
fn slip_rate(p: array<f32, 8>, f: f32, kt: f32) -> f32 {
    return p[SLIP_K0] * exp(abs(f) * p[SLIP_X_BETA] / kt);
}
