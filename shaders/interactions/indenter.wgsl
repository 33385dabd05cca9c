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
