// neo_hookean: W = μ/2·(I₁ − 3) − μ·ln J + λ/2·(ln J)², P = μ(F − F⁻ᵀ) + λ·ln J·F⁻ᵀ; p = [e, nu].
fn neo_hookean_tetra(p: array<f32, 8>, f: mat3x3<f32>, j: f32, f_inv_t: mat3x3<f32>) -> TetraDensity {
    let lm = lame_constants(p[NEO_HOOKEAN_E], p[NEO_HOOKEAN_NU]);
    let ln_j = log(j);
    let i1 = dot(f[0], f[0]) + dot(f[1], f[1]) + dot(f[2], f[2]);
    let w = 0.5 * lm.x * (i1 - 3.0) - lm.x * ln_j + 0.5 * lm.y * ln_j * ln_j;
    return TetraDensity(w, lm.x * (f - f_inv_t) + (lm.y * ln_j) * f_inv_t);
}
