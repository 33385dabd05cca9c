// wall: E = ½k·(d − n̂·x)² where n̂·x < d; p = [nx, ny, nz, d, k] (n normalised here).
fn wall_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {
    let raw = vec3<f32>(p[WALL_NX], p[WALL_NY], p[WALL_NZ]);
    let scale = max(max(abs(raw.x), abs(raw.y)), abs(raw.z));
    let n = normalize(raw / scale);
    let depth = p[WALL_D] - dot(n, x);
    if depth > 0.0 {
        return OneBody(0.5 * p[WALL_K] * depth * depth, p[WALL_K] * depth * n);
    }
    return OneBody(0.0, vec3<f32>(0.0));
}

// The Hessian k·n̂n̂ᵀ inside the wall (0 outside), positive semi-definite as
// it stands, for the implicit step (shaders/common/implicit.wgsl).
fn wall_hessian(p: array<f32, 8>, x: vec3<f32>) -> mat3x3<f32> {
    let raw = vec3<f32>(p[WALL_NX], p[WALL_NY], p[WALL_NZ]);
    let scale = max(max(abs(raw.x), abs(raw.y)), abs(raw.z));
    let n = normalize(raw / scale);
    if p[WALL_D] - dot(n, x) > 0.0 {
        return p[WALL_K] * mat3x3<f32>(n * n.x, n * n.y, n * n.z);
    }
    return mat3x3<f32>();
}
