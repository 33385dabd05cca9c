// linear_elastic (St Venant–Kirchhoff): E = ½(FᵀF − I), W = μ·E:E + λ/2·(tr E)²,
// P = F·(2μE + λ·tr E·I); p = [e, nu].
fn linear_elastic_tetra(p: array<f32, 8>, f: mat3x3<f32>, j: f32, f_inv_t: mat3x3<f32>) -> TetraDensity {
    let lm = lame_constants(p[LINEAR_ELASTIC_E], p[LINEAR_ELASTIC_NU]);
    let identity = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    let green = 0.5 * (transpose(f) * f - identity);
    let trace = green[0].x + green[1].y + green[2].z;
    let ee = dot(green[0], green[0]) + dot(green[1], green[1]) + dot(green[2], green[2]);
    let w = lm.x * ee + 0.5 * lm.y * trace * trace;
    return TetraDensity(w, f * (2.0 * lm.x * green + (lm.y * trace) * identity));
}

// ∂²W/∂F∂F, entry [3A + α][3B + β] = ∂²W/∂F_αA∂F_βB (the implicit step's
// element block, shaders/common/implicit.wgsl), from P = F·S:
// δ_αβ·S_AB + μ·F_αB·F_βA + μ·(FFᵀ)_αβ·δ_AB + λ·F_αA·F_βB, with
// S = 2μE + λ·tr E·I and F_αA = f[A][α].
fn linear_elastic_tetra_hessian(p: array<f32, 8>, f: mat3x3<f32>, j: f32, f_inv_t: mat3x3<f32>) -> array<f32, 81> {
    let lm = lame_constants(p[LINEAR_ELASTIC_E], p[LINEAR_ELASTIC_NU]);
    let identity = mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
    let green = 0.5 * (transpose(f) * f - identity);
    let s = 2.0 * lm.x * green + (lm.y * (green[0].x + green[1].y + green[2].z)) * identity;
    let fft = f * transpose(f);
    var c: array<f32, 81>;
    for (var a = 0u; a < 3u; a++) {
        for (var al = 0u; al < 3u; al++) {
            for (var b = 0u; b < 3u; b++) {
                for (var be = 0u; be < 3u; be++) {
                    var v = lm.x * f[b][al] * f[a][be] + lm.y * f[a][al] * f[b][be];
                    if al == be {
                        v += s[b][a];
                    }
                    if a == b {
                        v += lm.x * fft[be][al];
                    }
                    c[(3u * a + al) * 9u + 3u * b + be] = v;
                }
            }
        }
    }
    return c;
}
