// neo_hookean: W = μ/2·(I₁ − 3) − μ·ln J + λ/2·(ln J)², P = μ(F − F⁻ᵀ) + λ·ln J·F⁻ᵀ; p = [e, nu].
fn neo_hookean_tetra(p: array<f32, 8>, f: mat3x3<f32>, j: f32, f_inv_t: mat3x3<f32>) -> TetraDensity {
    let lm = lame_constants(p[NEO_HOOKEAN_E], p[NEO_HOOKEAN_NU]);
    let ln_j = log(j);
    let i1 = dot(f[0], f[0]) + dot(f[1], f[1]) + dot(f[2], f[2]);
    let w = 0.5 * lm.x * (i1 - 3.0) - lm.x * ln_j + 0.5 * lm.y * ln_j * ln_j;
    return TetraDensity(w, lm.x * (f - f_inv_t) + (lm.y * ln_j) * f_inv_t);
}

// ∂²W/∂F∂F, entry [3A + α][3B + β] = ∂²W/∂F_αA∂F_βB (the implicit step's
// element block, shaders/common/implicit.wgsl):
// μ·δ_αβ·δ_AB + (μ − λ·ln J)·F⁻¹_Aβ·F⁻¹_Bα + λ·F⁻¹_Aα·F⁻¹_Bβ, with
// F⁻¹_Aβ = f_inv_t[A][β].
fn neo_hookean_tetra_hessian(p: array<f32, 8>, f: mat3x3<f32>, j: f32, f_inv_t: mat3x3<f32>) -> array<f32, 81> {
    let lm = lame_constants(p[NEO_HOOKEAN_E], p[NEO_HOOKEAN_NU]);
    let twist = lm.x - lm.y * log(j);
    var c: array<f32, 81>;
    for (var a = 0u; a < 3u; a++) {
        for (var al = 0u; al < 3u; al++) {
            for (var b = 0u; b < 3u; b++) {
                for (var be = 0u; be < 3u; be++) {
                    let same = select(0.0, lm.x, a == b && al == be);
                    c[(3u * a + al) * 9u + 3u * b + be] = same + twist * f_inv_t[a][be] * f_inv_t[b][al] + lm.y * f_inv_t[a][al] * f_inv_t[b][be];
                }
            }
        }
    }
    return c;
}
