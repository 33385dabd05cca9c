// constant_force: E = −f·x, F = f; p = [fx, fy, fz].
fn constant_force_one(p: array<f32, 8>, x: vec3<f32>) -> OneBody {
    let f = vec3<f32>(p[CONSTANT_FORCE_FX], p[CONSTANT_FORCE_FY], p[CONSTANT_FORCE_FZ]);
    return OneBody(-dot(f, x), f);
}

// A constant force has no stiffness (the implicit step, shaders/common/implicit.wgsl).
fn constant_force_hessian(p: array<f32, 8>, x: vec3<f32>) -> mat3x3<f32> {
    return mat3x3<f32>();
}
