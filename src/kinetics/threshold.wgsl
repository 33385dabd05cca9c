// threshold (src/kinetics/threshold.rs): beyond its threshold × (1 + spread·(u − ½))
// in strain or tension a bond breaks at `rate` (at once when rate = 0).
fn threshold_beyond(p: array<f32, 8>, force: f32, strain: f32, u: f32) -> Beyond {
    let factor = 1.0 + p[THRESHOLD_SPREAD] * (u - 0.5);
    let over_strain = p[THRESHOLD_STRAIN] > 0.0 && abs(strain) > p[THRESHOLD_STRAIN] * factor;
    let over_force = p[THRESHOLD_FORCE] > 0.0 && force > p[THRESHOLD_FORCE] * factor;
    return Beyond(over_strain || over_force, p[THRESHOLD_RATE]);
}
