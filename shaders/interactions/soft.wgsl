// soft: E = A[1 + cos(πr/rc)] for r < rc; p = [A, rc].
fn soft_radial(p: array<f32, 8>, r: f32) -> Radial {
    if r < p[1] {
        let w = 3.141592653589793 / p[1];
        return Radial(p[0] * (1.0 + cos(w * r)), -p[0] * w * sin(w * r));
    }
    return RADIAL_ZERO;
}
