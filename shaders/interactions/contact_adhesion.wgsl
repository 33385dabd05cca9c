// contact_adhesion: E = ε·Σ_t A_t·s_a·s_b·s_c, ε = −w (the kernel:
// shaders/common/adhesion.wgsl); p: w, d_on, d_off.
// The quintic switch s(d) = 1 − (10t³ − 15t⁴ + 6t⁵), t = (d − d_on)/(d_off − d_on),
// 1 up to d_on and 0 from d_off on, with s′ (in `energy` and `de_dr`).
fn contact_adhesion_switch(p: array<f32, 8>, d: f32) -> Radial {
    let on = p[CONTACT_ADHESION_D_ON];
    let off = p[CONTACT_ADHESION_D_OFF];
    if d >= off {
        return RADIAL_ZERO;
    }
    if d <= on {
        return Radial(1.0, 0.0);
    }
    let width = off - on;
    let t = (d - on) / width;
    let t2 = t * t;
    return Radial(1.0 - t2 * t * (10.0 - 15.0 * t + 6.0 * t2), -30.0 * t2 * (1.0 - t) * (1.0 - t) / width);
}

// s″(d), for the implicit step's Gauss–Newton weight ε·s″·B (src/gpu/implicit.rs).
fn contact_adhesion_switch_curvature(p: array<f32, 8>, d: f32) -> f32 {
    let on = p[CONTACT_ADHESION_D_ON];
    let off = p[CONTACT_ADHESION_D_OFF];
    if d >= off || d <= on {
        return 0.0;
    }
    let width = off - on;
    let t = (d - on) / width;
    return -60.0 * t * (1.0 - t) * (1.0 - 2.0 * t) / (width * width);
}

// Energy per area of a face in full contact: ε = −w.
fn contact_adhesion_density(p: array<f32, 8>) -> f32 {
    return -p[CONTACT_ADHESION_W];
}
