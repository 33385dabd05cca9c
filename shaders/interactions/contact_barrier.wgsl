// contact_barrier: b(d) = −κ(d − d̂)²·ln(d/d̂) for 0 < d < d̂ (the IPC log
// barrier), zero beyond d̂; p: dhat, kappa. At d ≤ 0 the energy is +∞ and
// b′ = −∞ (the step clamp never lets a pair get there).
fn contact_barrier_contact(p: array<f32, 8>, d: f32) -> Radial {
    let dhat = p[CONTACT_BARRIER_DHAT];
    let kappa = p[CONTACT_BARRIER_KAPPA];
    if d >= dhat {
        return RADIAL_ZERO;
    }
    if d <= 0.0 {
        let huge = bitcast<f32>(0x7f800000u);
        return Radial(huge, -huge);
    }
    let gap = d - dhat;
    let log = log(d / dhat);
    return Radial(-kappa * gap * gap * log, -kappa * (2.0 * gap * log + gap * gap / d));
}

// b″(d), the Gauss–Newton weight of the implicit step (src/gpu/implicit.rs).
fn contact_barrier_contact_curvature(p: array<f32, 8>, d: f32) -> f32 {
    let dhat = p[CONTACT_BARRIER_DHAT];
    if d >= dhat {
        return 0.0;
    }
    if d <= 0.0 {
        return bitcast<f32>(0x7f800000u);
    }
    let gap = d - dhat;
    return -p[CONTACT_BARRIER_KAPPA] * (2.0 * log(d / dhat) + 4.0 * gap / d - gap * gap / (d * d));
}
