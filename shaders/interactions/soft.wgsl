// soft: E = A[1 + cos(πr/rc)] for r < rc; p = [A, rc].
fn soft_radial(p: array<f32, 8>, r: f32) -> Radial {
    if r < p[SOFT_RC] {
        let w = 3.141592653589793 / p[SOFT_RC];
        return Radial(p[SOFT_A] * (1.0 + cos(w * r)), -p[SOFT_A] * w * sin(w * r));
    }
    return RADIAL_ZERO;
}
