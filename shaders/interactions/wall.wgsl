// wall: E = ½k·(d − n̂·x)² where n̂·x < d; p = [nx, ny, nz, d, k] (n normalised here).
fn wall_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {
    let raw = vec3<f32>(p[0], p[1], p[2]);
    let scale = max(max(abs(raw.x), abs(raw.y)), abs(raw.z));
    let n = normalize(raw / scale);
    let depth = p[3] - dot(n, x);
    if depth > 0.0 {
        return OneBody(0.5 * p[4] * depth * depth, p[4] * depth * n);
    }
    return OneBody(0.0, vec3<f32>(0.0));
}
