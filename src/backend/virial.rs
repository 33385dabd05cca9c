//! Virial tensor helpers: symmetric 3×3 tensors stored as (xx, yy, zz, xy, xz, yz).

use glam::DVec3;

/// The symmetric part of a ⊗ b that the virial keeps.
#[inline]
pub(super) fn outer(a: DVec3, b: DVec3) -> [f64; 6] {
    [a.x * b.x, a.y * b.y, a.z * b.z, a.x * b.y, a.x * b.z, a.y * b.z]
}

/// `a += b`, component-wise.
#[inline]
pub(super) fn add6(a: &mut [f64; 6], b: [f64; 6]) {
    for k in 0..6 {
        a[k] += b[k];
    }
}
