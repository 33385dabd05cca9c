// rebind (src/kinetics/rebind.rs): an unbound bond within the capture radius rebinds at k_on: (k_on, capture).
fn rebind_on_rate(p: array<f32, 8>) -> vec2<f32> {
    return vec2<f32>(p[REBIND_K_ON], p[REBIND_CAPTURE]);
}
