// flat_punch: E = (K/3)δ³, F = Kδ²·n̂ where δ = −n̂·(x − c) > 0 and the lateral
// distance from the axis is below a; p = [x, y, z, nx, ny, nz, a, K] (n normalised here).
fn flat_punch_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {
    let raw = vec3<f32>(p[FLAT_PUNCH_NX], p[FLAT_PUNCH_NY], p[FLAT_PUNCH_NZ]);
    let scale = max(max(abs(raw.x), abs(raw.y)), abs(raw.z));
    let n = normalize(raw / scale);
    let d = x - vec3<f32>(p[FLAT_PUNCH_X], p[FLAT_PUNCH_Y], p[FLAT_PUNCH_Z]);
    let depth = -dot(n, d);
    let lateral = d + depth * n;
    if depth <= 0.0 || dot(lateral, lateral) >= p[FLAT_PUNCH_A] * p[FLAT_PUNCH_A] {
        return OneBody(0.0, vec3<f32>(0.0));
    }
    return OneBody(p[FLAT_PUNCH_K] / 3.0 * depth * depth * depth, p[FLAT_PUNCH_K] * depth * depth * n);
}
