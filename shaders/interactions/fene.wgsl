// fene: E = −½KR0²·ln(1 − (r/R0)²) + WCA(ε, σ) for r < 2^(1/6)σ; p = [K, R0, ε, σ].
// Beyond R0 the energy and tension are +∞, as on the CPU (the step is refused).
fn fene_radial(p: array<f32, 8>, r: f32) -> Radial {
    let k = p[FENE_K];
    let r0 = p[FENE_R0];
    let x2 = (r / r0) * (r / r0);
    if !(x2 < 1.0) {
        let inf = bitcast<f32>(0x7f800000u);
        return Radial(inf, inf);
    }
    let logarg = 1.0 - x2;
    var out = Radial(-0.5 * k * r0 * r0 * log(logarg), k * r / logarg);
    let eps = p[FENE_EPSILON];
    let sigma = p[FENE_SIGMA];
    if r * r < 1.2599210498948732 * sigma * sigma {
        let s2 = sigma * sigma / (r * r);
        let s6 = s2 * s2 * s2;
        let s12 = s6 * s6;
        out.energy += 4.0 * eps * (s12 - s6) + eps;
        out.de_dr += 4.0 * eps * (-12.0 * s12 + 6.0 * s6) / r;
    }
    return out;
}
