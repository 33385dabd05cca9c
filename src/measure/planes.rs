//! Method of planes: the force transmitted across a plane.
//!
//! # Plane tension
//!
//! Thermo column `planetension/AXIS/POS` (AXIS `x`, `y` or `z`): the total
//! normal force that the terms crossing the plane x_AXIS = POS transmit
//! across it (force units, pN in `cell` units), **positive when the two
//! sides pull on each other (tension)** and negative when they push.
//! With the segments of [`Term`](crate::backend::Term) (bonds and pairs
//! from i to j, angles from the vertex, body terms from the nodes'
//! centroid), a segment whose end lies on the + side (x_AXIS ≥ POS) of a
//! plane its start is not on contributes −f·n̂, and one whose end lies on
//! the − side contributes +f·n̂, f being the force on the end and n̂ the
//! plane's normal along +AXIS. For a bond or pair of tension T = dE/dr and
//! direction û this is T·|û·n̂|. On a periodic axis the plane and its
//! periodic images are one plane. External fields transmit nothing.
//!
//! A chain held between two walls by end forces ±F transmits exactly F
//! across every plane between its ends once relaxed (a test checks it).
//! Integrated over POS across a periodic box, the plane tension is −W_aa,
//! the virial component along the axis.
//!
//! # Cortical tension
//!
//! Thermo column `gamma/BODYTYPE`: the method-of-planes estimator (Todd,
//! Evans & Daivis, Phys. Rev. E 52, 1627, 1995) of the cortical tension,
//!
//! γ = ⟨ Σ_cut T·|û·n̂| ⟩_planes / (2πR),
//!
//! over [`PLANES`] diametral planes through the centroid c of each body (the
//! mean of its node positions), with normals spread over the half sphere
//! (a Fibonacci lattice) and R the nodes' mean distance from c. The cut
//! counts the explicit load-bearing elements, bonds, pairs and angles,
//! whose segments cross a plane inside the disc |x − c| < 1.5·R (so the
//! cell's own cortex, not its neighbours'). Surface (`body`) laws are not
//! elements of the cut: a `surface_tension` γ is its own parameter, and
//! the pressure of `turgor` pushes the plane's two halves apart rather
//! than holding them together. The column is the mean over the bodies of
//! the type; units force/length (pN/µm = mN/m). For a pressurised shell of
//! edge springs, Young–Laplace gives γ = ΔP·R/2 (checked in
//! `tests/suite/measure.rs`).

use std::f64::consts::PI;

use glam::DVec3;

use crate::backend::{CpuBackend, TermKind};
use crate::system::{Model, SimBox, State};

/// Number of diametral planes the cortical-tension estimator averages over.
pub const PLANES: usize = 24;

/// Where a segment ends relative to a plane it crosses: +1 on the + side,
/// −1 on the − side, 0 when it does not cross. `a` is the start coordinate,
/// `d` the segment's extent along the normal, `period` the box length on a
/// periodic axis: the plane's periodic copies crossed, signed (more than
/// one for a pair through a far image in a box shorter than twice the
/// cutoff, `neighbor::ImageShifts`).
#[inline]
fn crossing(a: f64, d: f64, pos: f64, period: Option<f64>) -> f64 {
    match period {
        None => match (a >= pos, a + d >= pos) {
            (false, true) => 1.0,
            (true, false) => -1.0,
            _ => 0.0,
        },
        Some(l) => (((a - pos).rem_euclid(l) + d) / l).floor(),
    }
}

/// Force transmitted across the plane x_axis = pos (tension positive).
/// Needs a force evaluation of `backend` at `state` first.
pub fn plane_tension(backend: &CpuBackend, model: &Model, state: &State, sim_box: &SimBox, axis: usize, pos: f64) -> f64 {
    let period = sim_box.periodic[axis].then(|| sim_box.lengths()[axis]);
    let mut total = 0.0;
    backend.for_each_term(model, state, sim_box, |term| {
        for s in term.segments {
            let side = crossing(s.from[axis], s.d[axis], pos, period);
            if side != 0.0 {
                total -= side * s.force[axis];
            }
        }
    });
    total
}

/// `n` unit normals spread over the upper half sphere (z > 0), a Fibonacci lattice.
pub fn fibonacci_normals(n: usize) -> Vec<DVec3> {
    let golden = PI * (3.0 - 5f64.sqrt());
    (0..n)
        .map(|m| {
            let z = 1.0 - (m as f64 + 0.5) / n as f64;
            let rho = (1.0 - z * z).sqrt();
            let phi = golden * m as f64;
            DVec3::new(rho * phi.cos(), rho * phi.sin(), z)
        })
        .collect()
}

/// Centroid and mean node distance of body `b` (image-consistent nodes).
pub fn body_centre_and_radius(model: &Model, b: usize, positions: &[DVec3], sim_box: &SimBox) -> (DVec3, f64) {
    let body = &model.bodies[b];
    let images = sim_box.images();
    let mut x = Vec::with_capacity(body.nodes.len());
    body.mesh.unwrap_into(|k| positions[body.nodes[k as usize] as usize], |d| images.minimum_image(d), &mut x);
    let c = x.iter().sum::<DVec3>() / x.len() as f64;
    let r = x.iter().map(|p| (*p - c).length()).sum::<f64>() / x.len() as f64;
    (c, r)
}

/// Mean over the bodies of `body_type` of the cortical-tension estimator γ
/// (NaN when the type has no body). Needs a force evaluation at `state`.
pub fn cortical_tension(backend: &CpuBackend, model: &Model, state: &State, sim_box: &SimBox, body_type: usize) -> f64 {
    let images = sim_box.images();
    let normals = fibonacci_normals(PLANES);
    let bodies: Vec<usize> = (0..model.bodies.len()).filter(|&b| model.bodies[b].body_type as usize == body_type).collect();
    let mut sum = 0.0;
    for &b in &bodies {
        let (c, r) = body_centre_and_radius(model, b, &state.positions, sim_box);
        let disc2 = (1.5 * r).powi(2);
        let mut cut = vec![0.0; normals.len()];
        backend.for_each_term(model, state, sim_box, |term| {
            if term.kind == TermKind::Body {
                return;
            }
            for s in term.segments {
                let a = c + images.minimum_image(s.from - c);
                for (n, total) in normals.iter().zip(cut.iter_mut()) {
                    let (ha, hd) = ((a - c).dot(*n), s.d.dot(*n));
                    let side = crossing(ha, hd, 0.0, None);
                    if side == 0.0 {
                        continue;
                    }
                    let at = a + s.d * (-ha / hd);
                    if (at - c).length_squared() < disc2 {
                        *total -= side * s.force.dot(*n);
                    }
                }
            }
        });
        sum += cut.iter().sum::<f64>() / cut.len() as f64 / (2.0 * PI * r);
    }
    if bodies.is_empty() {
        f64::NAN
    } else {
        sum / bodies.len() as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn crossings_follow_the_half_open_sides_and_periodic_images() {
        assert_eq!(crossing(0.0, 1.0, 0.5, None), 1.0);
        assert_eq!(crossing(1.0, -1.0, 0.5, None), -1.0);
        assert_eq!(crossing(0.0, 0.4, 0.5, None), 0.0);
        // A particle on the plane is on its + side.
        assert_eq!(crossing(0.5, 0.2, 0.5, None), 0.0);
        assert_eq!(crossing(0.4, 0.1, 0.5, None), 1.0);
        // Periodic box of length 10: the plane at 0.5 is also at 10.5 and −9.5.
        assert_eq!(crossing(9.8, 1.0, 0.5, Some(10.0)), 1.0);
        assert_eq!(crossing(-9.2, -0.5, 0.5, Some(10.0)), -1.0);
        assert_eq!(crossing(3.0, 1.0, 0.5, Some(10.0)), 0.0);
        assert_eq!(crossing(20.2, 0.5, 0.5, Some(10.0)), 1.0);
        // Longer than the period: every copy of the plane crossed counts.
        assert_eq!(crossing(3.0, 25.0, 0.5, Some(10.0)), 2.0);
        assert_eq!(crossing(3.0, -12.0, 0.5, Some(10.0)), -1.0);
        assert_eq!(crossing(3.0, -13.0, 0.5, Some(10.0)), -2.0);
    }

    #[test]
    fn fibonacci_normals_are_unit_and_cover_the_half_sphere() {
        let n = fibonacci_normals(PLANES);
        assert!(n.iter().all(|v| (v.length() - 1.0).abs() < 1e-14 && v.z > 0.0));
        // Their mean is (0, 0, 1/2) for a uniform half sphere.
        let mean = n.iter().sum::<DVec3>() / n.len() as f64;
        assert!(mean.truncate().length() < 0.05 && (mean.z - 0.5).abs() < 0.01, "{mean}");
    }
}
