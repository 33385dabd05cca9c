// indenter: E = (K/3)(R − r)³ where r = |x − c| < R, F = K(R − r)²·(x − c)/r; p = [x, y, z, R, K].
fn indenter_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {
    let d = x - vec3<f32>(p[INDENTER_X], p[INDENTER_Y], p[INDENTER_Z]);
    let r = length(d);
    let depth = p[INDENTER_R] - r;
    if depth <= 0.0 {
        return OneBody(0.0, vec3<f32>(0.0));
    }
    let energy = p[INDENTER_K] / 3.0 * depth * depth * depth;
    if r > 0.0 {
        return OneBody(energy, (p[INDENTER_K] * depth * depth / r) * d);
    }
    return OneBody(energy, vec3<f32>(0.0));
}

// The Hessian's positive semi-definite part, for the implicit step
// (shaders/common/implicit.wgsl): inside the sphere E″ = 2K(R − r) along
// û = (x − c)/r; the transverse E′/r = −K(R − r)²/r is negative and dropped,
// as the CPU's projection of the term's Hessian drops it (0 outside).
fn indenter_hessian(p: array<f32, 8>, x: vec3<f32>) -> mat3x3<f32> {
    let d = x - vec3<f32>(p[INDENTER_X], p[INDENTER_Y], p[INDENTER_Z]);
    let r = length(d);
    let depth = p[INDENTER_R] - r;
    if depth <= 0.0 || r == 0.0 {
        return mat3x3<f32>();
    }
    let u = d / r;
    return (2.0 * p[INDENTER_K] * depth) * mat3x3<f32>(u * u.x, u * u.y, u * u.z);
}
