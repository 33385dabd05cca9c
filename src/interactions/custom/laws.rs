//! The evaluators of custom terms, one per law family: each reads its
//! tapes from behind the parameter values ([`tape_of`]) and runs them.

use glam::DVec3;

use crate::expr::tape::run;
use crate::hessian::RankOne;
use crate::interactions::{over_r, OneBody, Radial, SurfaceHessian, SurfaceMesh, ThreeBody};
use crate::mesh::triangle_area_gradient;

/// The `i`-th of the `m` tapes behind a custom term's parameter values.
#[inline(always)]
fn tape_of(p: &[f64], m: usize, i: usize) -> &[f64] {
    let trailer = p.len() - m;
    let start = p[trailer + i] as usize;
    let end = if i + 1 < m { p[trailer + i + 1] as usize } else { trailer };
    &p[start..end]
}

pub(super) fn radial_eval(p: &[f64], r: f64) -> Radial {
    let mut out = [0.0; 3];
    run(tape_of(p, 2, 1), p, &[r], &mut out);
    Radial { energy: out[0], de_dr: out[1], d2e_dr2: out[2] }
}

pub(super) fn radial_force(p: &[f64], r2: f64) -> f64 {
    let r = r2.sqrt();
    let mut out = [0.0];
    run(tape_of(p, 2, 0), p, &[r], &mut out);
    over_r(out[0], r)
}

pub(super) fn pair_eval(p: &[f64], r: f64) -> Radial {
    if r < p[0] {
        radial_eval(p, r)
    } else {
        Radial::ZERO
    }
}

pub(super) fn pair_force(p: &[f64], r2: f64) -> f64 {
    if r2 < p[0] * p[0] {
        radial_force(p, r2)
    } else {
        0.0
    }
}

/// E(θ) at the middle particle j: F = −(dE/dθ)(dθ/dc)∇c with c = cos θ,
/// dθ/dc = −1/sin θ. Exactly straight or folded (sin θ = 0), ∇c = 0 and
/// so is the force.
pub(super) fn angle_eval(p: &[f64], [ri, rj, rk]: [DVec3; 3]) -> ThreeBody {
    let (u, v) = (ri - rj, rk - rj);
    let (lu, lv) = (u.length(), v.length());
    let (uh, vh) = (u / lu, v / lv);
    let c = uh.dot(vh).clamp(-1.0, 1.0);
    let mut out = [0.0; 2];
    run(tape_of(p, 1, 0), p, &[c.acos()], &mut out);
    let s = (1.0 - c * c).sqrt();
    let de_dc = if s > 0.0 { -out[1] / s } else { 0.0 };
    let fi = -de_dc * (vh - c * uh) / lu;
    let fk = -de_dc * (uh - c * vh) / lv;
    ThreeBody { energy: out[0], forces: [fi, -fi - fk, fk] }
}

pub(super) fn external_eval(p: &[f64], x: DVec3) -> OneBody {
    let mut out = [0.0; 4];
    run(tape_of(p, 1, 0), p, &[x.x, x.y, x.z], &mut out);
    OneBody { energy: out[0], force: -DVec3::new(out[1], out[2], out[3]) }
}

/// V and A with their gradients (added into `dv`, `da`).
fn volume_and_area(mesh: &SurfaceMesh, x: &[DVec3], dv: &mut [DVec3], da: &mut [DVec3]) -> (f64, f64) {
    let volume = mesh.volume_gradient(x, dv);
    let mut area = 0.0;
    for (t, face) in mesh.triangles().iter().enumerate() {
        let (a, g) = triangle_area_gradient(mesh.corners(t, x));
        area += a;
        for (node, g) in face.iter().zip(g) {
            da[*node as usize] += g;
        }
    }
    (volume, area)
}

pub(super) fn body_eval(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], forces: &mut [DVec3]) -> f64 {
    let (mut dv, mut da) = (vec![DVec3::ZERO; x.len()], vec![DVec3::ZERO; x.len()]);
    let (volume, area) = volume_and_area(mesh, x, &mut dv, &mut da);
    let mut out = [0.0; 3];
    run(tape_of(p, 2, 0), p, &[volume, area], &mut out);
    for ((f, gv), ga) in forces.iter_mut().zip(&dv).zip(&da) {
        *f -= out[1] * *gv + out[2] * *ga;
    }
    out[0]
}

/// Gauss–Newton model: max(E_VV, 0)·∇V∇Vᵀ + max(E_AA, 0)·∇A∇Aᵀ, plus the
/// exact E_A·∇²A face by face; the cross term E_VA and E_V·∇²V are left out
/// (as `turgor` leaves out −ΔP·∇²V).
pub(super) fn body_hessian(p: &[f64], mesh: &SurfaceMesh, x: &[DVec3], out: &mut SurfaceHessian) {
    let (mut dv, mut da) = (vec![DVec3::ZERO; x.len()], vec![DVec3::ZERO; x.len()]);
    let (volume, area) = volume_and_area(mesh, x, &mut dv, &mut da);
    let (mut first, mut second) = ([0.0; 3], [0.0; 2]);
    run(tape_of(p, 2, 0), p, &[volume, area], &mut first);
    run(tape_of(p, 2, 1), p, &[volume, area], &mut second);
    for (weight, gradient) in [(second[0], dv), (second[1], da)] {
        if weight > 0.0 {
            out.rank_one.push(RankOne { weight, gradient });
        }
    }
    if first[2] != 0.0 {
        for (t, face) in mesh.triangles().iter().enumerate() {
            out.push_face(*face, mesh.corners(t, x), first[2], 0.0);
        }
    }
}
